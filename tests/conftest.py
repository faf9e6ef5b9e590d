"""Shared fixtures: the reference problems, as the package carries them."""

import manakov
import pytest

PROBLEM_NAMES = ("generic", "physical", "wide", "near_degenerate")


@pytest.fixture(params=PROBLEM_NAMES)
def reference_problem(request):
    """Each of the four shared reference tops in turn."""
    return manakov.problem(request.param)
