"""The scripts in examples/ run and print what they claim."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

# What each example must print: a pattern whose number must be below a bound.
# The bounds are the claims the examples make (roundoff-level conservation and
# round trip), not the values they happen to print.
CLAIMS = {
    "long_run.py": (["1e4"], r"drift of\s+H0: ([0-9.e+-]+)", 1e-13),
    "kotter_along_trajectory.py": (["generic"], r"round trip .*: ([0-9.e+-]+)", 1e-12),
    "theta_identities.py": ([], r"relative error: ([0-9.e+-]+)", 1e-13),
    # The map's level-set route and the solutions' theta route agree to the
    # accuracy of the reduction's constants (tests/test_tori_solution.py).
    "frequency_map.py": (["generic", "24"], r"map vs solve: ([0-9.e+-]+)", 1e-13),
    # issue 10's 1e-11 on [0, 100] (201 samples, gauss16 at dt = 1e-3)
    "theorem.py": (
        ["physical", "/tmp/manakov_theorem_example.png"],
        r"\[0, 100\]: ([0-9.e+-]+)",
        1e-11,
    ),
    # docs/theorem.md: both evaluations of the Theorem agree to their accuracy
    "precise_theorem.py": (
        ["wide", "/tmp/manakov_precise_example.png"],
        r"precise vs double on \[0, 100\]: ([0-9.e+-]+)",
        1e-13,
    ),
    "riemann_basis.py": (["--no-plot"], r"tau asymmetry \(relative\): ([0-9.e+-]+)", 1e-14),
    # docs/clebsch.md: the Clebsch closed form to 1e-11 on [0, 100]
    "fluid_body.py": (["clebsch_generic", "20"], r"\[0, 100\]: ([0-9.e+-]+)", 1e-11),
}


@pytest.mark.parametrize("name", sorted(CLAIMS))
def test_example_runs_and_meets_its_claim(name, tmp_path):
    args, pattern, bound = CLAIMS[name]
    out = subprocess.run(
        [sys.executable, str(EXAMPLES / name), *args],
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
        cwd=tmp_path,  # examples that write figures write them there
    ).stdout
    m = re.search(pattern, out)
    assert m, out
    assert float(m.group(1)) <= bound, out


def test_every_example_is_tested():
    assert {p.name for p in EXAMPLES.glob("*.py")} == set(CLAIMS)
