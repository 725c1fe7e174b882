"""The search's GA on arrays: pymoo's GA, the same generations to the bit, without its object model.

The global search's GA (`search.run_optimizer`, "ga") is pymoo 0.6.2's `GA` with the
parent-centric crossover PCX (η = ζ = 0.5), pymoo's polynomial mutation, binary tournaments on
the fitness, fitness survival and `optimizers.NumpyDuplicates`. pymoo keeps every point as an
`Individual` object in a `Population`, and its bookkeeping (building, copying and reading those
objects one by one) took about 50 ms of each diagnosis's 15 generations on machine G, a
twentieth of the search (issue 36, thirteenth session). Here the same generation runs on numpy
arrays, drawing from the same random generator in the same order:

1. the first population: the rows given (the start table's), else pymoo's uniform sampling; rows
   within 1e-16 of an earlier one dropped; evaluated;
2. each generation, until pymoo's termination (`Termination`: the generation budget, or the
   stagnation rule of `optimizers.Stagnation`): offspring by pymoo's mating (`mating`: tournaments
   of two by the fitness, ties by a coin; PCX on three parents with probability 0.9, else one of
   them copied; PM on each variable with probability 1/n, applied to a row with probability 0.9;
   duplicates of the row's batch, the population and the offspring so far dropped, and the mating
   repeated up to 100 times until there are enough), evaluated, the population and offspring
   merged and the best `pop_size` kept (a stable sort by the fitness);
3. after the first population and after each generation, the best point (the first of the lowest
   fitness) is the optimum the termination and the progress callback see.

The crossover, the mutation and the bound repair are pymoo's own array functions (`pcx`,
`repair_random_init`, `mut_pm`); what is rewritten is the plumbing between them. Tested against
pymoo's `GA` run by `pymoo.optimize.minimize` (tests/identification/test_ga.py): the same points,
values, evaluations and per-generation history to the bit, from uniform and given starts, with
ties, duplicates, early stops and a mating that gives too few offspring.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray
from pymoo.operators.crossover.pcx import pcx
from pymoo.operators.mutation.pm import mut_pm
from pymoo.operators.repair.bounds_repair import repair_random_init

from .optimizers import (
    BatchProblem,
    GenerationLog,
    OnGeneration,
    OptimizerRun,
    Stagnation,
    duplicate_distances,
)

__all__ = ["PCX_ETA", "PCX_ZETA", "Termination", "genetic_algorithm"]

PCX_ETA = 0.5  # PCX's spread along the other parents' directions (Deb et al. 2002)
PCX_ZETA = 0.5  # PCX's spread along the direction to the parents' centroid
CROSSOVER_PROB = 0.9  # pymoo's Crossover default: the mating's share that crosses over
MUTATION_PROB = 0.9  # pymoo's PM default: the share of rows mutated
MUTATION_ETA = 20  # pymoo's PM default distribution index
PARENTS = 3  # PCX's parents per offspring
TOURNAMENT = 2  # pymoo's binary tournament
MAX_MATINGS = 100  # pymoo's Mating: rounds to fill the offspring before it gives up
DUPLICATE_EPS = 1e-16  # pymoo's DefaultDuplicateElimination


class Termination:
    """pymoo's ``TerminateIfAny(MaximumGenerationTermination(generations),
    RobustTermination(RelativeObjectiveTermination(rtol), period=patience))`` of
    `Stagnation.termination`, on the best value alone (`update` once per generation)."""

    def __init__(self, generations: int, stagnation: Stagnation) -> None:
        self.generations, self.rtol, self.patience = generations, stagnation.rtol, stagnation.patience
        self.reference: float | None = None  # the objective termination's reference best value
        self.window: list[float] = []  # the robust wrapper's last `patience` progress values
        self.forced = False
        self.perc = 0.0

    def update(self, generation: int, best: float) -> None:
        """After a generation (1 the first population) whose best value is `best`."""
        if self.forced:
            self.perc = 1.0
            return
        self.window.append(self._objective(best))
        del self.window[: -self.patience]
        self.perc = max(generation / self.generations, min(self.window))

    def _objective(self, current: float) -> float:
        """pymoo's DeltaToleranceTermination with `optimizers.RelativeObjectiveTermination`'s delta."""
        prev = self.reference
        if prev is None:
            perc = 0.0
        else:
            if not (np.isfinite(prev) and np.isfinite(current)):
                delta = np.inf
            else:
                gain = max(0.0, prev - current)
                delta = (0.0 if gain == 0.0 else np.inf) if prev == 0.0 else gain / abs(prev)
            if delta <= self.rtol:
                return 1.0  # stagnant: the reference stays
            perc = 1 / (1 + (delta - self.rtol))
        self.reference = current
        return perc

    @property
    def done(self) -> bool:
        return self.perc >= 1.0


def genetic_algorithm(
    problem: BatchProblem,
    pop_size: int,
    generations: int,
    seed: int,
    stagnation: Stagnation,
    on_generation: OnGeneration | None = None,
    initial: NDArray[np.float64] | None = None,
    offspring: int | None = None,
) -> OptimizerRun:
    """The GA over the problem's box (the module docstring) from `seed`: `generations` in all, the
    first population counting as the first, each later one of `offspring` new points (default
    `pop_size`); `initial` (pop_size, n) the first population (default uniform). Returns the best
    point, its value, the evaluations, the best value per generation and the final population."""
    rng = np.random.default_rng(seed)
    xl, xu = problem.xl, problem.xu
    n_off = pop_size if offspring is None else offspring
    if initial is None:  # pymoo's FloatRandomSampling
        X = xl + (xu - xl) * rng.random((pop_size, len(xl)))
    else:
        X = np.atleast_2d(np.asarray(initial))
    X = X[~_duplicates(X, None)]
    F = problem.evaluate_batch(X)
    termination, log = Termination(generations, stagnation), GenerationLog(generations, on_generation)

    def post_advance(generation: int) -> None:
        best = float(F[int(np.argmin(F))])
        termination.update(generation, best)
        log.record(generation, best)

    generation = 1
    post_advance(generation)
    while not termination.done:
        generation += 1
        off = mating(rng, X, F, n_off, xl, xu)
        if len(off) == 0:  # pymoo then stops after one more survival of the population
            termination.forced = True
        else:
            X, F = np.concatenate([X, off]), np.concatenate([F, problem.evaluate_batch(off)])
        keep = np.lexsort([F, np.zeros(len(F))])[:pop_size]  # FitnessSurvival: (CV, F), stable
        X, F = X[keep], F[keep]
        post_advance(generation)
    best = int(np.argmin(F))
    return OptimizerRun(np.clip(X[best], xl, xu), float(F[best]), problem.evaluations, log.history,
                        np.clip(X, xl, xu), np.asarray(F, dtype=np.float64))  # fmt: skip


def mating(
    rng: np.random.Generator, X: NDArray[np.float64], F: NDArray[np.float64], n_offsprings: int,
    xl: NDArray[np.float64], xu: NDArray[np.float64],
) -> NDArray[np.float64]:  # fmt: skip
    """pymoo's `Mating.do` (an `InfillCriterion`): matings until `n_offsprings` new points that
    duplicate neither each other nor the population, at most `MAX_MATINGS` rounds."""
    off = np.empty((0, X.shape[1]))
    for _ in range(MAX_MATINGS):
        if len(off) >= n_offsprings:
            break
        new = _mate(rng, X, F, n_offsprings - len(off), xl, xu)
        new = new[~_duplicates(new, None)]
        for other in (X, off):  # pymoo's DuplicateElimination.do(new, pop, off)
            if len(other) > 0 and len(new) > 0:
                new = new[~_duplicates(new, other)]
        off = np.concatenate([off, new[: n_offsprings - len(off)]])
    return off


def _mate(
    rng: np.random.Generator, X: NDArray[np.float64], F: NDArray[np.float64], n_matings: int,
    xl: NDArray[np.float64], xu: NDArray[np.float64],
) -> NDArray[np.float64]:  # fmt: skip
    """One round of pymoo's `Mating._do`: tournament selection, PCX crossover, PM mutation."""
    n_var = X.shape[1]
    # TournamentSelection: permutations of the population, pairs compared by the fitness
    n_random = n_matings * PARENTS * TOURNAMENT
    perms = [rng.permutation(len(X)) for _ in range(math.ceil(n_random / len(X)))]
    P = np.concatenate(perms)[:n_random].reshape(n_matings * PARENTS, TOURNAMENT)
    a, b = P[:, 0], P[:, 1]
    winners = np.where(F[a] < F[b], a, b)
    for i in np.flatnonzero(~((F[a] < F[b]) | (F[a] > F[b]))):  # a tie: pymoo's coin, in order
        winners[i] = rng.choice([a[i], b[i]])
    parents = np.swapaxes(X[winners.reshape(n_matings, PARENTS)], 0, 1)  # (parents, matings, n)
    # Crossover.do with PCX (one offspring of three parents)
    children = np.empty((1, n_matings, n_var), dtype=parents.dtype)
    cross = rng.random(n_matings) < np.full(n_matings, CROSSOVER_PROB)
    if np.any(cross):
        eta, zeta = np.full((n_matings, 1), PCX_ETA), np.full((n_matings, 1), PCX_ZETA)
        Xp = pcx(parents, eta, zeta, index=0, random_state=rng)
        Xp = repair_random_init(Xp, parents[0], xl, xu, random_state=rng)
        children[:, cross] = Xp[None, :][:, cross]
    for k in np.flatnonzero(~cross):
        s = rng.choice(np.arange(PARENTS), size=1, replace=False)
        children[:, k] = np.copy(parents[s, k])
    children = children.reshape(-1, n_var)
    # Mutation.do with PM
    n = len(children)
    mutated = mut_pm(children.astype(float), xl, xu, np.full(n, MUTATION_ETA), np.full(n, min(0.5, 1 / n_var)),
                     at_least_once=False, random_state=rng)  # fmt: skip
    rows = rng.random(size=n) <= np.full(n, MUTATION_PROB)
    children[rows] = mutated[rows]
    return children


def _duplicates(X: NDArray[np.float64], other: NDArray[np.float64] | None) -> NDArray[np.bool_]:
    """`optimizers.NumpyDuplicates`' test: rows of X within `DUPLICATE_EPS` of an earlier row of
    X (`other` None) or of any row of `other`."""
    D = duplicate_distances(X, other)
    D[np.isnan(D)] = np.inf
    return np.any(D <= DUPLICATE_EPS, axis=1)  # type: ignore[no-any-return]
