"""Coverage of the 90 % intervals (issue 9): do the intervals hold, how wide are they, what is detected.

    python benchmarks/uq_coverage.py [--cases 100] [--case-seed 4201] [--absent 0.333]
                                     [--healthy 20] [--uq-calibration FILE] [--uncertainty laplace]

Smallest run (the smoke test): ``--cases 2 --healthy 1 --pop-size 4 --generations 1 --no-polish``.
Reported in BENCHMARKS.md, "Uncertainty" (and the healthy false detections under "Detection").

Cases: DESIGN §7 ranges (`emaphm.faults.random_faults`) from --case-seed, a seed of this script's
own (the interval calibration draws from 4101, bench_multifault from 2611); each fault but k7 is
absent (healthy) with probability --absent, so that spurious detections can be counted. Case i
is identified once, as ``emaphm identify --true-faults K --seed i+1 --json`` does.

Printed, per fault and pooled:
- coverage: the fraction of true values inside [ci90_low, ci90_high] (k7 on the circle, scored
  only where the true eccentricity is >= 0.05, as its direction means little below);
- the median half-width of the intervals (k7: of the arc; the whole circle counts 0.5);
- spurious detections: faults whose truth is healthy but whose verdict is "present", over all
  such faults; and how many of them were "cannot tell";
- detections of the faults that are present (verdict "present"), for the sensitivity;
- the eccentricity direction flagged ``phase_undefined`` where the true eccentricity is < 0.01;
- the extra wall time of the uncertainty step per identification;
- with --healthy N: false detections on N healthy runs (seeds 2000..), as the detection
  thresholds' own benchmark counts them, now with the interval rule.
"""

from __future__ import annotations

import argparse
import statistics

import numpy as np
from _cases import (  # benchmarks/ first on sys.path
    BUDGET,
    add_settings,
    budget_text,
    covers,
    draw_cases,
    machine_line,
    settings_of,
)

import emaphm
from emaphm import FAULT_NAMES, HEALTHY

SETTINGS = (*BUDGET, "optimizer", "start")  # the identification's settings this benchmark sets


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=100)
    parser.add_argument("--case-seed", type=int, default=4201)
    parser.add_argument("--absent", type=float, default=1 / 3)
    parser.add_argument("--healthy", type=int, default=20)
    parser.add_argument("--uq-calibration", default=None)
    parser.add_argument("--uncertainty", default="laplace", choices=("laplace", "mcmc"))
    add_settings(parser, SETTINGS)
    args = parser.parse_args(argv)
    print(machine_line(f"{args.cases} cases (seed {args.case_seed}, absent {args.absent:.3f}), "
                       f"uncertainty {args.uncertainty}, interval calibration {args.uq_calibration or 'packaged'}, "
                       f"{budget_text(args)}, optimizer {args.optimizer or 'default'}"))  # fmt: skip
    cases = draw_cases(args.cases, args.case_seed, absent=args.absent)
    inside, scored, half, uq_walls, errs = [], [], [], [], []
    spurious = unsure_zero = zero_faults = found = present_faults = 0
    undefined = small_zeta = 0
    for i, k in enumerate(cases):
        r = emaphm.identify(
            true_faults=k, seed=i + 1, uncertainty=args.uncertainty, uq_calibration=args.uq_calibration,
            **settings_of(args, SETTINGS),
        )  # fmt: skip
        if r.uncertainty is None:
            print(f"{i:>4} does not fit (NRMSE {r.fit_nrmse}): no intervals", flush=True)
            continue
        u = r.uncertainty
        ok = covers(u.ci90_low, u.ci90_high, k)
        mask = np.ones(8, dtype=bool)
        mask[6] = k[5] >= 0.05
        inside.append(ok)
        scored.append(mask)
        half.append(u.half_width())
        uq_walls.append(u.details["wall_time_s"])
        errs.append(r.percent_error)
        if k[5] < 0.01:
            small_zeta += 1
            undefined += "phase_undefined" in u.flags[6]
        verdicts = r.fault_verdicts or {}
        for j, name in enumerate(FAULT_NAMES):
            if name not in verdicts:
                continue
            if k[j] == HEALTHY[j]:
                zero_faults += 1
                spurious += verdicts[name] == "present"
                unsure_zero += verdicts[name] == "cannot tell"
            else:
                present_faults += 1
                found += verdicts[name] == "present"
        missed = [f"k{j + 1}" for j in range(8) if mask[j] and not ok[j]]
        print(f"{i:>4} %err {r.percent_error:5.2f}  outside: {' '.join(missed) or '-':<20} "
              f"present: {' '.join(r.detected) or '-'}", flush=True)  # fmt: skip
    inside_a, scored_a, half_a = np.array(inside), np.array(scored), np.array(half)
    n = len(inside_a)
    print()
    print(f"{'fault':<20} {'coverage':>8} {'scored':>6} {'median half-width':>18}")
    for j, name in enumerate(FAULT_NAMES):
        s = scored_a[:, j]
        cov = inside_a[s, j].mean() if s.any() else float("nan")
        width = float(np.median(half_a[s, j])) if s.any() else float("nan")
        print(f"k{j + 1} {name:<17} {cov:>8.3f} {int(s.sum()):>6} {width:>18.4f}")
    pooled = inside_a[scored_a].mean()
    print(f"pooled coverage {pooled:.3f} over {int(scored_a.sum())} intervals of {n} cases; "
          f"%err median {statistics.median(errs):.2f}")  # fmt: skip
    print(f"spurious detections: {spurious} of {zero_faults} healthy faults ({100 * spurious / max(zero_faults, 1):.1f} %); "
          f"'cannot tell' {unsure_zero}; faults present detected: {found} of {present_faults}")  # fmt: skip
    print(
        f"eccentricity direction flagged phase_undefined: {undefined} of {small_zeta} cases with true zeta < 0.01"
    )
    print(f"extra wall time of the uncertainty step: median {1000 * statistics.median(uq_walls):.0f} ms, "
          f"max {1000 * max(uq_walls):.0f} ms")  # fmt: skip
    if args.healthy:
        alarms = 0
        for s in range(2000, 2000 + args.healthy):
            r = emaphm.identify(
                true_faults=HEALTHY, seed=s, uq_calibration=args.uq_calibration, **settings_of(args, SETTINGS)
            )
            alarms += bool(r.detected)
            if r.detected:
                print(f"healthy seed {s}: reported {', '.join(r.detected)}", flush=True)
        print(f"healthy actuator: {alarms} false detections in {args.healthy} noisy runs")


if __name__ == "__main__":
    main()
