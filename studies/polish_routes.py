"""Issue 36: the best point's polish, round CMA-ES against the preconditioned one, on the hard cases.

    python studies/polish_routes.py [--cases 6061/1/2,7/2/2,...] [--start table|random]

Each case (case seed / case / seed, `bench_multifault.py`'s numbering) is measured as ``emaphm
identify --true-faults K --seed S`` measures it; the global search runs once (the start table's 15
generations by default), then from its best point (k7 re-centred, as `polish_stage` does) each
polish: ``round`` (`polish.polish`, the CMA-ES of `limits.POLISH_BUDGET`), ``pre``
(`preconditioned.preconditioned_polish`, the default since the fourth session) and ``lm`` (its
least-squares descent alone). Prints the search's fitness, each polish's fitness over the round
one's (below 1: better) and its monitor runs. The figures of docs/identification.md §3 came
from this at the commit that added it (machine C, 2026-12-01).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

HARD = "6061/1/2,7/2/2,7/9/2,6061/19/2,6061/34/1,7/2/1"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", default=HARD)
    parser.add_argument("--start", default="table", choices=("table", "random"))
    args = parser.parse_args(argv)
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "benchmarks"))
    from _cases import machine_line, measure

    from emaphm.faults import random_faults
    from emaphm.identification import polish, search
    from emaphm.identification.descents import lm_polish
    from emaphm.identification.identifier import FaultIdentifier
    from emaphm.identification.preconditioned import preconditioned_polish
    from emaphm.identification.problem import recentre_phase

    print(machine_line(f"cases {args.cases}; start {args.start}; polishes round, pre, lm"))
    for case in args.cases.split(","):
        case_seed, j, seed = (int(v) for v in case.split("/"))
        trace = measure(random_faults(max(j + 1, 40), seed=case_seed)[j], seed)
        ident = FaultIdentifier(start=args.start, uncertainty="none", last_stage="none")
        context = ident.prepare(trace.t, trace.i_q).context_.with_seed(seed)
        state, _ = search.global_search(None, context)
        start, residuals = recentre_phase(state.run), context.residuals()
        routes = {
            "round": lambda: polish.polish(context.evaluate, start, seed=seed),
            "pre": lambda: preconditioned_polish(context.evaluate, residuals, start, seed=seed),
            "lm": lambda: lm_polish(residuals, start),
        }
        row, base = [], None
        for name, route in routes.items():
            t = time.perf_counter()
            run = route()
            wall = time.perf_counter() - t
            base = run.f if base is None else base
            row.append(f"{name} {run.f / base:.3f} (+{run.evaluations - start.evaluations}, {wall:.2f} s)")
        print(f"{case:>10}: search {start.f:.4f} ({start.evaluations})  " + "  ".join(row), flush=True)


if __name__ == "__main__":
    main()
