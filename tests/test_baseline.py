"""Each actuator's own baseline (issue 33): its constants from healthy recordings, and identify --baseline."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

import emaphm
from emaphm.actuator import load_params
from emaphm.baseline import FILES, baseline, make_baseline
from emaphm.baseline.files import NAMEPLATE_FILES
from emaphm.calibration import load_calibration, params_hash
from emaphm.errors import InputError
from emaphm.identification.uncertainty import load_factors
from emaphm.identification.verdict import fit_limit
from emaphm.models import MonitorEma
from emaphm.params import EmaParams
from emaphm.results import SimResult
from tests.helpers import EXIT_OF_VERDICT, run_cli

GAIN = 1.06  # a current sensor reading 6 % high, on every recording of the actuator
NEWCOMER = np.array([0.30, 0.15, 0.0, 0.25, 0.0, 0.10, 0.60, 0.42])


def _recorded(k, seed, gain=GAIN):
    trace = emaphm.simulate(k, seed=seed)
    return SimResult(t=trace.t, signals={**trace.signals, "i_q": gain * trace.signals["i_q"]}, metadata=trace.metadata)


@pytest.fixture(scope="module")
def healthy(tmp_path_factory):
    folder = tmp_path_factory.mktemp("healthy")
    paths = []
    for s in range(3):
        path = folder / f"h{s}.h5"
        emaphm.write_trace(_recorded(emaphm.HEALTHY, 100 + s), path)
        paths.append(path)
    return paths


@pytest.fixture(scope="module")
def folder(healthy, tmp_path_factory):
    return baseline(healthy, tmp_path_factory.mktemp("b") / "A7")


def test_the_sensor_gain_is_measured_and_the_twin_constants_stay_within_their_intervals(folder):
    record = json.loads((folder / FILES["record"]).read_text())
    gain = record["factors"]["i_gain"]
    # the gain the recordings were made with, within its interval and to 1 %
    assert gain["ci90"][0] <= GAIN <= gain["ci90"][1] and abs(gain["factor"] - GAIN) < 0.01
    # the twin's other constants are its nameplate: each interval holds 1 (they are the truth)
    for name in ("k_t_eq", "J_eq", "F_D0", "K_P0"):
        low, high = record["factors"][name]["ci90"]
        assert low <= 1.0 <= high, name
    # and the fits improve on the nameplate's, whose current is 6 % off
    for r in record["recordings"]:
        assert r["fit_nrmse"] < 0.5 * r["nameplate_fit_nrmse"] and len(r["sha256"]) == 64


def test_the_folder_holds_what_identify_needs_bound_together(folder):
    assert {p.name for p in folder.iterdir()} >= {*FILES.values(), "index.html", "fit-1.png", "fit-3.png"}
    params = load_params(folder / FILES["params"])
    calibration = load_calibration(folder / FILES["calibration"])
    MonitorEma(params, calibration=calibration)  # the calibration is the fitted actuator's: no refusal
    factors = load_factors(folder / FILES["uq_calibration"])
    assert factors.matches(calibration)
    # the constants' covariance, which widens each diagnosis' intervals: positive definite on the fitted ones
    cov = np.array(factors.record["constants"]["log_covariance"])
    assert cov.shape == (7, 7) and np.all(np.linalg.eigvalsh(cov) > 0)
    # the nameplate and its own calibration, for the start table the type shares
    nameplate = load_params(folder / NAMEPLATE_FILES["params"])
    assert params_hash(nameplate) == params_hash(EmaParams()) != params_hash(params)
    MonitorEma(nameplate, calibration=load_calibration(folder / NAMEPLATE_FILES["calibration"]))
    text = (folder / FILES["params"]).read_text()
    assert "current sensor's gain" in text and "90 % interval" in text and "sha256" in text
    assert "<table>" in (folder / "index.html").read_text()


@pytest.mark.slow  # two identifications, ~25 s
def test_identify_with_the_baseline_reads_the_short_right_where_the_nameplate_does_not(folder):
    # the newcomer's case (a 25 % short in phase B among four other faults) through the same 6 %-high sensor
    recording = _recorded(NEWCOMER, 7)
    alone = emaphm.identify(reference=recording, seed=1)
    based = emaphm.identify(reference=recording, seed=1, baseline=folder)
    err_alone, err_based = (emaphm.percent_error(r.estimate, NEWCOMER) for r in (alone, based))
    assert err_based <= 3.0 < err_alone and err_based < 0.6 * err_alone
    assert based.settings["baseline"]["directory"] == str(folder) and based.settings["baseline"]["current_gain"] > 1.04
    assert alone.settings["baseline"] is None
    assert based.uncertainty.details["constants_from"].startswith("the baseline's fit")
    # the search starts from the nameplate's table, the one every actuator of the type shares
    assert alone.settings["stages"][0]["start"] == based.settings["stages"][0]["start"] == "table"
    assert based.settings["stages"][0]["table"] == alone.settings["stages"][0]["table"]
    assert based.settings["baseline"]["table_from"]["params"] == str(folder / NAMEPLATE_FILES["params"])


def test_a_folder_without_the_nameplate_starts_uniform(folder, tmp_path):
    # a folder made before the nameplate's files were written: "auto" is a uniform start, recorded so
    old = tmp_path / "old"
    shutil.copytree(folder, old)
    for name in NAMEPLATE_FILES.values():
        (old / name).unlink()
    quick = {"seed": 1, "pop_size": 8, "generations": 2, "polish": False, "last_stage": "none", "uncertainty": "none"}
    r = emaphm.identify(true_faults=emaphm.HEALTHY, baseline=old, **quick)
    assert r.settings["stages"][0]["start"] == "random" and r.settings["identify"]["start"] == "random"
    assert r.settings["baseline"]["table_from"] is None
    assert "holds neither" in r.settings["baseline"]["table_skipped"]
    # a nameplate calibration that is not the nameplate's (another actuator's): the same, no refusal
    shutil.copy(folder / FILES["calibration"], old / NAMEPLATE_FILES["calibration"])
    shutil.copy(folder / NAMEPLATE_FILES["params"], old / NAMEPLATE_FILES["params"])
    r = emaphm.identify(true_faults=emaphm.HEALTHY, baseline=old, **quick)
    assert r.settings["stages"][0]["start"] == "random" and r.settings["baseline"]["table_from"] is None
    assert r.settings["baseline"]["table_skipped"].startswith("the nameplate's files do not load as a monitor")
    assert based_skip(folder) is None


def based_skip(folder):
    """What a baseline folder's record says of its nameplate's start table (None: it is used)."""
    from emaphm.baseline import baseline_inputs

    return baseline_inputs(folder)["table_skipped"]


def test_a_broken_nameplate_pair_is_said_not_silent(folder, tmp_path, capsys):
    # one file without its pair, or a calibration that is not JSON: uniform, and the reason named,
    # in the result's record and as one note line from the command
    broken = tmp_path / "broken"
    shutil.copytree(folder, broken)
    (broken / NAMEPLATE_FILES["calibration"]).unlink()
    assert based_skip(broken) == f"the folder holds {NAMEPLATE_FILES['params']} without its pair"
    (broken / NAMEPLATE_FILES["calibration"]).write_text("{not json")
    assert "do not load as a monitor" in based_skip(broken)
    out = tmp_path / "r.json"
    code, _, err = run_cli(
        ["identify", "--true-faults", "0,0,0,0,0,0,0,0.5", "--baseline", str(broken), "--seed", "1", "--pop-size", "8",
         "--generations", "2", "--no-polish", "--last-stage", "none", "--uncertainty", "none", "--output", str(out)],
        capsys,
    )  # fmt: skip
    assert code == EXIT_OF_VERDICT[json.loads(out.read_text())["verdict"]]
    notes = [line for line in err.splitlines() if line.startswith("emaphm: note:")]
    assert len(notes) == 1 and "starts uniform" in notes[0] and "do not load as a monitor" in notes[0], err
    assert json.loads(out.read_text())["settings"]["baseline"]["table_skipped"] is not None


def test_recordings_of_two_actuators_are_refused_with_the_reason(healthy, tmp_path):
    other = tmp_path / "other.h5"
    emaphm.write_trace(_recorded(emaphm.HEALTHY, 200, gain=1.25), other)
    with pytest.raises(InputError, match=r"disagree on i_gain|fits far worse"):
        make_baseline([healthy[0], other, healthy[1]])


def test_bad_inputs_are_refused_in_one_line_before_the_work(folder, healthy, tmp_path, capsys):
    full = tmp_path / "full"
    full.mkdir()
    (full / "x.txt").write_text("x")
    code, _, err = run_cli(["baseline", str(healthy[0]), "--output", str(full)], capsys)
    assert code == 2 and "not an empty folder or an earlier baseline" in err and err.count("\n") == 1
    code, _, err = run_cli(["baseline", str(tmp_path / "none.h5"), "--output", str(tmp_path / "b")], capsys)
    assert code == 2 and "no such recording" in err and not (tmp_path / "b").exists()
    args = ["identify", "--true-faults", "0,0,0,0,0,0,0,0.5", "--baseline"]
    code, _, err = run_cli([*args, str(folder), "--calibration", str(folder / FILES["calibration"])], capsys)
    assert code == 2 and "--baseline gives the actuator's --calibration" in err
    code, _, err = run_cli([*args, str(tmp_path)], capsys)
    assert code == 2 and "is missing: not a baseline folder" in err
    with pytest.raises(InputError, match="at least one recording"):
        make_baseline([])


@pytest.mark.slow  # two baselines from the shell, ~10 s
def test_the_command_writes_the_folder_and_says_what_it_found(healthy, tmp_path, capsys):
    code, _, err = run_cli(["baseline", *map(str, healthy[:2]), "--output", str(tmp_path / "B")], capsys)
    text = " ".join(err.split())
    assert code == 0 and "i_gain:" in text and "identify --baseline" in text and (tmp_path / "B" / "uq.json").is_file()
    # run again into the same folder: an earlier baseline is replaced whole
    code, _, _ = run_cli(["baseline", *map(str, healthy[1:]), "--output", str(tmp_path / "B")], capsys)
    record = json.loads((tmp_path / "B" / FILES["record"]).read_text())
    assert code == 0 and [r["file"] for r in record["recordings"]] == [str(p) for p in healthy[1:]]


def test_the_doubtful_limit_follows_the_baseline_s_own_healthy_fits():
    twin = {"data": {"fit_nrmse": [0.01] * 40}}
    limit, _ = fit_limit(twin, "default")
    assert fit_limit({**twin, "baseline": {"fit_nrmse": [0.005, 0.006]}}, "default")[0] == limit  # no looser
    poorer, source = fit_limit({**twin, "baseline": {"fit_nrmse": [0.02, 0.03]}}, "default")
    assert poorer == pytest.approx(emaphm.identification.limits.DOUBTFUL_MARGIN * 0.03) and "baseline" in source


def test_a_nameplate_without_its_calibration_starts_from_the_packaged_one_and_says_so(healthy, tmp_path, capsys):
    nameplate = tmp_path / "nameplate.toml"
    nameplate.write_text("[motor]\nR_s = 0.55\n")
    code, _, err = run_cli(["baseline", str(healthy[0]), "--params", str(nameplate), "--output", str(tmp_path / "W")],
                           capsys)  # fmt: skip
    assert code == 0 and "the packaged one (made for the paper's actuator) was the start" in " ".join(err.split())
    record = json.loads((tmp_path / "W" / FILES["record"]).read_text())
    assert record["warm_start"] and load_params(tmp_path / "W" / FILES["params"]).motor.R_s == 0.55
    # the folder is bound to the fitted actuator: identify takes it without --params or --calibration
    r = emaphm.identify(true_faults=emaphm.HEALTHY, seed=1, baseline=tmp_path / "W", pop_size=6, generations=1,
                        polish=False, uncertainty="none")  # fmt: skip
    assert r.settings["baseline"]["directory"] == str(tmp_path / "W")
    # a calibration given for another actuator is still refused
    with pytest.raises(InputError, match="made for other actuator parameters"):
        make_baseline([healthy[0]], params=nameplate, calibration=Path(emaphm.__file__).parent / "data" / "calibration.json")
