"""`to_reference`: a measurement → a trace on the model grid, ready for `emaphm.identify`.

next-features §D.3–§D.4. The steps, each refusing with a one-line `InputError` and a hint:

1. **span and rates** — each channel's span within (`MIN_DURATION`, `MAX_SPAN`] before anything
   is allocated; currents and angles at `MIN_RATE_FAST` or faster, theta_cmd/theta_u at
   `MIN_RATE_SLOW` or faster.
2. **plausibility** — outliers, current and position ranges, constant currents
   (`emaphm.measured.checks`), per channel and named by row.
3. **segments** — NaN runs and time gaps split each channel; the longest stretch clean in every
   channel is used (`emaphm.measured.timebase`), never interpolated across a gap.
4. **angle ratio** — the rotor angle must turn p·τ times the surface angle (`checks.angle_ratio`).
5. **i_q** — mapped, or from the phase currents on *their own* grid (`emaphm.measured.alignment`:
   Clarke/Park of `kernels.transforms`, θ0 estimated, sign from the motion).
6. **resampling** (`emaphm.measured.grid`) — every signal onto t_k = k/f_s from the segment's start with
   `identification.signals.resample`: a source faster than the grid is low-passed on its own
   grid first (Butterworth order 8 at 0.4·f_s, zero phase; a jittered fast source is first
   interpolated onto a uniform grid at its own rate), slower ones are interpolated linearly
   (positions at 500 Hz are never held).

The trace holds t (from 0), theta_cmd, i_q, theta_u when mapped, and i_a, i_b, i_c, theta_e
(with θ0 added, unwrapped) when the phase currents or the angle were mapped. Its metadata, and
`Reference.report`, record the provenance and every decision (§D.3 item 9).
"""

from __future__ import annotations

import dataclasses
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .._version import __version__
from ..errors import Doubt, InputError
from ..params import EmaParams
from ..results import SimResult
from . import limits
from .checks import angle_ratio, plausibility, span_problems, value_problems
from .grid import Run, cut_run, grid_signals
from .measurement import Channel, Measurement
from .timebase import clean_runs, common_segment, frozen_runs, starts_at_rest

__all__ = ["FAST_ROLES", "Reference", "to_reference", "write_reference"]

FAST_ROLES = ("i_q", "i_a", "i_b", "i_c", "theta_e", "theta_m")


@dataclass(frozen=True)
class Reference:
    """A measured reference on the model grid.

    trace : SimResult  t from 0 at f_s, theta_cmd, i_q (+ theta_u, i_a, i_b, i_c, theta_e), SI
    report : dict  JSON-ready: provenance, angle offset, segments, resampling, flags, warnings
    """

    trace: SimResult
    report: dict[str, Any]


def to_reference(
    measurement: Measurement,
    params: EmaParams | str | os.PathLike[str] | None = None,
    f_s: float | None = None,
) -> Reference:
    """Turn `measurement` into a reference trace on the model grid (see the module docstring).

    Parameters
    ----------
    measurement : Measurement
        From `load_measurement`.
    params : EmaParams or path, optional
        The actuator (pole pairs, gear, I_max, theta_max, the grid's f_s), or its actuator file;
        nominal by default.
    f_s : float, optional
        Rate of the model grid [Hz]; ``params.controller.f_s`` by default.

    Returns
    -------
    Reference

    Raises
    ------
    InputError
        Implausible or unusable data, with the likely cause.
    """
    from ..actuator import resolve_params

    params = resolve_params(params)
    f_s = float(f_s if f_s is not None else params.controller.f_s)
    if not (math.isfinite(f_s) and f_s > 0):
        raise InputError(f"f_s must be a positive number of Hz, got {f_s!r}")
    m = measurement
    src = m.source
    channels = list(m.channels.values())
    warnings = list(m.warnings)
    _check_channels(channels, params, src)  # 1. span and rates, 2. plausibility

    channels = _dropouts_as_gaps(channels, m["theta_cmd"], warnings)
    breaks = {ch.role: clean_runs(ch) for ch in channels}  # 3. segments
    try:
        seg, candidates = common_segment(channels, breaks)
    except InputError as exc:
        raise InputError(f"{src}: {exc}") from None
    if not starts_at_rest(m["theta_cmd"], seg.start):
        warnings.append(_in_motion(seg.start))
    runs = {ch.role: cut_run(ch, seg.runs[ch.role], seg.start, seg.end) for ch in channels}
    theta_e_run, angle_info = _angle(m, runs, params)  # 4. angle ratio

    n = math.floor((seg.end - seg.start) * f_s + 1e-9) + 1  # 6. the model grid
    t_abs = seg.start + np.arange(n) / f_s
    signals, resampling, alignment_report, flags = grid_signals(
        m, runs, theta_e_run, params, t_abs, f_s, warnings
    )

    t = t_abs - seg.start
    report = _report(m, params, f_s, seg, candidates, breaks, n, resampling, alignment_report, angle_info)
    cut = report["segments"]["dropped_s"] > 1.0 / f_s
    report["flags"] = flags + (["segment_cut"] if cut else [])
    if cut:
        warnings.append(_cut_warning(report["segments"], f_s))
    report["warnings"] = warnings
    # the preconditions not met, as plain strings so that a converted trace's file keeps them
    report["doubts"] = [str(w) for w in warnings if isinstance(w, Doubt)]
    metadata = {
        "model": "measured",
        "source": str(src),
        "sha256": m.sha256,
        "f_s": f_s,
        "params": params.to_dict(),
        "measured": report,
        "version": __version__,
    }
    order = ("theta_cmd", "theta_u", "i_q", "i_a", "i_b", "i_c", "theta_e")  # as the twin's traces
    trace = SimResult(t=t, signals={k: signals[k] for k in order if k in signals}, metadata=metadata)
    problems = plausibility(trace, params)
    if problems:
        raise InputError(f"{src}: after conversion: {problems[0]}")
    return Reference(trace, report)


def _in_motion(start: float) -> Doubt:
    """The precondition a recording that starts in motion breaks (`timebase.starts_at_rest`)."""
    return Doubt(
        f"the recording starts in motion: the position command moves in its first {1000 * limits.REST_WINDOW_S:g} ms "
        f"(from {start:.4g} s in the file), but the monitor starts at rest; start the logger before the command, "
        "or the diagnosis may be off"
    )


def _dropouts_as_gaps(channels: list[Channel], command: Channel, warnings: list[str]) -> list[Channel]:
    """The channels with each current's dropouts logged as zeros or held values (`frozen_runs`)
    made NaN, so that they split the record like a gap; a warning names each channel's first one."""
    out = []
    for ch in channels:
        runs = frozen_runs(ch, command)
        if runs:
            values = ch.values.copy()
            for first, last in runs:
                values[first : last + 1] = np.nan
            a, b = runs[0]
            warnings.append(
                f"{ch.role} holds exactly {ch.values[a]:g} A for {1000 * (ch.t[b] - ch.t[a]):.3g} ms from {ch.row(a)} "
                f"while the command moves: a dropout logged as {'zeros' if ch.values[a] == 0 else 'held values'}, "
                f"treated as a gap ({len(runs)} such run(s))"
            )
            ch = dataclasses.replace(ch, values=values)
        out.append(ch)
    return out


def _check_channels(channels: list[Channel], params: EmaParams, src: Any) -> None:
    """Steps 1 and 2: each channel's span, rate and values; `InputError` naming the first problem."""
    for ch in channels:  # 1. span and rates, before anything is allocated
        finite = ch.t[np.isfinite(ch.t)]
        problems = span_problems(float(finite[-1] - finite[0]), what=ch.label)
        if problems:
            raise InputError(f"{src}: {problems[0]}")
    for ch in channels:
        fast = ch.role in FAST_ROLES
        need = limits.MIN_RATE_FAST if fast else limits.MIN_RATE_SLOW
        if ch.f_s < need:
            kind = "currents and rotor angles" if fast else "positions"
            raise InputError(
                f"{src}: {ch.label} is sampled at {ch.f_s:.4g} Hz; {kind} need at least {need:g} Hz"
            )
    for ch in channels:  # 2. plausibility
        problems = value_problems(ch.role, ch.values, params, label=ch.label, row=ch.row)
        if problems:
            raise InputError(f"{src}: {problems[0]}")


def _angle(m: Measurement, runs: dict[str, Run], params: EmaParams) -> tuple[Run | None, dict[str, Any]]:
    """Step 4: the electrical angle's run (unwrapped; θ_m times p) and the angle-ratio check's
    report, {} without a mapped angle; `InputError` when the ratio is not p·τ."""
    angle_role = m.channel_map.angle_role
    if angle_role is None:
        return None, {}
    t_ang, ang = runs[angle_role]
    ang = np.unwrap(ang)
    theta_e_run = (t_ang, ang * params.motor.p if angle_role == "theta_m" else ang)
    ref_role = "theta_u" if "theta_u" in m else "theta_cmd"
    t_ref, ref = runs[ref_role]
    inside = (t_ref >= t_ang[0]) & (t_ref <= t_ang[-1])
    problem, angle_info = angle_ratio(
        angle_role, np.interp(t_ref[inside], t_ang, ang), ref_role, ref[inside], params
    )
    if problem:
        raise InputError(f"{m.source}: {problem}")
    return theta_e_run, angle_info


def _cut_warning(segments: dict[str, Any], f_s: float) -> str:
    """The warning for a record that gaps or NaN runs split (`segments` of the report)."""
    first, last = segments["record"]
    used = segments["used"]
    share = 100.0 * (used[1] - used[0]) / (last - first) if last > first else 100.0
    late = used[0] - first > 1.0 / f_s
    return (
        f"gaps or NaN runs split the record: only {used[0]:g}..{used[1]:g} s ({share:.0f} % of it) is used"
        + (
            "; it starts inside the command, where the monitor starts from rest: the diagnosis is unreliable "
            "unless the command was at rest there"
            if late
            else ""
        )
    )


def write_reference(reference: Reference, path: str | os.PathLike[str]) -> Path:
    """Write the reference's trace with `emaphm.io.write_trace` (atomic; HDF5 or CSV + JSON).

    The report travels in the metadata (``measured``, a JSON attribute); `emaphm.io.read_trace`
    gives it back as a dict.

    Parameters
    ----------
    reference : Reference
        A reference made by `to_reference`.
    path : str or path
        The file to write (``.h5`` or ``.csv``).
    """
    from ..io import write_trace

    return write_trace(reference.trace, path)


def _report(
    m: Measurement,
    params: EmaParams,
    f_s: float,
    seg: Any,
    candidates: list[Any],
    breaks: dict[str, Any],
    n: int,
    resampling: dict[str, str],
    alignment: dict[str, Any],
    angle_ratio_info: dict[str, Any],
) -> dict[str, Any]:
    first = min(float(np.nanmin(ch.t)) for ch in m.channels.values())
    last = max(float(np.nanmax(ch.t)) for ch in m.channels.values())
    dropped_rows = {
        role: int(np.count_nonzero(~((ch.t >= seg.start) & (ch.t <= seg.end)) | ~np.isfinite(ch.values)))
        for role, ch in m.channels.items()
    }
    angle: dict[str, Any] = {"source": m.channel_map.angle_role, "pole_pairs": params.motor.p}
    angle.update(alignment)
    if "offset_deg" not in angle and m.channel_map.angle_offset_deg is not None:
        angle.update(offset_deg=m.channel_map.angle_offset_deg, offset_method="given in the channel map")
    if angle_ratio_info:
        angle["ratio_check"] = angle_ratio_info
    return {
        "source": {k: v for k, v in m.provenance.items() if k != "channels"},
        "channels": {
            role: {**ch.summary(), "resampling": resampling.get(role, "not resampled (used through i_q)")}
            for role, ch in m.channels.items()
        },
        "grid": {"f_s": f_s, "samples": n, "start_in_source_s": seg.start, "duration_s": (n - 1) / f_s},
        "angle": angle,
        "segments": {
            "used": [seg.start, seg.end],
            "record": [first, last],
            "candidates": [[g.start, g.end] for g in candidates],
            "gaps": [g for b in breaks.values() for g in b.gaps],
            "dropped_s": max(0.0, (last - first) - (seg.end - seg.start)),
            "dropped_rows": dropped_rows,
        },
        "limits": limits.as_dict(),
    }
