"""The fault vector k = (k1..k8), each in [0, 1] (DESIGN §2), and its mapping to physical parameters.

| k  | name                 | maps to                                   | healthy |
|----|----------------------|-------------------------------------------|---------|
| k1 | friction             | F_S = F_S0·(1 + 2·k1), F_D = F_D0·(1 + 2·k1) | 0    |
| k2 | backlash             | B = B0·(1 + 99·k2)                        | 0       |
| k3 | short_a              | N_A = 1 − k3 (fraction of healthy turns)  | 0       |
| k4 | short_b              | N_B = 1 − k4                              | 0       |
| k5 | short_c              | N_C = 1 − k5                              | 0       |
| k6 | eccentricity         | ζ = k6                                    | 0       |
| k7 | eccentricity_phase   | φ_e = 2π·k7                               | any     |
| k8 | kp_drift             | K_P = K_P0·(0.5 + k8)                     | 0.5     |

Faults are data: the mapping produces per-phase parameters and factors that the kernels read.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .choices import HEALTHY_TEXT
from .errors import InputError
from .params import EmaParams

__all__ = [
    "FAULT_DESCRIPTIONS",
    "FAULT_NAMES",
    "HEALTHY",
    "N_MIN",
    "RANDOM_CASE_RANGES",
    "SHORTS",
    "TABLE1_REFERENCE",
    "FaultedParameters",
    "apply_faults",
    "as_fault_matrix",
    "as_fault_vector",
    "fault_parameter_columns",
    "parse_faults",
    "random_faults",
]

FAULT_NAMES: tuple[str, ...] = (
    "friction",
    "backlash",
    "short_a",
    "short_b",
    "short_c",
    "eccentricity",
    "eccentricity_phase",
    "kp_drift",
)
SHORTS: tuple[int, ...] = tuple(FAULT_NAMES.index(n) for n in ("short_a", "short_b", "short_c"))
"""The indices of the three phases' shorts k3..k5 in the fault vector."""
FAULT_DESCRIPTIONS: tuple[str, ...] = (
    "dry friction, F = F0·(1 + 2·k1)",
    "backlash, B = B0·(1 + 99·k2)",
    "coil short circuit phase A, N_A = 1 − k3",
    "coil short circuit phase B, N_B = 1 − k4",
    "coil short circuit phase C, N_C = 1 − k5",
    "static eccentricity modulus, ζ = k6",
    "static eccentricity phase, φ_e = 2π·k7",
    "proportional-gain drift, K_P = K_P0·(0.5 + k8)",
)
HEALTHY: NDArray[np.float64] = np.array([float(v) for v in HEALTHY_TEXT.split(",")])
HEALTHY.setflags(write=False)
TABLE1_REFERENCE: NDArray[np.float64] = np.array(
    [0.2383, 0.5003, 5.32e-7, 0.4503, 0.0404, 0.0028, 0.2785, 0.5]
)  # the paper's Table 1 "Ref." row
TABLE1_REFERENCE.setflags(write=False)

N_MIN = 0.05
"""Smallest fraction of healthy turns kept in a shorted coil (DESIGN §3.6): N_x = max(1 − k, N_MIN)."""


def as_fault_vector(faults: ArrayLike, *, name: str = "fault vector") -> NDArray[np.float64]:
    """Validate and return `faults` as a new float array of 8 values in [0, 1].

    Raises `InputError` with a one-line reason for a wrong length, a non-number, NaN/inf or a value
    outside [0, 1].

    Parameters
    ----------
    faults : array_like of 8 floats
        The values to check.
    name : str
        What `faults` is, for the error message (e.g. ``"scenario 'a'"``).
    """
    try:
        arr = np.array(faults, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be 8 numbers, got {faults!r}") from None
    if arr.ndim != 1 or arr.size != len(FAULT_NAMES):
        raise InputError(f"{name} must have {len(FAULT_NAMES)} values (k1..k8), got {arr.size}")
    bad = ~np.isfinite(arr)
    if bad.any():
        i = int(np.argmax(bad))
        raise InputError(f"{name}: k{i + 1} ({FAULT_NAMES[i]}) is {arr[i]}, must be a number in [0, 1]")
    out = (arr < 0.0) | (arr > 1.0)
    if out.any():
        i = int(np.argmax(out))
        raise InputError(f"{name}: k{i + 1} ({FAULT_NAMES[i]}) = {arr[i]:g} is outside [0, 1]")
    return arr


def parse_faults(text: str, *, option: str = "--faults") -> NDArray[np.float64]:
    """Parse the CLI form ``K1,...,K8`` into a validated fault vector (errors name `option`)."""
    parts = [p.strip() for p in text.split(",")]
    values: list[float] = []
    for i, part in enumerate(parts):
        try:
            values.append(float(part))
        except ValueError:
            raise InputError(f"{option}: value {i + 1} ({part!r}) is not a number") from None
    return as_fault_vector(values, name=option)


@dataclass(frozen=True)
class FaultedParameters:
    """Physical parameters after applying a fault vector (DESIGN §2).

    F_S : float  static friction, motor side [N·m]
    F_D : float  dynamic friction, motor side [N·m]
    B : float  total backlash, user side [rad]
    N : tuple[float, float, float]  fraction of healthy turns of phases A, B, C [-]
    zeta : float  relative static eccentricity [-]
    phi_e : float  eccentricity direction, electrical [rad]
    K_P : float  proportional gain of the position PID [A/rad]
    """

    F_S: float
    F_D: float
    B: float
    N: tuple[float, float, float]
    zeta: float
    phi_e: float
    K_P: float


def as_fault_matrix(K: ArrayLike, *, name: str = "fault matrix") -> NDArray[np.float64]:
    """Validate a matrix of fault vectors, one per row (shape (m, 8)), each entry in [0, 1]."""
    arr = np.array(K, dtype=np.float64, ndmin=2)
    if arr.ndim != 2 or arr.shape[1] != len(FAULT_NAMES):
        raise InputError(f"{name} must have shape (m, {len(FAULT_NAMES)}), got {arr.shape}")
    if not np.all(np.isfinite(arr)) or np.any((arr < 0.0) | (arr > 1.0)):
        row = int(np.argmax(~np.isfinite(arr).all(axis=1) | ((arr < 0) | (arr > 1)).any(axis=1)))
        as_fault_vector(arr[row], name=f"{name} row {row}")  # raises with the reason
    return arr


def fault_parameter_columns(K: NDArray[np.float64], params: EmaParams) -> dict[str, NDArray[np.float64]]:
    """The DESIGN §2 mapping for validated fault rows K (shape (m, 8)): one array per parameter."""
    tr = params.transmission
    friction = 1.0 + 2.0 * K[:, 0]
    N = np.maximum(1.0 - K[:, 2:5], N_MIN)
    return {
        "F_S": tr.F_S0 * friction,
        "F_D": tr.F_D0 * friction,
        "B": tr.B0 * (1.0 + 99.0 * K[:, 1]),
        "N_A": N[:, 0],
        "N_B": N[:, 1],
        "N_C": N[:, 2],
        "zeta": K[:, 5].copy(),
        "phi_e": 2.0 * math.pi * K[:, 6],
        "K_P": params.controller.K_P0 * (0.5 + K[:, 7]),
    }


def apply_faults(faults: ArrayLike, params: EmaParams) -> FaultedParameters:
    """Map a fault vector to the physical parameters it changes (DESIGN §2).

    Parameters
    ----------
    faults : array_like of 8 floats in [0, 1]
        The fault vector k1..k8 (checked by `as_fault_vector`).
    params : EmaParams
        The healthy actuator whose parameters the faults change.
    """
    K = as_fault_vector(faults)[None, :]
    col = {name: float(v[0]) for name, v in fault_parameter_columns(K, params).items()}
    return FaultedParameters(
        F_S=col["F_S"], F_D=col["F_D"], B=col["B"], N=(col["N_A"], col["N_B"], col["N_C"]),
        zeta=col["zeta"], phi_e=col["phi_e"], K_P=col["K_P"],
    )  # fmt: skip


RANDOM_CASE_RANGES: tuple[tuple[float, float], ...] = (
    (0.0, 0.6), (0.0, 0.6), (0.0, 0.5), (0.0, 0.5), (0.0, 0.5), (0.0, 0.3), (0.0, 1.0), (0.3, 0.7),
)  # fmt: skip
"""DESIGN §7 ranges of the random benchmark cases, (low, high) per fault k1..k8."""


def random_faults(n: int, seed: int, *, absent: float = 0.0) -> NDArray[np.float64]:
    """n random fault vectors, uniform in `RANDOM_CASE_RANGES`, from `seed` (shape (n, 8)).

    With `absent` > 0 each fault but k7 is healthy (`HEALTHY`) with that probability, drawn
    from a stream of its own (the values are those of ``absent=0``): actuators where some faults
    are truly absent, on which spurious detections can be counted.
    """
    if not 0.0 <= absent <= 1.0:
        raise InputError(f"absent must be a probability in [0, 1], got {absent}")
    low, high = np.array(RANDOM_CASE_RANGES).T
    K = low + (high - low) * np.random.default_rng(seed).uniform(size=(n, len(FAULT_NAMES)))
    if absent > 0.0:
        healthy = np.random.default_rng([seed, 1]).uniform(size=K.shape) < absent
        healthy[:, 6] = False  # k7 is the direction of k6, not a fault of its own
        K = np.where(healthy, HEALTHY, K)
    return K


def describe(k: Sequence[float] | NDArray[np.float64]) -> str:
    """One line naming each fault and its value, e.g. for logs."""
    return ", ".join(f"k{i + 1} {n}={v:.4g}" for i, (n, v) in enumerate(zip(FAULT_NAMES, k, strict=True)))
