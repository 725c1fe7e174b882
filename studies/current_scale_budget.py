"""Issue 36, seventeenth session: the current's scale refit at two trial-point budgets, paired.

    python studies/current_scale_budget.py [--budgets 40,20] SCRIPT [ARGS...]

Runs SCRIPT (a benchmark or a study, e.g. ``benchmarks/bench_rig_mistakes.py --more`` or
``studies/current_scale.py --cases 30 --seed 2611``) with every refit of the current's scale
(`current_scale.current_scale`) made at both budgets (`limits.CURRENT_SCALE_NFEV`), the first
one's record going on into the diagnosis as if the script ran with it. At the end prints on stderr
over the refits: how many would change whether the scale makes the result doubtful
(`scale_doubts`, at the default ±3.3 % limit), the largest change of γ and of the fit ratio, the
refits' time and their monitor runs at each budget. Not a benchmark of the whole process.
"""

from __future__ import annotations

import argparse
import atexit
import os
import runpy
import sys
import time
from typing import Any

from emaphm.identification import current_scale as scale
from emaphm.identification import limits, preconditions

LIMIT = 0.033  # the default |γ − 1| limit (`scale_limit` without an actuator file)


def report(budgets: tuple[int, int], refits: list[list[tuple[dict[str, Any], float]]]) -> None:
    flips, d_gain, d_ratio, times, runs = 0, 0.0, 0.0, [0.0, 0.0], [0, 0]
    for pair in refits:
        (a, ta), (b, tb) = pair
        if not a or not b:
            continue
        flips += bool(scale.scale_doubts(a, LIMIT, "")) != bool(scale.scale_doubts(b, LIMIT, ""))
        d_gain = max(d_gain, abs(a["gain"] - b["gain"]))
        if a["fit_ratio"] is not None and b["fit_ratio"] is not None:
            d_ratio = max(d_ratio, abs(a["fit_ratio"] - b["fit_ratio"]) / a["fit_ratio"])
        elif (a["fit_ratio"] is None) != (b["fit_ratio"] is None):
            flips += 1  # compared at one budget only: counted as a change
        times = [times[0] + ta, times[1] + tb]
        runs = [runs[0] + a["evaluations"], runs[1] + b["evaluations"]]
    print(f"current scale at {budgets[0]} and {budgets[1]} trial points: {len(refits)} refits, "
          f"doubtful changed {flips}, largest change of gamma {d_gain:.2e}, of the fit ratio {100 * d_ratio:.3f} %, "
          f"time {times[0]:.2f} vs {times[1]:.2f} s, monitor runs {runs[0]} vs {runs[1]}", file=sys.stderr)  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--budgets", default="40,20", help="the two budgets, the first one's record used")
    parser.add_argument("script")
    args, rest = parser.parse_known_args()
    budgets = tuple(int(b) for b in args.budgets.split(","))
    if len(budgets) != 2:
        parser.error("--budgets takes two numbers")
    refits: list[list[tuple[dict[str, Any], float]]] = []
    refit = scale.current_scale

    def both(context: Any, faults: Any, present: Any) -> dict[str, Any]:
        pair, kept = [], limits.CURRENT_SCALE_NFEV
        try:
            for budget in budgets:
                limits.CURRENT_SCALE_NFEV = budget
                start = time.perf_counter()
                pair.append((refit(context, faults, present), time.perf_counter() - start))
        finally:
            limits.CURRENT_SCALE_NFEV = kept
        refits.append(pair)
        return pair[0][0]

    preconditions.current_scale = both
    atexit.register(report, budgets, refits)
    sys.argv = [args.script, *rest]
    sys.path.insert(0, os.path.dirname(os.path.abspath(args.script)))  # the script's own folder first
    runpy.run_path(args.script, run_name="__main__")


if __name__ == "__main__":
    main()
