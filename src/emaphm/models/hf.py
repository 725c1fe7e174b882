"""The high-fidelity three-phase EMA twin (DESIGN §3): API layer over `kernels.hf_twin`."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from .._threads import thread_map
from ..errors import InputError
from ..faults import HEALTHY, FaultedParameters, apply_faults, as_fault_matrix, as_fault_vector
from ..kernels.foc import FocPack
from ..kernels.hf_twin import N_OUT, OUT_COLUMNS, simulate_hf
from ..kernels.pmsm_abc import StatorPack, stator_pack
from ..kernels.sensors import adc
from ..kernels.transforms import q_error
from ..params import EmaParams
from ..results import SimResult
from ._base import _EmaModel, check_finite, check_seed, controller_pack, mechanics_pack

__all__ = ["MAX_SUBSTEPS", "HighFidelityEma", "foc_pack"]

# 6x the sub-steps of the most shorted coil the fault vector allows (N = 0.05, n_sub ~ 320)
MAX_SUBSTEPS = 2000
# FOC: largest step over the fastest electrical time constant of a pair of phases in series
FOC_STEP_FRACTION = 0.02


def foc_pack(params: EmaParams) -> FocPack:
    """The FOC drive's run constants (`kernels.foc`) for `params`; on = 0 for a hysteresis drive."""
    inv, m = params.inverter, params.motor
    if not inv.foc:  # on = 0: the kernel reads none of the other fields
        return FocPack._make(0.0 for _ in FocPack._fields)
    double = inv.update == "double"
    # update instants: the peaks at (j − φ)·T_pwm, with the valleys half a period later when double
    T_u = inv.T_update
    j = math.ceil(inv.pwm_phase * inv.T_pwm / T_u - 1e-9)  # the first instant j·T_u − φ·T_pwm ≥ 0
    t_first = j * T_u - inv.pwm_phase * inv.T_pwm
    first_peak = True
    if double:
        first_peak = round((t_first + inv.pwm_phase * inv.T_pwm) / T_u) % 2 == 0
    advance = (inv.computation_delay + 0.5) if inv.angle_compensation else 0.0
    return FocPack(
        1.0, inv.T_pwm, T_u, float(double), max(t_first, 0.0), float(first_peak),
        float(inv.computation_delay), inv.dead_time, float(inv.dead_time_compensation),
        inv.K_p_i, inv.K_i_i, float(inv.modulation == "svpwm"), float(inv.decoupling),
        float(inv.emf_feedforward), advance, inv.voltage_limit * inv.V_linear, inv.V_dc,
        m.L_s, m.psi_m, float(m.p),
    )  # fmt: skip


class HighFidelityEma(_EmaModel):
    """The high-fidelity three-phase EMA twin (DESIGN §3).

    Parameters
    ----------
    params : EmaParams or path
        The actuator, or its actuator file (default: the nominal parameters of DESIGN §7).
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
        More than `MAX_SUBSTEPS` means parameters no run could finish with (e.g. L_s mistyped
        by orders of magnitude): `InputError`, instead of a silent hang.
        """
        integ = self.params.integration
        if self.params.inverter.foc:
            # PWM: the volt-seconds of each step are exact (kernels.foc), so the sub-step only has
            # to resolve the stator's own dynamics: the fastest pair of phases in series
            pairs = ((sp.L_a + sp.L_b) / (sp.R_a + sp.R_b), (sp.L_b + sp.L_c) / (sp.R_b + sp.R_c),
                     (sp.L_c + sp.L_a) / (sp.R_c + sp.R_a))  # fmt: skip
            return max(1, math.ceil(integ.dt / (FOC_STEP_FRACTION * min(pairs)) - 1e-9))
        L_min = min(sp.L_a, sp.L_b, sp.L_c)
        n_sub = max(1, math.ceil(sp.V_dc * integ.dt / (L_min * integ.ripple_fraction * sp.h) - 1e-9))
        if n_sub > MAX_SUBSTEPS:
            raise InputError(
                f"the stator needs {n_sub} electrical sub-steps per {integ.dt:g} s step "
                f"(V_dc = {sp.V_dc:g} V, smallest phase inductance {L_min:.3g} H, band h = {sp.h:g} A); "
                f"at most {MAX_SUBSTEPS}: check L_s, h and dt"
            )
        return n_sub

    def simulate_batch(
        self,
        K: ArrayLike,
        *,
        noise: bool = True,
        seeds: Sequence[int] | None = None,
        duration: float | None = None,
        workers: int | None = None,
    ) -> list[SimResult]:
        """`simulate` for each fault row of K (seeds[j] for row j; 0 for all when None), the runs
        side by side on `workers` threads (None or 0: numba's thread count, `numba_threads`).

        Each result is the one `simulate` gives for that row and seed, to the bit: the kernel
        releases the GIL, and nothing is shared between runs but the read-only command.
        """
        import numba

        rows = as_fault_matrix(K)
        seeds = [0] * len(rows) if seeds is None else [check_seed(s) for s in seeds]
        if len(seeds) != len(rows):
            raise InputError(f"seeds has {len(seeds)} values for {len(rows)} fault rows")
        if workers is not None and workers < 0:
            raise InputError(f"workers must be 0 or more, got {workers}")
        return thread_map(
            lambda ks: self.simulate(ks[0], noise=noise, seed=ks[1], duration=duration),
            list(zip(rows, seeds, strict=True)),
            workers or numba.get_num_threads(),
        )

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
            controller_pack(params, fp), sp, mechanics_pack(params, fp), foc_pack(params),
            params.integration.dt, params.steps_per_sample, n_sub, out,
        )  # fmt: skip
        check_finite(out, self.model, k)
        col = {name: out[:, j].copy() for j, name in enumerate(OUT_COLUMNS)}

        # phase-current ADC; i_q carries the same conversion error, Park-transformed, so that
        # the measured i_q and the measured phase currents agree
        measured = np.empty((3, n))
        for j, name in enumerate(("i_a", "i_b", "i_c")):
            adc(col[name], current_noise[j], sens.lsb_current, sens.full_scale_current, measured[j])
        i_q = np.empty(n)
        q_error(*(measured - np.stack([col["i_a"], col["i_b"], col["i_c"]])), col["theta_e"], col["i_q"], i_q)

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
