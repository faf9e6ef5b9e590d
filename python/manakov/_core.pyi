"""Type stubs for the compiled module ``manakov._core`` (private; use ``manakov``)."""

import numpy as np
import numpy.typing as npt

__version__: str

class ConvergenceError(RuntimeError): ...

# --- curve (rust/python/curve.rs) ---

def curve_branch_points(d: npt.NDArray[np.complex128]) -> npt.NDArray[np.complex128]: ...
def curve_constants(
    d: npt.NDArray[np.complex128],
) -> tuple[npt.NDArray[np.complex128], npt.NDArray[np.complex128], npt.NDArray[np.complex128]]: ...
def curve_eval(
    d: npt.NDArray[np.complex128], x: npt.NDArray[np.complex128]
) -> tuple[npt.NDArray[np.complex128], npt.NDArray[np.complex128]]: ...
def curve_wurzel(
    d: npt.NDArray[np.complex128],
    z1: npt.NDArray[np.complex128],
    y1: npt.NDArray[np.complex128],
    z2: npt.NDArray[np.complex128],
    y2: npt.NDArray[np.complex128],
    eps: npt.NDArray[np.int8] | None = None,
) -> tuple[npt.NDArray[np.complex128], npt.NDArray[np.complex128]]: ...
def curve_xi_eta(
    d: npt.NDArray[np.complex128],
    z1: npt.NDArray[np.complex128],
    y1: npt.NDArray[np.complex128],
    z2: npt.NDArray[np.complex128],
    y2: npt.NDArray[np.complex128],
    g: npt.NDArray[np.complex128],
    eps: npt.NDArray[np.int8] | None = None,
    sqrt_c: npt.NDArray[np.complex128] | None = None,
) -> tuple[npt.NDArray[np.complex128], npt.NDArray[np.complex128]]: ...
def curve_points_from_xi_eta(
    d: npt.NDArray[np.complex128],
    xi: npt.NDArray[np.complex128],
    eta: npt.NDArray[np.complex128],
    sqrt_c: npt.NDArray[np.complex128] | None = None,
    g_ref: npt.NDArray[np.complex128] | None = None,
    rtol: float = 1e-08,
) -> tuple[npt.NDArray[np.complex128], npt.NDArray[np.int8], npt.NDArray[np.float64]]: ...

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
def kotter_lax_m(
    a: npt.NDArray[np.float64],
    b: npt.NDArray[np.float64],
    l: npt.NDArray[np.float64],
    s: npt.NDArray[np.complex128],
    sqrt_g: npt.NDArray[np.complex128],
) -> npt.NDArray[np.complex128]: ...
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
    zd: npt.NDArray[np.complex128] | None = None,
) -> npt.NDArray[np.float64]: ...
