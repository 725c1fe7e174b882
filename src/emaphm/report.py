"""A diagnosis report a person reads (issue 10, item 6): ``emaphm identify … --report DIR``.

The folder gets three figures (``fit.png``: measured vs fitted current with the residual;
``faults.png``: the faults with their 90 % intervals; ``convergence.png``) and ``index.html``, a
single self-contained page (the figures are embedded, no network, no script but one that counts
the images that loaded) with the verdict, the per-fault table, the warnings, the input's
provenance (file, SHA-256, channel map and conversion when there was one) and every setting.

Writing is atomic per file and the page comes last: an interrupted report leaves either the
previous page or none, never a page that points at missing figures.
"""

from __future__ import annotations

import base64
import html
import json
import os
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from .errors import InputError

__all__ = ["REPORT_FILES", "check_report_dir", "input_provenance", "write_report"]

REPORT_FILES = ("fit.png", "faults.png", "convergence.png", "index.html")


def check_report_dir(path: str | os.PathLike[str], *, option: str = "--report") -> Path:
    """Validate a report folder before the work: a folder or a new name in a writable folder."""
    p = Path(path)
    if p.exists() and not p.is_dir():
        raise InputError(f"{option} {p}: exists and is not a folder")
    parent = p if p.is_dir() else p.absolute().parent
    if not parent.is_dir():
        raise InputError(f"{option} {p}: folder {parent} does not exist")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise InputError(f"{option} {p}: folder {parent} is not writable")
    return p


def write_report(
    result: Any, directory: str | os.PathLike[str], *, provenance: dict[str, Any] | None = None
) -> Path:
    """Write the report of an `IdentificationResult` into `directory`; returns the page's path.

    `provenance` (JSON-ready) describes the input: e.g. ``{"reference": path, "sha256": …,
    "map": …, "conversion": …}``; shown as it is.
    """
    import numpy as np

    from .faults import FAULT_NAMES
    from .plots import plot_convergence, plot_fit_curves, plot_vectors

    out = check_report_dir(directory)
    out.mkdir(parents=True, exist_ok=True)
    data = result.to_json()
    figures: dict[str, bytes] = {}
    with tempfile.TemporaryDirectory(dir=out, prefix=".report-") as tmp_name:
        tmp = Path(tmp_name)
        if result.curves is not None:
            nrmse = data["fit_nrmse"]
            title = f"fit NRMSE {100 * nrmse:.2f} % of the filtered current" if nrmse is not None else ""
            plot_fit_curves(result.curves, tmp / "fit.png", title, model=_fit_model(data))
        bounds = (
            {"estimate": (np.asarray(data["ci90_low"]), np.asarray(data["ci90_high"]))}
            if data["ci90_low"] is not None
            else None
        )
        undefined = {"estimate"} if data["uq_flags"] and "phase_undefined" in data["uq_flags"][6] else set()
        truth = None if result.truth is None else np.asarray(result.truth)
        plot_vectors(truth, {"estimate": np.asarray(result.estimate)}, FAULT_NAMES, tmp / "faults.png",
                     intervals=bounds, phase_undefined=undefined)  # fmt: skip
        plot_convergence(
            {"best fitness": [v for v in data["history"] if v is not None]}, tmp / "convergence.png"
        )
        for name in REPORT_FILES[:-1]:
            if (tmp / name).is_file():
                figures[name] = (tmp / name).read_bytes()
                os.replace(tmp / name, out / name)
        page = tmp / "index.html"
        page.write_text(_page(data, figures, provenance or {}), encoding="utf-8")
        os.replace(page, out / "index.html")
    return out / "index.html"


def input_provenance(
    reference: str | os.PathLike[str] | None,
    *,
    truth: Sequence[float] | None = None,
    channel_map: str | os.PathLike[str] | None = None,
    conversion: dict[str, Any] | None = None,
    params: str | os.PathLike[str] | None = None,
    calibration: str | os.PathLike[str] | None = None,
) -> dict[str, Any]:
    """The report's description of an identification's input, for `write_report(provenance=)`.

    `reference` is the file identified (its SHA-256 is recorded), or None for the HF twin run
    with `truth`; `channel_map` and `conversion` (``settings["conversion"]`` of the result) when
    the file was a rig's recording; `params` and `calibration` the files given (None: the nominal
    actuator, the packaged calibration).
    """
    from .io import sha256_of

    return {
        "reference": str(reference) if reference is not None else "HF twin, noise on",
        "sha256": sha256_of(reference) if reference is not None else None,
        "true_faults": None if truth is None else [float(v) for v in truth],
        "channel_map": str(channel_map) if channel_map is not None else None,
        "conversion": conversion,
        "params": str(params) if params is not None else "nominal",
        "calibration": str(calibration) if calibration is not None else "packaged",
    }


_STYLE = """
body{font-family:system-ui,sans-serif;max-width:980px;margin:2em auto;padding:0 1em;color:#222}
h1{font-size:1.4em} h2{font-size:1.1em;margin-top:1.6em;border-bottom:1px solid #ddd}
table{border-collapse:collapse;font-size:.9em} td,th{border:1px solid #ccc;padding:.25em .6em}
td.num{text-align:right;font-variant-numeric:tabular-nums} th{background:#f3f3f3}
.verdict{display:inline-block;padding:.3em .8em;border-radius:4px;font-weight:bold}
.fits{background:#e3f4e3;color:#1d5e1d} .nofit{background:#fbe3e3;color:#8a1c1c} .doubt{background:#fff0cc;color:#6b4a00}
.present{font-weight:bold;color:#8a1c1c} .warn{background:#fff6dd;padding:.5em 1em;border-left:4px solid #e0b000}
img{max-width:100%;border:1px solid #eee} pre{background:#f7f7f7;padding:.8em;overflow-x:auto;font-size:.8em}
"""

_COUNT_IMAGES = (
    "window.addEventListener('load',function(){var i=Array.prototype.slice.call(document.images);"
    "document.body.setAttribute('data-images-loaded',"
    "i.filter(function(x){return x.complete&&x.naturalWidth>0}).length+'/'+i.length)});"
)


def _page(data: dict[str, Any], figures: dict[str, bytes], provenance: dict[str, Any]) -> str:
    from .tables import fault_rows

    e = html.escape
    detected = ", ".join(data["detected"]) or "none (healthy)"
    headline = {
        "fits": f'<span class="verdict fits">fits: detected {e(detected)}</span>',
        "doubtful": f'<span class="verdict doubt">doubtful: detected {e(detected)}, but '
        f"{len(data.get('doubts') or [])} reason(s) below say why this may not be a diagnosis</span>",
    }.get(
        data["verdict"],
        '<span class="verdict nofit">does not fit: the model does not explain this recording; '
        "no faults are reported</span>",
    )
    numbers = [
        ("fit NRMSE", "-" if data["fit_nrmse"] is None else f"{100 * data['fit_nrmse']:.2f} %"),
        ("fitness, eq. (3)", f"{data['fitness']:.4g}"),
        ("%err against the truth", "-" if data["percent_error"] is None else f"{data['percent_error']:.2f}"),
        ("evaluations", str(data["evaluations"])),
        ("wall time", f"{data['wall_time_s']:.1f} s"),
        ("optimiser, seed", f"{data['optimizer']}, {data['seed']}"),
        ("intervals", data["uq_method"]),
        ("emaphm", data["version"]),
    ]
    columns, rows = fault_rows(data)
    verdict_at = columns.index("verdict")
    table = ["<table><tr>" + "".join(f"<th>{e(c)}</th>" for c in columns) + "</tr>"]
    for row in rows:
        cells = []
        for j, cell in enumerate(row):
            cls = ' class="present"' if j == verdict_at and cell == "present" else ""
            cls = ' class="num"' if j not in (0, verdict_at) and cell[:1].isdigit() else cls
            cells.append(f"<td{cls}>{e(cell)}</td>")
        table.append("<tr>" + "".join(cells) + "</tr>")
    table.append("</table>")
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f"<title>emaphm diagnosis: {e(data['verdict'])}</title>",
        f"<style>{_STYLE}</style><script>{_COUNT_IMAGES}</script></head><body>",
        "<h1>emaphm diagnosis</h1>",
        f"<p>{headline}</p>",
        "<table>" + "".join(f"<tr><th>{e(k)}</th><td>{e(v)}</td></tr>" for k, v in numbers) + "</table>",
    ]
    if data["warnings"]:
        parts.append('<h2>Warnings</h2><div class="warn"><ul>')
        parts += [f"<li>{e(w)}</li>" for w in data["warnings"]]
        parts.append("</ul></div>")
    parts += ["<h2>Faults</h2>", "".join(table)]
    captions = {
        "fit.png": f"Measured current (filtered) and the {_fit_model(data)} at the identified faults, with the residual",
        "faults.png": "Identified faults with their 90 % intervals",
        "convergence.png": "Best fitness per generation (global search, then polish)",
    }
    parts.append("<h2>Figures</h2>")
    for name, blob in figures.items():
        encoded = base64.b64encode(blob).decode("ascii")
        parts.append(
            f'<figure><img alt="{e(captions[name])}" src="data:image/png;base64,{encoded}">'
            f"<figcaption>{e(captions[name])} ({e(name)})</figcaption></figure>"
        )
    parts += [
        "<h2>Input</h2>",
        f"<pre>{e(json.dumps(provenance, indent=2, default=str))}</pre>",
        "<h2>Settings</h2>",
        f"<pre>{e(json.dumps({k: v for k, v in data['settings'].items() if k != 'conversion'}, indent=2, default=str))}</pre>",
        "</body></html>",
    ]
    return "\n".join(parts) + "\n"


def _fit_model(data: dict[str, Any]) -> str:
    """Which model's current the fit shows: the switching model's after a switching last stage
    that ran (`FaultIdentifier.curves`), else the LF monitor's."""
    from .identification.result import stage_record

    stage = (stage_record(data["settings"].get("stages", []), "last_stage") or {}).get("switching")
    return "switching model" if stage is not None and "error" not in stage else "LF model"
