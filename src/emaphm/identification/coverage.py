"""Is a measurement inside what the monitor model was calibrated for? (issue 8, item 5)

The monitor's coefficients are fitted on one command (the FDI chirp of DESIGN §6, 1 s). A trace
recorded under another command, or running on after it (a 2 s chirp, the chirp followed by a
hold), is still identified, but nothing has measured how well: a 2 s chirp gave 13 %err and the
chirp followed by a hold 28–69 %err with the short in the wrong phase, where the calibrated 1 s
chirp gives about 3. Such a result carries a warning instead of passing for a calibrated one.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ..calibration import Calibration

__all__ = ["COMMAND_TOLERANCE", "command_warnings"]

# the command may differ from the calibrated one by this fraction of its peak (sampling and
# interpolation of a recorded command stay far below: ~1e-6 for a 10 Hz chirp at 3 kHz)
COMMAND_TOLERANCE = 1e-3


def command_warnings(t: ArrayLike, theta_cmd: ArrayLike, calibration: Calibration) -> list[str]:
    """Reasons why a trace's command lies outside the calibration's; [] when it does not.

    t [s] starts the trace (shifted to 0 here), theta_cmd [rad] is its position command.
    """
    command = calibration.command()
    if command is None:
        return ["the calibration records no command: its accuracy on this one is unknown"]
    times = np.asarray(t, dtype=np.float64)
    times = times - times[0]
    theta = np.asarray(theta_cmd, dtype=np.float64)
    reasons = []
    span, duration = float(times[-1]), float(command.duration)
    # one sample period of slack: a 1 s command ends at 0.9999 s or 1.0 s depending on the logger
    step = float(np.median(np.diff(times))) if len(times) > 1 else 0.0
    if span > duration + step + 1e-9:
        reasons.append(
            f"the trace runs {span:g} s, the monitor was calibrated on a {duration:g} s command: "
            "its accuracy beyond that is not known"
        )
    inside = times <= duration
    expected = np.asarray(command(times[inside]), dtype=np.float64)
    peak = float(np.max(np.abs(expected))) if expected.size else 0.0
    deviation = float(np.max(np.abs(theta[inside] - expected))) if expected.size else 0.0
    if peak > 0.0 and deviation > COMMAND_TOLERANCE * peak:
        reasons.append(
            f"the position command differs from the one the monitor was calibrated on "
            f"({type(command).__name__}, by up to {deviation:.3g} rad of {peak:.3g}): "
            "the identification is not calibrated for it"
        )
    return reasons
