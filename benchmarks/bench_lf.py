"""LF monitor model speed (DESIGN §9): time per simulated second on one thread, the HF/LF cost ratio,
population throughput on 1 vs 2 threads, and one generation's whole evaluate() on 1 vs 2 threads.

    python benchmarks/bench_lf.py [--repeats 20] [--population 200] [--evaluate 96] [--rounds 9]

Smallest run (the smoke test): ``--repeats 1 --population 4 --evaluate 4 --rounds 1``.
Reported in BENCHMARKS.md, "LF monitor speed" and "evaluate() of a generation".

Targets: LF ≤ 2 ms per simulated second (goal ≤ 0.5 ms); population speed-up 2 threads vs 1
≥ 1.6× (goal ≥ 1.9×); the whole evaluate() (LF, filter and eq. 3 fused per row,
`Fitness.of_monitor`, what identification runs) 2 threads vs 1 ≥ 1.7× (goal ≥ 1.9×). The first
calls (compile or cache load) are excluded; the first is reported apart.

evaluate(): the reference is the HF twin's Table 1 current (noise on, seed 0) on the default FDI
chirp; the population is --evaluate random points of the optimiser's box (seed --seed), mapped as
`FaultIdentifier.fit` maps them; --rounds rounds alternate 1 and 2 threads (in a rotating order)
so that machine noise hits both alike. The comparison with the path before the fused kernel
(``studies/bench_evaluate.py``) is a study.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numba
import numpy as np
from _cases import (  # benchmarks/ is the script's folder, first on sys.path
    N_AUX,
    Fitness,
    machine_line,
    search_to_faults,
    simulate_lf,
    simulate_lf_many,
)

import emaphm
from emaphm.identification import Comparison


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=20)
    parser.add_argument("--population", type=int, default=200)
    parser.add_argument(
        "--evaluate", type=int, default=96, help="population of the evaluate() timing (0: skip)"
    )
    parser.add_argument("--rounds", type=int, default=9, help="interleaved 1/2-thread rounds")
    parser.add_argument("--seed", type=int, default=0, help="seed of the random fault rows")
    args = parser.parse_args(argv)
    print(machine_line(f"numba threads available {numba.config.NUMBA_NUM_THREADS}"))

    lf = emaphm.MonitorEma()
    t0 = time.perf_counter()
    lf.simulate(emaphm.TABLE1_REFERENCE, duration=0.01)
    print(f"first LF call (compile or cache load): {time.perf_counter() - t0:.2f} s")
    _, theta_cmd = lf.sample_grid()
    sim_s = (len(theta_cmd) - 1) / lf.params.controller.f_s
    row = lf.rows(emaphm.TABLE1_REFERENCE)[0]
    out, no_aux = np.empty(len(theta_cmd)), np.empty((0, N_AUX))
    numba.set_num_threads(1)
    walls = []
    for _ in range(args.repeats):
        t0 = time.perf_counter()
        simulate_lf(theta_cmd, row, out, no_aux)  # the kernel alone, as the GA calls it
        walls.append(time.perf_counter() - t0)
    lf_kernel = statistics.median(walls) / sim_s
    walls = []
    for _ in range(args.repeats):
        t0 = time.perf_counter()
        lf.simulate(emaphm.TABLE1_REFERENCE)  # the API call with all signals
        walls.append(time.perf_counter() - t0)
    lf_api = statistics.median(walls) / sim_s
    hf_walls = []
    for seed in range(min(3, args.repeats)):
        t0 = time.perf_counter()
        emaphm.simulate(emaphm.TABLE1_REFERENCE, seed=seed)
        hf_walls.append(time.perf_counter() - t0)
    hf = statistics.median(hf_walls) / sim_s
    print("Table 1 fault vector, FDI chirp, one thread:")
    print(f"  LF kernel         {1e3 * lf_kernel:8.3f} ms per simulated second (median of {args.repeats})")
    print(f"  LF API simulate() {1e3 * lf_api:8.3f} ms per simulated second")
    print(f"  HF simulate()     {1e3 * hf:8.1f} ms per simulated second (median of {len(hf_walls)})")
    print(f"  HF/LF cost ratio  {hf / lf_kernel:8.0f} (kernel) / {hf / lf_api:.0f} (API)")

    K = np.random.default_rng(args.seed).uniform(0.0, 1.0, (args.population, 8))
    rows = lf.rows(K)
    pop_out = np.empty((args.population, len(theta_cmd)))
    simulate_lf_many(theta_cmd, rows[:2], pop_out[:2])  # compile/load the parallel kernel
    # interleave 1- and 2-thread timings so that machine noise hits both alike
    ratios, best = [], {1: np.inf, 2: np.inf}
    for _ in range(args.rounds):
        wall = {}
        for threads in (1, 2):
            numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
            wall[threads] = _timed(simulate_lf_many, theta_cmd, rows, pop_out)
            best[threads] = min(best[threads], wall[threads])
        ratios.append(wall[1] / wall[2])
    for threads in (1, 2):
        print(f"  population of {args.population}, {threads} thread(s): best {best[threads]:.3f} s "
              f"({args.population * sim_s / best[threads]:.0f} simulated s per wall s)")  # fmt: skip
    print(f"  speed-up 2 threads vs 1: median {statistics.median(ratios):.2f}x over {args.rounds} interleaved "
          f"rounds (range {min(ratios):.2f}-{max(ratios):.2f})")  # fmt: skip
    if args.evaluate:
        evaluate(lf, args)
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)


def evaluate(monitor: emaphm.MonitorEma, args: argparse.Namespace) -> None:
    """One generation's evaluate() (the fused kernel) on 1 and 2 threads, interleaved rounds."""
    grid, _ = monitor.sample_grid()
    measured = emaphm.simulate(emaphm.TABLE1_REFERENCE, noise=True, seed=0)
    fitness = Fitness(Comparison.from_trace(measured.t, measured.i_q, grid, monitor.params.controller.f_s))
    K = search_to_faults(np.random.default_rng(args.seed).uniform(0.0, 1.0, (args.evaluate, 8)))
    fitness.of_monitor(monitor, K)  # compile or cache load
    wall: dict[int, list[float]] = {1: [], 2: []}
    for r in range(args.rounds):
        for threads in (1, 2) if r % 2 == 0 else (2, 1):
            numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
            wall[threads].append(_timed(fitness.of_monitor, monitor, K))
    print(
        f"evaluate() of one generation ({args.evaluate} rows x {len(grid)} samples, LF + filter + eq. 3 fused):"
    )
    for threads in (1, 2):
        xs = wall[threads]
        print(f"  {threads} thread(s): median {1e3 * statistics.median(xs):6.1f} ms "
              f"(min {1e3 * min(xs):6.1f}, max {1e3 * max(xs):6.1f})")  # fmt: skip
    ratios = [a / b for a, b in zip(wall[1], wall[2], strict=True)]
    print(f"  2 threads vs 1: {statistics.median(ratios):.2f}x per round (range {min(ratios):.2f}-{max(ratios):.2f}); "
          f"of the minima {min(wall[1]) / min(wall[2]):.2f}x")  # fmt: skip


def _timed(fn, *a) -> float:  # type: ignore[no-untyped-def]
    t0 = time.perf_counter()
    fn(*a)
    return time.perf_counter() - t0


if __name__ == "__main__":
    main()
