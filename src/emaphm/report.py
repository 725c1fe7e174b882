"""A diagnosis report a planner reads (issue 10, item 6; issue 34, item 4): ``emaphm identify …
--report DIR``.

The folder gets the figures (``fit.png``: measured vs fitted current with the residual;
``faults.png``: the faults as distances from healthy with their 90 % intervals and the detection
and failure thresholds, not drawn for a result that does not fit; ``convergence.png``) and
``index.html``, a single self-contained page (`report_page`: the figures and the result's JSON
are embedded, no network, no script but one that counts the images that loaded): the verdict
first, the actuator's id and baseline, the faults in physical units, the warnings, the fit, a
short table of the input's provenance and the key settings, and the JSON as a download.

Writing is atomic per file and the page comes last: an interrupted report leaves either the
previous page or none, never a page that points at missing figures.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from . import report_page
from .errors import InputError

if TYPE_CHECKING:
    from .params import EmaParams

__all__ = ["REPORT_FILES", "check_report_dir", "input_provenance", "write_report"]

REPORT_FILES = ("fit.png", "faults.png", "convergence.png", "index.html")


def check_report_dir(path: str | os.PathLike[str], *, option: str = "--report") -> Path:
    """Validate a report folder before the work: a folder or a new name in a writable folder."""
    p = Path(path)
    if p.exists() and not p.is_dir():
        raise InputError(f"{option} {p}: exists and is not a folder")
    parent = p if p.is_dir() else p.absolute().parent
    if not parent.is_dir():
        raise InputError(f"{option} {p}: folder {parent} does not exist")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise InputError(f"{option} {p}: folder {parent} is not writable")
    return p


def write_report(
    result: Any,
    directory: str | os.PathLike[str],
    *,
    provenance: dict[str, Any] | None = None,
    params: EmaParams | None = None,
    thresholds: Mapping[str, float] | None = None,
    failure_thresholds: Mapping[str, float] | None = None,
) -> Path:
    """Write the report of an `IdentificationResult` into `directory`; returns the page's path.

    Parameters
    ----------
    result : IdentificationResult
        The identification reported.
    directory : path
        The report folder (made if new).
    provenance : dict, optional
        The input (`input_provenance`, JSON-ready): e.g. ``{"reference": path, "sha256": …,
        "map": …, "conversion": …}``.
    params : EmaParams, optional
        The actuator the result was identified for: the faults' physical units come from it
        (default: the nominal actuator; the page says so when the result's actuator differs).
    thresholds : mapping of str to float, optional
        The detection thresholds the result was judged with (fault units from healthy; default:
        the result's record's, else the packaged ones).
    failure_thresholds : mapping of str to float, optional
        The actuator's failure thresholds (its file's ``[thresholds]``, `actuator.load_thresholds`),
        drawn and tabled beside the detection thresholds when given.
    """
    from .params import EmaParams

    out = check_report_dir(directory)
    out.mkdir(parents=True, exist_ok=True)
    data = result.to_json()
    view = {
        "params": params if params is not None else EmaParams(),
        "detection": _detection_thresholds(thresholds, data["settings"], (provenance or {}).get("detection")),
        "failure": dict(failure_thresholds) if failure_thresholds else None,
        "provenance": provenance or {},
    }
    figures: dict[str, bytes] = {}
    with tempfile.TemporaryDirectory(dir=out, prefix=".report-") as tmp_name:
        tmp = Path(tmp_name)
        _draw(result, data, view, tmp)
        for name in REPORT_FILES[:-1]:
            if (tmp / name).is_file():
                figures[name] = (tmp / name).read_bytes()
                os.replace(tmp / name, out / name)
        page = tmp / "index.html"
        page.write_text(report_page.page(data, figures, view), encoding="utf-8")
        os.replace(page, out / "index.html")
    for name in set(REPORT_FILES[:-1]) - set(figures):  # a previous report's figure this one has not
        (out / name).unlink(missing_ok=True)
    return out / "index.html"


def _detection_thresholds(
    given: Mapping[str, float] | None, settings: dict[str, Any], file: str | None
) -> dict[str, Any]:
    """The detection thresholds shown and where they come from: `given` (read from `file`, when the
    provenance names one), else the result's record's (``settings["detection"]["thresholds"]`` when
    it has them), else the packaged ones."""
    if given is not None:
        return {"thresholds": dict(given), "source": file if file and file != "packaged" else "given"}
    recorded = settings.get("detection")
    if isinstance(recorded, Mapping) and isinstance(recorded.get("thresholds"), Mapping):
        return {
            "thresholds": dict(recorded["thresholds"]),
            "source": str(recorded.get("source", "the result's record")),
        }
    from .identification.detection import load_thresholds

    return {"thresholds": dict(load_thresholds()["thresholds"]), "source": "packaged"}


def _draw(result: Any, data: dict[str, Any], view: dict[str, Any], tmp: Path) -> None:
    """The figures into `tmp`, each with its title: the fit (when the result has its curves), the
    faults (not for a result that does not fit: it reports none) and the convergence."""
    from .plots import plot_convergence, plot_fit_curves

    if result.curves is not None:
        model = report_page.fit_model(data)
        nrmse = data["fit_nrmse"]
        fit = f", NRMSE {100 * nrmse:.2f} % of the filtered current" if nrmse is not None else ""
        at = "at the search's end point" if data["verdict"] == "does not fit" else "at the identified faults"
        plot_fit_curves(
            result.curves, tmp / "fit.png", f"Fit: measured vs {model} current{fit}", model=model, fitted=at
        )
    if data["verdict"] != "does not fit":
        _draw_faults(data, view, tmp / "faults.png")
    history = [v for v in data["history"] if v is not None]
    plot_convergence(
        {"best fitness": history}, tmp / "convergence.png", "Convergence: best fitness per generation"
    )


def _draw_faults(data: dict[str, Any], view: dict[str, Any], path: Path) -> None:
    """faults.png: each fault as its distance from healthy (`tables.HEALTHY_OF`; the K_P drift
    signed), labelled in physical units, with the detection and failure thresholds; the
    eccentricity's direction (k7) as text."""
    from .plots import plot_faults
    from .tables import HEALTHY_OF, direction_note, physical_faults, short_physical

    k, low, high, truth = data["estimate"], data["ci90_low"], data["ci90_high"], data["truth"]
    values = physical_faults(k, view["params"])
    limits = {"detection threshold": view["detection"]["thresholds"], "failure threshold": view["failure"]}
    plot_faults(
        {n: k[i] - h for n, (i, h) in HEALTHY_OF.items()}, path,
        intervals=None if low is None else {n: (low[i] - h, high[i] - h) for n, (i, h) in HEALTHY_OF.items()},
        truth=None if truth is None else {n: truth[i] - h for n, (i, h) in HEALTHY_OF.items()},
        thresholds={label: v for label, v in limits.items() if v},
        labels={n: f"k{i + 1} {n}\n{short_physical(n, values[n])}" for n, (i, _) in HEALTHY_OF.items()},
        verdicts=data.get("fault_verdicts") or {n: "present" for n in data["detected"]},
        signed=("kp_drift",), note=direction_note(data, values),
        title=f"Faults as distance from healthy ({data['verdict']})",
    )  # fmt: skip


def input_provenance(
    reference: str | os.PathLike[str] | None,
    *,
    truth: Sequence[float] | None = None,
    channel_map: str | os.PathLike[str] | None = None,
    conversion: dict[str, Any] | None = None,
    params: str | os.PathLike[str] | None = None,
    calibration: str | os.PathLike[str] | None = None,
    detection: str | os.PathLike[str] | None = None,
) -> dict[str, Any]:
    """The report's description of an identification's input, for `write_report(provenance=)`.

    `reference` is the file identified (its SHA-256 is recorded), or None for the HF twin run
    with `truth`; `channel_map` and `conversion` (``settings["conversion"]`` of the result) when
    the file was a rig's recording; `params`, `calibration` and `detection` the files given (None:
    the nominal actuator, the packaged calibration and detection thresholds).
    """
    from .io import sha256_of

    return {
        "reference": str(reference) if reference is not None else "HF twin, noise on",
        "sha256": sha256_of(reference) if reference is not None else None,
        "true_faults": None if truth is None else [float(v) for v in truth],
        "channel_map": str(channel_map) if channel_map is not None else None,
        "conversion": conversion,
        "params": str(params) if params is not None else "nominal",
        "calibration": str(calibration) if calibration is not None else "packaged",
        "detection": str(detection) if detection is not None else "packaged",
    }
