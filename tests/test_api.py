"""API contract of the dynamics functions: dtypes, shapes, broadcasting, read-only and
non-contiguous inputs, inputs never modified, exact exception types, no panics."""

# ruff: noqa: E741
from __future__ import annotations

import warnings

import numpy as np
import pytest

import manakov

# Two runs of the same method and step ending at the same t: equal up to roundoff
# accumulated over ~t_end/dt steps (1e-13 is ~500 ulps of |l| ~ 1).
SAME_STEP_ATOL = 1e-13


@pytest.fixture
def top():
    p = manakov.problem("generic")
    return manakov.ManakovTop(p.a, p.b)


def test_scalar_in_scalar_out(top):
    l = manakov.problem("generic").l0
    h = top.hamiltonian(l)
    assert np.ndim(h) == 0 and isinstance(h, float)
    ints = top.integrals(l)
    assert all(np.ndim(v) == 0 for v in ints.values())
    assert top.vector_field(l).shape == (6,)
    assert manakov.poisson_tensor(l).shape == (6, 6)


def test_broadcasting_over_leading_axes(top):
    rng = np.random.default_rng(0)
    ls = rng.normal(size=(2, 3, 6))
    f = top.vector_field(ls)
    assert f.shape == (2, 3, 6)
    for idx in np.ndindex(2, 3):
        np.testing.assert_array_equal(f[idx], top.vector_field(ls[idx]))
        assert top.hamiltonian(ls)[idx] == top.hamiltonian(ls[idx])
    assert manakov.poisson_tensor(ls).shape == (2, 3, 6, 6)
    assert all(v.shape == (2, 3) for v in top.integrals(ls).values())
    assert top.vector_field(np.zeros((0, 6))).shape == (0, 6)


@pytest.mark.parametrize("dtype", [np.float32, np.int64, np.float64])
def test_other_real_dtypes_are_converted(top, dtype):
    l = np.array([1, -2, 0, 3, 1, 2], dtype=dtype)
    np.testing.assert_array_equal(top.vector_field(l), top.vector_field(l.astype(float)))
    assert top.vector_field(l).dtype == np.float64


def test_read_only_and_non_contiguous_inputs(top):
    rng = np.random.default_rng(1)
    base = rng.normal(size=(4, 12))
    view = base[:, ::2]  # non-contiguous (stride 2)
    assert not view.flags.c_contiguous
    ro = view.copy()
    ro.setflags(write=False)
    np.testing.assert_array_equal(top.vector_field(view), top.vector_field(ro))
    np.testing.assert_array_equal(top.vector_field(view.T.copy().T), top.vector_field(ro))
    before = base.copy()
    top.integrate(view[0], 1.0)
    top.integrate_many(view, 1.0)
    manakov.poisson_tensor(view)
    np.testing.assert_array_equal(base, before)
    # Fortran-ordered input
    np.testing.assert_array_equal(top.vector_field(np.asfortranarray(ro)), top.vector_field(ro))


def test_constructor_inputs_are_not_modified_and_attributes_read_only():
    a = np.array([0.3, 1.1, 2.0, 3.7])
    b = np.array([0.5, -0.2, 1.4, 0.9])
    top = manakov.ManakovTop(a, b)
    a[0] = 99.0
    assert top.a[0] == 0.3
    for arr in (top.a, top.b, top.c):
        with pytest.raises(ValueError):
            arr[0] = 1.0
    assert top.n == 4 and top.c.shape == (4, 4)


def test_trajectory_shapes(top):
    tr = top.integrate(manakov.problem("generic").l0, 2.0, sample_every=0.5)
    assert tr.t.shape == (5,) and tr.l.shape == (5, 6)
    assert all(v.shape == (5,) for v in tr.integrals.values())
    assert tr.steps > 0 and tr.evals > tr.steps


@pytest.mark.parametrize(
    "a,b,match",
    [
        ([1.0, 2.0, 1.0, 3.0], [0, 1, 2, 3], r"a\[0\] == a\[2\]"),
        ([1.0, 2.0, 3.0], [0, 1], "same length"),
        ([1.0, 2.0], [0.0, 1.0], "n >= 3"),
        ([1.0, np.nan, 3.0], [0, 1, 2], "finite"),
        ([1.0, 2.0, 3.0], [0, np.inf, 2], "finite"),
        ([[1.0, 2.0, 3.0]], [[0, 1, 2]], "1-d"),
        ([1.0, 2.0, 3.0 + 1j], [0, 1, 2], "real"),
        ([0.0, 1e-300, 1.0], [1e300, -1e300, 0.0], "overflow"),
    ],
)
def test_manakov_top_rejects_bad_parameters(a, b, match):
    with pytest.raises(ValueError, match=match):
        manakov.ManakovTop(a, b)


@pytest.mark.parametrize(
    "c,match",
    [
        (np.array([[0, 1, 2], [1.5, 0, 3], [2, 3, 0]]), "symmetric"),
        (np.ones((3, 4)), "shape"),
        (np.ones((2, 2)), "n >= 3"),
        (np.full((3, 3), np.nan), "finite"),
    ],
)
def test_frahm_top_rejects_bad_c(c, match):
    with pytest.raises(ValueError, match=match):
        manakov.FrahmTop(c)


def test_frahm_top_accepts_roundoff_asymmetry():
    c = np.array([[0, 1, 2], [1 + 2e-16, 0, 3], [2, 3, 0]])
    top = manakov.FrahmTop(c)  # 2e-16 is 1 ulp of 1 < the 8-ulp symmetry tolerance
    np.testing.assert_array_equal(top.c, c)


@pytest.mark.parametrize(
    "l", [np.ones(5), np.ones((2, 7)), np.array([np.nan] * 6), 3.0, np.array([1j] * 6)]
)
def test_state_functions_reject_bad_states(top, l):
    for fn in (top.vector_field, top.hamiltonian, top.integrals):
        with pytest.raises(ValueError):
            fn(l)


def test_poisson_tensor_rejects_bad_lengths():
    with pytest.raises(ValueError):
        manakov.poisson_tensor(np.ones(5))
    with pytest.raises(ValueError):
        manakov.poisson_tensor(2.0)


def test_no_panic_reaches_python_from_the_core():
    """Direct calls into the compiled module with inconsistent arguments raise ValueError."""
    from manakov import _core

    c = manakov.problem("generic")
    cm = _core.manakov_c(c.a, c.b)
    bad_calls = [
        lambda: _core.vector_field(cm, np.ones((2, 5))),
        lambda: _core.vector_field(np.ones((3, 4)), np.ones((2, 6))),
        lambda: _core.so4_integrals(np.ones(3), np.ones((1, 6))),
        lambda: _core.manakov_integrals(np.arange(4.0), np.ones((1, 5))),
        lambda: _core.poisson_tensor(np.ones((1, 4))),
        lambda: _core.integrate(cm, np.ones(5), 0.0, np.array([1.0]), "gauss6", 0.1, 0, 0, 1000),
        lambda: _core.integrate(cm, np.ones(6), 0.0, np.array([1.0]), "nope", 0.1, 0, 0, 1000),
        lambda: _core.integrate(cm, np.ones(6), 0.0, np.array([np.nan]), "gauss6", 0.1, 0, 0, 1000),
        lambda: _core.integrate(cm, np.ones(6), np.inf, np.array([1.0]), "gauss6", 0.1, 0, 0, 1000),
        lambda: _core.integrate_many(
            cm, np.ones((2, 5)), 0.0, np.array([1.0]), "gauss6", 0.1, 0, 0, 1000, True
        ),
        lambda: _core.integrate(cm, np.ones(6), 0.0, np.array([1.0]), "gauss6", 0.1, 0, 0, 0),
        lambda: _core.gauss_tableau("dopri5"),
        lambda: _core.manakov_c(np.ones(3), np.ones(3)),
    ]
    for call in bad_calls:
        with pytest.raises(ValueError):
            call()


def test_overflow_is_an_error_not_a_silent_nan(top):
    huge = np.full(6, 1e200)
    with pytest.raises(ValueError, match="overflow"):
        top.vector_field(huge)
    with pytest.raises(ValueError, match="overflow"):
        top.hamiltonian(huge)
    with pytest.raises(ValueError, match="overflow"):
        top.integrals(huge)
    # The default step scales as 1/|l0|: 1e200 steps would be needed.
    with pytest.raises(ValueError, match=r"huge \|l0\|"):
        top.integrate(huge, 1.0)
    for method in ("gauss16", "gauss4", "dop853", "dopri5"):
        with pytest.raises(manakov.ConvergenceError):
            top.integrate(huge, 1.0, dt=0.1, method=method)


# --- Review findings: each input below once gave a silent NaN/inf, a discarded imaginary
# part, a numpy warning instead of ValueError, or a spurious ConvergenceError.


def test_manakov_integrals_overflow_is_an_error():
    top5 = manakov.ManakovTop([1.0, 2.0, 3.0, 4.0, 5.0], [3.0, 1.0, 2.0, 0.0, 4.0])
    with pytest.raises(ValueError, match="overflow"):
        top5.manakov_integrals(np.full(10, 1e100))


def test_matrix_helpers_reject_complex_and_non_finite():
    l = np.array([0.3, -0.5, 0.7, 0.2, 0.9, -0.4])
    with pytest.raises(ValueError, match="real"):
        manakov.to_matrix(l + 1j)
    with pytest.raises(ValueError, match="finite"):
        manakov.to_matrix(np.full(6, np.nan))
    with pytest.raises(ValueError, match="real"):
        manakov.from_matrix(manakov.to_matrix(l) + 0j)
    with pytest.raises(ValueError, match="finite"):
        manakov.from_matrix(np.full((3, 3), np.nan))


def test_from_matrix_skew_check_does_not_overflow():
    """Issue 11 fuzz: m + m^T overflowed (a RuntimeWarning) for entries near 1e308."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ValueError, match="skew"):
            manakov.from_matrix([[0.0, 1e308], [1e308, 0.0]])
        l = manakov.from_matrix([[0.0, 1.7e308], [-1.7e308, 0.0]])
    assert l.tolist() == [1.7e308]


@pytest.mark.parametrize("t_eval", [[1e-320], [1e-320, 1.0], [0.0, 5e-324, 1.0]])
@pytest.mark.parametrize("method", ["gauss4", "gauss6", "gauss16"])
def test_subnormal_sample_spacing_integrates(top, t_eval, method):
    """Steps with a subnormal size once made 0/0 in the stage predictor."""
    l0 = manakov.problem("generic").l0
    tr = top.integrate(l0, t_eval[-1], t_eval=t_eval, method=method)
    np.testing.assert_array_equal(tr.l[0], l0)  # a subnormal step cannot move l
    ref = top.integrate(l0, t_eval[-1], t_eval=[t_eval[-1]], method=method)
    # Both end at the same t with the same method and step: equal to roundoff
    # accumulated over ~t_end/dt steps.
    np.testing.assert_allclose(tr.l[-1], ref.l[-1], rtol=0, atol=SAME_STEP_ATOL)


def test_so_n_integrate_subnormal_step():
    top3 = manakov.ManakovTop([1.0, 2.0, 3.0], [3.0, 1.0, 2.0])
    tr = top3.integrate([1.0, 2.0, 3.0], 1.0, t_eval=[1e-320, 1.0], method="gauss6")
    assert np.all(np.isfinite(tr.l))


@pytest.mark.parametrize("method", ["gauss16", "gauss4", "dop853", "dopri5"])
def test_step_budget_bounds_every_method(top, method):
    """A huge t_end once ran for hours (up to 1e11 steps, GIL released, no Ctrl-C)."""
    l0 = manakov.problem("generic").l0
    with pytest.raises(ValueError, match="max_steps"):
        top.integrate(l0, 1e12, t_eval=[0.0, 1e12], method=method, max_steps=1000)
    with pytest.raises(ValueError, match="max_steps"):
        top.integrate_many(np.array([l0]), 1e12, t_eval=[0.0, 1e12], method=method, max_steps=1000)
    # Samples do not reset the budget: 100 samples of ~30 steps each exceed 1000.
    with pytest.raises(ValueError, match="max_steps"):
        top.integrate(l0, 1e4, sample_every=100.0, method=method, max_steps=1000)
    # ... nor do chunks of the Python loop.
    with pytest.raises(ValueError, match="max_steps"):
        top.integrate(l0, 1e4, method=method, max_steps=1000, chunks=50)


def test_default_step_budget_stops_a_huge_gauss_run_at_once(top):
    l0 = manakov.problem("generic").l0
    # ~3e9 default gauss16 steps: refused before any step is taken.
    with pytest.raises(ValueError, match="max_steps"):
        top.integrate(l0, 1e9, t_eval=[0.0, 1e9])
    assert manakov.top.DEFAULT_MAX_STEPS <= 10**8


@pytest.mark.parametrize("bad", [0, -1, 1.5, 10**12, "many"])
def test_max_steps_must_be_a_positive_integer(top, bad):
    with pytest.raises(ValueError, match="max_steps"):
        top.integrate(manakov.problem("generic").l0, 1.0, max_steps=bad)


def test_empty_trajectory_has_empty_drifts(top):
    """A run with no samples once raised IndexError in relative_drift."""
    tr = top.integrate(manakov.problem("generic").l0, 1.0, t_eval=[])
    assert tr.l.shape == (0, 6)
    assert all(v.shape == (0,) for v in tr.relative_drift().values())
    assert all(v == 0.0 for v in tr.max_drift().values())
