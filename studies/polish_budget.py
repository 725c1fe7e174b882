"""Issue 36: what each part of the polish stage gives after the start table's search.

    python studies/polish_budget.py [--case-seeds 7,6061] [--cases 40] [--seed 1]

Each case (`bench_multifault.py`'s numbering, one optimiser seed) is measured as ``emaphm
identify --true-faults K --seed S`` measures it; the global search runs once from the default
start (the start table for the chirp), then the polish stage's two parts as `polish_stage` runs
them: the best point's preconditioned polish (`preconditioned.preconditioned_polish`), whose
CMA-ES history gives the fitness it had reached after fewer generations, and the least-squares
polish of the distinct runner-ups (`polish.polish_runner_ups`), which says which of them, if any,
gave the kept point. Prints per case the search's fitness, the preconditioned polish's at its
10th, 20th and last generation (over its final value), and the runner-up that won with its
fitness over the best point's polish; then how often each budget would have kept the same point.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--case-seeds", default="7,6061")
    parser.add_argument("--cases", type=int, default=40)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args(argv)
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "benchmarks"))
    from _cases import machine_line, measure

    from emaphm.faults import random_faults
    from emaphm.identification import search
    from emaphm.identification.identifier import FaultIdentifier
    from emaphm.identification.polish import polish_runner_ups
    from emaphm.identification.preconditioned import preconditioned_polish
    from emaphm.identification.problem import recentre_phase

    print(machine_line(f"case seeds {args.case_seeds} x {args.cases} cases, optimiser seed {args.seed}"))
    print("case          search    pre@10  pre@20  pre@end  runs  winner  f/pre   runs")
    won: list[int] = []
    late: list[float] = []
    for case_seed in (int(v) for v in args.case_seeds.split(",")):
        cases = random_faults(args.cases, seed=case_seed)
        for j in range(args.cases):
            trace = measure(cases[j], args.seed)
            ident = FaultIdentifier(uncertainty="none", last_stage="none")
            context = ident.prepare(trace.t, trace.i_q).context_.with_seed(args.seed)
            state, _ = search.global_search(None, context)
            start, residuals = recentre_phase(state.run), context.residuals()
            pre = preconditioned_polish(context.evaluate, residuals, start, seed=args.seed)
            cma = pre.history[len(start.history) :]
            at = [min(cma[: g + 1]) / pre.f if len(cma) > g else 1.0 for g in (9, 19)]
            late.append(at[1])
            run, winner = polish_runner_ups(residuals, context.evaluate, state.run, pre)
            won.append(winner)
            print(f"{case_seed:>5}/{j:<3} {start.f:9.4f}  {at[0]:6.3f}  {at[1]:6.3f}  {pre.f:7.4f}  "
                  f"{pre.evaluations - start.evaluations:4d}  {winner:6d}  {run.f / pre.f:5.3f}  "
                  f"{run.evaluations - pre.evaluations:5d}", flush=True)  # fmt: skip
    n = len(won)
    print(f"\nruns: {n}; a runner-up gave the kept point in {sum(w > 0 for w in won)} "
          f"(by rank: {', '.join(f'{r}: {won.count(r)}' for r in range(1, 5))})")
    print(f"the preconditioned polish at its 20th generation within 1.01x its end in "
          f"{sum(v <= 1.01 for v in late)} of {n}, within 1.05x in {sum(v <= 1.05 for v in late)}")


if __name__ == "__main__":
    main()
