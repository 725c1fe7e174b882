"""The fleet page of ``emaphm fleet STORE --output DIR`` (issue 35, item 3): one self-contained HTML
file, a row per actuator in the report's order, its trend chart folded under it; checked on
hand-made reports, by the browser check's parser without a browser, and in headless Chromium."""

from __future__ import annotations

import json
import os
import re
import shutil
import sys
from pathlib import Path

import pytest

from emaphm import fleet_page
from emaphm.fleet_page import page, write_fleet_page
from emaphm.fleet_svg import chart, number

ROOT = Path(__file__).resolve().parents[1]
FAULTS = ("friction", "backlash", "short_a", "short_b", "short_c", "eccentricity", "kp_drift")
DUE = {"unit": "hours", "rul_p05": 12.5, "rul_median": 30.0,
       "date_p05": "2027-01-03", "date_median": None}  # fmt: skip

sys.path.insert(0, str(ROOT / "scripts"))
try:
    from check_fleet_in_browser import page_problems
finally:
    sys.path.pop(0)


def _series(healthy: float = 0.0, n: int = 8, slope: float = 0.02) -> dict:
    """A fault's diagnoses over `n` flights growing by `slope` a flight, the fourth left out."""
    flights = list(range(1, n + 1))
    values = [healthy + slope * f for f in flights]
    return {"flight": flights, "value": values, "low": [None] + [v - 0.02 for v in values[1:]],
            "high": [None] + [v + 0.02 for v in values[1:]], "used": [i != 3 for i in range(n)],
            "trend_flight": [1, n + 5], "trend_value": [healthy + slope, healthy + slope * (n + 5)],
            "healthy": healthy, "threshold_value": healthy + 0.25}  # fmt: skip


def _entry(ident: str, colour: str, verdict: str = "fits", **changes: object) -> dict:
    """An actuator's entry that fits, with faults, predictions and a chart's series."""
    entry = {
        "actuator": ident, "campaign": "c1", "flight": 8, "flights": 8, "verdict": verdict, "doubts": [],
        "fit_nrmse": 0.021, "worst_fault": "backlash", "threshold_share": 0.64, "exceeded": [],
        "faults": {f: {"value": 0.16, "share": 0.64, "verdict": "present" if f == "backlash" else "absent"}
                   for f in FAULTS},
        "rul_p05": 3.2, "rul_median": 6.0, "rul_p95": 11.0, "prob_fail_before_next_inspection": 0.31,
        "most_likely_fault": "backlash", "remaining_share": 0.32, "colour": colour,
        "reason": f"{colour}: RUL p05 3.2 flights", "doubtful_left_out": 1, "due": None, "report": None,
        "_series": {"backlash": _series(), "kp_drift": _series(healthy=0.5)},
    }  # fmt: skip
    entry.update(changes)
    return entry


def _report(entries: list[dict], placeholder: bool = True) -> dict:
    counts = {c: sum(a["colour"] == c for a in entries) for c in ("red", "orange", "yellow", "green")}
    counts.update({v: sum(a["verdict"] == v for a in entries) for v in ("doubtful", "does not fit")})
    return {"store": "/data/store", "campaign": "c1", "generated": "2026-11-27T13:40:00+00:00",
            "version": "0.1.0", "inspection_interval": 10.0, "unit": "flights", "include_doubtful": False,
            "thresholds": {f: {"threshold": 0.25, "placeholder": placeholder} for f in FAULTS},
            "counts": counts, "actuators": entries}  # fmt: skip


def _fleet() -> dict:
    """A small fleet with every case: each colour, doubtful, does not fit, no series, a due date."""
    return _report([
        _entry("A-001", "red", threshold_share=1.12, exceeded=["backlash"], due=DUE, report="r/A-001.html"),
        _entry("A-002", "red", "does not fit", doubts=["fit NRMSE 9 % above 5 %"], reason="does not fit"),
        _entry("A.0_3-x", "orange", "doubtful", doubts=["fit NRMSE 3.1 % above 2.5 %", "k at a bound"]),
        _entry("A-004", "yellow", rul_p05=None, rul_median=None, rul_p95=None, _series={}),
        _entry("A-005", "green", rul_p05=float("inf"), rul_median=float("inf"), rul_p95=float("inf")),
    ])  # fmt: skip


def _folded(html: str, ident: str) -> str:
    """The actuator's row and the part folded under it."""
    start = html.index(f'<tr id="a-{ident}"')
    return html[start : html.index("</details></td></tr>", start)]


def test_the_page_is_written_atomically_and_keeps_the_order(tmp_path):
    report = _fleet()
    assert write_fleet_page(report, tmp_path) == tmp_path / "index.html"
    assert [p.name for p in tmp_path.iterdir()] == ["index.html"]  # no temporary left beside
    html = (tmp_path / "index.html").read_text(encoding="utf-8")
    assert re.findall(r'<tr id="a-([^"]+)" class="act"', html) == [a["actuator"] for a in report["actuators"]]
    assert page_problems(html) == []
    # the page keeps the order it is given, even one that is not by urgency (the check then objects)
    shuffled = dict(report, actuators=report["actuators"][::-1])
    html = page(shuffled)
    assert re.findall(r'<tr id="a-([^"]+)" class="act"', html)[0] == "A-005"
    assert any(p.startswith("rows out of urgency order: A-005 (green) before") for p in page_problems(html))


def test_the_header_legend_and_downloads(tmp_path):
    html = page(_fleet())
    assert '<span class="chip red" data-count="2">red 2</span>' in html
    assert "1 doubtful, 1 do not fit" in html and "doubtful diagnoses are left out of the trends" in html
    assert "10 flights" in html and "2026-11-27T13:40:00+00:00" in html and "/data/store" in html
    assert re.search(r'<div id="legend">.*≤ 0 %.*0–25 %.*25–50 %.*&gt; 50 %', html)
    assert '<a id="fleet-json" href="fleet.json" download>' in html and 'href="fleet.csv"' in html
    assert "placeholder: not an airworthiness limit" in html
    assert "placeholder" not in page(_report(_fleet()["actuators"], placeholder=False))
    assert "used in the trends" in page(dict(_fleet(), include_doubtful=True))


def test_the_row_shows_the_predictions():
    html = page(_fleet())
    row = _folded(html, "A-001")
    assert '<td class="fv over">112 %</td>' in row and "<td>3.2 / 6 / 11</td>" in row
    assert "<td>31 %</td>" in row  # P(fail before the next inspection)
    assert "12.5 / 30 hours<br>2027-01-03 / —" in row and '<a href="r/A-001.html">report</a>' in row
    assert "<td>— / — / —</td>" in _folded(html, "A-004")  # no prediction
    assert "beyond / beyond / beyond" in _folded(html, "A-005")  # no failure within the horizon
    assert "<svg" not in _folded(html, "A-004")  # no series, no chart
    assert (number(None), number(float("nan")), number(float("inf")), number(1234.5), number(0.0213)) == (
        "—", "—", "beyond", "1234", "0.0213")  # fmt: skip


def test_user_strings_are_escaped():
    evil = '<script>alert("x")</script>&'
    entries = [_entry("A.0_7-x", "red", "doubtful", reason=evil, doubts=[evil], report='r e/"<x>.html')]
    report = dict(_report(entries), store=evil, campaign=evil, generated=evil, version=evil)
    report["thresholds"] = {evil: {"threshold": 0.25, "placeholder": True}}
    html = page(report)
    assert "<script>alert" not in html and '"x"' not in html
    assert "&lt;script&gt;alert(&quot;x&quot;)&lt;/script&gt;&amp;" in html
    assert 'id="a-A.0_7-x"' in html and 'href="#a-A.0_7-x"' in html
    assert 'href="r%20e/%22%3Cx%3E.html"' in html
    assert page_problems(html) == []


def test_does_not_fit_shows_no_fault_values_or_chart():
    html = page(_fleet())
    part = _folded(html, "A-002")  # its entry carries faults, a worst fault and series: none is shown
    assert "fv" not in part and "<svg" not in part and "0.160" not in part and "64 %" not in part
    assert "<td>—</td><td>—</td>" in part and "No fault values are shown" in part
    assert "fit NRMSE 9 % above 5 %" in part and "<b>does not fit</b>: does not fit" in part
    # the check sees a page that shows them
    broken = html.replace("No fault values are shown", '<span class="fv">0.160</span>')
    assert page_problems(broken) == ["row A-002 does not fit but shows fault values or a chart"]


def test_a_doubtful_row_is_marked_with_its_doubts():
    part = _folded(page(_fleet()), "A.0_3-x")
    assert '<td class="v doubt" title="fit NRMSE 3.1 % above 2.5 %; k at a bound">doubtful</td>' in part
    assert '<ul class="doubts"><li>fit NRMSE 3.1 % above 2.5 %</li><li>k at a bound</li></ul>' in part
    assert "doubtful diagnoses left out of the trend: 1" in part


def test_the_chart_draws_points_whiskers_trend_and_thresholds():
    svg = chart("A-1", {"backlash": _series(), "kp_drift": _series(healthy=0.5)}, _report([])["thresholds"])
    assert svg.startswith('<svg class="trend"') and svg.endswith("</svg>")
    assert "<title>Trends of actuator A-1: fault value k of backlash, kp_drift" in svg
    assert svg.count('<path class="pt"') == 2 and svg.count('<path class="pu"') == 2  # used, left out
    assert svg.count("h0") == 2 * (7 + 2)  # 7 used dots, 1 hollow one drawn twice, per panel
    assert svg.count("V") >= 2 * 7  # whiskers: not where low/high are None
    assert svg.count('<path class="tr"') == 2 and svg.count('<path class="hl"') == 2
    assert svg.count(">failure</text>") == 3  # kp_drift fails on both sides of healthy 0.5
    assert svg.count(">flight</text>") == 2 and svg.count(">fault value k (fault units)</text>") == 2
    assert "backlash: threshold 0.25 (placeholder)" in svg
    assert chart("A-1", {"friction": {}}).count("no diagnoses") == 1  # an empty series: a panel that says so


def test_a_large_fleet_stays_small_and_says_how_many_charts_it_left_out(tmp_path):
    colours = ["red"] * 20 + ["orange"] * 30 + ["yellow"] * 50 + ["green"] * 1900
    report = _report([_entry(f"A-{i:05d}", c) for i, c in enumerate(colours)])
    path = write_fleet_page(report, tmp_path)
    # a fifth of the 10 000 actuators the page is sized for: a fifth of its 25 MB
    assert path.stat().st_size <= 25e6 / 5
    html = path.read_text(encoding="utf-8")
    assert html.count("<svg") == 1000
    assert "1000 trend charts drawn; 1000 charts left out to keep the page small: 1000 of green rows" in html
    assert html.count("Chart left out to keep the page small") == 1000
    assert page_problems(html) == []


def test_the_size_budget_stops_the_charts_urgent_ones_first(monkeypatch):
    report = _report([_entry(f"A-{i}", "red" if i < 5 else "green") for i in range(20)])
    bare = dict(report, actuators=[dict(a, _series={}) for a in report["actuators"]])
    # room for a few charts: the page's budget keeps 100 kB aside for the header
    monkeypatch.setattr(fleet_page, "PAGE_BUDGET", len(page(bare).encode("utf-8")) + 100_000 + 8000)
    html = page(report)
    drawn = re.findall(r'data-for="a-(A-\d+)"><td colspan="11"><details><summary>details and trend</summary>'
                       r"[^\n]*\n<svg", html)  # fmt: skip
    assert 0 < len(drawn) < 20 and drawn == [f"A-{i}" for i in range(len(drawn))]
    left = 20 - len(drawn)
    assert (
        f"{left} charts left out to keep the page small: 0 of green rows after the first 1000, {left} once"
        in html
    )
    assert page_problems(html) == []


def test_the_check_counts_against_fleet_json(tmp_path):
    report = _fleet()
    write_fleet_page(report, tmp_path)
    (tmp_path / "fleet.json").write_text(json.dumps({"actuators": [{}] * 6}))
    html = (tmp_path / "index.html").read_text(encoding="utf-8")
    assert page_problems(html, tmp_path) == ["5 actuator rows, fleet.json has 6"]


@pytest.mark.skipif(
    shutil.which("chromium") is None and not os.environ.get("EMAPHM_REQUIRE_BROWSER"),
    reason="no headless Chromium (apt install chromium); .ci/run installs it and requires this test",
)
def test_the_fleet_page_renders_in_a_real_headless_browser(tmp_path):
    assert shutil.which("chromium"), "EMAPHM_REQUIRE_BROWSER is set but chromium is not installed"
    sys.path.insert(0, str(ROOT / "scripts"))
    try:
        from check_fleet_in_browser import check
    finally:
        sys.path.pop(0)
    report = _fleet()
    write_fleet_page(report, tmp_path)
    entries = [{k: v for k, v in a.items() if k != "_series"} for a in report["actuators"]]
    (tmp_path / "fleet.json").write_text(json.dumps(dict(report, actuators=entries)))
    assert check(tmp_path) == []
    # a green row (and its folded part) moved before the first red one
    page_file = tmp_path / "index.html"
    html = page_file.read_text(encoding="utf-8")
    green = re.search(r'<tr id="a-A-005".*?</details></td></tr>\n', html, re.S).group(0)
    first = html.index('<tr id="a-A-001"')
    page_file.write_text(html[:first] + green + html[first:].replace(green, ""), encoding="utf-8")
    assert check(tmp_path) == ["rows out of urgency order: A-005 (green) before A-001 (red)"]
