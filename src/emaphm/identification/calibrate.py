"""Calibration of the LF monitor model against the HF twin (paper §4.2, DESIGN §4.4).

A real-coded GA (pymoo, seeded) searches the coefficients of `emaphm.calibration.Coefficients`
within `COEFFICIENT_BOUNDS` to minimise the mean NRMSE (see `signals`) between the filtered HF
i_q and the filtered LF current over the fitting scenarios. One generation is one call of the
population kernel: every candidate × every scenario is one row. The result is checked on
scenarios not used for fitting and written, with that record, to a versioned calibration file.
"""

from __future__ import annotations

import dataclasses
import datetime as _dt
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from pymoo.algorithms.soo.nonconvex.ga import GA

from .._version import __version__
from .._versions import versions
from ..calibration import COEFFICIENT_BOUNDS, Calibration, Coefficients
from ..commands import Chirp, Command, command_record
from ..errors import InputError
from ..faults import HEALTHY, as_fault_vector
from ..kernels.monitor import simulate_lf_many
from ..models import HighFidelityEma, check_seed, monitor_rows
from ..params import EmaParams
from .optimizers import BatchProblem, minimize_batch
from .signals import CUTOFF_HZ, FILTER_ORDER, Comparison

__all__ = ["CHECK_SCENARIOS", "FIT_SCENARIOS", "Scenario", "calibrate", "scenario_nrmse"]


@dataclass(frozen=True)
class Scenario:
    """A named fault vector the HF twin is run with."""

    name: str
    faults: tuple[float, ...]

    def __post_init__(self) -> None:
        as_fault_vector(self.faults, name=f"scenario {self.name!r}")


def _k(**changes: float) -> tuple[float, ...]:
    k = list(HEALTHY)
    for name, value in changes.items():
        k[int(name[1:]) - 1] = value
    return tuple(k)


# DESIGN §4.4 / issue: healthy, a short in each phase, eccentricity at two phases, a combined case
FIT_SCENARIOS: tuple[Scenario, ...] = (
    Scenario("healthy", _k()),
    Scenario("short A k3=0.3", _k(k3=0.3)),
    Scenario("short B k4=0.3", _k(k4=0.3)),
    Scenario("short C k5=0.3", _k(k5=0.3)),
    Scenario("eccentricity k6=0.3 phase 0", _k(k6=0.3, k7=0.0)),
    Scenario("eccentricity k6=0.3 phase 0.4", _k(k6=0.3, k7=0.4)),
    Scenario("combined", _k(k1=0.3, k2=0.2, k4=0.2, k6=0.1, k7=0.6, k8=0.4)),
)
# not used for fitting: other magnitudes, phases, the mechanical faults, the gain, the paper's case
CHECK_SCENARIOS: tuple[Scenario, ...] = (
    Scenario("friction k1=0.5", _k(k1=0.5)),
    Scenario("backlash k2=0.4", _k(k2=0.4)),
    Scenario("gain k8=0.25", _k(k8=0.25)),
    Scenario("short B k4=0.45 + friction k1=0.2", _k(k1=0.2, k4=0.45)),
    Scenario("eccentricity k6=0.2 phase 0.75", _k(k6=0.2, k7=0.75)),
    Scenario("shorts A+C k3=0.15 k5=0.25", _k(k3=0.15, k5=0.25)),
    Scenario("paper Table 1 reference", (0.2383, 0.5003, 5.32e-7, 0.4503, 0.0404, 0.0028, 0.2785, 0.5)),
    Scenario("random mix", (0.41, 0.18, 0.07, 0.22, 0.31, 0.12, 0.83, 0.62)),
)

Progress = Callable[[str, int, int], None]  # (stage, done, total)


def hf_references(
    scenarios: Sequence[Scenario],
    hf: HighFidelityEma,
    *,
    noise: bool,
    seed: int,
    progress: Progress | None = None,
) -> list[Comparison]:
    """Filtered HF i_q of each scenario on the sample grid."""
    out = []
    for j, sc in enumerate(scenarios):
        r = hf.simulate(sc.faults, noise=noise, seed=seed)
        out.append(Comparison.from_signal(r.t, r.i_q, hf.params.controller.f_s))
        if progress:
            progress("HF scenarios", j + 1, len(scenarios))
    return out


def scenario_nrmse(
    coefficients: Sequence[Coefficients],
    scenarios: Sequence[Scenario],
    references: Sequence[Comparison],
    params: EmaParams,
    theta_cmd: NDArray[np.float64],
    n_lf: int,
) -> NDArray[np.float64]:
    """NRMSE of the LF model per (coefficient set, scenario): shape (len(coefficients), len(scenarios)).

    All runs are rows of one population-kernel call.
    """
    K = np.array([sc.faults for sc in scenarios])
    n_c, n_s = len(coefficients), len(scenarios)
    rows = monitor_rows(np.tile(K, (n_c, 1)), params, [c for c in coefficients for _ in range(n_s)], n_lf)
    currents = np.empty((rows.shape[0], len(theta_cmd)))
    simulate_lf_many(theta_cmd, rows, currents)
    by_case = currents.reshape(n_c, n_s, -1)
    out = np.empty((n_c, n_s))
    for s, ref in enumerate(references):
        out[:, s] = ref.nrmse(by_case[:, s, :])
    return out


def calibrate(
    *,
    seed: int = 1,
    pop_size: int = 60,
    generations: int = 150,
    n_lf: int = 1,
    params: EmaParams | None = None,
    command: Command | None = None,
    fit: Sequence[Scenario] = FIT_SCENARIOS,
    check: Sequence[Scenario] = CHECK_SCENARIOS,
    progress: Progress | None = None,
) -> Calibration:
    """Fit the LF coefficients to the HF twin and check them on held-out scenarios.

    The HF references are noise-free (the twin's deterministic response); the held-out check is
    also reported with noise on (seed `seed`). Returns a `Calibration` whose record holds the
    scenario sets, the NRMSE of each, the seed, the settings, the GA history and the versions of
    emaphm, Python and the numerical packages.
    """
    seed = check_seed(seed)
    for name, value, least in (("pop_size", pop_size, 4), ("generations", generations, 1), ("n_lf", n_lf, 1)):
        if not isinstance(value, int) or value < least:
            raise InputError(f"{name} must be a whole number >= {least}, got {value!r}")
    params = params if params is not None else EmaParams()
    hf = HighFidelityEma(params, command if command is not None else Chirp())
    command = hf.command
    start = time.perf_counter()
    fit_refs = hf_references(fit, hf, noise=False, seed=seed, progress=progress)
    check_refs = hf_references(check, hf, noise=False, seed=seed, progress=progress)
    check_refs_noisy = hf_references(check, hf, noise=True, seed=seed, progress=progress)
    _, theta_cmd = hf.sample_grid()

    def objective(X: NDArray[np.float64]) -> NDArray[np.float64]:
        coeffs = [Coefficients.from_vector(x) for x in X]
        return scenario_nrmse(coeffs, fit, fit_refs, params, theta_cmd, n_lf).mean(axis=1)

    def on_generation(generation: int, total: int, best: float) -> None:
        if progress:
            progress("GA generations", generation, total)

    # the mean NRMSE over the fitting scenarios as a function of the coefficient vector
    lo, hi = zip(*COEFFICIENT_BOUNDS.values(), strict=True)
    problem = BatchProblem(objective, lo, hi)
    # a fixed number of generations: no early stop
    x, _, history = minimize_batch(
        problem, GA(pop_size=pop_size), generations, seed=seed, on_generation=on_generation
    )
    best = Coefficients.from_vector(x)
    fit_nrmse = scenario_nrmse([best], fit, fit_refs, params, theta_cmd, n_lf)[0]
    check_nrmse = scenario_nrmse([best], check, check_refs, params, theta_cmd, n_lf)[0]
    check_noisy = scenario_nrmse([best], check, check_refs_noisy, params, theta_cmd, n_lf)[0]
    start_nrmse = scenario_nrmse(
        [Coefficients()], tuple(fit) + tuple(check), fit_refs + check_refs, params, theta_cmd, n_lf
    )[0]

    def table(scenarios: Sequence[Scenario], values: NDArray[np.float64]) -> list[dict[str, Any]]:
        return [
            {"name": s.name, "faults": list(s.faults), "nrmse": float(v)}
            for s, v in zip(scenarios, values, strict=True)
        ]

    record = {
        "package_version": __version__,
        "versions": versions(),
        "created": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"),
        "seed": seed,
        "settings": {
            "optimizer": (
                "pymoo GA, real-coded: binary tournament, SBX crossover, polynomial mutation, "
                "elitist survival, duplicates eliminated; all generations run (no early stop)"
            ),
            "pop_size": pop_size,
            "generations": generations,
            "evaluations": problem.evaluations,
            "objective": "mean NRMSE over the fitting scenarios (HF noise off)",
            "nrmse": "||I_HF - I_LF|| / ||I_HF - mean(I_HF)||, both filtered",
            "filter": f"Butterworth order {FILTER_ORDER}, {CUTOFF_HZ:g} Hz, zero phase (sosfiltfilt)",
            "bounds": {k: list(v) for k, v in COEFFICIENT_BOUNDS.items()},
            "command": command_record(command),
            "params": params.to_dict(),
            "wall_time_s": round(time.perf_counter() - start, 2),
        },
        "ga_history": history,
        "fit_scenarios": table(fit, fit_nrmse),
        "check_scenarios": table(check, check_nrmse),
        "check_scenarios_noise_on": table(check, check_noisy),
        "before_calibration": {
            "coefficients": dataclasses.asdict(Coefficients()),
            "scenarios": table(tuple(fit) + tuple(check), start_nrmse),
        },
    }
    return Calibration(best, n_lf, record)
