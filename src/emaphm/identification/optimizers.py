"""Optimisers over the box [0, 1]^n, each evaluating a whole population per call (DESIGN §5).

GA, DE, PSO and CMA-ES come from pymoo; the grey wolf optimiser (GWO, Mirjalili et al. 2014) is
our own, vectorised and seeded. Every optimiser takes the same batch objective
``evaluate(X: (m, n)) -> (m,)``, stops at its generation budget or earlier when the best value has
stagnated, reports each generation to a callback, and returns an `OptimizerRun`. The local polish
(on by default in `identify`) refines the best point with a small CMA-ES, also one batch per
generation.

The GA is real-coded with the parent-centric crossover PCX (Deb et al. 2002) instead of pymoo's
default SBX. The three coil shorts act on the current through a linear mix of (k3, k4, k5): a
total loss plus a 2θ_e ripple vector. So the fitness valleys are rotated against the axes, and the
coordinate-wise SBX drifts into the wrong phase assignment (seen: 8–41 % err over five seeds on the
Table 1 case). PCX is rotation-invariant and found the right basin in every seed.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray
from pymoo.core.callback import Callback
from pymoo.core.problem import Problem
from pymoo.optimize import minimize

from ..errors import InputError

__all__ = [
    "DEFAULT_BUDGETS",
    "OPTIMIZERS",
    "OptimizerRun",
    "Stagnation",
    "check_optimizer",
    "polish",
    "run_optimizer",
]

Objective = Callable[[NDArray[np.float64]], NDArray[np.float64]]
OnGeneration = Callable[[int, int, float], None]  # (generation, max generations, best value)

OPTIMIZERS = ("ga", "de", "pso", "cmaes", "gwo")
# (population, max generations) of the global search: 3840 evaluations for every optimiser. The
# GA gets a wider, shorter run: at 64 x 60 it ended in a wrong basin in 4 of 10 seeds on the
# Table 1 case, at 96 x 40 in none (benchmarks: docs/identification.md §3)
DEFAULT_BUDGETS: dict[str, tuple[int, int]] = {
    "ga": (96, 40),
    "de": (64, 60),
    "pso": (64, 60),
    "cmaes": (64, 60),
    "gwo": (64, 60),
}
POLISH_BUDGET = (32, 50)  # population, generations of the CMA-ES polish


@dataclass
class Stagnation:
    """Stop when the best value has improved by less than `rtol` (relative) over `patience` generations."""

    patience: int = 25
    rtol: float = 1e-3
    history: list[float] = field(default_factory=list)

    def update(self, best: float) -> bool:
        """Record this generation's best; True when the run should stop."""
        self.history.append(best)
        if len(self.history) <= self.patience:
            return False
        old = self.history[-self.patience - 1]
        return old - best <= self.rtol * abs(old)


@dataclass(frozen=True)
class OptimizerRun:
    """The outcome of one optimiser run: best point, value, evaluations, best value per generation."""

    x: NDArray[np.float64]
    f: float
    evaluations: int
    history: list[float]


class _BatchProblem(Problem):  # type: ignore[misc]
    def __init__(self, evaluate: Objective, n_var: int, counter: list[int]) -> None:
        super().__init__(n_var=n_var, n_obj=1, xl=np.zeros(n_var), xu=np.ones(n_var))
        self._evaluate_batch, self._counter = evaluate, counter

    def _evaluate(self, X: NDArray[np.float64], out: dict[str, Any], *args: Any, **kwargs: Any) -> None:
        self._counter[0] += len(X)
        out["F"] = self._evaluate_batch(np.clip(X, 0.0, 1.0))


class _Monitor(Callback):  # type: ignore[misc]
    def __init__(self, stop: Stagnation, generations: int, on_generation: OnGeneration | None) -> None:
        super().__init__()
        self.stop, self.generations, self.on_generation = stop, generations, on_generation

    def notify(self, algorithm: Any) -> None:
        best = float(np.min(algorithm.pop.get("F")))
        if algorithm.opt is not None and len(algorithm.opt):
            best = min(best, float(algorithm.opt.get("F").min()))
        if self.on_generation:
            self.on_generation(algorithm.n_gen, self.generations, best)
        if self.stop.update(best):
            algorithm.termination.force_termination = True


def check_optimizer(name: str) -> str:
    """`name` if it is one of `OPTIMIZERS`, else `InputError` listing them."""
    if name not in OPTIMIZERS:
        raise InputError(f"unknown optimizer {name!r}; choose one of {', '.join(OPTIMIZERS)}")
    return name


def _pymoo_algorithm(name: str, pop_size: int, n_var: int, rng: np.random.Generator) -> Any:
    if name == "ga":
        from pymoo.algorithms.soo.nonconvex.ga import GA
        from pymoo.operators.crossover.pcx import PCX

        return GA(pop_size=pop_size, crossover=PCX(eta=0.5, zeta=0.5))
    if name == "de":
        from pymoo.algorithms.soo.nonconvex.de import DE

        return DE(pop_size=pop_size, variant="DE/rand/1/bin", CR=0.7, F=0.6)
    if name == "pso":
        from pymoo.algorithms.soo.nonconvex.pso import PSO

        return PSO(pop_size=pop_size)
    if name == "cmaes":
        from pymoo.algorithms.soo.nonconvex.cmaes import CMAES

        return CMAES(x0=rng.uniform(0.2, 0.8, n_var), sigma=0.3, popsize=pop_size, restarts=0)
    raise AssertionError(f"no pymoo algorithm for {name!r}")  # names are checked before


def run_optimizer(
    name: str,
    evaluate: Objective,
    *,
    n_var: int = 8,
    pop_size: int | None = None,
    generations: int | None = None,
    seed: int = 0,
    stagnation: Stagnation | None = None,
    on_generation: OnGeneration | None = None,
) -> OptimizerRun:
    """Minimise `evaluate` over [0, 1]^n_var with optimiser `name` (one of `OPTIMIZERS`)."""
    check_optimizer(name)
    default_pop, default_gen = DEFAULT_BUDGETS[name]
    pop_size = default_pop if pop_size is None else pop_size
    generations = default_gen if generations is None else generations
    if pop_size < 4 or generations < 1:
        raise InputError(
            f"need a population of at least 4 and 1 generation, got {pop_size} and {generations}"
        )
    stop = stagnation if stagnation is not None else Stagnation()
    rng = np.random.default_rng(seed)
    if name == "gwo":
        return _grey_wolf(evaluate, n_var, pop_size, generations, rng, stop, on_generation)
    counter = [0]
    res = minimize(
        _BatchProblem(evaluate, n_var, counter),
        _pymoo_algorithm(name, pop_size, n_var, rng),
        ("n_gen", generations),
        seed=seed,
        verbose=False,
        callback=_Monitor(stop, generations, on_generation),
    )
    x = np.clip(np.atleast_2d(res.X)[0], 0.0, 1.0)
    return OptimizerRun(x, float(np.atleast_1d(res.F)[0]), counter[0], list(stop.history))


def _grey_wolf(
    evaluate: Objective,
    n_var: int,
    pack: int,
    generations: int,
    rng: np.random.Generator,
    stop: Stagnation,
    on_generation: OnGeneration | None,
) -> OptimizerRun:
    """Grey wolf optimiser: the pack moves towards the three best wolves (α, β, δ).

    a falls linearly from 2 to 0; each leader L pulls a wolf to L − A·|C·L − X| with
    A = 2a·r1 − a and C = 2·r2 (r uniform in [0, 1]); the new position is the mean of the three
    pulls, clipped to the box. The leaders are the best points seen so far.
    """
    X = rng.uniform(0.0, 1.0, (pack, n_var))
    F = evaluate(X)
    evaluations = pack
    order = np.argsort(F)
    leaders, leader_f = X[order[:3]].copy(), F[order[:3]].copy()
    for gen in range(1, generations + 1):
        a = 2.0 * (1.0 - (gen - 1) / max(generations - 1, 1))
        pulls = np.zeros_like(X)
        for L in leaders:
            A = 2.0 * a * rng.uniform(size=X.shape) - a
            C = 2.0 * rng.uniform(size=X.shape)
            pulls += L - A * np.abs(C * L - X)
        X = np.clip(pulls / 3.0, 0.0, 1.0)
        F = evaluate(X)
        evaluations += pack
        pool_x, pool_f = np.vstack([leaders, X]), np.concatenate([leader_f, F])
        best = np.argsort(pool_f)[:3]
        leaders, leader_f = pool_x[best].copy(), pool_f[best].copy()
        if on_generation:
            on_generation(gen, generations, float(leader_f[0]))
        if stop.update(float(leader_f[0])):
            break
    return OptimizerRun(leaders[0].copy(), float(leader_f[0]), evaluations, list(stop.history))


def polish(
    evaluate: Objective,
    start: OptimizerRun,
    *,
    n_var: int = 8,
    seed: int = 0,
    sigma: float = 0.05,
    stagnation: Stagnation | None = None,
    on_generation: OnGeneration | None = None,
) -> OptimizerRun:
    """Refine a run's best point with a small CMA-ES around it (step `sigma` in the unit box).

    Keeps the start point if the polish finds nothing better; the history continues the start's.
    """
    from pymoo.algorithms.soo.nonconvex.cmaes import CMAES

    pop_size, generations = POLISH_BUDGET
    stop = stagnation if stagnation is not None else Stagnation(patience=15)
    counter = [0]
    res = minimize(
        _BatchProblem(evaluate, n_var, counter),
        CMAES(x0=np.clip(start.x, 0.0, 1.0), sigma=sigma, popsize=pop_size, restarts=0),
        ("n_gen", generations),
        seed=seed,
        verbose=False,
        callback=_Monitor(stop, generations, on_generation),
    )
    x, f = np.clip(np.atleast_2d(res.X)[0], 0.0, 1.0), float(np.atleast_1d(res.F)[0])
    if f >= start.f:
        x, f = start.x, start.f
    return OptimizerRun(x, f, start.evaluations + counter[0], [*start.history, *stop.history])
