"""Models of the EMA: they hold parameters, pack them for the kernels and wrap the result.

`HighFidelityEma` is the three-phase digital twin of DESIGN §3 ("the real actuator").
`simulate()` is the one-call entry point of DESIGN §8.
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._version import __version__
from .commands import Chirp, Command, command_record
from .errors import InputError
from .faults import HEALTHY, FaultedParameters, apply_faults, as_fault_vector
from .kernels.controller import ControllerPack
from .kernels.hf_twin import N_OUT, OUT_COLUMNS, simulate_hf
from .kernels.mechanics import MechanicsPack
from .kernels.pmsm_abc import StatorPack, stator_pack
from .kernels.sensors import adc
from .kernels.transforms import clarke, park
from .params import EmaParams
from .results import SimResult

__all__ = ["HighFidelityEma", "simulate"]


def check_seed(seed: Any) -> int:
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InputError(f"seed must be a whole number >= 0, got {seed!r}")
    return int(seed)


def controller_pack(params: EmaParams, fp: FaultedParameters) -> ControllerPack:
    """Controller parameters for the kernels, with the K_P drift applied."""
    c = params.controller
    return ControllerPack(fp.K_P, c.K_I, c.K_D, c.tau_D, c.I_max, 1.0 / c.f_s, params.transmission.tau)


def mechanics_pack(params: EmaParams, fp: FaultedParameters) -> MechanicsPack:
    """Drive-train parameters for the kernels, with friction and backlash faults applied."""
    tr = params.transmission
    return MechanicsPack(tr.J, tr.C, fp.F_S, fp.F_D, fp.B, tr.tau, tr.eta, tr.theta_max, tr.T_load)


@functools.lru_cache(maxsize=32)
def _sample_grid(
    command: Command, f_s: float, duration: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    t = np.arange(round(duration * f_s) + 1) / f_s
    theta_cmd = np.ascontiguousarray(command(t), dtype=np.float64)
    t.setflags(write=False)
    theta_cmd.setflags(write=False)
    return t, theta_cmd


@functools.lru_cache(maxsize=32)
def _params_dict(params: EmaParams) -> dict[str, Any]:
    return params.to_dict()


class _EmaModel:
    """What both fidelities share: parameters, command, the sample grid and the result metadata."""

    model = ""

    def __init__(self, params: EmaParams | None = None, command: Command | None = None) -> None:
        self.params = params if params is not None else EmaParams()
        self.command = command if command is not None else Chirp()

    def sample_grid(self, duration: float | None = None) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Sample instants t_k = k/f_s [s] over `duration` (default: the command's) and θ_cmd(t_k) [rad].

        The arrays are cached and read-only.
        """
        duration = float(self.command.duration if duration is None else duration)
        if not (math.isfinite(duration) and duration > 0):
            raise InputError(f"duration must be > 0 s, got {duration!r}")
        return _sample_grid(self.command, self.params.controller.f_s, duration)  # type: ignore[arg-type]

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


class HighFidelityEma(_EmaModel):
    """The high-fidelity three-phase EMA twin (DESIGN §3).

    Parameters
    ----------
    params : EmaParams
        Nominal parameters (DESIGN §7).
    command : Command
        Position command; the velocity-limited FDI chirp by default.
    """

    model = "hf"

    def stator_pack(self, fp: FaultedParameters) -> StatorPack:
        """Per-phase stator parameters with shorts (turn removal) and eccentricity applied."""
        m, inv = self.params.motor, self.params.inverter
        return stator_pack(
            inv.V_dc, inv.h, m.p,
            [n * m.R_s for n in fp.N],  # DESIGN §3.6: R_x = N_x·R_s
            [n**2 * m.L_s for n in fp.N],  # L_x = N_x²·L_s
            [n * m.k_e for n in fp.N],  # k_e,x = N_x·k_e
            fp.zeta, fp.phi_e,
        )  # fmt: skip

    def substeps(self, sp: StatorPack) -> int:
        """Electrical sub-steps per step: no current may move by more than r_h·h per sub-step.

        The bound uses the largest possible slope V_dc/L_min; healthy it gives 1 at Δt = 1 µs.
        """
        integ = self.params.integration
        L_min = min(sp.L_a, sp.L_b, sp.L_c)
        return max(1, math.ceil(sp.V_dc * integ.dt / (L_min * integ.ripple_fraction * sp.h) - 1e-9))

    def simulate(
        self,
        faults: ArrayLike = HEALTHY,
        *,
        noise: bool = True,
        seed: int = 0,
        duration: float | None = None,
    ) -> SimResult:
        """Simulate the twin with fault vector `faults` and return the sampled signals.

        `seed` drives every random choice (the measurement noise); `noise=False` leaves only the
        deterministic ADC quantisation. `duration` defaults to the command's.
        """
        k = as_fault_vector(faults)
        seed = check_seed(seed)
        params = self.params
        t, theta_cmd = self.sample_grid(duration)
        n = len(t)

        sens = params.sensors
        rng = np.random.default_rng(seed)
        if noise:
            theta_noise = rng.normal(0.0, sens.sigma_position, n)
            current_noise = rng.normal(0.0, sens.sigma_current, (3, n))
        else:
            theta_noise = np.zeros(n)
            current_noise = np.zeros((3, n))

        fp = apply_faults(k, params)
        sp = self.stator_pack(fp)
        n_sub = self.substeps(sp)
        out = np.empty((n, N_OUT))
        simulate_hf(
            theta_cmd, theta_noise, sens.lsb_position, sens.full_scale_position,
            controller_pack(params, fp), sp, mechanics_pack(params, fp),
            params.integration.dt, params.steps_per_sample, n_sub, out,
        )  # fmt: skip
        col = {name: out[:, j].copy() for j, name in enumerate(OUT_COLUMNS)}

        # phase-current ADC; i_q carries the same conversion error, Park-transformed, so that
        # the measured i_q and the measured phase currents agree
        measured = np.empty((3, n))
        for j, name in enumerate(("i_a", "i_b", "i_c")):
            adc(col[name], current_noise[j], sens.lsb_current, sens.full_scale_current, measured[j])
        err_alpha, err_beta = clarke(*(measured - np.stack([col["i_a"], col["i_b"], col["i_c"]])))
        i_q = col["i_q"] + park(err_alpha, err_beta, col["theta_e"])[1]

        signals = {
            "theta_cmd": theta_cmd,
            "theta_u": col["theta_u_meas"],
            "i_q": i_q,
            "i_a": measured[0],
            "i_b": measured[1],
            "i_c": measured[2],
            "theta_e": col["theta_e"],
            "omega_m": col["omega_m"],
            "i_q_ref": col["i_q_ref"],
            "T_m": col["T_m"],
            "theta_u_true": col["theta_u"],
        }
        return SimResult(
            t=t, signals=signals, metadata=self.metadata(k, seed, noise, t, electrical_substeps=n_sub)
        )


def simulate(
    faults: ArrayLike = HEALTHY,
    *,
    model: str = "hf",
    noise: bool = True,
    seed: int = 0,
    params: EmaParams | None = None,
    command: Command | None = None,
    duration: float | None = None,
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
        Override the nominal parameters, the FDI chirp, or its duration [s].
    """
    from .monitor import MonitorEma

    models: dict[str, type[HighFidelityEma] | type[MonitorEma]] = {"hf": HighFidelityEma, "lf": MonitorEma}
    if model not in models:
        raise InputError(f"unknown model {model!r}; available: {', '.join(models)}")
    return models[model](params, command).simulate(faults, noise=noise, seed=seed, duration=duration)
