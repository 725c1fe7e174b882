"""What every stage of an identification compares against (`prepare` builds it once per recording).

The measurement on the monitor's grid, filtered (`signals.Comparison`); the samples compared
(`weights.moving_mask` × `weights.band_mask`) and their weights (`weights.error_weights`); eq. 3
over them (`fitness.Fitness`); the monitor under the measurement's command; the settings and the
optimiser's seed. ``context.evaluate(X)`` scores rows of the search box exactly as the search does.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..callbacks import Progress
from ..commands import Command
from ..errors import InputError, SimulationError
from ..kernels.monitor import RING_OUTER
from ..models import MonitorEma
from ..results import check_time_axis
from . import limits
from .fitness import Fitness
from .optimizers import OnGeneration
from .problem import search_to_faults
from .settings import IdentifySettings
from .signals import Comparison, nrmse
from .weights import BAND_HZ, REST_SETTLE_S, band_mask, error_weights, moving_mask, resolve_error_corner

__all__ = ["Context", "prepare"]


@dataclass(frozen=True)
class Context:
    """One recording prepared for the stages (`prepare`).

    monitor : the monitor under the measurement's command; duration : the span compared [s] (it
    ends `limits.TAIL_MARGIN_S` after the last compared sample); reference : the filtered
    measurement on the model grid over it; whole : the same over the whole recording when longer
    (None: the same); mask : the samples compared (0/1); compared, above_band : the fractions of
    the recording compared and left out as faster than `weights.BAND_HZ`; error_corner_hz : the
    corner of the frequency weights (None: none); objective : eq. 3 over the compared samples;
    doubtful_nrmse : the fit above which the result is doubtful (`verdict.fit_limit`), which also
    starts the second search when below its trigger.
    """

    settings: IdentifySettings
    seed: int
    monitor: MonitorEma
    duration: float
    reference: Comparison
    whole: Comparison | None
    mask: NDArray[np.float64]
    compared: float
    above_band: float
    error_corner_hz: float | None
    objective: Fitness
    on_generation: OnGeneration | None = None
    # the NRMSE above which a fit is doubtful for this monitor (`verdict.fit_limit`; None: not known)
    doubtful_nrmse: float | None = None
    # progress of work that is not a generation (label, done, total): the start table's build
    on_progress: Progress | None = None
    # the monitor whose start table the search starts from (a baseline's nameplate, under the same
    # command; None: `monitor`): every actuator of a type shares its table (`start_table`)
    table_monitor: MonitorEma | None = None

    def with_seed(self, seed: int) -> Context:
        """The same comparison searched from another optimiser seed (`second_search`)."""
        return replace(self, seed=seed)

    def evaluate(self, X: NDArray[np.float64]) -> NDArray[np.float64]:
        """eq. 3 of rows X of the search box: one parallel kernel call (simulation, filter and sum
        fused per row); a diverged row gets NaN, which the optimisers rank last."""
        return self.objective.of_monitor(self.monitor, search_to_faults(X), duration=self.duration)

    def residuals(
        self, objective: Fitness | None = None
    ) -> Callable[[NDArray[np.float64]], NDArray[np.float64]]:
        """Eq. (3)'s residual vectors r = √w·(I_ref − I_LF) over the compared samples for rows X
        of the box: Σ r² per row is `objective` (default: the context's) of those faults."""
        fitness = self.objective if objective is None else objective

        def residuals(X: NDArray[np.float64]) -> NDArray[np.float64]:
            return fitness.residuals_of_monitor(self.monitor, search_to_faults(X), duration=self.duration)

        return residuals

    def fit_of(self, faults: NDArray[np.float64]) -> tuple[float, NDArray[np.float64] | None]:
        """The monitor's fit at `faults`: its NRMSE over the compared samples (inf when the run
        diverges) and its filtered current (None then)."""
        try:
            fitted = self.reference.filtered(self.monitor.simulate(faults, duration=self.duration).i_q)
        except SimulationError:
            return float("inf"), None
        keep = self.mask > 0
        return float(nrmse(self.reference.reference[keep], fitted[keep])), fitted

    def curves(self, fitted: NDArray[np.float64] | None) -> dict[str, NDArray[np.float64]]:
        """The fit as curves on the model grid over the whole recording: ``t`` [s], the filtered
        ``measured`` current and the ``fitted`` model current [A] (NaN where not simulated or
        diverged), and ``compared``, each sample's weight in the fitness (0: left out)."""
        shown = self.whole if self.whole is not None else self.reference
        out = np.full_like(shown.reference, np.nan)
        compared = np.zeros_like(shown.reference)
        n = len(self.reference.reference)
        if fitted is not None:
            out[:n] = fitted
        compared[:n] = self.mask
        return {"t": shown.t, "measured": shown.reference, "fitted": out, "compared": compared}


def _checked(t: ArrayLike, i_q: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    t, i_q = np.asarray(t, dtype=np.float64), np.asarray(i_q, dtype=np.float64)
    if t.ndim != 1 or t.shape != i_q.shape:
        raise InputError(f"t and i_q must be 1-D of equal length, got {t.shape} and {i_q.shape}")
    if len(t) < limits.MIN_SAMPLES:
        raise InputError(f"the reference has {len(t)} samples; at least {limits.MIN_SAMPLES} are needed")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(i_q))):
        raise InputError("the reference contains NaN or inf")
    check_time_axis(t, "the reference's time axis")
    span = float(t[-1] - t[0])
    if span > limits.MAX_SPAN:
        raise InputError(
            f"the reference spans {span:g} s; at most {limits.MAX_SPAN:g} s can be compared "
            "(is the time axis in seconds?)"
        )
    return t, i_q


def _too_few(kept: int, rest_current: float, position: NDArray[np.float64] | None) -> InputError:
    small_rests = (
        f" (a rest at under {1e3 * rest_current:.0f} mA is left out {1e3 * REST_SETTLE_S:g} ms "
        "after the surface stops)"
        if rest_current > 0 and position is not None
        else ""
    )
    return InputError(
        f"only {kept} samples of the recording can be compared (at least {limits.MIN_SAMPLES} are needed): "
        f"the others are rests in a hold{small_rests}, or a command faster than the "
        f"{BAND_HZ:g} Hz the monitor was fitted on"
    )


def prepare(
    t: ArrayLike,
    i_q: ArrayLike,
    command: Command | None,
    theta_u: ArrayLike | None,
    *,
    settings: IdentifySettings,
    monitor: MonitorEma | None = None,
    on_generation: OnGeneration | None = None,
    doubtful_nrmse: float | None = None,
    on_progress: Progress | None = None,
) -> Context:
    """Check the measurement i_q [A] at t [s] (under `command`, default the monitor's; `theta_u`
    [rad], the surface position if measured, tells the rests in holds) and set up the comparison."""
    t, i_q = _checked(t, i_q)
    base = monitor if monitor is not None else MonitorEma(monitor=settings.monitor)
    model = MonitorEma(
        base.params, command if command is not None else base.command, base.calibration, allow_mismatch=True
    )  # fmt: skip  (base was checked when it was built)
    duration = min(float(t[-1] - t[0]), model.command.duration)
    grid, theta_grid = model.sample_grid(duration)
    f_s = model.params.controller.f_s
    position = None
    if theta_u is not None:
        pos = np.asarray(theta_u, dtype=np.float64)
        if pos.shape != t.shape or not np.all(np.isfinite(pos)):
            raise InputError("theta_u must be finite and sampled at the reference's times")
        position = np.interp(grid, t - t[0], pos)
    # long holds where the surface rests are left out (`moving_mask`): that current is not the
    # faults'; so is motion faster than the monitor was fitted on (`band_mask`). The whole filtered
    # measurement serves the rests whose current the loop's switching decides, and the figures
    in_band = band_mask(theta_grid, f_s)
    whole = Comparison.from_trace(t - t[0], i_q, grid, f_s)
    rest_current = RING_OUTER * model.calibration.coefficients.i_D
    mask = (
        moving_mask(theta_grid, f_s, theta_u=position, i_meas=whole.reference, rest_current=rest_current)
        * in_band
    )
    kept = np.flatnonzero(mask)
    if len(kept) < limits.MIN_SAMPLES:
        raise _too_few(len(kept), rest_current, position)
    compared = float(mask.mean())  # of the whole recording
    corner = resolve_error_corner(settings.error_corner, model.monitor)
    emphasis = error_weights(theta_grid, f_s, corner)
    # what follows the last compared sample (and TAIL_MARGIN_S) is not simulated: the search costs
    # what the compared span costs (a 2 s chirp whose second half is above the band, a final hold)
    end = int(min(len(grid), kept[-1] + 1 + round(limits.TAIL_MARGIN_S * f_s)))
    shown: Comparison | None = None
    if end < len(grid):
        shown, duration = whole, float(grid[end - 1] - grid[0])
        grid, theta_grid = model.sample_grid(duration)
        mask, emphasis = mask[: len(grid)], emphasis[: len(grid)]
    reference = whole if shown is None else Comparison.from_trace(t - t[0], i_q, grid, f_s)
    return Context(
        settings, settings.seed, model, duration, reference, shown, mask, compared, float(1.0 - in_band.mean()),
        corner, Fitness(reference, settings.slope_unit, mask, emphasis), on_generation, doubtful_nrmse,
        on_progress,
    )  # fmt: skip
