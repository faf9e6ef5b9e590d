"""Progress reports of long calls: a text bar on stderr, or the caller's callable."""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from typing import TextIO

import numpy as np


class ProgressBar:
    """Text progress bar: ``update(fraction)`` redraws, ``close()`` ends the line.

    Draws only when the stream is a terminal unless ``force`` is set, so logs
    and pipes stay clean.
    """

    def __init__(
        self, label: str = "", *, width: int = 30, stream: TextIO | None = None, force: bool = False
    ) -> None:
        self.label = label
        self.width = width
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = force or bool(getattr(self.stream, "isatty", lambda: False)())
        self.start = time.perf_counter()
        self.fraction = 0.0

    def update(self, fraction: float) -> None:
        """Show ``fraction`` (clipped to [0, 1]) done, with elapsed time and an estimate left."""
        self.fraction = min(max(float(fraction), 0.0), 1.0)
        if not self.enabled:
            return
        filled = int(round(self.width * self.fraction))
        elapsed = time.perf_counter() - self.start
        left = elapsed * (1 - self.fraction) / self.fraction if self.fraction > 0 else float("nan")
        bar = "#" * filled + "-" * (self.width - filled)
        pct = 100 * self.fraction
        line = f"\r{self.label} [{bar}] {pct:5.1f}%  {elapsed:6.1f}s  (~{left:.1f}s left)"
        self.stream.write(line)
        self.stream.flush()

    def close(self) -> None:
        """Finish the line."""
        if self.enabled:
            self.stream.write("\n")
            self.stream.flush()


class Progress:
    """The ``progress`` argument of a long call, resolved once: a context manager
    that reports the fraction done.

    ``progress`` is ``None`` (automatic: a bar on stderr when stderr is a
    terminal and the call is ``long``), ``True`` (a bar on stderr, always),
    ``False`` (nothing) or a callable ``f(fraction)``, called with fractions in
    [0, 1] that never decrease, from the calling thread, ending with 1.0 when
    the call completes. An exception raised by the callable stops the call and
    propagates (with ``.partial`` where the call keeps partial results).

    Raises
    ------
    ValueError
        Any other ``progress``.
    """

    def __init__(self, progress: object, label: str, *, long: bool) -> None:
        self._bar: ProgressBar | None = None
        self._fn: Callable[[float], object] | None = None
        self._last = 0.0
        self._reported = False
        if progress is None or isinstance(progress, (bool, np.bool_)):
            show = long if progress is None else bool(progress)
            if show:
                self._bar = ProgressBar(label, force=progress is not None)
                if not self._bar.enabled:
                    self._bar = None
        elif callable(progress):
            self._fn = progress
        else:
            raise ValueError(
                f"progress must be True, False, None or a callable f(fraction), got {progress!r}"
            )

    @property
    def active(self) -> bool:
        """Whether anything is reported (a bar is drawn or a callable called)."""
        return self._bar is not None or self._fn is not None

    def __call__(self, fraction: float) -> None:
        """Report ``fraction`` done (clipped to [0, 1], never below the last report)."""
        f = min(max(float(fraction), self._last), 1.0)
        if f == self._last and self._reported:
            return
        self._last, self._reported = f, True
        if self._bar is not None:
            self._bar.update(f)
        if self._fn is not None:
            self._fn(f)

    def close(self) -> None:
        """End the bar's line (if a bar is drawn)."""
        if self._bar is not None:
            self._bar.close()
            self._bar = None

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
