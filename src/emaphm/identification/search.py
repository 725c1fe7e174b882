"""Stage 1 and the search as a whole: the global search, then the polish, the final checks and
the least-squares polish (`SEARCH_STAGES`), then the fit measured (`measure_fit`).

`run_search` runs these stages from the context's seed; the second search (`second_search`) runs
them again from another seed.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..faults import as_fault_vector
from . import checks, limits, polish, start_table
from .context import Context
from .ga import PCX_ETA, PCX_ZETA, genetic_algorithm
from .gwo import grey_wolf
from .multistart import multistart
from .optimizers import (
    BatchProblem,
    NumpyDuplicates,
    Objective,
    OnGeneration,
    OptimizerRun,
    Residuals,
    Stagnation,
    check_optimizer,
    run_pymoo,
)
from .problem import search_to_faults
from .state import Record, Stage, State, finite

__all__ = ["SEARCH_STAGES", "global_search", "measure_fit", "run_optimizer", "run_search"]


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
    residuals: Residuals | None = None,
    initial: NDArray[np.float64] | None = None,
    offspring: int | None = None,
) -> OptimizerRun:
    """Minimise `evaluate` over [0, 1]^n_var with optimiser `name` (one of `OPTIMIZERS`).

    `initial` (pop_size, n_var): the GA's first population (`start_table`; default uniform);
    `offspring`: the GA's new points per generation (default one per member of the population).

    Stops at `generations` or when `stagnation` (default `Stagnation()`) says so. "multistart"
    (`multistart.multistart`) needs `residuals` too (rows → residual vectors, Σ r² = `evaluate`);
    its population is its sample and its generations its least-squares descents.
    """
    check_optimizer(name)
    default_pop, default_gen = limits.DEFAULT_BUDGETS[name]
    pop_size = default_pop if pop_size is None else pop_size
    generations = default_gen if generations is None else generations
    if pop_size < 4 or generations < 1:
        raise InputError(
            f"need a population of at least 4 and 1 generation, got {pop_size} and {generations}"
        )
    if name == "multistart":
        if residuals is None:
            raise InputError("the multistart search needs the residuals of its objective")
        return multistart(evaluate, residuals, n_var=n_var, sample=pop_size, descents=generations, seed=seed,
                          on_generation=on_generation)  # fmt: skip
    if initial is not None and (name != "ga" or np.shape(initial) != (pop_size, n_var)):
        raise InputError(f"a first population is the GA's, of {pop_size} x {n_var} points")
    if offspring is not None and (name != "ga" or not 1 <= offspring <= pop_size):
        raise InputError(f"offspring per generation are the GA's, 1 to its population {pop_size}, got {offspring}")
    stop = stagnation if stagnation is not None else Stagnation()
    rng = np.random.default_rng(seed)
    problem = BatchProblem(evaluate, np.zeros(n_var), np.ones(n_var))
    if name == "gwo":
        return grey_wolf(problem, pop_size, generations, rng, stop, on_generation)
    if name == "ga":  # pymoo's GA on arrays, the same generations to the bit (`ga`)
        return genetic_algorithm(problem, pop_size, generations, seed, stop, on_generation,
                                 None if initial is None else np.array(initial), offspring)  # fmt: skip
    if name == "cmaes":  # the seed as `cma` can take it (0 would be the clock's)
        from .cmaes import cma_seed

        seed = cma_seed(seed)
    x, f, history, res = run_pymoo(
        problem, _pymoo_algorithm(name, pop_size, generations, n_var, rng, initial, offspring),
        stop.termination(generations),
        generations, seed, on_generation,
    )  # fmt: skip
    pop = res.pop
    return OptimizerRun(x, f, problem.evaluations, history, np.clip(pop.get("X"), problem.xl, problem.xu),
                        np.asarray(pop.get("F"), dtype=np.float64).reshape(-1))  # fmt: skip


def _pymoo_algorithm(
    name: str, pop_size: int, generations: int, n_var: int, rng: np.random.Generator,
    initial: NDArray[np.float64] | None = None, offspring: int | None = None,
) -> Any:  # fmt: skip
    """The pymoo algorithm of optimiser `name`; for the GA, which `run_optimizer` runs on arrays
    (`ga.genetic_algorithm`), the pymoo one that does the same (its reference in the tests)."""
    if name == "ga":
        from pymoo.algorithms.soo.nonconvex.ga import GA
        from pymoo.operators.crossover.pcx import PCX

        sampling = {} if initial is None else {"sampling": np.array(initial)}  # an array: the first population
        return GA(pop_size=pop_size, n_offsprings=offspring, crossover=PCX(eta=PCX_ETA, zeta=PCX_ZETA),
                  eliminate_duplicates=NumpyDuplicates(), **sampling)  # fmt: skip
    if name == "de":
        from pymoo.algorithms.soo.nonconvex.de import DE

        return DE(pop_size=pop_size, variant="DE/rand/1/bin", CR=0.7, F=0.6)
    if name == "pso":
        from pymoo.algorithms.soo.nonconvex.pso import PSO

        return PSO(pop_size=pop_size)
    if name == "cmaes":
        from .cmaes import cmaes

        return cmaes(rng.uniform(0.2, 0.8, n_var), 0.3, pop_size, generations)
    raise AssertionError(f"no pymoo algorithm for {name!r}")  # names are checked before


def global_search(state: State | None, context: Context) -> tuple[State, Record]:
    """Stage 1: the settings' optimiser over the box [0, 1]^8 (`run_optimizer`), one parallel
    monitor call per generation (multistart: per round of its descents), from the context's seed.

    The GA's first population comes from the start table where the settings' ``start`` says so
    (`start_table.uses_table`), and it then runs `limits.TABLE_GENERATIONS` generations unless
    the settings give them, of `limits.TABLE_OFFSPRING` x its population new points each; the
    record says which start it took."""
    s = context.settings
    initial, generations, offspring, started = None, s.generations, None, {"start": "random"}
    theta_cmd = start_table.uses_table(context)
    if theta_cmd is not None:
        pop_size = limits.DEFAULT_BUDGETS["ga"][0] if s.pop_size is None else s.pop_size
        initial, table = start_table.first_population(context, theta_cmd, pop_size, context.on_progress)
        generations = limits.TABLE_GENERATIONS if s.generations is None else s.generations
        offspring = max(1, round(limits.TABLE_OFFSPRING * pop_size))
        started = {"start": "table", "offspring": offspring, **table}
    run = run_optimizer(
        s.optimizer, context.evaluate, pop_size=s.pop_size, generations=generations, seed=context.seed,
        stagnation=Stagnation(s.patience, s.rtol), on_generation=context.on_generation,
        residuals=context.residuals(), initial=initial, offspring=offspring,
    )  # fmt: skip
    return State(run), {
        "stage": "search", "optimizer": s.optimizer, "seed": context.seed, "generations_run": len(run.history),
        "evaluations": run.evaluations, "fitness": run.f, **started,
    }  # fmt: skip


def measure_fit(state: State | None, context: Context) -> tuple[State, Record]:
    """The fit at the search's estimate: the monitor's NRMSE over the compared samples (inf when
    its run diverges), which the second search, the last stage and the verdict read."""
    assert state is not None
    faults = as_fault_vector(search_to_faults(state.run.x[None, :])[0])
    fit_nrmse, fitted = context.fit_of(faults)
    return State(state.run, fit_nrmse, fitted), {"stage": "fit", "fit_nrmse": finite(fit_nrmse)}


# one whole search: 1 the global search, 2 the polish, 3 the final checks, the least-squares polish
SEARCH_STAGES: tuple[Stage, ...] = (
    global_search,
    polish.polish_stage,
    checks.final_checks,
    polish.least_squares_stage,
    measure_fit,
)


def run_search(context: Context) -> tuple[State, list[Record]]:
    """The search's stages in order from the context's seed: the state and their records."""
    state: State | None = None
    records: list[Record] = []
    for stage in SEARCH_STAGES:
        state, record = stage(state, context)
        records.append(record)
    assert state is not None
    return state, records
