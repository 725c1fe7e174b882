"""The requirements an actuator must meet, as ``KIND=LIMIT`` (``emaphm thresholds --require``).

Each is an upper limit that the actuator meets while its metric stays below the limit:

- ``tracking``: max |θ_u − θ_cmd| over the reference command [rad], θ_u the surface's true
  position (``theta_u_true``; the measured ``theta_u`` differs by the position ADC's step);
- ``tracking_rms``: the RMS of θ_u − θ_cmd over the reference command [rad];
- ``current``: the peak |i_q,ref| [A], the position loop's quadrature current demand, the signal
  that saturates at ±I_max (the measured ``i_q`` follows it within the hysteresis band and
  ripples past it); ``current=I_max`` means "the demand never saturates", ``0.9 I_max`` a
  margin below it. A limit above I_max is refused: the demand can never reach it;
- ``free_play``: the total free play at the surface [rad], B = B0·(1 + 99·k2) (`emaphm.faults`).

Angles take the units of `emaphm.units.UNITS` (``"0.5 deg"``, ``"2 mrad"``, ``"30 arcmin"``),
currents ``"8 A"`` or ``"8000 mA"``; a bare number is SI. `derive_thresholds`
(`emaphm.prognostics.thresholds`) finds the failure threshold of each fault under them.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

from ..errors import InputError
from ..params import EmaParams
from ..units import UNITS, parameter_units, split_quantity, to_si

__all__ = ["REQUIREMENT_KINDS", "SIMULATED", "Requirement", "parse_requirement", "resolve_requirements"]

# kind -> (SI unit, what is measured)
REQUIREMENT_KINDS: dict[str, tuple[str, str]] = {
    "tracking": ("rad", "max |θ_u − θ_cmd| over the reference command"),
    "tracking_rms": ("rad", "RMS of θ_u − θ_cmd over the reference command"),
    "current": ("A", "peak |i_q,ref|, the quadrature current demand (saturates at I_max)"),
    "free_play": ("rad", "total free play at the surface, B = B0·(1 + 99·k2)"),
}
SIMULATED = ("tracking", "tracking_rms", "current")  # the kinds that need the twin

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

    Parameters
    ----------
    text : str
        ``KIND=LIMIT`` (above); the limit in SI or with a unit suffix.
    params : EmaParams, optional
        The actuator whose I_max a fraction refers to.
    where : str
        The option or table the text came from, for the error message.
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

_EXAMPLES = {"tracking": "0.5deg", "tracking_rms": "0.2deg", "current": "I_max", "free_play": "1.5mrad"}


def resolve_requirements(requirements: Sequence[Requirement | str], params: EmaParams) -> list[Requirement]:
    """The requirements resolved for the actuator `params` (see `Requirement.resolve`); `InputError`
    for none, or for two of one kind."""
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
