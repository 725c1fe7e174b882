"""Stage 6: the uncertainty of an identified fault vector: 90 % intervals that hold, and flags for what the
measurement cannot tell (issue 9; docs/uncertainty.md).

**Laplace** (``uncertainty="laplace"``, the default) linearises the monitor model about the
estimate k̂, at the cost of one population call of 33 rows (≈ 1 % of an identification):

1. u = (k1..k5, e_x, e_y, k8), with the eccentricity as a Cartesian pair
   (e_x, e_y) = k6·(cos 2πk7, sin 2πk7): its direction k7 is a phase, and near ζ = 0 only the
   pair is smooth.
2. r = √w·(I_ref − I_LF(û)), the weighted filtered residual of eq. (3) on the compared samples
   (n of them); s² = Σr² / (n − 8); τ, the integrated autocorrelation time of r (Sokal's
   window, c = 5). The filtered residual is strongly autocorrelated (τ ≈ 30–140 samples):
   taken as independent, the samples would make the variances τ times too small.
3. J = ∂r/∂u by central differences at h = 10⁻³ and 3·10⁻³ (one-sided at a bound of the box).
4. Cov_u = (JᵀJ)⁺·M·(JᵀJ)⁺, M the Newey–West long-run covariance of the scores over 5 τ
   (`sandwich`), carried to k by the delta method (σ_raw). A parameter whose σ differs by
   more than 50 % between the two steps is flagged ``nonsmooth`` (friction and backlash make the
   fitness non-smooth) and takes the larger.
5. Noise alone does not make the error: the monitor's discrepancy from the actuator biases every
   estimate (the same on every noise draw). Each σ is therefore calibrated on simulated HF cases
   that no benchmark uses (`fit_factors`, ``emaphm calibrate-uq``):
   σ_j = √((c_j·σ_raw,j)² + b_j²), a scale c_j and a floor b_j per fault, shipped in
   ``emaphm/data/uq_calibration.json`` and tied to the LF calibration it was fitted with.
6. 90 % intervals k̂ ± 1.645·σ; where that crosses a bound of [0, 1] the one-sided interval
   [0, k̂ + 1.282·σ] (or [k̂ − 1.282·σ, 1]) and the flag ``at_bound``. k7 is an arc of the circle
   (``ci90_low > ci90_high`` when it wraps through 0), the whole circle [0, 1] with the flag
   ``phase_undefined`` when the eccentricity is within 2 σ of 0 (its direction then means
   nothing). ``non_identifiable`` marks the parameters of a direction of JᵀJ whose eigenvalue is
   below 10⁻⁶ of the largest: combinations the measurement cannot tell apart.
"""

from ...choices import UQ_METHODS
from .factors import FIT_COVERAGE, PACKAGED_FACTORS, Factors, fit_factors, load_factors
from .intervals import (
    PHASE,
    Z90,
    ZETA,
    Uncertainty,
    covers,
    half_widths,
    intervals,
    to_cartesian,
    to_faults,
    verdicts,
)
from .laplace import LAPLACE_STEPS, integrated_time, laplace, sandwich

__all__ = [
    "FIT_COVERAGE",
    "LAPLACE_STEPS",
    "PACKAGED_FACTORS",
    "PHASE",
    "UQ_METHODS",
    "Z90",
    "ZETA",
    "Factors",
    "Uncertainty",
    "covers",
    "fit_factors",
    "half_widths",
    "integrated_time",
    "intervals",
    "laplace",
    "load_factors",
    "sandwich",
    "to_cartesian",
    "to_faults",
    "verdicts",
]  # fmt: skip
