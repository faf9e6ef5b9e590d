"""Ctrl-C in a child process, for the tests that a long call stops in time."""

from __future__ import annotations

import signal
import subprocess
import sys
import time

#: Ctrl-C must stop a call within this long (the project's promise).
STOP_WITHIN_S = 0.5


def sigint_after(child: str, delay: float) -> tuple[str, float, subprocess.Popen]:
    """Run ``python -c child``, wait for it to print ``ready``, send SIGINT ``delay``
    seconds later; return the next line it prints, the seconds from the signal to
    that line, and the process (still to be ``communicate``-d)."""
    proc = subprocess.Popen(
        [sys.executable, "-c", child],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert proc.stdout is not None
    assert proc.stdout.readline().strip() == "ready"
    time.sleep(delay)
    sent = time.perf_counter()
    proc.send_signal(signal.SIGINT)
    line = proc.stdout.readline()
    return line, time.perf_counter() - sent, proc
