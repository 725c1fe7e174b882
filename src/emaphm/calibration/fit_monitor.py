"""Calibration of the LF monitor model against the HF twin (paper §4.2, DESIGN §4.4): `calibrate`.

A real-coded GA (pymoo, seeded) searches the coefficients of `emaphm.calibration.Coefficients`
within `coefficient_bounds(params)` (`COEFFICIENT_BOUNDS` scaled to the actuator's nameplate) to
minimise the mean NRMSE (see `identification.signals`) between the filtered HF i_q and the filtered
LF current over the fitting scenarios (`emaphm.calibration.scenarios`). One generation is one call of
the population kernel: every candidate × every scenario is one row. The result is checked on
scenarios not used for fitting and written, with that record, to a versioned calibration file.

`calibrate` runs its steps in order: `_task` (the inputs checked, the coefficients to fit and to
hold), `_references` (the HF runs), `_search` (the GA), `_scores` (each scenario's NRMSE before and
after) and `_settings` (the record of how it was made).
"""

from __future__ import annotations

import dataclasses
import datetime as _dt
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from pymoo.algorithms.soo.nonconvex.ga import GA

from .._version import __version__
from .._versions import versions
from ..commands import Command, command_record
from ..errors import InputError
from ..identification.optimizers import BatchProblem, NumpyDuplicates, minimize_batch
from ..identification.signals import CUTOFF_HZ, FILTER_ORDER, Comparison
from ..models._base import check_seed
from ..params import EmaParams
from .coefficients import FOC_UNUSED, SURROGATE, Coefficients, checked_free, coefficient_bounds
from .files import Calibration, check_monitor, held_coefficients
from .scenarios import (
    CALIBRATION_COMMANDS,
    CHECK_SCENARIOS,
    FIT_SCENARIOS,
    PAPER_CHECK_SCENARIOS,
    PAPER_FIT_SCENARIOS,
    Progress,
    Scenario,
    hf_references,
    scenario_nrmse,
)

__all__ = ["calibrate"]


def calibrate(
    *,
    monitor: str = "default",
    seed: int = 1,
    pop_size: int = 60,
    generations: int = 150,
    n_lf: int = 1,
    params: EmaParams | None = None,
    fit: Sequence[Scenario] | None = None,
    check: Sequence[Scenario] | None = None,
    commands: Mapping[str, Command] | None = None,
    progress: Progress | None = None,
    free: Sequence[str] | None = None,
    start: Calibration | None = None,
) -> Calibration:
    """Fit the LF coefficients to the HF twin and check them on held-out scenarios.

    `monitor` is ``"default"`` (the paper's single-phase model with the loop-error surrogate,
    fitted on `FIT_SCENARIOS`: multi-fault actuators under every `CALIBRATION_COMMANDS` entry)
    or ``"paper"`` (the paper's model alone, eqs. 1–2, surrogate off, fitted on the paper's
    scenarios under the chirp, `PAPER_FIT_SCENARIOS`). The HF references are noise-free (the
    twin's deterministic response); the held-out check is also reported with noise on (seed
    `seed`). Returns a `Calibration` whose record holds the monitor, the scenario sets, the
    NRMSE of each, the seed, the settings, the GA history and the versions.

    `commands` names the commands the scenarios refer to (`CALIBRATION_COMMANDS` by default):
    e.g. ``commands={"rig": SampledCommand(t, theta)}`` with scenarios whose command is "rig"
    calibrates the monitor for a rig's own manoeuvre.

    `free` names the coefficients to fit (default: all the monitor's); the others are held at
    `start`'s (a calibration of the same monitor, actuator and `n_lf`; default: the packaged
    calibration of the nominal actuator), which is also the record's `before_calibration`.
    Without `free` every coefficient is fitted from the first guess and `start` must not be
    given. Re-fitting a subset measures what one change of the monitor does without moving every
    coefficient with the GA's own spread.

    Parameters
    ----------
    monitor : {"default", "paper"}
        The monitor model to calibrate (above).
    seed : int
        Seed of the GA and of the noisy held-out check.
    pop_size, generations : int
        The GA's population and number of generations.
    n_lf : int
        LF steps per sample period (1: the LF model steps at the sample time T_s).
    params : EmaParams, optional
        The actuator (default: the paper's nominal one).
    fit, check : sequence of Scenario, optional
        The fitting and held-out scenarios (default: those of `monitor`).
    progress : callable, optional
        ``progress(stage, done, total)``, called as the references run and the GA advances.
    commands, free, start
        See above.
    """
    task = _task(monitor, seed, pop_size, generations, n_lf, params, fit, check, commands, free, start)
    began = time.perf_counter()
    refs = _references(task, progress)
    best, evaluations, history = _search(task, refs, progress)
    scores = _scores(task, best, refs)
    record = {
        "monitor": task.monitor,
        "package_version": __version__,
        "versions": versions(),
        "created": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"),
        "seed": task.seed,
        "settings": _settings(task, evaluations, began),
        "ga_history": history,
        **scores,
    }
    return Calibration(best, task.n_lf, record)


@dataclass(frozen=True)
class _Task:
    """What one calibration fits: its settings, scenarios, and the coefficients it searches and holds."""

    monitor: str
    seed: int
    pop_size: int
    generations: int
    n_lf: int
    params: EmaParams
    fit: tuple[Scenario, ...]
    check: tuple[Scenario, ...]
    commands: dict[str, Command]
    bounds: dict[str, tuple[float, float]]  # every coefficient's box for this actuator
    fitted: list[str]  # the coefficients searched, in the box's order
    initial: Coefficients  # the start: held where not fitted, and the record's before_calibration
    held_from: str  # where `initial` comes from (the record's settings)
    subset: bool  # `free` given: the GA's first population holds the start

    def coefficients(self, x: NDArray[np.float64]) -> Coefficients:
        """The coefficients with the fitted ones set to `x` (in `fitted` order), the others held."""
        fixed = dataclasses.asdict(self.initial)
        return Coefficients(**{**fixed, **{n: float(v) for n, v in zip(self.fitted, x, strict=True)}})

    def nrmse(
        self, coefficients: Sequence[Coefficients], scenarios: Sequence[Scenario], refs: Sequence[Comparison]
    ) -> NDArray[np.float64]:
        """`scenario_nrmse` of this task's actuator, LF step, commands and monitor."""
        return scenario_nrmse(
            coefficients, scenarios, refs, self.params, self.n_lf, self.commands, self.monitor
        )


def _task(
    monitor: str,
    seed: int,
    pop_size: int,
    generations: int,
    n_lf: int,
    params: EmaParams | None,
    fit: Sequence[Scenario] | None,
    check: Sequence[Scenario] | None,
    commands: Mapping[str, Command] | None,
    free: Sequence[str] | None,
    start: Calibration | None,
) -> _Task:
    """`calibrate`'s inputs checked (`InputError`) and resolved to the defaults of the monitor."""
    seed = check_seed(seed)
    check_monitor(monitor)
    for name, value, least in (("pop_size", pop_size, 4), ("generations", generations, 1), ("n_lf", n_lf, 1)):
        if not isinstance(value, int) or value < least:
            raise InputError(f"{name} must be a whole number >= {least}, got {value!r}")
    paper = monitor == "paper"
    fit = tuple(fit if fit is not None else PAPER_FIT_SCENARIOS if paper else FIT_SCENARIOS)
    check = tuple(check if check is not None else PAPER_CHECK_SCENARIOS if paper else CHECK_SCENARIOS)
    params = params if params is not None else EmaParams()
    commands = dict(commands if commands is not None else CALIBRATION_COMMANDS)
    if not fit:
        raise InputError("calibration needs at least one fitting scenario")
    for sc in fit + check:
        if sc.command not in commands:
            raise InputError(
                f"scenario {sc.name!r}: unknown command {sc.command!r}; choose one of {', '.join(commands)}"
            )
    # the searched coefficients; the paper's monitor keeps the surrogate at zero (no loop error)
    bounds = coefficient_bounds(params)
    foc = params.inverter.foc
    allowed = [
        n for n in bounds if not (paper and (n in SURROGATE or n == "V_H")) and not (foc and n in FOC_UNUSED)
    ]
    fitted = checked_free(free, allowed, monitor)
    initial, held_from = held_coefficients(free, start, monitor, params, n_lf)
    return _Task(
        monitor, seed, pop_size, generations, n_lf, params, fit, check, commands,
        bounds, fitted, initial, held_from, subset=free is not None,
    )  # fmt: skip


@dataclass(frozen=True)
class _References:
    """The filtered HF i_q of each scenario: the fitting set, and the check set noise off and on."""

    fit: list[Comparison]
    check: list[Comparison]
    check_noisy: list[Comparison]


def _references(task: _Task, progress: Progress | None) -> _References:
    """Run the HF twin on the fitting and check scenarios (noise off; the check also noise on)."""

    def run(scenarios: tuple[Scenario, ...], noise: bool) -> list[Comparison]:
        return hf_references(
            scenarios, task.params, noise=noise, seed=task.seed, progress=progress, commands=task.commands
        )

    return _References(run(task.fit, False), run(task.check, False), run(task.check, True))


def _search(
    task: _Task, refs: _References, progress: Progress | None
) -> tuple[Coefficients, int, list[float]]:
    """The GA over the fitted coefficients: the best coefficients, the evaluations, the best per generation."""

    def objective(X: NDArray[np.float64]) -> NDArray[np.float64]:
        return task.nrmse([task.coefficients(x) for x in X], task.fit, refs.fit).mean(axis=1)

    def on_generation(generation: int, total: int, best: float) -> None:
        if progress:
            progress("GA generations", generation, total)

    # the mean NRMSE over the fitting scenarios as a function of the coefficient vector
    lo, hi = zip(*(task.bounds[n] for n in task.fitted), strict=True)
    problem = BatchProblem(objective, lo, hi)
    algorithm = GA(pop_size=task.pop_size, eliminate_duplicates=NumpyDuplicates())
    if task.subset:
        # a subset fit starts from where it is: the start's values are one of the first population
        # (uniform in the box otherwise, from the seed), so the GA's elitism never ends it worse
        X0 = np.random.default_rng(task.seed).uniform(lo, hi, size=(task.pop_size, len(task.fitted)))
        X0[0] = np.clip([getattr(task.initial, n) for n in task.fitted], lo, hi)
        algorithm = GA(pop_size=task.pop_size, sampling=X0, eliminate_duplicates=NumpyDuplicates())
    # a fixed number of generations: no early stop
    x, _, history = minimize_batch(
        problem, algorithm, task.generations, seed=task.seed, on_generation=on_generation
    )
    return task.coefficients(x), problem.evaluations, history


def _scores(task: _Task, best: Coefficients, refs: _References) -> dict[str, Any]:
    """The NRMSE tables of the record: fitted, held out (noise off and on), and before calibration."""
    fit_nrmse = task.nrmse([best], task.fit, refs.fit)[0]
    check_nrmse = task.nrmse([best], task.check, refs.check)[0]
    check_noisy = task.nrmse([best], task.check, refs.check_noisy)[0]
    start_nrmse = task.nrmse([task.initial], task.fit + task.check, refs.fit + refs.check)[0]

    def table(scenarios: Sequence[Scenario], values: NDArray[np.float64]) -> list[dict[str, Any]]:
        return [
            {"name": s.name, "command": s.command, "faults": list(s.faults), "nrmse": float(v)}
            for s, v in zip(scenarios, values, strict=True)
        ]

    return {
        "fit_scenarios": table(task.fit, fit_nrmse),
        "check_scenarios": table(task.check, check_nrmse),
        "check_scenarios_noise_on": table(task.check, check_noisy),
        "before_calibration": {
            "coefficients": dataclasses.asdict(task.initial),
            "scenarios": table(task.fit + task.check, start_nrmse),
        },
    }


def _settings(task: _Task, evaluations: int, began: float) -> dict[str, Any]:
    """The record's settings: the GA, the objective, the box, what was fitted, the commands, the actuator."""
    # the commands whose accuracy the record measures: fitted or held out (`coverage`)
    used = dict.fromkeys(sc.command for sc in task.fit + task.check)
    return {
        "optimizer": (
            "pymoo GA, real-coded: binary tournament, SBX crossover, polynomial mutation, "
            "elitist survival, duplicates eliminated; all generations run (no early stop)"
        ),
        "pop_size": task.pop_size,
        "generations": task.generations,
        "evaluations": evaluations,
        "objective": "mean NRMSE over the fitting scenarios (HF noise off)",
        "nrmse": "||I_HF - I_LF|| / ||I_HF - mean(I_HF)||, both filtered",
        "filter": f"Butterworth order {FILTER_ORDER}, {CUTOFF_HZ:g} Hz, zero phase (sosfiltfilt)",
        "bounds": {k: list(v) for k, v in task.bounds.items()},
        "fitted": task.fitted,
        "held_from": task.held_from,
        # the first is the main one (the FDI chirp); every command fitted or checked is listed
        "command": command_record(task.commands[next(iter(used))]),
        "commands": {c: command_record(task.commands[c]) for c in used},
        "params": task.params.to_dict(),
        "wall_time_s": round(time.perf_counter() - began, 2),
    }
