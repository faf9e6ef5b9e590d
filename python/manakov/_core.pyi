"""Type stubs for the compiled module ``manakov._core`` (private; use ``manakov``)."""

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "ConvergenceError",
    "__version__",
    "check_c",
    "gauss_tableau",
    "hamiltonian",
    "integrate",
    "integrate_many",
    "manakov_c",
    "manakov_integral_labels",
    "manakov_integrals",
    "poisson_tensor",
    "so4_integrals",
    "vector_field",
]

__version__: str

class ConvergenceError(RuntimeError): ...

# --- so4 / integrate (rust/python/so4.rs) ---
def manakov_c(a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]: ...
def check_c(c: NDArray[np.float64]) -> None: ...
def vector_field(c: NDArray[np.float64], l: NDArray[np.float64]) -> NDArray[np.float64]: ...
def hamiltonian(c: NDArray[np.float64], l: NDArray[np.float64]) -> NDArray[np.float64]: ...
def so4_integrals(a: NDArray[np.float64], l: NDArray[np.float64]) -> NDArray[np.float64]: ...
def manakov_integral_labels(n: int) -> list[tuple[int, int]]: ...
def manakov_integrals(a: NDArray[np.float64], l: NDArray[np.float64]) -> NDArray[np.float64]: ...
def poisson_tensor(l: NDArray[np.float64]) -> NDArray[np.float64]: ...
def integrate(
    c: NDArray[np.float64],
    l0: NDArray[np.float64],
    t0: float,
    times: NDArray[np.float64],
    method: str,
    dt: float,
    rtol: float,
    atol: float,
) -> tuple[NDArray[np.float64], int, int]: ...
def integrate_many(
    c: NDArray[np.float64],
    l0s: NDArray[np.float64],
    t0: float,
    times: NDArray[np.float64],
    method: str,
    dt: float,
    rtol: float,
    atol: float,
    parallel: bool,
) -> tuple[NDArray[np.float64], int]: ...
def gauss_tableau(
    method: str,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]: ...
