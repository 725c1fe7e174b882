"""The grey wolf optimiser (GWO, Mirjalili et al. 2014), vectorised and seeded (`search.run_optimizer`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from pymoo.core.population import Population

from .optimizers import BatchProblem, GenerationLog, OnGeneration, OptimizerRun, Stagnation

__all__ = ["grey_wolf"]


@dataclass
class _LoopState:
    """What pymoo's terminations read from an algorithm, for a loop of our own (the GWO)."""

    n_gen: int
    best: float

    @property
    def opt(self) -> Any:
        return Population.new("F", np.array([[self.best]]))


def grey_wolf(
    problem: BatchProblem,
    pack: int,
    generations: int,
    rng: np.random.Generator,
    stagnation: Stagnation,
    on_generation: OnGeneration | None,
) -> OptimizerRun:
    """Grey wolf optimiser: the pack moves towards the three best wolves (α, β, δ).

    a falls linearly from 2 to 0; each leader L pulls a wolf to L − A·|C·L − X| with
    A = 2a·r1 − a and C = 2·r2 (r uniform in [0, 1]); the new position is the mean of the three
    pulls, clipped to the box. The leaders are the best points seen so far. The initial pack is
    evaluated before generation 1.
    """
    lo, hi = problem.xl, problem.xu
    X = rng.uniform(lo, hi, (pack, problem.n_var))
    F = problem.evaluate_batch(X)
    order = np.argsort(F)
    leaders, leader_f = X[order[:3]].copy(), F[order[:3]].copy()
    log, stop = GenerationLog(generations, on_generation), stagnation.termination(generations)
    for gen in range(1, generations + 1):
        a = 2.0 * (1.0 - (gen - 1) / max(generations - 1, 1))
        pulls = np.zeros_like(X)
        for L in leaders:
            A = 2.0 * a * rng.uniform(size=X.shape) - a
            C = 2.0 * rng.uniform(size=X.shape)
            pulls += L - A * np.abs(C * L - X)
        X = np.clip(pulls / 3.0, lo, hi)
        F = problem.evaluate_batch(X)
        pool_x, pool_f = np.vstack([leaders, X]), np.concatenate([leader_f, F])
        best = np.argsort(pool_f)[:3]
        leaders, leader_f = pool_x[best].copy(), pool_f[best].copy()
        log.record(gen, float(leader_f[0]))
        stop.update(_LoopState(gen, float(leader_f[0])))
        if stop.has_terminated():
            break
    return OptimizerRun(leaders[0].copy(), float(leader_f[0]), problem.evaluations, log.history, X, F)
