"""Failure thresholds derived from the HF twin and the requirements the actuator must meet.

A failure threshold is the distance from healthy, in fault units (the names of `FAULTS`:
friction k1, backlash k2, short_a/b/c k3..k5, eccentricity k6, kp_drift |k8 − 0.5|), at which
the actuator first breaks a requirement. `derive_thresholds` finds it for each fault alone (the
others healthy) on the high-fidelity twin, noise off, under a reference command (the FDI chirp
by default); `thresholds_toml` writes the ``[thresholds]`` table of the actuator file that
`emaphm.actuator.load_thresholds` (and ``emaphm rul --params``) reads.

Requirements (`Requirement`, `parse_requirement`), each an upper limit that the actuator meets
while its metric stays below the limit:

- ``tracking``: max |θ_u − θ_cmd| over the reference command [rad], θ_u the surface's true
  position (``theta_u_true``; the measured ``theta_u`` differs by the position ADC's step);
- ``tracking_rms``: the RMS of θ_u − θ_cmd over the reference command [rad];
- ``current``: the peak |i_q,ref| [A], the position loop's quadrature current demand, the signal
  that saturates at ±I_max (the measured ``i_q`` follows it within the hysteresis band and
  ripples past it); ``current=I_max`` means "the demand never saturates", ``0.9 I_max`` a
  margin below it. A limit above I_max is refused: the demand can never reach it;
- ``free_play``: the total free play at the surface [rad], B = B0·(1 + 99·k2) (`emaphm.faults`):
  geometric, so the backlash threshold is solved in closed form, (limit/B0 − 1)/99, without a
  simulation; a limit beyond k2 = 1 gives no threshold, one at or below B0 is refused.

Angles take the units of `emaphm.units.UNITS` (``"0.5 deg"``, ``"2 mrad"``, ``"30 arcmin"``),
currents ``"8 A"`` or ``"8000 mA"``; a bare number is SI.

The search, per fault: the metrics on a grid of `GRID_POINTS` distances over the fault's range
((0, 1], (0, 0.5] for kp_drift), then bisection of the first grid interval where a requirement
breaks, down to `resolution`. The threshold is the upper end of the final interval: the twin
breaks a requirement there, and meets them all at the lower end, less than `resolution` below.
Eccentricity takes the worst case over the phases k7 in `ECCENTRICITY_PHASES`, kp_drift over
both directions (k8 = 0.5 − d, a gain that sags, and 0.5 + d): per requirement, the largest
metric of those cases at each distance. A metric that falls between neighbouring grid points is
reported as a warning: the threshold is then the first crossing the grid finds, and a crossing
between grid points may be missed. A healthy actuator that already breaks a requirement is an
`InputError`: no threshold can be derived from it.
"""

from __future__ import annotations

import math
import os
import re
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
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
from ..units import UNITS, parameter_units, split_quantity, to_si

__all__ = [
    "ECCENTRICITY_PHASES",
    "GRID_POINTS",
    "REQUIREMENT_KINDS",
    "Requirement",
    "derive_thresholds",
    "parse_requirement",
    "thresholds_toml",
]

# kind -> (SI unit, what is measured)
REQUIREMENT_KINDS: dict[str, tuple[str, str]] = {
    "tracking": ("rad", "max |θ_u − θ_cmd| over the reference command"),
    "tracking_rms": ("rad", "RMS of θ_u − θ_cmd over the reference command"),
    "current": ("A", "peak |i_q,ref|, the quadrature current demand (saturates at I_max)"),
    "free_play": ("rad", "total free play at the surface, B = B0·(1 + 99·k2)"),
}
SIMULATED = ("tracking", "tracking_rms", "current")  # the kinds that need the twin
GRID_POINTS = 10  # coarse grid over a fault's range, before the bisection
ECCENTRICITY_PHASES = (0.0, 0.25, 0.5, 0.75)  # k7: the eccentricity's direction, worst case over these
MONOTONE_TOLERANCE = 0.005  # a fall of a metric by more than this fraction between grid points is reported

_I_MAX = re.compile(r"^\s*(?:([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*[*·x×]?\s*)?I_max\s*$")


@dataclass(frozen=True)
class Requirement:
    """One requirement: the actuator meets it while the metric of `kind` stays below `limit`.

    kind : str  one of `REQUIREMENT_KINDS`
    limit : float  the limit in SI (rad or A)
    text : str  the limit as given, e.g. "0.5 deg" or "0.9 I_max"
    unit : str  the unit to show values in ("deg"); default the SI unit
    of_I_max : float or None  for ``current``, the limit as a fraction of I_max, when given so
        (`resolve` sets `limit` from the actuator's I_max)
    """

    kind: str
    limit: float
    text: str = ""
    unit: str = ""
    of_I_max: float | None = None

    def __post_init__(self) -> None:
        if self.kind not in REQUIREMENT_KINDS:
            raise InputError(f"unknown requirement {self.kind!r}; choose from {', '.join(REQUIREMENT_KINDS)}")
        limit = self.limit
        if isinstance(limit, bool) or not (
            isinstance(limit, (int, float)) and math.isfinite(limit) and limit > 0
        ):
            raise InputError(
                f"requirement {self.kind}: the limit must be a finite number > 0, got {self.limit!r}"
            )
        si = self.si_unit
        if self.unit and self.unit not in parameter_units(si):
            raise InputError(
                f"requirement {self.kind}: unit {self.unit!r} is not one of {', '.join(parameter_units(si))}"
            )
        object.__setattr__(self, "limit", float(self.limit))
        object.__setattr__(self, "unit", self.unit or si)
        object.__setattr__(self, "text", self.text or f"{self.limit:g} {si}")

    @property
    def si_unit(self) -> str:
        """The SI unit of the limit and the metric."""
        return REQUIREMENT_KINDS[self.kind][0]

    @property
    def scale(self) -> float:
        """SI value of one `unit`: a value in `unit` is the SI value / scale."""
        return UNITS[self.si_unit][self.unit]

    def show(self, value: float) -> str:
        """`value` (SI) in the requirement's unit, e.g. "1.43 deg"."""
        return f"{value / self.scale:.4g} {self.unit}"

    def resolve(self, params: EmaParams) -> Requirement:
        """This requirement for the actuator `params`: a fraction of I_max becomes amperes.

        `InputError` for a current limit above I_max (the demand saturates there, it can never
        be reached).
        """
        req = self
        if self.of_I_max is not None:
            req = replace(self, limit=self.of_I_max * params.controller.I_max)
        if req.kind == "current" and req.limit > params.controller.I_max * (1.0 + 1e-12):
            raise InputError(
                f"requirement current = {req.text}: above I_max = {params.controller.I_max:g} A, where the "
                "current demand saturates: it can never be reached; give at most I_max"
            )
        return req

    def to_json(self) -> dict[str, Any]:
        """The requirement as recorded in a result."""
        return {
            "kind": self.kind, "limit": self.limit, "si_unit": self.si_unit, "text": self.text,
            "unit": self.unit, "scale": self.scale, "of_I_max": self.of_I_max,
            "metric": REQUIREMENT_KINDS[self.kind][1],
        }  # fmt: skip


def parse_requirement(text: str, *, params: EmaParams | None = None, where: str = "--require") -> Requirement:
    """A `Requirement` from ``KIND=LIMIT``: ``"tracking=0.5 deg"``, ``"tracking_rms=2mrad"``,
    ``"current=I_max"``, ``"current=0.9 I_max"``, ``"current=8 A"``, ``"free_play=1.5 mrad"``.

    A bare number is SI; a fraction of I_max is taken of `params` (default: the nominal
    actuator; `derive_thresholds` resolves it again for its own), and a current limit above
    I_max is refused when `params` is given (`derive_thresholds` checks it in any case).
    `InputError` naming `where` for an unknown kind, a unit of another kind, or a limit that is
    not > 0.
    """
    if not isinstance(text, str) or "=" not in text:
        raise InputError(f"{where}: {text!r} must be KIND=LIMIT, e.g. tracking=0.5deg")
    kind, raw = (s.strip() for s in text.split("=", 1))
    if kind not in REQUIREMENT_KINDS:
        raise InputError(f"{where}: unknown requirement {kind!r}; choose from {', '.join(REQUIREMENT_KINDS)}")
    if not raw:
        raise InputError(f"{where}: {kind} has no limit, e.g. {kind}={_EXAMPLES[kind]}")
    si = REQUIREMENT_KINDS[kind][0]
    if "I_max" in raw:
        match = _I_MAX.match(raw)
        if kind != "current" or match is None:
            raise InputError(
                f"{where}: {kind} = {raw!r}: I_max is a current: write current=I_max or 0.9 I_max"
            )
        fraction = float(match.group(1)) if match.group(1) is not None else 1.0
        if not (math.isfinite(fraction) and fraction > 0):
            raise InputError(f"{where}: current = {raw!r}: the fraction of I_max must be > 0")
        req = Requirement(kind, fraction, raw, "A", of_I_max=fraction)
        return req.resolve(params if params is not None else EmaParams())
    value = float(to_si(raw, kind, si, where))
    if not (math.isfinite(value) and value > 0):
        raise InputError(f"{where}: {kind} = {raw!r}: the limit must be a finite number > 0")
    parsed = split_quantity(raw)  # to_si parsed it: a number, then a unit of the kind or none
    unit = parsed[1] if parsed is not None and parsed[1] else si
    req = Requirement(kind, value, raw, unit)
    return req.resolve(params) if params is not None else req


_EXAMPLES = {"tracking": "0.5deg", "tracking_rms": "0.2deg", "current": "I_max", "free_play": "1.5mrad"}


def _fault_vector(name: str, d: float, case: float) -> NDArray[np.float64]:
    """The fault vector with fault `name` at distance `d` from healthy, the others healthy;
    `case` is the eccentricity's phase k7, or the direction (±1) of the gain drift."""
    k = HEALTHY.copy()
    j = int(FAULTS[name][0][1:]) - 1
    if name == "kp_drift":
        k[j] = 0.5 + case * d
    else:
        k[j] = d
    if name == "eccentricity":
        k[6] = case
    return k


def _cases(name: str) -> tuple[tuple[str, float], ...]:
    """The (label, case) pairs whose worst case a fault's metrics are."""
    if name == "eccentricity":
        return tuple((f"k7 = {phase:g}", phase) for phase in ECCENTRICITY_PHASES)
    if name == "kp_drift":
        return (("k8 = 0.5 - d", -1.0), ("k8 = 0.5 + d", 1.0))
    return (("", 0.0),)


def _span(name: str) -> float:
    """The largest distance from healthy the fault can take."""
    return 0.5 if name == "kp_drift" else 1.0


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
    reqs = _requirements(requirements, actuator)
    names = list(FAULTS) if faults is None else [faults] if isinstance(faults, str) else list(faults)
    for name in names:
        if name not in FAULTS:
            raise InputError(f"unknown fault {name!r}; choose from {', '.join(FAULTS)}")
    if len(set(names)) != len(names) or not names:
        raise InputError(f"faults must be distinct names of {', '.join(FAULTS)}, got {names}")
    if not (isinstance(resolution, (int, float)) and 0 < resolution <= 0.1):
        raise InputError(f"resolution must be in (0, 0.1] fault units, got {resolution!r}")
    simulated = [r for r in reqs if r.kind in SIMULATED]
    by_kind = {r.kind: r for r in reqs}
    model = HighFidelityEma(actuator, cmd)
    model.sample_grid()  # a command the twin cannot run: refused before the work

    # the work, in simulations: the healthy run, then per fault its grid and its bisection
    steps = {n: _bisection_steps(_span(n) / GRID_POINTS, resolution) for n in names}
    plan = {n: len(_cases(n)) * (GRID_POINTS + steps[n]) + (n == "backlash") for n in names}
    total = (1 + sum(plan.values())) if simulated else 0
    count = {"done": 0, "simulations": 0}

    def tick(step: int = 1) -> None:
        count["done"] = min(count["done"] + step, total)
        if progress is not None:
            progress(count["done"], total)

    def measure(k: NDArray[np.float64]) -> dict[str, float]:
        out: dict[str, float] = {}
        if simulated:
            result = model.simulate(k, noise=False, seed=0)
            count["simulations"] += 1
            error = result.theta_u_true - result.theta_cmd
            out["tracking"] = float(np.max(np.abs(error)))
            out["tracking_rms"] = float(np.sqrt(np.mean(error**2)))
            out["current"] = float(np.max(np.abs(result.i_q_ref)))
            tick()
        out["free_play"] = apply_faults(k, actuator).B
        return {r.kind: out[r.kind] for r in reqs}

    healthy = measure(HEALTHY)
    for r in reqs:
        if healthy[r.kind] >= r.limit:
            where = "" if r.kind == "free_play" else f" on the {command_record(cmd)['type']} command"
            raise InputError(
                f"requirement {r.kind} = {r.text}: the healthy actuator already reaches "
                f"{r.show(healthy[r.kind])}{where} ({REQUIREMENT_KINDS[r.kind][1]}); "
                "a threshold needs a limit above the healthy value"
            )

    warnings: list[str] = []
    results: dict[str, Any] = {}
    for name in names:
        done_before = count["done"]
        entry: dict[str, Any] = {"threshold": None, "limited_by": None, "at_threshold": None, "case": None,
                                 "met_below": None, "grid": None, "monotone": None}  # fmt: skip
        if simulated:
            entry.update(_search(name, reqs, simulated, healthy, measure, resolution, steps[name], warnings))
        if name == "backlash" and "free_play" in by_kind:
            _free_play(entry, by_kind["free_play"], actuator, simulated, measure)
        status = _status(name, entry, simulated, set(by_kind))
        results[name] = {"column": FAULTS[name][0], "range": [0.0, _span(name)], "status": status, **entry,
                         "healthy": dict(healthy)}  # fmt: skip
        if entry["threshold"] is None:
            results[name]["rul_placeholder"] = PLACEHOLDER_THRESHOLDS[name]
        if simulated:
            tick(done_before + plan[name] - count["done"])  # the bisection steps not needed
    if progress is not None and total:
        progress(total, total)
    return {
        "requirements": [r.to_json() for r in reqs],
        "command": command_record(cmd),
        "params_hash": params_hash(actuator),
        "resolution": float(resolution),
        "healthy": healthy,
        "faults": results,
        "warnings": warnings,
        "simulations": count["simulations"],
        "wall_time_s": round(time.perf_counter() - start, 3),
        "version": __version__,
    }


def _requirements(requirements: Sequence[Requirement | str], params: EmaParams) -> list[Requirement]:
    if isinstance(requirements, (str, Requirement)):
        requirements = [requirements]
    reqs = [
        r.resolve(params) if isinstance(r, Requirement) else parse_requirement(r, params=params)
        for r in requirements
    ]
    if not reqs:
        kinds = ", ".join(REQUIREMENT_KINDS)
        raise InputError(f"give at least one requirement, e.g. tracking=0.5deg (kinds: {kinds})")
    seen: set[str] = set()
    for r in reqs:
        if r.kind in seen:
            raise InputError(f"requirement {r.kind} is given twice: give one limit per kind")
        seen.add(r.kind)
    return reqs


def _bisection_steps(width: float, resolution: float) -> int:
    """Halvings that bring an interval of `width` down to `resolution` or less."""
    return max(0, math.ceil(math.log2(width / resolution) - 1e-12))


def _search(
    name: str,
    reqs: list[Requirement],
    simulated: list[Requirement],
    healthy: dict[str, float],
    measure: Callable[[NDArray[np.float64]], dict[str, float]],
    resolution: float,
    steps: int,
    warnings: list[str],
) -> dict[str, Any]:
    """Grid, then bisection, of the simulated requirements for one fault (see the module docstring)."""
    cases = _cases(name)

    def worst(d: float) -> tuple[dict[str, float], dict[str, str]]:
        runs = [(label, measure(_fault_vector(name, d, case))) for label, case in cases]
        metrics, which = {}, {}
        for r in reqs:
            label, m = max(runs, key=lambda run: run[1][r.kind])
            metrics[r.kind], which[r.kind] = m[r.kind], label
        return metrics, which

    def broken(metrics: dict[str, float]) -> list[Requirement]:
        return [r for r in simulated if metrics[r.kind] >= r.limit]

    span = _span(name)
    distances = [span * (i + 1) / GRID_POINTS for i in range(GRID_POINTS)]
    grid = [worst(d) for d in distances]
    values = {r.kind: [m[r.kind] for m, _ in grid] for r in reqs}
    monotone = _monotone(
        name, [0.0, *distances], simulated, {k: [healthy[k], *v] for k, v in values.items()}, warnings
    )
    found: dict[str, Any] = {"grid": {"distance": distances, **values}, "monotone": monotone}
    first = next((i for i, (m, _) in enumerate(grid) if broken(m)), None)
    if first is None:
        return found
    lo = distances[first - 1] if first > 0 else 0.0
    hi, (at, which) = distances[first], grid[first]
    for _ in range(steps):
        if hi - lo <= resolution:
            break
        mid = 0.5 * (lo + hi)
        m, w = worst(mid)
        if broken(m):
            hi, at, which = mid, m, w
        else:
            lo = mid
    limiting = max(broken(at), key=lambda r: at[r.kind] / r.limit)
    return {
        "threshold": hi, "limited_by": limiting.kind, "at_threshold": at,
        "case": which[limiting.kind] or None, "met_below": lo, **found,
    }  # fmt: skip


def _monotone(
    name: str,
    distances: list[float],
    simulated: list[Requirement],
    values_by_kind: dict[str, list[float]],
    warnings: list[str],
) -> dict[str, bool]:
    """Whether each metric grows (within `MONOTONE_TOLERANCE`) from healthy over the grid; a
    warning for each one that falls."""
    out = {}
    for r in simulated:
        values = values_by_kind[r.kind]
        falls = [i for i in range(1, len(values)) if values[i] < values[i - 1] * (1.0 - MONOTONE_TOLERANCE)]
        out[r.kind] = not falls
        if falls:
            i = falls[0]
            warnings.append(
                f"{name}: {r.kind} is not monotone on the grid: it falls from {r.show(values[i - 1])} at "
                f"d = {distances[i - 1]:g} to {r.show(values[i])} at d = {distances[i]:g}"
                + (f" (and {len(falls) - 1} more fall(s))" if len(falls) > 1 else "")
                + "; the threshold is the first crossing found, one between grid points may be missed"
            )
    return out


def _free_play(
    entry: dict[str, Any],
    req: Requirement,
    params: EmaParams,
    simulated: list[Requirement],
    measure: Callable[[NDArray[np.float64]], dict[str, float]],
) -> None:
    """The backlash threshold of the free-play requirement, in closed form: B0·(1 + 99·k2) = limit.

    It replaces the simulated threshold when it comes first; the twin is then run once there,
    for the other requirements' metrics at the threshold.
    """
    B0 = params.transmission.B0
    d = (req.limit / B0 - 1.0) / 99.0 if B0 > 0 else math.inf
    entry["free_play_reached_at"] = d if math.isfinite(d) else None
    if d > 1.0 or (entry["threshold"] is not None and entry["threshold"] <= d):
        return
    at = measure(_fault_vector("backlash", d, 0.0)) if simulated else {"free_play": req.limit}
    at["free_play"] = req.limit  # B(d) = limit exactly (the mapping's rounding aside)
    entry.update(threshold=d, limited_by="free_play", at_threshold=at, case=None, met_below=None)


def _status(name: str, entry: dict[str, Any], simulated: list[Requirement], kinds: set[str]) -> str:
    if entry["threshold"] is not None:
        return "derived"
    if not simulated and not (name == "backlash" and "free_play" in kinds):
        return "no requirement given depends on this fault"
    span = _span(name)
    column = FAULTS[name][0]
    reach = f"|k8 - 0.5| = {span:g}" if name == "kp_drift" else f"{column} = {span:g}"
    return f"no requirement reached up to {reach}, the end of its range"


def _decimals(resolution: float) -> int:
    """Decimals that show a distance to `resolution`: 3 for 0.005, 2 for 0.01."""
    return max(1, math.ceil(-math.log10(resolution) - 1e-9))


def _round_down(value: float, resolution: float) -> str:
    """`value` rounded down to the decimals of `resolution` (a threshold errs early), as TOML."""
    decimals = _decimals(resolution)
    rounded = math.floor(value * 10**decimals + 1e-9) / 10**decimals
    if rounded <= 0.0:  # a threshold below the resolution's last decimal: two significant digits
        decimals = 1 - math.floor(math.log10(value))
        rounded = math.floor(value * 10**decimals) / 10**decimals
    text = f"{rounded:.{decimals}f}".rstrip("0")
    return text + "0" if text.endswith(".") else text


def _show(req: dict[str, Any], value: float) -> str:
    return f"{value / req['scale']:.4g} {req['unit']}"


def thresholds_toml(result: dict[str, Any]) -> str:
    """The ``[thresholds]`` table of a `derive_thresholds` result, to paste into the actuator file.

    Only the faults with a threshold, each rounded down to the decimals of the resolution (a
    threshold that errs, errs early) and commented with the requirement that limits it; the
    header names the actuator, the command, the requirements, and the faults left out (for which
    ``emaphm rul`` falls back to its placeholders). `emaphm.actuator.load_thresholds` reads it.
    """
    reqs = {r["kind"]: r for r in result["requirements"]}
    given = ", ".join(f"{r['kind']} = {r['text']}" for r in result["requirements"])
    lines = [
        f"# failure thresholds derived by 'emaphm thresholds' (emaphm {result['version']}), actuator "
        f"{result['params_hash']}, {result['command']['type']} command",
        f"# requirements: {given}",
        f"# distances from healthy in fault units, rounded down to {_decimals(result['resolution'])} decimals "
        f"(resolution {result['resolution']:g})",
    ]
    left_out = [name for name, f in result["faults"].items() if f["threshold"] is None]
    if left_out:
        lines.append(
            "# no threshold derived (emaphm rul uses its placeholders there, not limits): "
            + ", ".join(left_out)
        )
    lines.append("[thresholds]")
    entries = []
    for name, f in result["faults"].items():
        if f["threshold"] is None:
            continue
        req = reqs[f["limited_by"]]
        reached = _show(req, f["at_threshold"][req["kind"]])
        comment = f"limited by {req['kind']} < {req['text']} ({reached} there)" + (
            f", worst case {f['case']}" if f["case"] else ""
        )
        entries.append((f"{name} = {_round_down(f['threshold'], result['resolution'])}", comment))
    width = max((len(e) for e, _ in entries), default=0)
    lines += [f"{e.ljust(width)}  # {c}" for e, c in entries]
    return "\n".join(lines) + "\n"
