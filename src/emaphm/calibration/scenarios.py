"""The scenarios the monitor is calibrated and checked on, and the two runs that score them.

A `Scenario` is a named fault vector the HF twin is run with under one of the calibration's
commands (`CALIBRATION_COMMANDS`). The default monitor is fitted on `FIT_SCENARIOS` and checked
on `CHECK_SCENARIOS`; the paper's monitor on `PAPER_FIT_SCENARIOS` / `PAPER_CHECK_SCENARIOS`
(paper §4.2, DESIGN §4.4). `hf_references` runs the HF twin on them (the filtered i_q), and
`scenario_nrmse` the LF model with candidate coefficients, one population-kernel call per command.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..callbacks import Progress
from ..commands import Chirp, ChirpHold, Command, Steps
from ..faults import HEALTHY, as_fault_vector, random_faults
from ..identification.signals import Comparison
from ..kernels.monitor import simulate_lf_many
from ..models import HighFidelityEma
from ..models.lf import monitor_rows
from ..params import EmaParams
from .coefficients import Coefficients

__all__ = [
    "CALIBRATION_COMMANDS",
    "CHECK_SCENARIOS",
    "FIT_SCENARIOS",
    "PAPER_CHECK_SCENARIOS",
    "PAPER_FIT_SCENARIOS",
    "Progress",
    "Scenario",
    "hf_references",
    "scenario_nrmse",
]


# The commands the monitor is calibrated over (issue 8, item 5): the FDI chirp of DESIGN §6; the
# chirp run on for a second (what `emaphm simulate --duration 2` records: it sweeps on to 19.5 Hz);
# the chirp followed by a hold; a staircase of steps. A trace whose command is none of these is
# still identified, with a warning (`coverage.command_warnings`).
CALIBRATION_COMMANDS: dict[str, Command] = {
    "chirp": Chirp(),
    "chirp-2s": Chirp(T=2.0, f1=19.5),
    "chirp-hold": ChirpHold(),
    "steps": Steps(),
}


@dataclass(frozen=True)
class Scenario:
    """A named fault vector the HF twin is run with, under the command named `command` (a key of
    the `commands` given to `calibrate`, `CALIBRATION_COMMANDS` by default).

    name : str  the scenario's name in the calibration record
    faults : tuple of 8 floats in [0, 1]  the fault vector k1..k8
    command : str  the name of its command
    """

    name: str
    faults: tuple[float, ...]
    command: str = "chirp"

    def __post_init__(self) -> None:
        as_fault_vector(self.faults, name=f"scenario {self.name!r}")


def _k(**changes: float) -> tuple[float, ...]:
    k = list(HEALTHY)
    for name, value in changes.items():
        k[int(name[1:]) - 1] = value
    return tuple(k)


def _random(n: int, seed: int, command: str) -> tuple[Scenario, ...]:
    return tuple(
        Scenario(f"{command} random {seed}/{j}", tuple(float(v) for v in k), command)
        for j, k in enumerate(random_faults(n, seed))
    )


def _sparse(n: int, seed: int, command: str) -> tuple[Scenario, ...]:
    """Random actuators whose shorts sit in one or two phases only (the others healthy).

    A coil short is local: a real actuator more often has one shorted phase than three. The
    DESIGN §7 draw (`_random`) shorts all three phases at once; these cases keep the loop
    surrogate honest for the unbalanced ones (the paper's Table 1 case is one).
    """
    rng = np.random.default_rng(seed)
    out = []
    for j, k in enumerate(random_faults(n, seed)):
        k = k.copy()
        keep = rng.choice(3, size=int(rng.integers(1, 3)), replace=False)
        k[[2 + x for x in range(3) if x not in keep]] = 0.0
        out.append(Scenario(f"{command} sparse {seed}/{j}", tuple(float(v) for v in k), command))
    return tuple(out)


# DESIGN §4.4 / the paper: healthy, a short in each phase, eccentricity at two phases, a combined case
PAPER_FIT_SCENARIOS: tuple[Scenario, ...] = (
    Scenario("healthy", _k()),
    Scenario("short A k3=0.3", _k(k3=0.3)),
    Scenario("short B k4=0.3", _k(k4=0.3)),
    Scenario("short C k5=0.3", _k(k5=0.3)),
    Scenario("eccentricity k6=0.3 phase 0", _k(k6=0.3, k7=0.0)),
    Scenario("eccentricity k6=0.3 phase 0.4", _k(k6=0.3, k7=0.4)),
    Scenario("combined", _k(k1=0.3, k2=0.2, k4=0.2, k6=0.1, k7=0.6, k8=0.4)),
)
# The default monitor's fitting set (issue 8, item 1): the paper's scenarios, random multi-fault
# actuators in the DESIGN §7 ranges (the loop surrogate fitted on single shorts alone extrapolated
# badly to two or three), random ones with one or two shorted phases, and a staircase of steps
# (the only command that reaches the voltage limit: it pins k_e,eq, which the chirp leaves free).
# The chirp run on to 2 s and the chirp with a hold are checked, not fitted: their stick-slip
# makes the HF itself chaotic (HF against HF with k1 + 1e-5: 1.7-4.4 % NRMSE), and fitted they
# pulled the coefficients after that noise (monitor-model.md §3). The seeds (3101..3105; checks
# 3201..3205) are this set's own: no benchmark draws from them.
FIT_SCENARIOS: tuple[Scenario, ...] = (
    PAPER_FIT_SCENARIOS
    + _random(9, 3101, "chirp")
    + _sparse(8, 3105, "chirp")
    + (Scenario("steps healthy", _k(), "steps"),)
    + _random(5, 3104, "steps")
)
# not used for fitting: other magnitudes, phases, the mechanical faults, the gain, the paper's case
PAPER_CHECK_SCENARIOS: tuple[Scenario, ...] = (
    Scenario("friction k1=0.5", _k(k1=0.5)),
    Scenario("backlash k2=0.4", _k(k2=0.4)),
    Scenario("gain k8=0.25", _k(k8=0.25)),
    Scenario("short B k4=0.45 + friction k1=0.2", _k(k1=0.2, k4=0.45)),
    Scenario("eccentricity k6=0.2 phase 0.75", _k(k6=0.2, k7=0.75)),
    Scenario("shorts A+C k3=0.15 k5=0.25", _k(k3=0.15, k5=0.25)),
    Scenario("paper Table 1 reference", (0.2383, 0.5003, 5.32e-7, 0.4503, 0.0404, 0.0028, 0.2785, 0.5)),
    Scenario("random mix", (0.41, 0.18, 0.07, 0.22, 0.31, 0.12, 0.83, 0.62)),
)
CHECK_SCENARIOS: tuple[Scenario, ...] = (
    PAPER_CHECK_SCENARIOS
    + _random(6, 3201, "chirp")
    + _sparse(4, 3205, "chirp")
    + tuple(
        Scenario(f"{c} paper Table 1 reference", PAPER_CHECK_SCENARIOS[6].faults, c)
        for c in ("chirp-2s", "chirp-hold", "steps")
    )
    + _random(3, 3202, "chirp-2s")
    + _random(3, 3203, "chirp-hold")
    + _random(3, 3204, "steps")
)


def hf_references(
    scenarios: Sequence[Scenario],
    params: EmaParams,
    *,
    noise: bool,
    seed: int,
    progress: Progress | None = None,
    commands: Mapping[str, Command] = CALIBRATION_COMMANDS,
) -> list[Comparison]:
    """Filtered HF i_q of each scenario on the sample grid of its command (the runs of one
    command side by side, `HighFidelityEma.simulate_batch`).

    Parameters
    ----------
    scenarios : sequence of Scenario
        The fault vectors and the commands they run under.
    params : EmaParams
        The actuator.
    noise : bool
        Add the seeded measurement noise.
    seed : int
        Seed of the noise.
    progress : callable, optional
        ``progress(stage, done, total)`` after each command's batch.
    commands : mapping of str to Command
        The commands the scenarios name (`CALIBRATION_COMMANDS` by default).
    """
    out: dict[int, Comparison] = {}
    for command in dict.fromkeys(sc.command for sc in scenarios):
        js = [j for j, sc in enumerate(scenarios) if sc.command == command]
        runs = HighFidelityEma(params, commands[command]).simulate_batch(
            [scenarios[j].faults for j in js], noise=noise, seeds=[seed] * len(js)
        )
        out.update(
            {
                j: Comparison.from_signal(r.t, r.i_q, params.controller.f_s)
                for j, r in zip(js, runs, strict=True)
            }
        )
        if progress:
            progress(f"HF scenarios ({'noise on' if noise else 'noise off'})", len(out), len(scenarios))
    return [out[j] for j in range(len(scenarios))]


def scenario_nrmse(
    coefficients: Sequence[Coefficients],
    scenarios: Sequence[Scenario],
    references: Sequence[Comparison],
    params: EmaParams,
    n_lf: int,
    commands: Mapping[str, Command] = CALIBRATION_COMMANDS,
    monitor: str = "default",
) -> NDArray[np.float64]:
    """NRMSE of the LF model per (coefficient set, scenario): shape (len(coefficients), len(scenarios)).

    The runs of one command are rows of one population-kernel call; `monitor` sets the
    structure (`models.monitor_rows`).

    Parameters
    ----------
    coefficients : sequence of Coefficients
        The coefficient sets to score.
    scenarios : sequence of Scenario
        The fault vectors and their commands.
    references : sequence of Comparison
        The filtered HF i_q of each scenario (`hf_references`).
    params : EmaParams
        The actuator.
    n_lf : int
        LF steps per sample period.
    commands : mapping of str to Command
        The commands the scenarios name (`CALIBRATION_COMMANDS` by default).
    monitor : {"default", "paper"}
        The monitor model's structure.
    """
    n_c = len(coefficients)
    out = np.empty((n_c, len(scenarios)))
    for command in dict.fromkeys(sc.command for sc in scenarios):
        which = [j for j, sc in enumerate(scenarios) if sc.command == command]
        _, theta_cmd = HighFidelityEma(params, commands[command]).sample_grid()
        K = np.array([scenarios[j].faults for j in which])
        n_s = len(which)
        rows = monitor_rows(
            np.tile(K, (n_c, 1)), params, [c for c in coefficients for _ in range(n_s)], n_lf, monitor
        )
        currents = np.empty((rows.shape[0], len(theta_cmd)))
        simulate_lf_many(theta_cmd, rows, currents)
        by_case = currents.reshape(n_c, n_s, -1)
        for s, j in enumerate(which):
            out[:, j] = references[j].nrmse(by_case[:, s, :])
    return out
