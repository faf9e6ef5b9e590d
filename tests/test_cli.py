# The state is called l, as in the paper: E741 does not apply.
# ruff: noqa: E741
"""The ``manakov`` command line: simulate, kotter, theta; Ctrl-C, pipes, --version."""

from __future__ import annotations

import io
import itertools
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

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


#: Ctrl-C must stop a CLI run within this long (issue 11).
STOP_WITHIN_S = 0.5


def _run(*argv, cwd=None, timeout=120):
    return subprocess.run(
        [sys.executable, "-m", "manakov", *argv],
        capture_output=True,
        text=True,
        timeout=timeout,
        cwd=cwd,
    )


@pytest.mark.parametrize("method", ["dop853", "dopri5"])
def test_explicit_methods_run_without_dt(method, tmp_path, capsys):
    # "--method dop853" failed with "--dt must be > 0, got 0.0" (only dopri5 was exempt).
    out = tmp_path / "e.npz"
    argv = ["simulate", "generic", "--t-end", "5", "--method", method, "--no-plot", "-o", str(out)]
    assert cli.main(argv) == 0
    text = capsys.readouterr().out
    assert f"with {method}" in text and "mean step" in text
    data = np.load(out)
    assert data["t"][-1] == 5.0 and not data["partial"]


def _printed_step(text):
    m = re.search(r"(\d+) steps, (?:mean )?step ([0-9.e+-]+) \((\d+) samples\)", text)
    assert m, text
    return int(m.group(1)), float(m.group(2)), int(m.group(3))


def test_default_samples_do_not_shrink_the_step_and_the_step_used_is_printed(tmp_path, capsys):
    # 20001 default samples forced steps of 0.05 on 'physical' while dt was printed.
    p = manakov.problem("physical")
    dt = manakov.ManakovTop(p.a, p.b).default_dt(p.l0)
    t_end = 1000.0
    out = str(tmp_path / "p.npz")
    assert cli.main(["simulate", "physical", "--t-end", str(t_end), "--no-plot", "-o", out]) == 0
    steps, step, samples = _printed_step(capsys.readouterr().out)
    assert steps == samples - 1  # one step per sample interval
    assert step == pytest.approx(t_end / steps, rel=1e-3)
    assert dt / 1.01 < step <= dt * (1 + 1e-9)  # the method's step, not smaller
    assert np.load(out)["t"].size == samples


def test_explicit_samples_print_the_step_they_force(tmp_path, capsys):
    out = str(tmp_path / "p.npz")
    argv = ["simulate", "physical", "--t-end", "1000", "--samples", "20001", "--no-plot"]
    assert cli.main([*argv, "-o", out]) == 0
    steps, step, samples = _printed_step(capsys.readouterr().out)
    assert samples == 20001 and steps == 20000
    assert step == pytest.approx(0.05, rel=1e-3)  # the step used, not the requested dt


def test_t_end_zero_is_refused_instead_of_20001_identical_samples(tmp_path, capsys):
    out = tmp_path / "z.npz"
    assert cli.main(["simulate", "generic", "--t-end", "0", "-o", str(out), "--no-plot"]) == 2
    assert "--t-end must be finite and > 0" in capsys.readouterr().err
    assert not out.exists()


def test_piping_into_head_ends_quietly():
    proc = subprocess.Popen(
        [sys.executable, "-m", "manakov", "simulate", "generic", "--t-end", "2000", "-o", "-"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    assert proc.stdout is not None and proc.stderr is not None
    header = proc.stdout.readline().decode()
    first = proc.stdout.readline().decode()
    proc.stdout.close()  # what `head -2` does
    err = proc.stderr.read().decode()
    proc.stderr.close()
    proc.wait(timeout=60)
    assert header.startswith("t,l12,")
    assert float(first.split(",")[0]) == 0.0
    assert "Broken pipe" not in err and "Traceback" not in err, err
    assert proc.returncode == cli.EXIT_BROKEN_PIPE


def test_csv_on_stdout_is_the_trajectory_and_the_report_goes_to_stderr():
    r = _run("simulate", "generic", "--t-end", "3", "--samples", "4", "-o", "-")
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert lines[0].startswith("t,l12,") and len(lines) == 5
    assert "max relative drift" in r.stderr
    p = manakov.problem("generic")
    row0 = np.array([float(x) for x in lines[1].split(",")])
    np.testing.assert_array_equal(row0[1:7], p.l0)


def test_version_and_python_dash_m(capsys):
    with pytest.raises(SystemExit) as e:
        cli.main(["--version"])
    assert e.value.code == 0
    assert capsys.readouterr().out.strip() == f"manakov {manakov.__version__}"
    r = _run("--version")
    assert r.returncode == 0 and r.stdout.strip() == f"manakov {manakov.__version__}"


@pytest.mark.parametrize("command", [c.name for c in cli.COMMANDS])
def test_every_subcommand_has_help_with_an_example(command):
    r = _run(command, "--help")
    assert r.returncode == 0, r.stderr
    assert "example:" in r.stdout and f"manakov {command}" in r.stdout


def test_the_top_level_help_lists_every_subcommand():
    r = _run("--help")
    assert r.returncode == 0
    for c in cli.COMMANDS:
        assert c.name in r.stdout


def _brute_theta(z, tau, a, b, nmax=12):
    """theta[a;b](z, tau) by the plain double sum (36) with characteristics."""
    a = np.asarray(a) / 2
    b = np.asarray(b) / 2
    total = 0j
    for n in itertools.product(range(-nmax, nmax + 1), repeat=2):
        m = np.asarray(n) + a
        total += np.exp(1j * np.pi * m @ tau @ m + 2j * np.pi * m @ (z + b))
    return total


TAU_ARG = "0.3+1.1j,0.1+0.4j,0.1+0.4j,-0.2+1.3j"
Z_ARG = "0.2+0.1j,0.7-0.3j"
#: The brute-force sum to |n| <= 12 has terms below exp(-pi 0.9 144) ~ 1e-176; what
#: is left is the rounding of ~600 terms of size <= ~3 and the 10 printed digits.
THETA_CLI_RTOL = 1e-9


def test_theta_prints_all_sixteen_values_against_the_plain_sum(capsys):
    assert cli.main(["theta", "--tau", TAU_ARG, "--z", Z_ARG]) == 0
    rows = [ln.split() for ln in capsys.readouterr().out.splitlines() if not ln.startswith("#")]
    assert len(rows) == 16
    tau = np.array([[0.3 + 1.1j, 0.1 + 0.4j], [0.1 + 0.4j, -0.2 + 1.3j]])
    z = np.array([0.2 + 0.1j, 0.7 - 0.3j])
    for idx, a, b, value in rows:
        want = _brute_theta(z, tau, [int(c) for c in a], [int(c) for c in b])
        got = complex(value)
        assert int(idx) == 8 * int(a[0]) + 4 * int(a[1]) + 2 * int(b[0]) + int(b[1])
        assert abs(got - want) <= THETA_CLI_RTOL * max(abs(want), 1.0), (idx, got, want)


def test_theta_one_characteristic_by_label_and_pair(capsys):
    tau = np.array([[0.3 + 1.1j, 0.1 + 0.4j], [0.1 + 0.4j, -0.2 + 1.3j]])
    z = np.array([0.2 + 0.1j, 0.7 - 0.3j])
    want = _brute_theta(z, tau, [1, 0], [0, 0])  # theta12 of (35): top row a = (1, 0)
    for char in ("theta12", "1 0;0 0", "8"):
        assert cli.main(["theta", "--tau", TAU_ARG, "--z", Z_ARG, "--char", char]) == 0
        got = complex(capsys.readouterr().out.strip())
        assert abs(got - want) <= THETA_CLI_RTOL * abs(want), char


@pytest.mark.parametrize(
    "argv",
    [
        ["theta", "--tau", "1j,0,0", "--z", "0"],  # not g*g
        ["theta", "--tau", TAU_ARG, "--z", "0.1"],  # z of the wrong genus
        ["theta", "--tau", TAU_ARG, "--z", Z_ARG, "--char", "theta99"],
        ["theta", "--tau", "0.3-1j", "--z", "0"],  # Im tau < 0
        ["kotter", "--a", "1,2,3", "--b", "0,1,2", "--l0", "1,2,3"],  # n = 3
        ["kotter", "nosuchtop"],
    ],
)
def test_bad_subcommand_arguments_exit_with_status_2(argv, capsys):
    assert cli.main(argv) == 2
    assert "manakov: error:" in capsys.readouterr().err


def test_kotter_prints_the_reduction_and_round_trip(tmp_path, capsys):
    png = tmp_path / "k.png"
    assert cli.main(["kotter", "generic", "--plot", str(png)]) == 0
    text = capsys.readouterr().out
    p = manakov.problem("generic")
    # h0..h3 of (6)-(7) with the complementary pairs, computed here from l0.
    l12, l13, l14, l23, l24, l34 = p.l0
    a1, a2, a3, a4 = p.a
    h0 = l12 * l34 - l13 * l24 + l14 * l23
    h1 = float(np.sum(p.l0**2))
    pairs = {(0, 1): (2, 3), (0, 2): (1, 3), (0, 3): (1, 2), (1, 2): (0, 3), (1, 3): (0, 2)}
    pairs[(2, 3)] = (0, 1)
    idx = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
    h2 = sum((p.a[pairs[jk][0]] + p.a[pairs[jk][1]]) * v**2 for jk, v in zip(idx, p.l0))
    h3 = sum(p.a[pairs[jk][0]] * p.a[pairs[jk][1]] * v**2 for jk, v in zip(idx, p.l0))
    m = re.search(r"h0..h3 = (.*)", text)
    assert m
    printed = [float(x) for x in m.group(1).split(",")]
    np.testing.assert_allclose(printed, [h0, h1, h2, h3], rtol=1e-9)
    err = float(re.search(r"max relative error ([0-9.e+-]+)", text).group(1))
    assert err < 1e-12
    assert "d4 = d1 d2 d3" in text and "(z1, y1)" in text
    pytest.importorskip("matplotlib")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_png_outputs_are_ignored_by_git():
    root = Path(__file__).resolve().parents[1]
    patterns = (root / ".gitignore").read_text().split()
    assert "*.png" in patterns


def _sigint_after(argv, cwd, wait_s):
    proc = subprocess.Popen(
        [sys.executable, "-m", "manakov", *argv],
        cwd=cwd,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    time.sleep(wait_s)
    assert proc.poll() is None, proc.communicate()
    sent = time.perf_counter()
    proc.send_signal(signal.SIGINT)
    assert proc.stderr is not None
    # The run has stopped (partial output written) when the CLI prints its one line;
    # the interpreter's shutdown after that is not part of the run.
    line = proc.stderr.readline()
    stopped = time.perf_counter() - sent
    out, err = proc.communicate(timeout=60)
    return proc.returncode, out, line + err, stopped


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
@pytest.mark.parametrize("suffix", [".npz", ".csv"])
def test_sigint_writes_partial_output_and_exits_130(tmp_path, suffix):
    # A run of minutes (t_end = 1e7 of 'generic': ~3e7 steps).
    out = tmp_path / f"long{suffix}"
    argv = ["simulate", "generic", "--t-end", "1e7", "--no-plot", "-o", str(out)]
    code, stdout, err, stopped = _sigint_after(argv, tmp_path, 2.5)
    assert code == cli.EXIT_INTERRUPTED, (stdout, err)
    assert stopped < STOP_WITHIN_S, f"stopped {stopped:.3f} s after SIGINT"
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    part = tmp_path / f"long.partial{suffix}"
    assert str(part) in err and "(partial)" in err
    assert not out.exists()
    if suffix == ".npz":
        data = np.load(part)
        t, l = data["t"], data["l"]
        assert bool(data["partial"])
    else:
        lines = part.read_text().splitlines()
        assert lines[0].startswith("# partial")
        data = np.loadtxt(part, delimiter=",", skiprows=2)
        t, l = data[:, 0], data[:, 1:7]
    assert 2 <= t.size < 20001 and t[-1] < 1e7
    # The samples are the run's: the same spacing as the full run, and each is
    # what integrating from l0 gives (checked on the first stretch).
    np.testing.assert_allclose(np.diff(t), 1e7 / 20000, rtol=1e-9)
    p = manakov.problem("generic")
    top = manakov.ManakovTop(p.a, p.b)
    k = min(t.size, 3)
    ref = top.integrate(p.l0, t[k - 1], t_eval=t[:k], method="dop853", rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(l[:k], ref.l, atol=1e-9)


def test_commands_registry_builds_the_parser():
    names = [c.name for c in cli.COMMANDS]
    assert names == [
        "simulate",
        "kotter",
        "theta",
        "theorem",
        "frequency-map",
        "fluid-simulate",
        "fluid-theorem",
    ]
    for c in cli.COMMANDS:
        assert callable(c.run) and callable(c.add_arguments) and c.example.startswith("manakov ")


#: The Theorem's claim on [0, 100] for the shared 'physical' top (issue 10).
THEOREM_CLI_RTOL = 1e-11


def test_theorem_subcommand_writes_png_and_reports_the_error(tmp_path, capsys):
    png = tmp_path / "th.png"
    argv = ["theorem", "physical", "-o", str(png), "--t-end", "10", "--samples", "21"]
    assert cli.main(argv) == 0
    text = capsys.readouterr().out
    assert png.exists() and png.stat().st_size > 0
    err = float(re.search(r"= ([0-9.e+-]+)", text).group(1))
    # Independent of the CLI's own number: theta solution against a gauss16 run here.
    p = manakov.problem("physical")
    top = manakov.ManakovTop(p.a, p.b)
    t = np.linspace(0.0, 10.0, 21)
    ref = top.integrate(p.l0, 10.0, t_eval=t, dt=1e-3).l
    mine = np.max(np.abs(top.solve(p.l0).l(t) - ref)) / np.linalg.norm(p.l0)
    assert err <= THEOREM_CLI_RTOL and mine <= THEOREM_CLI_RTOL


def test_theorem_subcommand_rejects_unknown_problem():
    # As every subcommand that takes a top: the package's message, naming the known ones.
    r = _run("theorem", "nope")
    assert r.returncode == 2 and "unknown problem 'nope'; known: generic" in r.stderr


def test_frequency_map_subcommand_writes_png_and_counts_states(tmp_path, capsys):
    png = tmp_path / "fm.png"
    argv = ["frequency-map", "generic", "--grid", "4", "-o", str(png), "--no-progress"]
    assert cli.main(argv) == 0
    text = capsys.readouterr().out
    assert png.exists() and png.stat().st_size > 0
    assert "generic: 16 states (" in text
    counted = sum(int(n) for n in re.findall(r": (\d+)", text.split("(", 1)[1]))
    assert counted == 16


def test_frequency_map_subcommand_rejects_a_tiny_grid():
    r = _run("frequency-map", "generic", "--grid", "1")
    assert r.returncode != 0 and "--grid must be >= 2" in r.stderr
