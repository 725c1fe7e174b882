"""Steps 5 and 6 of `to_reference`: i_q and every signal onto the model grid t_k = k/f_s.

A channel's clean run is cut to the segment ± `MARGIN` (`cut_run`), so the filters' edge
transients fall outside it; `to_grid` resamples it with `identification.signals.resample` (a
source faster than the grid low-passed on its own grid first, a jittered fast source first
interpolated onto a uniform grid at its own rate, slower ones interpolated linearly) and says
what it did; `grid_signals` builds the trace's signals, i_q from the phase currents when it is
not mapped (`emaphm.measured.alignment`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..identification.signals import ANTI_ALIAS_ABOVE, ANTI_ALIAS_FRACTION, resample
from ..params import EmaParams
from .alignment import phases_to_iq
from .measurement import Channel, Measurement

__all__ = ["MARGIN", "UNIFORM", "current_at", "cut_run", "grid_signals", "to_grid"]

MARGIN = 0.05  # [s] of a run kept beyond the segment, so the filters' edge transients fall outside
UNIFORM = 1e-3  # relative step jitter below which a source counts as uniform (as `resample`)

Run = tuple[NDArray[np.float64], NDArray[np.float64]]  # (t, values) of a channel's clean run


def grid_signals(
    m: Measurement,
    runs: dict[str, Run],
    theta_e_run: Run | None,
    params: EmaParams,
    t_abs: NDArray[np.float64],
    f_s: float,
    warnings: list[str],
) -> tuple[dict[str, NDArray[np.float64]], dict[str, str], dict[str, Any], list[str]]:
    """The trace's signals on the grid `t_abs`, how each was resampled, the alignment's report
    and the flags; warnings are appended to `warnings`."""
    cmap = m.channel_map
    signals: dict[str, NDArray[np.float64]] = {}
    resampling: dict[str, str] = {}
    flags: list[str] = []

    def on_grid(role: str, t_src: NDArray[np.float64], x: NDArray[np.float64]) -> NDArray[np.float64]:
        values, how = to_grid(t_src, x, t_abs, f_s)
        resampling[role] = how
        return values

    signals["theta_cmd"] = on_grid("theta_cmd", *runs["theta_cmd"])
    alignment_report: dict[str, Any] = {}
    if "i_q" in m:  # 5. i_q
        signals["i_q"] = on_grid("i_q", *runs["i_q"])
    if "theta_u" in m:
        signals["theta_u"] = on_grid("theta_u", *runs["theta_u"])
    else:
        warnings.append(
            "theta_u is not mapped: the trace has no measured position, so holds of the command where the "
            "surface rests are told from the command alone"
        )
    if "i_a" in m and "i_q" in m:
        warnings.append("the map gives i_q and the phase currents: i_q is used, the phases only stored")
    if "i_a" in m:
        t_cur, i_a = runs["i_a"]
        i_b = current_at(runs["i_b"], t_cur)
        i_c = current_at(runs["i_c"], t_cur) if "i_c" in m else None
        if "i_q" not in m:
            assert theta_e_run is not None  # the map requires an angle with the phase currents
            given = cmap.electrical_offset_deg(params.motor.p)
            offset = None if given is None else math.radians(given)
            al = phases_to_iq(t_cur, i_a, i_b, i_c, np.interp(t_cur, *theta_e_run), params, offset=offset)
            warnings += al.warnings
            alignment_report = al.report
            signals["i_q"] = on_grid("i_q", t_cur, al.i_q)
            i_a, i_b, i_c = al.phases
            flags += ["i_q_from_phases", "angle_offset_" + ("estimated" if offset is None else "given")]
            flags += ["zero_sequence_removed"] if al.report.get("zero_sequence_removed") else []
            flags += ["pi_added"] if al.report.get("pi_added") else []
        if "i_c" not in m:
            i_c = -i_a - i_b  # isolated neutral (DESIGN §3.4)
            flags.append("i_c_reconstructed")
        assert i_c is not None
        for role, x in (("i_a", i_a), ("i_b", i_b), ("i_c", i_c)):
            signals[role] = on_grid(role, t_cur, x)
    if theta_e_run is not None:
        theta0 = math.radians(alignment_report.get("offset_deg", cmap.electrical_offset_deg(params.motor.p) or 0.0))
        signals["theta_e"] = on_grid("theta_e", theta_e_run[0], theta_e_run[1] + theta0)
    return signals, resampling, alignment_report, flags


def cut_run(
    ch: Channel, run: tuple[int, int], start: float, end: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The samples of `ch`'s clean run that lie within the segment ± `MARGIN`."""
    a, b = run
    t = ch.t[a : b + 1]
    lo = max(int(np.searchsorted(t, start - MARGIN, side="right")) - 1, 0)
    hi = min(int(np.searchsorted(t, end + MARGIN, side="left")) + 1, len(t))
    return t[lo:hi], ch.values[a : b + 1][lo:hi]


def current_at(
    run: tuple[NDArray[np.float64], NDArray[np.float64]], t: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Another current on the grid t: as is when it shares the grid, else interpolated."""
    t_src, x = run
    if len(t_src) == len(t) and np.array_equal(t_src, t):
        return x
    return np.interp(t, t_src, x)


def to_grid(
    t_src: NDArray[np.float64], x: NDArray[np.float64], t_grid: NDArray[np.float64], f_s: float
) -> tuple[NDArray[np.float64], str]:
    """`signals.resample`, after regularising a jittered fast source; and what was done."""
    steps = np.diff(t_src)
    step = float(np.median(steps))
    f_src = 1.0 / step
    how = ""
    if f_src > ANTI_ALIAS_ABOVE * f_s and np.max(np.abs(steps - step)) > UNIFORM * step:
        t_reg = t_src[0] + np.arange(math.ceil((t_src[-1] - t_src[0]) / step) + 1) * step
        x = np.interp(t_reg, t_src, x)
        t_src = t_reg
        how = f"jittered: interpolated to a uniform {f_src:.6g} Hz grid, then "
    if f_src > ANTI_ALIAS_ABOVE * f_s:
        how += (
            f"low-passed at {ANTI_ALIAS_FRACTION * f_s:g} Hz on its {f_src:.6g} Hz grid, then interpolated "
            f"to {f_s:g} Hz"
        )
    elif f_src < f_s / ANTI_ALIAS_ABOVE:
        how += f"interpolated linearly from {f_src:.6g} Hz to {f_s:g} Hz"
    else:
        how += f"interpolated at the same rate ({f_src:.6g} Hz)"
    return resample(t_src, x, t_grid, f_s), how
