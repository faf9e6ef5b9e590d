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
from _npz import load_npz

import manakov
from manakov import cli
from manakov._progress import ProgressBar


def test_simulate_builtin_problem_writes_npz_and_png(tmp_path, capsys):
    out = tmp_path / "gen.npz"
    assert cli.main(["simulate", "generic", "--t-end", "20", "-o", str(out)]) == 0
    data = load_npz(out)
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
    data = load_npz(out)
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
    assert load_npz(out)["t"].size == samples


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
        data = load_npz(part)
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


# --- one convention for the command line: any top, partial work, figures that read ---

#: A user's top that is none of the built-in problems (a, b as floats, l0 of so(4)).
CUSTOM_A = "0.1,0.9,2.3,3.1"
CUSTOM_B = "0.4,-0.6,1.1,2.5"
CUSTOM_L0 = "0.7,-0.2,0.6,1.0,-0.5,0.3"
CUSTOM = ["--a", CUSTOM_A, "--b", CUSTOM_B, "--l0", CUSTOM_L0]


def _custom_top():
    a, b, l0 = (np.array([float(x) for x in s.split(",")]) for s in (CUSTOM_A, CUSTOM_B, CUSTOM_L0))
    return manakov.ManakovTop(a, b), l0


def _is_png(path):
    return Path(path).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_python_dash_m_alone_shows_the_version():
    # `python -m manakov` printed "the following arguments are required" and exited 2.
    r = _run()
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert lines[0] == f"manakov {manakov.__version__}"
    assert all(c.name in r.stdout for c in cli.COMMANDS)


def test_theorem_runs_on_a_top_that_is_not_built_in(tmp_path):
    # theorem took only the built-in problems (no --a/--b/--l0).
    png = tmp_path / "custom-theorem.png"
    r = _run("theorem", *CUSTOM, "--t-end", "10", "--samples", "21", "-o", str(png))
    assert r.returncode == 0, r.stderr
    assert _is_png(png) and r.stdout.startswith("custom: max |l_theta - l_int| / |l0|")
    printed = float(re.search(r"= ([0-9.e+-]+)", r.stdout).group(1))
    # The same comparison made here: the theta solution against a gauss16 run.
    top, l0 = _custom_top()
    t = np.linspace(0.0, 10.0, 21)
    ref = top.integrate(l0, 10.0, t_eval=t, dt=1e-3).l
    mine = float(np.max(np.abs(top.solve(l0).l(t) - ref)) / np.linalg.norm(l0))
    assert printed <= THEOREM_CLI_RTOL and mine <= THEOREM_CLI_RTOL
    assert printed == pytest.approx(mine, rel=1e-2)


def test_frequency_map_runs_on_a_top_that_is_not_built_in(tmp_path):
    png = tmp_path / "custom-fm.png"
    r = _run("frequency-map", *CUSTOM, "--grid", "4", "-o", str(png), "--no-progress")
    assert r.returncode == 0, r.stderr
    assert _is_png(png) and r.stdout.startswith("custom: 16 states (")
    # The counts are those of the library on the same slice.
    top, l0 = _custom_top()
    fm = manakov.frequency_map(top, manakov.tori.casimir_slice(l0, 4)[2])
    assert ", ".join(f"{k}: {v}" for k, v in fm.counts().items()) in r.stdout


@pytest.mark.parametrize("suffix", [".json", ".toml"])
def test_every_top_command_takes_a_problem_file(tmp_path, suffix):
    a, b, l0 = CUSTOM_A, CUSTOM_B, CUSTOM_L0
    if suffix == ".json":
        text = f'{{"name": "mytop", "a": [{a}], "b": [{b}], "l0": [{l0}]}}'
    else:
        text = f'name = "mytop"\na = [{a}]\nb = [{b}]\nl0 = [{l0}]\n'
    path = tmp_path / f"mytop{suffix}"
    path.write_text(text)
    top, l0v = _custom_top()
    for argv in (
        ["simulate", "--t-end", "2", "--no-plot", "-o", str(tmp_path / "s.npz")],
        ["kotter"],
        ["theorem", "--t-end", "2", "--samples", "5", "-o", str(tmp_path / "t.png")],
        ["frequency-map", "--grid", "2", "-o", str(tmp_path / "f.png"), "--no-progress"],
    ):
        r = _run(*argv, "--problem-file", str(path), cwd=tmp_path)
        assert r.returncode == 0, (argv, r.stderr)
        assert "mytop" in r.stdout, (argv, r.stdout)
    np.testing.assert_array_equal(load_npz(tmp_path / "s.npz")["l"][0], l0v)


def test_a_problem_file_with_a_table_of_tops_is_picked_by_name(tmp_path):
    # problems.json itself: its 'tops' table, a name picks one.
    src = Path(manakov.__file__).parent / "data" / "problems.json"
    r = _run("kotter", "physical", "--problem-file", str(src))
    assert r.returncode == 0, r.stderr
    assert r.stdout == _run("kotter", "physical").stdout
    r = _run("kotter", "--problem-file", str(src))
    assert r.returncode == 2 and "name the one to use" in r.stderr


@pytest.mark.parametrize(
    "text, match",
    [
        ('{"a": [1, 2, 3, 4], "b": [0, 1, 2, 3]}', "missing key(s) l0"),
        ("{not json", "does not parse"),
        ('{"a": "x", "b": [0], "l0": [1]}', "lists of numbers"),
    ],
)
def test_a_bad_problem_file_is_an_error_naming_the_file(tmp_path, text, match):
    path = tmp_path / "bad.json"
    path.write_text(text)
    r = _run("kotter", "--problem-file", str(path))
    assert r.returncode == 2 and "manakov: error:" in r.stderr
    assert match in r.stderr and "bad.json" in r.stderr


@pytest.mark.parametrize("command", ["theorem", "frequency-map"])
def test_long_commands_show_a_progress_bar(command, tmp_path):
    out = str(tmp_path / "x.png")
    extra = ["--t-end", "20", "--samples", "11"] if command == "theorem" else ["--grid", "8"]
    r = _run(command, "generic", *extra, "-o", out, "--progress")
    assert r.returncode == 0, r.stderr
    assert "100.0%" in r.stderr


#: After Ctrl-C a long command stops (within STOP_WITHIN_S, the library's
#: guarantee) and then draws the figure of the work done; the figure of a
#: 600 x 600 map takes ~0.3 s to draw here: 3 s is a bound on both, with margin.
PARTIAL_FIGURE_WITHIN_S = 3.0


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
@pytest.mark.parametrize(
    "argv, kept",
    [
        # The two runs of the trip-up report: minutes long, Ctrl-C after 2.5 s.
        (["theorem", "generic", "--t-end", "1e5", "--samples", "400001"], "samples up to t ="),
        (["frequency-map", "generic", "--grid", "600"], "not computed:"),
    ],
)
def test_sigint_writes_the_partial_figure_and_exits_130(argv, kept, tmp_path):
    out = tmp_path / "long.png"
    code, stdout, err, stopped = _sigint_after([*argv, "-o", str(out)], tmp_path, 2.5)
    assert code == cli.EXIT_INTERRUPTED, (stdout, err)
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    part = tmp_path / "long.partial.png"
    assert f"to {part} (partial)" in err and kept in err
    assert _is_png(part) and not out.exists()
    assert stopped < PARTIAL_FIGURE_WITHIN_S, f"line after {stopped:.3f} s"


def test_messages_print_the_digits_that_matter():
    # The rest state: "relative distance ... = NaN <= 1e-12".
    r = _run("kotter", "generic", "--l0", "0,0,0,0,0,0")
    assert r.returncode == 2 and "rest state" in r.stderr
    assert "nan" not in r.stderr.lower()
    # A repeated root: 17 digits and a rounding-noise imaginary part.
    r = _run("kotter", "generic", "--l0", "1,0,0,0,0,0.5")
    assert r.returncode == 2
    root = re.search(r"repeated root s = (\S+) ", r.stderr).group(1)
    assert re.fullmatch(r"-?[0-9.]+", root) and len(re.sub(r"\D", "", root)) <= 10, root
    # The reduction of a state whose curve is real: real numbers print as real.
    r = _run("kotter", "generic")
    assert r.returncode == 0
    d_line = next(x for x in r.stdout.splitlines() if x.strip().startswith("d = "))
    assert "j" not in d_line and "e-" not in d_line, d_line


# The figures, inspected as they are saved: a user's command run with a hook on
# matplotlib's Figure.savefig that records the drawn figure's geometry.
_FIGURE_HOOK = r"""
import json, sys
import numpy as np
import matplotlib
matplotlib.use("Agg")
from matplotlib.figure import Figure
from matplotlib.text import Annotation, Text

figures = []
drawn = []
_save, _draw_text = Figure.savefig, Text.draw

def draw_text(self, renderer):
    drawn.append(self)
    return _draw_text(self, renderer)

def savefig(self, *args, **kwargs):
    _save(self, *args, **kwargs)
    drawn.clear()
    self.canvas.draw()  # measured at the figure's own dpi, as its bbox is
    r = self.canvas.get_renderer()
    # The texts drawn (tick labels outside the view limits exist but are not drawn).
    texts = [t for t in dict.fromkeys(drawn) if t.get_visible() and t.get_text().strip()]
    def box(t):
        b = t.get_window_extent(r)
        return [b.x0, b.y0, b.x1, b.y1]
    fig = {
        "bbox": [self.bbox.x0, self.bbox.y0, self.bbox.x1, self.bbox.y1],
        "texts": [[t.get_text(), box(t)] for t in texts if not isinstance(t, Annotation)],
        "labels": [[t.get_text(), box(t)] for t in texts if isinstance(t, Annotation)],
        "axes": [],
    }
    for ax in self.axes:
        if not ax.get_visible() or ax.get_label() == "<colorbar>":
            continue
        # Drawn curves only (a marker-only line shows samples, not a curve).
        steps = [float(np.max(np.diff(np.asarray(l.get_xdata(), float))))
                 for l in ax.get_lines()
                 if len(l.get_xdata()) > 2 and l.get_linestyle() not in ("None", "")]
        fig["axes"].append({
            "xlim": list(ax.get_xlim()), "ylim": list(ax.get_ylim()),
            "xticks": len(ax.get_xticks()), "yticks": len(ax.get_yticks()),
            "max_step": max(steps) if steps else None,
        })
    figures.append(fig)

Figure.savefig = savefig
Text.draw = draw_text
from manakov.cli import main
status = main(sys.argv[1:])
print("FIGURES " + json.dumps(figures))
sys.exit(status)
"""


def _figures(*argv, cwd):
    r = subprocess.run(
        [sys.executable, "-c", _FIGURE_HOOK, *argv],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=cwd,
    )
    assert r.returncode == 0, r.stderr
    line = next(x for x in r.stdout.splitlines() if x.startswith("FIGURES "))
    import json

    return json.loads(line[len("FIGURES ") :])


def _inside(box, fig, slack=1.0):
    return (
        box[0] >= fig[0] - slack
        and box[1] >= fig[1] - slack
        and box[2] <= fig[2] + slack
        and box[3] <= fig[3] + slack
    )


def _overlap(a, b):
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


@pytest.mark.parametrize("name", ["generic", "wide", "near_degenerate"])
def test_the_kotter_figure_has_axes_of_the_data_and_labels_that_read(name, tmp_path):
    # `manakov kotter generic --plot` scaled the imaginary axis to rounding noise
    # (labels 1e-30, the divisor at +-3e-30) and wrote d0 over d2.
    pytest.importorskip("matplotlib")
    (fig,) = _figures("kotter", name, "--plot", "k.png", cwd=tmp_path)
    p = manakov.problem(name)
    k = manakov.kotter(p.a, p.b, p.l0)
    extent = max(float(np.max(np.abs(k.d))), abs(complex(np.prod(k.d))))
    for ax in fig["axes"]:
        for lim, ticks in ((ax["xlim"], ax["xticks"]), (ax["ylim"], ax["yticks"])):
            if ticks:  # a drawn axis spans a part of the data, never its rounding noise
                assert abs(lim[1] - lim[0]) >= 1e-3 * extent, (lim, extent)
    labels = fig["labels"]
    assert len(labels) == 7
    for i in range(len(labels)):
        for j in range(i + 1, len(labels)):
            assert not _overlap(labels[i][1], labels[j][1]), (labels[i][0], labels[j][0])
    for text, box in fig["texts"] + labels:
        assert _inside(box, fig["bbox"]), text


def test_the_theorem_figure_title_fits_and_its_curves_are_smooth(tmp_path):
    # The theorem PNG's title was cut off at the right edge.
    pytest.importorskip("matplotlib")
    (fig,) = _figures("theorem", "generic", "--t-end", "100", "-o", "t.png", cwd=tmp_path)
    for text, box in fig["texts"]:
        assert _inside(box, fig["bbox"]), text
    # l(t) drawn densely: the fastest oscillation of 'generic' has a period ~2.
    assert fig["axes"][0]["max_step"] <= 0.05


def test_the_simulate_figure_is_smooth_at_a_short_t_end(tmp_path):
    # `simulate` at a short --t-end drew a polyline through samples 0.34 apart.
    pytest.importorskip("matplotlib")
    (fig,) = _figures("simulate", "generic", "--t-end", "10", "-o", "s.npz", cwd=tmp_path)
    assert fig["axes"][0]["max_step"] <= 0.05
    for text, box in fig["texts"]:
        assert _inside(box, fig["bbox"]), text
