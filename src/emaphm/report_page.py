"""The page of a diagnosis report (`report.write_report`): one self-contained HTML file a planner reads.

Top to bottom: the verdict, big (with the reasons of a doubtful one right under it); the actuator's
id, the baseline and the recording; the faults in physical units with their thresholds and the
faults figure (a result that does not fit reports none: no table, no figure, a sentence); the
warnings; the fit and its figures; a short table of the input's provenance and the key settings;
the result's JSON as a download (a ``data:`` link, so the page stays one file).
"""

from __future__ import annotations

import base64
import datetime
import html
import json
from typing import Any

from .identification.settings import budget_text

__all__ = ["fit_model", "page"]

e = html.escape

_STYLE = """
body{font-family:system-ui,sans-serif;max-width:1000px;margin:2em auto;padding:0 1em;color:#222}
h1{font-size:1.3em} h2{font-size:1.1em;margin-top:1.6em;border-bottom:1px solid #ddd}
table{border-collapse:collapse;font-size:.9em} td,th{border:1px solid #ccc;padding:.25em .6em;text-align:left}
td.num{text-align:right;font-variant-numeric:tabular-nums} th{background:#f3f3f3}
.verdict{display:block;padding:.8em 1.2em;border-radius:6px;border-left:8px solid}
.verdict .word{font-size:2.2em;font-weight:bold;margin:0 0 .2em} .verdict p{margin:.3em 0;font-size:1.05em}
.fits{background:#e3f4e3;color:#1d5e1d} .nofit{background:#fbe3e3;color:#8a1c1c} .doubt{background:#fff0cc;color:#6b4a00}
.present,.exceeded{font-weight:bold;color:#8a1c1c} .warn{background:#fff6dd;padding:.5em 1em;border-left:4px solid #e0b000}
.small{font-size:.8em} img{max-width:100%;border:1px solid #eee} .note{color:#555;font-size:.9em}
"""

_COUNT_IMAGES = (
    "window.addEventListener('load',function(){var i=Array.prototype.slice.call(document.images);"
    "document.body.setAttribute('data-images-loaded',"
    "i.filter(function(x){return x.complete&&x.naturalWidth>0}).length+'/'+i.length)});"
)

_CAPTIONS = {
    "fit.png": "Measured current (filtered) and the {model} at the identified faults, with the residual",
    "faults.png": "The faults as distance from healthy, with their 90 % intervals and thresholds",
    "convergence.png": "Best fitness per generation (global search, then polish)",
}


def page(data: dict[str, Any], figures: dict[str, bytes], view: dict[str, Any]) -> str:
    """The report's HTML: `data` the result's JSON, `figures` file name -> PNG, `view` the actuator
    (``params``), the ``detection`` and ``failure`` thresholds and the input's ``provenance``."""
    nofit = data["verdict"] == "does not fit"
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f"<title>emaphm diagnosis: {e(data['verdict'])}</title>",
        f"<style>{_STYLE}</style><script>{_COUNT_IMAGES}</script></head><body>",
        f"<h1>emaphm diagnosis{e(_title_id(data))}</h1>",
        _verdict(data),
        _pairs(_identity(data, view["provenance"])),
        "<h2>Faults</h2>",
    ]
    if nofit:
        parts.append(
            '<p class="nofaults">No faults are reported: the model does not explain this recording, so '
            "the values its search ended at are not a diagnosis (they are in the JSON below, for an "
            "engineer looking into why).</p>"
        )
    else:
        parts += _faults(data, view, figures)
    others = [w for w in data["warnings"] if w not in (data.get("doubts") or [])]
    if others:
        parts.append('<h2>Warnings</h2><div class="warn"><ul>')
        parts += [f"<li>{e(w)}</li>" for w in others]
        parts.append("</ul></div>")
    parts += ["<h2>Fit</h2>", _pairs(_numbers(data))]
    parts += [
        _figure(name, figures[name], data) for name in ("fit.png", "convergence.png") if name in figures
    ]
    blob = json.dumps(data, indent=2, default=str).encode("utf-8")
    parts += [
        "<h2>Input and settings</h2>",
        "<p>The input:</p>",
        _pairs(_provenance(view["provenance"])),
        "<p>The key settings (every one is in the JSON):</p>",
        _pairs(_settings(data, view)),
        f'<p>Everything (every setting, the stage records, the intervals): <a id="result-json" download="result.json" '
        f'href="data:application/json;base64,{base64.b64encode(blob).decode("ascii")}">result.json</a> '
        f"({len(blob) / 1024:.0f} kB).</p>",
        "</body></html>",
    ]
    return "\n".join(parts) + "\n"


def _verdict(data: dict[str, Any]) -> str:
    """The verdict block: the word, big, and what it means; a doubtful one's reasons right under it."""
    detected = ", ".join(data["detected"]) or "none (healthy)"
    nrmse = data["fit_nrmse"]
    fit = "-" if nrmse is None else f"{100 * nrmse:.1f} %"
    if data["verdict"] == "fits":
        return (f'<div class="verdict fits"><p class="word">fits</p>'
                f"<p>Faults present: {e(detected)}.</p></div>")  # fmt: skip
    if data["verdict"] == "doubtful":
        reasons = "".join(f"<li>{e(d)}</li>" for d in data.get("doubts") or [])
        return (
            f'<div class="verdict doubt"><p class="word">doubtful</p><p>Faults found: {e(detected)}; not a sure '
            f'diagnosis, because:</p><ul class="doubts">{reasons}</ul></div>'
        )
    from .identification.limits import FIT_NRMSE_LIMIT

    return (
        f'<div class="verdict nofit"><p class="word">does not fit</p><p>The model does not explain this '
        f"recording (fit NRMSE {e(fit)}; above {100 * FIT_NRMSE_LIMIT:g} % no diagnosis is made): no faults "
        "are reported.</p></div>"
    )


def _actuator_id(data: dict[str, Any]) -> str:
    given = data["settings"].get("actuator_id")
    return str(given) if given not in (None, "") else "not given (emaphm identify --actuator-id)"


def _title_id(data: dict[str, Any]) -> str:
    given = data["settings"].get("actuator_id")
    return f" of actuator {given}" if given not in (None, "") else ""


def _identity(data: dict[str, Any], provenance: dict[str, Any]) -> list[tuple[str, str]]:
    """Which actuator, against which baseline, from which recording, when."""
    baseline = data["settings"].get("baseline")
    if isinstance(baseline, dict):
        baseline = baseline.get("path") or baseline.get("name") or baseline.get("source")
    written = datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC")
    return [
        ("actuator", _actuator_id(data)),
        ("baseline", str(baseline) if baseline else "none (the actuator file's nameplate)"),
        ("recording", str(provenance.get("reference") or data["settings"].get("reference", "-"))),
        ("report written", written),
    ]


def _faults(data: dict[str, Any], view: dict[str, Any], figures: dict[str, bytes]) -> list[str]:
    """The faults of a result that fits (or is doubtful): in physical units with their thresholds,
    the figure, then the fault vector as the CLI prints it."""
    from .tables import fault_rows, physical_rows

    columns, rows = physical_rows(
        data, view["params"], detection=view["detection"]["thresholds"], failure=view["failure"]
    )
    parts = [_table(columns, rows, "physical")]
    source = view["detection"]["source"]
    parts.append(
        f'<p class="note">Distances from healthy in fault units (k − 0 for k1..k6, k8 − 0.5 for the gain). '
        f"Detection thresholds: {e(source)}; failure thresholds: "
        f"{'the actuator file' if view['failure'] else 'none given (an actuator file with [thresholds])'}."
        f"{e(_actuator_note(data, view['params']))}</p>"
    )
    if "faults.png" in figures:
        parts.append(_figure("faults.png", figures["faults.png"], data))
    columns, rows = fault_rows(data)
    parts += ["<h2>The fault vector k1..k8</h2>", _table(columns, rows, "vector small")]
    return parts


def _actuator_note(data: dict[str, Any], params: Any) -> str:
    """A warning when the physical units come from another actuator than the result's."""
    from .calibration import params_hash

    recorded = (data["settings"].get("params") or {}).get("params_hash")
    if recorded is None or recorded == params_hash(params):
        return ""
    return (
        f" The physical units are of another actuator ({params_hash(params)}) than the result's ({recorded})."
    )


def _table(columns: list[str], rows: list[list[str]], cls: str) -> str:
    out = [f'<table class="{cls}"><tr>' + "".join(f"<th>{e(c)}</th>" for c in columns) + "</tr>"]
    for row in rows:
        cells = []
        for cell in row:
            kind = "present" if cell == "present" else "exceeded" if "(exceeded)" in cell else ""
            kind = kind or ("num" if _is_number(cell) else "")
            cells.append(f'<td class="{kind}">{e(cell)}</td>' if kind else f"<td>{e(cell)}</td>")
        out.append("<tr>" + "".join(cells) + "</tr>")
    return "".join(out) + "</table>"


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _pairs(rows: list[tuple[str, str]]) -> str:
    return "<table>" + "".join(f"<tr><th>{e(k)}</th><td>{e(v)}</td></tr>" for k, v in rows) + "</table>"


def _figure(name: str, blob: bytes, data: dict[str, Any]) -> str:
    caption = _CAPTIONS[name].format(model=fit_model(data))
    if data["verdict"] == "does not fit":  # no faults are reported: the search's end point is not one
        caption = caption.replace("the identified faults", "the search's end point")
    encoded = base64.b64encode(blob).decode("ascii")
    return (
        f'<figure><img alt="{e(caption)}" src="data:image/png;base64,{encoded}">'
        f"<figcaption>{e(caption)} ({e(name)})</figcaption></figure>"
    )


def _numbers(data: dict[str, Any]) -> list[tuple[str, str]]:
    limit = data["settings"].get("doubtful_above") or {}
    return [
        (
            "fit NRMSE",
            "-" if data["fit_nrmse"] is None else f"{100 * data['fit_nrmse']:.2f} % of the filtered current",
        ),
        ("doubtful above", f"{100 * limit['nrmse']:.2f} % ({limit['source']})" if limit else "-"),
        ("fitness, eq. (3)", f"{data['fitness']:.4g} A²"),
        ("%err against the truth", "-" if data["percent_error"] is None else f"{data['percent_error']:.2f}"),
        ("evaluations, wall time", f"{data['evaluations']}, {data['wall_time_s']:.1f} s"),
    ]


def _provenance(provenance: dict[str, Any]) -> list[tuple[str, str]]:
    """The input, one short line per item (the full record is in the JSON)."""
    names = {"reference": "recording", "sha256": "SHA-256", "true_faults": "true faults", "channel_map": "channel map",
             "conversion": "conversion", "params": "actuator file", "calibration": "LF calibration",
             "detection": "detection thresholds"}  # fmt: skip
    rows = []
    for key, value in provenance.items():
        if value is None:
            continue
        text = _brief_conversion(value) if key == "conversion" else value
        text = ", ".join(f"{v:g}" for v in value) if key == "true_faults" else text
        rows.append((names.get(key, key), str(text)))
    return rows


def _brief_conversion(conversion: Any) -> str:
    """A rig recording's conversion in one line: its grid, angle offset, segment and scalar items."""
    if not isinstance(conversion, dict):
        return str(conversion)
    grid, angle, seg = (conversion.get(k) or {} for k in ("grid", "angle", "segments"))
    items = [f"{k}: {v}" for k, v in conversion.items() if isinstance(v, (int, float, str))]
    if grid.get("f_s"):
        items.append(f"{grid.get('samples', '?')} samples at {grid['f_s']:g} Hz")
    if angle.get("offset_deg") is not None:
        items.append(f"angle offset {angle['offset_deg']:.1f}° electrical ({angle.get('offset_method', '')})")
    if seg.get("used"):
        items.append(f"used {seg['used'][0]:.3g} to {seg['used'][1]:.3g} s of the record")
    return "; ".join(items) + ("; the rest in the JSON" if len(items) < len(conversion) else "")


def _settings(data: dict[str, Any], view: dict[str, Any]) -> list[tuple[str, str]]:
    """The key settings (the rest are in the JSON)."""
    s = data["settings"]
    run = s.get("identify") or {}
    cal, par, uq = (s.get(k) or {} for k in ("calibration", "params", "uq_calibration"))
    budget = budget_text(data["optimizer"], run.get("pop_size"), run.get("generations"))
    return [
        ("optimiser, seed", f"{data['optimizer']}, {data['seed']}"),
        ("budget", budget + (", polish" if run.get("polish") else ", no polish")),
        ("monitor, last stage", f"{cal.get('monitor', '-')}, {s.get('last_stage', '-')}"),
        ("actuator parameters", f"{par.get('source', '-')} (hash {par.get('params_hash', '-')})"),
        ("LF calibration", f"{cal.get('source', '-')} ({cal.get('created') or 'undated'})"),
        ("intervals", f"{data['uq_method']}" + (f", calibration {uq.get('source')}" if uq else "")),
        ("detection thresholds", view["detection"]["source"]),
        ("emaphm", data["version"]),
    ]


def fit_model(data: dict[str, Any]) -> str:
    """Which model's current the fit shows: the switching model's after a switching last stage
    that ran (`FaultIdentifier.curves`), else the LF monitor's."""
    from .identification.result import stage_record

    stage = (stage_record(data["settings"].get("stages", []), "last_stage") or {}).get("switching")
    return "switching model" if stage is not None and "error" not in stage else "LF model"
