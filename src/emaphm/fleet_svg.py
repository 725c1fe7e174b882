"""The trend charts of the fleet page (`fleet_page`): inline SVG written as text, no plotting library.

One ``<svg>`` per actuator, with a ``<title>``, and one panel per fault series (three to a row):
the diagnoses' fault values k against the flight with their 90 % interval whiskers (filled dots:
used in the trend; hollow grey: left out of it), the fitted trend line, the
healthy level (dotted) and the failure threshold (dashed), mirrored about healthy too when that
stays inside [0, 1] (the gain drift k8 fails on both sides of its healthy 0.5). The styles
are the page's CSS classes (`CHART_CSS`) and the dots and whiskers are placed to the pixel, so a panel of 20
flights is about 1.5 kB and 10 000 charts are written in about a second.
"""

from __future__ import annotations

import html
import math
from collections.abc import Callable, Sequence
from typing import Any

__all__ = ["CHART_CSS", "chart", "finite", "number"]

e = html.escape

W, H = 300, 180  # one panel [px]
LEFT, RIGHT, TOP, BOTTOM = 48, 12, 22, 32  # the plot area's margins inside a panel [px]
PER_ROW = 3  # panels side by side

CHART_CSS = """
svg.trend{font-size:10px;background:#fff;margin:.3em 0;overflow:visible}
.trend path{fill:none} .trend .fr{fill:none;stroke:#999} .trend .gd{stroke:#eee}
.trend .hl{stroke:#2e7d32;stroke-dasharray:2 3} .trend .th{stroke:#c62828;stroke-dasharray:6 3}
.trend .wk{stroke:#1f4e79} .trend .pt{stroke:#1f4e79;stroke-width:6;stroke-linecap:round}
.trend .pu{stroke:#999;stroke-width:6;stroke-linecap:round}
.trend .pi{stroke:#fff;stroke-width:3;stroke-linecap:round}
.trend .tr{stroke:#e65100;stroke-width:1.5} .trend .tt{font-weight:bold;font-size:11px}
.trend .ye{text-anchor:end} .trend .xm{text-anchor:middle} .trend .lh{fill:#2e7d32} .trend .lt{fill:#c62828}
"""


def chart(actuator: str, series: dict[str, dict[str, Any]], thresholds: dict[str, Any] | None = None) -> str:
    """The SVG of one actuator's trends: one panel per fault of `series`.

    Parameters
    ----------
    actuator : str
        the actuator's id, for the chart's title
    series : dict
        fault name -> ``{"flight", "value", "low", "high", "used", "trend_flight", "trend_value",
        "healthy", "threshold_value"}``: lists over the diagnoses (``low``/``high`` may hold None,
        ``used`` False for a diagnosis left out of the trend), the trend line's points, the
        healthy k and the fault value k at which it fails [fault units]
    thresholds : dict, optional
        fault name -> ``{"threshold", "placeholder"}`` (the fleet report's, distances from healthy):
        shown in the panel's title, and healthy + threshold is the failure line of a series
        without ``threshold_value``

    Returns
    -------
    str
        ``<svg class="trend">...</svg>``
    """
    thresholds = thresholds or {}
    names = list(series)
    cols, rows = max(1, min(len(names), PER_ROW)), max(1, -(-len(names) // PER_ROW))
    width, height = cols * W, rows * H
    title = (
        f"Trends of actuator {actuator}: fault value k of {', '.join(names) or 'no fault'} against the "
        "flight, with the healthy level and the failure threshold"
    )
    out = [
        f'<svg class="trend" role="img" width="{width}" height="{height}" viewBox="0 0 {width} {height}">'
        f"<title>{e(title)}</title>"
    ]
    for i, name in enumerate(names):
        limit = thresholds.get(name) or {}
        out.append(_panel(name, series[name] or {}, limit, (i % PER_ROW) * W, (i // PER_ROW) * H))
    out.append("</svg>")
    return "".join(out)


def _panel(name: str, s: dict[str, Any], limit: dict[str, Any], x0: int, y0: int) -> str:
    """One fault's panel, its top left corner at (`x0`, `y0`) [px]."""
    flights = [float(f) for f in s.get("flight") or []]
    n = len(flights)
    values, low, high = (_pad(s.get(key), n) for key in ("value", "low", "high"))
    used = [u is not False for u in _pad(s.get("used"), n)]
    trend = [
        (float(f), min(max(float(v), 0.0), 1.0))  # k lives in [0, 1]: an extrapolation is cut there
        for f, v in zip(s.get("trend_flight") or [], s.get("trend_value") or [], strict=False)
        if finite(f) and finite(v)
    ]
    healthy = float(s.get("healthy", 0.0))
    threshold: Any = limit.get("threshold")
    failure = _failure_levels(
        healthy, s.get("threshold_value", healthy + threshold if finite(threshold) else None)
    )
    threshold = threshold if finite(threshold) else (abs(failure[0] - healthy) if failure else None)
    ys = [float(v) for v in (*values, *low, *high) if finite(v)] + [v for _, v in trend] + [healthy, *failure]
    left, right, top, bottom = x0 + LEFT, x0 + W - RIGHT, y0 + TOP, y0 + H - BOTTOM
    X, x_ticks = _scale(flights + [f for f, _ in trend], left, right, whole=True)
    Y, y_ticks = _scale(ys, bottom, top, whole=False)
    where = f": threshold {_g(threshold)}" if finite(threshold) else ""
    out = [
        f'<rect class="fr" x="{left}" y="{top}" width="{right - left}" height="{bottom - top}"/>',
        '<path class="gd" d="' + "".join(f"M{left} {Y(v):.1f}H{right}" for v in y_ticks) + '"/>',
        f'<text class="tt" x="{x0 + 4}" y="{y0 + 14}">{e(name)}{e(where)}'
        f"{' (placeholder)' if limit.get('placeholder') else ''}</text>",
        *(f'<text class="ye" x="{left - 3}" y="{Y(v) + 3:.1f}">{_g(v)}</text>' for v in y_ticks),
        *(f'<text class="xm" x="{X(v):.1f}" y="{bottom + 12}">{_g(v)}</text>' for v in x_ticks),
        f'<text class="xm" x="{(left + right) / 2:.0f}" y="{y0 + H - 4}">flight</text>',
        f'<text class="xm" transform="rotate(-90)" x="{-(top + bottom) / 2:.0f}" y="{x0 + 11}">'
        "fault value k (fault units)</text>",
        f'<path class="hl" d="M{left} {Y(healthy):.1f}H{right}"/>',
        f'<text class="lh ye" x="{right - 2}" y="{Y(healthy) - 3:.1f}">healthy</text>',
    ]
    if failure:
        out.append('<path class="th" d="' + "".join(f"M{left} {Y(v):.1f}H{right}" for v in failure) + '"/>')
        out += [f'<text class="lt ye" x="{right - 2}" y="{Y(v) - 3:.1f}">failure</text>' for v in failure]
    out += _marks(flights, values, low, high, used, X, Y)
    if len(trend) > 1:
        out.append('<path class="tr" d="M' + " ".join(f"{X(f):.1f} {Y(v):.1f}" for f, v in trend) + '"/>')
    if not n:
        out.append(
            f'<text class="xm" x="{(left + right) / 2:.0f}" y="{(top + bottom) / 2:.0f}">no diagnoses</text>'
        )
    return "".join(out)


def _marks(
    flights: list[float], values: list[Any], low: list[Any], high: list[Any], used: list[bool],
    X: Callable[[float], float], Y: Callable[[float], float],
) -> list[str]:  # fmt: skip
    """The whiskers (low to high) and the dots: one path each, a dot a zero-length round-capped line."""
    whiskers: list[str] = []
    dots: list[str] = []
    hollow: list[str] = []
    for f, v, lo, hi, u in zip(flights, values, low, high, used, strict=True):
        x = f"{X(f):.0f}"
        if finite(lo) and finite(hi):
            whiskers.append(f"M{x} {Y(lo):.0f}V{Y(hi):.0f}")
        if finite(v):
            (dots if u else hollow).append(f"M{x} {Y(v):.0f}h0")
    out = [f'<path class="wk" d="{"".join(whiskers)}"/>'] if whiskers else []
    if dots:
        out.append(f'<path class="pt" d="{"".join(dots)}"/>')
    if hollow:
        d = "".join(hollow)
        out.append(f'<path class="pu" d="{d}"/><path class="pi" d="{d}"/>')
    return out


def _failure_levels(healthy: float, level: Any) -> list[float]:
    """Where k fails: `level`, and its mirror about `healthy` when that is inside [0, 1] too (k8)."""
    if not finite(level):
        return []
    mirror = 2 * healthy - float(level)
    return [float(level)] + ([mirror] if 0 <= mirror <= 1 and abs(mirror - level) > 1e-9 else [])


def _scale(
    data: Sequence[float], start: float, end: float, whole: bool
) -> tuple[Callable[[float], float], list[float]]:
    """The map from data to pixels over `start`..`end` (a little margin around the data) and the ticks;
    `whole`: whole-number ticks (flights)."""
    good = [v for v in data if finite(v)] or [0.0, 1.0]
    lo, hi = min(good), max(good)
    if hi - lo < 1e-9:
        lo, hi = lo - (1 if whole else 0.1), hi + (1 if whole else 0.1)
    pad = 0.04 * (hi - lo)
    lo, hi = lo - pad, hi + pad
    factor = (end - start) / (hi - lo)
    return (lambda v: start + (v - lo) * factor), _ticks(lo, hi, whole)


def _ticks(lo: float, hi: float, whole: bool, count: int = 4) -> list[float]:
    """About `count` round numbers (1, 2 or 5 times a power of ten) between `lo` and `hi`."""
    raw = (hi - lo) / count
    power = 10 ** math.floor(math.log10(raw))
    step = next(m * power for m in (1, 2, 5, 10) if m * power >= raw)
    if whole:
        step = max(1.0, round(step))
    first = math.ceil(lo / step) * step
    return [round(first + i * step, 10) for i in range(int((hi - first) / step) + 1)]


def _pad(values: Any, n: int) -> list[Any]:
    """`values` as a list of length `n` (None where missing)."""
    items = list(values or [])[:n]
    return items + [None] * (n - len(items))


def finite(v: Any) -> bool:
    """Whether `v` is a finite number (None, a bool or a string is not)."""
    if v is None or isinstance(v, (bool, str)):
        return False
    try:
        return math.isfinite(v)
    except TypeError:
        return False


def _g(v: Any) -> str:
    return f"{v:.3g}"


def number(v: Any, fmt: str = "") -> str:
    """A number for the page (three digits, or whole above 100, unless `fmt`): "—" when there is none,
    "beyond" for an infinite prediction."""
    if not finite(v):
        return "beyond" if isinstance(v, float) and v == math.inf else "—"
    return format(v, fmt or (".0f" if abs(v) >= 100 else ".3g"))
