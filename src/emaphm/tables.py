"""The per-fault tables of a diagnosis: the fault vector (`fault_rows`, shared by ``emaphm identify``
and ``emaphm demo``) and the faults in physical units (`physical_faults`, `physical_rows`, for the
report a planner reads)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from rich.table import Table

if TYPE_CHECKING:
    from .params import EmaParams

__all__ = [
    "HEALTHY_OF", "direction_note", "fault_rows", "fault_table", "physical_faults", "physical_rows",
    "short_physical",
]  # fmt: skip

# each fault but the eccentricity direction (k7) as a distance from healthy: column -> healthy value
HEALTHY_OF: dict[str, tuple[int, float]] = {
    "friction": (0, 0.0), "backlash": (1, 0.0), "short_a": (2, 0.0), "short_b": (3, 0.0),
    "short_c": (4, 0.0), "eccentricity": (5, 0.0), "kp_drift": (7, 0.5),
}  # fmt: skip


def fault_rows(data: dict[str, Any]) -> tuple[list[str], list[list[str]]]:
    """The column names and the text rows of the per-fault table of an identification's JSON
    (`IdentificationResult.to_json`): one row per fault with its value, the ± half-width,
    interval and flags of its 90 % interval when there is one, the true value when known, and
    its verdict (present / absent / cannot tell; "-" when the monitor does not explain the
    recording)."""
    from .identification.uncertainty import half_widths

    intervals = data["ci90_low"] is not None
    columns = ["fault", "identified"]
    if intervals:
        columns += ["± half-width", "90 % interval", "flags"]
        half = half_widths(data["ci90_low"], data["ci90_high"])
    if data["truth"] is not None:
        columns.append("true")
    columns.append("verdict")
    verdicts = data.get("fault_verdicts") or {}
    rows = []
    for i, name in enumerate(data["fault_names"]):
        row = [f"k{i + 1} {name}", f"{data['estimate'][i]:.4f}"]
        if intervals:
            lo, hi = data["ci90_low"][i], data["ci90_high"][i]
            whole = name == "eccentricity_phase" and (lo, hi) == (0.0, 1.0)
            row += [
                f"{half[i]:.4f}",
                "whole circle" if whole else f"[{lo:.4f}, {hi:.4f}]",
                " ".join(data["uq_flags"][i]),
            ]
        if data["truth"] is not None:
            row.append(f"{data['truth'][i]:.4f}")
        if data["verdict"] == "does not fit":
            row.append("-")
        elif verdicts:
            row.append(verdicts.get(name, "(direction)"))
        else:
            row.append("present" if name in data["detected"] else "-")
        rows.append(row)
    return columns, rows


def fault_table(data: dict[str, Any], title: str) -> Table:
    """The per-fault table (`fault_rows`) as a rich table."""
    columns, rows = fault_rows(data)
    table = Table(title=title)
    for name in columns:
        table.add_column(name, justify="left" if name in ("fault", "flags", "verdict") else "right")
    for row in rows:
        table.add_row(*row)
    return table


def physical_faults(
    estimate: Sequence[float], params: EmaParams | None = None
) -> dict[str, dict[str, float]]:
    """Each fault of the fault vector `estimate` in the physical units of the actuator `params`
    (default: the nominal one), by the DESIGN §2 mapping (`faults.fault_parameter_columns`).

    friction: ``F_S``, ``F_D`` [N·m] and ``times_nominal`` (1 + 2·k1); backlash: ``B_mrad`` [mrad]
    and ``times_nominal`` (1 + 99·k2); short_a/b/c: ``shorted_percent`` (100·(1 − N), N the
    fraction of healthy turns kept); eccentricity: ``zeta_percent`` (100·ζ) and its direction
    ``phi_e_deg`` [electrical deg]; kp_drift: ``K_P`` [A/rad] and ``drift_percent`` (100·(k8 − 0.5),
    the drift of K_P in % of K_P0).
    """
    import numpy as np

    from .faults import as_fault_vector, fault_parameter_columns
    from .params import EmaParams

    k = as_fault_vector(estimate, name="estimate")
    col = {n: float(v[0]) for n, v in fault_parameter_columns(k[None, :], params or EmaParams()).items()}
    shorts = {f"short_{p.lower()}": {"shorted_percent": 100.0 * (1.0 - col[f"N_{p}"])} for p in "ABC"}
    return {
        "friction": {"F_S": col["F_S"], "F_D": col["F_D"], "times_nominal": 1.0 + 2.0 * k[0]},
        "backlash": {"B_mrad": 1e3 * col["B"], "times_nominal": 1.0 + 99.0 * k[1]},
        **shorts,
        "eccentricity": {"zeta_percent": 100.0 * col["zeta"], "phi_e_deg": float(np.degrees(col["phi_e"]))},
        "kp_drift": {"K_P": col["K_P"], "drift_percent": 100.0 * (k[7] - 0.5)},
    }


def _physical_text(name: str, v: dict[str, float], direction_defined: bool = True) -> str:
    """One fault's physical values (`physical_faults`) as the report writes them."""
    if name == "friction":
        return f"F_S {v['F_S']:.4g} N·m ({v['times_nominal']:.2f} × nominal)"
    if name == "backlash":
        return f"B {v['B_mrad']:.3g} mrad ({v['times_nominal']:.1f} × nominal)"
    if name.startswith("short_"):
        return f"{v['shorted_percent']:.1f} % of phase {name[-1].upper()}'s turns shorted"
    if name == "eccentricity":
        way = f"{v['phi_e_deg']:.0f}° electrical" if direction_defined else "undefined (too small)"
        return f"ζ {v['zeta_percent']:.1f} % (relative); direction {way}"
    return f"K_P {v['K_P']:.4g} A/rad ({v['drift_percent']:+.1f} % of K_P0)"


def physical_rows(
    data: dict[str, Any],
    params: EmaParams | None = None,
    *,
    detection: Mapping[str, float] | None = None,
    failure: Mapping[str, float] | None = None,
) -> tuple[list[str], list[list[str]]]:
    """The column names and text rows of the faults in physical units of an identification's JSON
    (`IdentificationResult.to_json`) for the actuator `params`: one row per fault but the
    eccentricity direction (k7, written with the eccentricity), with k, its distance from healthy
    (K_P drift signed) and 90 % interval, the physical value (`physical_faults`), the `detection`
    threshold and, when given, the `failure` threshold (both distances from healthy, fault units;
    the failure threshold "(exceeded)" when the distance is past it) and the verdict ("-" for a
    result that does not fit)."""
    values = physical_faults(data["estimate"], params)
    intervals = data["ci90_low"] is not None
    columns = ["fault", "k", "from healthy", *(["90 % interval"] * intervals), "in physical units"]
    columns += ["detection threshold", *(["failure threshold"] * (failure is not None)), "verdict"]
    verdicts = data.get("fault_verdicts") or {}
    undefined = bool(data["uq_flags"]) and "phase_undefined" in data["uq_flags"][6]
    rows = []
    for name, (i, healthy) in HEALTHY_OF.items():
        k = data["estimate"][i]
        distance = k - healthy
        row = [
            f"k{i + 1} {name}",
            f"{k:.4f}",
            f"{distance:+.4f}" if name == "kp_drift" else f"{distance:.4f}",
        ]
        if intervals:
            lo, hi = data["ci90_low"][i] - healthy, data["ci90_high"][i] - healthy
            row.append(f"[{lo:+.4f}, {hi:+.4f}]" if name == "kp_drift" else f"[{lo:.4f}, {hi:.4f}]")
        row.append(_physical_text(name, values[name], not undefined))
        row.append(_threshold(detection, name, None))
        if failure is not None:
            row.append(_threshold(failure, name, distance))
        if data["verdict"] == "does not fit":
            row.append("-")
        else:
            row.append(verdicts.get(name) or ("present" if name in data["detected"] else "-"))
        rows.append(row)
    return columns, rows


def _threshold(thresholds: Mapping[str, float] | None, name: str, distance: float | None) -> str:
    """A threshold's cell: its value, "(exceeded)" when `distance` is given and past it, "-" when
    there is none."""
    value = (thresholds or {}).get(name)
    if value is None or not math.isfinite(value):
        return "-"
    return f"{value:.4g}" + (" (exceeded)" if distance is not None and abs(distance) > value else "")


def short_physical(name: str, v: dict[str, float]) -> str:
    """One fault's physical value (`tables.physical_faults`) in a few characters, for a figure's axis."""
    if name == "friction":
        return f"{v['times_nominal']:.2f} × F_S0"
    if name == "backlash":
        return f"{v['B_mrad']:.3g} mrad"
    if name.startswith("short_"):
        return f"{v['shorted_percent']:.1f} % shorted"
    if name == "eccentricity":
        return f"ζ {v['zeta_percent']:.1f} %"
    return f"K_P {v['drift_percent']:+.1f} %"


def direction_note(data: dict[str, Any], values: dict[str, dict[str, float]]) -> str:
    """The eccentricity's direction (k7) as text: a direction, not a distance from healthy."""
    k7 = data["estimate"][6]
    if data["uq_flags"] and "phase_undefined" in data["uq_flags"][6]:
        return f"eccentricity direction (k7 = {k7:.3f}): undefined, the eccentricity is too small"
    return f"eccentricity direction (k7 = {k7:.3f}): {values['eccentricity']['phi_e_deg']:.0f}° electrical"
