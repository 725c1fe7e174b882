"""A switching last stage, measured and not built: the estimate polished on the twin at another step (issue 8).

    python benchmarks/switching_polish.py [--cases 8] [--case-seed 2611] [--command chirp]
                                          [--step 2e-6] [--psi 0] [--budget 200]
    python benchmarks/switching_polish.py --step 2e-6,2.5e-6,1.25e-6     # averaged over three steps
    python benchmarks/switching_polish.py --method space-mapping --step 2e-6,2.5e-6,1.25e-6 [--psi 0.005]

Issue 8 suggested a multi-fidelity identification whose last stage runs a slower switching
model for a few hundred evaluations, structurally different from the twin that makes the test
data. Here that model is the twin's own hysteresis drive at another integration step (--step,
2 µs against the twin's 1 µs; `tail_conditioning.py --step` measures how close it is at the
truth), optionally with its magnet flux linkage off by --psi (a model that is not exact).
For each random case: the twin's noisy measurement (noise seed 1000 + case), the default
identification (`FaultIdentifier`, seed 1), then a CMA-ES polish (the `cma` package pymoo
installs; step 0.01, population 10, --budget evaluations) of eq. 3, with the identifier's own
weights and compared samples, on the switching model's current from the identification's
estimate. With several steps (--step 2e-6,2.5e-6,1.25e-6) the switching current is the mean of
the runs at each: a stick–slip realisation of one discretisation is averaged out, so the polish
fits the faults rather than the realisation (each evaluation then costs one run per step; the
budget counts evaluations). --method space-mapping runs instead the identification's own last stage
(`switching.space_mapping`, as ``identify`` does with ``last_stage="switching"``) with this
switching model (its steps, its ψ_m): what the built stage makes of a switching model that is not
exact. Printed per case: %err before and after, and eq. 3 of the switching model at the
truth, at the estimate and at the polished point; then the medians.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import platform
import time

import cma
import numpy as np
from _machine import cpu_model  # benchmarks/ is the script's folder, first on sys.path

import emaphm
from emaphm.calibration.scenarios import CALIBRATION_COMMANDS
from emaphm.faults import random_faults
from emaphm.identification.identify import FaultIdentifier, recentre_phase, search_to_faults
from emaphm.identification.metrics import percent_error
from emaphm.identification.switching import SwitchingModel, space_mapping
from emaphm.models import HighFidelityEma
from emaphm.params import EmaParams


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=8)
    parser.add_argument("--case-seed", type=int, default=2611)
    parser.add_argument("--command", default="chirp", choices=tuple(CALIBRATION_COMMANDS))
    parser.add_argument(
        "--step", default="2e-6", help="the switching model's integration step(s) [s], comma-separated"
    )
    parser.add_argument("--psi", type=float, default=0.0, help="its ψ_m off by this fraction")
    parser.add_argument("--budget", type=int, default=200, help="switching-model evaluations per case")
    parser.add_argument("--method", default="cma", choices=("cma", "space-mapping"), help="the last stage")
    args = parser.parse_args()
    print(f"emaphm {emaphm.__version__}, Python {platform.python_version()}, {os.cpu_count()} cores "
          f"({cpu_model()}); {args.cases} cases (seed {args.case_seed}), command {args.command}; switching "
          f"model: the twin at {args.step} s (averaged), ψ_m × {1 + args.psi:g}; {args.method}"
          + (f", {args.budget} evaluations" if args.method == "cma" else ""))  # fmt: skip
    command = CALIBRATION_COMMANDS[args.command]
    base = EmaParams()
    # the switching model: the twin at each step (ψ_m off by --psi), its current the runs' mean
    model = SwitchingModel(
        dataclasses.replace(
            base, motor=dataclasses.replace(base.motor, psi_m=base.motor.psi_m * (1.0 + args.psi))
        ),
        command,
        [float(s) for s in args.step.split(",")],
    )
    twin = HighFidelityEma(base, command=command)
    before, after = [], []
    for j, k in enumerate(random_faults(args.cases, args.case_seed)):
        measured = twin.simulate(k, noise=True, seed=1000 + j)
        ident = FaultIdentifier(seed=1, last_stage="none").fit(
            measured.t, measured.i_q, command, theta_u=measured.theta_u
        )
        x0, eq3, span = np.array(ident.faults_), ident.objective_, ident.duration_
        if args.method == "space-mapping":
            start = time.perf_counter()
            monitor_ = ident.monitor_  # the stage as the package runs it, with the switching model above

            def lf(k: np.ndarray, m=monitor_, d=span) -> np.ndarray:  # type: ignore[no-untyped-def]
                return m.simulate(k, duration=d).i_q

            def hf(k: np.ndarray, d=span) -> np.ndarray:  # type: ignore[no-untyped-def]
                return model.current(k, duration=d, workers=2)

            stage = space_mapping(
                eq3, ident.residuals, lf, hf, search_to_faults, recentre_phase(ident.run_).x
            )
            f_truth = float(eq3(model.current(k, duration=span, workers=2)))
            before.append(percent_error(x0, k))
            after.append(percent_error(search_to_faults(stage.x[None, :])[0], k))
            print(f"case {j:>3}: %err {before[-1]:5.2f} -> {after[-1]:5.2f}; switching eq. 3 at the truth {f_truth:.4g}, "
                  f"at the estimate {stage.start_fitness:.4g}, iterate {stage.iterate} {stage.fitness:.4g} "
                  f"({time.perf_counter() - start:.1f} s)", flush=True)  # fmt: skip
            continue

        def f(X: np.ndarray, eq3=eq3, span=span) -> np.ndarray:  # type: ignore[no-untyped-def]
            X = np.clip(np.atleast_2d(X), 0.0, 1.0)
            runs = [model.current(x, duration=span) for x in X]
            return np.asarray(eq3(np.array(runs)), dtype=np.float64)

        start = time.perf_counter()
        f0, f_truth = float(f(x0)[0]), float(f(k)[0])
        es = cma.CMAEvolutionStrategy(
            x0, 0.01, {"bounds": [0, 1], "popsize": 10, "maxfevals": args.budget, "seed": 1, "verbose": -9}
        )
        best_x, best_f = x0, f0
        while not es.stop():
            X = es.ask()
            F = f(np.array(X))
            es.tell(X, list(F))
            i = int(np.argmin(F))
            if F[i] < best_f:
                best_x, best_f = np.clip(X[i], 0.0, 1.0), float(F[i])
        before.append(percent_error(x0, k))
        after.append(percent_error(best_x, k))
        print(f"case {j:>3}: %err {before[-1]:5.2f} -> {after[-1]:5.2f}; switching eq. 3 at the truth {f_truth:.4g}, "
              f"at the estimate {f0:.4g}, polished {best_f:.4g} ({time.perf_counter() - start:.1f} s)", flush=True)  # fmt: skip
    b, a = np.array(before), np.array(after)
    print(f"%err median {np.median(b):.2f} -> {np.median(a):.2f}, mean {b.mean():.2f} -> {a.mean():.2f}, "
          f"max {b.max():.2f} -> {a.max():.2f}; better in {int(np.sum(a < b))} of {len(b)}")  # fmt: skip


if __name__ == "__main__":
    main()
