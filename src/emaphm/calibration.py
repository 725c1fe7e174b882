"""Calibration of the LF monitor model: its coefficients and the versioned file that holds them.

The coefficients are those of the paper §4.2 (DESIGN §4.4): the shape-function coefficients
k_FS, k_E (k_FT follows from them, see `Coefficients.k_FT`), the equivalent torque and back-EMF
gains k_t,eq and k_e,eq, plus the inertia J_eq the LF model sees and the time constant τ_i of its
simplified current loop. `emaphm calibrate` fits them with a GA against the HF twin
(`emaphm.identification.calibrate`); the result ships as ``emaphm/data/calibration.json`` and is
what the LF model loads by default.

A calibration belongs to one actuator: it records the parameters it was fitted for
(``settings.params``) and their digest (``params_hash``, `params_hash`). `MonitorEma` refuses
a calibration made for other parameters (`Calibration.check_params`): the LF model would
otherwise mix the user's drive train with, e.g., the inertia J_eq fitted for another one.
The measurement-noise levels (``sensors.sigma_*``) are not part of the actuator: they are left
out of the comparison and of the digest.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ._data import read_package_json
from .errors import InputError
from .params import EmaParams

__all__ = [
    "COEFFICIENT_BOUNDS",
    "NAMEPLATE_SCALED",
    "Calibration",
    "Coefficients",
    "actuator_params",
    "check_monitor",
    "coefficient_bounds",
    "default_calibration",
    "load_calibration",
    "params_hash",
]

NOT_ACTUATOR = ("sigma_current", "sigma_position")  # noise levels: not part of what is calibrated

FORMAT = "emaphm-lf-calibration"
FORMAT_VERSION = 5
# the coefficients each older readable version lacks (i_R: the monitor's breakaway ripple, i_D: its
# dead zone at standstill): its coefficients are the same model with those at 0, read as such
OLDER_VERSIONS_LACK: dict[int, tuple[str, ...]] = {3: ("i_R", "i_D"), 4: ("i_D",)}
READABLE_VERSIONS = (*OLDER_VERSIONS_LACK, FORMAT_VERSION)

# GA search bounds of each calibrated coefficient (SI)
COEFFICIENT_BOUNDS: dict[str, tuple[float, float]] = {
    "k_FS": (0.0, 100.0),  # [-]
    "k_E": (0.0, 3.0),  # [-]
    "k_t_eq": (0.10, 0.20),  # [N·m/A]
    "k_e_eq": (0.05, 0.20),  # [V·s/rad]
    "J_eq": (4.0e-5, 6.5e-5),  # [kg·m²]
    "tau_i": (1e-6, 3e-4),  # [s]
    "k_H": (-0.1, 0.1),  # [-]
    "delta_0": (0.0, 0.02),  # [A]
    "delta_1": (0.0, 0.1),  # [A]
    "delta_u": (-0.05, 0.1),  # [A]
    "delta_2": (-0.05, 0.05),  # [A]
    "V_H": (1e-4, 0.05),  # [V]
    # [A]; the q current's ripple peak cannot exceed the hysteresis band's width h (0.1 A here):
    # scaled with the actuator's h (`coefficient_bounds`)
    "i_R": (0.0, 0.1),
    # [A]; the half-band of the loop's dead zone at standstill: h/2 in the twin's comparators, up
    # to h for what the monitor's averaged loop needs; scaled with the actuator's h too
    "i_D": (0.0, 0.1),
}


@dataclass(frozen=True)
class Coefficients:
    """Equivalent single-phase motor and shape-function coefficients.

    The defaults are the first guess before calibration: nameplate gains (k_t,eq = 1.5·p·ψ_m,
    k_e,eq = p·ψ_m, J_eq = J_m + J_u/τ²), unit shape coefficients, a one-sample current lag and
    no current-loop surrogate error.

    k_FS : float  single-phase contribution of the short-circuit shape function [-]
    k_E : float  eccentricity calibration coefficient [-]
    k_t_eq : float  equivalent torque gain (healthy, φ_T = 1) [N·m/A]
    k_e_eq : float  equivalent back-EMF coefficient (healthy) [V·s/rad]
    J_eq : float  inertia at the motor shaft seen by the LF model [kg·m²]
    tau_i : float  time constant of the simplified current loop [s]
    k_H : float  2θ_e ripple of the loop's current per unit of lost turns [-]
    delta_0 : float  loop offset of the measured current, healthy [A]
    delta_1 : float  growth of that offset per unit of lost turns Σ(1 − N_x) [A]
    delta_u : float  growth of that offset with the unbalance of the lost turns |U| (kernels.monitor.unbalance) [A]
    delta_2 : float  part of that offset in step with the shorted phases' 2θ_e pattern c₂ [A]
    V_H : float  q-axis voltage (R_eq·i + k_e,eq·ω_m) over which the offset reverses its sign [V]
    i_R : float  peak of the loop's current ripple about i_m that breaks a stuck motor away [A]
    i_D : float  half-band of the loop's dead zone at standstill (kernels.monitor.standstill_dead_zone) [A]
    """

    k_FS: float = 1.0
    k_E: float = 1.0
    k_t_eq: float = 0.15
    k_e_eq: float = 0.10
    J_eq: float = 5.125e-5
    tau_i: float = 1e-4
    k_H: float = 0.0
    delta_0: float = 0.0
    delta_1: float = 0.0
    delta_u: float = 0.0
    delta_2: float = 0.0
    V_H: float = 0.01
    i_R: float = 0.0
    i_D: float = 0.0

    def __post_init__(self) -> None:
        # the nameplate-scaled coefficients, i_R and i_D are checked against their actuator's box by
        # `check_bounds`; here only that they are positive (i_R, i_D: not negative)
        for name, (lo, hi) in COEFFICIENT_BOUNDS.items():
            v = getattr(self, name)
            if name in ACTUATOR_SCALED:
                lo, hi = 0.0, math.inf
                ok = (
                    isinstance(v, (int, float))
                    and math.isfinite(v)
                    and (v > 0 or (name in BAND_SCALED and v == 0))
                )
            else:
                ok = isinstance(v, (int, float)) and math.isfinite(v) and lo <= v <= hi
            if not ok:
                raise InputError(
                    f"calibration coefficient {name}={v!r} is outside its range [{lo:g}, {hi:g}]"
                )

    @classmethod
    def first_guess(cls, params: EmaParams | None = None) -> Coefficients:
        """The coefficients before calibration for an actuator: the defaults with its nameplate k_t, k_e, J."""
        nominal, ratio = cls(), _nameplate_ratios(params)
        return cls(**{name: getattr(nominal, name) * r for name, r in ratio.items()})

    def check_bounds(self, params: EmaParams | None = None, *, where: str = "calibration") -> None:
        """`InputError` unless every coefficient lies in `coefficient_bounds(params)`."""
        for name, (lo, hi) in coefficient_bounds(params).items():
            v = getattr(self, name)
            if not lo <= v <= hi:
                raise InputError(
                    f"{where}: coefficient {name}={v!r} is outside its range [{lo:.4g}, {hi:.4g}]"
                    + (" for these actuator parameters" if name in ACTUATOR_SCALED else "")
                )

    @property
    def k_FT(self) -> float:
        """Global short-circuit coefficient, k_FT = 1/(3 + 1.5·k_FS) so that a healthy φ_SC = 1.

        k_FT multiplies k_t,eq and k_e,eq everywhere it appears, so the GA would only see their
        products; fixing φ_SC(healthy) = 1 removes that degenerate direction and makes k_t,eq
        the healthy torque constant.
        """
        return 1.0 / (3.0 + 1.5 * self.k_FS)

    def as_vector(self) -> list[float]:
        return [float(getattr(self, n)) for n in COEFFICIENT_BOUNDS]

    @classmethod
    def from_vector(cls, x: Any) -> Coefficients:
        return cls(**{n: float(v) for n, v in zip(COEFFICIENT_BOUNDS, x, strict=True)})


# the coefficients whose search box scales with the actuator's nameplate value (k_t = 1.5·p·ψ_m,
# k_e = p·ψ_m, J = J_m + J_u/τ²): COEFFICIENT_BOUNDS holds their box for the nominal actuator
NAMEPLATE_SCALED = ("k_t_eq", "k_e_eq", "J_eq")
# the coefficients whose box scales with the actuator's hysteresis band h (and may be 0)
BAND_SCALED = ("i_R", "i_D")
# all the coefficients whose box follows the actuator
ACTUATOR_SCALED = (*NAMEPLATE_SCALED, *BAND_SCALED)


def coefficient_bounds(params: EmaParams | None = None) -> dict[str, tuple[float, float]]:
    """The calibration's search box for an actuator (`COEFFICIENT_BOUNDS` for the nominal one).

    k_t,eq, k_e,eq and J_eq keep the nominal box's ratios to the nameplate k_t, k_e and J, so a
    motor with twice the flux, say, is searched around its own constants, and i_R its ratio to
    the hysteresis band h; the dimensionless shape coefficients and the loop surrogate keep their
    boxes.
    """
    ratio = _nameplate_ratios(params)
    return {
        name: (lo * ratio[name], hi * ratio[name]) if name in ratio else (lo, hi)
        for name, (lo, hi) in COEFFICIENT_BOUNDS.items()
    }


def _nameplate_ratios(params: EmaParams | None) -> dict[str, float]:
    """k_t, k_e, J and the band h of `params` over the nominal actuator's (exactly 1 for the nominal one)."""
    nominal = EmaParams()
    params = params if params is not None else nominal
    return {
        "k_t_eq": params.motor.k_t / nominal.motor.k_t,
        "k_e_eq": params.motor.k_e / nominal.motor.k_e,
        "J_eq": params.transmission.J / nominal.transmission.J,
        **{name: params.inverter.h / nominal.inverter.h for name in BAND_SCALED},
    }


def actuator_params(params: dict[str, dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """The parameter groups (`EmaParams.to_dict` form) without the measurement-noise levels."""
    return {
        group: {k: v for k, v in values.items() if k not in NOT_ACTUATOR} for group, values in params.items()
    }


def params_hash(params: EmaParams | dict[str, dict[str, Any]]) -> str:
    """A 16-hex digest of the actuator parameters (noise levels excluded), stable across runs."""
    data = params if isinstance(params, dict) else params.to_dict()
    text = json.dumps(actuator_params(data), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


@dataclass(frozen=True)
class Calibration:
    """A calibration: coefficients, the LF step, and the record of how they were obtained."""

    coefficients: Coefficients = field(default_factory=Coefficients)
    n_lf: int = 1  # LF steps per sample period (1: the LF model steps at T_s = 100 µs)
    record: dict[str, Any] = field(default_factory=dict)

    @property
    def monitor(self) -> str:
        """The monitor model calibrated: "default" or "paper" (the surrogate off, eqs. 1–2 alone)."""
        return str(self.record.get("monitor", "default"))

    @property
    def params(self) -> dict[str, dict[str, Any]] | None:
        """The parameters (`EmaParams.to_dict` form) this calibration was fitted for, if recorded."""
        params = self.record.get("settings", {}).get("params")
        return params if isinstance(params, dict) else None

    def command(self) -> Any:
        """The main position command the calibration was fitted under (None if not recorded or sampled)."""
        return _command_of(self.record.get("settings", {}).get("command"))

    def commands(self) -> dict[str, Any]:
        """Every position command the calibration was fitted under, by name ({} if none is recorded)."""
        settings = self.record.get("settings", {})
        recorded = settings.get("commands")
        if not isinstance(recorded, dict):
            main = self.command()
            return {} if main is None else {"main": main}
        built = {name: _command_of(rec) for name, rec in recorded.items()}
        return {name: c for name, c in built.items() if c is not None}

    @property
    def params_hash(self) -> str | None:
        """Digest of the recorded parameters (`params_hash`), None for an unbound calibration."""
        return None if self.params is None else params_hash(self.params)

    def check_params(self, params: EmaParams, *, where: str = "the calibration") -> None:
        """`InputError` unless `params` are the actuator this calibration was fitted for.

        A calibration that records no parameters (built in code) is accepted for any.
        """
        made_for = self.params
        if made_for is None:
            return
        mine, theirs = actuator_params(params.to_dict()), actuator_params(made_for)
        differ = [
            f"{group}.{key} = {value!r} (calibrated for {theirs.get(group, {}).get(key)!r})"
            for group, values in mine.items()
            for key, value in values.items()
            if theirs.get(group, {}).get(key) != value
        ]
        if differ:
            more = f" and {len(differ) - 2} more" if len(differ) > 2 else ""
            raise InputError(
                f"{where} was made for other actuator parameters (hash {params_hash(made_for)}, these are "
                f"{params_hash(params)}): {'; '.join(differ[:2])}{more}; "
                "calibrate the monitor for them ('emaphm calibrate --params FILE --output cal.json', "
                "or emaphm.calibrate(params=...)) and pass that calibration"
            )

    def to_json(self) -> dict[str, Any]:
        data = {
            "format": FORMAT,
            "format_version": FORMAT_VERSION,
            "coefficients": dataclasses.asdict(self.coefficients),
            "derived": {"k_FT": self.coefficients.k_FT},
            "n_lf": self.n_lf,
            **self.record,
        }
        if self.params_hash is not None:
            data["params_hash"] = self.params_hash
        return data

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write the calibration file atomically (JSON)."""
        from .io import atomic_path

        p = Path(path)
        if not p.parent.is_dir():
            raise InputError(f"{p}: folder {p.parent} does not exist")
        with atomic_path(p) as tmp:
            tmp.write_text(json.dumps(self.to_json(), indent=2) + "\n")
        return p


def _command_of(record: Any) -> Any:
    """The command a `command_record` describes (None if it is missing, sampled or not buildable)."""
    from .commands import make_command

    rec = dict(record) if isinstance(record, dict) else {}
    kind = rec.pop("type", None)
    if kind is None or kind == "sampled":
        return None
    try:
        return make_command(kind, **rec)
    except InputError:
        return None


def _parse(data: Any, where: str) -> Calibration:
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise InputError(f"{where}: not an emaphm LF calibration file")
    if data.get("format_version") not in READABLE_VERSIONS:
        older = isinstance(data.get("format_version"), int) and data["format_version"] < FORMAT_VERSION
        raise InputError(
            f"{where}: calibration format version {data.get('format_version')!r}, expected "
            + " or ".join(map(str, READABLE_VERSIONS))
            + (
                "; it was written by an older emaphm for another monitor model: run emaphm calibrate again"
                if older
                else ""
            )
        )
    monitor = data.get("monitor", "default")
    if not isinstance(monitor, str) or monitor not in MONITOR_FILES:
        raise InputError(f"{where}: unknown monitor {monitor!r}; expected one of {', '.join(MONITOR_FILES)}")
    coeffs = data.get("coefficients")
    if isinstance(coeffs, dict):  # what an older version lacks is 0
        absent = OLDER_VERSIONS_LACK.get(data["format_version"], ())
        coeffs = {**{name: 0.0 for name in absent if name not in coeffs}, **coeffs}
    if not isinstance(coeffs, dict) or set(coeffs) != set(COEFFICIENT_BOUNDS):
        raise InputError(f"{where}: coefficients must be exactly {', '.join(COEFFICIENT_BOUNDS)}")
    n_lf = data.get("n_lf")
    if not isinstance(n_lf, int) or not 1 <= n_lf <= 100:
        raise InputError(f"{where}: n_lf must be a whole number 1..100, got {n_lf!r}")
    record = {
        k: v
        for k, v in data.items()
        if k not in ("format", "format_version", "coefficients", "derived", "n_lf", "params_hash")
    }
    try:
        cal = Calibration(Coefficients(**coeffs), n_lf, record)
        recorded = cal.params
        cal.coefficients.check_bounds(
            None if recorded is None else EmaParams.from_dict(recorded), where=where
        )
    except InputError as exc:
        raise InputError(f"{where}: {exc}".replace(f"{where}: {where}: ", f"{where}: ")) from None
    if monitor == "paper" and any(getattr(cal.coefficients, n) != 0.0 for n in SURROGATE):
        raise InputError(
            f"{where}: a 'paper' monitor has no loop surrogate, but {', '.join(SURROGATE)} are not all 0"
        )
    stored = data.get("params_hash")
    if stored is not None and stored != cal.params_hash:
        raise InputError(f"{where}: params_hash {stored!r} does not match the recorded parameters")
    return cal


def load_calibration(path: str | os.PathLike[str]) -> Calibration:
    """Read a calibration file; a missing, unreadable or inconsistent file raises `InputError`."""
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such calibration file")
    try:
        data = json.loads(p.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"{p}: corrupt calibration file ({exc})") from None
    return _parse(data, str(p))


# the packaged calibration of each monitor model (issue 8): the default monitor, and the paper's
# single-phase model with its shape functions alone (eqs. 1–2, no loop-error surrogate)
MONITOR_FILES = {"default": "calibration.json", "paper": "calibration-paper.json"}


# the loop-error surrogate's coefficients, the loop's breakaway ripple and its dead zone, which
# the paper's monitor holds at zero (V_H, a scale, has no effect then)
SURROGATE = ("k_H", "delta_0", "delta_1", "delta_u", "delta_2", "i_R", "i_D")


def check_monitor(monitor: Any) -> str:
    """`monitor` if it names a packaged monitor model, else `InputError`."""
    if not isinstance(monitor, str) or monitor not in MONITOR_FILES:
        raise InputError(f"unknown monitor {monitor!r}; choose one of {', '.join(MONITOR_FILES)}")
    return monitor


@functools.lru_cache(maxsize=len(MONITOR_FILES))
def default_calibration(monitor: str = "default") -> Calibration:
    """The calibration shipped with the package for `monitor` (``emaphm/data/calibration*.json``), read once."""
    name = MONITOR_FILES[check_monitor(monitor)]
    cal = _parse(read_package_json(name), f"emaphm/data/{name}")
    if cal.monitor != monitor:
        raise InputError(f"emaphm/data/{name} holds the {cal.monitor!r} monitor, not {monitor!r}")
    return cal
