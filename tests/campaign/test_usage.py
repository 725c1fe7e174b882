"""Usage per flight (issue 35 item 4): hours, cycles and dates in the campaign file, kept in the store
whatever the job keys, and the RUL in those units with a due date."""

from __future__ import annotations

import datetime as dt
import json

import pytest

from emaphm.campaign import ResultStore, load_campaign, run_campaign
from emaphm.campaign.store import RESULT_COLUMNS
from emaphm.campaign.usage import flight_usages, parse_usage
from emaphm.errors import InputError
from emaphm.prognostics.fleet import fleet_report
from emaphm.prognostics.rul import rul_report
from emaphm.prognostics.usage import due, rates
from tests.helpers import run_cli

SPEC = """[campaign]
name = "u"

[identify]
pop_size = 6
generations = 2
polish = false
uncertainty = "none"

[[actuator]]
id = "H"
flights = 3
start  = [0.05, 0.02, 0, 0, 0, 0, 0, 0.5]
growth = [0.01, 0.004, 0, 0, 0, 0, 0, 0]
{usage}
"""


def test_usage_per_flight_or_at_each_flight():
    rate = parse_usage({"hours": 2.5, "cycles": [1, 3, 4], "first_date": dt.date(2026, 1, 5), "days": 3}, "x")
    assert flight_usages(rate, [1, 2, 3], "x")[1] == {"hours": 5.0, "cycles": 3.0, "date": "2026-01-08"}
    assert flight_usages(rate, [0, 1, 2, 3], "x")[0] is None  # a one-off measurement has no flight
    listed = parse_usage({"dates": ["2026-02-01", dt.date(2026, 2, 9)]}, "x")
    assert flight_usages(listed, [1, 2], "x")[1]["date"] == "2026-02-09"
    with pytest.raises(InputError, match="2 values for 3 flights"):
        flight_usages(listed, [1, 2, 3], "x")


@pytest.mark.parametrize(
    "usage, message",
    [
        ({"hours": -1}, "hours must be a number > 0"),
        ({"hours": [3, 2]}, "must not decrease"),
        ({"dates": ["2026-02-03", "2026-02-01"]}, "back in time"),
        ({"first_date": "2026-01-01"}, "first_date and days"),
        ({"dates": ["2026-01-01"], "days": 2}, "not both"),
        ({"hours": 1, "minutes": 3}, "unknown key(s) minutes"),
        ({"dates": ["yesterday"]}, "not a date"),
    ],
)
def test_bad_usage_is_refused_naming_the_key(usage, message):
    with pytest.raises(InputError, match=message.replace("(", r"\(").replace(")", r"\)")):
        parse_usage(usage, "c.toml: actuator 'H'")


def test_the_rate_and_the_due_date():
    rows = [{"flight": f, "hours": 2.0 * f, "cycles": None, "date": f"2026-03-{2 * f:02d}"} for f in (1, 2, 3)]
    rate = rates(rows, 3.0)
    assert rate["hours"] == pytest.approx(2.0) and rate["cycles"] is None and rate["days"] == pytest.approx(2.0)
    assert rate["date"] == dt.date(2026, 3, 6)
    d = due({"rul_p05": 4.0, "rul_median": None}, rate, "hours")
    assert d == {"unit": "hours", "rul_p05": 8.0, "rul_median": None, "date_p05": "2026-03-14", "date_median": None}


def test_usage_reaches_the_store_for_flights_already_done_and_the_rul_in_hours(tmp_path):
    spec = tmp_path / "c.toml"
    spec.write_text(SPEC.format(usage=""))
    run_campaign(spec, tmp_path / "out", scheduler="serial")
    assert ResultStore(tmp_path / "out").read_usage().num_rows == 0
    keys = {j.key for j in load_campaign(spec).jobs()}
    spec.write_text(SPEC.format(usage='usage = { hours = 1.5, first_date = 2026-04-01, days = 2 }'))
    assert {j.key for j in load_campaign(spec).jobs()} == keys  # usage does not change a diagnosis
    summary = run_campaign(spec, tmp_path / "out", scheduler="serial")
    assert summary.submitted == 0
    usage = ResultStore(tmp_path / "out").read_usage().to_pylist()
    assert [(u["flight"], u["hours"], u["date"]) for u in usage] == [
        (1, 1.5, "2026-04-01"), (2, 3.0, "2026-04-03"), (3, 4.5, "2026-04-05"),
    ]  # fmt: skip
    with pytest.raises(InputError, match="no cycles recorded"):
        fleet_report(tmp_path / "out", unit="cycles")


def _rows(actuator, flights):
    out = []
    for f in flights:
        row = {c: None for c in RESULT_COLUMNS}
        row.update(job_key=f"{actuator}-{f}", campaign="u", actuator=actuator, flight=f, seed=1, identify_seed=1,
                   verdict="fits", finished=f"2026-01-01T00:00:{f:02d}", k1=0.05 + 0.02 * f, std_k1=0.005,
                   **{f"k{i}": 0.0 for i in range(2, 8)}, k8=0.5, **{f"std_k{i}": 0.005 for i in range(2, 9)},
                   fault_verdicts=json.dumps({"friction": "present"}))  # fmt: skip
        out.append(row)
    return out


def test_an_interval_in_hours_is_that_many_flights_at_the_actuators_rate(tmp_path, capsys):
    store = ResultStore(tmp_path)
    store.write("results", _rows("H", range(1, 9)))
    store.write_usage("u", [{"campaign": "u", "actuator": "H", "flight": f, "hours": 2.0 * f,
                             "date": f"2026-05-{f:02d}"} for f in range(1, 9)])  # fmt: skip
    in_flights = rul_report(tmp_path, "H", inspection_interval=5.0, thresholds={"friction": 0.45})
    in_hours = rul_report(tmp_path, "H", inspection_interval=10.0, unit="hours", thresholds={"friction": 0.45})
    assert in_hours["first_failure"] == in_flights["first_failure"]  # 10 h = 5 flights at 2 h a flight
    first = in_flights["first_failure"]
    assert in_hours["due"]["rul_median"] == pytest.approx(2.0 * first["rul_median"], abs=2e-3)
    expected = dt.date(2026, 5, 8) + dt.timedelta(days=round(first["rul_p05"]))
    assert in_hours["due"]["date_p05"] == expected.isoformat()
    by_hours = fleet_report(tmp_path, inspection_interval=10.0, unit="hours", thresholds={"friction": 0.45})
    by_flights = fleet_report(tmp_path, inspection_interval=5.0, thresholds={"friction": 0.45})
    assert by_hours["actuators"][0]["remaining_share"] == by_flights["actuators"][0]["remaining_share"]
    code, out, _ = run_cli(["rul", str(tmp_path), "--actuator", "H", "--unit", "hours"], capsys)
    assert code == 0 and "due:" in out and "hours at 5 %" in out


def test_a_one_off_measurement_needs_no_usage_but_a_history_does(tmp_path):
    store = ResultStore(tmp_path)
    one_off = _rows("ONE", [0])
    store.write("results", one_off + _rows("H", range(1, 4)))
    store.write_usage("u", [{"campaign": "u", "actuator": "H", "flight": f, "hours": 1.0 * f} for f in range(1, 4)])
    by = {e["actuator"]: e for e in fleet_report(tmp_path, unit="hours")["actuators"]}
    assert by["ONE"]["due"] is None and by["H"]["due"]["unit"] == "hours"
    store.write("results", _rows("H2", range(1, 3)))
    with pytest.raises(InputError, match="'H2' has no hours recorded"):
        fleet_report(tmp_path, unit="hours")
