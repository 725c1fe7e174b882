"""`baseline`: one actuator's constants and monitor from recordings of it when healthy (issue 33).

The recordings are read as `identify` reads them (`identification.recording.measurement`: a rig's
file through its channel map, or a trace), each prepared for the comparison as the identification
prepares it (`identification.context.prepare`), and the constants fitted to all of them at once
(`fit.fit_constants`). Each recording is also fitted alone: recordings that are not of one healthy
actuator are refused with the reason (one fits far worse than the others, or two disagree on a
constant beyond their intervals). What `identify --baseline` needs is written by `files.write`.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from ..actuator import resolve_params
from ..calibration import Calibration
from ..callbacks import Progress
from ..errors import InputError
from ..identification.context import prepare
from ..identification.recording import measurement
from ..identification.settings import IdentifySettings
from ..io import sha256_of
from ..models import MonitorEma
from .fit import CONSTANTS, Z90, BaselineFit, fit_constants, relative

__all__ = ["DISAGREE_SIGMAS", "WORSE_FIT", "Baseline", "make_baseline"]

# two recordings disagree when a constant's fitted factors differ by more than this many standard
# deviations of their difference (each from its own fit's 90 % interval)
DISAGREE_SIGMAS = 4.0
# a recording fits "far worse" than the others above this many times their median NRMSE
WORSE_FIT = 2.5
# the noise seeds of the nameplate twin's healthy runs the fit is measured against (`fit.relative`)
TWIN_SEED = 33_000


class Baseline:
    """A baseline made (`make_baseline`): the fitted actuator and calibration, the record, and each
    recording's context and monitor current at the baseline's constants (`currents`, for the report)."""

    def __init__(self, params: Any, calibration: Calibration, fit: BaselineFit, record: dict[str, Any],
                 nameplate: Any, contexts: list[Any], currents: list[Any],
                 nameplate_calibration: Calibration | None = None) -> None:  # fmt: skip
        self.params, self.calibration, self.fit, self.record = params, calibration, fit, record
        self.nameplate, self.contexts, self.currents = nameplate, contexts, currents
        # the nameplate's own monitor calibration (None: a warm start from another actuator's), whose
        # start table every actuator of the type shares (`identify --baseline`)
        self.nameplate_calibration = nameplate_calibration


def make_baseline(
    recordings: Sequence[str | os.PathLike[str]],
    *,
    channel_map: Any = None,
    params: Any = None,
    calibration: Calibration | str | os.PathLike[str] | None = None,
    progress: Progress | None = None,
) -> Baseline:
    """Fit the baseline of one actuator from its healthy `recordings` (files; with `channel_map`,
    a rig's recordings read through it), about the nameplate `params` (an actuator file or
    `EmaParams`; default the nominal one) and its monitor `calibration` (default the packaged one)."""
    from .fit import apply

    if not recordings:
        raise InputError("give at least one recording of the healthy actuator")
    start = time.perf_counter()
    nameplate = resolve_params(params)
    monitor, warm = _monitor(nameplate, calibration)
    settings = IdentifySettings()
    contexts = []
    for i, rec in enumerate(recordings):
        m = measurement(None, rec, channel_map, nameplate, 0)
        contexts.append(
            prepare(m.trace.t, m.trace.i_q, m.command, m.theta_u, settings=settings, monitor=monitor)
        )
        if progress is not None:
            progress("recordings read", i + 1, len(recordings))
    twin = fit_constants(
        _twin_contexts(contexts, nameplate, monitor, settings), nameplate, monitor.calibration
    )
    fit = relative(fit_constants(contexts, nameplate, monitor.calibration), twin)
    if progress is not None:
        progress("constants fitted", 1, 1)
    alone = (
        [relative(fit_constants([ctx], nameplate, monitor.calibration), twin) for ctx in contexts]
        if len(contexts) > 1
        else []
    )
    _check_one_healthy_actuator([str(r) for r in recordings], fit, alone)
    fitted, cal = apply(nameplate, monitor.calibration, fit.factors)
    currents = _currents(contexts, fitted, cal, fit.factors["i_gain"])
    fit = replace(fit, fit_nrmse=[_nrmse(ctx, i) for ctx, i in zip(contexts, currents, strict=True)])
    record = {
        "recordings": [{"file": str(r), "sha256": sha256_of(r), "fit_nrmse": round(f, 6),
                        "nameplate_fit_nrmse": round(s, 6)} for r, f, s in zip(recordings, fit.fit_nrmse, fit.start_nrmse, strict=True)],
        "channel_map": None if channel_map is None else str(channel_map),
        # the calibration the fit started from, when it was made for another actuator (`_monitor`)
        "warm_start": warm,
        "factors": {c: _factor_record(fit, c) for c in CONSTANTS},
        "alone": [{c: round(a.factors[c], 6) for c in CONSTANTS} for a in alone],
        "fit": fit.details,
        "wall_time_s": round(time.perf_counter() - start, 2),
    }  # fmt: skip
    return Baseline(fitted, cal, fit, record, nameplate, contexts, currents, None if warm else monitor.calibration)


def _monitor(nameplate: Any, calibration: Any) -> tuple[MonitorEma, str | None]:
    """The nameplate's monitor, and None; with no calibration given for a nameplate the packaged
    one was not made for, the packaged one's coefficients as the start (what moves with the
    constants is refitted; the rest is the packaged actuator's) and a sentence saying so."""
    try:
        return MonitorEma(nameplate, calibration=calibration), None
    except InputError:
        if calibration is not None:
            raise  # a calibration given for another actuator: refused as identify refuses it
    return MonitorEma(nameplate, allow_mismatch=True), (
        "no calibration was given for this nameplate: the packaged one (made for the paper's actuator) "
        "was the start; calibrating the monitor for the nameplate ('emaphm calibrate --params') is better"
    )


def _twin_contexts(contexts: list[Any], nameplate: Any, monitor: MonitorEma, settings: Any) -> list[Any]:
    """The nameplate's twin, healthy, noise on, under each recording's command, prepared alike."""
    from ..faults import HEALTHY
    from ..models import HighFidelityEma

    out = []
    for i, ctx in enumerate(contexts):
        trace = HighFidelityEma(nameplate, ctx.monitor.command).simulate(
            HEALTHY, noise=True, seed=TWIN_SEED + i
        )
        out.append(
            prepare(
                trace.t, trace.i_q, ctx.monitor.command, trace.theta_u, settings=settings, monitor=monitor
            )
        )
    return out


def _currents(contexts: list[Any], params: Any, calibration: Calibration, gain: float) -> list[Any]:
    """Each recording's monitor current at the baseline's constants, healthy, filtered as the
    recording is and through the sensor's `gain`: one simulation each, for the fits and the report."""
    from ..faults import HEALTHY

    out = []
    for ctx in contexts:
        model = MonitorEma(params, ctx.monitor.command, calibration, allow_mismatch=True)
        out.append(gain * ctx.reference.filtered(model.simulate(HEALTHY, duration=ctx.duration).i_q))
    return out


def _nrmse(ctx: Any, current: Any) -> float:
    """A recording's NRMSE against `current` over its compared samples."""
    from ..identification.signals import nrmse

    keep = ctx.mask > 0
    return float(nrmse(ctx.reference.reference[keep], current[keep]))


def _factor_record(fit: BaselineFit, name: str) -> dict[str, float]:
    return {
        "factor": round(fit.factors[name], 6),
        "ci90": [round(fit.low[name], 6), round(fit.high[name], 6)],
    }


def _check_one_healthy_actuator(names: list[str], joint: BaselineFit, alone: list[BaselineFit]) -> None:
    """`InputError` when a recording fits far worse than the others, or two disagree on a constant."""
    if len(alone) < 2:
        return
    fits = np.array(joint.fit_nrmse)
    median = float(np.median(fits))
    worst = int(np.argmax(fits))
    if fits[worst] > WORSE_FIT * median and fits[worst] > 0.03:
        raise InputError(
            f"{names[worst]} fits far worse than the other recordings (NRMSE {100 * fits[worst]:.2f} % against a "
            f"median {100 * median:.2f} %): is it of this actuator, healthy, and read with the right map?"
        )
    for i in range(len(alone)):
        for j in range(i + 1, len(alone)):
            for c in CONSTANTS:
                a, b = (math.log(x.factors[c]) for x in (alone[i], alone[j]))
                sa, sb = (math.log(x.high[c] / x.low[c]) / (2 * Z90) for x in (alone[i], alone[j]))
                if abs(a - b) > DISAGREE_SIGMAS * math.hypot(sa, sb):
                    raise InputError(
                        f"{names[i]} and {names[j]} disagree on {c} ({alone[i].factors[c]:.4f} against "
                        f"{alone[j].factors[c]:.4f} x the nameplate, beyond their intervals): are they of one "
                        "healthy actuator?"
                    )
