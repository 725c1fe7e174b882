# Study, not a benchmark: moved from benchmarks/ at dae85bf (last changed at ba050eb); rerun it at that
# commit to reproduce its figures: HISTORY.md §"Multi-fault identification" (30 cases of seed 5151),
# results/bias-from-truth-5151-2026-11-22.txt; docs/identification.md.
"""Where the identification's own model bias takes the estimate, without the search (issue 8).

    python studies/bias_from_truth.py [--cases 30] [--case-seed 5151] [--seed 1]
                                         [--corners off,auto,4.6] [--command chirp]

For each random actuator (DESIGN §7 ranges, `emaphm.faults.random_faults` of --case-seed) one
noisy measurement is made as ``emaphm identify --true-faults K --seed S`` makes it. eq. 3 is then
minimised by a local search started at the true vector (two CMA-ES polishes, steps 0.02 and
0.01 in the unit box, `optimizers.polish`), once per eq. 3 weighting given by --corners
(`--error-corner`: off is the paper's eq. 3, auto the default's, a number a corner in Hz). Where
it ends is where the monitor's discrepancy pulls the estimate: a full identification ends near
it unless its search fails (on 8 of bench_multifault's cases, seed 1, a scratch comparison found
the two 0.0-1.1 %err apart), so this separates model bias from search failures without a
global search. Printed: %err of each end point, then median / p90 / max / mean per weighting.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))  # the shared helpers
from _cases import noise_seed_of

import emaphm
from emaphm.calibration.scenarios import CALIBRATION_COMMANDS
from emaphm.commands import SampledCommand
from emaphm.faults import random_faults
from emaphm.identification.identifier import FaultIdentifier
from emaphm.identification.optimizers import OptimizerRun
from emaphm.identification.polish import polish
from emaphm.identification.problem import search_to_faults
from emaphm.identification.settings import parse_error_corner
from emaphm.models import HighFidelityEma, MonitorEma


def corner_of(text: str) -> float | str | None:
    """An entry of --corners read as identify --error-corner reads it."""
    return parse_error_corner(text if text in ("off", "auto") else float(text), name="--corners")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=30)
    parser.add_argument("--case-seed", type=int, default=5151)
    parser.add_argument("--seed", type=int, default=1, help="the measurement's seed (as identify --seed)")
    parser.add_argument("--corners", default="off,auto", help="comma-separated: off, auto or Hz")
    parser.add_argument("--command", default="chirp", choices=tuple(CALIBRATION_COMMANDS))
    args = parser.parse_args()
    corners = args.corners.split(",")
    command = CALIBRATION_COMMANDS[args.command]
    hf, monitor = HighFidelityEma(None, command), MonitorEma(None, command)
    print(f"emaphm {emaphm.__version__}, Python {platform.python_version()}, {os.cpu_count()} cores; "
          f"{args.cases} cases (seed {args.case_seed}), measurement seed {args.seed}, command {args.command}; "
          f"local search from the truth, %err of its end point per --error-corner")  # fmt: skip
    print(f"{'case':>4} " + " ".join(f"{c:>7}" for c in corners))
    errs: dict[str, list[float]] = {c: [] for c in corners}
    for j, k in enumerate(random_faults(args.cases, args.case_seed)):
        trace = hf.simulate(k, noise=True, seed=noise_seed_of(args.seed))
        x0 = k.copy()
        x0[6] = (k[6] + 0.5) / 2.0  # the representative of k7 inside the box (`recentre_phase`)
        line = []
        for c in corners:
            ident = FaultIdentifier(monitor=monitor, error_corner=corner_of(c)).prepare(
                trace.t, trace.i_q, SampledCommand(trace.t - trace.t[0], trace.theta_cmd), trace.theta_u
            )

            def evaluate(X: np.ndarray, ident: FaultIdentifier = ident) -> np.ndarray:
                return ident.objective_.of_monitor(
                    ident.monitor_, search_to_faults(X), duration=ident.duration_
                )

            run = OptimizerRun(x0, float(evaluate(x0[None, :])[0]), 0, [])
            for step, sigma in enumerate((0.02, 0.01)):
                run = polish(evaluate, run, seed=step, sigma=sigma)
            err = emaphm.percent_error(search_to_faults(run.x[None, :])[0], k)
            errs[c].append(err)
            line.append(f"{err:7.2f}")
        print(f"{j:>4} " + " ".join(line), flush=True)
    print()
    for c, e in errs.items():
        print(f"--error-corner {c}: %err median {np.median(e):.2f}, p90 {np.percentile(e, 90):.2f}, "
              f"max {max(e):.2f}, mean {np.mean(e):.2f}")  # fmt: skip


if __name__ == "__main__":
    main()
