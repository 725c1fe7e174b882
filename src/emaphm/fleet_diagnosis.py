"""One actuator's latest diagnosis as a page of the fleet (``emaphm fleet --output DIR``, issue 35).

A campaign's store keeps each diagnosis's faults, intervals, verdicts, doubts and warnings, not
its currents: this page is the diagnosis report without its figures (`report_page` is the whole
one, from ``emaphm identify --report``). The verdict first, each reason of a "doubtful" one, the
faults in physical units with their 90 % intervals and the detection and failure thresholds
(`tables.physical_rows`; no fault values for "does not fit"), then the recording, the settings and
the store row it came from. Written for the `FIRST_PAGES` most urgent actuators that have a chart on
the fleet page and every red one, into ``DIR/actuators/<campaign>--<id>.html``, linked from its row
(``report``).
"""

from __future__ import annotations

import html
import json
import shutil
import tempfile
from pathlib import Path
from typing import Any

from .atomic import replace_folder

__all__ = ["FIRST_PAGES", "diagnosis_page", "write_diagnosis_pages"]

FIRST_PAGES = 1000  # the most urgent actuators with a page (and every red one beyond)

_STYLE = (
    "body{font-family:system-ui,sans-serif;margin:1.5em;max-width:70em;color:#222}"
    "table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #ccc;padding:.25em .5em;text-align:left}"
    ".verdict{font-size:1.6em;font-weight:bold;padding:.3em .6em;display:inline-block;border-radius:.3em}"
    ".fits{background:#e3f3e3}.doubtful{background:#fff3cd}.nofit{background:#f8d7da}.note{color:#555}"
)


def _data(row: dict[str, Any]) -> dict[str, Any]:
    """An identification's JSON (the fields `tables.physical_rows` reads) from a store row."""

    def loads(v: Any) -> Any:
        return json.loads(v) if v else None

    k = [row.get(f"k{i}") for i in range(1, 9)]
    lo, hi = ([row.get(f"{b}_k{i}") for i in range(1, 9)] for b in ("ci90_low", "ci90_high"))
    return {
        "estimate": k, "verdict": row.get("verdict"), "fault_verdicts": loads(row.get("fault_verdicts")),
        "detected": (row.get("detected") or "").split(","), "uq_flags": loads(row.get("uq_flags")),
        "ci90_low": lo if None not in lo else None, "ci90_high": hi if None not in hi else None,
    }  # fmt: skip


def diagnosis_page(entry: dict[str, Any], row: dict[str, Any], params: Any = None,
                   failure: dict[str, float] | None = None, nominal: bool | None = None) -> str:  # fmt: skip
    """The page of `entry` (`fleet.fleet_report`) from its latest diagnosis `row` (a store row);
    faults in the physical units of `params` (default: the nominal actuator, which the page then
    says: `nominal`)."""
    from .tables import physical_rows

    e = html.escape
    verdict = row.get("verdict") or "-"
    cls = {"fits": "fits", "doubtful": "doubtful"}.get(verdict, "nofit")
    doubts = json.loads(row.get("doubts") or "[]")
    warnings = [w for w in json.loads(row.get("warnings") or "[]") if w not in doubts]
    parts = [
        f"<!doctype html><html><head><meta charset='utf-8'><title>{e(entry['actuator'])}: latest diagnosis</title>",
        f"<style>{_STYLE}</style></head><body><p><a href='../index.html#a-{e(entry['actuator'])}'>← the fleet</a></p>",
        f"<h1>Actuator {e(entry['actuator'])}: flight {row.get('flight')}</h1>",
        f"<p class='verdict {cls}'>{e(verdict)}</p>",
        f"<p>colour <b>{e(entry['colour'])}</b>: {e(entry['reason'])}</p>",
    ]  # fmt: skip
    if doubts:
        parts.append("<h2>Why doubtful</h2><ul>" + "".join(f"<li>{e(d)}</li>" for d in doubts) + "</ul>")
    if verdict == "does not fit":
        parts.append("<p>The monitor cannot explain this recording: no faults are reported.</p>")
    elif row.get("k1") is not None:
        from .identification.detection import load_thresholds

        detection = load_thresholds()["thresholds"]
        columns, rows = physical_rows(_data(row), params, detection=detection, failure=failure)
        head = "".join(f"<th>{e(c)}</th>" for c in columns)
        body = "".join("<tr>" + "".join(f"<td>{e(c)}</td>" for c in r) + "</tr>" for r in rows)
        nominal = params is None if nominal is None else nominal
        unit = " (physical units of the nominal actuator: pass --params for yours)" if nominal else ""
        parts.append(f"<h2>Faults{e(unit)}</h2><table><tr>{head}</tr>{body}</table>")
    if warnings:
        parts.append("<h2>Warnings</h2><ul>" + "".join(f"<li>{e(w)}</li>" for w in warnings) + "</ul>")
    facts = {
        "fit NRMSE": None if row.get("fit_nrmse") is None else f"{100 * row['fit_nrmse']:.2f} %",
        "recording": row.get("reference") or "the twin (a simulated measurement)",
        "recording SHA-256": row.get("reference_sha256"), "campaign": row.get("campaign"),
        "seed": row.get("identify_seed"), "finished": row.get("finished"), "emaphm": row.get("version"),
        "job key": row.get("job_key"), "settings": row.get("settings"),
    }  # fmt: skip
    rows_html = "".join(f"<tr><th>{e(k)}</th><td>{e(str(v))}</td></tr>" for k, v in facts.items() if v is not None)
    parts.append(f"<h2>Where it comes from</h2><table>{rows_html}</table></body></html>")
    return "\n".join(parts)


def write_diagnosis_pages(report: dict[str, Any], folder: Path, params: Any = None,
                          failure: dict[str, float] | None = None) -> int:  # fmt: skip
    """Write ``folder/actuators/<campaign>--<id>.html`` for each entry of `report` that keeps its
    latest row (``_latest``) and set its ``report`` link; how many were written. The pages are
    written into a new folder that then replaces ``actuators/`` whole."""
    from .params import EmaParams

    if failure is None:  # the thresholds the fleet was ranked by (placeholders where none was given)
        failure = {n: t["threshold"] for n, t in (report.get("thresholds") or {}).items()}
    entries = [e for i, e in enumerate(report["actuators"])  # the most urgent, and every red one
               if e.get("_latest") is not None and (i < FIRST_PAGES or e.get("colour") == "red")]  # fmt: skip
    target = folder / "actuators"
    tmp = Path(tempfile.mkdtemp(dir=folder, prefix=".actuators-"))
    try:
        units = params if params is not None else EmaParams()
        for entry in entries:
            name = f"{entry['campaign']}--{entry['actuator']}.html"
            page = diagnosis_page(entry, entry["_latest"], units, failure, nominal=params is None)
            (tmp / name).write_text(page, encoding="utf-8")
            entry["report"] = f"actuators/{name}"
        replace_folder(tmp, target)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return len(entries)
