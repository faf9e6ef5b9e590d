"""The command line of the body in a fluid: ``manakov fluid-simulate`` and ``fluid-theorem``."""

from __future__ import annotations

import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from manakov.cli import main


def test_fluid_simulate_reference_body_writes_npz_and_png(tmp_path, capsys):
    out = tmp_path / "cg.npz"
    assert main(["fluid-simulate", "clebsch_generic", "--t-end", "20", "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "clebsch_generic (clebsch case)" in text and "wrote" in text
    with np.load(out) as d:
        assert d["M"].shape == d["p"].shape == d["x"].shape == (2001, 3)
        assert d["R"].shape == (2001, 3, 3) and not bool(d["partial"])
        for k in ("pp", "Mp", "H", "F"):
            assert np.max(np.abs(d[k] - d[k][0])) < 1e-13 * max(abs(d[k][0]), 1.0)
        P = np.einsum("sij,sj->si", d["R"], d["p"])
        assert np.max(np.abs(P - P[0])) < 1e-13
    png = out.with_suffix(".png")
    assert png.exists() and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_fluid_simulate_custom_body_writes_csv(tmp_path, capsys):
    out = tmp_path / "b.csv"
    argv = ["fluid-simulate", "--A", "1,2,3", "--B", "0,0,0", "--C", "2,1,3"]
    argv += ["--M0", "1,0,0.5", "--p0", "0,1,0.2", "--t-end", "5", "--samples", "11"]
    assert main([*argv, "-o", str(out), "--no-plot"]) == 0
    header = out.read_text().splitlines()[0].split(",")
    assert header[:10] == ["t", "M1", "M2", "M3", "p1", "p2", "p3", "x1", "x2", "x3"]
    assert header[-3:] == ["pp", "Mp", "H"]
    data = np.loadtxt(out, delimiter=",", skiprows=1)
    assert data.shape == (11, len(header)) and data[-1, 0] == 5.0
    assert not out.with_suffix(".png").exists()


@pytest.mark.parametrize(
    "argv, message",
    [
        (["fluid-simulate"], "name a reference body"),
        (["fluid-simulate", "nope"], "unknown body"),
        (["fluid-simulate", "general", "--A", "1,2,3"], "not both"),
        (["fluid-simulate", "--A", "1,2", "--B", "0,0,0", "--C", "1,1,1"], "3 numbers"),
        (["fluid-simulate", "--A", "1,2,3", "--B", "0,0,0", "--C", "1,1,1"], "--M0 and --p0"),
        (
            [
                "fluid-simulate",
                "--A",
                "1,2,3",
                "--B",
                "5,5,5",
                "--C",
                "1,1,1",
                "--M0",
                "1,0,0",
                "--p0",
                "0,1,0",
            ],
            "positive definite",
        ),
        (["fluid-simulate", "general", "--t-end", "0"], "t-end"),
        (["fluid-simulate", "general", "--samples", "1"], "samples"),
        (["fluid-simulate", "general", "-o", "x.txt"], ".npz or .csv"),
    ],
)
def test_bad_arguments_exit_2_with_the_reason(argv, message, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    assert message in capsys.readouterr().err


def test_fluid_theorem_writes_png_and_reports_the_error(tmp_path, capsys):
    out = tmp_path / "nd.png"
    assert main(["fluid-theorem", "clebsch_near_degenerate", "-o", str(out)]) == 0
    text = capsys.readouterr().out
    err = float(text.split("on [0, 100] = ")[1].split()[0])
    assert err <= 1e-11  # docs/clebsch.md: the closed form on [0, 100]
    assert "frequencies nu = (0.06293808" in text
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(SystemExit):
        main(["fluid-theorem", "general"])  # not a Clebsch body: argparse refuses it


def test_sigint_writes_the_partial_motion_and_exits_130(tmp_path):
    out = tmp_path / "g.npz"
    argv = ["fluid-simulate", "general", "--t-end", "1e8", "--samples", "100001"]
    argv += ["--max-steps", str(10**11), "-o", str(out), "--no-plot"]
    code = f"import sys; from manakov.cli import main; sys.exit(main({argv!r}))"
    proc = subprocess.Popen([sys.executable, "-c", code], stderr=subprocess.PIPE, text=True)
    try:
        time.sleep(1.5)
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=30)
    finally:
        proc.kill()
    assert proc.returncode == 130, err
    part = out.with_name("g.partial.npz")
    assert "partial" in err and part.exists()
    with np.load(part) as d:
        assert bool(d["partial"]) and d["t"].size >= 1 and d["R"].shape == (d["t"].size, 3, 3)
