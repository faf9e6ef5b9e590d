"""API contract of the reduction and curve functions under bad input: complex where real
is expected, overflow, non-finite values, malformed shapes (review findings)."""

# ruff: noqa: E741
from __future__ import annotations

import numpy as np
import pytest

import manakov
from manakov import reduction

P = manakov.problem("generic")
# The round trip l -> Kotter -> l, relative to |l|: the claim of issue 4.
ROUND_TRIP_TOL = 1e-12
L0 = np.asarray(P.l0, dtype=float)


@pytest.mark.parametrize(
    "call",
    [
        lambda: manakov.kotter(P.a, P.b, L0 + 1j),
        lambda: manakov.kotter(np.asarray(P.a) + 1j, P.b, L0),
        lambda: manakov.kotter(P.a, np.asarray(P.b) + 1j, L0),
        lambda: reduction.integrals(P.a, L0 + 1j),
        lambda: reduction.quartic(P.a, np.array([0.1, 1.0, 2.0, 3.0]) + 1j),
        lambda: reduction.schottky(P.a, L0 + 1j, 0.5),
    ],
)
def test_complex_where_real_expected_is_rejected(call):
    with pytest.raises(ValueError, match="real"):
        call()


def test_integrals_reject_non_finite_and_overflow():
    with pytest.raises(ValueError, match="finite"):
        reduction.integrals(P.a, np.full(6, np.nan))
    with pytest.raises(ValueError, match="overflow"):
        reduction.integrals(P.a, L0 * 1e300)
    with pytest.raises(ValueError, match="overflow"):
        reduction.quartic(P.a, [1e300, 1.0, 2.0, 3.0])


def test_schottky_checks_l_shape_and_s_before_numpy_warns():
    with pytest.raises(ValueError, match="shape"):
        reduction.schottky(P.a, 1.0, 0.5)
    with pytest.raises(ValueError, match="shape"):
        reduction.schottky(P.a, [1.0, 2.0], 0.5)
    # Under filterwarnings=error a numpy RuntimeWarning from G(inf) would escape instead.
    with pytest.raises(ValueError, match="finite"):
        reduction.schottky(P.a, L0, np.inf)
    with pytest.raises(ValueError, match="finite"):
        reduction.schottky(P.a, L0, 1e300)
    with pytest.raises(ValueError, match="finite"):
        reduction.lax_pair(P.a, P.b, L0, 1e300)


def test_curve_overflow_is_an_error():
    curve = manakov.KotterCurve(0.5 + 0.2j, 1.5 - 0.1j, 2.3 + 0.4j)
    with pytest.raises(ValueError, match="overflow"):
        curve.R(1e300)
    with pytest.raises(ValueError, match="overflow"):
        curve.y(1e300)


def test_inputs_are_not_modified_and_strided_read_only_inputs_work():
    top = manakov.ManakovTop(P.a, P.b)
    base = np.tile(L0, (3, 2))
    view = base[:, ::2]  # non-contiguous, shape (3, 6)
    before = base.copy()
    a = np.array(P.a, dtype=float)
    a_before = a.copy()
    k = manakov.kotter(a, P.b, view)
    reduction.integrals(a, view)
    reduction.schottky(a, view, 0.3 + 0.1j)
    reduction.lax_pair(a, P.b, view, 0.3 + 0.1j)
    ro = np.asfortranarray(view)
    ro.setflags(write=False)
    k_ro = top.kotter(ro)
    np.testing.assert_array_equal(k_ro.z1, k.z1)
    np.testing.assert_array_equal(base, before)
    np.testing.assert_array_equal(a, a_before)
    curve = k.curve[0]
    z1 = np.array(k.z1)
    z1_before = z1.copy()
    xi = np.array(k.xi)
    xi_before = xi.copy()
    curve.wurzel(z1[0], k.y1[0], k.z2[0], k.y2[0])
    curve.points_from_wurzel(xi[0], k.eta[0])
    top.from_kotter(k)
    np.testing.assert_array_equal(z1, z1_before)
    np.testing.assert_array_equal(xi, xi_before)


@pytest.mark.parametrize("scale", [1e-100, 1e-80, 1e77, 1e150])
def test_kotter_out_of_range_state_names_the_cause(scale):
    """Out of range, h ~ |l|^2 and F's coefficients ~ |l|^4 under/overflow; the errors
    once blamed a self-dual state (1e-100) or the form (38)/(40) (1e-80)."""
    with pytest.raises(ValueError, match="rescale l"):
        manakov.kotter(P.a, P.b, L0 * scale)


@pytest.mark.parametrize("scale", [1e-50, 1e50])
def test_kotter_inside_the_range_round_trips(scale):
    top = manakov.ManakovTop(P.a, P.b)
    l = L0 * scale
    back = top.from_kotter(top.kotter(l))
    # The round-trip claim of issue 4, at any scale in range.
    np.testing.assert_allclose(back, l, rtol=0, atol=ROUND_TRIP_TOL * np.max(np.abs(l)))


def test_from_kotter_rejects_g_zero_and_non_kotter():
    import dataclasses

    top = manakov.ManakovTop(P.a, P.b)
    k = top.kotter(L0)
    # g = 1/(1 - eps P_0) (42) is never 0; g = 0 once gave l = 0 silently.
    with pytest.raises(ValueError, match="g"):
        top.from_kotter(dataclasses.replace(k, g=0.0))
    with pytest.raises(TypeError, match="Kotter"):
        top.from_kotter(5)


def test_kotter_fields_are_read_only_like_the_curve_outputs():
    """Every array field of a Kotter is read-only (as the curve's outputs are), for one
    state and a batch; dataclasses.replace with a caller's writable array stores a
    read-only copy and leaves the caller's array alone; from_kotter still inverts."""
    import dataclasses

    top = manakov.ManakovTop(P.a, P.b)
    for l in (L0, np.array([L0, 1.1 * L0])):
        k = top.kotter(l)
        arrays = {f.name: getattr(k, f.name) for f in dataclasses.fields(k)}
        arrays = {n: v for n, v in arrays.items() if isinstance(v, np.ndarray)}
        assert {"xi", "eta", "d", "s", "branch", "zd"} <= set(arrays)
        for name, v in arrays.items():
            assert not v.flags.writeable, name
            with pytest.raises(ValueError, match="read-only"):
                v[...] = v
        np.testing.assert_allclose(
            top.from_kotter(k), l, rtol=0, atol=ROUND_TRIP_TOL * np.max(np.abs(l))
        )
    k = top.kotter(L0)
    zd = k.zd.copy()
    k2 = dataclasses.replace(k, zd=zd)
    assert not k2.zd.flags.writeable and zd.flags.writeable
    zd[0, 0] += 1.0  # the caller's array stays the caller's: k2 holds a copy
    np.testing.assert_array_equal(k2.zd, k.zd)
    k3 = dataclasses.replace(k, zd=k.zd.copy())
    np.testing.assert_allclose(
        top.from_kotter(k3), L0, rtol=0, atol=ROUND_TRIP_TOL * np.max(np.abs(L0))
    )
