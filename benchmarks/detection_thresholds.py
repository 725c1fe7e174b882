"""Detection thresholds from repeated healthy, noisy identifications, and their false-alarm rate.

    python benchmarks/detection_thresholds.py [--runs 20] [--write src/emaphm/data/detection.json]

1. Identify the healthy twin (noise on) with seeds 1000..1000+runs−1 (each seed gives another noise
   realisation and another optimiser seed). For every detectable fault the threshold is
   1.25 × the largest departure from healthy seen in these runs, plus 0.005 (k1..k6 from 0,
   k8 from 0.5).
2. Measure the false-alarm rate on fresh healthy runs, seeds 2000..2000+runs−1: a run is a false
   alarm when any fault is reported.
3. Check sensitivity: single faults of 0.1 (k8: 0.6) and of 0.2 (k8: 0.7), one run each.
Prints every figure; with --write, stores thresholds and the record as the package's file.
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import time

import numpy as np

import emaphm
from emaphm.faults import FAULT_NAMES, HEALTHY
from emaphm.identification.detection import DETECTABLE, detect
from emaphm.identification.fitness import ERROR_CORNER_HZ
from emaphm.identification.identify import identify


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=20)
    parser.add_argument("--optimizer", default="ga")
    parser.add_argument("--write", default=None, help="path of the thresholds file to write")
    args = parser.parse_args()
    idx = [FAULT_NAMES.index(n) for n in DETECTABLE]
    start = time.perf_counter()

    def healthy_runs(first_seed: int) -> np.ndarray:
        out = []
        for s in range(first_seed, first_seed + args.runs):
            r = identify(HEALTHY, optimizer=args.optimizer, seed=s, thresholds={})
            out.append(r.estimate)
            print(f"  seed {s}: " + " ".join(f"{v:.3f}" for v in r.estimate), flush=True)
        return np.array(out)

    print(f"healthy runs for the thresholds (seeds {1000}..{1000 + args.runs - 1}):")
    fit = healthy_runs(1000)
    deviation = np.abs(fit - HEALTHY)[:, idx]
    thresholds = {
        name: round(1.25 * float(deviation[:, j].max()) + 0.005, 4) for j, name in enumerate(DETECTABLE)
    }
    print(
        "largest healthy departure: "
        + ", ".join(f"{n} {deviation[:, j].max():.4f}" for j, n in enumerate(DETECTABLE))
    )
    print("thresholds:                " + ", ".join(f"{n} {v:.4f}" for n, v in thresholds.items()))

    print(f"fresh healthy runs for the false-alarm rate (seeds 2000..{2000 + args.runs - 1}):")
    check = healthy_runs(2000)
    alarms = [detect(k, thresholds) for k in check]
    false_runs = sum(1 for a in alarms if a)
    print(f"false alarms: {false_runs} of {args.runs} runs " + str([a for a in alarms if a]))

    print("sensitivity (single faults, one run each, seed 3000):")
    sensitivity = []
    for name in DETECTABLE:
        for size in (0.1, 0.2):
            k = np.array(HEALTHY)
            i = FAULT_NAMES.index(name)
            k[i] = 0.5 + size if name == "kp_drift" else size
            if name == "eccentricity":
                k[6] = 0.3
            found = detect(
                identify(k, optimizer=args.optimizer, seed=3000, thresholds={}).estimate, thresholds
            )
            sensitivity.append({"fault": name, "value": float(k[i]), "detected": found})
            print(f"  {name}={k[i]:.2f}: detected {found}", flush=True)
    wall = time.perf_counter() - start
    print(f"total wall time {wall:.0f} s")
    if args.write:
        record = {
            "thresholds": thresholds,
            "monitor": "default",  # identify() warns when another monitor uses these thresholds
            "rule": "1.25 x the largest healthy departure + 0.005 (k1..k6 from 0, k8 from 0.5)",
            "optimizer": args.optimizer,
            "error_corner_hz": ERROR_CORNER_HZ,  # the eq. 3 frequency weights the identifications used
            "threshold_seeds": [1000, 1000 + args.runs - 1],
            "false_alarm_seeds": [2000, 2000 + args.runs - 1],
            "false_alarm_runs": false_runs,
            "runs": args.runs,
            "false_alarms": [a for a in alarms if a],
            "healthy_estimates_threshold_set": fit.round(5).tolist(),
            "healthy_estimates_check_set": check.round(5).tolist(),
            "sensitivity": sensitivity,
            "package_version": emaphm.__version__,
            "created": dt.datetime.now(dt.UTC).isoformat(timespec="seconds"),
            "wall_time_s": round(wall, 1),
        }
        with open(args.write, "w") as fh:
            json.dump(record, fh, indent=2)
            fh.write("\n")
        print(f"wrote {args.write}")


if __name__ == "__main__":
    main()
