"""manakov: the four-dimensional free rigid body and its solution in theta functions.

Frahm's equations in Manakov's integrable case, after A. M. Perelomov, *Motion of
four-dimensional rigid body around a fixed point: an elementary approach*.
Equation numbers in docstrings are the paper's.
"""

from ._core import ConvergenceError, __version__
from .curve import CurvePoints, KotterCurve, Wurzel
from .problems import Problem, benchmark_setup, problem, problem_names
from .top import (
    METHODS,
    FrahmTop,
    ManakovTop,
    Trajectory,
    from_matrix,
    poisson_tensor,
    to_matrix,
)

__all__ = [
    "ConvergenceError",
    "CurvePoints",
    "KotterCurve",
    "Problem",
    "Wurzel",
    "FrahmTop",
    "METHODS",
    "ManakovTop",
    "Problem",
    "Trajectory",
    "__version__",
    "benchmark_setup",
    "from_matrix",
    "poisson_tensor",
    "problem",
    "problem_names",
    "to_matrix",
]
