"""Is a measurement inside what the monitor model was calibrated for? (issue 8, item 5)

The monitor's coefficients are fitted and checked on a few commands (the packaged calibration:
fitted on the FDI chirp of DESIGN §6 and a staircase of steps, checked also on that chirp run on
for 2 s and on the chirp followed by a hold; `calibration.scenarios.CALIBRATION_COMMANDS`). A trace recorded under another command, or
running on beyond them, is still identified, but nothing has measured how well: before the
monitor was calibrated on them, a 2 s chirp gave 13 %err and the chirp followed by a hold
28–69 %err with the short in the wrong phase, where the calibrated 1 s chirp gave about 3. Such a
result carries a warning instead of passing for a calibrated one.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..calibration import Calibration
from ..commands import Command
from .windows import running_max

__all__ = ["COMMAND_TOLERANCE", "command_rate", "command_warnings", "matches"]

# the command may differ from the calibrated one by this fraction of its peak (sampling and
# interpolation of a recorded command stay far below: ~1e-6 for a 10 Hz chirp at 3 kHz)
COMMAND_TOLERANCE = 1e-3


def matches(
    times: NDArray[np.float64], theta: NDArray[np.float64], command: Command, step: float, h: float
) -> bool:
    """Whether θ_cmd is `command` over the trace's times within the command.

    At each sample |θ_cmd − command| may reach `COMMAND_TOLERANCE` of the command's peak, plus,
    for a command logged every h [s] (> the trace's `step`) and interpolated linearly, that
    interpolation's own error there, h²/8·|θ''| (the largest |θ''| within h of the sample). The
    command may be shifted by up to one sample period `step` either way (a logger that stamps the
    demand a sample early or late).
    """
    inside = times <= command.duration
    if not inside.any():
        return False
    for shift in (0.0, -step, step):
        expected = np.asarray(command(np.clip(times[inside] - shift, 0.0, None)), dtype=np.float64)
        peak = float(np.max(np.abs(expected)))
        allowed = np.full(len(expected), COMMAND_TOLERANCE * peak)
        if h > step and len(expected) > 2:
            curvature = np.zeros(len(expected))
            curvature[1:-1] = np.abs(np.diff(expected, 2)) / step**2
            reach = math.ceil(h / step)  # the centred window of 2 * reach + 1 samples
            allowed += h * h / 8.0 * running_max(curvature, reach, reach, mode="nearest")
        deviation = np.abs(theta[inside] - expected)
        if np.all(deviation <= allowed) or (peak == 0.0 and not deviation.any()):
            return True
    return False


def command_warnings(
    t: ArrayLike, theta_cmd: ArrayLike, calibration: Calibration, source_rate: float | None = None
) -> list[str]:
    """Reasons why a trace's command lies outside the calibration's commands; [] when it does not.

    t [s] starts the trace (shifted to 0 here), theta_cmd [rad] is its position command. The trace
    is inside when one calibrated command lasts at least as long and matches it over the trace:
    within `COMMAND_TOLERANCE` of its peak, plus, for a command logged at `source_rate` [Hz] below
    the trace's and interpolated onto it linearly, that interpolation's own error h²/8·max|θ''|
    (h = 1/source_rate; a chirp logged at 500 Hz departs by 2.3e-3 of its peak).
    """
    commands = calibration.commands()
    if not commands:
        return ["the calibration records no command: its accuracy on this one is unknown"]
    times = np.asarray(t, dtype=np.float64)
    times = times - times[0]
    theta = np.asarray(theta_cmd, dtype=np.float64)
    span = float(times[-1])
    # one sample period of slack: a 1 s command ends at 0.9999 s or 1.0 s depending on the logger
    step = float(np.median(np.diff(times))) if len(times) > 1 else 0.0
    longest = max(float(c.duration) for c in commands.values())
    names = ", ".join(f"{name} ({c.duration:g} s)" for name, c in commands.items())
    if span > longest + step + 1e-9:
        return [
            f"the trace runs {span:g} s, the monitor was calibrated on commands of at most {longest:g} s "
            f"({names}): its accuracy beyond that is not known"
        ]
    for command in commands.values():
        if span > float(command.duration) + step + 1e-9:
            continue
        h = 1.0 / source_rate if source_rate and source_rate > 0 else 0.0
        if matches(times, theta, command, step, h):
            return []
    return [
        f"the position command is none of those the monitor was calibrated on ({names}): "
        "the identification is not calibrated for it"
    ]


def command_rate(conversion: dict[str, Any] | None) -> float | None:
    """The rate [Hz] a recording's command was logged at (its conversion report); None for a trace."""
    channel = (conversion or {}).get("channels", {}).get("theta_cmd") or {}
    rate = channel.get("rate_hz")
    return float(rate) if isinstance(rate, (int, float)) and rate > 0 else None
