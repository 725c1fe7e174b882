"""The actuator's constants the nameplate does not fix, as factors about it (issues 33, item 1 and 4).

A baseline (`emaphm.baseline`) fits them to recordings of the actuator when healthy; without one,
the actuator file's ``[tolerances]`` table says how far each may be from its nameplate. Either
way their uncertainty widens the fault intervals for what it can move
(`identification.uncertainty.constants`). Each constant is a factor on what it scales:

    i_gain   the current sensor's gain (the measured current is i_gain × the actuator's)
    k_t_eq   the monitor's torque gain            k_e_eq   its back-EMF gain (both ∝ ψ_m)
    J_eq     the inertia at the motor shaft (J_m + J_u/τ²)
    F_S0, F_D0   static and dynamic friction, healthy
    K_P0     the position loop's gain as it acts

The ``[tolerances]`` table names physical quantities, each a relative tolerance (a uniform band
±T, σ = T/√3 in log): ``psi_m`` moves k_t,eq and k_e,eq together, ``J`` the inertia, ``friction``
both friction levels, ``current_gain`` the sensor, ``K_P`` the position gain. Default (`TOLERANCES`):
±2 % on ψ_m, J and friction, as the issue asks; the others 0.
"""

from __future__ import annotations

import math
import os
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .errors import InputError
from .params import EmaParams

__all__ = ["CONSTANTS", "TOLERANCES", "apply", "load_tolerances", "tolerance_covariance"]

CONSTANTS = ("i_gain", "k_t_eq", "k_e_eq", "J_eq", "F_S0", "F_D0", "K_P0")
TOLERANCES: dict[str, float] = {"psi_m": 0.02, "J": 0.02, "friction": 0.02, "current_gain": 0.0, "K_P": 0.0}
# which constants each tolerance moves (all by the same factor)
_MOVES: dict[str, tuple[str, ...]] = {
    "psi_m": ("k_t_eq", "k_e_eq"), "J": ("J_eq",), "friction": ("F_S0", "F_D0"), "current_gain": ("i_gain",),
    "K_P": ("K_P0",),
}  # fmt: skip


def apply(params: EmaParams, calibration: Any, factors: dict[str, float]) -> tuple[EmaParams, Any]:
    """The actuator and the monitor's calibration with the constants scaled by `factors` (a
    missing one: 1). The sensor's gain `i_gain` scales neither: it is the measurement's."""
    f = {c: float(factors.get(c, 1.0)) for c in (*CONSTANTS, "B0")}
    tr = params.transmission
    transmission = replace(
        tr, F_S0=tr.F_S0 * f["F_S0"], F_D0=tr.F_D0 * f["F_D0"], B0=tr.B0 * f["B0"], J_m=tr.J_m * f["J_eq"],
        J_u=tr.J_u * f["J_eq"],
    )  # fmt: skip
    controller = replace(params.controller, K_P0=params.controller.K_P0 * f["K_P0"])
    motor = replace(params.motor, psi_m=params.motor.psi_m * f["k_e_eq"])
    fitted = replace(params, transmission=transmission, controller=controller, motor=motor)
    c = calibration.coefficients
    coefficients = replace(c, k_t_eq=c.k_t_eq * f["k_t_eq"], k_e_eq=c.k_e_eq * f["k_e_eq"], J_eq=c.J_eq * f["J_eq"])
    return fitted, replace(calibration, coefficients=coefficients)


def load_tolerances(path: str | os.PathLike[str] | None) -> dict[str, float]:
    """The ``[tolerances]`` table of an actuator file over `TOLERANCES` (None: the defaults)."""
    out = dict(TOLERANCES)
    if path is None:
        return out
    from .io import read_toml

    p = Path(path)
    table = read_toml(p, "actuator file").get("tolerances", {})
    if not isinstance(table, dict):
        raise InputError(f"{p}: [tolerances] must be a table of QUANTITY = relative tolerance")
    for name, value in table.items():
        if name not in TOLERANCES:
            raise InputError(f"{p}: [tolerances] {name!r} is not one of {', '.join(TOLERANCES)}")
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0.0 <= value < 0.5:
            raise InputError(f"{p}: [tolerances] {name} = {value!r} must be a relative tolerance in [0, 0.5)")
        out[name] = float(value)
    return out


def tolerance_covariance(tolerances: dict[str, float]) -> NDArray[np.float64]:
    """The covariance of the constants' log-factors (`CONSTANTS` order) that the tolerances allow."""
    index = {c: i for i, c in enumerate(CONSTANTS)}
    cov = np.zeros((len(CONSTANTS), len(CONSTANTS)))
    for name, t in tolerances.items():
        a = np.zeros(len(CONSTANTS))
        a[[index[c] for c in _MOVES[name]]] = 1.0
        sigma = math.log1p(t) / math.sqrt(3.0)
        cov += sigma**2 * np.outer(a, a)
    return cov
