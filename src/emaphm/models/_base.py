"""What both fidelities share: parameter packs, the sample grid, seeds, metadata, output checks.

`HighFidelityEma` (`hf.py`, kernels/hf_twin.py) and `MonitorEma` (`lf.py`, kernels/monitor.py)
derive from `_EmaModel`; `emaphm.models.simulate` dispatches between them.
"""

from __future__ import annotations

import functools
import math
import os
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .._version import __version__
from ..commands import Chirp, Command, SampledCommand, command_record
from ..errors import InputError, SimulationError
from ..faults import FaultedParameters
from ..kernels.controller import ControllerPack
from ..kernels.mechanics import MechanicsPack
from ..params import EmaParams

__all__ = [
    "MAX_SAMPLES",
    "MAX_SEED",
    "_EmaModel",
    "check_finite",
    "check_seed",
    "controller_pack",
    "mechanics_pack",
    "sample_count",
]


MAX_SEED = 2**63 - 1  # seeds are stored as int64 (HDF5 attributes, JSON readers)
MAX_SAMPLES = 10_000_001  # 1000 s at 10 kHz: about 2 GB of HF signals; beyond it, a mistake


def check_seed(seed: Any) -> int:
    """`seed` as an int if it is a whole number in 0..2^63 − 1, else `InputError`."""
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not 0 <= seed <= MAX_SEED:
        raise InputError(f"seed must be a whole number in 0..2^63-1, got {seed!r}")
    return int(seed)


def check_finite(out: NDArray[np.float64], model: str, faults: NDArray[np.float64]) -> None:
    """Raise `SimulationError` when a kernel output holds NaN or inf (it names the fault vector)."""
    if not np.all(np.isfinite(out)):
        k = ", ".join(f"{v:.6g}" for v in np.ravel(faults))
        raise SimulationError(
            f"the {model.upper()} simulation diverged (NaN or inf) for faults [{k}]; "
            "check the parameters (inductances, inertia, gains) and the time step"
        )


def sample_count(duration: float, f_s: float) -> int:
    """Samples on 0, 1/f_s, … up to `duration` [s] inclusive: floor(duration·f_s) + 1.

    The floor (with a rounding allowance) keeps the grid inside a measured trace whose span is
    not a whole number of sample periods (1 s at 3 kHz ends at 0.99967 s, within 9996/f_s).
    """
    return math.floor(duration * f_s * (1.0 + 1e-12) + 1e-9) + 1


def controller_pack(params: EmaParams, fp: FaultedParameters) -> ControllerPack:
    """Controller parameters for the kernels, with the K_P drift applied."""
    c = params.controller
    return ControllerPack(fp.K_P, c.K_I, c.K_D, c.tau_D, c.I_max, 1.0 / c.f_s, params.transmission.tau)


def mechanics_pack(params: EmaParams, fp: FaultedParameters) -> MechanicsPack:
    """Drive-train parameters for the kernels, with friction and backlash faults applied."""
    tr = params.transmission
    return MechanicsPack(tr.J, tr.C, fp.F_S, fp.F_D, fp.B, tr.tau, tr.eta, tr.theta_max, tr.T_load)


def _grid(command: Command, f_s: float, duration: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    t = np.arange(sample_count(duration, f_s)) / f_s
    theta_cmd = np.ascontiguousarray(command(t), dtype=np.float64)
    t.setflags(write=False)
    theta_cmd.setflags(write=False)
    return t, theta_cmd


# the grids of the built-in commands, which are small and few; a recording's (`SampledCommand`,
# hashed by identity) is not kept: a long-lived campaign worker kept 32 of them alive (review L5)
_sample_grid = functools.lru_cache(maxsize=32)(_grid)


@functools.lru_cache(maxsize=32)
def _params_dict(params: EmaParams) -> dict[str, Any]:
    return params.to_dict()


class _EmaModel:
    """What both fidelities share: parameters, command, the sample grid and the result metadata."""

    model = ""

    def __init__(
        self, params: EmaParams | str | os.PathLike[str] | None = None, command: Command | None = None
    ) -> None:
        from ..actuator import resolve_params

        self.params = resolve_params(params)  # an actuator file's path works as the docs say
        self.command = command if command is not None else Chirp()

    def sample_grid(self, duration: float | None = None) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Sample instants t_k = k/f_s [s] over `duration` (default: the command's) and θ_cmd(t_k) [rad].

        The arrays are read-only, and cached for the built-in commands.
        """
        duration = float(self.command.duration if duration is None else duration)
        if not (math.isfinite(duration) and duration > 0):
            raise InputError(f"duration must be a finite number > 0 s, got {duration!r}")
        f_s = self.params.controller.f_s
        n = sample_count(duration, f_s)
        if n < 2:
            raise InputError(f"duration {duration:g} s is shorter than one sample period ({1 / f_s:g} s)")
        if n > MAX_SAMPLES:
            raise InputError(
                f"duration {duration:g} s is longer than one run can simulate: at most "
                f"{(MAX_SAMPLES - 1) / f_s:g} s ({MAX_SAMPLES - 1} samples at {f_s:g} Hz)"
            )
        grid = _grid if isinstance(self.command, SampledCommand) else _sample_grid
        return grid(self.command, self.params.controller.f_s, duration)

    def metadata(
        self, k: NDArray[np.float64], seed: int, noise: bool, t: NDArray[np.float64], **extra: Any
    ) -> dict[str, Any]:
        """What produced a result: model, faults, seed, noise, command, parameters, version."""
        return {
            "model": self.model,
            "faults": k.tolist(),
            "seed": seed,
            "noise": bool(noise),
            "duration": float(t[-1]),
            "command": command_record(self.command),
            "params": {group: dict(values) for group, values in _params_dict(self.params).items()},
            **extra,
            "version": __version__,
        }
