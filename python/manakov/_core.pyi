"""Type stubs for the compiled module ``manakov._core`` (private; use ``manakov``)."""

import numpy as np
import numpy.typing as npt

__all__ = ["ConvergenceError", "__version__", "theta_jet", "theta_plan_info"]

__version__: str

class ConvergenceError(RuntimeError): ...

def theta_jet(
    z: npt.NDArray[np.complex128],
    tau: npt.NDArray[np.complex128],
    tol: float,
    order: int,
    scaled: bool,
) -> tuple[
    npt.NDArray[np.complex128],
    npt.NDArray[np.complex128],
    npt.NDArray[np.complex128],
    npt.NDArray[np.float64],
    bool,
]: ...
def theta_plan_info(
    tau: npt.NDArray[np.complex128], tol: float, order: int
) -> tuple[float, float, float, float]: ...
