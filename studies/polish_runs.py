"""Issue 36: where the polish stage's monitor runs go, descent by descent.

    python studies/polish_runs.py [--case-seed 5151] [--cases 9] [--seed 1]

The Table 1 case and --cases random ones (`emaphm.faults.random_faults` of --case-seed), each as
``emaphm identify --true-faults K --seed S``. For each, it prints every call of the in-house
least-squares descents (`lm.levenberg_marquardt_many`: the best point's descent in the
preconditioned polish, the runner-ups, the last polishes, the current's scale refits) as each
descent's trial points, difference Jacobians (n rows each), stop and final eq. 3. It also prints
the whitened CMA-ES of the best point's polish: its generations, its end over the descent's end,
and the first generation within 5 % / 1 % / 0.1 % of its end. Last come the polish stage's
winner (0: the best point), the evaluations and the %err.

The tenth session's "before" figures (runner-ups 140–150 runs, 88–136 of them on Jacobians; the
CMA-ES with nothing below its descent's end in 6 of 10 cases) are this study at 8e2e5ef, where
the secant options do not exist yet (its `lm` has the same entry points).
"""

from __future__ import annotations

import argparse

import numpy as np

TABLE1 = [0.2383, 0.5003, 0.0, 0.4503, 0.0404, 0.0028, 0.2785, 0.5]


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--case-seed", type=int, default=5151)
    parser.add_argument("--cases", type=int, default=9)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args(argv)
    import emaphm
    from emaphm.faults import random_faults
    from emaphm.identification import descents, lm, polish

    calls: list[list[tuple[int, int, str, float]]] = []
    cma: list[np.ndarray] = []
    many = lm.levenberg_marquardt_many

    def counted_many(*a, **k):  # type: ignore[no-untyped-def]
        results = many(*a, **k)
        calls.append([(r.nfev, r.njev, r.status, r.f) for r in results])
        return results

    lm.levenberg_marquardt_many = descents.levenberg_marquardt_many = counted_many
    preconditioned = polish.preconditioned_polish

    def with_history(evaluate, residuals, start, **k):  # type: ignore[no-untyped-def]
        run = preconditioned(evaluate, residuals, start, **k)
        cma.append(np.asarray(run.history[len(start.history) :]))  # the descent's end, then one per generation
        return run

    polish.preconditioned_polish = with_history
    cases = [np.asarray(TABLE1), *random_faults(args.cases, args.case_seed)]
    for i, k in enumerate(cases):
        calls.clear()
        cma.clear()
        run = emaphm.identify(true_faults=k, seed=args.seed)
        print(f"case {i}{' (Table 1)' if i == 0 else ''}: {run.evaluations} evaluations, {run.percent_error:.2f} %err, "
              f"polish winner {run.stage('polish')['candidate']}")  # fmt: skip
        for c in calls:
            print("   descents (trials, Jacobians, stop, f):", ", ".join(f"({a}, {b}, {s}, {f:.5f})" for a, b, s, f in c))
        if cma:
            h = cma[0]
            within = {q: int(np.argmax(h <= h[-1] * q)) for q in (1.05, 1.01, 1.001)}
            print(f"   CMA-ES: {len(h) - 1} generations, end / descent's end {h[-1] / h[0]:.4f}, "
                  f"first within 5 / 1 / 0.1 %: {within[1.05]} / {within[1.01]} / {within[1.001]}")  # fmt: skip


if __name__ == "__main__":
    main()
