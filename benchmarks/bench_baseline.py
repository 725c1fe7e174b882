"""Each actuator's own baseline (issue 33): diagnoses of toleranced actuators with and without it.

    python benchmarks/bench_baseline.py [--actuators 6] [--cases 4] [--tolerance 0.02]
                                        [--gain-spread 0.0] [--seed 3307] [--healthy 1]
                                        [--params FILE --calibration CAL --uq-calibration UQ --detection DET]

Each actuator is drawn about the nameplate (`tolerances.drawn_actuator`: R_s, L_s, ψ_m, J_m, J_u,
F_S0, F_D0 each uniform within ±--tolerance, the twin's integration step one of 0.5, 1, 2 µs) with,
with --gain-spread G, a current sensor whose gain is uniform in 1 ± G. Three healthy recordings of
it (the FDI chirp, noise on, their own seeds) make its baseline (``emaphm baseline``, timed); then
--cases random multi-fault cases (DESIGN §7 ranges, a third of the faults absent) and --healthy
healthy runs of it are identified twice, as ``emaphm identify --reference REC --seed 1`` with the
nameplate's files and with ``--baseline DIR``. Printed per run and in summary, both ways: %err
median / p90 / max, the pooled coverage of the 90 % intervals (k7 where ζ >= 0.05), runs above
5 %err with verdict "fits", the verdicts, healthy runs with a detection; and the baseline's wall
time.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np
from _cases import (  # benchmarks/ first on sys.path
    add_settings,
    covers,
    machine_line,
    resolve_params,
    settings_of,
    spread,
)

import emaphm
from emaphm.baseline import baseline
from emaphm.faults import random_faults
from emaphm.models import HighFidelityEma
from emaphm.results import SimResult
from emaphm.tolerances import drawn_actuator

STEPS = (5e-7, 1e-6, 2e-6)


class Tally:
    def __init__(self) -> None:
        self.errs: list[float] = []
        self.inside: list[np.ndarray] = []
        self.verdicts: list[str] = []
        self.fits_bad = 0
        self.healthy_detections = 0

    def add(self, r: emaphm.IdentificationResult, k: np.ndarray) -> str:
        err = emaphm.percent_error(r.estimate, k)
        self.errs.append(err)
        self.verdicts.append(r.verdict)
        self.fits_bad += err > 5.0 and r.verdict == "fits"
        cov = "-"
        if r.uncertainty is not None:
            mask = np.ones(8, dtype=bool)
            mask[6] = k[5] >= 0.05
            ok = covers(r.uncertainty.ci90_low, r.uncertainty.ci90_high, k)[mask]
            self.inside.append(ok)
            cov = f"{ok.mean():.2f}"
        return f"{err:6.2f} {100 * r.fit_nrmse:5.2f}% {cov:>4} {r.verdict:<9}"

    def summary(self, name: str) -> str:
        pooled = np.concatenate(self.inside) if self.inside else np.array([np.nan])
        return (f"{name}: %err {spread(self.errs)}; intervals hold the truth {pooled.mean():.3f}; runs above 5 %err "
                f"with 'fits' {self.fits_bad} of {len(self.errs)}; verdicts "
                + ", ".join(f"{v} {self.verdicts.count(v)}" for v in ("fits", "doubtful", "does not fit"))
                + f"; healthy runs with a detection {self.healthy_detections}")  # fmt: skip


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--actuators", type=int, default=6)
    parser.add_argument("--cases", type=int, default=4)
    parser.add_argument("--healthy", type=int, default=1)
    parser.add_argument("--tolerance", type=float, default=0.02)
    parser.add_argument("--gain-spread", type=float, default=0.0)
    parser.add_argument("--seed", type=int, default=3307)
    parser.add_argument("--params", default=None)
    parser.add_argument("--calibration", default=None)
    parser.add_argument("--uq-calibration", default=None)
    parser.add_argument("--detection", default=None)
    add_settings(parser)
    args = parser.parse_args(argv)
    nameplate = resolve_params(args.params)
    thresholds = None
    if args.detection:
        from emaphm.identification.detection import load_thresholds

        thresholds = dict(load_thresholds(args.detection)["thresholds"])
    print(machine_line(
        f"{args.actuators} actuators (seed {args.seed}) within ±{args.tolerance:g}, sensor gain 1 ± {args.gain_spread:g}, "
        f"steps {STEPS}; {args.cases} cases + {args.healthy} healthy each; nameplate {args.params or 'nominal'}"))  # fmt: skip
    work = Path(tempfile.mkdtemp(prefix="bench-baseline-"))
    plain, based, walls = Tally(), Tally(), []
    rng = np.random.default_rng([args.seed, 1])
    for a in range(args.actuators):
        plant = drawn_actuator(nameplate, 1000 * args.seed + a, tolerance=args.tolerance, steps=STEPS)
        gain = 1.0 + rng.uniform(-args.gain_spread, args.gain_spread)

        def recorded(k: np.ndarray, seed: int, plant=plant, gain=gain) -> SimResult:
            trace = HighFidelityEma(plant).simulate(k, seed=seed)
            return SimResult(t=trace.t, signals={**trace.signals, "i_q": gain * trace.signals["i_q"]},
                             metadata=trace.metadata)  # fmt: skip

        paths = []
        for s in range(3):
            path = work / f"a{a}-healthy{s}.h5"
            emaphm.write_trace(recorded(np.array(emaphm.HEALTHY, dtype=float), 10_000 * a + s), path)
            paths.append(path)
        start = time.perf_counter()
        folder = baseline(paths, work / f"a{a}", params=args.params, calibration=args.calibration,
                          uq_calibration=args.uq_calibration, detection=args.detection)  # fmt: skip
        walls.append(time.perf_counter() - start)
        print(f"actuator {a}: sensor gain {gain:.3f}, baseline {walls[-1]:.1f} s", flush=True)
        cases = [*random_faults(args.cases, 1000 * args.seed + a, absent=1 / 3)]
        cases += [np.array(emaphm.HEALTHY, dtype=float)] * args.healthy
        for j, k in enumerate(cases):
            trace = recorded(k, 20_000 * a + j)
            r0 = emaphm.identify(reference=trace, seed=1, params=args.params, calibration=args.calibration,
                                 uq_calibration=args.uq_calibration, thresholds=thresholds, **settings_of(args))  # fmt: skip
            r1 = emaphm.identify(reference=trace, seed=1, baseline=folder, **settings_of(args))
            healthy = j >= args.cases
            if healthy:
                plain.healthy_detections += bool(r0.detected)
                based.healthy_detections += bool(r1.detected)
            line = f"  {'healthy' if healthy else f'case {j}':>7}  nameplate {plain.add(r0, k)}  baseline {based.add(r1, k)}"
            print(line + (f"  detected: {','.join(r0.detected) or '-'} / {','.join(r1.detected) or '-'}" if healthy else ""),
                  flush=True)  # fmt: skip
    print()
    print(plain.summary("nameplate"))
    print(based.summary("baseline "))
    print(f"baseline wall time (three 1 s recordings): median {np.median(walls):.1f} s, max {max(walls):.1f} s")


if __name__ == "__main__":
    main()
