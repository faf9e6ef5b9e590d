"""The package's copy of the reference problems is the shared one, unchanged."""

import json
from pathlib import Path

import manakov
import numpy as np
import pytest
from conftest import PROBLEM_NAMES

SHARED = Path(__file__).resolve().parents[2] / "shared" / "reference" / "problems.json"


def test_all_four_problems_are_carried():
    assert set(manakov.problem_names()) == set(PROBLEM_NAMES)


@pytest.mark.skipif(not SHARED.exists(), reason="shared/ is not beside this checkout")
def test_package_copy_matches_shared_reference():
    shared = json.loads(SHARED.read_text())
    for name, top in shared["tops"].items():
        p = manakov.problem(name)
        np.testing.assert_array_equal(p.a, top["a"])
        np.testing.assert_array_equal(p.b, top["b"])
        np.testing.assert_array_equal(p.l0, top["l0"])
    assert manakov.benchmark_setup("theta") == shared["benchmark"]["theta"]


def test_unknown_problem_is_a_value_error():
    with pytest.raises(ValueError, match="unknown problem"):
        manakov.problem("no-such-top")
