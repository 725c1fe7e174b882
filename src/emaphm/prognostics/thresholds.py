"""Failure thresholds derived from the HF twin and the requirements the actuator must meet.

A failure threshold is the distance from healthy, in fault units (the names of `FAULTS`:
friction k1, backlash k2, short_a/b/c k3..k5, eccentricity k6, kp_drift |k8 − 0.5|), at which
the actuator first breaks a requirement (`Requirement`, `parse_requirement`: tracking error,
current demand, free play; `emaphm.prognostics.requirements`). `derive_thresholds` finds it for
each fault alone (the others healthy) on the high-fidelity twin, noise off, under a reference
command (the FDI chirp by default), by a grid and a bisection (`emaphm.prognostics.threshold_search`);
`thresholds_toml` (`emaphm.prognostics.threshold_table`) writes the ``[thresholds]`` table of the
actuator file that `emaphm.actuator.load_thresholds` (and ``emaphm rul --params``) reads.

Free play is geometric, B = B0·(1 + 99·k2), so the backlash threshold of a free-play
requirement is solved in closed form, (limit/B0 − 1)/99, without a simulation; a limit beyond
k2 = 1 gives no threshold, one at or below B0 is refused. A metric that falls between
neighbouring grid points is reported as a warning: the threshold is then the first crossing
the grid finds, and a crossing between grid points may be missed. A healthy actuator that
already breaks a requirement is an `InputError`: no threshold can be derived from it.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .._version import __version__
from ..actuator import resolve_params
from ..commands import Chirp, Command, command_record, make_command
from ..errors import InputError
from ..failure import FAULTS, PLACEHOLDER_THRESHOLDS
from ..faults import HEALTHY, apply_faults
from ..params import EmaParams
from .requirements import REQUIREMENT_KINDS, SIMULATED, Requirement, parse_requirement, resolve_requirements
from .threshold_search import (
    ECCENTRICITY_PHASES,
    GRID_POINTS,
    bisection_steps,
    fault_cases,
    fault_span,
    free_play_threshold,
    search,
)
from .threshold_table import thresholds_toml

__all__ = [
    "ECCENTRICITY_PHASES",
    "GRID_POINTS",
    "REQUIREMENT_KINDS",
    "Requirement",
    "derive_thresholds",
    "parse_requirement",
    "thresholds_toml",
]


def derive_thresholds(
    requirements: Sequence[Requirement | str],
    *,
    params: EmaParams | str | os.PathLike[str] | None = None,
    command: Command | str | None = None,
    faults: Sequence[str] | None = None,
    resolution: float = 0.005,
    progress: Callable[[int, int], None] | None = None,
) -> dict[str, Any]:
    """The failure threshold of each fault under `requirements` (see the module docstring), JSON-ready.

    Parameters
    ----------
    requirements : Requirement or "KIND=LIMIT" strings
        At least one; one per kind.
    params : EmaParams or path of an actuator file, optional
        The actuator (default: the nominal one).
    command : Command or its name, optional
        The reference command (default: the FDI chirp, `Chirp`).
    faults : names of `FAULTS`, optional
        The faults to derive (default: all).
    resolution : float
        Width of the final bisection interval, in fault units (0 < resolution <= 0.1).
    progress : callable(done, total), optional
        Called after each simulation (``total`` is an upper bound; the last call has done == total).

    Returns
    -------
    dict with ``requirements``, ``command``, ``params_hash``, ``resolution``, ``healthy`` (each
    requirement's metric, healthy, in SI), ``faults`` (per fault: ``column``, ``range``,
    ``status``, ``threshold`` or None, ``limited_by`` (the requirement's kind), ``at_threshold``
    (every metric there), ``case`` (the worst case there: k7 or the drift's direction),
    ``met_below`` (a distance, less than `resolution` below, where every requirement is met),
    ``grid`` (the coarse grid's distances and metrics), ``monotone`` (per simulated
    requirement), ``healthy``; for backlash under a free-play requirement
    ``free_play_reached_at``, the closed-form k2; for a fault without a threshold
    ``rul_placeholder``, the placeholder ``emaphm rul`` falls back to), ``warnings``,
    ``simulations``, ``wall_time_s``, ``version``.
    """
    from ..calibration import params_hash
    from ..models import HighFidelityEma

    start = time.perf_counter()
    actuator = resolve_params(params)
    cmd: Command = (
        Chirp() if command is None else make_command(command) if isinstance(command, str) else command
    )
    reqs = resolve_requirements(requirements, actuator)
    names = _fault_names(faults)
    if not (isinstance(resolution, (int, float)) and 0 < resolution <= 0.1):
        raise InputError(f"resolution must be in (0, 0.1] fault units, got {resolution!r}")
    simulated = [r for r in reqs if r.kind in SIMULATED]
    by_kind = {r.kind: r for r in reqs}
    model = HighFidelityEma(actuator, cmd)
    model.sample_grid()  # a command the twin cannot run: refused before the work

    # the work, in simulations: the healthy run, then per fault its grid and its bisection
    steps = {n: bisection_steps(fault_span(n) / GRID_POINTS, resolution) for n in names}
    plan = {n: len(fault_cases(n)) * (GRID_POINTS + steps[n]) + (n == "backlash") for n in names}
    twin = _Twin(model, actuator, reqs, (1 + sum(plan.values())) if simulated else 0, progress)
    healthy = twin.measure(HEALTHY)
    _check_healthy(reqs, healthy, cmd)
    warnings: list[str] = []
    results: dict[str, Any] = {}
    for name in names:
        done_before = twin.done
        results[name] = _fault_result(
            name, twin, simulated, by_kind, healthy, resolution, steps[name], warnings
        )
        if simulated:
            twin.tick(done_before + plan[name] - twin.done)  # the bisection steps not needed
    if progress is not None and twin.total:
        progress(twin.total, twin.total)
    return {
        "requirements": [r.to_json() for r in reqs], "command": command_record(cmd),
        "params_hash": params_hash(actuator), "resolution": float(resolution), "healthy": healthy,
        "faults": results, "warnings": warnings, "simulations": twin.simulations,
        "wall_time_s": round(time.perf_counter() - start, 3), "version": __version__,
    }  # fmt: skip


def _fault_names(faults: Sequence[str] | str | None) -> list[str]:
    names = list(FAULTS) if faults is None else [faults] if isinstance(faults, str) else list(faults)
    for name in names:
        if name not in FAULTS:
            raise InputError(f"unknown fault {name!r}; choose from {', '.join(FAULTS)}")
    if len(set(names)) != len(names) or not names:
        raise InputError(f"faults must be distinct names of {', '.join(FAULTS)}, got {names}")
    return names


class _Twin:
    """The twin's runs of one derivation: the metrics of a fault vector, counted, with progress."""

    def __init__(
        self,
        model: Any,
        actuator: EmaParams,
        reqs: list[Requirement],
        total: int,
        progress: Callable[[int, int], None] | None,
    ) -> None:
        self.model, self.actuator, self.reqs = model, actuator, reqs
        self.simulated = [r for r in reqs if r.kind in SIMULATED]
        self.total, self.progress = total, progress
        self.done = 0
        self.simulations = 0

    def tick(self, step: int = 1) -> None:
        self.done = min(self.done + step, self.total)
        if self.progress is not None:
            self.progress(self.done, self.total)

    def measure(self, k: NDArray[np.float64]) -> dict[str, float]:
        """Every requirement's metric at the fault vector `k` (SI)."""
        out: dict[str, float] = {}
        if self.simulated:
            result = self.model.simulate(k, noise=False, seed=0)
            self.simulations += 1
            error = result.theta_u_true - result.theta_cmd
            out["tracking"] = float(np.max(np.abs(error)))
            out["tracking_rms"] = float(np.sqrt(np.mean(error**2)))
            out["current"] = float(np.max(np.abs(result.i_q_ref)))
            self.tick()
        out["free_play"] = apply_faults(k, self.actuator).B
        return {r.kind: out[r.kind] for r in self.reqs}


def _check_healthy(reqs: list[Requirement], healthy: dict[str, float], cmd: Command) -> None:
    """`InputError` when the healthy actuator already breaks a requirement."""
    for r in reqs:
        if healthy[r.kind] >= r.limit:
            where = "" if r.kind == "free_play" else f" on the {command_record(cmd)['type']} command"
            raise InputError(
                f"requirement {r.kind} = {r.text}: the healthy actuator already reaches "
                f"{r.show(healthy[r.kind])}{where} ({REQUIREMENT_KINDS[r.kind][1]}); "
                "a threshold needs a limit above the healthy value"
            )


def _fault_result(
    name: str,
    twin: _Twin,
    simulated: list[Requirement],
    by_kind: dict[str, Requirement],
    healthy: dict[str, float],
    resolution: float,
    steps: int,
    warnings: list[str],
) -> dict[str, Any]:
    """One fault's entry of the result: its threshold by the search and, for backlash, free play."""
    entry: dict[str, Any] = {"threshold": None, "limited_by": None, "at_threshold": None, "case": None,
                             "met_below": None, "grid": None, "monotone": None}  # fmt: skip
    if simulated:
        entry.update(search(name, twin.reqs, simulated, healthy, twin.measure, resolution, steps, warnings))
    if name == "backlash" and "free_play" in by_kind:
        free_play_threshold(entry, by_kind["free_play"], twin.actuator, simulated, twin.measure)
    status = _status(name, entry, simulated, set(by_kind))
    result = {"column": FAULTS[name][0], "range": [0.0, fault_span(name)], "status": status, **entry,
              "healthy": dict(healthy)}  # fmt: skip
    if entry["threshold"] is None:
        result["rul_placeholder"] = PLACEHOLDER_THRESHOLDS[name]
    return result


def _status(name: str, entry: dict[str, Any], simulated: list[Requirement], kinds: set[str]) -> str:
    if entry["threshold"] is not None:
        return "derived"
    if not simulated and not (name == "backlash" and "free_play" in kinds):
        return "no requirement given depends on this fault"
    span = fault_span(name)
    column = FAULTS[name][0]
    reach = f"|k8 - 0.5| = {span:g}" if name == "kp_drift" else f"{column} = {span:g}"
    return f"no requirement reached up to {reach}, the end of its range"
