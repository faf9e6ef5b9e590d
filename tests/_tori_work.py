"""Test-side work functions for the chunk engine of manakov.tori.

A separate module so that dask workers (spawned processes, which inherit
sys.path) can import the functions by reference.
"""

import os
import time

import numpy as np


def mix(scale, states):
    """A deterministic, float-sensitive per-state function (rows independent).

    Bit-identical results need the same arithmetic on every worker: a fixed
    sequence of numpy ufuncs on each row.
    """
    x = np.asarray(states, dtype=float)
    y = np.sin(scale * x).sum(axis=1) * np.exp(-np.abs(x[:, 0])) + np.sqrt(np.abs(x[:, 1]))
    return np.stack([y, np.cos(y)], axis=1)


def slow_mix(scale, states, delay=0.05):
    """``mix`` after a pause, so that a worker can be killed while chunks are in flight."""
    time.sleep(delay)
    return mix(scale, states)


def pid(_scale, _states):
    return os.getpid()
