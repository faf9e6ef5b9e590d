"""Type stubs for the compiled module ``manakov._core`` (private; use ``manakov``)."""

import numpy as np
import numpy.typing as npt

__version__: str

class ConvergenceError(RuntimeError): ...

# --- kotter (rust/python/kotter.rs) ---

def kotter_integrals(
    a: npt.NDArray[np.float64], l: npt.NDArray[np.float64]
) -> npt.NDArray[np.float64]: ...
def kotter_schottky(
    a: npt.NDArray[np.float64],
    l: npt.NDArray[np.float64],
    s: npt.NDArray[np.complex128],
    sqrt_g: npt.NDArray[np.complex128],
) -> tuple[npt.NDArray[np.complex128], npt.NDArray[np.complex128]]: ...
def kotter_quartic(
    a: npt.NDArray[np.float64], h: npt.NDArray[np.float64]
) -> npt.NDArray[np.float64]: ...
def kotter_batch(
    a: npt.NDArray[np.float64], l: npt.NDArray[np.float64]
) -> dict[str, npt.NDArray[np.generic]]: ...
def kotter_from_points(
    alpha: npt.NDArray[np.complex128],
    beta: npt.NDArray[np.complex128],
    gamma: npt.NDArray[np.complex128],
    delta: npt.NDArray[np.complex128],
    d: npt.NDArray[np.complex128],
    z1: npt.NDArray[np.complex128],
    y1: npt.NDArray[np.complex128],
    z2: npt.NDArray[np.complex128],
    y2: npt.NDArray[np.complex128],
    g: npt.NDArray[np.complex128],
    branch: npt.NDArray[np.int8],
) -> npt.NDArray[np.float64]: ...
