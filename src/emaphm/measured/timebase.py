"""Clean segments of a multi-rate record (next-features §D.3 item 4).

A channel's record breaks wherever a sample or its time is NaN (a NaN run) and wherever the time
step exceeds `GAP_FACTOR` × the channel's median step (a gap). The pieces between are *clean
runs*. The record used is the longest interval covered by a clean run of **every** channel; it
must last `MIN_DURATION`, else `InputError` lists the gaps. Nothing is ever interpolated across a
gap: each channel is later resampled from the samples of its own run only.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import InputError
from .limits import FROZEN_MIN_S, FROZEN_MIN_SAMPLES, GAP_FACTOR, MIN_DURATION, REST_SPREAD, REST_WINDOW_S
from .measurement import Channel

__all__ = ["Breaks", "Segment", "clean_runs", "common_segment", "frozen_runs", "starts_at_rest"]

_LISTED = 5  # gaps named in a message


@dataclass(frozen=True)
class Breaks:
    """The clean runs of one channel and what broke them.

    runs : list of (first, last)  inclusive sample indices of each clean run (≥ 2 samples)
    gaps : list of dict  each break: ``kind`` (``"NaN"`` or ``"gap"``), ``from``/``to`` [s], ``row``
    """

    runs: list[tuple[int, int]]
    gaps: list[dict[str, Any]]


@dataclass(frozen=True)
class Segment:
    """The interval used, [start, end] [s], and the clean run of each channel that covers it."""

    start: float
    end: float
    runs: Mapping[str, tuple[int, int]]

    @property
    def duration(self) -> float:
        return self.end - self.start


def clean_runs(ch: Channel) -> Breaks:
    """Split `ch` at NaN samples and at steps longer than `GAP_FACTOR` × its median step."""
    valid = np.isfinite(ch.t) & np.isfinite(ch.values)
    idx = np.flatnonzero(valid)
    gaps: list[dict[str, Any]] = []
    if len(idx) < 2:
        return Breaks([], [{"channel": ch.role, "kind": "NaN", "from": None, "to": None, "row": ch.row(0),
                            "samples": int(len(ch.t) - len(idx))}])  # fmt: skip
    consecutive = np.diff(idx) == 1
    steps = np.diff(ch.t[idx])
    step = float(np.median(steps[consecutive])) if consecutive.any() else float(np.median(steps))
    cut = ~consecutive | (steps > GAP_FACTOR * step)
    runs = []
    first = 0
    for k in np.flatnonzero(cut):
        a, b = int(idx[k]), int(idx[k + 1])
        nan_run = b - a - 1
        gaps.append({
            "channel": ch.role,
            "kind": "NaN" if nan_run else "gap",
            "from": float(ch.t[a]),
            "to": float(ch.t[b]),
            "row": ch.row(a + 1) if nan_run else ch.row(b),
            "samples": int(nan_run),
        })  # fmt: skip
        runs.append((int(idx[first]), a))
        first = int(k) + 1
    runs.append((int(idx[first]), int(idx[-1])))
    # a NaN run at the start or the end of the record is a break too, only for the report
    if idx[0] > 0:
        gaps.insert(0, {"channel": ch.role, "kind": "NaN", "from": None, "to": float(ch.t[idx[0]]),
                        "row": ch.row(0), "samples": int(idx[0])})  # fmt: skip
    if idx[-1] < len(ch.t) - 1:
        gaps.append({"channel": ch.role, "kind": "NaN", "from": float(ch.t[idx[-1]]), "to": None,
                     "row": ch.row(int(idx[-1]) + 1), "samples": int(len(ch.t) - 1 - idx[-1])})  # fmt: skip
    return Breaks([r for r in runs if r[1] > r[0]], gaps)


def common_segment(
    channels: Sequence[Channel], breaks: Mapping[str, Breaks]
) -> tuple[Segment, list[Segment]]:
    """The longest interval covered by a clean run of every channel, and all candidates.

    `InputError` (listing the gaps) when the longest lasts less than `MIN_DURATION`.
    """
    candidates: list[tuple[float, float, dict[str, tuple[int, int]]]] = [(-np.inf, np.inf, {})]
    for ch in channels:
        runs = breaks[ch.role].runs  # sorted, disjoint, like the candidates: merge them in one pass
        nxt = []
        i = j = 0
        while i < len(candidates) and j < len(runs):
            lo, hi, chosen = candidates[i]
            a, b = runs[j]
            s, e = max(lo, float(ch.t[a])), min(hi, float(ch.t[b]))
            if e > s:
                nxt.append((s, e, {**chosen, ch.role: (a, b)}))
            if hi < float(ch.t[b]):
                i += 1
            else:
                j += 1
        candidates = nxt
    segments = sorted((Segment(s, e, runs) for s, e, runs in candidates), key=lambda g: g.start)
    best = max(segments, key=lambda g: g.duration, default=None)
    command = next((ch for ch in channels if ch.role == "theta_cmd"), None)
    if best is not None and command is not None and not starts_at_rest(command, best.start):
        # the monitor starts at rest: a stretch that starts at rest in the command is worth more
        # than a longer one that starts in motion (the newcomer's 20 ms dropout mid-chirp)
        resting = [g for g in segments if g.duration >= MIN_DURATION and starts_at_rest(command, g.start)]
        best = max(resting, key=lambda g: g.duration, default=best)
    if best is None or best.duration < MIN_DURATION:
        gaps = [g for ch in channels for g in breaks[ch.role].gaps]
        listed = "; ".join(_describe(g) for g in gaps[:_LISTED]) + (
            f"; {len(gaps) - _LISTED} more" if len(gaps) > _LISTED else ""
        )
        longest = f"{best.duration:.3g} s" if best is not None else "none"
        raise InputError(
            f"no clean stretch of {MIN_DURATION:g} s common to all channels (longest: {longest}); "
            f"gaps: {listed or 'none'}"
        )
    return best, segments


def frozen_runs(ch: Channel, command: Channel) -> list[tuple[int, int]]:
    """The runs (first, last sample) where a current channel holds exactly one value (zeros, or a
    logger holding its last sample) for at least `FROZEN_MIN_S` and `FROZEN_MIN_SAMPLES` while the
    position command moves by more than `REST_SPREAD` of its range: a dropout, since a measured
    current carries noise and changes with the motion. [] for a channel that is not a current."""
    if not ch.role.startswith("i_") or len(ch.values) < FROZEN_MIN_SAMPLES:
        return []
    v = ch.values
    same = np.concatenate(([False], v[1:] == v[:-1], [False]))
    edges = np.flatnonzero(np.diff(same.astype(np.int8)))
    finite = np.isfinite(command.values)
    span = float(np.ptp(command.values[finite])) if finite.any() else 0.0
    runs = []
    for a, b in zip(edges[::2], edges[1::2], strict=True):
        first, last = int(a), int(b)  # the run of equal values, v[first] == ... == v[last]
        if last - first + 1 < FROZEN_MIN_SAMPLES or ch.t[last] - ch.t[first] < FROZEN_MIN_S:
            continue
        moving = command.values[(command.t >= ch.t[first]) & (command.t <= ch.t[last]) & finite]
        if span > 0 and len(moving) > 1 and float(np.ptp(moving)) > REST_SPREAD * span:
            runs.append((first, last))
    return runs


def starts_at_rest(command: Channel, start: float) -> bool:
    """Whether the position command holds still over the first `REST_WINDOW_S` from `start`: it
    moves by at most `REST_SPREAD` of its whole range there (a chirp at 3 ms moves 3 % of it)."""
    finite = np.isfinite(command.values)
    values, t = command.values[finite], command.t[finite]
    span = float(np.ptp(values)) if len(values) else 0.0
    window = values[(t >= start) & (t <= start + REST_WINDOW_S)]
    if span == 0.0 or len(window) < 2:
        return True
    return float(np.ptp(window)) <= REST_SPREAD * span


def _describe(g: dict[str, Any]) -> str:
    span = (
        f"{g['from']:.6g}..{g['to']:.6g} s" if g["from"] is not None and g["to"] is not None else "at an end"
    )
    if g["kind"] == "NaN":
        return f"{g['channel']}: {g['samples']} NaN sample(s) from {g['row']} ({span})"
    return f"{g['channel']}: time gap {span} at {g['row']}"
