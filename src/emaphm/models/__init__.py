"""Models of the EMA, one module per fidelity, mirroring `kernels/` (DESIGN §3, §4, §8).

- `HighFidelityEma` (`hf.py` over `kernels/hf_twin.py`): the three-phase digital twin, "the real
  actuator";
- `MonitorEma` (`lf.py` over `kernels/monitor.py`): the calibrated low-fidelity monitor model;
- `simulate()`: the one-call entry point of DESIGN §8.

Each model holds its parameters, validates input, packs parameters for the kernels, checks the
kernel output and wraps it in a `SimResult`.
"""

from __future__ import annotations

import os

from numpy.typing import ArrayLike

from ..calibration import Calibration
from ..commands import Command
from ..errors import InputError
from ..faults import HEALTHY
from ..params import EmaParams
from ..results import SimResult
from .hf import HighFidelityEma
from .lf import MonitorEma

__all__ = ["HighFidelityEma", "MonitorEma", "make_model", "simulate"]

MODELS: dict[str, type[HighFidelityEma] | type[MonitorEma]] = {"hf": HighFidelityEma, "lf": MonitorEma}


def simulate(
    faults: ArrayLike = HEALTHY,
    *,
    model: str = "hf",
    noise: bool = True,
    seed: int = 0,
    params: EmaParams | str | os.PathLike[str] | None = None,
    command: Command | None = None,
    duration: float | None = None,
    calibration: Calibration | str | os.PathLike[str] | None = None,
    monitor: str | None = None,
) -> SimResult:
    """Simulate the EMA with fault vector `faults` (DESIGN §8).

    Parameters
    ----------
    faults : array_like of 8 floats in [0, 1]
        k1..k8 (see `emaphm.faults`); healthy by default.
    model : {"hf", "lf"}
        Fidelity: the high-fidelity twin or the calibrated low-fidelity monitor model (i_q is
        then the equivalent current).
    noise : bool
        Add the seeded measurement noise (ADC quantisation is always on in the HF twin).
    seed : int
        Seed of every random choice.
    params, command, duration
        Override the nominal parameters (an `EmaParams` or an actuator file's path), the FDI
        chirp, or its duration [s].
    calibration : Calibration or path, optional
        The monitor model's calibration (``model="lf"`` only; the packaged one by default).
    monitor : {"default", "paper"}, optional
        Which monitor model (``model="lf"`` only): see `MonitorEma`.
    """
    ema = make_model(model, params=params, command=command, calibration=calibration, monitor=monitor)
    return ema.simulate(faults, noise=noise, seed=seed, duration=duration)


def make_model(
    model: str = "hf",
    *,
    params: EmaParams | str | os.PathLike[str] | None = None,
    command: Command | None = None,
    calibration: Calibration | str | os.PathLike[str] | None = None,
    monitor: str | None = None,
) -> HighFidelityEma | MonitorEma:
    """The model named `model` ("hf" or "lf"); `calibration` and `monitor` only for the monitor
    model (`InputError` else).

    Parameters
    ----------
    model : {"hf", "lf"}
        The fidelity.
    params : EmaParams or path, optional
        The actuator, or its actuator file (default: the paper's nominal one).
    command : Command, optional
        The position command (default: the FDI chirp).
    calibration : Calibration or path, optional
        The monitor model's calibration (``"lf"`` only; default: the packaged one).
    monitor : {"default", "paper"}, optional
        The monitor model (``"lf"`` only; None: the calibration's).
    """
    if model not in MODELS:
        raise InputError(f"unknown model {model!r}; available: {', '.join(MODELS)}")
    if model == "lf":
        return MonitorEma(params, command, calibration, monitor=monitor)
    if calibration is not None:
        raise InputError("a calibration applies to the monitor model only (--model lf, model='lf')")
    if monitor is not None:
        raise InputError("a monitor choice applies to the monitor model only (--model lf, model='lf')")
    return HighFidelityEma(params, command)
