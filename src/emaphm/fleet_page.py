"""The fleet page of ``emaphm fleet STORE --output DIR`` (issue 35, item 3): one self-contained HTML
file that lists a fleet's actuators, most urgent first, for the maintenance planner.

Top to bottom: the header (the store, the campaign, when, the inspection interval, the count of each
colour as chips, the doubtful ones, the failure thresholds with a note when they are placeholders),
the colour code, the downloads (``fleet.json`` and ``fleet.csv``, which the caller writes beside the
page), then one table row per actuator in the report's order, its details and trend chart
(`fleet_svg`) folded in a ``<details>`` under it. An actuator whose latest diagnosis does not fit
shows its verdict and reason: no fault values, no chart. It looks like the diagnosis page
(`report_page`): one file, its own CSS, no script library, nothing fetched.

Size: charts are drawn for the first `FIRST_CHARTS` rows and for every row that is not green, while
the page stays under `PAGE_BUDGET` bytes; the page says how many were left out.
"""

from __future__ import annotations

import html
from pathlib import Path
from typing import Any
from urllib.parse import quote

from .atomic import atomic_path
from .fleet_svg import CHART_CSS, chart
from .fleet_svg import finite as _finite
from .fleet_svg import number as _num

__all__ = ["FIRST_CHARTS", "PAGE_BUDGET", "page", "write_fleet_page"]

e = html.escape

FIRST_CHARTS = 1000  # rows that get a chart whatever their colour (later ones only when not green)
PAGE_BUDGET = 22_000_000  # bytes: no more charts once the page would grow past this (the goal is 25 MB)
COLOURS = ("red", "orange", "yellow", "green")  # most urgent first
NOFIT = "does not fit"
DASH = "—"
COLUMNS = ("colour", "actuator", "verdict", "worst fault", "threshold share",
           "RUL p05 / median / p95 [flights]", "P(fail before next inspection)", "due", "flights stored",
           "reason", "diagnosis")  # fmt: skip

_STYLE = """
body{font-family:system-ui,sans-serif;max-width:1400px;margin:2em auto;padding:0 1em;color:#222}
h1{font-size:1.3em} h2{font-size:1.1em;margin-top:1.6em;border-bottom:1px solid #ddd}
table{border-collapse:collapse;font-size:.9em} th{background:#f3f3f3} #fleet>thead th{position:sticky;top:0}
td,th{border:1px solid #ccc;padding:.25em .6em;text-align:left}
tr.act>td:nth-child(n+5):nth-child(-n+9),.faults td{text-align:right;font-variant-numeric:tabular-nums}
tr.act>td:nth-child(n+5):nth-child(-n+9){white-space:nowrap}
.chip{display:inline-block;padding:.05em .6em;border-radius:1em;font-weight:bold;color:#fff}
.chip.red{background:#c62828} .chip.orange{background:#e65100} .chip.yellow{background:#f9d71c;color:#333}
.chip.green{background:#2e7d32} .v.fits{color:#1d5e1d} .v.doubt{background:#fff0cc;color:#6b4a00}
.v.doubt,.v.nofit{font-weight:bold} .chip,td.v{white-space:nowrap}
.v.doubt::after{content:" \\26A0"} .v.nofit{background:#fbe3e3;color:#8a1c1c}
.over,.present{font-weight:bold;color:#8a1c1c}
.warn{background:#fff6dd;padding:.5em 1em;border-left:4px solid #e0b000}
tr.more>td{border-top:none;padding:0 .6em .15em 2em;font-size:.95em} summary{cursor:pointer;color:#555}
.note{color:#555;font-size:.9em} #legend{margin:.6em 0}
"""

# the page's own check, read by scripts/check_fleet_in_browser.py: the charts parsed as SVG with a
# title, and the width of the first one once shown (its <details> opened, then closed again)
_COUNT_CHARTS = (
    "window.addEventListener('load',function(){var s=document.querySelectorAll('svg.trend'),n=0,w=0;"
    "for(var i=0;i<s.length;i++){if(s[i] instanceof SVGSVGElement&&s[i].querySelector('title'))n++}"
    "if(s.length){var d=s[0].closest('details'),o=d.open;d.open=true;w=s[0].getBoundingClientRect().width;"
    "d.open=o}document.body.setAttribute('data-charts-parsed',n+'/'+s.length);"
    "document.body.setAttribute('data-first-chart-width',Math.round(w))});"
)


def write_fleet_page(report: dict[str, Any], folder: Path) -> Path:
    """Write the fleet page ``folder/index.html`` (atomically: a temporary file beside, then a rename).

    Parameters
    ----------
    report : dict
        the fleet report: ``store``, ``campaign``, ``generated``, ``version``, ``inspection_interval``
        and its ``unit``, ``include_doubtful``, ``thresholds``, ``counts`` and ``actuators`` (the
        entries, most urgent first: the page keeps their order)
    folder : Path
        an existing folder (``fleet.json`` and ``fleet.csv`` are written there by the caller)

    Returns
    -------
    Path
        the page's path
    """
    target = Path(folder) / "index.html"
    text = page(report)
    with atomic_path(target) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return target


def page(report: dict[str, Any]) -> str:
    """The fleet page's HTML for `report` (see `write_fleet_page`)."""
    entries = list(report.get("actuators") or [])
    rows = [_row(a) for a in entries]
    folded = [_details(a) for a in entries]
    size = sum(
        len(r.encode("utf-8")) + len(f.encode("utf-8")) + 200 for r, f in zip(rows, folded, strict=True)
    )
    charts, left_out = _charts(entries, report.get("thresholds") or {}, PAGE_BUDGET - size - 100_000)
    drawn = sum(1 for c in charts if c)
    tally = ", ".join(f"{int((report.get('counts') or {}).get(c) or 0)} {c}" for c in COLOURS)
    parts = [
        '<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">',
        f"<title>emaphm fleet: {e(tally)}</title>",
        f"<style>{_STYLE}{CHART_CSS}</style><script>{_COUNT_CHARTS}</script></head><body>",
        _header(report, len(entries), drawn, left_out),
        f'<table id="fleet" data-actuators="{len(entries)}" data-charts="{drawn}" '
        f'data-charts-left-out="{sum(left_out)}">'
        "<thead><tr>" + "".join(f'<th scope="col">{e(c)}</th>' for c in COLUMNS) + "</tr></thead><tbody>",
    ]
    for a, row, fold, svg in zip(entries, rows, folded, charts, strict=True):
        what = "details and trend" if svg else "details"
        parts += [
            row,
            f'<tr class="more" data-for="a-{e(str(a.get("actuator", "")))}"><td colspan="{len(COLUMNS)}">'
            f"<details><summary>{what}</summary>{fold}",
            svg or ("" if svg is None else '<p class="note">Chart left out to keep the page small.</p>'),
            "</details></td></tr>",
        ]
    parts.append("</tbody></table></body></html>\n")
    return "\n".join(parts)


def _charts(
    entries: list[dict[str, Any]], thresholds: dict[str, Any], budget: int
) -> tuple[list[str | None], tuple[int, int]]:
    """Each entry's chart: the SVG, "" when left out (size), None when it has none (no series, or
    does not fit); and how many were left out, being green after the first `FIRST_CHARTS` rows and
    for want of room in `budget` bytes."""
    out: list[str | None] = []
    spent, green, over, full = 0, 0, 0, False
    for i, a in enumerate(entries):
        series = a.get("_series")
        if a.get("verdict") == NOFIT or series == {}:
            out.append(None)
            continue
        if series is None or (i >= FIRST_CHARTS and a.get("colour") == "green"):  # None: not made (a green one)
            out.append("")
            green += 1
            continue
        svg = "" if full else chart(str(a.get("actuator", "")), series, thresholds)
        if not svg or spent + len(svg) > budget:
            svg, full, over = "", True, over + 1
        spent += len(svg)
        out.append(svg)
    return out, (green, over)


def _header(report: dict[str, Any], n: int, drawn: int, left_out: tuple[int, int]) -> str:
    """The title, what the page is of, the counts, the thresholds, the colour code and the downloads."""
    counts = report.get("counts") or {}
    chips = " ".join(
        f'<span class="chip {c}" data-count="{int(counts.get(c) or 0)}">{c} {int(counts.get(c) or 0)}</span>'
        for c in COLOURS
    )
    doubtful = f"{int(counts.get('doubtful') or 0)} doubtful, {int(counts.get(NOFIT) or 0)} do not fit"
    use = "used in" if report.get("include_doubtful") else "left out of"
    interval = report.get("inspection_interval")
    title = (
        f"campaign {report['campaign']}" if report.get("campaign") else Path(str(report.get("store"))).name
    )
    pairs = [
        ("store", e(str(report.get("store", "")))),
        ("campaign", e(str(report.get("campaign") or "all campaigns of the store"))),
        ("generated", e(str(report.get("generated", "")))),
        ("emaphm", e(str(report.get("version", "")))),
        ("inspection interval", e(f"{_num(interval)} {report.get('unit', '')}")),
        (f"actuators ({n})", chips),
        ("latest diagnoses", e(f"{doubtful}; doubtful diagnoses are {use} the trends")),
    ]
    charts = f"{drawn} trend charts drawn"
    if sum(left_out):
        charts += (f"; {sum(left_out)} charts left out to keep the page small: {left_out[0]} of green "
                   f"rows after the first {FIRST_CHARTS}, {left_out[1]} once the page reached "
                   f"{PAGE_BUDGET / 1e6:g} MB")  # fmt: skip
    return "".join([
        f"<h1>emaphm fleet: {e(title)}</h1>",
        "<table>" + "".join(f"<tr><th>{k}</th><td>{v}</td></tr>" for k, v in pairs) + "</table>",
        _thresholds(report.get("thresholds") or {}),
        _LEGEND,
        f'<p class="note" id="charts-note">{e(charts)}. {_READING}</p>',
        '<p class="downloads">Download: <a id="fleet-json" href="fleet.json" download>fleet.json</a> · '
        '<a id="fleet-csv" href="fleet.csv" download>fleet.csv</a> (beside this page).</p>',
        "<h2>Actuators, most urgent first</h2>",
    ])  # fmt: skip


_LEGEND = (
    '<div id="legend"><b>Colour code</b>, by the share of the inspection interval remaining before a '
    'predicted failure: <span class="chip red">red</span> ≤ 0 % (or a fault at or above its failure '
    'threshold) · <span class="chip orange">orange</span> 0–25 % · '
    '<span class="chip yellow">yellow</span> 25–50 % · <span class="chip green">green</span> &gt; 50 %.</div>'
)
_READING = (
    "A row's details hold its chart: each fault's value k against the flight, filled dots the diagnoses "
    "used in the trend with their 90 % intervals, hollow grey dots those it leaves out (doubtful, not "
    "fitting, or before the fault was tracked), the orange line the fitted trend, green dotted the "
    "healthy level, red dashed the failure threshold."
)


def _thresholds(thresholds: dict[str, Any]) -> str:
    """The failure thresholds in one small table, and the note when some are placeholders."""
    if not thresholds:
        return ""
    marked = [name for name, t in thresholds.items() if (t or {}).get("placeholder")]
    cells = "".join(
        f"<td>{e(name)} {_num((t or {}).get('threshold'))}{' *' if name in marked else ''}</td>"
        for name, t in thresholds.items()
    )
    out = f"<table><tr><th>failure thresholds (distance from healthy, fault units)</th>{cells}</tr></table>"
    if marked:
        out += (f'<p class="warn" id="placeholder">* placeholder: not an airworthiness limit '
                f"({e(', '.join(marked))}).</p>")  # fmt: skip
    return out


def _row(a: dict[str, Any]) -> str:
    """One actuator's row: the colour (a chip with its name), the verdict (the doubts as its tooltip),
    the worst fault, the predictions, the reason and a link to its diagnosis page."""
    ident, colour, verdict = (e(str(a.get(k, ""))) for k in ("actuator", "colour", "verdict"))
    nofit = a.get("verdict") == NOFIT
    kind = {"doubtful": "doubt", NOFIT: "nofit"}.get(str(a.get("verdict")), "fits")
    doubts = "; ".join(str(d) for d in a.get("doubts") or [])
    share = a.get("threshold_share") if not nofit and _finite(a.get("threshold_share")) else None
    link = a.get("report")
    cells = [
        f'<td><span class="chip {colour}">{colour}</span></td><td><a href="#a-{ident}">{ident}</a></td>',
        f'<td class="v {kind}"' + (f' title="{e(doubts)}"' if doubts else "") + f">{verdict}</td>",
        f"<td>{DASH if nofit or not a.get('worst_fault') else e(str(a['worst_fault']))}</td>",
        f"<td>{DASH}</td>"
        if share is None
        else f'<td class="fv{" over" if share >= 1 else ""}">{_percent(share)}</td>',
        f"<td>{' / '.join(_num(a.get(k)) for k in ('rul_p05', 'rul_median', 'rul_p95'))}</td>",
        f"<td>{_percent(a.get('prob_fail_before_next_inspection'))}</td><td>{_due(a.get('due'))}</td>",
        f"<td>{e(str(a.get('flights', DASH)))}</td><td>{e(str(a.get('reason') or ''))}</td>",
        f'<td><a href="{e(quote(str(link), safe="/:._-~#"))}">report</a></td>' if link else "<td></td>",
    ]
    head = f'<tr id="a-{ident}" class="act" data-colour="{colour}" data-verdict="{verdict}">'
    return head + "".join(cells) + "</tr>"


def _details(a: dict[str, Any]) -> str:
    """What a row's ``<details>`` holds besides its chart: the verdict with its reason and doubts (for
    one that is doubtful or does not fit), the predictions in words and, unless it does not fit, the
    faults."""
    nofit = a.get("verdict") == NOFIT
    out = []
    if a.get("verdict") != "fits":
        out.append(f"<p><b>{e(str(a.get('verdict', '')))}</b>: {e(str(a.get('reason') or ''))}</p>")
    if a.get("doubts"):
        out.append('<ul class="doubts">' + "".join(f"<li>{e(str(d))}</li>" for d in a["doubts"]) + "</ul>")
    facts = [f"last flight {e(str(a.get('flight', DASH)))}"]
    if a.get("sized_at_flight") not in (None, a.get("flight")) and not nofit:
        facts.append(f"faults as of flight {e(str(a['sized_at_flight']))} (its latest sized diagnosis)")
    if a.get("rul_p05") is None and a.get("rul_status") not in (None, "tracked"):
        facts.append(f"no RUL: {e(str(a['rul_status']))}")
    if _finite(a.get("remaining_share")):
        facts.append(f"{_percent(a['remaining_share'])} of the inspection interval remaining")
    if a.get("most_likely_fault") and not nofit:
        facts.append(f"most likely to fail: {e(str(a['most_likely_fault']))}")
    if a.get("doubtful_left_out"):
        facts.append(f"doubtful diagnoses left out of the trend: {int(a['doubtful_left_out'])}")
    out.append(f"<p>{'; '.join(facts)}.</p>")
    if nofit:
        out.append('<p class="nofaults">No fault values are shown: the model does not explain the latest '
                   "recording, so its search's end point is not a diagnosis.</p>")  # fmt: skip
    elif a.get("faults"):
        faults = {str(name): f or {} for name, f in a["faults"].items()}
        verdicts = [str(f.get("verdict") or DASH) for f in faults.values()]
        out.append(
            '<table class="faults"><tr><th>fault</th>' + "".join(f"<td>{e(n)}</td>" for n in faults)
            + '</tr><tr class="fv"><th>value k</th>' + "".join(f"<td>{_num(f.get('value'), '.3f')}</td>"
                                                             for f in faults.values())
            + '</tr><tr class="fv"><th>share of its threshold</th>'
            + "".join(f"<td>{_percent(f.get('share'))}</td>" for f in faults.values())
            + "</tr><tr><th>verdict</th>"
            + "".join(f'<td class="present">{v}</td>' if v == "present" else f"<td>{e(v)}</td>"
                      for v in verdicts)
            + "</tr></table>"
        )  # fmt: skip
    return "".join(out)


def _due(due: dict[str, Any] | None) -> str:
    """When the actuator is due, in the inspection interval's unit (and as dates when known)."""
    if not due:
        return DASH
    text = f"{_num(due.get('rul_p05'))} / {_num(due.get('rul_median'))} {due.get('unit', '')}"
    dates = [due.get(k) for k in ("date_p05", "date_median")]
    return e(text) + (f"<br>{e(' / '.join(str(d or DASH) for d in dates))}" if any(dates) else "")


def _percent(v: Any) -> str:
    return f"{_num(100 * v, '.0f')} %" if _finite(v) else DASH
