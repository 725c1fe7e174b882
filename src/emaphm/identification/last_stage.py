"""Stage 5, the last stage (issue 8): the monitor's bias corrected by a switching model of the drive.

The averaged monitor errs at the truth like a twin with a 1 % torque error (LF-vs-HF NRMSE median
1.8 %, 7 in 1000 random cases above 4 %; docs/theory/monitor-model.md §4), and that bias, not the
search, makes most of an estimate's error. A switching model, the mean of the twin's hysteresis
drive at three other integration steps, follows the twin to 1.05 % median and 2.74 % at worst
over 1000 random cases (`studies/tail_conditioning.py --switching`), but one evaluation costs
≈ 50 ms of one thread, ~100 monitor runs: a search on it does not fit the time budget. So the
search stays on the monitor and this stage corrects it where the estimate is, by output space
mapping:

    d_j = F(I_S(k_j)) − F(I_LF(k_j)),   d̄_j = (d_1 + … + d_j) / j,
    k_(j+1) = argmin_k  Σ w · (I_ref − F(I_LF(k)) − d̄_j)²    (eq. 3 of the corrected monitor)

with F the comparison filter, I_S the switching model's current (`SwitchingModel`: the mean of its
runs at `switching_steps`), w eq. 3's weights and each argmin a least-squares polish of the
monitor from k_j (`polish.least_squares_polish`). d is the monitor's error near the estimate;
where it changes slowly with k, the fixed point is where the switching model fits the measurement
with the monitor's sensitivities (where those mislead, the fixed point is elsewhere: docs/
identification.md §6). Averaging d over the iterations (and I_S over the steps) keeps
the chaotic stick–slip realisation of any one run out of the correction: a polish on one
discretisation's current fitted that realisation instead of the faults (benchmarks/results/
HISTORY.md, "A switching last stage, measured and not built").

Each iteration costs one switching evaluation (one twin run per step, side by side on threads)
and one least-squares polish of the monitor; `limits.SWITCHING_ITERATIONS` of them, after one at the
search's estimate. The final estimate is the iterate with the lowest sum of the switching model's
eq. 3 and the corrected monitor's under the last correction d̄ (the switching model's alone
carries the chaotic stick–slip realisation of its runs; review L3), the search's estimate among
them: where that one wins, it stands (`SwitchingStage.taken`). The iterations stop early when a
run diverges or the polish leaves the point where it was; the record says why.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._threads import thread_map
from ..choices import LAST_STAGES
from ..commands import Command
from ..errors import InputError, SimulationError
from ..models import HighFidelityEma
from ..params import EmaParams
from . import limits
from .context import Context
from .fitness import Fitness
from .optimizers import OptimizerRun
from .polish import least_squares_polish
from .problem import recentre_phase, search_to_faults
from .signals import nrmse
from .state import Record, State

__all__ = [
    "LAST_STAGES",
    "SwitchingModel",
    "SwitchingStage",
    "last_stage",
    "resolve_last_stage",
    "space_mapping",
    "switching_steps",
]


def switching_steps(params: EmaParams) -> tuple[float, ...]:
    """The switching model's integration steps [s] for an actuator: `limits.SWITCHING_STEP_FACTORS`
    times its own step dt, each rounded to the nearest whole fraction 1/(n·f_s) of its sample
    period (`EmaParams` needs a whole number of steps per sample): 2, 2.5 and 1.25 µs at the
    paper's 1 µs and 10 kHz; 1.98, 2.5 and 1.25 µs at 8 kHz."""
    period = 1.0 / params.controller.f_s
    steps = []
    for factor in limits.SWITCHING_STEP_FACTORS:
        n = max(1, round(period / (factor * params.integration.dt)))
        steps.append(period / n)
    return tuple(steps)


def resolve_last_stage(value: str, monitor: str, *, polish: bool = True) -> str:
    """The last stage an identification runs ("switching" or "none") for a `LAST_STAGES` setting;
    "auto" gives the switching stage with the default monitor, none with the paper's. Without the
    polish none runs: a raw search stays raw."""
    if value not in LAST_STAGES:
        raise InputError(f"unknown last stage {value!r}; use one of {', '.join(LAST_STAGES)}")
    if not polish:
        return "none"
    if value == "auto":
        return "switching" if monitor == "default" else "none"
    return value


class SwitchingModel:
    """The twin's switching drive at other integration steps (default: `switching_steps` of the
    actuator); its current is the mean of one noise-free run at each step, the runs side by side on
    `workers` threads (the twin's kernel releases the GIL)."""

    def __init__(self, params: EmaParams, command: Command, steps: Sequence[float] | None = None) -> None:
        steps = switching_steps(params) if steps is None else steps
        if not steps:
            raise InputError("the switching model needs at least one integration step")
        self.steps = tuple(float(s) for s in steps)
        self.models = [
            HighFidelityEma(
                dataclasses.replace(params, integration=dataclasses.replace(params.integration, dt=s)),
                command=command,
            )
            for s in self.steps
        ]

    def current(self, faults: ArrayLike, *, duration: float, workers: int = 1) -> NDArray[np.float64]:
        """i_q [A] on the model grid over `duration`: the mean over the steps (noise off)."""
        k = np.asarray(faults, dtype=np.float64)

        def run(model: HighFidelityEma) -> NDArray[np.float64]:
            return model.simulate(k, noise=False, duration=duration).i_q

        # the finest step first (the most steps: `thread_map`'s costs); the mean in the steps' order
        costs = [1.0 / s for s in self.steps]
        return np.mean(thread_map(run, self.models, workers, costs=costs), axis=0)  # type: ignore[no-any-return]


@dataclass
class SwitchingStage:
    """What the switching last stage did (`space_mapping`).

    x : the final point in the search box; objective : eq. 3 of the corrected monitor (the
    reference less d̄), for the intervals; current : the switching model's current at the final
    estimate (unfiltered); fitness, fit_nrmse : its eq. 3 and NRMSE over the compared samples;
    start_fitness : the switching model's eq. 3 at the search's estimate; iterate : the iterate
    taken (0: the search's estimate, and objective the monitor's own); evaluations : the monitor's
    in the least-squares polishes and the choice; history : the switching model's eq. 3 at each
    iterate; smooth : the corrected monitor's eq. 3 under the last correction there (the iterate
    taken has the lowest sum of the two); stopped : why the iterations ended; points : the iterates.
    """

    x: NDArray[np.float64]
    objective: Fitness
    current: NDArray[np.float64]
    fitness: float
    fit_nrmse: float
    start_fitness: float
    iterate: int
    evaluations: int
    history: list[float]
    smooth: list[float]
    stopped: str
    points: list[NDArray[np.float64]]

    @property
    def taken(self) -> bool:
        """Whether the stage moved the search's estimate."""
        return self.iterate > 0

    def record(self, steps: Sequence[float]) -> dict[str, Any]:
        """For the result's settings (JSON)."""
        return {
            "steps_s": [float(s) for s in steps],
            "iterations": len(self.history) - 1,
            "taken": self.taken,
            # the iterate taken: the lowest sum of the switching model's eq. 3 and the corrected
            # monitor's (0: the search's estimate); why the iterations ended
            "iterate": self.iterate,
            "stopped": self.stopped,
            "start_fitness": _rounded(self.start_fitness),
            "fitness": _rounded(self.fitness),
            "fit_nrmse": _rounded(self.fit_nrmse),
            # the switching model's eq. 3 at the search's estimate and after each iteration
            "history": [_rounded(f) for f in self.history],
            # the corrected monitor's eq. 3 under the last correction at each iterate
            "smooth_history": [_rounded(f) for f in self.smooth],
            "monitor_evaluations": self.evaluations,
        }


def _rounded(value: float) -> float | None:
    return round(float(value), 8) if np.isfinite(value) else None


def space_mapping(
    objective: Fitness,
    residuals_of: Callable[[Fitness], Callable[[NDArray[np.float64]], NDArray[np.float64]]],
    monitor_current: Callable[[NDArray[np.float64]], NDArray[np.float64]],
    switching_current: Callable[[NDArray[np.float64]], NDArray[np.float64]],
    to_faults: Callable[[NDArray[np.float64]], NDArray[np.float64]],
    x0: NDArray[np.float64],
    *,
    iterations: int | None = None,
) -> SwitchingStage:
    """Output space mapping from the search's point x0 (in the search box; module docstring).

    `objective` is eq. 3 against the measurement; `residuals_of(fitness)` gives eq. 3's residual
    vectors for rows of the box under another `Fitness` (`Context.residuals`);
    `monitor_current(k)` and `switching_current(k)` the two models' unfiltered currents for one
    fault vector k; `to_faults` maps rows of the box to fault rows (`search_to_faults`). The
    iterations stop early when a run diverges or the polish does not move the point (the record
    says which). A switching run at x0 that diverges raises `SimulationError`.
    """
    iterations = limits.SWITCHING_ITERATIONS if iterations is None else iterations
    if iterations < 1:
        raise InputError(f"the switching stage needs at least one iteration, got {iterations}")

    def switching_fit(x: NDArray[np.float64]) -> tuple[NDArray[np.float64], float]:
        current = switching_current(to_faults(x[None, :])[0])
        if not np.all(np.isfinite(current)):
            raise SimulationError("the switching model diverged")
        return current, float(objective(current))

    x = np.array(x0, dtype=np.float64, copy=True)
    current, f = switching_fit(x)
    # each iterate: its point, the switching model's current and eq. 3 there, the corrected eq. 3
    iterates = [(x, current, f, objective)]
    d_mean, evaluations, stopped = np.zeros_like(objective.comparison.reference), 0, "all iterations run"
    for j in range(iterations):
        try:
            d = objective.comparison.filtered(current - monitor_current(to_faults(x[None, :])[0]))
        except SimulationError:
            stopped = f"the monitor diverged at iterate {j}"
            break
        d_mean = d_mean + (d - d_mean) / (j + 1)
        corrected = objective.shifted(d_mean)
        residuals = residuals_of(corrected)
        r0 = residuals(x[None, :])[0]
        run = least_squares_polish(residuals, OptimizerRun(x, float(r0 @ r0), 1, []))
        evaluations += run.evaluations
        if np.array_equal(run.x, x):
            stopped = f"the polish did not move the estimate at iterate {j + 1}"
            break
        x = np.array(run.x, dtype=np.float64)
        try:
            current, f = switching_fit(x)
        except SimulationError:
            stopped = f"the switching model diverged at iterate {j + 1}"
            break
        iterates.append((x, current, f, corrected))
    smooth = _smooth_fitness(residuals_of(objective.shifted(d_mean)), [it[0] for it in iterates])
    evaluations += len(iterates)
    history = [it[2] for it in iterates]
    best = int(np.argmin(np.asarray(history) + smooth))
    x, current, fitness, corrected = iterates[best]
    keep, measured = objective.weights > 0, objective.comparison
    fit_nrmse = float(nrmse(measured.reference[keep], measured.filtered(current)[keep]))
    return SwitchingStage(x, corrected, current, fitness, fit_nrmse, history[0], best, evaluations, history,
                          [float(v) for v in smooth], stopped, [it[0] for it in iterates])  # fmt: skip


def _smooth_fitness(
    residuals: Callable[[NDArray[np.float64]], NDArray[np.float64]], points: list[Any]
) -> NDArray[np.float64]:
    """The corrected monitor's eq. 3 under the last correction d̄ at each iterate (inf where its
    run diverges): smooth in the faults, where the switching model's eq. 3 carries the chaotic
    stick-slip realisation of its runs (review L3); the choice among iterates adds the two."""
    R = residuals(np.array(points))
    f = np.sum(R * R, axis=1)
    return np.where(np.isfinite(f), f, np.inf)  # type: ignore[no-any-return]


def last_stage(state: State | None, context: Context) -> tuple[State, Record]:
    """Stage 5: the settings' last stage (`resolve_last_stage`); the switching one runs from the
    search's point (k7 recentred) when the fit explains the measurement, and sets the final point,
    eq. 3, fit and the corrected eq. 3 for the intervals to the switching model's (`space_mapping`)."""
    import numba

    assert state is not None
    s, monitor, duration = context.settings, context.monitor, context.duration
    resolved = resolve_last_stage(s.last_stage, monitor.monitor, polish=s.polish)
    record: Record = {"stage": "last_stage", "last_stage": resolved, "switching": None}
    if resolved != "switching" or not state.fit_nrmse <= limits.FIT_NRMSE_LIMIT:
        return state, record
    x0 = recentre_phase(state.run).x
    model = SwitchingModel(monitor.params, monitor.command)
    workers = numba.get_num_threads()
    try:
        stage = space_mapping(
            context.objective, context.residuals, lambda k: monitor.simulate(k, duration=duration).i_q,
            lambda k: model.current(k, duration=duration, workers=workers), search_to_faults, x0,
        )  # fmt: skip
    except SimulationError as exc:  # the switching model diverged at the search's estimate
        record["switching"] = {"steps_s": list(model.steps), "taken": False, "error": str(exc)}
        return dataclasses.replace(state, x=x0), record
    record["switching"] = stage.record(model.steps)
    run = dataclasses.replace(state.run, evaluations=state.run.evaluations + stage.evaluations)
    fitted = context.reference.filtered(stage.current)
    return State(run, stage.fit_nrmse, fitted, stage.x, stage.fitness, stage.objective), record
