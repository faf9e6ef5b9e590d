"""The long-double reference of ``tests/data/longdouble_ref.py`` for tests."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest


def longdouble_ref():
    """The module ``longdouble_ref`` (heyoka's Taylor integrator in long double and
    quadruple precision); the calling test is skipped where heyoka is missing."""
    pytest.importorskip("heyoka")
    data = str(Path(__file__).resolve().parent / "data")
    if data not in sys.path:
        sys.path.insert(0, data)
    import longdouble_ref

    return longdouble_ref
