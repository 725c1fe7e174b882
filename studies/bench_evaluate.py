# Study, not a benchmark: moved from benchmarks/ at dae85bf (last changed at b75b9c6); rerun it at that
# commit to reproduce its figures: HISTORY.md §"The whole evaluate() of a generation", results/evaluate-*.txt.
# The fused path alone is now timed by benchmarks/bench_lf.py --evaluate.
"""One optimiser generation's evaluate() (DESIGN §9): the old path against the fused kernel, 1 vs 2 threads.

    python studies/bench_evaluate.py [--population 96] [--rounds 9] [--seed 0]

The reference is the HF twin's Table 1 current (noise on, seed 0) on the default FDI chirp (1 s,
10001 samples); the population is --population random points of the optimiser's box, mapped as
`FaultIdentifier.fit` maps them. Two evaluate() bodies are timed:

- old: ``fitness(monitor.simulate_many(K, check=False))``: the parallel LF kernel, then scipy's
  `sosfiltfilt` and the eq. (3) sum in numpy, serially (the two parts are also timed apart);
- new: ``fitness.of_monitor(monitor, K)``: simulation, filter and sum fused per row in one parallel
  kernel (`kernels.fitness.fitness_lf_many`), what identification runs.

Rounds interleave the four cases (path x threads, in a rotating order) so that machine noise hits
all alike; the first calls (compile or cache load) are excluded. Prints median and min/max per
case, the 2-vs-1-thread ratio per round (median and range), of the medians and of the minima
(on a shared machine the minima are the least disturbed), and new/old per thread count.
Target: new evaluate() 2 threads vs 1 >= 1.7x (goal >= 1.9x).
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numba
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))  # the shared helpers
from _machine import cpu_model

import emaphm
from emaphm._versions import versions
from emaphm.faults import TABLE1_REFERENCE
from emaphm.identification.fitness import Fitness
from emaphm.identification.problem import search_to_faults
from emaphm.identification.signals import Comparison
from emaphm.models import MonitorEma


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--population", type=int, default=96)
    parser.add_argument("--rounds", type=int, default=9)
    parser.add_argument("--seed", type=int, default=0, help="seed of the random population")
    args = parser.parse_args()
    print(f"machine: {os.cpu_count()} cores ({len(os.sched_getaffinity(0))} usable), {cpu_model()}; "
          f"numba threads available {numba.config.NUMBA_NUM_THREADS}")  # fmt: skip
    print("versions: " + ", ".join(f"{k} {v}" for k, v in versions().items()))
    if os.path.exists("/proc/loadavg"):  # a busy machine cannot give 2 threads their 2 cores
        with open("/proc/loadavg", encoding="utf-8") as f:
            print(f"load average at start (1, 5, 15 min): {' '.join(f.read().split()[:3])}")
    if numba.config.NUMBA_NUM_THREADS < 2:
        raise SystemExit("needs 2 numba threads")

    monitor = MonitorEma()
    grid, _ = monitor.sample_grid()
    measured = emaphm.simulate(TABLE1_REFERENCE, noise=True, seed=0)
    fitness = Fitness(Comparison.from_trace(measured.t, measured.i_q, grid, monitor.params.controller.f_s))
    K = search_to_faults(np.random.default_rng(args.seed).uniform(0.0, 1.0, (args.population, 8)))
    print(f"population {args.population} rows x {len(grid)} samples (FDI chirp, {grid[-1]:g} s), "
          f"{args.rounds} interleaved rounds")  # fmt: skip

    parts: dict[str, list[float]] = {"kernel": [], "filter": []}

    def old(threads: int) -> np.ndarray:
        t0 = time.perf_counter()
        currents = monitor.simulate_many(K, check=False)
        t1 = time.perf_counter()
        f = fitness(currents)
        t2 = time.perf_counter()
        if threads == 1:
            parts["kernel"].append(t1 - t0)
            parts["filter"].append(t2 - t1)
        return f  # type: ignore[no-any-return]

    def new(threads: int) -> np.ndarray:
        return fitness.of_monitor(monitor, K)

    paths: dict[str, Callable[[int], np.ndarray]] = {"old": old, "new": new}
    f_old, f_new = old(0), new(0)  # compile or load both, and compare
    rel = np.abs(f_new - f_old) / np.abs(f_old)
    print(f"agreement new vs old: max relative difference {rel.max():.1e}, "
          f"{int(np.sum(f_new == f_old))}/{len(f_old)} bit-identical")  # fmt: skip

    cases = [(p, t) for p in paths for t in (1, 2)]
    wall: dict[tuple[str, int], list[float]] = {c: [] for c in cases}
    for r in range(args.rounds):
        for path, threads in cases[r % 4 :] + cases[: r % 4]:
            numba.set_num_threads(threads)
            t0 = time.perf_counter()
            paths[path](threads)
            wall[path, threads].append(time.perf_counter() - t0)
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)

    def fmt(xs: list[float]) -> str:
        return f"median {1e3 * statistics.median(xs):6.1f} ms (min {1e3 * min(xs):6.1f}, max {1e3 * max(xs):6.1f})"

    print("evaluate() of one generation:")
    for path, threads in cases:
        print(f"  {path} {threads} thread(s): {fmt(wall[path, threads])}")
    print(f"  old, its parts on 1 thread: LF kernel {fmt(parts['kernel'])}")
    print(f"                              filter + eq. 3 {fmt(parts['filter'])}")
    for path in paths:
        ratios = [a / b for a, b in zip(wall[path, 1], wall[path, 2], strict=True)]
        print(f"  {path}: 2 threads vs 1 {statistics.median(ratios):.2f}x per round "
              f"(range {min(ratios):.2f}-{max(ratios):.2f}); of the medians "
              f"{statistics.median(wall[path, 1]) / statistics.median(wall[path, 2]):.2f}x, of the minima "
              f"{min(wall[path, 1]) / min(wall[path, 2]):.2f}x")  # fmt: skip
    for threads in (1, 2):
        ratios = [a / b for a, b in zip(wall["old", threads], wall["new", threads], strict=True)]
        print(f"  new vs old on {threads} thread(s): {statistics.median(ratios):.2f}x faster per round "
              f"(range {min(ratios):.2f}-{max(ratios):.2f})")  # fmt: skip


if __name__ == "__main__":
    main()
