"""A baseline's folder: everything `identify --baseline DIR` needs for one actuator (issue 33).

    actuator.toml     the nameplate with the fitted constants (each with its interval and the
                      provenance in the comment above it)
    calibration.json  the monitor's calibration for it: the nameplate's, with k_t,eq, k_e,eq and
                      J_eq fitted (`fit`), bound to the fitted actuator
    uq.json           the interval calibration: the nameplate's factors (the monitor's discrepancy
                      from the actuator, which a few per cent on the constants do not change),
                      bound to this calibration, with the baseline's own fits
    detection.json    the detection thresholds (the nameplate's)
    nameplate.toml, nameplate-calibration.json   the nameplate and its own monitor calibration,
                      whose start table the search starts from (one table for every actuator of
                      the type; absent when the calibration was another actuator's, and in
                      folders made before them: the search then starts uniform)
    baseline.json     the record: the recordings and their SHA-256, the factors with their
                      intervals, each recording's fit, the settings and versions
    index.html, fit-N.png   a short report

The folder is written whole or not at all: into a temporary folder beside it, then renamed.
"""

from __future__ import annotations

import datetime as _dt
import json
import os
import tempfile
from pathlib import Path
from typing import Any

from .._version import __version__
from .._versions import versions
from ..actuator import params_template
from ..atomic import replace_folder
from ..calibration.files import params_hash
from ..errors import InputError
from ..identification.detection import load_thresholds
from ..identification.uncertainty import Factors, load_factors
from .fit import CONSTANTS
from .make import Baseline

__all__ = ["FILES", "NAMEPLATE_FILES", "baseline_files", "baseline_inputs", "check_output_dir", "write_baseline"]

FILES = {
    "params": "actuator.toml", "calibration": "calibration.json", "uq_calibration": "uq.json",
    "detection": "detection.json", "record": "baseline.json",
}  # fmt: skip
NAMEPLATE_FILES = {"params": "nameplate.toml", "calibration": "nameplate-calibration.json"}  # optional
_WHAT = {
    "i_gain": "the current sensor's gain (identify divides the current by it)",
    "k_t_eq": "the monitor's torque gain k_t,eq", "k_e_eq": "the back-EMF gain k_e,eq (psi_m)",
    "J_eq": "the inertia J_eq (J_m, J_u)", "F_S0": "static friction F_S0", "F_D0": "dynamic friction F_D0",
    "K_P0": "the position gain K_P0 as it acts",
}  # fmt: skip


def check_output_dir(path: str | os.PathLike[str]) -> Path:
    """A new folder, an empty one, or an earlier baseline (replaced); `InputError` else, before the work."""
    p = Path(path)
    if p.exists() and (not p.is_dir() or (any(p.iterdir()) and not (p / FILES["record"]).is_file())):
        raise InputError(f"--output {p}: exists and is not an empty folder or an earlier baseline")
    if not p.absolute().parent.is_dir():
        raise InputError(f"--output {p}: folder {p.absolute().parent} does not exist")
    return p


def baseline_files(directory: str | os.PathLike[str]) -> dict[str, Path]:
    """The files of a baseline folder by role (`FILES`); `InputError` naming the first missing one."""
    d = Path(directory)
    if not d.is_dir():
        raise InputError(f"--baseline {d}: no such folder (make one with 'emaphm baseline')")
    files = {role: d / name for role, name in FILES.items()}
    for path in files.values():
        if not path.is_file():
            raise InputError(
                f"--baseline {d}: {path.name} is missing: not a baseline folder from 'emaphm baseline'"
            )
    return files


def baseline_inputs(directory: str | os.PathLike[str], **given: Any) -> dict[str, Any]:
    """What `identify` takes from a baseline folder: params, calibration, uq_calibration (paths),
    thresholds (the detection file's), ``record`` (which baseline, for the result) and the
    nameplate's monitor whose start table the search starts from with its files (``table_monitor``,
    ``table_from``; None in a folder without them, and ``table_skipped`` says why). `given`:
    those the caller passed too, each refused (the baseline gives them)."""
    clash = [name for name, value in given.items() if value is not None]
    if clash:
        raise InputError(
            f"--baseline gives the actuator's {', '.join(clash)}: leave {'it' if len(clash) == 1 else 'them'} out"
        )
    files = baseline_files(directory)
    try:
        record = json.loads(files["record"].read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"--baseline {directory}: {files['record'].name} is not readable ({exc})") from None
    from ..io import sha256_of

    return {
        "params": files["params"], "calibration": files["calibration"], "uq_calibration": files["uq_calibration"],
        "thresholds": dict(load_thresholds(files["detection"])["thresholds"]),
        "current_gain": float(record.get("factors", {}).get("i_gain", {}).get("factor", 1.0)),
        "record": {"directory": str(directory), "created": record.get("created"), "sha256": sha256_of(files["record"]),
                   "params_hash": record.get("params_hash"), "recordings": [r.get("file") for r in record.get("recordings", [])]},
        **_nameplate(Path(directory)),
    }  # fmt: skip


def _nameplate(directory: Path) -> dict[str, Any]:
    """{"table_monitor": the nameplate's monitor, whose start table the search starts from,
    "table_from": its files, "table_skipped": None}; the first two None when they are not in the
    folder or are not a calibration of that nameplate (a start only: the search then starts
    uniform), and "table_skipped" then says why in one line, for the result's record."""
    from ..actuator import load_params
    from ..models import MonitorEma

    paths = {role: directory / name for role, name in NAMEPLATE_FILES.items()}
    present = [p.name for p in paths.values() if p.is_file()]

    def skipped(why: str) -> dict[str, Any]:
        return {"table_monitor": None, "table_from": None, "table_skipped": why}

    if not present:
        return skipped(f"the folder holds neither {' nor '.join(NAMEPLATE_FILES.values())} (made before them, "
                       "or from another actuator's calibration)")  # fmt: skip
    if len(present) < len(paths):
        return skipped(f"the folder holds {present[0]} without its pair")
    try:
        monitor = MonitorEma(load_params(paths["params"]), calibration=paths["calibration"])
    except InputError as exc:
        return skipped(f"the nameplate's files do not load as a monitor ({exc})")
    return {"table_monitor": monitor, "table_from": {role: str(p) for role, p in paths.items()}, "table_skipped": None}


def write_baseline(
    made: Baseline, output: str | os.PathLike[str], *, uq_calibration: Any = None, detection: Any = None
) -> Path:
    """Write the baseline folder (module docstring); returns its path. `uq_calibration` and
    `detection`: the nameplate's files (default: the packaged ones)."""
    out = check_output_dir(output)
    created = _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")
    calibration = _calibration(made, created)
    with tempfile.TemporaryDirectory(
        dir=out.absolute().parent, prefix=f".{out.name}-", ignore_cleanup_errors=True
    ) as tmp_name:
        tmp = Path(tmp_name)
        (tmp / FILES["params"]).write_text(_actuator_text(made, created))
        calibration.save(tmp / FILES["calibration"])
        if made.nameplate_calibration is not None:
            (tmp / NAMEPLATE_FILES["params"]).write_text(params_template(made.nameplate))
            made.nameplate_calibration.save(tmp / NAMEPLATE_FILES["calibration"])
        _uq(made, calibration, uq_calibration).save(tmp / FILES["uq_calibration"])
        thresholds = dict(load_thresholds(detection))
        (tmp / FILES["detection"]).write_text(json.dumps(
            {**json.loads(json.dumps(thresholds, default=_plain)), "baseline": {"from": str(detection or "packaged")}},
            indent=2) + "\n")  # fmt: skip
        record = {**made.record, "created": created, "version": __version__, "versions": versions(),
                  "nameplate_params_hash": params_hash(made.nameplate), "params_hash": params_hash(made.params),
                  "uq_calibration_from": str(uq_calibration or "packaged"), "detection_from": str(detection or "packaged")}  # fmt: skip
        (tmp / FILES["record"]).write_text(json.dumps(record, indent=2) + "\n")
        from .report import write_report

        write_report(made, tmp)
        replace_folder(tmp, out)
    return out


def _plain(value: Any) -> Any:
    return dict(value) if hasattr(value, "items") else list(value)


def _calibration(made: Baseline, created: str) -> Any:
    from dataclasses import replace

    record = json.loads(json.dumps(made.calibration.record, default=_plain))
    record.setdefault("settings", {})["params"] = made.params.to_dict()
    record["created"] = created
    record["baseline"] = {"factors": {c: made.fit.factors[c] for c in ("k_t_eq", "k_e_eq", "J_eq")},
                          "nameplate_created": made.calibration.record.get("created")}  # fmt: skip
    return replace(made.calibration, record=record)


def _uq(made: Baseline, calibration: Any, given: Any) -> Factors:
    nameplate = given if isinstance(given, Factors) else load_factors(given)
    record = json.loads(json.dumps(nameplate.record, default=_plain))
    record["lf_calibration"] = {"monitor": calibration.monitor, "created": calibration.record["created"],
                                "params_hash": calibration.params_hash}  # fmt: skip
    record["baseline"] = {"fit_nrmse": list(made.fit.fit_nrmse), "from": str(given or "packaged")}
    # the constants' covariance (log-factors), which widens every diagnosis' intervals (`uncertainty.constants`)
    record["constants"] = {"names": list(CONSTANTS), "log_covariance": made.fit.details["log_covariance"]}
    return Factors(nameplate.scale, nameplate.floor, record)


def _actuator_text(made: Baseline, created: str) -> str:
    lines = [f"# the baseline of one actuator, emaphm {__version__}, {created}: the nameplate with the constants",
             "# fitted to recordings of it when healthy (emaphm baseline; baseline.json has the record):"]  # fmt: skip
    for c in CONSTANTS:
        f, lo, hi = made.fit.factors[c], made.fit.low[c], made.fit.high[c]
        lines.append(f"#   {_WHAT[c]}: {f:.4f} x the nameplate (90 % interval {lo:.4f}-{hi:.4f})")
    lines += [f"#   recording {r['file']} (sha256 {r['sha256'][:16]}...): fit NRMSE {100 * r['fit_nrmse']:.2f} %"
              for r in made.record["recordings"]]  # fmt: skip
    lines.append(
        "# R_s, L_s, the healthy free play B0 and the drive stay the nameplate's: under current control the "
        "recordings do not tell R_s and L_s, and a fitted B0 moved every backlash estimate (docs/your-actuator.md §0)"
    )
    return "\n".join(lines) + "\n" + params_template(made.params)
