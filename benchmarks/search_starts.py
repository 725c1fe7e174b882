"""One long GA against two shorter independent GAs: how often does each end in a wrong basin?

    python benchmarks/search_starts.py [--cases 20] [--case-seed 4242]

An experiment for issue 8 item 3 ("no wrong basins"), not the default identification. Random
cases in the DESIGN §7 ranges from --case-seed; two noisy measurements each (noise seeds 101, 102).
On each measurement:
  A: the default, one GA 96 x 40 then the CMA-ES polish;
  B: two independent GAs 64 x 30 (seeds s and s + 7919), the better one polished.
Prints per measurement the final fitness, %err, wall time and evaluations of A and B, and the
count of runs whose fitness exceeds 1.2x the better of the two ("wrong basin").
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import emaphm
from emaphm.commands import Chirp
from emaphm.faults import random_faults
from emaphm.identification import Comparison
from emaphm.identification.fitness import Fitness
from emaphm.identification.identify import search_to_faults
from emaphm.identification.optimizers import Stagnation, polish, run_optimizer
from emaphm.models import HighFidelityEma, MonitorEma


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=20)
    parser.add_argument("--case-seed", type=int, default=4242)
    args = parser.parse_args()
    monitor, hf = MonitorEma(), HighFidelityEma(command=Chirp())
    grid, _ = monitor.sample_grid(1.0)
    wrong = {"A": 0, "B": 0}
    errors: dict[str, list[float]] = {"A": [], "B": []}
    for j, k in enumerate(random_faults(args.cases, args.case_seed)):
        for s in (1, 2):
            trace = hf.simulate(k, noise=True, seed=100 + s)
            fitness = Fitness(Comparison.from_trace(trace.t, trace.i_q, grid, 1e4), "s")

            def evaluate(X: np.ndarray, fitness: Fitness = fitness) -> np.ndarray:
                return fitness.of_monitor(monitor, search_to_faults(X))

            t0 = time.perf_counter()
            a = polish(evaluate, run_optimizer("ga", evaluate, seed=s, stagnation=Stagnation()), seed=s)
            t1 = time.perf_counter()
            b1, b2 = (
                run_optimizer("ga", evaluate, pop_size=64, generations=30, seed=seed, stagnation=Stagnation())
                for seed in (s, s + 7919)
            )
            b = polish(evaluate, min((b1, b2), key=lambda r: r.f), seed=s)
            t2 = time.perf_counter()
            best = min(a.f, b.f)
            line = [f"case {j:>3} seed {s}"]
            for name, run, wall in (("A", a, t1 - t0), ("B", b, t2 - t1)):
                err = emaphm.percent_error(search_to_faults(run.x[None])[0], k)
                errors[name].append(err)
                flag = run.f > 1.2 * best
                wrong[name] += flag
                line.append(f"{name} f {run.f:.4f} %err {err:6.2f} {wall:4.1f} s {run.evaluations:>5} ev"
                            + (" WRONG" if flag else "      "))  # fmt: skip
            print(" | ".join(line), flush=True)
    n = len(errors["A"])
    for name in ("A", "B"):
        e = errors[name]
        print(f"{name}: wrong basins {wrong[name]} of {n}; %err median {np.median(e):.2f}, max {max(e):.2f}")


if __name__ == "__main__":
    main()
