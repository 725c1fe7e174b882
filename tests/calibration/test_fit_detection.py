"""The detection thresholds' calibration (`calibrate_detection`): its method on stand-in
identifications, one real run at a tiny budget, its refusals, and its atomic write."""

import json
from types import SimpleNamespace

import numpy as np
import pytest

from emaphm import EmaParams, InputError
from emaphm.calibration import calibrate_detection, fit_detection, params_hash
from emaphm.faults import HEALTHY
from emaphm.identification.detection import DETECTABLE, load_thresholds
from emaphm.identification.settings import IdentifySettings


def offset(**changes):
    """A departure from healthy: zeros with some entries set, e.g. offset(k1=0.004)."""
    out = np.zeros(len(HEALTHY))
    for name, value in changes.items():
        out[int(name[1:]) - 1] = value
    return out


def fake_identify(offsets):
    """identify() replaced by one that returns healthy + offsets[seed] (zeros for unknown seeds)."""
    calls = []

    def identify(k, *, seed, settings, **inputs):
        calls.append((np.array(k), seed, {**inputs, **settings.to_json()}))
        return SimpleNamespace(estimate=np.array(k) + offsets.get(seed, 0.0))

    return identify, calls


def test_the_thresholds_follow_the_rule_and_the_record_says_what_made_them(tmp_path, monkeypatch):
    # thresholds from seeds 1000..1001: friction departs 0.004, then 0.008 -> 1.25 * 0.008 + 0.005;
    # k8 departs 0.002 below 0.5 (either way counts); k7, a direction, has no threshold
    offsets = {1000: offset(k1=0.004), 1001: offset(k1=0.008, k7=0.3, k8=-0.002)}
    offsets[2001] = offset(k3=0.05)  # a false alarm: short_a
    identify, calls = fake_identify(offsets)
    monkeypatch.setattr(fit_detection, "identify", identify)
    progress = []
    out = tmp_path / "detection.json"
    record = calibrate_detection(
        runs=2, output=out, progress=lambda *a: progress.append(a), settings=IdentifySettings(pop_size=4)
    )
    assert record["thresholds"]["friction"] == round(1.25 * 0.008 + 0.005, 4)
    assert record["thresholds"]["kp_drift"] == round(1.25 * 0.002 + 0.005, 4)
    assert record["thresholds"]["backlash"] == 0.005  # no departure: the 0.005 margin alone
    assert record["false_alarm_runs"] == 1 and record["false_alarms"] == [["short_a"]]
    assert [c[1] for c in calls[:4]] == [1000, 1001, 2000, 2001]
    assert all(c[2]["thresholds"] == {} and c[2]["pop_size"] == 4 for c in calls)
    # every single fault of 0.1 and 0.2 (k8 0.6 and 0.7), seed 3000: the stand-in reports them all
    assert len(record["sensitivity"]) == 2 * len(DETECTABLE) and {c[1] for c in calls[4:]} == {3000}
    assert all(s["detected"] == [s["fault"]] for s in record["sensitivity"])
    assert progress[0] == ("healthy runs (thresholds)", 1, 2) and progress[-1][1:] == (14, 14)
    # what they were made with (review L4)
    assert record["params_hash"] == params_hash(EmaParams()) and record["monitor"] == "default"
    assert record["last_stage"] == "switching" and record["settings"]["runs"] == 2
    assert {"created", "versions", "lf_calibration", "package_version"} <= set(record)
    assert json.loads(out.read_text()) == record
    assert load_thresholds(out)["thresholds"] == record["thresholds"]  # a loadable file
    assert [p.name for p in tmp_path.iterdir()] == ["detection.json"]  # no temporary left


@pytest.mark.slow  # ~4 s: two identifications of the healthy twin at a tiny budget
def test_a_tiny_real_run_writes_a_loadable_file(tmp_path):
    out = tmp_path / "thresholds.json"
    tiny = IdentifySettings(pop_size=4, generations=1)
    record = calibrate_detection(runs=1, sensitivity_seed=None, settings=tiny, output=out)
    read = load_thresholds(out)
    assert set(read["thresholds"]) == set(DETECTABLE)
    assert all(v >= 0.005 for v in read["thresholds"].values())
    assert read["sensitivity"] is None and len(read["healthy_estimates_check_set"]) == 1
    assert read["params_hash"] == params_hash(EmaParams()) == record["params_hash"]


OTHER = EmaParams.from_dict(
    {**EmaParams().to_dict(), "motor": {**EmaParams().to_dict()["motor"], "R_s": 0.6}}
)


@pytest.mark.parametrize(
    ("settings", "match"),
    [
        ({"runs": 0}, "runs must be a whole number >= 1"),
        ({"runs": True}, "runs must be a whole number >= 1"),
        ({"threshold_seed": -1}, "seed must be a whole number"),
        ({"sensitivity_seed": 1.5}, "seed must be a whole number"),
        ({"false_alarm_seed": 1010}, "false-alarm runs must be fresh: seeds 1010..1029 overlap"),

        ({"output": "thresholds.txt"}, "unsupported file type"),
        ({"output": "no/such/folder/t.json"}, "does not exist"),
        ({"params": OTHER}, "made for other actuator parameters"),
        ({"calibration": "no-such-calibration.json"}, "no such"),
    ],
)
def test_bad_input_is_refused_in_one_line_before_any_work(settings, match, monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    identify, calls = fake_identify({})
    monkeypatch.setattr(fit_detection, "identify", identify)
    with pytest.raises(InputError, match=match) as info:
        calibrate_detection(**settings)
    assert "\n" not in str(info.value) and calls == []
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("failure", [RuntimeError, KeyboardInterrupt])
def test_a_run_that_fails_leaves_the_old_file_whole(failure, tmp_path, monkeypatch):
    out = tmp_path / "detection.json"
    out.write_text('{"old": true}\n')
    identify, calls = fake_identify({})

    def failing(k, *, seed, **settings):
        if len(calls) == 3:
            raise failure("stopped")
        return identify(k, seed=seed, **settings)

    monkeypatch.setattr(fit_detection, "identify", failing)
    with pytest.raises(failure):
        calibrate_detection(runs=2, output=out)
    assert out.read_text() == '{"old": true}\n'
    assert [p.name for p in tmp_path.iterdir()] == ["detection.json"]
