"""The calibration file of the LF monitor model: `Calibration`, its checks, loaders and digest.

A `Calibration` holds the coefficients (`emaphm.calibration.coefficients`), the LF step and the
record of how they were obtained. `emaphm calibrate` writes one (`emaphm.calibration.fit_monitor`);
the packaged ones ship as ``emaphm/data/calibration.json`` (and ``calibration-paper.json`` for the
paper's monitor) and are what the LF model loads by default.

A calibration belongs to one actuator: it records the parameters it was fitted for
(``settings.params``) and their digest (``params_hash``, `params_hash`). `MonitorEma` refuses one
made for other parameters (`Calibration.check_params`; another drive is named first): the LF model
would otherwise mix the user's drive train with, e.g., the J_eq fitted for another one. The
noise levels (``sensors.sigma_*``) are not part of the actuator nor of the digest.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .._data import read_package_json, record_copy
from ..errors import InputError
from ..params import EmaParams
from .coefficients import COEFFICIENT_BOUNDS, SURROGATE, Coefficients

__all__ = [
    "MONITOR_FILES",
    "Calibration",
    "actuator_params",
    "check_monitor",
    "default_calibration",
    "held_coefficients",
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


def actuator_params(params: dict[str, dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """The parameter groups `params` (`EmaParams.to_dict` form) without the measurement-noise levels."""
    return {
        group: {k: v for k, v in values.items() if k not in NOT_ACTUATOR} for group, values in params.items()
    }


def params_hash(params: EmaParams | dict[str, dict[str, Any]]) -> str:
    """A 16-hex digest of the actuator `params` (or its `to_dict` form; noise levels excluded), stable."""
    data = params if isinstance(params, dict) else params.to_dict()
    text = json.dumps(actuator_params(data), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


@dataclass(frozen=True)
class Calibration:
    """A calibration: coefficients, the LF step, and the record of how they were obtained.

    coefficients : Coefficients  the monitor's calibrated constants
    n_lf : int  LF steps per sample period (1: the LF model steps at T_s = 1/f_s)
    record : dict  how they were obtained (monitor, scenarios, NRMSE, seed, versions, ...)
    """

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
        drive, their_drive = params.inverter.control, theirs.get("inverter", {}).get("control", "hysteresis")
        differ = ([f"a {their_drive} drive, this one's is {drive}"] if drive != their_drive else []) + [
            f"{group}.{key} = {value!r} (calibrated for {theirs.get(group, {}).get(key)!r})"
            for group, values in mine.items()
            for key, value in values.items()
            if theirs.get(group, {}).get(key) != value and not (drive != their_drive and group == "inverter")
        ]
        if differ:
            raise InputError(
                f"{where} was made for other actuator parameters (hash {params_hash(made_for)}, these are "
                f"{params_hash(params)}): {'; '.join(differ[:2])}"
                f"{f' and {len(differ) - 2} more' if len(differ) > 2 else ''}; "
                "if it is this actuator's, pass the actuator file it was made for (--params, params=); else "
                "calibrate the monitor for these ('emaphm calibrate --params FILE --output cal.json') and pass it"
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
        from ..io import atomic_path

        p = Path(path)
        if not p.parent.is_dir():
            raise InputError(f"{p}: folder {p.parent} does not exist")
        with atomic_path(p) as tmp:
            tmp.write_text(json.dumps(self.to_json(), indent=2) + "\n")
        return p


def _command_of(record: Any) -> Any:
    """The command a `command_record` describes (None if it is missing, sampled or not buildable)."""
    from ..commands import make_command

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
    """Read the calibration file `path`; a missing, unreadable or inconsistent file raises `InputError`."""
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


def check_monitor(monitor: Any) -> str:
    """`monitor` if it names a packaged monitor model, else `InputError`."""
    if not isinstance(monitor, str) or monitor not in MONITOR_FILES:
        raise InputError(f"unknown monitor {monitor!r}; choose one of {', '.join(MONITOR_FILES)}")
    return monitor


def default_calibration(monitor: str = "default") -> Calibration:
    """The calibration shipped with the package for `monitor` (``emaphm/data/calibration*.json``).

    The file is read once; each call returns its own copy of the record, so that a caller that
    changes it cannot change what the next one gets (the coefficients are frozen).
    """
    cal = _packaged(check_monitor(monitor))
    return dataclasses.replace(cal, record=record_copy(cal.record))


@functools.lru_cache(maxsize=len(MONITOR_FILES))
def _packaged(monitor: str) -> Calibration:
    name = MONITOR_FILES[monitor]
    cal = _parse(read_package_json(name), f"emaphm/data/{name}")
    if cal.monitor != monitor:
        raise InputError(f"emaphm/data/{name} holds the {cal.monitor!r} monitor, not {monitor!r}")
    return cal


def held_coefficients(
    free: Sequence[str] | None, start: Calibration | None, monitor: str, params: EmaParams, n_lf: int = 1
) -> tuple[Coefficients, str]:
    """The coefficients a calibration starts from and holds where it does not fit, and what they are.

    The first guess without `free`; with it, `start` or the packaged calibration (of the nominal
    actuator only: another actuator's must be given). `start` must be of the same monitor,
    actuator and LF step (`n_lf`), and comes only with `free`.
    """
    if start is not None and free is None:
        raise InputError("a calibration to start from needs the coefficients to fit (free=, --free)")
    if start is None and free is None:
        return Coefficients.first_guess(params), "first guess"
    if start is None:
        if params_hash(params) != params_hash(EmaParams()):
            raise InputError(
                "fitting some coefficients of another actuator needs its own calibration to start "
                "from (start=, --start)"
            )
        start = default_calibration(monitor)
        label = "packaged"
    else:
        label = "given"
    if start.monitor != monitor:
        raise InputError(
            f"the calibration to start from is for the {start.monitor!r} monitor, not {monitor!r}"
        )
    start.check_params(params, where="the calibration to start from")
    if start.n_lf != n_lf:
        raise InputError(
            f"the calibration to start from was made with n_lf = {start.n_lf}, this one uses {n_lf}"
        )
    made = start.record.get("created", "unknown date")
    return start.coefficients, f"{label} calibration made {made} ({start.params_hash or 'unbound'})"
