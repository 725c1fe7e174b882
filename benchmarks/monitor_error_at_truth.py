"""Where in time the monitor at the true faults errs, against the HF twin (issue 8, item 5).

    python benchmarks/monitor_error_at_truth.py [--command chirp-2s] [--cases 12] [--window 0.25]
                                                [--case-seed 2611] [--only 0,12] [--floor]

For each of bench_multifault's random cases (its own seed 2611, noise off), per window of the
command: the RMS of (filtered HF current − filtered monitor current at the true faults) against
the RMS of the filtered HF current (mA, over the whole window), and the share of eq. 3 at the true faults that falls in
the window, over the samples the identification compares (`FaultIdentifier.prepare`: holds at
rest, parks and motion above the band left out). --floor adds the twin's own chaotic floor: the
NRMSE of the HF current against the HF with friction k1 + 1e-5.
"""

from __future__ import annotations

import argparse
import itertools

import numpy as np

from emaphm.commands import SampledCommand
from emaphm.faults import random_faults
from emaphm.identification import Comparison
from emaphm.identification.calibrate import CALIBRATION_COMMANDS
from emaphm.identification.identify import FaultIdentifier
from emaphm.models import HighFidelityEma, MonitorEma


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--command", default="chirp", choices=tuple(CALIBRATION_COMMANDS))
    parser.add_argument("--cases", type=int, default=12)
    parser.add_argument("--case-seed", type=int, default=2611)
    parser.add_argument("--window", type=float, default=0.25, help="window length [s]")
    parser.add_argument("--only", default=None, help="comma-separated case numbers")
    parser.add_argument("--floor", action="store_true", help="also HF against HF with k1 + 1e-5")
    args = parser.parse_args()
    command = CALIBRATION_COMMANDS[args.command]
    hf, monitor = HighFidelityEma(None, command), MonitorEma(None, command)
    cases = random_faults(args.cases, args.case_seed)
    only = None if args.only is None else {int(j) for j in args.only.split(",")}
    edges = np.arange(0.0, command.duration + 1e-9, args.window)
    print(
        f"command {args.command}, windows of {args.window:g} s: error / HF RMS [mA] and share of eq. 3 at the truth"
    )
    for j, k in enumerate(cases):
        if only is not None and j not in only:
            continue
        trace = hf.simulate(k, noise=False)
        whole = Comparison.from_signal(trace.t, trace.i_q, hf.params.controller.f_s)
        lf = whole.filtered(monitor.simulate(k).i_q)
        ident = FaultIdentifier(monitor=monitor).prepare(
            trace.t, trace.i_q, SampledCommand(trace.t, trace.theta_cmd), trace.theta_u
        )
        at_truth = ident.reference_.filtered(ident.monitor_.simulate(k, duration=ident.duration_).i_q)
        cost = ident.objective_.weights * (ident.reference_.reference - at_truth) ** 2
        t, tc = whole.t, ident.reference_.t
        cells = []
        for a, b in itertools.pairwise(edges):
            s = (t >= a) & (t < b)
            err = 1e3 * np.sqrt(np.mean((lf[s] - whole.reference[s]) ** 2))
            ref = 1e3 * np.sqrt(np.mean(whole.reference[s] ** 2))
            share = cost[(tc >= a) & (tc < b)].sum() / cost.sum()
            cells.append(f"{err:5.1f}/{ref:5.1f} {share:4.2f}")
        line = f"{j:>3} " + " | ".join(cells)
        if args.floor:
            k2 = k.copy()
            k2[0] += 1e-5
            line += f" | floor {100 * float(whole.nrmse(hf.simulate(k2, noise=False).i_q)):.2f} %"
        print(line, flush=True)


if __name__ == "__main__":
    main()
