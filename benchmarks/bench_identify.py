"""Identification accuracy and speed (DESIGN §9): random cases × repeats per optimiser, and Table 1.

    python benchmarks/bench_identify.py [--cases 10] [--repeats 2] [--seed 7] [--optimizers ga,de,pso,cmaes,gwo]

Random cases follow DESIGN §7: k1, k2 ~ U[0, 0.6], k3..k5 ~ U[0, 0.5], k6 ~ U[0, 0.3],
k7 ~ U[0, 1], k8 ~ U[0.3, 0.7], drawn from --seed. Each case is measured once on the HF twin with
noise on (noise seed = case index) and identified --repeats times (optimiser seeds 1..repeats) by
every optimiser, with the default budget and polish. Then the paper's Table 1 vector is identified
with seeds 1..5 (one measurement, noise seed 0), as `emaphm demo` does. Prints median and 90th
percentile %err, the per-fault mean absolute error, wall time per identification and evaluations.
The paper: Table 1 %err 4.64 ± 0.34, "minutes" per run.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time

import numpy as np

import emaphm
from emaphm.faults import FAULT_NAMES, TABLE1_REFERENCE, random_faults
from emaphm.identification.identify import identify
from emaphm.identification.metrics import absolute_errors, percent_error


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=10)
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument("--optimizers", default="ga,de,pso,cmaes,gwo")
    args = parser.parse_args()
    optimizers = args.optimizers.split(",")
    print(f"emaphm {emaphm.__version__}, Python {platform.python_version()}, {os.cpu_count()} cores; "
          f"{args.cases} random cases (seed {args.seed}) x {args.repeats} repeats")  # fmt: skip
    cases = random_faults(args.cases, args.seed)
    measured = [emaphm.simulate(k, noise=True, seed=j) for j, k in enumerate(cases)]

    rows = []
    for opt in optimizers:
        errs, abs_errs, walls, evals = [], [], [], []
        for k, trace in zip(cases, measured, strict=True):
            for rep in range(1, args.repeats + 1):
                t0 = time.perf_counter()
                res = identify(reference=trace, optimizer=opt, seed=rep)
                walls.append(time.perf_counter() - t0)
                errs.append(percent_error(res.estimate, k))
                abs_errs.append(absolute_errors(res.estimate, k))
                evals.append(res.evaluations)
        mae = np.mean(abs_errs, axis=0)
        rows.append(
            (opt, np.median(errs), np.percentile(errs, 90), max(errs), mae, np.median(walls), np.mean(evals))
        )
        print(f"  {opt}: median {np.median(errs):.2f}, p90 {np.percentile(errs, 90):.2f}, max {max(errs):.2f} %err, "
              f"{np.median(walls):.1f} s", flush=True)  # fmt: skip

    print("\nrandom cases (DESIGN §7 ranges), %err and per-fault mean absolute error")
    header = f"{'opt':<6} {'median':>7} {'p90':>6} {'max':>6} " + " ".join(
        f"{'k' + str(i + 1):>6}" for i in range(8)
    )
    print(header + f" {'wall s':>7} {'evals':>6}")
    for opt, med, p90, mx, mae, wall, ev in rows:
        print(
            f"{opt:<6} {med:>7.2f} {p90:>6.2f} {mx:>6.2f} "
            + " ".join(f"{v:>6.3f}" for v in mae)
            + f" {wall:>7.1f} {ev:>6.0f}"
        )

    print("\nTable 1 vector, one measurement (noise seed 0), seeds 1..5")
    trace = emaphm.simulate(TABLE1_REFERENCE, noise=True, seed=0)
    for opt in optimizers:
        errs, walls = [], []
        for s in range(1, 6):
            res = identify(reference=trace, optimizer=opt, seed=s)
            errs.append(percent_error(res.estimate, TABLE1_REFERENCE))
            walls.append(res.wall_time_s)
        print(f"{opt:<6} %err " + " ".join(f"{e:.2f}" for e in errs) + f"  mean {np.mean(errs):.2f} ± "
              f"{statistics.stdev(errs):.2f}, wall {np.mean(walls):.1f} s per run")  # fmt: skip
    print("paper  %err 4.46 4.67 4.16 4.96 4.93  mean 4.64 ± 0.34, minutes per run")
    print("fault names: " + ", ".join(f"k{i + 1} {n}" for i, n in enumerate(FAULT_NAMES)))


if __name__ == "__main__":
    main()
