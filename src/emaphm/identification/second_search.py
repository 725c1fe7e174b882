"""Stage 4: a second, independent search when the first one's fit is poorer than the monitor's usual.

It runs when the fit's NRMSE over the compared samples exceeds `limits.SECOND_SEARCH_NRMSE` of the
monitor, or the actuator's doubtful limit when lower (`verdict.fit_limit`, `Context.doubtful_nrmse`), while the fit still explains the measurement (`limits.FIT_NRMSE_LIMIT`), with the
settings' ``polish`` and ``second_search``; it searches from `second_seed` (and from a uniform
population with the optimiser's full budget, whatever the first search's start) and the lower eq. 3
fitness (the search's own measure) is kept. The kept state counts both searches' evaluations;
its history is the kept search's.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from . import limits, search
from .context import Context
from .state import Record, State, finite

__all__ = ["second_search", "second_seed"]


def second_seed(seed: int) -> int:
    """The optimiser seed of the second search, drawn from the first's."""
    return int(np.random.SeedSequence(seed).generate_state(1)[0])


def second_search(state: State | None, context: Context) -> tuple[State, Record]:
    """Stage 4 (see the module docstring); its record is None-valued when it did not run."""
    assert state is not None
    s = context.settings
    trigger = (
        limits.SECOND_SEARCH_NRMSE.get(context.monitor.monitor) if s.polish and s.second_search else None
    )
    if trigger is not None and context.doubtful_nrmse is not None:  # a fit that would be doubtful
        trigger = min(trigger, context.doubtful_nrmse)
    record: Record = {"stage": "second_search", "enabled": bool(s.polish and s.second_search), "ran": False}
    if trigger is None or not trigger < state.fit_nrmse <= limits.FIT_NRMSE_LIMIT:
        return state, record
    first = state
    other_seed = second_seed(context.seed)
    # from a uniform population with the full budget: the start table's rows were the first
    # search's start, and a second look is worth most where they led astray
    again = context.with_seed(other_seed)
    if s.start != "random":
        again = replace(again, settings=s.replace(start="random"))
    second, stages = search.run_search(again)
    # the lower eq. 3 fitness decides, among fits that explain the measurement: a second search
    # whose LF run diverged is never taken
    won = bool(second.run.f < first.run.f and second.fit_nrmse <= limits.FIT_NRMSE_LIMIT)
    kept = second if won else first
    record.update(
        ran=True, trigger=trigger, seed=other_seed,
        first_fit_nrmse=round(first.fit_nrmse, 6),  # finite: it started the search
        second_fit_nrmse=finite(second.fit_nrmse),
        fitness_ratio=finite(second.run.f / first.run.f) if first.run.f > 0 else None,
        first_evaluations=first.run.evaluations, second_evaluations=second.run.evaluations, taken=won,
        stages=stages,
    )  # fmt: skip
    total = first.run.evaluations + second.run.evaluations
    return replace(kept, run=replace(kept.run, evaluations=total)), record
