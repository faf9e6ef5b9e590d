"""The reference problems carried inside the package.

``data/problems.json`` is a verbatim copy of the project's shared reference
problems: four Manakov tops (``generic``, ``physical``, ``wide``,
``near_degenerate``), each with ``a``, ``b`` and an initial state ``l0`` ordered
(l12, l13, l14, l23, l24, l34), and the benchmark set-ups.
"""

from __future__ import annotations

import json
from functools import lru_cache
from importlib import resources
from typing import Any, NamedTuple

import numpy as np

__all__ = ["Problem", "problem", "problem_names", "benchmark_setup"]


class Problem(NamedTuple):
    """A reference top: Manakov parameters ``a``, ``b`` (2) and initial state ``l0``."""

    name: str
    a: np.ndarray
    b: np.ndarray
    l0: np.ndarray
    note: str


@lru_cache(maxsize=1)
def _data() -> dict[str, Any]:
    text = resources.files("manakov").joinpath("data/problems.json").read_text()
    return json.loads(text)


def problem_names() -> list[str]:
    """Names of the built-in reference tops.

    Returns
    -------
    list of str
        ``["generic", "physical", "wide", "near_degenerate"]`` in file order.
    """
    return list(_data()["tops"])


def problem(name: str) -> Problem:
    """Return the built-in reference top ``name`` (see :func:`problem_names`).

    Parameters
    ----------
    name : str

    Returns
    -------
    Problem
        ``(name, a, b, l0, note)``; ``a``, ``b`` of shape (4,) define ``c_ij`` by (2),
        ``l0`` of shape (6,) is ordered ``(l12, l13, l14, l23, l24, l34)``.

    Raises
    ------
    ValueError
        If there is no problem of that name.
    """
    tops = _data()["tops"]
    if name not in tops:
        raise ValueError(f"unknown problem {name!r}; known: {', '.join(tops)}")
    t = tops[name]
    return Problem(
        name=name,
        a=np.array(t["a"], dtype=float),
        b=np.array(t["b"], dtype=float),
        l0=np.array(t["l0"], dtype=float),
        note=t.get("note", ""),
    )


def benchmark_setup(name: str) -> dict[str, Any]:
    """The benchmark set-up ``name`` (``"integration"`` or ``"theta"``) as a dict.

    Parameters
    ----------
    name : str

    Returns
    -------
    dict
        A copy of the set-up's entry in ``data/problems.json``.

    Raises
    ------
    ValueError
        If there is no set-up of that name.
    """
    bench = _data()["benchmark"]
    if name not in bench:
        raise ValueError(f"unknown benchmark {name!r}; known: {', '.join(bench)}")
    return dict(bench[name])
