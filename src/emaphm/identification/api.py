"""`identify`: the library mirror of ``emaphm identify`` (DESIGN §8).

The measurement (`recording`), the stages of `identifier.FaultIdentifier`, the intervals (stage 6,
`uncertainty`) and the verdict (stage 7, `verdict`), and the result with its record (`result`).
"""

from __future__ import annotations

import os
import time
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._threads import numba_threads
from .._versions import versions
from ..actuator import resolve_params
from ..calibration import Calibration, params_hash
from ..callbacks import Progress
from ..commands import Chirp
from ..errors import Doubt, InputError
from ..models import MonitorEma
from ..params import EmaParams
from ..results import SimResult
from . import limits
from .baseline_inputs import divided_by_gain, with_baseline
from .coverage import command_rate
from .identifier import FaultIdentifier
from .last_stage import SwitchingModel, resolve_last_stage
from .optimizers import OnGeneration
from .preconditions import estimate_doubts
from .recording import Measurement, measurement, split_seed
from .result import IdentificationResult
from .settings import IdentifySettings
from .uncertainty import Factors, Uncertainty, load_factors
from .uncertainty.balanced import allowance, widen
from .uncertainty.balanced import doubts as balanced_doubts
from .verdict import explains, fit_doubts, fit_limit, fit_warnings, judge, recording_warnings

__all__ = ["identify"]


def identify(
    true_faults: ArrayLike | None = None,
    reference: str | os.PathLike[str] | SimResult | None = None,
    *,
    settings: IdentifySettings | None = None,
    params: EmaParams | str | os.PathLike[str] | None = None,
    calibration: Calibration | str | os.PathLike[str] | None = None,
    uq_calibration: Factors | str | os.PathLike[str] | None = None,
    channel_map: Any = None,
    thresholds: dict[str, float] | None = None,
    on_generation: OnGeneration | None = None,
    actuator_id: str | None = None,
    baseline: str | os.PathLike[str] | None = None,
    on_progress: Progress | None = None,
    **options: Any,
) -> IdentificationResult:
    """Identify the faults from `reference`, or from the HF twin run with `true_faults` (noise on).

    Parameters
    ----------
    true_faults : the faults k1..k8 the twin runs with; reference : a trace file or `SimResult`,
        or with `channel_map` (a `ChannelMap` or its file) a rig's recording. Exactly one of the two.
    settings : `IdentifySettings`; options : its fields as keywords (``seed=1``), over it. The seed
        is split into the twin's noise seed and the optimiser's.
    params : the actuator (`EmaParams` or an actuator file; default: the paper's nominal one).
    calibration, uq_calibration : the LF calibration and the interval calibration (objects or
        files; default: the packaged ones); an LF calibration for other parameters is refused.
    thresholds : the detection thresholds ({} reports nothing; default: the shipped ones).
    on_generation : progress callback (gen, max_gen, best); a negative gen counts MCMC steps.
    on_progress : progress callback (label, done, total) of the start table's build (`start_table`).
    actuator_id : the actuator's id (serial, tail position), recorded as ``settings["actuator_id"]``.
    baseline : a folder from `emaphm.baseline` (``emaphm baseline``): the actuator's own file,
        calibrations and thresholds (then not given otherwise), recorded as ``settings["baseline"]``;
        the search starts from the nameplate's start table the folder names (an older folder: uniform).
    """
    s, params, calibration, uq_calibration, thresholds, used, nameplate = with_baseline(
        baseline, IdentifySettings.resolve(settings, options), params, calibration, uq_calibration, thresholds
    )
    actuator, monitor, factors = _inputs(s, params, calibration, uq_calibration)
    start = time.perf_counter()
    noise_seed, opt_seed = split_seed(s.seed)
    m = divided_by_gain(measurement(true_faults, reference, channel_map, actuator, noise_seed, monitor), used)
    doubtful = fit_limit(_fit_record(s, factors, uq_calibration, monitor), monitor.monitor)
    balanced = allowance(params, used is not None)  # ψ_m's share of the shorts (`uncertainty.balanced`)
    ident = FaultIdentifier(s.replace(seed=opt_seed), monitor=monitor, on_generation=on_generation,
                            doubtful_nrmse=doubtful[0], on_progress=on_progress, table_monitor=nameplate)  # fmt: skip
    with numba_threads(s.workers):
        ident.fit(m.trace.t, m.trace.i_q, m.command, m.theta_u)
    warnings = [
        *(m.conversion or {}).get("warnings", []),
        *recording_warnings(ident.context_, m.trace.t, m.trace.theta_cmd, monitor.calibration, thresholds,
                            command_rate(m.conversion)),
    ]  # fmt: skip
    interval = None
    if factors is not None and explains(ident.fit_nrmse_):
        interval = _intervals(ident, factors, s, opt_seed, on_generation, warnings, params, balanced)
    warnings += fit_warnings(ident.fit_nrmse_)
    warnings += fit_doubts(ident.fit_nrmse_, *doubtful, ident.record("second_search"))
    detected, judged = judge(ident.faults_, ident.fit_nrmse_, interval, thresholds, balanced[0])
    checked: dict[str, Any] = {"motion": None, "current_scale": None}
    if explains(ident.fit_nrmse_):
        with numba_threads(s.workers):
            doubted, checked = estimate_doubts(ident.context_, ident.faults_, detected, m.trace.t, m.theta_u, params)
        warnings += doubted + balanced_doubts(ident.faults_, *balanced, thresholds, interval)
    doubts = [str(w) for w in warnings if isinstance(w, Doubt)]
    doubts += [w for w in (m.conversion or {}).get("doubts", []) if w not in doubts]  # a converted file's
    record = _record(s, ident, m, noise_seed, opt_seed, monitor, factors, params, calibration, uq_calibration)
    record["doubtful_above"] = {"nrmse": doubtful[0], "source": doubtful[1]}  # `verdict.fit_limit`
    record.update(checked)  # `preconditions.estimate_doubts`: the motion's and the current's scale
    record["baseline"] = used  # `baseline.baseline_inputs`; None: the nameplate
    record["actuator_id"] = actuator_id  # which actuator, for the report and the campaign
    return IdentificationResult(
        estimate=ident.faults_, fitness=ident.fitness_, evaluations=ident.run_.evaluations,
        wall_time_s=round(time.perf_counter() - start, 3), seed=s.seed, optimizer=s.optimizer, truth=m.truth,
        detected=detected, history=ident.run_.history, settings=record, warnings=warnings,
        fit_nrmse=ident.fit_nrmse_, uncertainty=interval, fault_verdicts=judged, curves=ident.curves(),
        doubts=doubts,
    )  # fmt: skip


def _inputs(
    s: IdentifySettings, params: Any, calibration: Any, uq_calibration: Any
) -> tuple[EmaParams, MonitorEma, Factors | None]:
    """The actuator, the monitor and the interval calibration, each checked before the twin runs."""
    actuator = resolve_params(params)
    if s.uncertainty == "mcmc":
        from .uncertainty.mcmc import check_emcee

        check_emcee()
    monitor = MonitorEma(actuator, calibration=calibration, monitor=s.monitor)  # one that does not fit: now
    stage = resolve_last_stage(s.last_stage, monitor.monitor, polish=s.polish)
    if stage == "switching":
        SwitchingModel(actuator, Chirp())  # its integration steps, for this actuator's dt and f_s
    return actuator, monitor, _factors(s.uncertainty, uq_calibration, stage)


def _factors(method: str, given: Factors | str | os.PathLike[str] | None, last_stage: str) -> Factors | None:
    """The interval calibration made for the last stage that runs (None: no intervals)."""
    if method == "none":
        return None
    return given if isinstance(given, Factors) else load_factors(given, last_stage=last_stage)


def _fit_record(
    s: IdentifySettings, factors: Factors | None, given: Any, monitor: MonitorEma
) -> dict[str, Any] | None:
    """The interval calibration's record that measured how well this monitor explains its twin
    (`verdict.fit_limit`): the one in use, else (no intervals asked for) the one that would be; None
    when it belongs to another LF calibration."""
    if factors is None and not isinstance(given, Factors):
        try:
            factors = load_factors(
                given, last_stage=resolve_last_stage(s.last_stage, monitor.monitor, polish=s.polish)
            )
        except InputError:
            return None
    if isinstance(given, Factors) and factors is None:
        factors = given
    if factors is None or not factors.record or not factors.matches(monitor.calibration):
        return None
    return factors.record


def _intervals(
    ident: FaultIdentifier,
    factors: Factors,
    s: IdentifySettings,
    seed: int,
    on_step: OnGeneration | None,
    warnings: list[str],
    params: Any = None,
    balanced: tuple[float, str] = (0.0, ""),
) -> Uncertainty | None:
    """Stage 6: the Laplace intervals about the estimate (with ``mcmc``, the posterior's from
    them), widened for what the actuator's constants may move (`uncertainty.constants`: a
    baseline's fit, else the actuator file `params`' tolerances) and the shorts' for the
    `balanced` part a ψ_m off its nameplate may explain (`uncertainty.balanced`); what makes
    them doubtful is appended to `warnings`."""
    from .uncertainty import laplace
    from .uncertainty.constants import constants_covariance

    search = ident.record("search") or {}
    doubt, other = factors.mismatch(ident.monitor_.calibration, ident.last_stage_, str(search.get("start", "random")))
    if doubt is not None:
        warnings.append(doubt)
    factors = Factors.identity() if other else factors
    start = time.perf_counter()
    interval = None
    with numba_threads(s.workers):
        try:
            cov_c, source = constants_covariance(factors.record, params)
            interval = laplace(ident.final_objective_, ident.monitor_, ident.faults_, duration=ident.duration_,
                               factors=factors, constants_cov=cov_c)  # fmt: skip
            interval.details["constants_from"] = source
        except InputError as exc:  # the estimate stands; only its intervals cannot be given
            warnings.append(f"no intervals: {exc}; faults are detected by the point rule")
        if interval is not None and s.uncertainty == "mcmc":
            interval = _posterior(ident, interval, factors, seed, on_step, warnings)
    if interval is not None:
        interval = widen(interval, ident.faults_, *balanced)
        interval.details["wall_time_s"] = round(time.perf_counter() - start, 4)
    return interval


def _posterior(
    ident: FaultIdentifier, local: Uncertainty, factors: Factors, seed: int, on_step: Any, warnings: list[str]
) -> Uncertainty:
    """The MCMC intervals from the Laplace ones (`uncertainty.mcmc.sample`); the Laplace ones if it fails."""
    from .uncertainty.mcmc import sample

    try:
        posterior = sample(ident.final_objective_, ident.monitor_, ident.faults_, local, duration=ident.duration_,
                           factors=factors, seed=seed, on_step=on_step)  # fmt: skip
    except InputError as exc:
        warnings.append(f"MCMC failed ({exc}): the Laplace intervals are reported")
        return local
    if not posterior.details["converged"]:
        warnings.append(
            f"the MCMC chain did not converge in {posterior.details['steps']} steps (autocorrelation "
            f"times up to {np.nanmax(posterior.details['autocorr_time']):.0f} steps): its intervals are indicative"
        )
    return posterior


def _record(
    s: IdentifySettings, ident: FaultIdentifier, m: Measurement, noise_seed: int, opt_seed: int, monitor: MonitorEma,
    factors: Factors | None, params: Any, calibration: Any, uq_calibration: Any,
) -> dict[str, Any]:  # fmt: skip
    """The result's ``settings``: the settings, constants and stage records, the inputs and versions."""
    ctx = ident.context_
    return {
        "identify": s.to_json(),
        "limits": limits.as_dict(),
        "stages": ident.records_,
        "reference": m.source,
        "conversion": m.conversion,  # a rig's recording (`channel_map`): θ0, rates, segments, flags
        "noise_seed": noise_seed if m.truth is not None else None,
        "optimizer_seed": opt_seed,
        "generations_run": len(ident.run_.history),  # the kept search's
        "last_stage": ident.last_stage_,  # the one that ran ("switching" or "none")
        "search_fitness": ident.search_fitness_,  # the monitor's eq. 3 at the search's estimate
        "samples_compared": round(ctx.compared, 4),  # long holds of the command are left out
        "samples_above_band": round(ctx.above_band, 4),  # faster than the monitor's band: left out
        "compared_span_s": round(ctx.duration, 4),  # ends TAIL_MARGIN_S after the last compared sample
        "error_corner_hz": ctx.error_corner_hz,  # of eq. 3's frequency weights; None: unweighted
        "optimizer_wall_time_s": round(ident.wall_time_, 3),
        "calibration": {
            "source": _source(calibration, "packaged", Calibration),
            "created": monitor.calibration.record.get("created"),
            "params_hash": monitor.calibration.params_hash,
            "monitor": monitor.monitor,
        },
        "params": {
            "source": _source(params, "nominal", EmaParams),
            "params_hash": params_hash(monitor.params),
        },
        "uq_calibration": None
        if factors is None
        else {
            "source": _source(uq_calibration, "packaged", Factors),
            "created": factors.record.get("created"),
            # the intervals use it only when it was fitted with this monitor (`_intervals`)
            "calibrated": bool(factors.record) and factors.matches(monitor.calibration),
        },
        "versions": versions(),
    }


def _source(value: Any, default: str, kind: type) -> str:
    """How an input was given, for the record: `default` when not given, its path, or an object."""
    if value is None:
        return default
    return f"{kind.__name__} object" if isinstance(value, kind) else str(value)
