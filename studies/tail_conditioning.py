# Study, not a benchmark: moved from benchmarks/ at dae85bf (last changed at 45be1cf); rerun it at that
# commit to reproduce its figures: HISTORY.md §"How small a torque error ...", §"The switching last stage",
# results/tail-conditioning-*.txt; docs/theory/monitor-model.md §4-5.
"""How much a small torque error costs each actuator: the conditioning behind the NRMSE tail (issue 8).

    python studies/tail_conditioning.py [--cases 1000] [--case-seed 9002] [--command chirp]
                                           [--psi 0.01] [--top 10]
    python studies/tail_conditioning.py --standstill 300
    python studies/tail_conditioning.py --step 2e-6
    python studies/tail_conditioning.py --switching

The monitor's NRMSE at the true faults has a tail (monitor-model.md §4): a few actuators in a
thousand reach 5-8 % where the median is under 2 %. This script asks whether those actuators are
the ones where *any* model with a small torque error must err: it runs the HF twin against
itself with the magnet flux linkage ψ_m changed by ±psi (a torque constant and back-EMF off by
that fraction, nothing else; noise off), and compares, case by case, that sensitivity with the
monitor's NRMSE at the truth (the packaged monitor, as `monitor_fidelity.py`).

Printed: median / p90 / p99 / max of each NRMSE over the cases; the sensitivity (the larger of
the +psi and −psi NRMSE) of the monitor's cases above 4 % against the sensitivity's own
distribution (its rank); the Spearman rank correlation of the two over all cases; and the --top
cases by the monitor's NRMSE with their sensitivity. A monitor error that tracks the twin's own
sensitivity is conditioning (the actuator amplifies a torque error), not a missing term.

--standstill N looks instead at the twin's current while its motor is stuck (the first N cases,
noise off): over each 2 ms in which ω_m = 0 throughout and |i_q,ref| > 0.12 A (beyond the loop's
ring at standstill, `monitor.RING_OUTER`·i_D), the mean of i_q − i_q,ref signed against the
demand (negative: the loop delivers less than asked). The monitor carries a constant shortfall
there (its loop surrogate's δ_H + δ_2·c₂, `monitor.loop_error`). Printed: its spread, and how much
of that spread a least-squares fit on what an averaged model could know at that instant (the
turns lost per phase, the phase directions of the demand and their products, the 6θ_e position on
the band's hexagon) explains. What no such fit explains is the loop's history (its legs'
switching state), which no averaged monitor carries.

--step DT compares instead the twin run at another integration step DT (its default 1 µs) with
itself: a *switching* monitor, the twin's own structure discretised differently, against the
averaged one (issue 8's "multi-fidelity" option, monitor-model.md §5). --switching compares the
switching model the identification's last stage fits with (`switching.SwitchingModel`: the mean
of the twin's runs at `switching.SWITCHING_STEPS`).
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))  # the shared helpers
from _machine import cpu_model
from scipy.stats import spearmanr

import emaphm
from emaphm.calibration.scenarios import CALIBRATION_COMMANDS
from emaphm.commands import Command
from emaphm.faults import random_faults
from emaphm.identification import Comparison
from emaphm.identification.last_stage import SwitchingModel
from emaphm.kernels.transforms import phase_directions
from emaphm.models import HighFidelityEma, MonitorEma
from emaphm.params import EmaParams

SWITCHING_STEPS = (2e-6, 2.5e-6, 1.25e-6)  # the paper actuator's (last_stage.switching_steps)


def _stats(v: np.ndarray) -> str:
    return (
        f"{np.median(v):5.2f} / {np.percentile(v, 90):5.2f} / {np.percentile(v, 99):5.2f} / {v.max():5.2f} %"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=1000)
    parser.add_argument("--case-seed", type=int, default=9002)
    parser.add_argument("--command", default="chirp", choices=tuple(CALIBRATION_COMMANDS))
    parser.add_argument("--psi", type=float, default=0.01, help="relative change of ψ_m (0.01: 1 %%)")
    parser.add_argument("--top", type=int, default=10, help="cases listed, by the monitor's NRMSE")
    parser.add_argument(
        "--standstill", type=int, default=0, help="N: the stuck-motor shortfall on N cases instead"
    )
    parser.add_argument(
        "--step", type=float, default=0.0, help="DT [s]: the twin at step DT against itself instead"
    )
    parser.add_argument(
        "--switching", action="store_true", help="the last stage's switching model against the twin instead"
    )
    args = parser.parse_args()
    if args.standstill:
        standstill(args)
        return
    if args.step or args.switching:
        other_step(args)
        return
    print(f"emaphm {emaphm.__version__}, Python {platform.python_version()}, {os.cpu_count()} cores "
          f"({cpu_model()}); {args.cases} cases (seed {args.case_seed}), command {args.command}, "
          f"HF noise off, ψ_m × (1 ± {args.psi:g})")  # fmt: skip
    start = time.perf_counter()
    base = EmaParams()
    cases, command, refs, lf = _at_the_truth(args, base)
    sens = []
    for sign in (1.0, -1.0):
        motor = dataclasses.replace(base.motor, psi_m=base.motor.psi_m * (1.0 + sign * args.psi))
        twin = HighFidelityEma(dataclasses.replace(base, motor=motor), command=command)
        sens.append(
            [100 * ref.nrmse(twin.simulate(k, noise=False).i_q) for ref, k in zip(refs, cases, strict=True)]
        )
    plus, minus = np.array(sens)
    worst = np.maximum(plus, minus)
    print(f"{'NRMSE against the twin, median / p90 / p99 / max':<52}")
    for label, v in (("monitor at the true faults", lf), (f"twin with ψ_m × (1 + {args.psi:g})", plus),
                     (f"twin with ψ_m × (1 − {args.psi:g})", minus)):  # fmt: skip
        print(f"  {label + ':':<36} {_stats(v)}   above 4 %: {int(np.sum(v > 4.0))}")
    rank = np.argsort(np.argsort(-worst))  # 0: the most sensitive case
    tail = np.flatnonzero(lf > 4.0)
    if tail.size:
        print(f"the monitor's cases above 4 % ({tail.size}): sensitivity median {np.median(worst[tail]):.2f} % "
              f"against {np.median(worst):.2f} % over all; their ranks among {args.cases} by sensitivity "
              f"(0: most sensitive): {sorted(int(r) for r in rank[tail])}")  # fmt: skip
    rho = spearmanr(lf, worst).statistic
    print(f"Spearman rank correlation, monitor NRMSE vs sensitivity, all cases: {rho:.2f}")
    print(f"{'case':>5} {'monitor':>8} {'+psi':>7} {'-psi':>7} {'rank':>5}   faults k1..k8")
    for j in np.argsort(-lf)[: args.top]:
        print(f"{j:>5} {lf[j]:>7.2f}% {plus[j]:>6.2f}% {minus[j]:>6.2f}% {rank[j]:>5}   "
              + " ".join(f"{x:.2f}" for x in cases[j]))  # fmt: skip
    print(f"({time.perf_counter() - start:.0f} s)")


def _at_the_truth(
    args: argparse.Namespace, base: EmaParams
) -> tuple[np.ndarray, Command, list[Comparison], np.ndarray]:
    """The cases, their command, the twin's filtered currents (noise off) and the monitor's NRMSE at the truth [%]."""
    cases = random_faults(args.cases, args.case_seed)
    command = CALIBRATION_COMMANDS[args.command]
    hf = HighFidelityEma(base, command=command)
    refs = [Comparison.from_signal(r.t, r.i_q, hf.params.controller.f_s)
            for r in (hf.simulate(k, noise=False) for k in cases)]  # fmt: skip
    currents = MonitorEma(command=command).simulate_many(cases)
    lf = 100 * np.array([ref.nrmse(i) for ref, i in zip(refs, currents, strict=True)])
    return cases, command, refs, lf


def other_step(args: argparse.Namespace) -> None:
    """The twin at integration step `args.step` against the twin at its own, and the monitor beside it."""
    base = EmaParams()
    steps = SWITCHING_STEPS if args.switching else (args.step,)
    name = f"the switching model (mean of the twin at {', '.join(f'{s:g}' for s in steps)} s)"
    print(f"emaphm {emaphm.__version__}, Python {platform.python_version()}, {os.cpu_count()} cores "
          f"({cpu_model()}); {args.cases} cases (seed {args.case_seed}), command {args.command}, "
          f"HF noise off; {name} against the twin at {base.integration.dt:g} s")  # fmt: skip
    start = time.perf_counter()
    cases, command, refs, lf = _at_the_truth(args, base)
    other = SwitchingModel(base, command, steps)
    t0 = time.perf_counter()
    sw = 100 * np.array(
        [ref.nrmse(other.current(k, duration=command.duration)) for ref, k in zip(refs, cases, strict=True)]
    )
    per_run = (time.perf_counter() - t0) / len(cases)
    for label, v in (("monitor at the true faults", lf), (name, sw)):
        print(f"  {label + ':':<36} {_stats(v)}   above 4 %: {int(np.sum(v > 4.0))}")
    print(f"{name}: {1e3 * per_run:.1f} ms per evaluation, one thread")
    print(f"{'case':>5} {'monitor':>8} {'step':>7}   faults k1..k8")
    for j in np.argsort(-lf)[: args.top]:
        print(f"{j:>5} {lf[j]:>7.2f}% {sw[j]:>6.2f}%   " + " ".join(f"{x:.2f}" for x in cases[j]))
    print(f"({time.perf_counter() - start:.0f} s)")


def standstill(args: argparse.Namespace) -> None:
    """The twin's current shortfall while its motor is stuck, and what an averaged model could explain of it."""
    print(f"emaphm {emaphm.__version__}, Python {platform.python_version()}, {os.cpu_count()} cores "
          f"({cpu_model()}); {args.standstill} cases (seed {args.case_seed}), command {args.command}, "
          "HF noise off; windows of 2 ms stuck throughout, |i_q,ref| > 0.12 A")  # fmt: skip
    start = time.perf_counter()
    hf = HighFidelityEma(command=CALIBRATION_COMMANDS[args.command])
    window = round(2e-3 * hf.params.controller.f_s)
    rows = []
    for j, k in enumerate(random_faults(args.standstill, args.case_seed)):
        r = hf.simulate(k, noise=False)
        for a in range(0, len(r.t) - window, window):
            s = slice(a, a + window)
            demand = float(np.mean(r.i_q_ref[s]))
            if np.all(r.omega_m[s] == 0.0) and abs(demand) > 0.12:
                u = np.sign(demand) * np.array(phase_directions(np.sin(r.theta_e[a]), np.cos(r.theta_e[a])))
                N = 1.0 - np.clip(k[2:5], 0.0, 0.95)  # the turn fractions N_x, clamped as the twin does
                lost = 1.0 - N
                six = 6.0 * r.theta_e[a]
                features = [*lost, *(lost * u * u), *(lost * u), np.cos(six), np.sin(six),
                            N[np.argmax(u)], N[np.argmin(u)]]  # fmt: skip
                rows.append((j, np.sign(demand) * float(np.mean(r.i_q[s] - r.i_q_ref[s])), *features))
    data = np.array(rows)
    shortfall, X = 1e3 * data[:, 1], data[:, 2:]
    print(f"{len(data)} windows from {len(set(data[:, 0]))} cases: i_q − i_q,ref against the demand "
          f"median {np.median(shortfall):.1f} mA, p10 {np.percentile(shortfall, 10):.1f}, "
          f"p90 {np.percentile(shortfall, 90):.1f}, std {shortfall.std():.1f} mA")  # fmt: skip
    for name, cols in (("turns lost per phase (3)", slice(0, 3)), ("all 13 features", slice(0, 13))):
        A = np.column_stack([np.ones(len(data)), X[:, cols]])
        coef, *_ = np.linalg.lstsq(A, shortfall, rcond=None)
        print(
            f"  left after a least-squares fit on a constant + {name}: {np.std(shortfall - A @ coef):.1f} mA"
        )
    print(f"({time.perf_counter() - start:.0f} s)")


if __name__ == "__main__":
    main()
