"""The actuator file: every parameter of the EMA (DESIGN §7) in a TOML file (issue 10).

``emaphm params --template > actuator.toml`` writes one table per block of the diagram
(``[motor]``, ``[inverter]``, ``[transmission]``, ``[controller]``, ``[sensors]``,
``[integration]``), each parameter keyed by its name in `emaphm.params` (``R_s = 0.5``) with its
unit and meaning as a comment. ``--params FILE`` (``params=`` in the API) reads it back:

- a value is a number in the SI unit of the comment, or a string with a unit from the closed
  table of `emaphm.units`: ``L_s = "1.5 mH"``, ``theta_max = "28.6 deg"``, ``I_max = "10000 mA"``;
  a choice is a string taken as it is (``control = "foc"``, ``modulation = "sine"``), a flag is
  ``true`` or ``false``;
- ``[inverter] control`` chooses the drive: ``"hysteresis"`` (the paper's, the default) or
  ``"foc"`` (field-oriented control with PWM); the keys of the other mode (`MODE_KEYS`: ``h`` for
  hysteresis, ``f_pwm``, ``K_p_i``, ... for FOC) are refused, and the template writes the FOC keys
  commented out under a hysteresis drive;
- a parameter left out keeps the paper's nominal value; a key may also stand at the top level
  (``R_s = 0.6``) and is then found in its block;
- unknown tables or keys, a unit of another kind (``R_s = "1 mH"``), a value that fails its
  check (``eta = 1.2``) or that lies outside the range emaphm accepts (`ACCEPTED`, wide enough
  for any EMA, narrow enough to catch a unit slip such as ``L_s = 1.5`` for 1.5 mH) raise
  `InputError` naming the key.
"""

from __future__ import annotations

import dataclasses
import math
import os
from pathlib import Path
from typing import Any

from ._fields import choice_problem
from .errors import InputError
from .failure import parse_thresholds
from .params import MODE_KEYS, EmaParams
from .units import parameter_units, to_si

__all__ = [
    "ACCEPTED",
    "load_params",
    "load_thresholds",
    "params_from_dict",
    "params_template",
    "resolve_params",
]

# the range emaphm accepts per parameter (SI): every EMA of flight controls fits, and a value given
# in the wrong unit (mH as H, deg as rad, mA as A) falls out of it
ACCEPTED: dict[str, tuple[float, float]] = {
    "p": (1, 50), "R_s": (1e-3, 100.0), "L_s": (1e-6, 0.5), "psi_m": (1e-4, 2.0),
    "V_dc": (5.0, 1000.0), "h": (1e-3, 10.0),
    "f_pwm": (1e3, 2e5), "dead_time": (0.0, 2e-5), "K_p_i": (1e-3, 1e4), "K_i_i": (0.0, 1e8),
    "computation_delay": (0, 2), "voltage_limit": (0.1, 1.0), "pwm_phase": (0.0, 1.0),
    "J_m": (1e-8, 1.0), "J_u": (1e-6, 1e4), "tau": (1.0, 1e4), "eta": (0.05, 1.0), "C": (0.0, 1.0),
    "F_S0": (0.0, 100.0), "F_D0": (0.0, 100.0), "B0": (0.0, 0.05), "theta_max": (0.01, 3.2),
    "T_load": (0.0, 1e5),
    "K_P0": (0.01, 1e5), "K_I": (0.0, 1e7), "K_D": (0.0, 1e4), "tau_D": (1e-6, 1.0),
    "I_max": (0.01, 1000.0), "f_s": (500.0, 1e6),
    "bits_current": (0, 32), "full_scale_current": (0.01, 1e4), "sigma_current": (0.0, 100.0),
    "bits_position": (0, 32), "full_scale_position": (0.01, 10.0), "sigma_position": (0.0, 0.1),
    "dt": (1e-8, 1e-3), "ripple_fraction": (0.01, 1.0),
}  # fmt: skip


def _groups() -> dict[str, type]:
    """Block name → parameter dataclass, in the order of `EmaParams`."""
    return {f.name: type(getattr(EmaParams(), f.name)) for f in dataclasses.fields(EmaParams)}


def _fields() -> dict[str, tuple[str, dataclasses.Field[Any]]]:
    """Parameter name → (block, field): the names are unique across blocks."""
    return {f.name: (group, f) for group, cls in _groups().items() for f in dataclasses.fields(cls)}


def params_from_dict(data: dict[str, Any], where: str = "actuator file") -> EmaParams:
    """`EmaParams` from the parsed TOML of an actuator file (see the module docstring)."""
    groups, fields = _groups(), _fields()
    raws: dict[str, Any] = {}  # key -> its raw value, in the order of the file
    seen: dict[str, str] = {}

    def place(key: str, raw: Any, block: str | None) -> None:
        if key not in fields:
            inside = f"[{block}] " if block else ""
            raise InputError(f"{where}: unknown parameter {inside}{key!r}; see 'emaphm params --template'")
        group, _ = fields[key]
        if block is not None and block != group:
            raise InputError(f"{where}: {key} belongs in [{group}], not in [{block}]")
        if key in seen:
            raise InputError(f"{where}: {key} is given twice ({seen[key]} and {block or 'top level'})")
        seen[key] = block or "top level"
        raws[key] = raw

    for key, raw in data.items():
        if key in ("thresholds", "tolerances"):  # `load_thresholds`, `constants.load_tolerances`
            continue
        if isinstance(raw, dict):
            if key not in groups:
                raise InputError(f"{where}: unknown table [{key}]; the tables are {', '.join(groups)}")
            for name, item in raw.items():
                place(name, item, key)
        else:
            place(key, raw, None)

    # the drive first: the other mode's keys are refused before their values are read
    control = _value("control", raws["control"], fields["control"][1], where) if "control" in raws else None
    _check_mode(control or "hysteresis", raws, where)
    values: dict[str, dict[str, Any]] = {g: {} for g in groups}
    for key, raw in raws.items():
        group, f = fields[key]
        values[group][key] = _value(key, raw, f, where)
    try:
        return EmaParams(**{g: groups[g](**v) for g, v in values.items()})
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None


def _check_mode(control: str, raws: dict[str, Any], where: str) -> None:
    """`InputError` for a key of `raws` that belongs to a control mode other than `control`."""
    for mode, keys in MODE_KEYS.items():
        if mode == control:
            continue
        for key in keys:
            if key in raws:
                raise InputError(
                    f'{where}: [inverter] {key} belongs to control = "{mode}", '
                    f'but this file\'s control is "{control}"'
                )


def _value(key: str, raw: Any, f: dataclasses.Field[Any], where: str) -> Any:
    """The value of one entry in its field's type: a choice as it is, a flag as it is, a number in
    SI (`to_si`) checked against `ACCEPTED`; `InputError` naming `where` and `key` otherwise."""
    if f.metadata["check"] in ("choice", "flag"):  # as TOML writes them: choices in double quotes
        problem = choice_problem(f.metadata, raw, quote=lambda c: f'"{c}"')
        if problem:
            raise InputError(f"{where}: {key} {problem}")
        return raw
    si_unit = f.metadata["unit"]
    value = to_si(raw, key, si_unit, where)
    lo, hi = ACCEPTED[key]
    if not (isinstance(value, (int, float)) and math.isfinite(value)):
        raise InputError(f"{where}: {key} must be a finite number, got {raw!r}")
    if not lo <= value <= hi:
        likely = _example_unit(si_unit, key)
        hint = (
            f': is it in another unit? write the unit, e.g. {key} = "{raw} {likely}"'
            if si_unit not in ("-", "bit") and likely != si_unit
            else ""
        )
        raise InputError(
            f"{where}: {key} = {raw!r} is outside the range emaphm accepts, {lo:g} to {hi:g} {si_unit}{hint}"
        )
    # the field's own type, so that 48, 48.0 and "48 V" are one actuator (one params_hash)
    if isinstance(f.default, int):
        return int(value) if float(value).is_integer() else value
    return float(value)


# the unit a value out of range was most likely meant in, for the hint (by key, then by SI unit)
_LIKELY_FOR_KEY = {"dead_time": "us"}
_LIKELY = {"rad": "deg", "A/rad": "A/deg", "A/(rad·s)": "A/(deg·s)", "A·s/rad": "A·s/deg"}


def _example_unit(si_unit: str, key: str = "") -> str:
    if key in _LIKELY_FOR_KEY:
        return _LIKELY_FOR_KEY[key]
    if si_unit in _LIKELY:
        return _LIKELY[si_unit]
    others = [u for u in parameter_units(si_unit) if u != si_unit]
    return others[0] if others else si_unit


def load_params(path: str | os.PathLike[str]) -> EmaParams:
    """Read an actuator file (TOML); `InputError` for a missing, malformed or invalid file.

    Parameters
    ----------
    path : str or path
        The actuator file (TOML; docs/your-actuator.md).
    """
    from .io import read_toml

    return params_from_dict(read_toml(path, "actuator file"), str(path))


def resolve_params(params: EmaParams | str | os.PathLike[str] | None) -> EmaParams:
    """`EmaParams` from parameters, the path of an actuator file, or None (the nominal actuator)."""
    if params is None:
        return EmaParams()
    if isinstance(params, EmaParams):
        return params
    if isinstance(params, (str, os.PathLike)):
        return load_params(params)
    raise InputError(f"params must be EmaParams or the path of an actuator file, got {type(params).__name__}")


def _toml_value(value: Any) -> str:
    """A parameter value as TOML: a flag as true/false, a choice quoted, a number as it is."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, int):
        return str(value)
    text = repr(float(value))
    return text if any(c in text for c in ".en") else text + ".0"


def params_template(params: EmaParams | None = None) -> str:
    """A complete actuator file (TOML) with the values of `params` (default: nominal), every key
    with its unit and meaning as a comment.

    The ``[inverter]`` table holds the keys of `params`' control mode; under a hysteresis drive
    the FOC keys follow commented out (their defaults), so the file is valid as it is and shows
    every key.
    """
    params = params if params is not None else EmaParams()
    lines = [
        "# emaphm actuator file: every parameter of the EMA (DESIGN §7), one table per block.",
        "# A value is a number in the unit of its comment, or a string with a unit:",
        '#   L_s = "1.5 mH", theta_max = "28.6 deg", I_max = "10000 mA".',
        "# A parameter left out keeps the nominal value of the paper's actuator.",
        "# Check a file with: emaphm params FILE",
    ]
    for group, cls in _groups().items():
        lines += ["", f"[{group}]  # {(cls.__doc__ or '').strip().splitlines()[0]}"]
        instance = getattr(params, group)
        meta = {f.name: f.metadata for f in dataclasses.fields(cls)}
        entries = [(name, _toml_value(getattr(instance, name)), "") for name in instance.fields_in_use()]
        extra = ""
        if group == "inverter" and instance.control == "hysteresis":
            extra = '# field-oriented control: set control = "foc", remove h and uncomment these'
            default = type(instance)(control="foc")
            entries += [(name, _toml_value(getattr(default, name)), "# ") for name in MODE_KEYS["foc"]]
        width = max(len(p) + len(n) + len(v) + 3 for n, v, p in entries)
        for name, value, prefix in entries:
            if prefix and extra:
                lines.append(extra)
                extra = ""
            text = f"{prefix}{name} = {value}".ljust(width)
            lines.append(text + f"  # [{meta[name]['unit']}] {meta[name]['doc']}")
    return "\n".join([*lines, "", *_TOLERANCES_TEMPLATE]) + "\n"


# the optional [tolerances] table, commented out at its defaults (`constants.TOLERANCES`)
_TOLERANCES_TEMPLATE = (
    "# How far this actuator may be from the values above (relative, a uniform band): the fault",
    "# intervals widen for what that can move (docs/uncertainty.md). These are the defaults.",
    "# [tolerances]",
    "# psi_m = 0.02          # the magnet flux",
    "# J = 0.02              # the inertia",
    "# friction = 0.02       # both friction levels",
    "# current_gain = 0.0    # the current sensor's gain",
    "# K_P = 0.0             # the position loop's gain as it acts",
)


def load_thresholds(path: str | os.PathLike[str]) -> dict[str, float]:
    """The ``[thresholds]`` table of an actuator file: failure thresholds per fault, as distances
    from healthy in fault units (``friction = 0.45``); {} when the file has none."""
    from .io import read_toml

    p = Path(path)
    load_params(p)  # the whole file is valid
    data = read_toml(p, "actuator file").get("thresholds", {})
    if not isinstance(data, dict):
        raise InputError(f"{p}: [thresholds] must be a table of FAULT = distance from healthy")
    return parse_thresholds(data, where=f"{p}: [thresholds]")
