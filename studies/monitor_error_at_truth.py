# Study, not a benchmark: moved from benchmarks/ at dae85bf (last changed at 7645bb6); rerun it at that
# commit to reproduce its figures: HISTORY.md (multi-fault sections, --by-frequency: ERROR_CORNER_HZ 2.38
# Hz); docs/theory/monitor-model.md, docs/identification.md.
"""Where in time the monitor at the true faults errs, against the HF twin (issue 8, item 5).

    python studies/monitor_error_at_truth.py [--command chirp-2s] [--cases 12] [--window 0.25]
                                                [--case-seed 2611] [--only 0,12] [--floor] [--angle]
    python studies/monitor_error_at_truth.py --by-frequency
    python studies/monitor_error_at_truth.py --command steps --cases 20 --rest-share


For each of bench_multifault's random cases (its own seed 2611, noise off), per window of the
command: the RMS of (filtered HF current − filtered monitor current at the true faults) against
the RMS of the filtered HF current (mA, over the whole window), and the share of eq. 3 at the true faults that falls in
the window, over the samples the identification compares (`FaultIdentifier.prepare`: holds at
rest, parks and motion above the band left out); at the end of each line eq. 3 at the truth in
all [1e-3 A²], with its sum, median and max over the cases. --floor adds the twin's own chaotic
floor: the NRMSE of the HF current against the HF with friction k1 + 1e-5. --angle adds to each
window the largest gap between the twin's and the monitor's motor (|Δθ_e|, electrical rad) and
between their surfaces, in the same unit (p·τ·|Δθ_u|): a motor gap far above the surface's is
the motor's angle inside the backlash, which the position sensor does not see (monitor-model.md §4).

--rest-share prints per case, instead of the windows, eq. 3 at the true faults over the samples
compared without the rests whose measured current is below the monitor's ring edge
(`fitness.moving_mask` with `rest_current` 0) and the share of it that those rests hold.

--by-frequency measures where `fitness.ERROR_CORNER_HZ` comes from: on the calibration's fitting
scenarios under the FDI chirp (`calibrate.FIT_SCENARIOS`, none of the benchmark's cases), the RMS
of the monitor's error at the true faults (noise off, filtered) per band of the command's local
frequency (`fitness.command_frequency`), and the corner f_c of σ²(f) = σ0²·(1 + (f/f_c)²) fitted
to it (least squares on the variances relative to each, so each band counts alike).
"""

from __future__ import annotations

import argparse
import itertools

import numpy as np

from emaphm.calibration.scenarios import CALIBRATION_COMMANDS, FIT_SCENARIOS
from emaphm.commands import SampledCommand
from emaphm.faults import random_faults
from emaphm.identification import Comparison
from emaphm.identification.fitness import Fitness
from emaphm.identification.identifier import FaultIdentifier
from emaphm.identification.weights import (
    ERROR_CORNER_HZ,
    band_mask,
    command_frequency,
    error_weights,
    moving_mask,
)
from emaphm.models import HighFidelityEma, MonitorEma


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--command", default="chirp", choices=tuple(CALIBRATION_COMMANDS))
    parser.add_argument("--cases", type=int, default=12)
    parser.add_argument("--case-seed", type=int, default=2611)
    parser.add_argument("--window", type=float, default=0.25, help="window length [s]")
    parser.add_argument("--only", default=None, help="comma-separated case numbers")
    parser.add_argument("--floor", action="store_true", help="also HF against HF with k1 + 1e-5")
    parser.add_argument("--angle", action="store_true", help="also the motors' and surfaces' gaps")
    parser.add_argument(
        "--rest-share",
        action="store_true",
        help="the share of eq. 3 at the truth in the rests below the ring edge",
    )
    parser.add_argument(
        "--by-frequency",
        action="store_true",
        help="the error per frequency band on the calibration's scenarios",
    )
    args = parser.parse_args()
    if args.by_frequency:
        by_frequency()
        return
    command = CALIBRATION_COMMANDS[args.command]
    hf, monitor = HighFidelityEma(None, command), MonitorEma(None, command)
    cases = random_faults(args.cases, args.case_seed)
    only = None if args.only is None else {int(j) for j in args.only.split(",")}
    edges = np.arange(0.0, command.duration + 1e-9, args.window)
    per_rad = hf.params.motor.p * hf.params.transmission.tau  # electrical rad per rad of the surface
    print(
        f"command {args.command}, windows of {args.window:g} s: error / HF RMS [mA] and share of eq. 3 at the truth"
        + (", then the motors' / surfaces' largest gap [electrical rad]" if args.angle else "")
    )
    totals: list = []  # eq. 3 per case, or (eq. 3, share) with --rest-share
    for j, k in enumerate(cases):
        if only is not None and j not in only:
            continue
        trace = hf.simulate(k, noise=False)
        whole = Comparison.from_signal(trace.t, trace.i_q, hf.params.controller.f_s)
        lf_trace = monitor.simulate(k)
        lf = whole.filtered(lf_trace.i_q)
        if args.angle:
            gap_e = np.abs(trace.theta_e - lf_trace.theta_e)
            gap_u = per_rad * np.abs(trace.theta_u_true - lf_trace.theta_u_true)
        ident = FaultIdentifier(monitor=monitor).prepare(
            trace.t, trace.i_q, SampledCommand(trace.t, trace.theta_cmd), trace.theta_u
        )
        at_truth = ident.reference_.filtered(ident.monitor_.simulate(k, duration=ident.duration_).i_q)
        cost = ident.objective_.weights * (ident.reference_.reference - at_truth) ** 2
        if args.rest_share:
            totals.append(rest_share(ident, k, trace))
            print(
                f"{j:>3} eq. 3 without the rule {1e3 * totals[-1][0]:7.2f}, in those rests {totals[-1][1]:4.2f}"
            )
            continue
        t, tc = whole.t, ident.reference_.t
        cells = []
        for a, b in itertools.pairwise(edges):
            s = (t >= a) & (t < b)
            err = 1e3 * np.sqrt(np.mean((lf[s] - whole.reference[s]) ** 2))
            ref = 1e3 * np.sqrt(np.mean(whole.reference[s] ** 2))
            share = cost[(tc >= a) & (tc < b)].sum() / cost.sum()
            cells.append(f"{err:5.1f}/{ref:5.1f} {share:4.2f}")
            if args.angle:
                w = (trace.t >= a) & (trace.t < b)
                cells[-1] += f" {gap_e[w].max():4.2f}/{gap_u[w].max():4.2f}"
        totals.append(float(cost.sum()))
        line = f"{j:>3} " + " | ".join(cells) + f" | eq. 3 {1e3 * totals[-1]:7.2f}"
        if args.floor:
            k2 = k.copy()
            k2[0] += 1e-5
            line += f" | floor {100 * float(whole.nrmse(hf.simulate(k2, noise=False).i_q)):.2f} %"
        print(line, flush=True)
    if args.rest_share and totals:
        shares = [share for _, share in totals]
        print(f"share of eq. 3 at the truth in the rests below the ring edge over {len(shares)} cases: "
              f"median {float(np.median(shares)):.2f}, max {max(shares):.2f}")  # fmt: skip
    elif totals:
        print(f"eq. 3 at the truth [1e-3 A^2] over {len(totals)} cases: sum {1e3 * sum(totals):.1f}, "
              f"median {1e3 * float(np.median(totals)):.2f}, max {1e3 * max(totals):.2f}")  # fmt: skip


def rest_share(ident: FaultIdentifier, k: np.ndarray, trace: object) -> tuple[float, float]:
    """Eq. 3 at the truth k without the rule for the rests below the ring edge, and the share of
    it those rests hold (the samples `ident.mask_` leaves out and the rule before it kept)."""
    # over the whole recording: the rule may end the compared span earlier (a final rest)
    monitor, f_s = ident.monitor_, ident.monitor_.params.controller.f_s
    whole = ident.whole_ if ident.whole_ is not None else ident.reference_
    grid, theta = monitor.sample_grid(float(whole.t[-1] - whole.t[0]))
    position = np.interp(grid, trace.t - trace.t[0], trace.theta_u)  # type: ignore[attr-defined]
    before = moving_mask(theta, f_s, theta_u=position) * band_mask(theta, f_s)
    after = np.zeros_like(before)
    after[: len(ident.mask_)] = ident.mask_
    fitness = Fitness(whole, ident.settings.slope_unit, before, error_weights(theta, f_s, ident.error_corner_hz_))
    at_truth = whole.filtered(monitor.simulate(k, duration=float(grid[-1] - grid[0])).i_q)
    cost = fitness.weights * (whole.reference - at_truth) ** 2
    gone = (before > 0) & (after == 0)
    return float(cost.sum()), float(cost[gone].sum() / cost.sum())


def by_frequency() -> None:
    from scipy.optimize import curve_fit

    command = CALIBRATION_COMMANDS["chirp"]
    hf, monitor = HighFidelityEma(None, command), MonitorEma(None, command)
    f_s = hf.params.controller.f_s
    edges = np.array([0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0 + 1e-9])
    sq, ref_sq, n = np.zeros(len(edges) - 1), np.zeros(len(edges) - 1), np.zeros(len(edges) - 1)
    scenarios = [sc for sc in FIT_SCENARIOS if sc.command == "chirp"]
    for sc in scenarios:
        k = np.asarray(sc.faults)
        trace = hf.simulate(k, noise=False)
        whole = Comparison.from_signal(trace.t, trace.i_q, f_s)
        error = whole.reference - whole.filtered(monitor.simulate(k).i_q)
        f = command_frequency(monitor.sample_grid()[1], f_s)[: len(error)]
        band = np.digitize(f, edges) - 1
        np.add.at(sq, band, error**2)
        np.add.at(ref_sq, band, whole.reference**2)
        np.add.at(n, band, 1.0)
    print(
        f"the monitor at the true faults, {len(scenarios)} fitting scenarios of the calibration, FDI chirp, noise off"
    )
    print(f"{'band [Hz]':>10} {'samples':>8} {'error RMS [mA]':>15} {'HF RMS [mA]':>12}")
    used = n > 0
    for a, b, m, e, r in zip(edges[:-1], edges[1:], n, sq, ref_sq, strict=True):
        if m:
            print(
                f"{a:4.0f}-{b:<5.0f} {int(m):>8} {1e3 * np.sqrt(e / m):>15.1f} {1e3 * np.sqrt(r / m):>12.1f}"
            )
    f_mid = 0.5 * (edges[:-1] + edges[1:])[used]
    var = (sq / np.maximum(n, 1))[used]
    (s0, corner), _ = curve_fit(
        lambda f, a, c: a * (1 + (f / c) ** 2), f_mid, var, p0=(var[0], 3.0), sigma=var
    )
    print(f"sigma^2(f) = s0^2 (1 + (f/f_c)^2): s0 {1e3 * np.sqrt(s0):.1f} mA, f_c {corner:.2f} Hz "
          f"(fitness.ERROR_CORNER_HZ = {ERROR_CORNER_HZ:g})")  # fmt: skip


if __name__ == "__main__":
    main()
