"""HF twin speed: wall seconds per simulated second on one thread (DESIGN §9).

Target ≤ 0.15 s, goal ≤ 0.05 s. Reported in BENCHMARKS.md, "HF twin speed". Run:

    python benchmarks/bench_hf.py [--repeats 5] [--control foc]
    python benchmarks/bench_hf.py --batch 40 [--repeats 5] [--control foc]

Smallest run (the smoke test): ``--repeats 1``, ``--batch 2 --repeats 1`` and
``--control foc --repeats 1``.

--control chooses the drive of the twin: "hysteresis" (the paper's comparators, the default) or
"foc" (field-oriented control with PWM, `InverterParams(control="foc")` with its default
settings: 20 kHz, single update, one period's delay, svpwm, 1 µs dead time compensated). The
machine line names it; the table is the same.

The first call loads (or compiles) the numba kernels and is reported apart; the figure is the
median over the repeats of each case, on the default FDI chirp (1 s simulated, Δt = 1 µs), and
the same median as nanoseconds per integration step (wall time of the whole `simulate` call over
the number of Δt steps, sub-steps included). The last column is the process CPU time per
simulated second (median): on a shared, busy machine it moves less than the wall time.

--batch N times instead `HighFidelityEma.simulate_batch` on N random fault rows (seed 9002,
noise off), on 1 thread and on 2 (the kernel releases the GIL), alternating, --repeats rounds:
the medians and their ratio.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")  # one thread, as the target states

import numpy as np
from _cases import draw_cases, machine_line  # benchmarks/ is the script's folder, first on sys.path

import emaphm
from emaphm.params import CONTROL_MODES, InverterParams

CASES = {
    "healthy": emaphm.HEALTHY,
    "Table 1 reference": emaphm.TABLE1_REFERENCE,
    "shorts k3=k4=0.5": np.array([0, 0, 0.5, 0.5, 0, 0, 0, 0.5]),
}


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--batch", type=int, default=0, help="N: time a batch of N runs on 1 and 2 threads")
    parser.add_argument(
        "--control", choices=CONTROL_MODES, default="hysteresis", help="the twin's current control (drive)"
    )
    args = parser.parse_args(argv)
    params = twin_params(args.control)
    if args.batch:
        batch(args, params)
        return

    t0 = time.perf_counter()
    emaphm.simulate(emaphm.HEALTHY, duration=0.01, params=params)
    first = time.perf_counter() - t0
    print(machine_line(f"NUMBA_NUM_THREADS={os.environ['NUMBA_NUM_THREADS']}, control={args.control}"))
    print(f"first call (import of kernels: compile or cache load): {first:.2f} s")
    dt = emaphm.EmaParams().integration.dt
    print(
        f"{'case':<22} {'sub-steps':>9} {'sim s':>6} {'wall s/sim s (median)':>22} {'min':>7} {'max':>7}"
        f" {'ns/step (median)':>17} {'cpu s/sim s':>12}"
    )
    for name, k in CASES.items():
        walls = []
        cpus = []
        for seed in range(args.repeats):
            t0 = time.perf_counter()
            c0 = time.process_time()
            r = emaphm.simulate(k, seed=seed, params=params)
            cpus.append(time.process_time() - c0)
            walls.append(time.perf_counter() - t0)
        sim_s = float(r.t[-1])
        per = [w / sim_s for w in walls]
        print(
            f"{name:<22} {r.metadata['electrical_substeps']:>9} {sim_s:>6.2f} "
            f"{statistics.median(per):>22.4f} {min(per):>7.4f} {max(per):>7.4f}"
            f" {statistics.median(per) * dt * 1e9:>17.1f} {statistics.median(cpus) / sim_s:>12.4f}"
        )


def twin_params(control: str) -> emaphm.EmaParams:
    """The nominal parameters with the current control `control` (its defaults)."""
    return emaphm.EmaParams(inverter=InverterParams(control=control))


def batch(args: argparse.Namespace, params: emaphm.EmaParams) -> None:
    """`simulate_batch` of args.batch random rows on 1 thread and on 2, alternating."""
    K = draw_cases(args.batch, 9002)
    twin = emaphm.HighFidelityEma(params)
    twin.simulate_batch(K[:2], noise=False, workers=2)  # compile or cache load
    print(
        machine_line(
            f"simulate_batch of {args.batch} random rows (seed 9002), noise off, {args.repeats} rounds, "
            f"control={args.control}"
        )
    )
    walls: dict[int, list[float]] = {1: [], 2: []}
    for _ in range(args.repeats):
        for workers in (1, 2):
            t0 = time.perf_counter()
            twin.simulate_batch(K, noise=False, workers=workers)
            walls[workers].append(time.perf_counter() - t0)
    one, two = statistics.median(walls[1]), statistics.median(walls[2])
    print(f"1 thread: {one:.2f} s ({1e3 * one / args.batch:.1f} ms per run); 2 threads: {two:.2f} s "
          f"({1e3 * two / args.batch:.1f} ms per run); speed-up {one / two:.2f}x (medians; per round "
          + ", ".join(f"{a / b:.2f}" for a, b in zip(walls[1], walls[2], strict=True)) + ")")  # fmt: skip


if __name__ == "__main__":
    main()
