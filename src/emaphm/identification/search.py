"""Stage 1 and the search as a whole: the global search, then the polish, the final checks and
the least-squares polish (`SEARCH_STAGES`), then the fit measured (`measure_fit`).

`run_search` runs these stages from the context's seed; the second search (`second_search`) runs
them again from another seed.
"""

from __future__ import annotations

from ..faults import as_fault_vector
from . import checks, polish
from .context import Context
from .optimizers import Stagnation, run_optimizer
from .problem import search_to_faults
from .state import Record, Stage, State, finite

__all__ = ["SEARCH_STAGES", "global_search", "measure_fit", "run_search"]


def global_search(state: State | None, context: Context) -> tuple[State, Record]:
    """Stage 1: the settings' optimiser over the box [0, 1]^8 (`optimizers.run_optimizer`), one
    parallel monitor call per generation, from the context's seed."""
    s = context.settings
    run = run_optimizer(
        s.optimizer, context.evaluate, pop_size=s.pop_size, generations=s.generations, seed=context.seed,
        stagnation=Stagnation(s.patience, s.rtol), on_generation=context.on_generation,
    )  # fmt: skip
    return State(run), {
        "stage": "search", "optimizer": s.optimizer, "seed": context.seed, "generations_run": len(run.history),
        "evaluations": run.evaluations, "fitness": run.f,
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
