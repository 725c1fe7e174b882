"""The high-fidelity three-phase EMA twin (DESIGN §3): API layer over `kernels.hf_twin`."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from .._threads import thread_map
from ..errors import InputError
from ..faults import HEALTHY, FaultedParameters, apply_faults, as_fault_matrix, as_fault_vector
from ..kernels.hf_twin import N_OUT, OUT_COLUMNS, simulate_hf
from ..kernels.pmsm_abc import StatorPack, stator_pack
from ..kernels.sensors import adc
from ..kernels.transforms import clarke, park
from ..results import SimResult
from ._base import _EmaModel, check_finite, check_seed, controller_pack, mechanics_pack

__all__ = ["MAX_SUBSTEPS", "HighFidelityEma"]

# 6x the sub-steps of the most shorted coil the fault vector allows (N = 0.05, n_sub ~ 320)
MAX_SUBSTEPS = 2000


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
        More than `MAX_SUBSTEPS` means parameters no run could finish with (e.g. L_s mistyped
        by orders of magnitude): `InputError`, instead of a silent hang.
        """
        integ = self.params.integration
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
            controller_pack(params, fp), sp, mechanics_pack(params, fp),
            params.integration.dt, params.steps_per_sample, n_sub, out,
        )  # fmt: skip
        check_finite(out, self.model, k)
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
