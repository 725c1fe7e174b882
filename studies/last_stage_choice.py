# Study, not a benchmark (issue 31, review L3): written at the commit that changed the choice; its
# figures are in the commit message and the closing note (24 chirp cases of seed 6061).
"""Which iterate the switching last stage should keep: rules compared on the same iterates.

    python studies/last_stage_choice.py [--cases 24] [--case-seed 6061] [--seeds 1] [--tolerance 0.02]

Each random case (DESIGN §7 ranges, `random_faults(cases, case-seed)`) is measured by the twin as
``emaphm identify --true-faults K --seed S`` measures it and identified with the defaults; the
last stage's iterates are captured and each rule's choice scored by %err: the switching model's
eq. 3 alone (the rule before review L3), its sum with the corrected monitor's under the last
correction (the rule now), the corrected monitor's alone, the last iterate, the search's estimate.
With --tolerance T the twin of each case is an actuator the monitor was not calibrated for: R_s,
L_s, psi_m, J_m, J_u, F_S0 and F_D0 each drawn uniformly within ±T of nominal (seeded by the case),
identified with the nominal actuator and its packaged calibration.
"""

from __future__ import annotations

import argparse
import statistics

import numpy as np

import emaphm
from emaphm.faults import random_faults
from emaphm.identification import last_stage
from emaphm.identification.problem import search_to_faults
from emaphm.identification.recording import split_seed
from emaphm.tolerances import drawn_actuator


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=24)
    parser.add_argument("--case-seed", type=int, default=6061)
    parser.add_argument("--seeds", type=int, default=1)
    parser.add_argument("--tolerance", type=float, default=0.0, help="draw each twin within ±T of nominal")
    args = parser.parse_args(argv)
    captured = []
    original = last_stage.space_mapping

    def capture(*a, **k):  # type: ignore[no-untyped-def]
        stage = original(*a, **k)
        captured.append(stage)
        return stage

    last_stage.space_mapping = capture  # type: ignore[assignment]
    rules = {
        "switching eq. 3 (before)": lambda st: int(np.argmin(st.history)),
        "sum (now)": lambda st: int(np.argmin(np.add(st.history, st.smooth))),
        "corrected monitor": lambda st: int(np.argmin(st.smooth)),
        "last iterate": lambda st: len(st.history) - 1,
        "search's estimate": lambda st: 0,
    }
    errs: dict[str, list[float]] = {name: [] for name in rules}
    twin = emaphm.HighFidelityEma()
    for c, k in enumerate(random_faults(args.cases, args.case_seed)):
        for s in range(1, args.seeds + 1):
            captured.clear()
            if args.tolerance > 0:
                twin = emaphm.HighFidelityEma(drawn_actuator(emaphm.EmaParams(), 1000 * args.case_seed + c, tolerance=args.tolerance))
            trace = twin.simulate(k, noise=True, seed=split_seed(s)[0])
            emaphm.identify(reference=trace, seed=s, uncertainty="none")
            if not captured:
                continue
            stage = captured[-1]
            per_iterate = [emaphm.percent_error(f, k) for f in search_to_faults(np.array(stage.points))]
            for name, rule in rules.items():
                errs[name].append(per_iterate[rule(stage)])
            print(c, s, [round(e, 2) for e in per_iterate], stage.stopped, flush=True)
    for name, e in errs.items():
        print(f"{name:26s} %err median {statistics.median(e):.3f} p90 {np.percentile(e, 90):.3f} max {max(e):.3f} "
              f"(n={len(e)})")  # fmt: skip


if __name__ == "__main__":
    main()
