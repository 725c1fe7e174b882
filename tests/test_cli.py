"""The command line of DESIGN §8: exit codes, one-line reasons, nothing half-written."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import emaphm
from emaphm import read_trace
from tests.helpers import EXIT_OF_VERDICT, run_cli


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


def test_demo_runs_and_writes_its_figures(tmp_path):
    from rich.console import Console

    from emaphm.demo import run_demo
    from emaphm.identification.settings import IdentifySettings

    console = Console(record=True, width=160)
    budget = {"pop_size": 16, "generations": 3, "polish": False}  # the table, not convergence
    data = run_demo(tmp_path / "demo", runs=2, console=console, settings=IdentifySettings(**budget))
    for name in ("hf_table1.png", "identified_current.png", "convergence.png", "identified_vs_true.png"):
        assert (tmp_path / "demo" / name).stat().st_size > 10_000
    out = console.export_text()
    assert "0.5003" in out and "%err" in out and "the paper" in out and "time [s]" in out
    assert len(data["percent_error"]) == 2 and all(0 < e < 100 for e in data["percent_error"])


def test_demo_bad_output_dir_exits_2(tmp_path, capsys):
    (tmp_path / "file").write_text("")
    code, _, err = run_cli(["demo", "--output-dir", str(tmp_path / "file")], capsys)
    assert code == 2 and "not a folder" in err


def test_entry_point_is_installed():
    # beside the interpreter that runs the tests, not on PATH: a venv's python run without
    # activating the venv has its scripts there and not on PATH
    exe = Path(sys.executable).parent / ("emaphm.exe" if sys.platform == "win32" else "emaphm")
    assert exe.is_file(), f"the console script is not installed beside {sys.executable}"
    res = subprocess.run([str(exe), "--version"], capture_output=True, text=True)
    assert res.returncode == 0 and res.stdout.startswith("emaphm ")
    for module in ("emaphm", "emaphm.cli"):
        res = subprocess.run([sys.executable, "-m", module, "--version"], capture_output=True, text=True)
        assert res.returncode == 0 and res.stdout.startswith("emaphm ")


def test_the_choice_lists_are_the_codes_own():
    # one list each (emaphm.choices, numpy-free for the CLI): the code's names are the same objects
    from emaphm import HEALTHY, choices
    from emaphm.commands import COMMANDS
    from emaphm.identification import last_stage, optimizers, uncertainty

    assert [float(v) for v in choices.HEALTHY_TEXT.split(",")] == list(HEALTHY)
    assert tuple(COMMANDS) == choices.COMMAND_NAMES
    assert uncertainty.UQ_METHODS is choices.UQ_METHODS
    assert last_stage.LAST_STAGES is choices.LAST_STAGES
    assert optimizers.OPTIMIZERS is choices.OPTIMIZERS


def test_cli_starts_without_the_numerical_stack():
    # emaphm --version must answer at once: the CLI module may not import numpy, numba, scipy, pymoo
    code = "import sys, emaphm.cli; print(sorted(m for m in ('numpy', 'numba', 'scipy', 'pymoo') if m in sys.modules))"
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert res.stdout.strip() == "[]"


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


PACKAGED_CALIBRATION = Path(emaphm.__file__).parent / "data" / "calibration.json"


@pytest.mark.parametrize(
    ("args", "reason"),
    [
        (["calibrate", "--output", "cal.txt"], "use .json"),
        (["calibrate", "--output", "no/such/dir/cal.json"], "does not exist"),
        (["calibrate", "--workers", "-1"], "--workers"),
        (["calibrate", "--generations", "0"], "generations"),
        (["calibrate", "--free", "bogus"], "cannot fit 'bogus' for the 'default' monitor"),
        (["calibrate", "--free", "i_D", "--monitor", "paper"], "cannot fit 'i_D' for the 'paper' monitor"),
        (["calibrate", "--free", ","], "at least one coefficient"),
        (["calibrate", "--start", str(PACKAGED_CALIBRATION)], "--start needs --free"),
        (
            [
                "calibrate",
                "--free",
                "i_D",
                "--start",
                str(PACKAGED_CALIBRATION.with_name("calibration-paper.json")),
            ],
            "is for the 'paper' monitor",
        ),
    ],
)
def test_calibrate_bad_input(tmp_path, capsys, monkeypatch, args, reason):
    monkeypatch.chdir(tmp_path)
    code, _, err = run_cli(args, capsys)
    assert code == 2 and reason in err
    assert list(tmp_path.iterdir()) == []


# ---- identify ---------------------------------------------------------------------------------

FAST = ["--pop-size", "16", "--generations", "5", "--no-polish"]


def test_identify_json(tmp_path, capsys):
    import json

    out = tmp_path / "result.json"
    code, stdout, _ = run_cli(
        [
            "identify",
            "--true-faults",
            "0.3,0,0,0,0,0,0,0.5",
            "--json",
            "--seed",
            "1",
            "--output",
            str(out),
            *FAST,
        ],
        capsys,
    )
    data = json.loads(stdout)
    assert code == EXIT_OF_VERDICT[data["verdict"]]
    for key in ("estimate", "fault_names", "truth", "percent_error", "fitness", "evaluations", "wall_time_s",
                "seed", "optimizer", "version", "detected"):  # fmt: skip
        assert key in data
    assert len(data["estimate"]) == 8 and data["truth"] == [0.3, 0, 0, 0, 0, 0, 0, 0.5]
    # the JSON's %err is the metric of its own estimate against its truth (16 x 5 is too small a
    # budget for accuracy: tests/identification/test_identify.py checks that)
    from emaphm import percent_error

    assert data["percent_error"] == pytest.approx(percent_error(data["estimate"], data["truth"]), rel=1e-12)
    assert all(0 <= v <= 1 for v in data["estimate"])
    assert set(data["settings"]["versions"]) >= {"emaphm", "numpy", "numba", "pymoo"}
    assert data["settings"]["calibration"]["params_hash"]
    assert json.loads(out.read_text())["estimate"] == data["estimate"]
    # the uncertainty (issue 9): Laplace by default, calibrated by the packaged file
    assert data["uq_method"] == "laplace" and data["settings"]["uq_calibration"]["calibrated"]
    for key in ("std", "ci90_low", "ci90_high", "uq_flags"):
        assert len(data[key]) == 8
    assert len(data["corr"]) == 8 and all(len(row) == 8 for row in data["corr"])
    for j in range(8):
        if j != 6:
            assert 0 <= data["ci90_low"][j] <= data["estimate"][j] <= data["ci90_high"][j] <= 1
    # no eccentricity in the truth: its direction is flagged, its interval the whole circle
    if "phase_undefined" in data["uq_flags"][6]:
        assert (data["ci90_low"][6], data["ci90_high"][6]) == (0.0, 1.0) and data["std"][6] is None
    assert set(data["fault_verdicts"]) == set(data["fault_names"]) - {"eccentricity_phase"}
    assert data["detected"] == [n for n, v in data["fault_verdicts"].items() if v == "present"]


def test_identify_without_uncertainty_gives_null_intervals(capsys):
    import json

    code, stdout, _ = run_cli(
        ["identify", "--true-faults", "0.3,0,0,0,0,0,0,0.5", "--json", "--uncertainty", "none", *FAST], capsys
    )
    data = json.loads(stdout)
    assert (
        code == EXIT_OF_VERDICT[data["verdict"]]
        and data["uq_method"] == "none"
        and data["ci90_low"] is None
        and data["fault_verdicts"] is None
    )


@pytest.mark.slow  # builds a start table, ~10 s
def test_identify_in_a_log_says_when_it_builds_a_start_table(tmp_path, capsys, monkeypatch):
    from collections import OrderedDict

    from emaphm.identification import start_table

    monkeypatch.setenv("EMAPHM_TABLE_DIR", str(tmp_path / "tables"))
    monkeypatch.setattr(start_table, "_MEMORY", OrderedDict())  # none kept from earlier tests
    args = ["identify", "--true-faults", "0.3,0,0,0,0,0,0,0.5", "--json", "--uncertainty", "none", *FAST,
            "--start", "table"]  # fmt: skip
    code, _, err = run_cli(args, capsys)
    label = "start table (once per actuator and command)"
    assert code in EXIT_OF_VERDICT.values()
    assert f"emaphm: {label}: {start_table.TABLE_ROWS} steps" in err and f"emaphm: {label}: done" in err
    # kept: the next diagnosis reads it and says nothing of it
    monkeypatch.setattr(start_table, "_MEMORY", OrderedDict())
    _, _, err = run_cli(args, capsys)
    assert label not in err


@pytest.mark.parametrize(
    ("args", "reason"),
    [
        (["--uncertainty", "bootstrap"], "--uncertainty"),
        (["--uq-calibration", "missing.json"], "no such interval calibration"),
        (["--uq-calibration", "missing.json", "--uncertainty", "none"], "--uq-calibration needs"),
    ],
)
def test_identify_refuses_a_bad_uncertainty_option_before_the_work(tmp_path, capsys, args, reason):
    out = tmp_path / "r.json"
    code, _, err = run_cli(
        ["identify", "--true-faults", "0.3,0,0,0,0,0,0,0.5", "--output", str(out), *args, *FAST], capsys
    )
    assert code == 2 and reason in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_identify_from_a_reference_trace(tmp_path, capsys):
    import json

    trace = tmp_path / "m.h5"
    run_cli(["simulate", "--faults", "0,0.3,0,0,0,0,0,0.5", "--output", str(trace)], capsys)
    code, stdout, _ = run_cli(["identify", "--reference", str(trace), "--json", *FAST], capsys)
    data = json.loads(stdout)
    assert code == EXIT_OF_VERDICT[data["verdict"]] and data["truth"] is None and data["percent_error"] is None


def test_identify_says_what_the_switching_last_stage_did(capsys, monkeypatch):
    import json

    from emaphm.identification import limits
    from emaphm.identification.result import stage_record

    monkeypatch.setattr(limits, "POLISH_BUDGET", (8, 2))
    monkeypatch.setattr(limits, "SWITCHING_ITERATIONS", 1)  # the stage runs, at its least cost
    args = ["identify", "--true-faults", "0.3,0,0,0,0,0,0,0.5", "--uncertainty", "none", "--pop-size", "8",
            "--generations", "2"]  # fmt: skip
    code, stdout, _ = run_cli(args, capsys)
    stdout = " ".join(stdout.split())  # the console wraps long lines
    code_json, json_out, _ = run_cli([*args, "--json"], capsys)
    data = json.loads(json_out)
    stage = stage_record(data["settings"]["stages"], "last_stage")["switching"]
    assert code == code_json == 0 and data["settings"]["last_stage"] == "switching"
    assert f"switching last stage: the switching model's eq. 3 {stage['start_fitness']:.4g}" in stdout
    assert ("iterate" in stdout) == stage["taken"]
    assert data["fitness"] == pytest.approx(stage["fitness"], rel=1e-6)
    code, json_out, _ = run_cli([*args, "--json", "--last-stage", "none"], capsys)
    settings = json.loads(json_out)["settings"]
    assert code == 0 and settings["last_stage"] == "none" and stage_record(settings["stages"], "last_stage")["switching"] is None
    # the same search either way: the monitor's fitness at the search's estimate
    assert settings["search_fitness"] == data["settings"]["search_fitness"]


def test_identify_says_when_a_poor_first_fit_started_a_second_search(capsys, monkeypatch):
    import json

    from emaphm.identification import limits
    from emaphm.identification.result import stage_record

    # a trigger every fit exceeds, a tiny polish: the second search runs, and the output says so
    # (without the switching last stage, which runs after it and is not what is checked here)
    monkeypatch.setitem(limits.SECOND_SEARCH_NRMSE, "default", 0.0)
    monkeypatch.setattr(limits, "POLISH_BUDGET", (8, 2))
    args = ["identify", "--true-faults", "0.3,0,0,0,0,0,0,0.5", "--uncertainty", "none", "--pop-size", "8",
            "--generations", "2", "--last-stage", "none"]  # fmt: skip
    code, stdout, _ = run_cli(args, capsys)
    stdout = " ".join(stdout.split())  # the console wraps long lines
    # a search that needed its second start is doubtful (exit 4), and says why
    assert code == 4 and "second search: the first fit's NRMSE " in stdout and "x the first: " in stdout
    assert "verdict: doubtful" in stdout
    code, json_out, _ = run_cli([*args, "--json"], capsys)
    data = json.loads(json_out)
    record = stage_record(data["settings"]["stages"], "second_search")
    assert code == 4 and record["trigger"] == 0.0 and record["first_fit_nrmse"] > 0.0
    assert any("second start" in d for d in data["doubts"])
    # the line says which result was kept, as the record does
    kept = "its result kept" if record["taken"] else "the first search's result kept"
    assert kept in stdout
    code, stdout, _ = run_cli([*args, "--json", "--no-second-search"], capsys)
    data = json.loads(stdout)
    assert stage_record(data["settings"]["stages"], "second_search") == {"stage": "second_search", "enabled": False, "ran": False}
    code, stdout, _ = run_cli([*args, "--no-second-search"], capsys)
    assert "second search" not in stdout


def test_the_second_search_help_gives_the_triggers_the_code_uses(capsys):
    from emaphm.identification.limits import SECOND_SEARCH_NRMSE

    code, stdout, _ = run_cli(["identify", "--help"], capsys)
    text = " ".join(stdout.replace("│", " ").split())
    assert code == 0
    assert (
        f"NRMSE above {100 * SECOND_SEARCH_NRMSE['default']:g} %; {100 * SECOND_SEARCH_NRMSE['paper']:g} %"
        in text
    )


def _write_bad_traces(d):
    (d / "corrupt.h5").write_bytes(b"garbage")
    (d / "nan.csv").write_text(
        "t,theta_cmd,theta_u,i_q\n" + "".join(f"{j / 1e4},0,0,{'nan' if j == 5 else 0}\n" for j in range(300))
    )
    (d / "few.csv").write_text("t,theta_cmd,theta_u,i_q\n" + "".join(f"{j / 1e4},0,0,0\n" for j in range(50)))
    (d / "nocmd.csv").write_text("t,theta_u,i_q\n" + "".join(f"{j / 1e4},0,0\n" for j in range(300)))


@pytest.mark.parametrize(
    ("args", "reason"),
    [
        (["identify"], "exactly one of"),
        (["identify", "--true-faults", "0,0,0,0,0,0,0,0.5", "--reference", "x.h5"], "exactly one of"),
        (["identify", "--true-faults", "0,0,0,0,0,0,0,0.5", "--optimizer", "sa"], "unknown --optimizer"),
        (["identify", "--true-faults", "0,0,0,0,0,0,0,1.5"], "--true-faults"),
        (["identify", "--reference", "missing.h5"], "no such file"),
        (["identify", "--reference", "corrupt.h5"], "cannot read"),
        (["identify", "--reference", "nan.csv"], "NaN"),
        (["identify", "--reference", "few.csv"], "at least 200"),
        (["identify", "--reference", "nocmd.csv"], "theta_cmd"),
        (["identify", "--true-faults", "0,0,0,0,0,0,0,0.5", "--output", "r.txt"], "--output"),
        (["identify", "--true-faults", "0,0,0,0,0,0,0,0.5", "--error-corner", "-3"], "--error-corner"),
        (["identify", "--true-faults", "0,0,0,0,0,0,0,0.5", "--error-corner", "fast"], "--error-corner"),
        (["identify", "--true-faults", "0,0,0,0,0,0,0,0.5", "--last-stage", "fast"], "--last-stage"),
    ],
)
def test_identify_bad_input_exits_2_and_writes_nothing(tmp_path, capsys, monkeypatch, args, reason):
    monkeypatch.chdir(tmp_path)
    _write_bad_traces(tmp_path)
    before = sorted(p.name for p in tmp_path.iterdir())
    code, stdout, err = run_cli(args, capsys)
    assert code == 2 and reason in err and len(err.strip().splitlines()) == 1
    assert stdout == "" and sorted(p.name for p in tmp_path.iterdir()) == before


def test_the_monitor_is_chosen_by_name_on_the_command_line(tmp_path, capsys):
    out = tmp_path / "lf.h5"
    code, _, err = run_cli(
        ["simulate", "--model", "lf", "--monitor", "paper", "--duration", "0.05", "--output", str(out)],
        capsys,
    )
    assert code == 0, err
    assert read_trace(out).metadata["monitor"] == "paper"
    for args, message in (
        (["--model", "lf", "--monitor", "three-phase"], "unknown monitor 'three-phase'"),
        (["--monitor", "paper"], "monitor model only"),
    ):
        target = tmp_path / "x.h5"
        code, _, err = run_cli(["simulate", *args, "--duration", "0.05", "--output", str(target)], capsys)
        assert code == 2 and message in err and not target.exists()


def test_calibrate_and_identify_refuse_an_unknown_monitor_before_any_work(tmp_path, capsys):
    out = tmp_path / "cal.json"
    code, _, err = run_cli(["calibrate", "--monitor", "exact", "--output", str(out)], capsys)
    assert code == 2 and "unknown monitor 'exact'" in err and len(err.strip().splitlines()) == 1
    assert not out.exists()
    code, _, err = run_cli(["identify", "--true-faults", "0,0,0,0,0,0,0,0.5", "--monitor", "exact"], capsys)
    assert code == 2 and "unknown --monitor 'exact'" in err


def test_calibrate_uq_refuses_too_few_cases_before_the_work(tmp_path, capsys):
    out = tmp_path / "uq.json"
    code, _, err = run_cli(["calibrate-uq", "--cases", "5", "--output", str(out)], capsys)
    assert code == 2 and "--cases" in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_identify_refuses_a_recording_faster_than_the_monitor_was_fitted_on(tmp_path, capsys):
    """A 15 Hz sine: nothing within the band the monitor was fitted on, so nothing to compare."""
    from emaphm.commands import Sine
    from emaphm.io import write_trace
    from emaphm.models import HighFidelityEma

    trace = tmp_path / "fast.h5"
    run = HighFidelityEma(command=Sine(amplitude=0.005, frequency=15.0, duration=0.5)).simulate(
        [0.1, 0.1, 0, 0, 0, 0, 0, 0.5], noise=True, seed=1
    )
    write_trace(run, trace)
    out = tmp_path / "r.json"
    code, _, err = run_cli(["identify", "--reference", str(trace), "--output", str(out), *FAST], capsys)
    assert code == 2 and "faster than the 10 Hz" in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


@pytest.mark.slow  # two identifications, ~4 s
def test_calibrate_detection_writes_thresholds_identify_can_load(tmp_path, capsys, monkeypatch):
    # the command replaces benchmarks/detection_thresholds.py; a tiny search keeps it to seconds
    import json

    from emaphm.calibration import params_hash
    from emaphm.identification import limits
    from emaphm.identification.detection import DETECTABLE, load_thresholds

    monkeypatch.setitem(limits.DEFAULT_BUDGETS, "ga", (8, 1))
    monkeypatch.setattr(limits, "POLISH_BUDGET", (4, 1))
    out = tmp_path / "detection.json"
    code, _, err = run_cli(["calibrate-detection", "--runs", "1", "--no-sensitivity", "--output", str(out)], capsys)
    assert code == 0 and f"wrote {out}" in " ".join(err.split())
    record = json.loads(out.read_text())
    assert set(record["thresholds"]) == set(DETECTABLE) and record["runs"] == 1 and record["sensitivity"] is None
    assert record["params_hash"] == params_hash(emaphm.EmaParams()) and record["threshold_seeds"] == [1000, 1000]
    assert dict(load_thresholds(out)["thresholds"]) == record["thresholds"]
    code, _, err = run_cli(["calibrate-detection", "--runs", "0", "--output", str(tmp_path / "no.json")], capsys)
    assert code == 2 and "runs must be" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "no.json").exists()


def tiny_calibration(tmp_path, capsys, monkeypatch, actuator_text):
    """An actuator file of `actuator_text` and a one-generation calibration of it from the shell
    (the polish's budget cut too, for the identifications that follow): their two paths."""
    from emaphm.identification import limits

    monkeypatch.setattr(limits, "POLISH_BUDGET", (4, 1))
    actuator = tmp_path / "actuator.toml"
    actuator.write_text(actuator_text)
    cal = tmp_path / "cal.json"
    code, _, _ = run_cli(["calibrate", "--params", str(actuator), "--pop-size", "4", "--generations", "1",
                          "--output", str(cal)], capsys)  # fmt: skip
    assert code == 0
    return actuator, cal


@pytest.mark.slow  # a tiny calibration and identification of another actuator, ~3 s
def test_an_8_khz_actuator_identifies_from_the_shell_with_the_switching_last_stage(tmp_path, capsys, monkeypatch):
    # review M1: fixed 2, 2.5, 1.25 us switching steps refused an 8 kHz actuator after the whole search
    import json

    actuator, cal = tiny_calibration(tmp_path, capsys, monkeypatch, '[controller]\nf_s = "8 kHz"\n')
    code, out, _ = run_cli(["identify", "--params", str(actuator), "--calibration", str(cal), "--true-faults",
                              "0.2,0,0,0.3,0,0,0,0.5", "--pop-size", "8", "--generations", "2",
                              "--uncertainty", "none", "--json"], capsys)  # fmt: skip
    data = json.loads(out)
    switching = next(r for r in data["settings"]["stages"] if r["stage"] == "last_stage")["switching"]
    assert code == EXIT_OF_VERDICT[data["verdict"]] and data["settings"]["last_stage"] == "switching"
    for step in switching["steps_s"]:  # whole fractions of the 125 us sample period
        assert 125e-6 / step == pytest.approx(round(125e-6 / step), abs=1e-9)


@pytest.mark.slow  # a tiny calibration and identification of an FOC actuator, ~5 s
def test_an_foc_actuator_calibrates_and_identifies_from_the_shell(tmp_path, capsys, monkeypatch):
    # issue 32: `emaphm calibrate --params foc.toml` works as for a hysteresis actuator, the
    # identification says which packaged file belongs to another actuator, and --detection takes
    # the actuator's own thresholds (a bad file refused in one line, before the work)
    import json

    from emaphm.identification.detection import DETECTABLE

    actuator, cal = tiny_calibration(
        tmp_path, capsys, monkeypatch, '[inverter]\ncontrol = "foc"\nf_pwm = "20 kHz"\nK_p_i = "9.42 V/A"\n'
    )
    record = json.loads(cal.read_text())
    assert "tau_i" not in record["settings"]["fitted"] and "i_D" not in record["settings"]["fitted"]
    assert record["settings"]["params"]["inverter"]["control"] == "foc"
    assert record["quality"]["verdict"] in ("good", "usable", "poor")  # judged and recorded
    args = ["identify", "--params", str(actuator), "--calibration", str(cal), "--true-faults",
            "0.2,0,0,0.3,0,0,0,0.5", "--pop-size", "8", "--generations", "2", "--json"]  # fmt: skip
    code, out, err = run_cli(args, capsys)
    data = json.loads(out)
    assert code == EXIT_OF_VERDICT[data["verdict"]]
    warned = " ".join(data["warnings"])
    assert "detection thresholds were measured on another actuator" in warned and "foc drive" in warned
    assert "interval calibration was fitted with another LF calibration" in warned
    thresholds = tmp_path / "det.json"
    thresholds.write_text(json.dumps({"thresholds": dict.fromkeys(DETECTABLE, 10.0)}))
    code, out, _ = run_cli([*args, "--detection", str(thresholds)], capsys)
    data = json.loads(out)
    assert "detection thresholds were measured" not in " ".join(data["warnings"])
    assert data["detected"] == []  # every fault below a threshold of 10
    bad = tmp_path / "bad.json"
    bad.write_text('{"thresholds": {"friction": -1}}')
    code, out, err = run_cli([*args, "--detection", str(bad)], capsys)
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1 and "detection thresholds" in err
    # a calibration of the hysteresis drive is refused for it, naming the drives
    code, _, err = run_cli(["identify", "--params", str(actuator), "--calibration",
                            str(Path(emaphm.__file__).parent / "data" / "calibration.json"),
                            "--true-faults", "0,0,0,0,0,0,0,0.5"], capsys)  # fmt: skip
    assert code == 2 and "a hysteresis drive, this one's is foc" in " ".join(err.split())


@pytest.mark.parametrize("suffix", [".parquet", ".mat"])
def test_a_rig_format_without_its_map_is_told_to_give_the_map(tmp_path, capsys, suffix):
    # the newcomer: 'identify --reference x.parquet' without --map said Parquet was unsupported
    rec = tmp_path / f"rig{suffix}"
    rec.write_bytes(b"PAR1" if suffix == ".parquet" else b"MATLAB")
    code, out, err = run_cli(["identify", "--reference", str(rec)], capsys)
    message = " ".join(err.split())
    assert code == 2 and out == "" and "give it with --map" in message and "unsupported" not in message


def test_the_printed_diagnosis_names_the_actuator_and_calibrations_it_rests_on(tmp_path, capsys):
    # the newcomer's m11: a recording of another actuator identified with the nominal one was
    # silently off, and the output never said which actuator or calibration it used
    code, out, _ = run_cli(["identify", "--true-faults", "0,0,0,0,0,0,0,0.5", "--pop-size", "6",
                            "--generations", "1", "--no-polish", "--uncertainty", "none"], capsys)  # fmt: skip
    text = " ".join(out.split())
    assert code in (0, 3, 4)  # a tiny search: fitting or not, the inputs are named
    assert "actuator: nominal (hash 9400227a7dd94ce8); monitor calibration: packaged (made 2026-" in text
    path = tmp_path / "act.toml"
    path.write_text("[motor]\nR_s = 0.6\n")
    code, _, err = run_cli(["identify", "--params", str(path), "--true-faults", "0,0,0,0,0,0,0,0.5"], capsys)
    assert code == 2 and "made for other actuator parameters" in err  # --params without its calibration
    # the newcomer's other slip: --calibration of another actuator without its --params names the way out
    cal = Path(__file__).resolve().parents[1] / "benchmarks" / "actuators" / "foc-textbook.cal.json"
    code, _, err = run_cli(["identify", "--calibration", str(cal), "--true-faults", "0,0,0,0,0,0,0,0.5"], capsys)
    assert code == 2 and "a foc drive" in err and "pass the actuator file it was made for (--params" in err


def test_a_command_runs_from_an_app_of_its_own_with_the_same_command_line(capsys):
    # main() builds only the command asked for (issue 36); its help and usage errors must be the
    # full app's, and anything that is not a command name gets the full app
    import typer.main

    from emaphm import cli

    one = cli._app_for(["identify", "--help"])
    assert one is not cli.app and cli._app_for(["--help"]) is cli.app and cli._app_for(["idntify"]) is cli.app
    assert set(typer.main.get_command(one).commands) == {"identify"}
    assert set(typer.main.get_command(cli.app).commands) == set(cli.NAMES)

    def help_of(app):
        with pytest.raises(SystemExit):
            app(args=["identify", "--help"], prog_name="emaphm")
        return capsys.readouterr().out

    assert "--true-faults" in help_of(one) and help_of(one) == help_of(cli.app)
    for argv in (["identify", "--bogus"], ["campaign", "run"]):
        with pytest.raises(SystemExit) as full:
            cli.app(args=argv, prog_name="emaphm")
        expected = capsys.readouterr().err
        with pytest.raises(SystemExit) as alone:
            cli._app_for(argv)(args=argv, prog_name="emaphm")
        assert (alone.value.code, capsys.readouterr().err) == (full.value.code, expected) and expected


# ---- the process's own exit (issue 36: the interpreter's teardown after the kernels, 0.13 s) ----


class _ExitedError(Exception):
    """os._exit, caught: its status."""


@pytest.mark.parametrize(("code", "status", "said"), [(None, 0, ""), (4, 4, ""), ("a reason", 1, "a reason\n")])
def test_the_process_ends_by_os_exit_after_the_atexit_functions_and_a_flush(monkeypatch, capsys, code, status, said):
    import atexit
    import os

    import emaphm.cli as cli

    ran: list[str] = []

    def exited(s: int) -> None:
        raise _ExitedError(s)

    monkeypatch.setattr(cli, "_bare_exit_safe", lambda: True)
    monkeypatch.setattr(atexit, "_run_exitfuncs", lambda: ran.append("atexit"))
    monkeypatch.setattr(os, "_exit", exited)
    print("written before the exit", end="")
    with pytest.raises(_ExitedError) as caught:
        cli._process_exit(code)
    assert caught.value.args == (status,) and ran == ["atexit"]
    out, err = capsys.readouterr()
    assert out == "written before the exit" and err == said


def test_the_process_ends_as_usual_where_a_thread_or_a_profiler_may_need_the_interpreter(monkeypatch):
    import cProfile
    import os
    import threading

    import emaphm.cli as cli

    monkeypatch.setattr(os, "_exit", lambda s: pytest.fail("os._exit called"))
    if not cli._bare_exit_safe():
        pytest.skip("this test process already has a thread, child or tracer that needs the usual exit")
    release = threading.Event()
    worker = threading.Thread(target=release.wait)  # not a daemon: the interpreter would wait for it
    worker.start()
    try:
        assert not cli._bare_exit_safe()
        with pytest.raises(SystemExit) as caught:
            cli._process_exit(3)
        assert caught.value.code == 3
    finally:
        release.set()
        worker.join()
    assert cli._bare_exit_safe()
    profiler = cProfile.Profile()
    profiler.enable()
    try:
        unsafe_under_profile = not cli._bare_exit_safe()
    finally:
        profiler.disable()
    assert unsafe_under_profile


def test_a_process_run_of_the_command_line_writes_all_its_output_and_its_status(tmp_path):
    # the whole path from the shell: stdout complete through a pipe, the status and stderr's one line
    template = subprocess.run([sys.executable, "-m", "emaphm", "params", "--template"], capture_output=True, text=True)
    assert template.returncode == 0 and "psi_m" in template.stdout and template.stderr == ""
    from typer.testing import CliRunner

    import emaphm.cli as cli

    assert CliRunner().invoke(cli.app, ["params", "--template"]).output == template.stdout
    bad = subprocess.run([sys.executable, "-m", "emaphm", "identify", "--true-faults", "2,0"],
                         capture_output=True, text=True)  # fmt: skip
    assert bad.returncode == 2 and bad.stdout == ""
    assert bad.stderr.count("\n") == 1 and bad.stderr.startswith("emaphm: error: --true-faults")


def test_stderr_is_rich_console_made_when_first_used(monkeypatch, capsys):
    # `err` answers "is stderr a terminal?" without rich where it plainly is not (issue 36: rich's
    # import was 17 ms of every command), and is rich's Console for everything else
    code = ("import sys; from emaphm.cli.output import err; t = err.is_terminal; "
            "print(t, 'rich.console' in sys.modules)")  # fmt: skip
    env = {k: v for k, v in __import__("os").environ.items() if k not in ("FORCE_TERMINAL", "TTY_COMPATIBLE",
           "FORCE_COLOR", "TTY_INTERACTIVE")}  # fmt: skip
    plain = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)
    assert plain.stdout.split() == ["False", "False"]
    for setting in ("FORCE_TERMINAL", "TTY_COMPATIBLE"):  # rich decides, as it did
        rich_says = "; from rich.console import Console; print(Console(stderr=True).is_terminal)"
        forced = subprocess.run([sys.executable, "-c", code + rich_says], capture_output=True, text=True,
                                env={**env, setting: "1"}, check=True)  # fmt: skip
        ours, imported, theirs = forced.stdout.split()
        assert imported == "True" and ours == theirs
    assert ours == "True"  # TTY_COMPATIBLE=1: a terminal to rich, whatever the stream
    from emaphm.cli.output import Stderr

    err = Stderr()
    err.print("a message [not markup]", markup=False)
    assert capsys.readouterr().err == "a message [not markup]\n"
    from rich.console import Console

    assert isinstance(err.console, Console) and err.console is err.console
