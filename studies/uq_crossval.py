# Study, not a benchmark: moved from benchmarks/ at dae85bf (last changed at 0d70484); rerun it at that
# commit to reproduce its figures: HISTORY.md §"Uncertainty of a diagnosis", results/uq-crossval-*.txt;
# docs/uncertainty.md.
"""Cross-validation of the interval calibration on its own cases (issue 9): why it fits to 92 %, not 90 %.

    python studies/uq_crossval.py [--targets 0.90 0.92] [--repeats 5]

Reads the cases stored in the shipped `emaphm/data/uq_calibration.json` (estimates, noise-only
σ, truths) and, for each training target, fits `uncertainty.fit_factors` on 3 of 4 folds and
measures the coverage of the 90 % intervals on the fourth (--repeats random fold splits, seed
0). Prints the mean held-out coverage per fault. No identification runs: 6.5 min on [B].
"""

from __future__ import annotations

import argparse

import numpy as np

from emaphm.faults import FAULT_NAMES
from emaphm.identification.uncertainty import covers, fit_factors, intervals, load_factors


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--targets", type=float, nargs="+", default=[0.90, 0.92])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    data = load_factors().record["data"]
    E, S, T = (np.array(data[k]) for k in ("estimates", "raw_std", "truths"))
    print(f"{len(E)} calibration cases, 4 folds x {args.repeats} repeats")
    rng = np.random.default_rng(0)
    for target in args.targets:
        held = []
        for _ in range(args.repeats):
            folds = np.array_split(rng.permutation(len(E)), 4)
            for f, test in enumerate(folds):
                train = np.concatenate([g for i, g in enumerate(folds) if i != f])
                factors, _ = fit_factors(E[train], S[train], T[train], coverage=target)
                _, lo, hi, _ = intervals(E[test], factors.apply(S[test]), with_flags=False)
                inside = covers(lo, hi, T[test])
                scored = np.ones_like(inside)
                scored[:, 6] = T[test, 5] >= 0.05
                held.append([inside[scored[:, j], j].mean() for j in range(len(FAULT_NAMES))])
        mean = np.mean(held, axis=0)
        print(f"fitted to {target:.2f}: held-out coverage " + " ".join(f"k{j + 1} {v:.3f}" for j, v in enumerate(mean))
              + f"; min {mean.min():.3f}")  # fmt: skip


if __name__ == "__main__":
    main()
