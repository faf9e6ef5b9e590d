"""The ``manakov simulate`` command line."""

from __future__ import annotations

import io
import subprocess
import sys

import numpy as np
import pytest

import manakov
from manakov import cli
from manakov._progress import ProgressBar


def test_simulate_builtin_problem_writes_npz_and_png(tmp_path, capsys):
    out = tmp_path / "gen.npz"
    assert cli.main(["simulate", "generic", "--t-end", "20", "-o", str(out)]) == 0
    data = np.load(out)
    p = manakov.problem("generic")
    np.testing.assert_array_equal(data["l"][0], p.l0)
    assert data["t"][-1] == 20.0 and data["l"].shape == (data["t"].size, 6)
    # The stored integrals are the package's, recomputed here from the stored states.
    top = manakov.ManakovTop(p.a, p.b)
    for name, v in top.integrals(data["l"]).items():
        np.testing.assert_array_equal(data[name], v)
    png = out.with_suffix(".png")
    pytest.importorskip("matplotlib")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "max relative drift" in capsys.readouterr().out


def test_simulate_custom_top_writes_csv(tmp_path):
    out = tmp_path / "c.csv"
    argv = [
        "simulate",
        "--a",
        "1,2,3",
        "--b",
        "0.5,-1,2",
        "--l0",
        "1,0.5,-0.2",
        "--t-end",
        "5",
        "--samples",
        "11",
        "-o",
        str(out),
        "--no-plot",
        "-q",
    ]
    assert cli.main(argv) == 0
    header = out.read_text().splitlines()[0].split(",")
    assert header[:4] == ["t", "l12", "l13", "l23"]
    data = np.loadtxt(out, delimiter=",", skiprows=1)
    assert data.shape == (11, len(header))
    np.testing.assert_array_equal(data[:, 0], np.linspace(0, 5, 11))
    assert not out.with_suffix(".png").exists()
    # The CSV round-trips doubles exactly (%.17g).
    top = manakov.ManakovTop([1, 2, 3], [0.5, -1, 2])
    tr = top.integrate([1, 0.5, -0.2], 5.0, t_eval=np.linspace(0, 5, 11))
    np.testing.assert_array_equal(data[:, 1:4], tr.l)


@pytest.mark.parametrize(
    "argv",
    [
        ["simulate", "nosuchtop"],
        ["simulate", "--a", "1,1,2", "--b", "0,1,2", "--l0", "1,2,3"],
        ["simulate", "--a", "1,2,3", "--b", "0,1,2", "--l0", "1,2"],
        ["simulate", "--a", "1,2,3", "--b", "0,1,2"],
        ["simulate", "generic", "--t-end", "-1"],
        ["simulate", "generic", "--t-end", "nan"],
        ["simulate", "generic", "--dt", "0"],
        ["simulate", "generic", "-o", "x.txt"],
        # Review findings: an unwritable output once ended in a traceback (after the
        # whole run), no samples in an IndexError, and a huge run had no step budget.
        ["simulate", "generic", "--t-end", "1", "-o", "no/such/dir/x.npz"],
        ["simulate", "generic", "--t-end", "1", "--samples", "0"],
        ["simulate", "generic", "--t-end", "1e4", "--max-steps", "100"],
    ],
)
def test_bad_arguments_exit_with_status_2(argv, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert cli.main([*argv, "--no-plot"]) == 2
    assert "manakov: error:" in capsys.readouterr().err


def test_repeated_a_message_names_the_pair(tmp_path, capsys):
    out = str(tmp_path / "x.npz")
    argv = ["simulate", "--a", "1,2,1", "--b", "0,1,2", "--l0", "1,2,3", "-o", out]
    assert cli.main(argv) == 2
    assert "a[0] == a[2]" in capsys.readouterr().err


def test_progress_bar_draws_to_the_stream():
    s = io.StringIO()
    bar = ProgressBar("run", stream=s, force=True, width=10)
    bar.update(0.5)
    bar.update(2.0)
    bar.close()
    text = s.getvalue()
    assert "[#####-----]  50.0%" in text and "[##########] 100.0%" in text and text.endswith("\n")
    quiet = io.StringIO()
    ProgressBar("run", stream=quiet).update(0.5)  # not a tty: draws nothing
    assert quiet.getvalue() == ""


def test_long_run_shows_progress_on_stderr(tmp_path, capsys):
    out = tmp_path / "g.npz"
    assert (
        cli.main(
            ["simulate", "generic", "--t-end", "50", "--progress", "--no-plot", "-o", str(out)]
        )
        == 0
    )
    assert "100.0%" in capsys.readouterr().err


def test_console_script_runs_as_a_module(tmp_path):
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "manakov.cli",
            "simulate",
            "physical",
            "--t-end",
            "3",
            "--no-plot",
            "-o",
            str(tmp_path / "p.npz"),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 0, r.stderr
    assert "physical" in r.stdout
