"""Actuators drawn about a nameplate: the plants a diagnosis must hold on, not only its own twin.

No real actuator matches its nameplate, and no real drive its data sheet: `drawn_actuator` gives
one drawn about an actuator file, for the benchmarks that score the diagnosis off its twin and for
the interval calibration of an FOC drive (`calibration.fit_intervals`), whose intervals must hold
on drives that share the description but not the details the twin happens to share with the
monitor (the PI gains as built, the carrier's phase, the integration step).
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from .params import EmaParams

__all__ = ["DRIVE_TOLERANCE", "TOLERANCED", "drawn_actuator"]

# the constants `tolerance` draws, by group of `EmaParams`
TOLERANCED = {"motor": ("R_s", "L_s", "psi_m"), "transmission": ("J_m", "J_u", "F_S0", "F_D0")}
# an FOC drive's PI gains as built, relative to the file's (the interval calibration's default)
DRIVE_TOLERANCE = 0.1


def drawn_actuator(
    params: EmaParams,
    seed: int,
    *,
    tolerance: float = 0.0,
    drive_tolerance: float = 0.0,
    steps: tuple[float, ...] = (),
) -> EmaParams:
    """An actuator drawn about `params` from `seed` (the same seed, the same actuator).

    Parameters
    ----------
    params : EmaParams
        The nameplate.
    seed : int
        Seed of the draws.
    tolerance : float
        The motor and drive-train constants of `TOLERANCED` each uniform within ±tolerance
        (relative).
    drive_tolerance : float
        For an FOC drive: its PI gains K_p_i, K_i_i each within ±drive_tolerance and its carrier
        at a uniform phase (`pwm_phase`); nothing for a hysteresis drive.
    steps : tuple of float
        The twin's integration step drawn from these [s] (each must divide 1/f_s); kept when empty.
    """
    rng = np.random.default_rng(seed)

    def scaled(group: Any, names: tuple[str, ...], spread: float) -> Any:
        return dataclasses.replace(
            group, **{n: getattr(group, n) * (1 + rng.uniform(-spread, spread)) for n in names}
        )

    out = dataclasses.replace(
        params, **{g: scaled(getattr(params, g), names, tolerance) for g, names in TOLERANCED.items()}
    )
    if params.inverter.foc:
        inverter = scaled(params.inverter, ("K_p_i", "K_i_i"), drive_tolerance)
        phase = float(rng.uniform()) if drive_tolerance > 0 else params.inverter.pwm_phase
        out = dataclasses.replace(out, inverter=dataclasses.replace(inverter, pwm_phase=phase))
    if steps:
        dt = float(steps[rng.integers(len(steps))])
        out = dataclasses.replace(out, integration=dataclasses.replace(out.integration, dt=dt))
    return out
