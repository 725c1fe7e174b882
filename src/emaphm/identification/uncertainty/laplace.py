"""The Laplace intervals of an estimate (``uncertainty="laplace"``; the package docstring's steps 1-6).

One population call of 33 rows about k̂: the Jacobian of eq. 3's residual at two steps, the
sandwich covariance for the autocorrelated, unequally weighted residual, the delta method to k,
then the calibrated 90 % intervals and the flags (`intervals.intervals`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InputError
from ...faults import FAULT_NAMES
from .factors import Factors
from .intervals import N_PARAMS, PHASE, ZETA, Uncertainty, intervals, to_cartesian, to_faults

if TYPE_CHECKING:
    from ...models import MonitorEma
    from ..fitness import Fitness

from ..limits import HAC_TAUS, LAPLACE_STEPS, NON_IDENTIFIABLE, NONSMOOTH_RATIO, PINV_RCOND, SOKAL_C

__all__ = [
    "HAC_TAUS",
    "LAPLACE_STEPS",
    "NONSMOOTH_RATIO",
    "NON_IDENTIFIABLE",
    "PINV_RCOND",
    "SOKAL_C",
    "integrated_time",
    "laplace",
    "sandwich",
]  # fmt: skip


def integrated_time(r: ArrayLike, c: float = SOKAL_C) -> float:
    """Integrated autocorrelation time of the series r [samples], with Sokal's adaptive window:
    τ(M) = 1 + 2·Σ_{t=1..M} ρ(t), at the smallest M ≥ c·τ(M) (as `emcee.autocorr`). White noise
    gives 1; an AR(1) series with coefficient a gives (1 + a)/(1 − a)."""
    x = np.asarray(r, dtype=np.float64)
    x = x - x.mean()
    n = len(x)
    if n < 2 or not np.any(x):
        return 1.0
    size = 1 << (2 * n - 1).bit_length()
    f = np.fft.rfft(x, size)
    acf = np.fft.irfft(f * np.conj(f), size)[:n]
    acf /= acf[0]
    taus = 2.0 * np.cumsum(acf) - 1.0
    window = np.arange(n) >= c * taus
    m = int(np.argmax(window)) if window.any() else n - 1
    return float(max(taus[m], 1.0))


def sandwich(J: NDArray[np.float64], r: NDArray[np.float64], tau: float) -> NDArray[np.float64]:
    """Cov of the least-squares estimate whose residual r has Jacobian J: (JᵀJ)⁺·M·(JᵀJ)⁺ with M the
    heteroscedasticity- and autocorrelation-consistent (Newey–West, Bartlett window) covariance
    of the scores g_t = J_t·r_t over lags up to L = `HAC_TAUS`·τ.

    The weights of eq. (3) differ from sample to sample (they follow the slope of the current),
    so the weighted residual is not of one variance, and it is autocorrelated: τ·s²·(JᵀJ)⁻¹
    (valid for equal variances) covered 50-60 % instead of 90 % on a linear-Gaussian oracle through
    the comparison filter over 0.3 s, where the sandwich covered 62-74 % (scratch variants of
    tests/identification/test_uncertainty.py); over 1 s, the real length, the sandwich covers
    78-85 % (that test).
    """
    n = len(r)
    g = J * r[:, None]
    L = min(int(np.ceil(HAC_TAUS * tau)), n - 1)
    kernel = 1.0 - np.abs(np.arange(-L, L + 1)) / (L + 1)  # Bartlett
    smoothed = _convolve_same(g, kernel)
    meat = g.T @ smoothed
    meat = (meat + meat.T) / 2
    bread = np.linalg.pinv(J.T @ J, rcond=PINV_RCOND, hermitian=True)
    return bread @ meat @ bread  # type: ignore[no-any-return]


def _convolve_same(g: NDArray[np.float64], kernel: NDArray[np.float64]) -> NDArray[np.float64]:
    """The columns of g (n, m) convolved with an odd-length kernel, the centre n samples (zeros
    beyond the ends): ``scipy.signal.fftconvolve(g, kernel[:, None], mode="same", axes=0)`` by
    numpy's FFT (pocketfft, as scipy.fft's) on a 5-smooth length. Not scipy's: ``scipy.signal``
    would cost 0.9 s to import (`signals`), and ``scipy.fft`` 0.3 s once the search no longer
    imports scipy.optimize (issue 36)."""
    n, half = g.shape[0], (len(kernel) - 1) // 2
    size = _five_smooth(n + len(kernel) - 1)
    full = np.fft.irfft(np.fft.rfft(g, size, axis=0) * np.fft.rfft(kernel, size)[:, None], size, axis=0)
    return full[half : half + n]  # type: ignore[no-any-return]


def _five_smooth(n: int) -> int:
    """The smallest 2^a·3^b·5^c ≥ n (an FFT length pocketfft handles fast; scipy's next_fast_len)."""
    best, p5 = 2 * n, 1
    while p5 < best:
        p35 = p5
        while p35 < best:
            m = p35
            while m < n:
                m *= 2
            best = min(best, m)
            p35 *= 3
        p5 *= 5
    return best


def _delta_to_faults(u: NDArray[np.float64], cov_u: NDArray[np.float64]) -> NDArray[np.float64]:
    """Cov of k from Cov of u by the delta method (only the (e_x, e_y) → (ζ, k7) block is not identity)."""
    ex, ey = u[ZETA], u[PHASE]
    rho = float(np.hypot(ex, ey))
    G = np.eye(N_PARAMS)
    if rho > 1e-12:
        G[ZETA, ZETA], G[ZETA, PHASE] = ex / rho, ey / rho
        G[PHASE, ZETA], G[PHASE, PHASE] = -ey / (2 * np.pi * rho**2), ex / (2 * np.pi * rho**2)
        return G @ cov_u @ G.T  # type: ignore[no-any-return]
    # at ζ = 0: ζ's spread is the pair's along its widest axis, the direction is undefined
    block = cov_u[ZETA : PHASE + 1, ZETA : PHASE + 1]
    _w, v = np.linalg.eigh(block)
    G[ZETA, ZETA], G[ZETA, PHASE] = v[0, -1], v[1, -1]
    G[PHASE, :] = 0.0
    cov = G @ cov_u @ G.T
    cov[PHASE, PHASE] = np.inf
    return cov  # type: ignore[no-any-return]


def laplace(
    objective: Fitness,
    monitor: MonitorEma,
    k_hat: ArrayLike,
    *,
    duration: float | None = None,
    factors: Factors | None = None,
    constants_cov: NDArray[np.float64] | None = None,
) -> Uncertainty:
    """Laplace intervals about the estimate k̂ (module docstring): one population call of 33 rows.
    `constants_cov`: the covariance of the actuator's constants' log-factors (`emaphm.constants`),
    whose effect on k̂ widens the calibrated intervals (`constants.shift_covariance`)."""
    k_hat = np.asarray(k_hat, dtype=np.float64)
    u0 = to_cartesian(k_hat)[0]
    factors = factors if factors is not None else Factors.identity()
    rows = [u0]
    spans = []
    for h in LAPLACE_STEPS:
        for j in range(N_PARAMS):
            up, down = u0.copy(), u0.copy()
            if j in (ZETA, PHASE):  # the pair is free (ζ ≤ 1 is kept by `to_faults`' range)
                up[j] += h
                down[j] -= h
            else:
                up[j], down[j] = min(u0[j] + h, 1.0), max(u0[j] - h, 0.0)
            rows += [up, down]
            spans.append(up[j] - down[j])
    K = np.clip(to_faults(np.array(rows)), 0.0, 1.0)
    R = _residuals(objective, monitor, K, duration)
    r0, n = R[0], R.shape[1]  # n: the samples eq. 3 weighs
    if not np.all(np.isfinite(r0)):
        raise InputError("the monitor diverges at the estimate: no uncertainty can be given")
    ssr = float(np.sum(r0 * r0))  # numpy's pairwise sum: the same whatever the rows' layout and BLAS
    s2 = ssr / max(n - N_PARAMS, 1)
    tau = integrated_time(r0)
    covs, sds = [], []
    for q in range(len(LAPLACE_STEPS)):
        J = _jacobian(R, rows, spans, u0, q, n)
        cov_u = sandwich(J, r0, tau)  # pinv at `PINV_RCOND`
        cov_k = _delta_to_faults(u0, cov_u)
        covs.append((J.T @ J, cov_k, cov_u))
        sds.append(np.sqrt(np.clip(np.diag(cov_k), 0.0, np.inf)))
    JtJ, cov_k, cov_u = covs[0]
    raw = np.fmax(sds[0], sds[1])
    flags_extra: list[list[str]] = [[] for _ in range(N_PARAMS)]
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.fmax(sds[0], sds[1]) / np.fmin(sds[0], sds[1])
    for jj in np.flatnonzero(ratio > NONSMOOTH_RATIO):
        flags_extra[int(jj)].append("nonsmooth")
    combos = _weak_directions(JtJ, raw, flags_extra)
    calibrated, added = _widened(factors.apply(raw), objective, monitor, k_hat, (R, rows, spans, u0, n), constants_cov,
                                 duration)  # fmt: skip
    std, lo, hi, flags = intervals(k_hat, calibrated)
    for j in range(N_PARAMS):
        flags[j] += flags_extra[j]
    sd_k = np.sqrt(np.clip(np.diag(cov_k), 0.0, np.inf))
    with np.errstate(divide="ignore", invalid="ignore"):
        corr = cov_k / np.outer(sd_k, sd_k)
    corr = np.where(np.isfinite(corr), np.clip(corr, -1.0, 1.0), np.nan)
    np.fill_diagonal(corr, 1.0)
    if "phase_undefined" in flags[PHASE]:
        corr[PHASE, :] = corr[:, PHASE] = np.nan
        corr[PHASE, PHASE] = 1.0
    details = {
        "residual_tau": round(tau, 2),
        "s2": s2,
        "n_eff": round(n / tau, 1),
        "steps": list(LAPLACE_STEPS),
        "non_identifiable": combos,
        "calibrated": bool(factors.record),
        "constants_std": None if constants_cov is None else [round(float(a), 6) for a in added],
    }
    return Uncertainty("laplace", std, lo, hi, corr, flags, raw, len(rows), details, cov_u)


def _residuals(objective: Fitness, monitor: MonitorEma, K: NDArray[np.float64], duration: float | None) -> NDArray[np.float64]:
    """√w·(I_ref − F(I_LF)) of the rows K on the samples eq. 3 weighs: for the monitor model the
    fused kernel (`Fitness.residuals_of_monitor`, one call, the numbers of filtering its currents
    and taking the residual in numpy: test_fitness_kernel), for another model (a test's oracle)
    from its ``simulate_many``."""
    from ...models import MonitorEma

    if isinstance(monitor, MonitorEma):
        return objective.residuals_of_monitor(monitor, K, duration=duration)
    keep, root_w, reference = objective.weighed()  # the fused kernel's layout
    currents = monitor.simulate_many(K, duration=duration, check=False)
    return root_w * (reference - objective.comparison.filtered(currents)[:, keep])  # type: ignore[no-any-return]


def _widened(calibrated: NDArray[np.float64], objective: Fitness, monitor: MonitorEma, k_hat: NDArray[np.float64],
             runs: tuple, constants_cov: NDArray[np.float64] | None, duration: float | None) -> tuple[NDArray[np.float64], NDArray[np.float64]]:  # fmt: skip
    """The calibrated σ widened by what the constants' covariance moves (`constants.shift_covariance`), and that part."""
    added = np.zeros(N_PARAMS)
    if constants_cov is None:
        return calibrated, added
    from .constants import shift_covariance

    R, rows, spans, u0, n = runs
    shift_u = shift_covariance(
        objective, monitor, k_hat, _jacobian(R, rows, spans, u0, 0, n), constants_cov, duration
    )
    added = np.sqrt(np.clip(np.diag(_delta_to_faults(u0, shift_u)), 0.0, np.inf))
    return np.sqrt(calibrated**2 + added**2), added


def _jacobian(
    R: NDArray[np.float64],
    rows: list[NDArray[np.float64]],
    spans: list[float],
    u0: NDArray[np.float64],
    q: int,
    n: int,
) -> NDArray[np.float64]:
    """−∂r/∂u at the q-th step from the residual rows R (the centre, then ± each parameter)."""
    r0 = R[0]
    J = np.empty((n, N_PARAMS))
    for j in range(N_PARAMS):
        i = 1 + 2 * (q * N_PARAMS + j)
        rp, rm = R[i], R[i + 1]
        ok_p, ok_m = np.all(np.isfinite(rp)), np.all(np.isfinite(rm))
        span = spans[q * N_PARAMS + j]
        if ok_p and ok_m and span > 0:
            J[:, j] = (rm - rp) / span  # −∂r/∂u = ∂model/∂u (the sign cancels in the sandwich)
        elif ok_p or ok_m:  # one side diverged: a one-sided difference from the centre
            up_by, down_by = rows[i][j] - u0[j], u0[j] - rows[i + 1][j]  # the real distances
            if ok_p and up_by > 0:
                J[:, j] = (r0 - rp) / up_by
            elif ok_m and down_by > 0:
                J[:, j] = (rm - r0) / down_by
            else:
                J[:, j] = 0.0
        else:
            J[:, j] = 0.0
    return J


def _weak_directions(
    JtJ: NDArray[np.float64], raw: NDArray[np.float64], flags_extra: list[list[str]]
) -> list[list[str]]:
    """The combinations the measurement cannot tell apart (eigenvalues of JᵀJ below
    `NON_IDENTIFIABLE` of the largest): flagged ``non_identifiable``; a direction the
    pseudo-inverse dropped gets σ = inf (in place in `raw`)."""
    w, v = np.linalg.eigh(JtJ)
    weak = w < NON_IDENTIFIABLE * max(float(w[-1]), 1e-300)
    combos = []
    for e in np.flatnonzero(weak):
        members = [j for j in range(N_PARAMS) if abs(v[j, e]) > 0.3]
        if ZETA in members or PHASE in members:
            members = sorted(set(members) | {ZETA, PHASE})
        combos.append([FAULT_NAMES[j] for j in members])
        # a direction the pseudo-inverse dropped (or a column no step could measure): its members'
        # σ is unknown, not small; they get the whole box and can never be reported present
        if w[e] <= PINV_RCOND * max(float(w[-1]), 1e-300):
            raw[members] = np.inf
        for j in members:
            if "non_identifiable" not in flags_extra[j]:
                flags_extra[j].append("non_identifiable")
    return combos
