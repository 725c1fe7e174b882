"""The best point's polish (stage 2) in the coordinates the Gauss–Newton Hessian makes round.

The search's fitness (eq. 3) is a sum of squares, f(x) = Σ r(x)², whose valleys near the bottom
are long and narrow in several faults at once. A CMA-ES started round (step 0.05 in every
direction, `polish.polish`) spends most of its runs learning that shape: on the hard cases of
`studies/multistart_cases.py` from the start table's 15 generations it used its whole 32 × 50
budget every time (1 569 runs). Here the shape is taken from the residuals instead:

1. a least-squares descent from the start (`descents.lm_polish`, 40–100 runs with its secant
   Jacobians), which goes down
   the valley's floor where its finite-difference Jacobian sees it;
2. the Jacobian J of the residuals at its end (n + 1 runs, `limits.LS_STEP`), so that
   f(x₀ + δ) ≈ f(x₀) + 2 rᵀJδ + δᵀ(JᵀJ)δ; with JᵀJ = V Λ Vᵀ the search runs in y, x = x₀ + V S y,
   S = diag(s_i), s_i = √(c·f(x₀) / (n λ_i)) (a step of one along each axis raises the model's
   f by c·f(x₀)/n), clipped to ``limits.PRECONDITIONED["steps"]`` in the unit box;
3. a CMA-ES in y from 0 with step 1 (``limits.PRECONDITIONED["budget"]``, stopped after
   ``"patience"`` generations without gain), a point outside the box clipped to it and charged for
   the distance, so that the search stays inside.

The fitness is rough on scales below ~1e-3 (the monitor's discrete stick and contact events:
forward differences of 1e-5 and 1e-3 disagree in sign in some faults), which is why the
Jacobian's step is 1e-2 and why the CMA-ES, not more least squares, finishes the polish.
Measured (BENCHMARKS.md, "The preconditioned polish"): 0.70–1.23 × the round CMA-ES's fitness
on the six hard cases in 360–700 runs against 1 569 (`studies/polish_routes.py`), within 1.016 × of
it on 159 paired random runs.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from . import limits
from .cmaes import cmaes_minimize
from .descents import lm_polish
from .lm import forward_probes
from .optimizers import (
    BatchProblem,
    Objective,
    OnGeneration,
    OptimizerRun,
    Residuals,
    Stagnation,
)

__all__ = ["preconditioned_polish", "whitening"]

# a point of y outside the box costs this × f(x₀) per squared unit-box distance (×1e4: 1e-2 away
# doubles f(x₀) a hundredfold), so that the CMA-ES turns back at a bound instead of sliding along it
OUTSIDE_COST = 1e6
# the CMA-ES's box in y, steps of the whitened axes: no bound in effect (each step is at least 1e-4
# in the unit box, so |y| = 100 is already 1e-2 away along the narrowest axis, 10 along the widest)
Y_BOUND = 100.0


def whitening(
    J: NDArray[np.float64], f0: float, scale: float, steps: tuple[float, float]
) -> NDArray[np.float64]:
    """The map M (n × n) with x = x₀ + M y: the eigenvectors of JᵀJ, each scaled so that a unit
    step raises the Gauss–Newton model's f by `scale`·f0/n (the module docstring), the steps
    clipped to `steps` (smallest, largest) in the unit box. A direction the residuals do not see
    (λ = 0) gets the largest step.

    J : the residuals' Jacobian (m × n) at x₀; f0 : f(x₀) = Σ r²; scale : c, the model's rise;
    steps : the bounds of each axis's step.
    """
    A = J.T @ J
    lam, V = np.linalg.eigh(0.5 * (A + A.T))
    with np.errstate(divide="ignore"):
        s = np.sqrt(scale * max(f0, 1e-300) / len(lam) / np.maximum(lam, 0.0))
    return V * np.clip(s, steps[0], steps[1])  # type: ignore[no-any-return]


def _jacobian(
    residuals: Residuals, x0: NDArray[np.float64], step: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The residual at x₀ and its forward-difference Jacobian (`lm.forward_probes`: backward at
    the upper bound), in one batch of n + 1 monitor runs."""
    probes, h = forward_probes(x0, step)
    R = np.asarray(residuals(np.vstack([x0[None, :], probes])), dtype=np.float64)
    return R[0], ((R[1:] - R[0]) / h[:, None]).T


def preconditioned_polish(
    evaluate: Objective,
    residuals: Residuals,
    start: OptimizerRun,
    *,
    seed: int = 0,
    on_generation: OnGeneration | None = None,
) -> OptimizerRun:
    """Refine the search's best point `start` (the module docstring): a least-squares descent,
    then a CMA-ES in the Gauss–Newton Hessian's round coordinates about its end. Keeps the best
    point seen (the start if nothing improves on it); the history continues the start's, one
    value per CMA-ES generation.

    evaluate : eq. 3 of rows of the box (the search's); residuals : rows → residual vectors,
    Σ r² = evaluate; start : the point to polish; seed : the CMA-ES's seed; on_generation : its
    progress.
    """
    descended = lm_polish(residuals, start)
    x0 = np.clip(np.asarray(descended.x, dtype=np.float64), 0.0, 1.0)
    r0, J = _jacobian(residuals, x0, limits.LS_STEP)
    evaluations = descended.evaluations + len(x0) + 1  # the start's, the descent's, the Jacobian's
    f0 = float(np.sum(r0 * r0))
    if not (np.isfinite(f0) and np.all(np.isfinite(J))):
        return OptimizerRun(descended.x, descended.f, evaluations, descended.history)
    M = whitening(J, f0, limits.PRECONDITIONED["scale"], tuple(limits.PRECONDITIONED["steps"]))

    def in_y(Y: NDArray[np.float64]) -> NDArray[np.float64]:
        X = x0 + Y @ M.T
        inside = np.clip(X, 0.0, 1.0)
        f = np.asarray(evaluate(inside), dtype=np.float64)
        return f + OUTSIDE_COST * f0 * np.sum((X - inside) ** 2, axis=1)  # type: ignore[no-any-return]

    pop_size, generations = limits.PRECONDITIONED["budget"]
    # y's box is wide enough to be no bound (the unit box is charged in `in_y`); pymoo's CMA-ES
    # works in y normalised to [0, 1], where a step of 1 in y is 1 / (2·Y_BOUND)
    bound = np.full(len(x0), Y_BOUND)
    problem = BatchProblem(in_y, -bound, bound)
    y, f, history = cmaes_minimize(
        problem, np.zeros(len(x0)), 0.5 / Y_BOUND, pop_size, generations, seed=seed,
        stagnation=Stagnation(patience=limits.PRECONDITIONED["patience"]), on_generation=on_generation,
    )  # fmt: skip
    evaluations += problem.evaluations
    x = x0 + M @ y
    if not (f < descended.f and np.all((x >= 0.0) & (x <= 1.0))):
        x, f = descended.x, descended.f
    return OptimizerRun(np.clip(x, 0.0, 1.0), float(f), evaluations, [*descended.history, *history])
