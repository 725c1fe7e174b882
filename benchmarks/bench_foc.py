"""Identification on a field-oriented-control drive off its twin (issue 32): accuracy, intervals, verdicts.

    python benchmarks/bench_foc.py --params FOC.toml --calibration CAL.json [--uq-calibration UQ.json]
                                   [--detection DETECTION.json]
                                   [--cases 12] [--seeds 2] [--case-seed 3203] [--healthy 3]
                                   [--drive-tolerance 0.1] [--tolerance 0.0] [--steps 5e-7,1e-6,2e-6]
                                   [--last-stage auto|switching|none] [--command chirp]

Smallest run (the smoke test): ``--cases 1 --seeds 1 --healthy 0 --pop-size 4 --generations 1
--no-polish --last-stage none`` (with the nominal actuator when --params is left out). Reported in
BENCHMARKS.md, "FOC drive".

The monitor is calibrated on the actuator file's nameplate (``emaphm calibrate --params FOC.toml``);
every measurement comes from an actuator drawn about it (`_cases.drawn_actuator`, one per case and
seed): the PI gains each within ±--drive-tolerance, the PWM carrier at a random phase, the twin's
integration step one of --steps, and with --tolerance the motor and drive-train constants (R_s, L_s,
ψ_m, J_m, J_u, F_S0, F_D0) within ±T. So the diagnosis is scored on plants that share the monitor's
drive description but not the details a twin happens to share with it. Cases: DESIGN §7 ranges
(`emaphm.faults.random_faults`) from --case-seed (this script's own), each identified as
``emaphm identify --reference REC --params FOC.toml --calibration CAL.json --seed S`` would.
--healthy N adds N healthy actuators (drawn the same way) and counts those with a detection.

Printed per run and in summary: %err (DESIGN §5), the fit NRMSE, the verdict and the warnings,
the faults outside their 90 % interval (k7 scored where the eccentricity is >= 0.05) and the
reasons of a "doubtful" verdict; then %err median / p90 / max, the pooled coverage, runs above 5
%err with verdict "fits" (and of them those without a warning), the verdicts' counts and the runs
at <= 2 %err flagged doubtful, healthy actuators with a detection. --command runs the twin on
another of the calibration's commands.
"""

from __future__ import annotations

import argparse

import numpy as np
from _cases import (  # benchmarks/ is the script's folder, first on sys.path
    BUDGET,
    CALIBRATION_COMMANDS,
    add_settings,
    budget_text,
    covers,
    draw_cases,
    drawn_actuator,
    load_thresholds,
    machine_line,
    noise_seed_of,
    params_hash,
    resolve_params,
    settings_of,
    spread,
)

import emaphm

SETTINGS = (*BUDGET, "optimizer", "start", "last_stage")


def steps_of(text: str) -> tuple[float, ...]:
    return tuple(float(s) for s in text.split(",") if s.strip())


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--params", default=None, help="FOC actuator file (default: the nominal actuator)")
    parser.add_argument("--calibration", default=None, help="its monitor calibration (default: packaged)")
    parser.add_argument("--uq-calibration", default=None, help="its interval calibration (default: packaged)")
    parser.add_argument("--detection", default=None, help="its detection thresholds (default: packaged)")
    parser.add_argument("--cases", type=int, default=12)
    parser.add_argument("--seeds", type=int, default=2)
    parser.add_argument("--case-seed", type=int, default=3203)
    parser.add_argument("--healthy", type=int, default=3)
    parser.add_argument("--drive-tolerance", type=float, default=0.1)
    parser.add_argument("--tolerance", type=float, default=0.0)
    parser.add_argument("--command", choices=sorted(CALIBRATION_COMMANDS), default="chirp")
    parser.add_argument(
        "--steps", type=steps_of, default=(5e-7, 1e-6, 2e-6), help="twin steps [s], comma-separated"
    )
    add_settings(parser, SETTINGS)
    args = parser.parse_args(argv)
    params = resolve_params(args.params)
    print(machine_line(
        f"{args.cases} cases (seed {args.case_seed}) x {args.seeds} seeds + {args.healthy} healthy; actuator "
        f"{args.params or 'nominal'} ({params_hash(params)}, control {params.inverter.control}), calibration "
        f"{args.calibration or 'packaged'}, intervals {args.uq_calibration or 'packaged'}, detection "
        f"{args.detection or 'packaged'}; plants: PI ±"
        f"{args.drive_tolerance:g}, constants ±{args.tolerance:g}, steps {args.steps}; {budget_text(args)}, "
        f"last stage {args.last_stage}, command {args.command}"))  # fmt: skip

    thresholds = None if args.detection is None else dict(load_thresholds(args.detection)["thresholds"])

    def run(k: np.ndarray, case: int, seed: int) -> emaphm.IdentificationResult:
        plant = drawn_actuator(params, 7919 * case + seed, tolerance=args.tolerance,
                               drive_tolerance=args.drive_tolerance, steps=args.steps)  # fmt: skip
        trace = emaphm.HighFidelityEma(plant, CALIBRATION_COMMANDS[args.command]).simulate(
            k, seed=noise_seed_of(seed)
        )
        return emaphm.identify(
            reference=trace, seed=seed, params=params, calibration=args.calibration,
            uq_calibration=args.uq_calibration, thresholds=thresholds, **settings_of(args, SETTINGS),
        )  # fmt: skip

    errs, fits, inside, fits_bad, unwarned_bad, verdicts = [], [], [], 0, 0, []
    print(f"{'case':>4} {'seed':>4} {'%err':>6} {'fit':>6}  {'verdict':<13} {'warn':>4}  outside")
    for j, k in enumerate(draw_cases(args.cases, args.case_seed)):
        for s in range(1, args.seeds + 1):
            r = run(k, j, s)
            err = emaphm.percent_error(r.estimate, k)
            errs.append(err)
            fits.append(r.fit_nrmse)
            verdicts.append(r.verdict)
            missed = "-"
            if r.uncertainty is not None:
                ok = covers(r.uncertainty.ci90_low, r.uncertainty.ci90_high, k)
                mask = np.ones(8, dtype=bool)
                mask[6] = k[5] >= 0.05
                inside.append(ok[mask])
                missed = " ".join(f"k{i + 1}" for i in range(8) if mask[i] and not ok[i]) or "-"
            bad = err > 5.0 and r.verdict == "fits"
            fits_bad += bad
            unwarned_bad += bad and not r.warnings
            print(f"{j:>4} {s:>4} {err:>6.2f} {100 * r.fit_nrmse:>5.2f}%  {r.verdict:<13} {len(r.warnings):>4}  {missed}"
                  + "".join(f"\n           doubtful: {d}" for d in r.doubts), flush=True)  # fmt: skip
    detections = 0
    for h in range(args.healthy):
        r = run(np.array(emaphm.HEALTHY, dtype=float), 10_000 + h, 1)
        detections += bool(r.detected)
        print(
            f"healthy {h}: fit {100 * r.fit_nrmse:.2f}%, {r.verdict}, detected: {' '.join(r.detected) or '-'}",
            flush=True,
        )
    n = len(errs)
    print()
    print(f"%err over {n} runs: {spread(errs)}")
    print(f"fit NRMSE: {spread(fits, 100, ' %')}")
    pooled = np.concatenate(inside) if inside else np.array([])
    print(f"90 % intervals hold the truth: {pooled.mean() if pooled.size else float('nan'):.3f} "
          f"({pooled.size} intervals of {len(inside)} runs with intervals)")  # fmt: skip
    print(f"runs above 5 %err with verdict 'fits': {fits_bad} of {n} (without a warning: {unwarned_bad})")
    good = [v for e, v in zip(errs, verdicts, strict=True) if e <= 2.0]
    print(f"verdicts: {', '.join(f'{v} {verdicts.count(v)}' for v in ('fits', 'doubtful', 'does not fit'))}; "
          f"runs at <= 2 %err flagged doubtful: {good.count('doubtful')} of {len(good)}")  # fmt: skip
    print(f"healthy actuators with a detection: {detections} of {args.healthy}")


if __name__ == "__main__":
    main()
