"""The low-fidelity monitor model (DESIGN §4): API layer over `kernels.monitor`."""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..calibration import Calibration, Coefficients, check_monitor, default_calibration, load_calibration
from ..commands import Command
from ..errors import InputError
from ..faults import FAULT_NAMES, HEALTHY, as_fault_matrix, as_fault_vector, fault_parameter_columns
from ..kernels.monitor import AUX_COLUMNS, IDX, N_AUX, N_FIELDS, simulate_lf, simulate_lf_many
from ..kernels.sensors import adc
from ..params import EmaParams
from ..results import SimResult
from ._base import _EmaModel, check_finite, check_seed

__all__ = ["MonitorEma", "monitor_rows", "resolve_calibration"]


def resolve_calibration(
    calibration: Calibration | str | os.PathLike[str] | None, monitor: str | None = None
) -> Calibration:
    """A `Calibration` from itself, a calibration file's path, or None (the packaged one of `monitor`).

    `monitor` ("default" or "paper") picks the packaged calibration; given with a calibration, it
    must be the monitor that calibration was made for (`InputError` otherwise).
    """
    if monitor is not None:
        check_monitor(monitor)
    if calibration is None:
        return default_calibration(monitor or "default")
    cal = calibration if isinstance(calibration, Calibration) else load_calibration(calibration)
    if monitor is not None and cal.monitor != monitor:
        raise InputError(f"the calibration is for the {cal.monitor!r} monitor, not {monitor!r}")
    return cal


def drive_fields(params: EmaParams, n_lf: int) -> dict[str, float]:
    """The monitor's current-loop fields (`kernels.monitor.LF_FIELDS`) for the actuator's drive.

    Hysteresis: foc = 0 (the lag τ_i). FOC: the drive's PI gains, its updates per LF step (the
    nearest whole number, at least 1: the LF step is split into that many PI periods), its
    computation delay, the nameplate back-EMF constant it feeds forward (0 when off) and its
    voltage limit.
    """
    inv = params.inverter
    if not inv.foc:
        return {"foc": 0.0, "K_p_i": 0.0, "K_i_i": 0.0, "n_u": 1.0, "delay": 0.0, "k_e_ff": 0.0, "V_lim": 0.0}
    dt_lf = 1.0 / (params.controller.f_s * n_lf)
    return {
        "foc": 1.0,
        "K_p_i": inv.K_p_i,
        "K_i_i": inv.K_i_i,
        "n_u": float(max(1, round(dt_lf / inv.T_update))),
        "delay": float(inv.computation_delay),
        "k_e_ff": params.motor.k_e if inv.emf_feedforward else 0.0,
        "V_lim": inv.voltage_limit * inv.V_linear,
    }


def _with_faults(rows: NDArray[np.float64], K: NDArray[np.float64], params: EmaParams) -> NDArray[np.float64]:
    """`rows` (m, N_FIELDS) with the fields the fault rows K set (DESIGN §2), in place."""
    for name, values in fault_parameter_columns(K, params).items():
        rows[:, IDX[name]] = values
    return rows


def monitor_rows(
    K: NDArray[np.float64],
    params: EmaParams,
    coefficients: Sequence[Coefficients],
    n_lf: int,
    monitor: str = "default",
) -> NDArray[np.float64]:
    """LF parameter rows (layout `kernels.monitor.LF_FIELDS`) for fault rows K (validated, (m, 8)).

    `coefficients` holds one `Coefficients` for all rows or one per row (calibration varies them).
    `monitor` sets the structure: "default" takes φ_T = φ_E from the eccentric flux linkage phase
    by phase (`kernels.monitor.phi_t`), "paper" the paper's φ_SC·φ_ECC (eqs. 1–2).
    """
    m = K.shape[0]
    if len(coefficients) not in (1, m):
        raise ValueError(f"need 1 or {m} coefficient sets, got {len(coefficients)}")
    tr, c, sens, mot = params.transmission, params.controller, params.sensors, params.motor
    rows = _with_faults(np.empty((m, N_FIELDS)), K, params)
    fixed = {
        "C": tr.C, "tau": tr.tau, "eta": tr.eta, "theta_max": tr.theta_max, "T_load": tr.T_load,
        "K_I": c.K_I, "K_D": c.K_D, "tau_D": c.tau_D, "I_max": c.I_max, "T_s": 1.0 / c.f_s,
        "lsb_theta": sens.lsb_position, "fs_theta": sens.full_scale_position, "p": mot.p,
        # DESIGN §4.2: the equivalent R and L are the phase values; they matter only near the
        # voltage limit, the amplitude-invariant phase-voltage limit of the inverter V_dc/√3
        "R_eq": mot.R_s, "L_eq": mot.L_s, "U_max": params.inverter.V_dc / math.sqrt(3.0), "n_lf": n_lf,
        "ecc_coupling": 1.0 if check_monitor(monitor) == "default" else 0.0,
    }  # fmt: skip
    fixed.update(drive_fields(params, n_lf))
    for name, value in fixed.items():
        rows[:, IDX[name]] = value
    cal: dict[str, list[float]] = {
        "k_FT": [x.k_FT for x in coefficients], "k_FS": [x.k_FS for x in coefficients],
        "k_E": [x.k_E for x in coefficients], "k_t_eq": [x.k_t_eq for x in coefficients],
        "k_e_eq": [x.k_e_eq for x in coefficients], "J": [x.J_eq for x in coefficients],
        "tau_i": [x.tau_i for x in coefficients], "k_H": [x.k_H for x in coefficients],
        "delta_0": [x.delta_0 for x in coefficients], "delta_1": [x.delta_1 for x in coefficients],
        "delta_u": [x.delta_u for x in coefficients], "delta_2": [x.delta_2 for x in coefficients],
        "V_H": [x.V_H for x in coefficients], "i_R": [x.i_R for x in coefficients],
        "i_D": [x.i_D for x in coefficients],
    }  # fmt: skip
    for name, per_row in cal.items():
        rows[:, IDX[name]] = per_row
    return rows


class MonitorEma(_EmaModel):
    """The low-fidelity monitor model (DESIGN §4): equivalent single-phase motor + shape functions.

    Parameters
    ----------
    params : EmaParams or path
        The actuator, or its actuator file (default: nominal): the LF model shares the drive train
        and controller with the HF twin.
    command : Command
        Position command; the FDI chirp by default.
    calibration : Calibration or path, optional
        Coefficients of the equivalent motor: a `Calibration`, the path of a file written by
        ``emaphm calibrate``, or None for the packaged calibration. A calibration belongs to one
        actuator: one made for other parameters raises `InputError` unless
        ``allow_mismatch=True``.
    monitor : {"default", "paper"}, optional
        The monitor model: "default" (the single-phase model with its loop-error surrogate,
        calibrated over multi-fault actuators and several commands) or "paper" (the paper's
        model, eqs. 1–2 alone, calibrated on the paper's scenarios). None: the calibration's.
    allow_mismatch : bool
        Accept a calibration made for other actuator parameters (to measure that mismatch).
    """

    model = "lf"

    def __init__(
        self,
        params: EmaParams | str | os.PathLike[str] | None = None,
        command: Command | None = None,
        calibration: Calibration | str | os.PathLike[str] | None = None,
        *,
        monitor: str | None = None,
        allow_mismatch: bool = False,
    ) -> None:
        super().__init__(params, command)
        self.calibration = resolve_calibration(calibration, monitor)
        self.monitor = self.calibration.monitor
        if not allow_mismatch:
            where = (
                "the packaged calibration"
                if calibration is None
                else f"calibration {calibration}"
                if not isinstance(calibration, Calibration)
                else "the calibration"
            )
            self.calibration.check_params(self.params, where=where)

    def rows(self, K: ArrayLike) -> NDArray[np.float64]:
        """Validated LF parameter rows for the fault rows K: `monitor_rows`' numbers, its fields
        that the faults do not set taken from one row built once for this actuator and
        calibration (the search asks for rows a few hundred times a diagnosis: 8 rows 31-35 -> 21 µs, `studies/step_timings.py`,
        issue 36)."""
        K = as_fault_matrix(K)
        params, cal = self.params, self.calibration
        kept = getattr(self, "_row_template", None)
        if kept is None or kept[0] is not params or kept[1] is not cal:
            template = monitor_rows(np.zeros((1, len(FAULT_NAMES))), params, [cal.coefficients], cal.n_lf, cal.monitor)[0]
            kept = self._row_template = (params, cal, template)
        return _with_faults(np.repeat(kept[2][None, :], len(K), axis=0), K, params)

    def simulate_many(
        self, K: ArrayLike, *, duration: float | None = None, check: bool = True
    ) -> NDArray[np.float64]:
        """i_q [A] of one run per fault row of K, shape (m, n_samples): one parallel kernel call.

        With `check`, a row that diverged (NaN or inf) raises `SimulationError`; without it the
        caller handles such rows (identification ranks them last).
        """
        _, theta_cmd = self.sample_grid(duration)
        K = as_fault_matrix(K)
        rows = self.rows(K)
        out = np.empty((rows.shape[0], len(theta_cmd)))
        simulate_lf_many(theta_cmd, rows, out)
        if check:
            bad = ~np.all(np.isfinite(out), axis=1)
            if bad.any():
                check_finite(out[bad][:1], self.model, K[bad][0])
        return out

    def simulate(
        self,
        faults: ArrayLike = HEALTHY,
        *,
        noise: bool = False,
        seed: int = 0,
        duration: float | None = None,
    ) -> SimResult:
        """Simulate the LF model. With `noise`, seeded measurement noise is added to i_q and θ_u
        afterwards (the monitor model itself is deterministic; noise does not enter its loop)."""
        k = as_fault_vector(faults)
        seed = check_seed(seed)
        t, theta_cmd = self.sample_grid(duration)
        i_q = np.empty(len(t))
        aux = np.empty((len(t), N_AUX))
        simulate_lf(theta_cmd, self.rows(k)[0], i_q, aux)
        check_finite(i_q, self.model, k)
        check_finite(aux, self.model, k)
        col = {name: aux[:, j].copy() for j, name in enumerate(AUX_COLUMNS)}
        theta_u = col["theta_u"].copy()
        if noise:
            sens = self.params.sensors
            rng = np.random.default_rng(seed)
            theta_noise = rng.normal(0.0, sens.sigma_position, len(t))
            adc(col["theta_u"], theta_noise, sens.lsb_position, sens.full_scale_position, theta_u)
            # Park of three independent phase errors of std σ_i has std √(2/3)·σ_i
            i_q = i_q + rng.normal(0.0, math.sqrt(2.0 / 3.0) * sens.sigma_current, len(t))
        signals = {
            "theta_cmd": theta_cmd, "theta_u": theta_u, "i_q": i_q, "theta_e": col["theta_e"],
            "omega_m": col["omega_m"], "i_q_ref": col["i_q_ref"], "T_m": col["T_m"], "theta_u_true": col["theta_u"],
        }  # fmt: skip
        cal = self.calibration
        extra = {
            "monitor": self.monitor,
            "calibration": {**cal.to_json(), "coefficients": dataclasses.asdict(cal.coefficients)},
        }
        return SimResult(t=t, signals=signals, metadata=self.metadata(k, seed, noise, t, **extra))
