"""Optimisers over a box, each evaluating a whole population per call (DESIGN §5).

GA, DE, PSO and CMA-ES come from pymoo; the grey wolf optimiser (GWO, Mirjalili et al. 2014) is
our own, vectorised and seeded. Every optimiser takes the same batch objective
``evaluate(X: (m, n)) -> (m,)``, stops at its generation budget or earlier when the best value has
stagnated (`Stagnation`), reports each generation to a callback, and returns an `OptimizerRun`.
The budgets are in `limits`; the grey wolf loop in `gwo`; the local polishes in `polish`.

The pieces shared with the calibration (`emaphm.calibration`): `BatchProblem` (the pymoo problem of a
batch objective on a box; it counts evaluations and turns any non-finite value into +inf) and
`GenerationLog` (the pymoo callback that records the best value of each generation and reports
it), and `NumpyDuplicates` (the GA's duplicate check without scipy.spatial).

The GA is real-coded with the parent-centric crossover PCX (Deb et al. 2002) instead of pymoo's
default SBX. The three coil shorts act on the current through a linear mix of (k3, k4, k5): a
total loss plus a 2θ_e ripple vector. So the fitness valleys are rotated against the axes, and the
coordinate-wise SBX drifts into the wrong phase assignment (seen: 8–41 % err over five seeds on the
Table 1 case). PCX is rotation-invariant; its budget is set where it found the right basin in all
10 seeds of the Table 1 case (96 x 40; at 64 x 60 it missed it in 4 of 10: `limits.DEFAULT_BUDGETS`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pymoo.core.callback import Callback
from pymoo.core.duplicate import DefaultDuplicateElimination
from pymoo.core.problem import Problem
from pymoo.core.termination import TerminateIfAny, Termination
from pymoo.optimize import minimize
from pymoo.termination.delta import DeltaToleranceTermination
from pymoo.termination.max_gen import MaximumGenerationTermination
from pymoo.termination.robust import RobustTermination

from ..choices import OPTIMIZERS
from ..errors import InputError

__all__ = [
    "OPTIMIZERS",
    "BatchProblem",
    "GenerationLog",
    "OptimizerRun",
    "RelativeObjectiveTermination",
    "Stagnation",
    "check_optimizer",
    "duplicate_distances",
    "minimize_batch",
    "run_pymoo",
]

Objective = Callable[[NDArray[np.float64]], NDArray[np.float64]]
# a batch of residual vectors: X (m, n) -> R (m, p), with the objective Σ_j R[i, j]² per row
Residuals = Callable[[NDArray[np.float64]], NDArray[np.float64]]
OnGeneration = Callable[[int, int, float], None]  # (generation, max generations, best value)


@dataclass(frozen=True)
class Stagnation:
    """The early stop: `patience` generations in a row without a relative improvement above `rtol`.

    Settings only; `termination` makes the pymoo termination that applies them.
    """

    patience: int = 25
    rtol: float = 1e-3

    def __post_init__(self) -> None:
        if not (isinstance(self.patience, int | np.integer) and self.patience >= 1):
            raise InputError(f"patience must be a whole number >= 1, got {self.patience!r}")
        if not (np.isfinite(self.rtol) and self.rtol >= 0):
            raise InputError(f"rtol must be finite and >= 0, got {self.rtol!r}")

    def termination(self, generations: int) -> Termination:
        """pymoo's termination: at `generations`, or earlier by this rule (fresh state per run).

        pymoo's `RobustTermination(SingleObjectiveSpaceTermination(tol), period)` with a relative
        tolerance. The objective-space termination keeps a reference best value: a generation
        whose best is within rtol·|reference| of it counts as stagnant; one that improves on it by
        more becomes the new reference. The robust wrapper stops after `patience` stagnant
        generations in a row, so at generation g when best(g − patience) − best(g) ≤
        rtol·|best(g − patience)| and no generation in between improved by more than rtol on the
        reference; at the earliest at generation patience + 1. A non-finite best never stops it.
        """
        return TerminateIfAny(
            MaximumGenerationTermination(generations),
            RobustTermination(RelativeObjectiveTermination(self.rtol), period=self.patience),
        )


class RelativeObjectiveTermination(DeltaToleranceTermination):  # type: ignore[misc]
    """pymoo's `SingleObjectiveSpaceTermination` with a relative tolerance: the improvement of the
    best value on the reference, divided by |reference| (pymoo divides by nothing).

    Built on pymoo's `DeltaToleranceTermination` with `SingleObjectiveSpaceTermination`'s `_data`
    (the best feasible value, inf when none) instead of subclassing it: its module
    (``pymoo.termination.ftol``) imports pymoo's hypervolume and with it `moocore` (its data sets,
    ``urllib.request``, ``platformdirs``), about 14 ms of every diagnosis's start for a
    multi-objective indicator (issue 36). `tests/identification/test_optimizers.py` checks both
    stop at the same generation.
    """

    def __init__(self, tol: float = 1e-6, only_feas: bool = True, **kwargs: Any) -> None:
        super().__init__(tol, **kwargs)
        self.only_feas = only_feas

    def _data(self, algorithm: Any) -> float:  # pymoo 0.6.2's SingleObjectiveSpaceTermination._data
        opt = algorithm.opt
        f = opt.get("f")
        if self.only_feas:
            f = f[opt.get("feas")]
        return float(f.min()) if len(f) > 0 else np.inf

    def _delta(self, prev: float, current: float) -> float:
        if not (np.isfinite(prev) and np.isfinite(current)):
            return np.inf
        gain = max(0.0, prev - current)
        if prev == 0.0:
            return 0.0 if gain == 0.0 else np.inf
        return gain / abs(prev)


@dataclass(frozen=True)
class OptimizerRun:
    """The outcome of one optimiser run: best point, value, evaluations, best value per generation;
    for a global search also its final population (points in the box and their values), from which
    `identify` polishes a second, distinct candidate."""

    x: NDArray[np.float64]
    f: float
    evaluations: int
    history: list[float]
    population: NDArray[np.float64] | None = None
    population_f: NDArray[np.float64] | None = None


class BatchProblem(Problem):  # type: ignore[misc]
    """Minimise a batch objective ``evaluate(X: (m, n)) -> (m,)`` over the box [xl, xu].

    Points are clipped to the box before they are evaluated. Any non-finite value (NaN, ±inf)
    becomes +inf, the worst possible, so it never ranks above a finite one (a NaN would make the
    optimisers' sorting and comparisons arbitrary, a −inf would win). `evaluations` counts the
    points evaluated.
    """

    def __init__(self, evaluate: Objective, xl: ArrayLike, xu: ArrayLike) -> None:
        xl, xu = np.asarray(xl, dtype=np.float64), np.asarray(xu, dtype=np.float64)
        if xl.ndim != 1 or xl.shape != xu.shape or not np.all(xl < xu):
            raise InputError(f"bounds must be two equal-length vectors with xl < xu, got {xl} and {xu}")
        super().__init__(n_var=len(xl), n_obj=1, xl=xl, xu=xu)
        self.objective = evaluate
        self.evaluations = 0

    def _evaluate(self, X: NDArray[np.float64], out: dict[str, Any], *args: Any, **kwargs: Any) -> None:
        out["F"] = self.evaluate_batch(X)

    def evaluate_batch(self, X: NDArray[np.float64]) -> NDArray[np.float64]:
        """Values of the rows of X (clipped to the box), non-finite ones as +inf; counted."""
        X = np.clip(X, self.xl, self.xu)
        f = np.asarray(self.objective(X), dtype=np.float64).reshape(len(X))
        self.evaluations += len(X)
        return np.where(np.isfinite(f), f, np.inf)


class NumpyDuplicates(DefaultDuplicateElimination):  # type: ignore[misc]
    """pymoo's default duplicate check (a member within `epsilon` of another is dropped), its
    pairwise distances computed with numpy: pymoo's come from scipy.spatial, whose import is
    about 0.25 s of a diagnosis's start (issue 36), for a 96 x 96 table of distances."""

    def calc_dist(self, pop: Any, other: Any = None) -> NDArray[np.float64]:
        X = np.asarray(self.func(pop), dtype=np.float64)
        return duplicate_distances(X, None if other is None else np.asarray(self.func(other), dtype=np.float64))


def duplicate_distances(X: NDArray[np.float64], other: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
    """The distances the GA's duplicate check compares with its epsilon (`NumpyDuplicates`,
    `ga`): of each row of X to each row of `other`, or (`other` None) to each earlier row of X
    (+inf elsewhere: each pair once, never a row with itself)."""
    Y = X if other is None else other
    D = np.sqrt(np.sum((X[:, None, :] - Y[None, :, :]) ** 2, axis=-1))
    if other is None:
        D[np.triu_indices(len(X))] = np.inf
    return D  # type: ignore[no-any-return]


def best_value(algorithm: Any) -> float:
    """The best objective value a pymoo algorithm holds (its optimum and its population)."""
    best = float(np.min(algorithm.pop.get("F")))
    if algorithm.opt is not None and len(algorithm.opt):
        best = min(best, float(algorithm.opt.get("F").min()))
    return best


class GenerationLog(Callback):  # type: ignore[misc]
    """pymoo callback: records the best value of each generation and reports it.

    `on_generation(generation, generations, best)` is called once per generation; `record` does
    the same for a loop that is not a pymoo algorithm (the GWO).
    """

    def __init__(self, generations: int, on_generation: OnGeneration | None = None) -> None:
        super().__init__()
        self.generations, self.on_generation = generations, on_generation
        self.history: list[float] = []

    def record(self, generation: int, best: float) -> None:
        self.history.append(best)
        if self.on_generation is not None:
            self.on_generation(generation, self.generations, best)

    def notify(self, algorithm: Any) -> None:
        self.record(algorithm.n_gen, best_value(algorithm))


def minimize_batch(
    problem: BatchProblem,
    algorithm: Any,
    generations: int,
    *,
    seed: int,
    stagnation: Stagnation | None = None,
    on_generation: OnGeneration | None = None,
) -> tuple[NDArray[np.float64], float, list[float]]:
    """Run a pymoo `algorithm` on `problem` for at most `generations` (fewer if it stagnates).

    Returns the best point (clipped to the box), its value and the best value per generation.
    """
    termination: Termination = (
        MaximumGenerationTermination(generations)
        if stagnation is None
        else stagnation.termination(generations)
    )
    x, f, history, _ = run_pymoo(problem, algorithm, termination, generations, seed, on_generation)
    return x, f, history


def run_pymoo(
    problem: BatchProblem,
    algorithm: Any,
    termination: Termination,
    generations: int,
    seed: int,
    on_generation: OnGeneration | None,
) -> tuple[NDArray[np.float64], float, list[float], Any]:
    """pymoo's `minimize` with a `GenerationLog`: best point (clipped), value, history, result."""
    log = GenerationLog(generations, on_generation)
    res = minimize(problem, algorithm, termination, seed=seed, verbose=False, callback=log)
    x = np.clip(np.atleast_2d(res.X)[0], problem.xl, problem.xu)
    return x, float(np.atleast_1d(res.F)[0]), log.history, res


def check_optimizer(name: str) -> str:
    """`name` if it is one of `OPTIMIZERS`, else `InputError` listing them."""
    if name not in OPTIMIZERS:
        raise InputError(f"unknown optimizer {name!r}; choose one of {', '.join(OPTIMIZERS)}")
    return name
