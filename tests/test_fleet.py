"""`emaphm fleet` (issue 35): every actuator ranked by urgency, thresholds checked per diagnosis,
the same RUL as `emaphm rul`; the store's compaction and the trend's many-at-once prediction."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from emaphm.campaign.store import RESULT_COLUMNS, ResultStore
from emaphm.campaign.synthetic import write_synthetic_store
from emaphm.failure import FAULTS, PLACEHOLDER_THRESHOLDS
from emaphm.prognostics import fleet as fleet_module
from emaphm.prognostics.fleet import BANDS, COLOURS, colour_of, fleet_report
from emaphm.prognostics.rul import rul_report
from emaphm.prognostics.trend import DegradationTrend, predict_many
from tests.helpers import run_cli

CONTRACT = ("actuator", "verdict", "worst_fault", "threshold_share", "rul_p05", "rul_median", "colour")


@pytest.fixture(scope="module")
def store(tmp_path_factory):
    root = tmp_path_factory.mktemp("fleet") / "store"
    write_synthetic_store(root, 40, 8, seed=3)
    return root


def _row(actuator, flight, verdict="fits", **k):
    row = {c: None for c in RESULT_COLUMNS}
    values = {f"k{i}": 0.0 for i in range(1, 9)} | {"k8": 0.5} | k
    row.update(
        job_key=f"{actuator}-{flight}", campaign="c", actuator=actuator, flight=flight, seed=1, identify_seed=1,
        verdict=verdict, finished=f"2026-01-01T00:00:{flight:02d}", doubts=json.dumps([] if verdict != "doubtful" else ["x"]),
        fault_verdicts=None if verdict == "does not fit" else json.dumps({n: "absent" for n in FAULTS}),
        **values, **{f"std_k{i}": 0.01 for i in range(1, 9)},
    )  # fmt: skip
    return row


def test_every_actuator_once_ranked_by_urgency_with_the_contract_keys(store):
    report = fleet_report(store)
    entries = report["actuators"]
    assert sorted(e["actuator"] for e in entries) == [f"A{i:02d}" for i in range(40)]
    assert all(set(CONTRACT) <= set(e) for e in entries)
    ranks = [COLOURS.index(e["colour"]) for e in entries]
    assert ranks == sorted(ranks)  # no green before a red
    for e in entries:  # the colour is the band of the remaining share (or yellow: nothing sized)
        if e["worst_fault"] is not None:
            assert e["colour"] == colour_of(e["remaining_share"])
    assert sum(report["counts"][c] for c in COLOURS) == 40


def test_the_worst_fault_is_the_largest_share_of_its_threshold_in_the_latest_sized_diagnosis(store):
    rows = ResultStore(store).read("results").to_pylist()
    for e in fleet_report(store)["actuators"][:10]:
        mine = [r for r in rows if r["actuator"] == e["actuator"] and r["verdict"] in ("fits", "doubtful")]
        latest = max(mine, key=lambda r: r["flight"])
        shares = {n: abs(latest[c] - h) / PLACEHOLDER_THRESHOLDS[n] for n, (c, _, h) in FAULTS.items()}
        worst = max(shares, key=shares.get)
        assert e["worst_fault"] == worst and e["threshold_share"] == pytest.approx(shares[worst], abs=1e-4)


def test_the_rul_is_the_one_emaphm_rul_gives(store):
    for e in fleet_report(store)["actuators"][:8]:
        first = rul_report(store, e["actuator"])["first_failure"]
        assert (e["rul_p05"], e["rul_median"], e["rul_p95"]) == (
            first.get("rul_p05"), first.get("rul_median"), first.get("rul_p95"),
        )  # fmt: skip


def test_one_measurement_over_its_threshold_is_red_now(tmp_path):
    ResultStore(tmp_path).write("results", [_row("ONE", 0, k2=0.30), _row("OK", 0, k2=0.02)])
    by = {e["actuator"]: e for e in fleet_report(tmp_path)["actuators"]}
    assert by["ONE"]["colour"] == "red" and by["ONE"]["exceeded"] == ["backlash"]
    assert by["ONE"]["threshold_share"] == pytest.approx(0.30 / PLACEHOLDER_THRESHOLDS["backlash"])
    assert by["OK"]["colour"] == "green" and by["OK"]["rul_p05"] is None  # one-off: no trend
    assert [e["actuator"] for e in fleet_report(tmp_path)["actuators"]] == ["ONE", "OK"]
    # a threshold given moves the share and the colour
    wide = {e["actuator"]: e for e in fleet_report(tmp_path, thresholds={"backlash": 0.6})["actuators"]}
    assert wide["ONE"]["colour"] == "yellow" and wide["ONE"]["threshold_share"] == pytest.approx(0.5)


def test_doubtful_and_unfitting_diagnoses(tmp_path):
    growing = [_row("D", f, k1=0.05 + 0.02 * f) for f in range(1, 7)]
    growing[-1]["verdict"] = "doubtful"
    nofit = [_row("N", f, verdict="does not fit") for f in (1, 2)]
    ResultStore(tmp_path).write("results", growing + nofit)
    by = {e["actuator"]: e for e in fleet_report(tmp_path)["actuators"]}
    assert by["D"]["verdict"] == "doubtful" and by["D"]["doubtful_left_out"] == 1
    assert (
        by["N"]["colour"] == "yellow" and by["N"]["worst_fault"] is None and "re-measure" in by["N"]["reason"]
    )
    with_doubtful = {e["actuator"]: e for e in fleet_report(tmp_path, include_doubtful=True)["actuators"]}
    assert with_doubtful["D"]["doubtful_left_out"] == 0


def test_the_bands():
    assert [colour_of(x) for x in (-0.5, 0.0, 0.1, 0.25, 0.3, 0.5, 0.51, None)] == [
        "red", "red", "orange", "orange", "yellow", "yellow", "green", "green",
    ]  # fmt: skip
    assert BANDS == (0.0, 0.25, 0.5)


def test_two_processes_give_what_one_gives(store, monkeypatch):
    one = fleet_report(store, seed=5)
    monkeypatch.setattr(fleet_module, "PARALLEL_FROM", 10)
    monkeypatch.setattr(fleet_module, "usable_cores", lambda: 2)
    two = fleet_report(store, seed=5)
    strip = lambda r: [{k: v for k, v in e.items()} for e in r["actuators"]]  # noqa: E731
    assert strip(one) == strip(two)


def test_predicting_many_trends_at_once_gives_each_ones_numbers():
    rng = np.random.default_rng(2)
    trends = [DegradationTrend(law).update(np.arange(1, 9), 0.05 + g * np.arange(1, 9) + rng.normal(0, 0.005, 8),
                                           np.full(8, 0.005))
              for law, g in (("linear", 0.01), ("exponential", 0.02), ("linear", -0.001))]  # fmt: skip
    z = rng.standard_normal((3, 500, 2))
    many = predict_many(trends, [0.3, 0.4, 0.2], 8.0, z)
    for trend, threshold, zi, est in zip(trends, [0.3, 0.4, 0.2], z, many, strict=True):
        one = trend.predict_rul(threshold, 8.0, 500, z=zi)
        np.testing.assert_allclose(est.samples, one.samples, rtol=1e-12)
        assert (est.p05, est.median, est.p95, est.never) == pytest.approx(
            (one.p05, one.median, one.p95, one.never)
        )


def test_compaction_keeps_every_row_once_and_survives_an_interruption(tmp_path):
    write_synthetic_store(tmp_path, 12, 3, seed=1)
    store = ResultStore(tmp_path)
    before = store.read("results").sort_by("job_key")
    assert store.compact(min_files=4) == 12 and store.loose_parts() == 0
    after = store.read("results").sort_by("job_key")
    assert after.equals(before.select(after.column_names))
    assert store.read("results", actuator="A03").num_rows == 3
    # rows written again (a compaction killed before it removed its sources) are read once
    store.write("results", store.read("results", actuator="A05").to_pylist())
    assert store.read("results").num_rows == 36
    # new rows after a compaction are read beside it
    store.write("results", [_row("NEW", 1) | {"campaign": "synthetic"}])
    assert store.read("results").num_rows == 37


def test_the_command(store, tmp_path, capsys):
    code, out, _ = run_cli(["fleet", str(store), "--json"], capsys)
    assert code == 0
    data = json.loads(out)
    assert len(data["actuators"]) == 40 and all("_series" not in e for e in data["actuators"])
    code, out, _ = run_cli(["fleet", str(store), "--top", "5", "--output", str(tmp_path / "page")], capsys)
    assert code == 0 and "35 more" in out and "placeholders" in out
    with (tmp_path / "page" / "fleet.csv").open() as fh:
        table = list(csv.DictReader(fh))
    assert [r["actuator"] for r in table] == [e["actuator"] for e in data["actuators"]]
    assert set(CONTRACT) <= set(table[0])
    assert (
        json.loads((tmp_path / "page" / "fleet.json").read_text())["actuators"][0]["actuator"]
        == table[0]["actuator"]
    )
    assert (tmp_path / "page" / "index.html").is_file()


@pytest.mark.parametrize(
    "args, message",
    [
        (["fleet", "NOWHERE"], "no such results store"),
        (["fleet", "{store}", "--campaign", "nope"], "no results of campaign 'nope'"),
        (["fleet", "{store}", "--threshold", "friction=-1"], "friction"),
        (["fleet", "{store}", "--inspection-interval", "0"], "--inspection-interval"),
    ],
)
def test_bad_input_is_one_line_and_writes_nothing(store, tmp_path, capsys, args, message):
    args = [a.format(store=store) for a in args] + ["--output", str(tmp_path / "out")]
    code, _, err = run_cli(args, capsys)
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists()


def test_the_rows_of_a_fleet_written_at_once_are_one_file(tmp_path):
    rows = [_row(f"B{i:03d}", f) | {"campaign": "w"} for i in range(70) for f in (1, 2)]
    store = ResultStore(tmp_path)
    (written,) = store.write("results", rows)
    assert written.parent == tmp_path / "compact" / "results" / "campaign=w" and store.loose_parts() == 0
    back = store.read("results").to_pylist()
    assert sorted((r["actuator"], r["flight"]) for r in back) == sorted((r["actuator"], r["flight"]) for r in rows)
    assert [r["flight"] for r in store.read("results", actuator="B007").to_pylist()] == [1, 2]
    # a few actuators' rows stay in their own folders
    store.write("results", rows[:4])
    assert store.loose_parts() == 2 and store.read("results").num_rows == 140


def test_each_charted_actuator_links_its_latest_diagnosis(tmp_path):
    ResultStore(tmp_path / "s").write("results", [_row("ONE", 0, k2=0.30), _row("NF", 1, verdict="does not fit")])
    from emaphm.prognostics.fleet_files import write_fleet

    report = fleet_report(tmp_path / "s", charts=True)
    write_fleet(report, tmp_path / "out")
    by = {e["actuator"]: e for e in report["actuators"]}
    page = (tmp_path / "out" / by["ONE"]["report"]).read_text()
    assert "mrad (30.7 × nominal)" in page  # the free play in physical units: B0·(1 + 99·0.30)
    assert "0.25 (exceeded)" in page  # backlash past its (placeholder) failure threshold
    nofit = (tmp_path / "out" / by["NF"]["report"]).read_text()
    assert "no faults are reported" in nofit and "k2 backlash" not in nofit
    assert json.loads((tmp_path / "out" / "fleet.json").read_text())["actuators"][0]["report"] == by["ONE"]["report"]
