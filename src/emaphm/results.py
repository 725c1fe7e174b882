"""`SimResult`: the sampled signals of one simulation, with their units and metadata."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .errors import InputError

__all__ = ["REQUIRED_SIGNALS", "UNITS", "SimResult", "check_time_axis"]

UNITS: dict[str, str] = {
    "t": "s",
    "theta_cmd": "rad",
    "theta_u": "rad",
    "i_q": "A",
    "i_a": "A",
    "i_b": "A",
    "i_c": "A",
    "theta_e": "rad",
    "omega_m": "rad/s",
    "i_q_ref": "A",
    "T_m": "N·m",
    "theta_u_true": "rad",
}
# what a diagnosis needs; theta_u (the measured surface position) is used when present (the holds
# where the surface rests are left out of the fitness) but a rig may not record it
REQUIRED_SIGNALS = ("t", "theta_cmd", "i_q")


def check_time_axis(t: Any, what: str = "the time axis") -> None:
    """`InputError` naming the first sample of `t` that does not follow the one before it: the
    times must increase strictly (`np.interp` and the filters need it; review L1)."""
    steps = np.diff(np.asarray(t, dtype=np.float64))
    if len(steps) and not np.all(steps > 0):
        row = int(np.flatnonzero(~(steps > 0))[0]) + 1
        raise InputError(f"{what} must increase strictly; sample {row} is at or before the one before it")


@dataclass(frozen=True)
class SimResult:
    """Signals on the sample grid t (SI units, see `UNITS`) and the metadata that produced them.

    Signals are reached as attributes (``result.i_q``) or by name (``result["i_a"]``).
    Measured signals (``theta_u``, ``i_a``, ``i_b``, ``i_c``, ``i_q``) carry the ADC and, when
    enabled, the noise; ``theta_u_true`` and ``T_m`` are the simulator's internal truth.

    t : ndarray  sample times [s]
    signals : mapping of str to ndarray  each signal on `t`, in SI (`UNITS`)
    metadata : mapping  what produced them (model, faults, seed, parameters, command, ...)
    """

    t: NDArray[np.float64]
    signals: Mapping[str, NDArray[np.float64]]
    metadata: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        check_time_axis(self.t)
        for name, values in self.signals.items():
            if values.shape != self.t.shape:
                raise ValueError(f"signal {name!r} has shape {values.shape}, t has {self.t.shape}")

    def __getattr__(self, name: str) -> NDArray[np.float64]:
        signals = self.__dict__.get("signals", {})
        if name in signals:
            return signals[name]  # type: ignore[no-any-return]
        raise AttributeError(f"SimResult has no signal or attribute {name!r}")

    def __getitem__(self, name: str) -> NDArray[np.float64]:
        if name == "t":
            return self.t
        return self.signals[name]

    @property
    def names(self) -> tuple[str, ...]:
        """All signal names, time first."""
        return ("t", *self.signals)
