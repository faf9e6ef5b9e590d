"""Ctrl-C stops a long theta batch; too-large batches and too-costly sums are refused."""

from __future__ import annotations

import sys
import textwrap
import time

import numpy as np
import pytest
from _sigint import STOP_WITHIN_S, sigint_after

import manakov
from manakov.theta import MAX_SECONDS_PER_POINT

TAU = np.array([[0.3 + 1.1j, 0.1 + 0.4j], [0.1 + 0.4j, -0.2 + 1.3j]])

# A batch of >= 10 s on any machine: genus 4 (256 thetas per point), its length
# calibrated in the child on a small batch, since machines differ by 2-3x.
CHILD = textwrap.dedent(
    """
    import sys, time
    import numpy as np
    import manakov
    tau = 1j * (np.eye(4) + 0.2 * np.ones((4, 4))) + 0.1 * np.arange(16).reshape(4, 4) % 3
    tau = (tau + tau.T) / 2
    probe = np.broadcast_to(0.1 * np.ones(4) + 0.05j, (2000, 4))
    t0 = time.perf_counter()
    manakov.theta_all(probe, tau, parallel={parallel})
    per_point = (time.perf_counter() - t0) / 2000
    n = int(min(max(10.0 / per_point, 2 * 10**4), 4 * 10**5))
    z = np.broadcast_to(0.1 * np.ones(4) + 0.05j, (n, 4))
    print("ready", flush=True)
    t0 = time.perf_counter()
    try:
        manakov.theta_all(z, tau, parallel={parallel})
    except KeyboardInterrupt:
        print("interrupted", time.perf_counter() - t0, flush=True)
        sys.exit(130)
    print("finished", time.perf_counter() - t0, flush=True)
    """
)


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
@pytest.mark.parametrize("parallel", [False, True])
def test_sigint_stops_a_long_theta_batch(parallel):
    # SIGINT 0.8 s in: well inside the batch.
    line, stopped, proc = sigint_after(CHILD.format(parallel=parallel), 0.8)
    # The call has stopped when the child reports it (interpreter shutdown after
    # that, freeing a 256 MB output, is not part of the call).
    out, err = proc.communicate(timeout=30)
    assert proc.returncode == 130, (line, out, err)
    assert line.startswith("interrupted"), (line, out, err)
    assert stopped < STOP_WITHIN_S, f"stopped {stopped:.3f} s after SIGINT"
    assert "Traceback" not in err


def test_a_batch_too_large_for_memory_is_a_memory_error_before_any_copy():
    # 10^9 points of genus 2 need 238 GiB of values; z itself is a 32-byte view.
    z = np.broadcast_to(np.zeros(2, complex), (10**9, 2))
    t0 = time.perf_counter()
    with pytest.raises(MemoryError, match="GiB"):
        manakov.theta_all(z, TAU)
    assert time.perf_counter() - t0 < 1.0


def test_fuzz_item_3_float_zeros_batch_is_a_memory_error():
    # The fuzzer's case, theta_all(np.zeros((10**8, 2)), tau), was a PanicException
    # ("PyObject pointer is null"); with a view instead of 1.6 GB of zeros.
    z = np.broadcast_to(np.zeros(2), (10**8, 2))
    with pytest.raises(MemoryError):
        manakov.theta_all(z, TAU)


def test_the_rust_output_allocation_is_fallible():
    # Past the Python pre-check, the binding's own allocation must not panic either.
    from manakov import _core

    z = np.broadcast_to(np.zeros(2, complex), (10**9, 2))
    with pytest.raises(MemoryError):
        _core.theta_jet(z, TAU, 1e-15, 0, True, False)
    z = np.broadcast_to(np.zeros(6, complex), (2**52, 6))
    tau6 = np.eye(6) * 2j
    with pytest.raises(ValueError, match="address space"):
        _core.theta_jet(z, tau6, 1e-15, 2, True, False)


def test_genus_6_near_the_term_cap_is_refused_at_once_with_the_estimate():
    tau = 0.3 + 0.2j * np.eye(6)  # ~2.2e8 terms, ~5-10 s of work per point
    t0 = time.perf_counter()
    with pytest.raises(ValueError, match=r"estimated .* s each"):
        manakov.theta(np.zeros(6), tau)
    assert time.perf_counter() - t0 < 0.1


def test_the_cost_estimate_bounds_the_time_of_an_accepted_large_genus_point():
    from manakov import _core

    tau = 0.3 + 0.5j * np.eye(6)
    est = _core.theta_plan_info(np.ascontiguousarray(tau), 1e-15, 0)[4]
    assert 0 < est <= MAX_SECONDS_PER_POINT
    t0 = time.perf_counter()
    manakov.theta(np.zeros(6), tau)
    took = time.perf_counter() - t0
    # The estimate errs high: the sum itself takes at most the estimate (with a
    # factor 3 for a loaded machine), never the 5-10 s of the fuzz report.
    assert took < 3 * est + 0.05, (took, est)


def test_theta_module_constant_matches_the_rust_budget():
    tau = 0.3 + 0.2j * np.eye(6)
    with pytest.raises(ValueError, match=f"{MAX_SECONDS_PER_POINT:g} s"):
        manakov.theta(np.zeros(6), tau)
