"""Shared fixtures: the reference problems, as the package carries them."""

import pytest

import manakov

PROBLEM_NAMES = ("generic", "physical", "wide", "near_degenerate")


@pytest.fixture(params=PROBLEM_NAMES)
def reference_problem(request):
    """Each of the four shared reference tops in turn."""
    return manakov.problem(request.param)


@pytest.fixture(scope="module")
def client():
    """A dask.distributed client on a 2-process LocalCluster (one per test module)."""
    distributed = pytest.importorskip("distributed")
    with (
        distributed.LocalCluster(
            n_workers=2,
            processes=True,
            threads_per_worker=1,
            dashboard_address=None,
            silence_logs=50,
        ) as cluster,
        distributed.Client(cluster) as c,
    ):
        yield c
