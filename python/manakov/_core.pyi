"""Type stubs for the compiled module ``manakov._core`` (private; use ``manakov``)."""

from collections.abc import Callable

import numpy as np
import numpy.typing as npt
from numpy.typing import NDArray
from typing_extensions import final

__all__ = [
    "ClosedFormError",
    "ConvergenceError",
    "check_budget",
    "check_c",
    "ClebschCore",
    "curve_branch_points",
    "curve_constants",
    "curve_eval",
    "curve_points_from_xi_eta",
    "curve_wurzel",
    "curve_xi_eta",
    "HyperellipticCore",
    "frequency_map",
    "gauss_steps",
    "SolutionCore",
    "gauss_tableau",
    "hamiltonian",
    "integrate",
    "integrate_many",
    "jacobi_ellipf",
    "jacobi_ellipj",
    "KirchhoffCore",
    "kirchhoff_casimirs",
    "kotter_batch",
    "kotter_from_points",
    "kotter_lax_m",
    "kotter_quartic",
    "kotter_schottky",
    "manakov_c",
    "manakov_integral_labels",
    "manakov_integrals",
    "MotionCore",
    "poisson_tensor",
    "real_torus",
    "so4_integrals",
    "theta_jet",
    "theta_plan_info",
    "tori_status_names",
    "torus_of_state",
    "vector_field",
    "__version__",
]

__version__: str

class ConvergenceError(RuntimeError): ...
class ClosedFormError(RuntimeError): ...

# --- riemann (rust/python/riemann.rs) ---

@final
class HyperellipticCore:
    def __new__(cls, branch_points: npt.NDArray[np.complex128]) -> HyperellipticCore: ...
    @property
    def genus(self) -> int: ...
    @property
    def branch_points(self) -> npt.NDArray[np.complex128]: ...
    def periods(self) -> tuple[npt.NDArray[np.complex128], npt.NDArray[np.complex128]]: ...
    def tau(self) -> npt.NDArray[np.complex128]: ...
    def cycle_periods(self) -> npt.NDArray[np.complex128]: ...
    def cycle_edges(self) -> npt.NDArray[np.int64]: ...
    def intersection_matrix(self) -> npt.NDArray[np.int64]: ...
    def symplectic_basis(self) -> npt.NDArray[np.int64]: ...
    def y(self, x: npt.NDArray[np.complex128], sheet: int) -> npt.NDArray[np.complex128]: ...
    def abel(
        self,
        x: npt.NDArray[np.complex128],
        y: npt.NDArray[np.complex128],
        route: int | None = None,
    ) -> npt.NDArray[np.complex128]: ...
    def abel_near_branch(
        self, k: int, dx: npt.NDArray[np.complex128], y: npt.NDArray[np.complex128]
    ) -> npt.NDArray[np.complex128]: ...
    def abel_branch_points(self) -> npt.NDArray[np.complex128]: ...
    def branch_chars(self) -> npt.NDArray[np.uint8]: ...
    def riemann_constant(self) -> npt.NDArray[np.complex128]: ...
    def riemann_constant_char(self) -> npt.NDArray[np.uint8]: ...
    def reduce(self, z: npt.NDArray[np.complex128]) -> npt.NDArray[np.complex128]: ...
    def invert(
        self, u: npt.NDArray[np.complex128]
    ) -> tuple[npt.NDArray[np.complex128], npt.NDArray[np.complex128]]: ...

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
    zd: npt.NDArray[np.complex128] | None = None,
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
    zd: npt.NDArray[np.complex128] | None = None,
) -> tuple[npt.NDArray[np.complex128], npt.NDArray[np.complex128]]: ...
def curve_points_from_xi_eta(
    d: npt.NDArray[np.complex128],
    xi: npt.NDArray[np.complex128],
    eta: npt.NDArray[np.complex128],
    sqrt_c: npt.NDArray[np.complex128] | None = None,
    g_ref: npt.NDArray[np.complex128] | None = None,
    rtol: float = 1e-08,
) -> tuple[
    npt.NDArray[np.complex128],
    npt.NDArray[np.int8],
    npt.NDArray[np.float64],
    npt.NDArray[np.complex128],
]: ...

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
    max_steps: int,
    progress: Callable[[int], object] | None = None,
) -> tuple[NDArray[np.float64], int, int, BaseException | None]: ...
def check_budget(
    method: str, t0: float, times: NDArray[np.float64], dt: float, max_steps: int
) -> None: ...
def gauss_steps(t0: float, times: NDArray[np.float64], dt: float) -> int: ...
def integrate_many(
    c: NDArray[np.float64],
    l0s: NDArray[np.float64],
    t0: float,
    times: NDArray[np.float64],
    method: str,
    dt: float,
    rtol: float,
    atol: float,
    max_steps: int,
    parallel: bool,
    progress: Callable[[int], object] | None = None,
) -> tuple[NDArray[np.float64], int]: ...
def gauss_tableau(
    method: str,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]: ...
def theta_jet(
    z: npt.NDArray[np.complex128],
    tau: npt.NDArray[np.complex128],
    tol: float,
    order: int,
    scaled: bool,
    parallel: bool,
) -> tuple[
    npt.NDArray[np.complex128],
    npt.NDArray[np.complex128],
    npt.NDArray[np.complex128],
    npt.NDArray[np.float64],
    bool,
]: ...
def theta_plan_info(
    tau: npt.NDArray[np.complex128], tol: float, order: int
) -> tuple[float, float, float, float, float]: ...

# --- kotter (rust/python/kotter.rs) ---

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
    a: npt.NDArray[np.float64],
    l: npt.NDArray[np.float64],
    l0: npt.NDArray[np.float64] | None = None,
    mask: bool = False,
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
def real_torus(
    tau: npt.NDArray[np.complex128],
    u: npt.NDArray[np.complex128],
    u2: npt.NDArray[np.complex128],
    chars: npt.NDArray[np.uint8],
) -> tuple[npt.NDArray[np.complex128], npt.NDArray[np.int64], npt.NDArray[np.float64]]: ...
def tori_status_names() -> list[str]: ...
def frequency_map(
    a: npt.NDArray[np.float64], b: npt.NDArray[np.float64], states: npt.NDArray[np.float64]
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.uint8]]: ...
def torus_of_state(
    a: npt.NDArray[np.float64], b: npt.NDArray[np.float64], l0: npt.NDArray[np.float64]
) -> tuple[
    npt.NDArray[np.complex128],
    npt.NDArray[np.int64],
    npt.NDArray[np.float64],
    npt.NDArray[np.complex128],
]: ...

@final
class SolutionCore:
    def __new__(
        cls,
        a: npt.NDArray[np.float64],
        b: npt.NDArray[np.float64],
        l0: npt.NDArray[np.float64],
    ) -> SolutionCore: ...
    def l(self, t: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...  # noqa: E743
    def abel(self, l: npt.NDArray[np.float64]) -> npt.NDArray[np.complex128]: ...
    @property
    def u0(self) -> npt.NDArray[np.complex128]: ...
    @property
    def rate(self) -> npt.NDArray[np.complex128]: ...
    @property
    def tau(self) -> npt.NDArray[np.complex128]: ...
    @property
    def riemann_constant(self) -> npt.NDArray[np.complex128]: ...
    @property
    def branch_points(self) -> npt.NDArray[np.complex128]: ...
    @property
    def characteristics(self) -> npt.NDArray[np.int64]: ...
    @property
    def constants(self) -> npt.NDArray[np.complex128]: ...
    @property
    def calibration(self) -> npt.NDArray[np.float64]: ...
    @property
    def self_check(self) -> float: ...
    @property
    def velocity_check(self) -> float: ...
    @property
    def drift_defect(self) -> float: ...
    @property
    def certify_every(self) -> str | None: ...
    def quotient(
        self,
    ) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.complex128], npt.NDArray[np.complex128]]: ...

@final
class KirchhoffCore:
    def __new__(
        cls,
        a: npt.NDArray[np.float64],
        b: npt.NDArray[np.float64],
        c: npt.NDArray[np.float64],
    ) -> KirchhoffCore: ...
    @property
    def rate_scale(self) -> float: ...
    def vector_field(self, y: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
    def hamiltonian(self, y: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
    def integrate(
        self,
        y0: npt.NDArray[np.float64],
        t0: float,
        times: npt.NDArray[np.float64],
        method: str,
        dt: float,
        rtol: float,
        atol: float,
        max_steps: int,
    ) -> tuple[npt.NDArray[np.float64], int, int, BaseException | None]: ...
    def integrate_many(
        self,
        y0s: npt.NDArray[np.float64],
        t0: float,
        times: npt.NDArray[np.float64],
        method: str,
        dt: float,
        rtol: float,
        atol: float,
        max_steps: int,
        parallel: bool,
    ) -> tuple[npt.NDArray[np.float64], int]: ...
    def integrate_space(
        self,
        s0: npt.NDArray[np.float64],
        t0: float,
        times: npt.NDArray[np.float64],
        method: str,
        dt: float,
        rtol: float,
        atol: float,
        max_steps: int,
    ) -> tuple[npt.NDArray[np.float64], int, int, BaseException | None]: ...

def kirchhoff_casimirs(y: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...

@final
class ClebschCore:
    def __new__(cls, a: npt.NDArray[np.float64], c: npt.NDArray[np.float64]) -> ClebschCore: ...
    @property
    def alpha(self) -> npt.NDArray[np.float64]: ...
    @property
    def beta(self) -> npt.NDArray[np.float64]: ...
    @property
    def order(self) -> npt.NDArray[np.int64]: ...
    @property
    def body_a(self) -> npt.NDArray[np.float64]: ...
    @property
    def violation(self) -> float: ...
    @property
    def mobius(self) -> tuple[float, float]: ...
    def to_so4(self, y: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
    def to_body(self, l: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...  # noqa: E741

# --- motion (rust/python/motion.rs) ---

@final
class MotionCore:
    def __new__(
        cls,
        a: npt.NDArray[np.float64],
        b: npt.NDArray[np.float64],
        l0: npt.NDArray[np.float64],
    ) -> MotionCore: ...
    @property
    def kind(self) -> str: ...
    def l(self, t: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...  # noqa: E743
    def l_precise(self, t: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
    def precise_polish(self) -> tuple[float, float]: ...
    @property
    def state_scale(self) -> float: ...
    @property
    def time_scale(self) -> float: ...
    def frame(
        self,
    ) -> tuple[
        npt.NDArray[np.float64],
        npt.NDArray[np.float64],
        list[float],
    ]: ...
    def genus2(self) -> SolutionCore | None: ...
    def euler(
        self,
    ) -> tuple[str, list[float], list[float], str, list[float]] | None: ...
    def closed_form_frequencies(self) -> list[float]: ...
    def near_euler_frequencies(self) -> list[float]: ...
    def near_plane_frequencies(self) -> list[float]: ...
    def closed_orbit_frequencies(self) -> list[float]: ...
    @property
    def stand_ins(self) -> tuple[int, str]: ...
    @property
    def stand_in_calls(self) -> int: ...
    def torus(
        self,
    ) -> tuple[
        npt.NDArray[np.complex128],
        npt.NDArray[np.int64],
        npt.NDArray[np.float64],
        npt.NDArray[np.complex128],
    ]: ...

def jacobi_ellipj(
    u: npt.NDArray[np.float64], m: float, m1: float
) -> tuple[
    npt.NDArray[np.float64],
    npt.NDArray[np.float64],
    npt.NDArray[np.float64],
    npt.NDArray[np.float64],
]: ...
def jacobi_ellipf(
    phi: npt.NDArray[np.float64], m: float, m1: float
) -> tuple[float, npt.NDArray[np.float64]]: ...
