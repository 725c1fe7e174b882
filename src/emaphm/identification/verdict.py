"""Stage 7: the verdict. Does the fit explain the recording, what does the result warn of, and which
faults are present.

A fit whose NRMSE exceeds `limits.FIT_NRMSE_LIMIT` is not a diagnosis ("does not fit": no faults
are reported); above `limits.FIT_NRMSE_WARN` it is reported with a warning. Faults are detected
by their 90 % intervals against the detection thresholds (`uncertainty.verdicts`), or by the
point rule without intervals (`detection.detect`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from . import limits
from .detection import detect, load_thresholds

if TYPE_CHECKING:
    from ..calibration import Calibration
    from .context import Context
    from .uncertainty import Uncertainty

__all__ = ["explains", "fit_warnings", "judge", "recording_warnings"]


def explains(fit_nrmse: float | None) -> bool:
    """Whether a fit's NRMSE (`limits.FIT_NRMSE_LIMIT`) makes it a diagnosis; None (not measured) does."""
    return fit_nrmse is None or fit_nrmse <= limits.FIT_NRMSE_LIMIT


def recording_warnings(
    context: Context,
    t: Any,
    theta_cmd: Any,
    calibration: Calibration,
    thresholds: dict[str, float] | None,
    command_rate: float | None = None,
) -> list[str]:
    """What the recording and the inputs leave doubtful: a command the monitor was not calibrated
    on, motion above the band, little data compared, thresholds measured with another monitor."""
    from .coverage import command_warnings

    warnings = command_warnings(t, theta_cmd, calibration, command_rate)
    if context.above_band > 0:
        warnings.append(
            f"{100 * context.above_band:.0f} % of the recording commands motion faster than the "
            f"{limits.BAND_HZ:g} Hz the monitor was fitted on; it is left out of the comparison (docs/identification.md §3)"
        )
    if context.compared < limits.MIN_COMPARED:
        warnings.append(
            f"only {100 * context.compared:.0f} % of the recording is compared: the rest is a hold where the surface "
            "rests, whose current does not depend on the faults, or motion faster than the monitor was fitted on; "
            "the diagnosis rests on little data"
        )
    if thresholds is None:
        from ..calibration.files import params_hash
        from ..params import EmaParams

        # the packaged thresholds were measured on the nominal actuator (older files do not say so)
        made_for = load_thresholds().get("params_hash") or params_hash(EmaParams())
        this = params_hash(context.monitor.params)
        if made_for is not None and made_for != this:
            drive = context.monitor.params.inverter.control
            warnings.append(
                f"the detection thresholds were measured on another actuator (hash {made_for}; this one "
                f"{this}, a {drive} drive): run 'emaphm calibrate-detection --params FILE' and pass its "
                "file with --detection"
            )
    measured_with = load_thresholds().get("monitor", "default") if thresholds is None else None
    if measured_with is not None and measured_with != context.monitor.monitor:
        warnings.append(
            f"the detection thresholds were measured with the {measured_with!r} monitor, not the "
            f"{context.monitor.monitor!r} one: faults near them may be reported wrongly"
        )
    return warnings


def fit_warnings(fit_nrmse: float) -> list[str]:
    """A poor fit's warning, or a fit that does not explain the recording's."""
    if not explains(fit_nrmse):
        return [
            f"the monitor cannot explain this recording (NRMSE {100 * fit_nrmse:.3g} % of the "
            f"filtered current, at most {100 * limits.FIT_NRMSE_LIMIT:g} % for a diagnosis): check the units, "
            "signs and command of the trace; no faults are reported"
        ]
    if fit_nrmse > limits.FIT_NRMSE_WARN:
        return [
            f"the fit is poor (NRMSE {100 * fit_nrmse:.3g} % of the filtered current; the twin's actuators "
            f"fit to 0.3-3.9 %): the faults below are doubtful; check the current's gain and the recording's segment, "
            "command and actuator"
        ]
    return []


def judge(
    faults: np.ndarray, fit_nrmse: float, interval: Uncertainty | None, thresholds: dict[str, float] | None
) -> tuple[list[str], dict[str, str] | None]:
    """The faults detected and, with intervals, the verdict per fault ("present", "absent",
    "cannot tell"); none when the fit does not explain the recording. `thresholds` overrides the
    shipped detection thresholds ({} reports nothing)."""
    from .uncertainty import verdicts

    limits_ = thresholds if thresholds is not None else load_thresholds()["thresholds"]
    if not explains(fit_nrmse):
        return [], None
    if interval is None:
        return detect(faults, limits_), None
    judged = verdicts(faults, interval.ci90_low, interval.ci90_high, limits_)
    return [name for name, v in judged.items() if v == "present"], judged
