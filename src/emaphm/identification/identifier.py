"""`FaultIdentifier`: the identification's stages run in order on one measured current.

    prepare   the recording on the model grid, the samples compared, eq. 3      (context)
    1 search        the global search over [0, 1]^8                            (search)
    2 polish        CMA-ES polish of the best point and of its runner-up       (polish)
    3 final checks  the shorts' phases, a trapped eccentricity                 (checks)
      least squares the search's last polish, then the fit measured            (polish, search)
    4 second search the whole search again from another seed on a poor fit     (second_search)
    5 last stage    the monitor's bias corrected by a switching model          (last_stage)

Uncertainty (6, `uncertainty`) and the verdict (7, `verdict`) follow in `api.identify`.
"""

from __future__ import annotations

import time
from dataclasses import replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..callbacks import Progress
from ..commands import Command
from ..errors import InputError
from ..faults import as_fault_vector
from ..models import MonitorEma
from . import search
from .context import Context, prepare
from .last_stage import last_stage
from .optimizers import OnGeneration
from .problem import search_to_faults
from .second_search import second_search
from .settings import IdentifySettings
from .state import Record, Stage, stage_record

__all__ = ["AFTER_SEARCH", "FaultIdentifier"]

# the stages after the search's own (`search.SEARCH_STAGES`), in order (the module docstring)
AFTER_SEARCH: tuple[Stage, ...] = (second_search, last_stage)


class FaultIdentifier:
    """Identify the fault vector from a measured quadrature current (scikit-learn style).

    Parameters
    ----------
    settings : IdentifySettings, optional
        How it runs; its ``seed`` is the optimiser's. Keywords (`options`) override its fields.
    monitor : MonitorEma or {"default", "paper"}, optional
        The calibrated monitor model (its command is replaced by the measurement's), or its name:
        the settings' ``monitor``, for the packaged calibration (None: the settings').
    on_generation : callable(gen, max_gen, best), optional
        Progress callback.
    doubtful_nrmse : float, optional
        The fit [-] above which the result is doubtful (`verdict.fit_limit`); the second search
        starts from it where it is below the monitor's trigger (`limits.SECOND_SEARCH_NRMSE`).
    on_progress : callable(label, done, total), optional
        Progress of work that is not a generation: the start table's build (`start_table`).
    table_monitor : MonitorEma, optional
        The monitor whose start table the search starts from (a baseline's nameplate; default the
        search's own).

    After `prepare`: ``context_`` (`context.Context`) and, from it, ``monitor_``, ``duration_``
    [s], ``reference_``, ``whole_``, ``mask_``, ``compared_``, ``above_band_``,
    ``error_corner_hz_`` and ``objective_`` (eq. 3: ``objective_.of_monitor(monitor_, K,
    duration=duration_)`` scores fault rows K as the search does). After `fit`: ``faults_``,
    ``fitness_`` (the final eq. 3: the switching model's after the last stage), ``fit_nrmse_``,
    ``fitted_``, ``run_`` (the search's run; its evaluations all stages'), ``search_fitness_``,
    ``final_objective_`` (eq. 3 for the intervals), ``last_stage_``, ``wall_time_`` [s] and
    ``records_``, one record per stage (`record`).
    """

    def __init__(
        self,
        settings: IdentifySettings | None = None,
        *,
        monitor: MonitorEma | str | None = None,
        on_generation: OnGeneration | None = None,
        doubtful_nrmse: float | None = None,
        on_progress: Progress | None = None,
        table_monitor: MonitorEma | None = None,
        **options: Any,
    ) -> None:
        if isinstance(monitor, str):  # the monitor by name: the settings' field (docs/conventions.md)
            options, monitor = {**options, "monitor": monitor}, None
        self.settings = IdentifySettings.resolve(settings, options)
        if monitor is not None and self.settings.monitor not in (None, monitor.monitor):
            raise InputError(
                f"monitor {self.settings.monitor!r} was asked for, the MonitorEma given is {monitor.monitor!r}"
            )
        self.monitor = monitor
        self.on_generation = on_generation
        self.doubtful_nrmse = doubtful_nrmse
        self.on_progress = on_progress
        self.table_monitor = table_monitor

    def prepare(
        self, t: ArrayLike, i_q: ArrayLike, command: Command | None = None, theta_u: ArrayLike | None = None
    ) -> FaultIdentifier:
        """Check the measurement i_q [A] at t [s] and set up what the stages compare (`fit` calls
        it first); `theta_u` [rad], the measured surface position at t if the trace has it,
        tells where the surface rests in a hold (`weights.moving_mask`)."""
        ctx = prepare(t, i_q, command, theta_u, settings=self.settings, monitor=self.monitor,
                      on_generation=self.on_generation, doubtful_nrmse=self.doubtful_nrmse,
                      on_progress=self.on_progress)  # fmt: skip
        if self.table_monitor is not None:  # under the recording's command, as the context's
            tm = self.table_monitor
            ctx = replace(ctx, table_monitor=MonitorEma(tm.params, ctx.monitor.command, tm.calibration, allow_mismatch=True))
        self.context_: Context = ctx
        self.monitor_, self.duration_, self.reference_, self.whole_ = (
            ctx.monitor,
            ctx.duration,
            ctx.reference,
            ctx.whole,
        )
        self.mask_, self.compared_, self.above_band_ = ctx.mask, ctx.compared, ctx.above_band
        self.error_corner_hz_, self.objective_ = ctx.error_corner_hz, ctx.objective
        return self

    def fit(
        self, t: ArrayLike, i_q: ArrayLike, command: Command | None = None, theta_u: ArrayLike | None = None
    ) -> FaultIdentifier:
        """Fit to the current i_q [A] sampled at t [s] under `command` (default: the FDI chirp):
        the search's stages (`search.run_search`), then `AFTER_SEARCH` in order, each
        ``stage(state, context) -> (state, record)``."""
        self.prepare(t, i_q, command, theta_u)
        start = time.perf_counter()
        state, self.records_ = search.run_search(self.context_)
        for stage in AFTER_SEARCH:
            state, record = stage(state, self.context_)
            self.records_.append(record)
        self.wall_time_ = time.perf_counter() - start
        self.run_, self.search_fitness_ = state.run, state.run.f
        self.faults_ = as_fault_vector(search_to_faults(state.point[None, :])[0])
        self.fitness_, self.fit_nrmse_, self.fitted_ = state.final_fitness, state.fit_nrmse, state.fitted
        self.final_objective_ = state.objective if state.objective is not None else self.context_.objective
        self.last_stage_: str = self.record("last_stage")["last_stage"]  # type: ignore[index]
        return self

    def record(self, stage: str) -> Record | None:
        """The record of `stage` (its name: "search", "polish", "final_checks", "least_squares",
        "fit", "second_search", "last_stage"), the kept search's for the search's stages (`state.stage_record`)."""
        return stage_record(self.records_, stage)

    def residuals(self, objective: Any = None) -> Any:
        """Eq. 3's residual vectors for rows of the search box (`context.Context.residuals`)."""
        return self.context_.residuals(objective)

    def curves(self) -> dict[str, NDArray[np.float64]]:
        """The fit as curves over the whole recording (`context.Context.curves`): the filtered
        ``measured`` and ``fitted`` currents [A] at ``t`` [s], and each sample's ``compared`` weight."""
        return self.context_.curves(self.fitted_)
