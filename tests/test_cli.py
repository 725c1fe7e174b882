"""The command line of DESIGN §8: exit codes, one-line reasons, nothing half-written."""

import subprocess
import sys

import numpy as np
import pytest

from emaphm import read_trace
from emaphm.cli import main


def run_cli(args, capsys):
    with pytest.raises(SystemExit) as exc:
        main(args)
        raise SystemExit(0)
    out = capsys.readouterr()
    return exc.value.code, out.out, out.err


@pytest.mark.parametrize(
    "bad",
    [
        "0,0,0,0,0,0,0",  # too few
        "0,0,0,0,0,0,0,0,0",  # too many
        "0,0,nan,0,0,0,0,0.5",
        "0,0,0,0,0,0,0,1.5",
        "0,-0.2,0,0,0,0,0,0.5",
        "0,abc,0,0,0,0,0,0.5",
    ],
)
def test_bad_fault_vector_exits_2_with_one_line_and_no_file(tmp_path, capsys, bad):
    out = tmp_path / "x.h5"
    code, _, err = run_cli(["simulate", "--faults", bad, "--output", str(out)], capsys)
    assert code == 2
    assert len(err.strip().splitlines()) == 1 and "--faults" in err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("args", "reason"),
    [
        (["simulate", "--output", "x.txt"], "unsupported file type"),
        (["simulate"], "--output"),
        (["simulate", "--output", "x.h5", "--seed", "abc"], "--seed"),
        (["simulate", "--output", "x.h5", "--model", "mf"], "unknown model"),
        (["simulate", "--output", "x.h5", "--command", "square"], "unknown command"),
        (["simulate", "--output", "x.h5", "--duration", "-1"], "duration"),
        (["nosuchcommand"], "No such command"),
    ],
)
def test_usage_errors_exit_2(tmp_path, capsys, monkeypatch, args, reason):
    monkeypatch.chdir(tmp_path)
    code, _, err = run_cli(args, capsys)
    assert code == 2
    assert reason in err and len(err.strip().splitlines()) == 1
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("suffix", [".h5", ".csv"])
def test_simulate_writes_a_trace(tmp_path, capsys, suffix):
    out = tmp_path / f"trace{suffix}"
    code, _, _ = run_cli(
        ["simulate", "--faults", "0.2,0.5,0,0.45,0.04,0,0.28,0.5", "--seed", "3", "--duration", "0.05",
         "--output", str(out)],
        capsys,
    )  # fmt: skip
    assert code == 0
    r = read_trace(out)
    assert len(r.t) == 501 and r.metadata["seed"] == 3
    assert r.metadata["faults"][3] == 0.45
    assert np.max(np.abs(r.i_a)) > 0.01  # it did move


def test_no_noise_flag(tmp_path, capsys):
    for seed in ("1", "2"):
        run_cli(["simulate", "--no-noise", "--seed", seed, "--duration", "0.02", "--output",
                 str(tmp_path / f"{seed}.h5")], capsys)  # fmt: skip
    a, b = read_trace(tmp_path / "1.h5"), read_trace(tmp_path / "2.h5")
    assert a.metadata["noise"] is False
    np.testing.assert_array_equal(a.i_q, b.i_q)


def test_demo_runs_and_writes_its_figure(tmp_path, capsys):
    code, out, _ = run_cli(["demo", "--output-dir", str(tmp_path / "demo")], capsys)
    assert code == 0
    assert (tmp_path / "demo" / "hf_table1.png").stat().st_size > 10_000
    assert "0.5003" in out and "not implemented" in out


def test_entry_point_is_installed():
    res = subprocess.run([sys.executable, "-m", "emaphm.cli", "--version"], capture_output=True, text=True)
    assert res.returncode == 0 and res.stdout.startswith("emaphm ")


def test_simulate_lf_model(tmp_path, capsys):
    out = tmp_path / "lf.csv"
    code, _, _ = run_cli(["simulate", "--model", "lf", "--duration", "0.1", "--output", str(out)], capsys)
    assert code == 0
    r = read_trace(out)
    assert r.metadata["model"] == "lf" and "calibration" in r.metadata
    assert {"t", "theta_cmd", "theta_u", "i_q"} <= set(r.names)


def test_calibrate_writes_a_loadable_file(tmp_path, capsys):
    from emaphm.calibration import load_calibration

    out = tmp_path / "cal.json"
    code, _, err = run_cli(
        ["calibrate", "--output", str(out), "--generations", "1", "--pop-size", "4", "--seed", "2"], capsys
    )
    assert code == 0 and "held out" in err
    cal = load_calibration(out)
    assert cal.record["seed"] == 2 and cal.record["settings"]["generations"] == 1


@pytest.mark.parametrize(
    ("args", "reason"),
    [
        (["calibrate", "--output", "cal.txt"], "must end in .json"),
        (["calibrate", "--output", "no/such/dir/cal.json"], "does not exist"),
        (["calibrate", "--workers", "-1"], "--workers"),
        (["calibrate", "--generations", "0"], "generations"),
    ],
)
def test_calibrate_bad_input(tmp_path, capsys, monkeypatch, args, reason):
    monkeypatch.chdir(tmp_path)
    code, _, err = run_cli(args, capsys)
    assert code == 2 and reason in err
    assert list(tmp_path.iterdir()) == []
