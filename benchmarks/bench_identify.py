"""Identification accuracy and speed (DESIGN §9): random cases × repeats per optimiser, the Table 1
case, and the extra wall time of the default uncertainty (Laplace; issue 9 target ≤ 0.5 s).

    python benchmarks/bench_identify.py [--cases 10] [--repeats 2] [--seed 7] [--optimizers ga,de,pso,cmaes,gwo]
                                        [--table1-seeds 5] [--uq-repeats 20]

Smallest run (the smoke test): ``--cases 1 --repeats 1 --optimizers ga --table1-seeds 1
--uq-repeats 1 --pop-size 4 --generations 1 --no-polish``. Reported in BENCHMARKS.md,
"Identification: Table 1 and random cases" and "Uncertainty".

Random cases follow DESIGN §7: k1, k2 ~ U[0, 0.6], k3..k5 ~ U[0, 0.5], k6 ~ U[0, 0.3],
k7 ~ U[0, 1], k8 ~ U[0.3, 0.7], drawn from --seed. Each case is measured once on the HF twin with
noise on (noise seed = case index) and identified --repeats times (optimiser seeds 1..repeats) by
every optimiser, with the default budget and polish. Then the paper's Table 1 vector is identified
with seeds 1..--table1-seeds (one measurement, noise seed 0), as `emaphm demo` does. Prints median
and 90th percentile %err, the per-fault mean absolute error, wall time per identification and
evaluations. The paper: Table 1 %err 4.64 ± 0.34, "minutes" per run.

--uq-repeats N: the Table 1 case (noise seed 1) is identified once with GA seed 1, then
`uncertainty.laplace` on its fitted identifier is timed N times (the call `identify` makes: 33 LF
rows in one population call, the comparison filter, the sandwich): median and max, next to the
identification's own wall time.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np
from _cases import (  # benchmarks/ is the script's folder, first on sys.path
    add_settings,
    budget,
    budget_text,
    draw_cases,
    laplace,
    load_factors,
    machine_line,
)

import emaphm
from emaphm.identification import absolute_errors, percent_error


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=10)
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument("--optimizers", default="ga,de,pso,cmaes,gwo")
    parser.add_argument("--table1-seeds", type=int, default=5, help="Table 1 with seeds 1..N (0: skip)")
    parser.add_argument("--uq-repeats", type=int, default=20, help="time the Laplace step N times (0: skip)")
    add_settings(parser)
    args = parser.parse_args(argv)
    optimizers = args.optimizers.split(",")
    print(
        machine_line(
            f"{args.cases} random cases (seed {args.seed}) x {args.repeats} repeats, {budget_text(args)}"
        )
    )
    cases = draw_cases(args.cases, args.seed)
    measured = [emaphm.simulate(k, noise=True, seed=j) for j, k in enumerate(cases)]

    rows = []
    for opt in optimizers:
        errs, abs_errs, walls, evals = [], [], [], []
        for k, trace in zip(cases, measured, strict=True):
            for rep in range(1, args.repeats + 1):
                t0 = time.perf_counter()
                res = emaphm.identify(reference=trace, optimizer=opt, seed=rep, **budget(args))
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

    if args.table1_seeds:
        print(f"\nTable 1 vector, one measurement (noise seed 0), seeds 1..{args.table1_seeds}")
        trace = emaphm.simulate(emaphm.TABLE1_REFERENCE, noise=True, seed=0)
        for opt in optimizers:
            errs, walls = [], []
            for s in range(1, args.table1_seeds + 1):
                res = emaphm.identify(reference=trace, optimizer=opt, seed=s, **budget(args))
                errs.append(percent_error(res.estimate, emaphm.TABLE1_REFERENCE))
                walls.append(res.wall_time_s)
            sd = statistics.stdev(errs) if len(errs) > 1 else float("nan")
            print(f"{opt:<6} %err " + " ".join(f"{e:.2f}" for e in errs) + f"  mean {np.mean(errs):.2f} ± "
                  f"{sd:.2f}, wall {np.mean(walls):.1f} s per run")  # fmt: skip
        print("paper  %err 4.46 4.67 4.16 4.96 4.93  mean 4.64 ± 0.34, minutes per run")
    print("fault names: " + ", ".join(f"k{i + 1} {n}" for i, n in enumerate(emaphm.FAULT_NAMES)))
    if args.uq_repeats:
        uncertainty_time(args)


def uncertainty_time(args: argparse.Namespace) -> None:
    """The Laplace step's wall time on the fitted identifier of the Table 1 case (GA seed 1)."""
    trace = emaphm.HighFidelityEma().simulate(emaphm.TABLE1_REFERENCE, noise=True, seed=1)
    t0 = time.perf_counter()
    ident = emaphm.FaultIdentifier(seed=1, monitor=emaphm.MonitorEma(), **budget(args)).fit(
        trace.t, trace.i_q, emaphm.Chirp(), trace.theta_u
    )
    fit_s = time.perf_counter() - t0
    factors = load_factors()

    def once():  # type: ignore[no-untyped-def]
        return laplace(
            ident.objective_, ident.monitor_, ident.faults_, duration=ident.duration_, factors=factors
        )

    once()  # warm
    walls = []
    for _ in range(args.uq_repeats):
        t0 = time.perf_counter()
        res = once()
        walls.append(time.perf_counter() - t0)
    print(f"\nidentification of the Table 1 case (search + polish + checks): {fit_s:.2f} s")
    print(f"Laplace uncertainty, {args.uq_repeats} repeats: median {1000 * statistics.median(walls):.1f} ms, "
          f"max {1000 * max(walls):.1f} ms ({res.evaluations} LF runs); "
          f"{100 * statistics.median(walls) / fit_s:.1f} % of the identification")  # fmt: skip
    print("half-widths:", np.round(res.half_width(), 4).tolist())


if __name__ == "__main__":
    main()
