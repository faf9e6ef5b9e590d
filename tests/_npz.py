"""Reading .npz files in tests."""

from __future__ import annotations

import numpy as np


def load_npz(path) -> dict[str, np.ndarray]:
    """The arrays of an .npz file, read and the file closed (an open NpzFile
    left to the garbage collector warns, and pytest turns that into a failure
    of whichever test runs then)."""
    with np.load(path) as f:
        return {k: f[k] for k in f.files}
