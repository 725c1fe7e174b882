"""The baseline's short report: its constants against the nameplate, and each recording's fit.

``index.html`` (self-contained: the figures embedded) and ``fit-N.png`` per recording (the
filtered measured current and the monitor's at the fitted constants, healthy, with the residual).
"""

from __future__ import annotations

import base64
import html
from pathlib import Path

from .fit import CONSTANTS
from .make import Baseline

__all__ = ["write_report"]

_NAMEPLATE = {
    "i_gain": ("current sensor gain", "", lambda b: 1.0),
    "k_t_eq": ("k_t,eq", "N·m/A", lambda b: b.calibration.coefficients.k_t_eq / b.fit.factors["k_t_eq"]),
    "k_e_eq": ("k_e,eq (ψ_m)", "V·s/rad", lambda b: b.calibration.coefficients.k_e_eq / b.fit.factors["k_e_eq"]),
    "J_eq": ("J_eq", "kg·m²", lambda b: b.calibration.coefficients.J_eq / b.fit.factors["J_eq"]),
    "F_S0": ("F_S0", "N·m", lambda b: b.nameplate.transmission.F_S0),
    "F_D0": ("F_D0", "N·m", lambda b: b.nameplate.transmission.F_D0),
    "K_P0": ("K_P0 as it acts", "A/rad", lambda b: b.nameplate.controller.K_P0),
}  # fmt: skip


def write_report(made: Baseline, directory: Path) -> Path:
    """Write ``index.html`` and the fit figures into `directory`; returns the page."""
    from ..plots import plot_fit_curves

    e = html.escape
    figures = []
    for i, (ctx, fitted) in enumerate(zip(made.contexts, made.currents, strict=True), start=1):
        nrmse = made.fit.fit_nrmse[i - 1]
        path = plot_fit_curves(ctx.curves(fitted), directory / f"fit-{i}.png",
                               f"recording {i}: NRMSE {100 * nrmse:.2f} % at the baseline's constants, healthy",
                               fitted="at the baseline's constants, healthy")  # fmt: skip
        figures.append(path)
    rows = []
    for c in CONSTANTS:
        name, unit, nameplate = _NAMEPLATE[c]
        value = nameplate(made)
        f, lo, hi = made.fit.factors[c], made.fit.low[c], made.fit.high[c]
        rows.append(f"<tr><td>{e(name)}</td><td>{value:.5g} {e(unit)}</td><td>{f * value:.5g} {e(unit)}</td>"
                    f"<td>{100 * (f - 1):+.2f} %</td><td>{lo:.4f} – {hi:.4f}</td></tr>")  # fmt: skip
    recs = "".join(
        f"<tr><td>{e(r['file'])}</td><td>{r['sha256'][:16]}…</td><td>{100 * r['nameplate_fit_nrmse']:.2f} %</td>"
        f"<td>{100 * r['fit_nrmse']:.2f} %</td></tr>"
        for r in made.record["recordings"]
    )
    images = "".join(
        f'<figure><img alt="{e(p.name)}" src="data:image/png;base64,{base64.b64encode(p.read_bytes()).decode()}">'
        f"<figcaption>{e(p.name)}</figcaption></figure>"
        for p in figures
    )
    page = (
        '<!DOCTYPE html><html lang="en"><head><meta charset="utf-8"><title>emaphm baseline</title>'
        "<style>body{font-family:system-ui,sans-serif;max-width:980px;margin:2em auto}table{border-collapse:collapse}"
        "td,th{border:1px solid #ccc;padding:.25em .6em}img{max-width:100%}</style></head><body>"
        "<h1>emaphm baseline</h1><p>The constants of this actuator fitted to recordings of it when healthy, "
        "about its nameplate (R_s, L_s, the healthy free play B0 and the drive stay the nameplate's).</p>"
        "<table><tr><th>constant</th><th>nameplate</th><th>this actuator</th><th>change</th>"
        "<th>90 % interval (× nameplate)</th></tr>" + "".join(rows) + "</table>"
        "<h2>Recordings</h2><table><tr><th>file</th><th>SHA-256</th><th>fit at the nameplate</th>"
        "<th>fit at the baseline</th></tr>" + recs + "</table><h2>Fits</h2>" + images + "</body></html>\n"
    )
    out = directory / "index.html"
    out.write_text(page, encoding="utf-8")
    return out
