"""The thorough uncertainty mode: the posterior of the fault vector by MCMC (``uncertainty="mcmc"``).

emcee's ensemble sampler (Foreman-Mackey et al., PASP 125:306, 2013; the optional extra
``emaphm[uq]``) with differential-evolution moves (80 % DEMove, 20 % DESnookerMove) samples u = (k1..k5, e_x, e_y, k8) (`uncertainty.to_cartesian`) under

    log p(u) = −err(u) / (2·τ·s²)      inside the box, −∞ outside

with err the eq. (3) fitness and τ, s² from the Laplace step (the residual's autocorrelation time
and variance): the likelihood of the filtered residual tempered by τ. The prior is uniform in
(k1..k5, e_x, e_y, k8) over the box and the disc ζ ≤ 1 (uniform in the pair, not in (ζ, k7)).
Each proposal half-ensemble is one population call. 32 walkers start from N(û, Cov_Laplace/4);
the chain runs in chunks of `limits.CHUNK` steps until it is ≥ 50 autocorrelation times long and τ
changed < 1 % between chunks, or `limits.MAX_STEPS` (then ``converged`` is false and the result warns).
3 τ are discarded and the rest thinned by τ/2.

Intervals are the 5–95 % quantiles; one-sided [0, q90] (``at_bound``) when more than 5 % of the
mass lies below 0.01 (above 0.99: [q10, 1]); k7 an arc about the circular mean, or the whole
circle (``phase_undefined``) when ζ is at its bound. Like the Laplace intervals they see the
noise only, so each half-width h is widened by the shipped discrepancy calibration,
√((scale·h)² + (1.645·floor)²): its coverage was measured for the Laplace intervals
(BENCHMARKS.md), not separately for these.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ...errors import InputError
from ...faults import FAULT_NAMES
from .. import limits
from .factors import Factors
from .intervals import PHASE, Z90, ZETA, Uncertainty, to_cartesian, to_faults

if TYPE_CHECKING:
    from ...models import MonitorEma
    from ..fitness import Fitness

__all__ = ["check_emcee", "sample"]



def check_emcee() -> None:
    """emcee must be installed for the mcmc mode: a one-line reason if it is not."""
    try:
        import emcee  # noqa: F401
    except ImportError:
        raise InputError("uncertainty 'mcmc' needs emcee: pip install 'emaphm[uq]'") from None


def sample(
    objective: Fitness,
    monitor: MonitorEma,
    k_hat: NDArray[np.float64],
    local: Uncertainty,
    *,
    duration: float,
    factors: Factors,
    seed: int,
    walkers: int | None = None,
    chunk: int | None = None,
    max_steps: int | None = None,
    on_step: Callable[[int, int, float], None] | None = None,
) -> Uncertainty:
    """Posterior intervals about the estimate `k_hat` of eq. 3 `objective` of `monitor` over
    `duration` [s] (module docstring); `local` is its Laplace result (τ, s², Cov). `on_step(−steps, max_steps, nan)` reports progress (negative:
    MCMC steps, not generations). Reproducible: walkers and moves are drawn from `seed`."""
    import emcee

    check_emcee()
    walkers = limits.WALKERS if walkers is None else walkers  # the registry's values at call time
    chunk = limits.CHUNK if chunk is None else chunk
    max_steps = limits.MAX_STEPS if max_steps is None else max_steps
    u0 = to_cartesian(k_hat)[0]
    tau_r, s2 = float(local.details["residual_tau"]), float(local.details["s2"])
    temper = 2.0 * tau_r * s2
    if not (np.isfinite(temper) and temper > 0):
        raise InputError("the residual at the estimate is zero: no likelihood to sample")
    evaluations = [0]

    def log_prob(U: NDArray[np.float64]) -> NDArray[np.float64]:
        U = np.atleast_2d(U)
        box = np.delete(U, [ZETA, PHASE], axis=1)
        inside = np.all((box >= 0.0) & (box <= 1.0), axis=1) & (np.hypot(U[:, ZETA], U[:, PHASE]) <= 1.0)
        out = np.full(len(U), -np.inf)
        if inside.any():
            f = objective.of_monitor(monitor, to_faults(U[inside]), duration=duration)
            evaluations[0] += int(inside.sum())
            out[inside] = np.where(np.isfinite(f), -f / temper, -np.inf)
        return out

    p0 = _start(u0, local, np.random.default_rng(seed), walkers)
    # differential-evolution moves: on the Table 1 case (2000 steps, 32 walkers) they halved the
    # autocorrelation times of the default stretch move (46-66 steps against 89-132), with the same
    # intervals to 0.003
    moves = [(emcee.moves.DEMove(), 0.8), (emcee.moves.DESnookerMove(), 0.2)]
    sampler = emcee.EnsembleSampler(walkers, 8, log_prob, vectorize=True, moves=moves)
    sampler.random_state = np.random.RandomState(seed % 2**32).get_state()
    state: Any = p0
    old_tau = np.inf
    converged = False
    tau = np.full(8, np.nan)
    while sampler.iteration < max_steps:
        sampler.run_mcmc(state, min(chunk, max_steps - sampler.iteration), progress=False)
        state = None
        tau = sampler.get_autocorr_time(tol=0)
        if on_step is not None:
            on_step(-sampler.iteration, max_steps, float("nan"))
        t_max = float(np.max(tau))
        if (
            np.isfinite(t_max)
            and sampler.iteration >= limits.MIN_TAUS * t_max
            and abs(old_tau - t_max) < limits.TAU_RTOL * t_max
        ):
            converged = True
            break
        old_tau = t_max
    t_max = float(np.nanmax(tau)) if np.any(np.isfinite(tau)) else 1.0
    discard = min(int(3 * t_max), sampler.iteration // 2)
    thin = max(int(t_max / 2), 1)
    K = to_faults(sampler.get_chain(discard=discard, thin=thin, flat=True))
    return summarise(K, local, factors, details={
        "walkers": walkers, "steps": int(sampler.iteration), "autocorr_time": [round(float(v), 1) for v in tau],
        "converged": converged, "discard": discard, "thin": thin, "samples": len(K),
        "acceptance": round(float(np.mean(sampler.acceptance_fraction)), 3), "seed": seed,
        "residual_tau": tau_r, "s2": s2,
    }, evaluations=local.evaluations + evaluations[0])  # fmt: skip


def _start(
    u0: NDArray[np.float64], local: Uncertainty, rng: np.random.Generator, walkers: int
) -> NDArray[np.float64]:
    """The walkers' start: N(û, Cov_Laplace/4), inside the box and the disc ζ ≤ 1."""
    cov = local.cov_u if local.cov_u is not None else np.diag(np.full(8, 1e-6))
    cov = 0.25 * (cov + cov.T) / 2 + np.eye(8) * 1e-12
    p0 = rng.multivariate_normal(u0, cov, size=walkers, method="eigh")
    keep = np.delete(np.arange(8), [ZETA, PHASE])
    p0[:, keep] = np.clip(p0[:, keep], 1e-9, 1.0 - 1e-9)
    rho = np.hypot(p0[:, ZETA], p0[:, PHASE])
    p0[:, [ZETA, PHASE]] /= np.maximum(rho / 0.999, 1.0)[:, None]
    return p0  # type: ignore[no-any-return]


def summarise(
    K: NDArray[np.float64], local: Uncertainty, factors: Factors, *, details: dict[str, Any], evaluations: int
) -> Uncertainty:
    """Quantile intervals, σ and correlations of posterior samples K (n x 8), widened by `factors`."""
    n = len(K)
    if n < 10:
        raise InputError(f"the chain kept only {n} samples: too few for intervals")
    lo, hi, std = np.empty(8), np.empty(8), K.std(axis=0)
    flags: list[list[str]] = [[] for _ in range(8)]
    centre = np.median(K, axis=0)
    for j in range(8):
        if j == PHASE:
            continue
        x = K[:, j]
        if np.mean(x < 0.01) > 0.05:
            lo[j], hi[j] = 0.0, float(np.quantile(x, 0.90))
            flags[j].append("at_bound")
        elif np.mean(x > 0.99) > 0.05:
            lo[j], hi[j] = float(np.quantile(x, 0.10)), 1.0
            flags[j].append("at_bound")
        else:
            lo[j], hi[j] = np.quantile(x, [0.05, 0.95])
    phase = 2 * np.pi * K[:, PHASE]
    mean_dir = float(np.mod(np.arctan2(np.sin(phase).mean(), np.cos(phase).mean()) / (2 * np.pi), 1.0))
    d = np.mod(K[:, PHASE] - mean_dir + 0.5, 1.0) - 0.5
    std[PHASE] = float(d.std())
    undefined = "at_bound" in flags[ZETA]
    # the discrepancy widening about the median (the Laplace calibration's form, on half-widths)
    for j in range(8):
        if j == PHASE:
            continue
        c, b = factors.scale[j], factors.floor[j]
        # the edge at the bound of a one-sided interval stays where it is
        fixed_lo = "at_bound" in flags[j] and lo[j] == 0.0
        fixed_hi = "at_bound" in flags[j] and not fixed_lo
        grow_lo, grow_hi = (np.sqrt((c * abs(e - centre[j])) ** 2 + (Z90 * b) ** 2) for e in (lo[j], hi[j]))
        if not fixed_lo:
            lo[j] = max(centre[j] - grow_lo, 0.0)
        if not fixed_hi:
            hi[j] = min(centre[j] + grow_hi, 1.0)
        std[j] = float(np.sqrt((c * std[j]) ** 2 + b**2))
    q5, q95 = np.quantile(d, [0.05, 0.95])
    half = np.sqrt((factors.scale[PHASE] * max(-q5, q95)) ** 2 + (Z90 * factors.floor[PHASE]) ** 2)
    std[PHASE] = float(np.sqrt((factors.scale[PHASE] * std[PHASE]) ** 2 + factors.floor[PHASE] ** 2))
    if undefined or half >= 0.5:
        lo[PHASE], hi[PHASE] = 0.0, 1.0
        if undefined:
            flags[PHASE].append("phase_undefined")
            std[PHASE] = np.nan
    else:
        lo[PHASE], hi[PHASE] = np.mod(mean_dir - half, 1.0), np.mod(mean_dir + half, 1.0)
    u = to_cartesian(K)
    corr = np.corrcoef(np.column_stack([K[:, :PHASE], d, K[:, PHASE + 1 :]]), rowvar=False)
    corr = np.where(np.isfinite(corr), corr, np.nan)
    if undefined:
        corr[PHASE, :] = corr[:, PHASE] = np.nan
        corr[PHASE, PHASE] = 1.0
    for j in range(len(FAULT_NAMES)):
        if "non_identifiable" in local.flags[j]:
            flags[j].append("non_identifiable")
    details = {**details, "cartesian_std": [round(float(v), 6) for v in u.std(axis=0)]}
    return Uncertainty("mcmc", std, lo, hi, corr, flags, local.raw_std, evaluations, details, local.cov_u)
