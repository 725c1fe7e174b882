"""Everyday rig mistakes in a recording: is any answered with a confident wrong diagnosis? (issue 34)

    python benchmarks/bench_rig_mistakes.py [--seed 7] [--only NAME[,NAME...]] [--out DIR] [--more]

One actuator (the nominal one) with the newcomer's faults k = 0.30, 0.15, 0, 0.25, 0, 0.10, 0.60,
0.42 (friction ×1.6, free play, a 25 % short in phase B, eccentricity 0.1, K_P −8 %) is run on the
HF twin (noise on, --seed) and logged as a rig would log it: a CSV with the time, the command and
the surface position in degrees, two phase currents and the electrical angle 20° behind the rotor's,
read through a channel map (docs/your-actuator.md §3). Each case then makes one mistake a rig makes
(a current-sensor gain, a logger started late, a dropout, an offset in the wrong degrees, a lever
arm, a command logged late, ...) and is identified as ``emaphm identify --reference REC.csv --map
REC.toml --seed 1`` would. The controls make none.

Per case: how it ended (refused with the reason's first words, or the verdict), %err, the faults
detected against the truth, and the outcome: a **confident wrong answer** is verdict "fits" with
%err above 3 or a false detection (a fault reported present that the truth has not, or one the
truth has reported absent); "right" is a control or mistake with %err <= 3 and the truth's faults.
Summary: the mistakes answered confidently wrong, and the controls (all must be "fits" and right).
"""

from __future__ import annotations

import argparse
import math
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from _cases import (  # benchmarks/ is the script's folder, first on sys.path
    add_settings,
    machine_line,
    settings_of,
)

import emaphm
from emaphm.errors import InputError

TRUTH = np.array([0.30, 0.15, 0.0, 0.25, 0.0, 0.10, 0.60, 0.42])
PRESENT = {"friction", "backlash", "short_b", "eccentricity", "kp_drift"}
OFFSET_DEG = 20.0  # the logged electrical angle is the rotor's minus this
GOOD_ERR = 3.0

Columns = dict[str, np.ndarray]
Map = dict[str, Any]


def rig_columns(trace: emaphm.SimResult) -> Columns:
    """What the rig logs: time [s], command and position [deg], two phase currents [A], angle [deg]."""
    return {
        "time": trace.t.copy(),
        "cmd": np.degrees(trace.theta_cmd),
        "pos": np.degrees(trace.theta_u),
        "Ia": trace.signals["i_a"].copy(),
        "Ib": trace.signals["i_b"].copy(),
        "elec": np.degrees(trace.signals["theta_e"]) - OFFSET_DEG,
    }


def rig_map(offset: Any = '"estimate"', kind: str | None = None) -> Map:
    return {"offset": offset, "kind": kind}


def write_case(folder: Path, name: str, columns: Columns, angle: Map) -> tuple[Path, Path]:
    csv, toml = folder / f"{name}.csv", folder / f"{name}.toml"
    names = list(columns)
    rows = np.column_stack([columns[n] for n in names])
    np.savetxt(csv, rows, delimiter=",", header=",".join(names), comments="", fmt="%.10g")
    kind = f'\nkind = "{angle["kind"]}"' if angle["kind"] else ""
    toml.write_text(
        "[channels]\n"
        't = { name = "time", unit = "s" }\ntheta_cmd = { name = "cmd", unit = "deg" }\n'
        'theta_u = { name = "pos", unit = "deg" }\ni_a = { name = "Ia", unit = "A" }\n'
        'i_b = { name = "Ib", unit = "A" }\ntheta_e = { name = "elec", unit = "deg" }\n'
        f"\n[angle]\noffset = {angle['offset']}{kind}\n"
    )
    return csv, toml


def _window(c: Columns, start: float, length: float) -> np.ndarray:
    return (c["time"] >= start) & (c["time"] < start + length)


def _scaled(names: tuple[str, ...], factor: float) -> Callable[[Columns], Columns]:
    return lambda c: {**c, **{n: factor * c[n] for n in names}}


def _late_start(at: float) -> Callable[[Columns], Columns]:
    return lambda c: {k: v[c["time"] >= at] for k, v in c.items()}


def _rows_missing(at: float) -> Callable[[Columns], Columns]:
    return lambda c: {k: v[~_window(c, at, 0.02)] for k, v in c.items()}


def _currents_frozen(at: float, zeros: bool) -> Callable[[Columns], Columns]:
    def change(c: Columns) -> Columns:
        w = _window(c, at, 0.02)
        first = int(np.argmax(w))
        return {**c, **{n: np.where(w, 0.0 if zeros else c[n][first], c[n]) for n in ("Ia", "Ib")}}

    return change


def _command_late(delay: float) -> Callable[[Columns], Columns]:
    return lambda c: {**c, "cmd": np.interp(c["time"] - delay, c["time"], c["cmd"], left=c["cmd"][0])}


def _swapped(c: Columns) -> Columns:
    return {**c, "Ia": c["Ib"], "Ib": c["Ia"]}


def cases(p: int) -> list[tuple[str, str, Callable[[Columns], Columns], Map]]:
    """(name, kind "control" | "mistake", change of the columns, the map's angle table)."""
    same: Callable[[Columns], Columns] = lambda c: c  # noqa: E731
    return [
        ("control", "control", same, rig_map()),
        ("control_offset_given", "control", same, rig_map(OFFSET_DEG)),
        ("control_offset_mechanical", "control", same, rig_map(OFFSET_DEG / p, "mechanical")),
        *[(f"current_gain_{g:g}", "mistake", _scaled(("Ia", "Ib"), g), rig_map()) for g in (1.05, 0.95, 1.1, 0.9)],
        # beyond the newcomer's: a gain of 7 % and of 3 % (the latter within what a ±2 % ψ_m and the
        # monitor's own scatter allow: `identification/current_scale.py`)
        *[(f"current_gain_{g:g}", "mistake", _scaled(("Ia", "Ib"), g), rig_map()) for g in (1.07, 0.93, 1.03, 0.97)],
        *[(f"starts_at_{t:g}s", "mistake", _late_start(t), rig_map()) for t in (0.1, 0.25, 0.5, 0.75)],
        *[(f"rows_missing_at_{t:g}s", "mistake", _rows_missing(t), rig_map()) for t in (0.25, 0.45)],
        ("dropout_zeros", "mistake", _currents_frozen(0.45, True), rig_map()),
        ("dropout_held", "mistake", _currents_frozen(0.45, False), rig_map()),
        ("offset_in_mechanical_degrees", "mistake", same, rig_map(OFFSET_DEG / p)),
        ("offset_15deg_off", "mistake", same, rig_map(OFFSET_DEG + 15)),
        ("offset_180deg_off", "mistake", same, rig_map(OFFSET_DEG + 180)),
        *[(f"lever_arm_{g:g}", "mistake", _scaled(("cmd", "pos"), g), rig_map()) for g in (0.9, 0.8, 1.1)],
        ("position_only_0.9", "mistake", _scaled(("pos",), 0.9), rig_map()),
        *[(f"command_{1000 * d:g}ms_late", "mistake", _command_late(d), rig_map()) for d in (0.005, 0.01)],
        ("current_sign_flipped", "mistake", _scaled(("Ia", "Ib"), -1.0), rig_map()),
        ("phases_swapped", "mistake", _swapped, rig_map()),
        ("current_in_mA_read_as_A", "mistake", _scaled(("Ia", "Ib"), 1000.0), rig_map()),
        ("command_in_rad_read_as_deg", "mistake", _scaled(("cmd",), math.pi / 180), rig_map()),
    ]


def _rows_missing_for(at: float, length: float) -> Callable[[Columns], Columns]:
    return lambda c: {k: v[~_window(c, at, length)] for k, v in c.items()}


def more_cases() -> list[tuple[str, str, Callable[[Columns], Columns], Map]]:
    """Mistakes of the same kinds at other sizes and places (``--more``): the newcomer's are the
    default list; these check that the answers do not hang on the sizes chosen there."""
    same: Callable[[Columns], Columns] = lambda c: c  # noqa: E731
    return [
        *[(f"starts_at_{t:g}s", "mistake", _late_start(t), rig_map()) for t in (0.05, 0.35)],
        *[(f"rows_missing_50ms_at_{t:g}s", "mistake", _rows_missing_for(t, 0.05), rig_map()) for t in (0.1, 0.7)],
        ("dropout_zeros_at_0.2s", "mistake", _currents_frozen(0.2, True), rig_map()),
        ("dropout_held_at_0.7s", "mistake", _currents_frozen(0.7, False), rig_map()),
        *[(f"offset_{d:g}deg_off", "mistake", same, rig_map(OFFSET_DEG + d)) for d in (5, 30, 90)],
        *[(f"lever_arm_{g:g}", "mistake", _scaled(("cmd", "pos"), g), rig_map()) for g in (0.95, 1.05, 1.2)],
        ("position_only_1.1", "mistake", _scaled(("pos",), 1.1), rig_map()),
        *[(f"command_{1000 * d:g}ms_late", "mistake", _command_late(d), rig_map()) for d in (0.002, 0.003)],
        *[(f"current_gain_{g:g}", "mistake", _scaled(("Ia", "Ib"), g), rig_map()) for g in (1.15, 0.85)],
    ]


def outcome(kind: str, result: emaphm.IdentificationResult | None, err: float | None) -> str:
    if result is None:
        return "refused"
    if result.verdict != "fits":
        return result.verdict
    detected = set(result.detected)
    false = bool(detected - PRESENT) or bool((result.fault_verdicts or {}) and any(
        result.fault_verdicts.get(n) == "absent" for n in PRESENT if n in (result.fault_verdicts or {})))  # fmt: skip
    right = err is not None and err <= GOOD_ERR and not false and PRESENT <= detected
    if right:
        return "right"
    return "CONFIDENT WRONG" if (err is not None and err > GOOD_ERR) or false else "fits, rough"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=7, help="the twin's noise seed")
    parser.add_argument("--only", default=None, help="comma-separated case names")
    parser.add_argument("--out", type=Path, default=None, help="keep the recordings in this folder")
    parser.add_argument("--more", action="store_true", help="also the same kinds of mistake at other sizes")
    add_settings(parser)
    args = parser.parse_args(argv)
    params = emaphm.EmaParams()
    print(machine_line(f"truth {TRUTH.tolist()}, twin noise seed {args.seed}, identify seed 1, default settings"))
    twin = emaphm.simulate(TRUTH, seed=args.seed)
    base = rig_columns(twin)
    chosen = cases(params.motor.p) + (more_cases() if args.more else [])
    if args.only:
        names = set(args.only.split(","))
        chosen = [c for c in chosen if c[0] in names]
    folder = args.out or Path(tempfile.mkdtemp(prefix="rig-mistakes-"))
    folder.mkdir(parents=True, exist_ok=True)
    tally: dict[str, list[str]] = {}
    print(f"{'case':<30} {'kind':<8} {'ended':<14} {'%err':>6} {'fit':>6} {'wall':>5}  detected / reason")
    for name, kind, change, angle in chosen:
        csv, toml = write_case(folder, name, change(dict(base)), angle)
        start = time.perf_counter()
        result, err, said = None, None, ""
        try:
            result = emaphm.identify(reference=csv, channel_map=toml, seed=1, **settings_of(args))
            err = emaphm.percent_error(result.estimate, TRUTH)
            said = ",".join(result.detected) or "-"
            said += "".join(f" | {d[:60]}" for d in result.doubts[:2])
        except InputError as exc:
            said = str(exc)[:110]
        ended = outcome(kind, result, err)
        tally.setdefault(kind, []).append(ended)
        fit = "" if result is None or result.fit_nrmse is None else f"{100 * result.fit_nrmse:.2f}%"
        print(f"{name:<30} {kind:<8} {ended:<14} {'' if err is None else f'{err:.2f}':>6} {fit:>6} "
              f"{time.perf_counter() - start:>5.1f}  {said}", flush=True)  # fmt: skip
    mistakes, controls = tally.get("mistake", []), tally.get("control", [])
    print()
    print(f"mistakes answered with a confident wrong diagnosis: {mistakes.count('CONFIDENT WRONG')} of {len(mistakes)} "
          f"(refused {mistakes.count('refused')}, does not fit {mistakes.count('does not fit')}, doubtful "
          f"{mistakes.count('doubtful')}, right {mistakes.count('right')}, fits but rough {mistakes.count('fits, rough')})")  # fmt: skip
    print(f"controls right with verdict 'fits': {controls.count('right')} of {len(controls)} ({', '.join(controls)})")
    print(f"recordings in {folder}")


if __name__ == "__main__":
    main()
