"""What passes from stage to stage (`State`) and what each stage leaves in the result (its record).

A stage is a function ``stage(state, context) -> (state, record)``: it takes the run so far (None
before the search) and the recording's `context.Context`, and returns the new run and a record, a
JSON-ready dict whose ``"stage"`` names it. `identifier.FaultIdentifier.fit` runs them in order;
the records, in order, are the result's ``settings["stages"]``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from .fitness import Fitness
from .optimizers import OptimizerRun

if TYPE_CHECKING:
    from .context import Context

__all__ = ["Record", "Stage", "State", "finite", "stage_record"]

Record = dict[str, Any]


@dataclass(frozen=True)
class State:
    """The identification so far.

    run : the search's run (its point in the box, the monitor's eq. 3 there, the evaluations of
    every stage so far, the best value per generation, its final population); fit_nrmse, fitted :
    the fit's NRMSE over the compared samples and the filtered model current at the estimate (inf
    and None before the fit is measured, or when its run diverged); x : the final point when a
    later stage moved it off the search's (the last stage); fitness, objective : the final eq. 3
    and the eq. 3 the intervals use, when a later stage changed them (None: the run's, the
    context's).
    """

    run: OptimizerRun
    fit_nrmse: float = math.inf
    fitted: NDArray[np.float64] | None = None
    x: NDArray[np.float64] | None = None
    fitness: float | None = None
    objective: Fitness | None = None

    @property
    def point(self) -> NDArray[np.float64]:
        """The final point in the search box."""
        return self.run.x if self.x is None else self.x

    @property
    def final_fitness(self) -> float:
        return self.run.f if self.fitness is None else self.fitness

    def with_run(self, run: OptimizerRun) -> State:
        return replace(self, run=run)


Stage = Callable[["State | None", "Context"], tuple[State, Record]]


def stage_record(stages: list[Record], name: str) -> Record | None:
    """The record of stage `name` among `stages` (`FaultIdentifier.records_`, a result's
    ``settings["stages"]`` or its JSON); for the search's own stages, the kept search's: the
    second search's, inside its record, when it was taken. None if `name` did not run."""
    found = [r for r in stages if r.get("stage") == name]
    if name not in ("second_search", "last_stage"):
        second = stage_record(stages, "second_search")
        if second is not None and second.get("taken"):
            found = [r for r in second["stages"] if r.get("stage") == name]
    return found[-1] if found else None


def finite(value: float, digits: int = 6) -> float | None:
    """`value` rounded for a record, None when it is not finite (JSON has no inf)."""
    return round(float(value), digits) if np.isfinite(value) else None
