"""A tiny dependency-free progress bar for long runs (written to stderr)."""

from __future__ import annotations

import sys
import time
from typing import TextIO


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
