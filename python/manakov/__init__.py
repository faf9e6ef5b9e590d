"""manakov: the four-dimensional free rigid body and its solution in theta functions.

Frahm's equations in Manakov's integrable case, after A. M. Perelomov, *Motion of
four-dimensional rigid body around a fixed point: an elementary approach*.
Equation numbers in docstrings are the paper's.
"""

from ._core import ClosedFormError, ConvergenceError, __version__
from .curve import CurvePoints, KotterCurve, Wurzel
from .fluid import (
    ClebschSolution,
    FluidProblem,
    FluidTrajectory,
    KirchhoffBody,
    SpaceTrajectory,
    fluid_problem,
    fluid_problem_names,
)
from .integrate import METHODS, Trajectory
from .problems import Problem, benchmark_setup, problem, problem_names
from .reduction import Kotter, LevelSet, from_kotter, kotter
from .riemann import HyperellipticCurve
from .solution import IntegratedValuesWarning, Solution
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
from .top import FrahmTop, ManakovTop, from_matrix, poisson_tensor, to_matrix
from .tori import FrequencyMap, Torus, frequency_map, real_torus

__all__ = [
    "benchmark_setup",
    "char_index",
    "ClebschSolution",
    "CHARACTERISTICS",
    "characteristics",
    "ClosedFormError",
    "ConvergenceError",
    "CurvePoints",
    "FluidProblem",
    "fluid_problem",
    "fluid_problem_names",
    "FluidTrajectory",
    "FrahmTop",
    "frequency_map",
    "FrequencyMap",
    "HyperellipticCurve",
    "IntegratedValuesWarning",
    "from_kotter",
    "from_matrix",
    "KirchhoffBody",
    "kotter",
    "Kotter",
    "LevelSet",
    "KotterCurve",
    "ManakovTop",
    "METHODS",
    "PAPER_CHARACTERISTICS",
    "PAPER_TABLE_35",
    "parity",
    "poisson_tensor",
    "problem",
    "Problem",
    "problem_names",
    "real_torus",
    "Solution",
    "SpaceTrajectory",
    "theta",
    "theta_all",
    "theta_jet",
    "to_matrix",
    "Torus",
    "Trajectory",
    "Wurzel",
    "__version__",
]
