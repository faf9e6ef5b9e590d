"""manakov: the four-dimensional free rigid body and its solution in theta functions.

Frahm's equations in Manakov's integrable case, after A. M. Perelomov, *Motion of
four-dimensional rigid body around a fixed point: an elementary approach*.
Equation numbers in docstrings are the paper's.
"""

from ._core import ConvergenceError, __version__
from .curve import CurvePoints, KotterCurve, Wurzel
from .kotter import Kotter, from_kotter, kotter  # (shadows the submodule name)
from .problems import Problem, benchmark_setup, problem, problem_names

__all__ = [
    "ConvergenceError",
    "CurvePoints",
    "Kotter",
    "KotterCurve",
    "Problem",
    "Wurzel",
    "__version__",
    "benchmark_setup",
    "from_kotter",
    "kotter",
    "problem",
    "problem_names",
]
