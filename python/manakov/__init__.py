"""manakov: the four-dimensional free rigid body and its solution in theta functions.

Frahm's equations in Manakov's integrable case, after A. M. Perelomov, *Motion of
four-dimensional rigid body around a fixed point: an elementary approach*.
Equation numbers in docstrings are the paper's.
"""

from ._core import ConvergenceError, __version__
from .problems import Problem, benchmark_setup, problem, problem_names
from .theta import (
    CHARACTERISTICS,
    PAPER_CHARACTERISTICS,
    PAPER_TABLE_35,
    char_index,
    characteristics,
    parity,
    theta,
    theta_all,
    theta_jet,
)

__all__ = [
    "CHARACTERISTICS",
    "PAPER_CHARACTERISTICS",
    "PAPER_TABLE_35",
    "char_index",
    "characteristics",
    "parity",
    "theta",
    "theta_all",
    "theta_jet",
    "ConvergenceError",
    "Problem",
    "__version__",
    "benchmark_setup",
    "problem",
    "problem_names",
]
