"""Issue 34/36: one drawn healthy actuator of `benchmarks/bench_foc.py`, identified with several seeds.

    python studies/drawn_healthy_seeds.py [--healthy 2] [--seeds 5]

Draws healthy actuator H of ``bench_foc.py --params benchmarks/actuators/foc-stiff.toml
--tolerance 0.02`` (the plant ``drawn_actuator(params, 7919 * (10 000 + H) + 1, tolerance=0.02,
drive_tolerance=0.1)``, its recording with noise seed of 1, as the benchmark makes it) and
identifies it with optimiser seeds 1..S, with the FOC stiff drive's calibration, interval
calibration and detection thresholds. Prints each seed's estimate, detections and verdict: whether
a detection on that actuator is the benchmark seed's luck or the actuator's (BENCHMARKS.md,
issue 36, fifteenth session; run it with ``PYTHONPATH=<worktree>/src`` for an older tree).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--healthy", type=int, default=2)
    parser.add_argument("--seeds", type=int, default=5)
    args = parser.parse_args(argv)
    import bench_foc
    from _cases import CALIBRATION_COMMANDS, load_thresholds, noise_seed_of, resolve_params

    import emaphm

    actuators = ROOT / "benchmarks" / "actuators"
    params = resolve_params(str(actuators / "foc-stiff.toml"))
    thresholds = dict(load_thresholds(str(actuators / "foc-stiff.det.json"))["thresholds"])
    plant = bench_foc.drawn_actuator(params, 7919 * (10_000 + args.healthy) + 1, tolerance=0.02,
                                     drive_tolerance=0.1, steps=(5e-7, 1e-6, 2e-6))  # fmt: skip
    healthy = np.array(emaphm.HEALTHY, dtype=float)
    trace = emaphm.HighFidelityEma(plant, CALIBRATION_COMMANDS["chirp"]).simulate(healthy, seed=noise_seed_of(1))
    for seed in range(1, args.seeds + 1):
        r = emaphm.identify(reference=trace, seed=seed, params=params, calibration=str(actuators / "foc-stiff.cal.json"),
                            uq_calibration=str(actuators / "foc-stiff.uq.json"), thresholds=thresholds)  # fmt: skip
        print(seed, np.round(r.estimate, 4), r.detected, r.verdict, flush=True)
    print("thresholds", thresholds)


if __name__ == "__main__":
    main()
