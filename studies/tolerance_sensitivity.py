"""Issue 34: which of a drawn actuator's constants moves the estimate, and does the monitor know it?

    python studies/tolerance_sensitivity.py [--case 8] [--seed 1] [--case-seed 3307] [--across 8]

One run of ``benchmarks/bench_foc.py --tolerance 0.02 --case-seed 3307`` (its case `--case`, seed
`--seed`: the same drawn actuator and noise), identified as that benchmark does with the
nameplate's files: the whole drawn actuator, then the nameplate with only the integration step,
only F_S0, only F_D0, only J_m and J_u, only ψ_m, only R_s and L_s of it drawn. Prints each
run's friction k1 and k_P drift k8 against the truth, with k1's interval. Then the monitor's own
answer to the same F_D0 change: its current at the truth with F_D0 scaled, identified by the
nameplate's monitor (no twin, no noise): what the linearised widening for the constants
(`identification/uncertainty/constants.py`) rests on.

Then, over `--across` random cases (seed 4401, nameplate actuator), F_D0 −2 % alone: the change
of k1 on the twin (the same noise seed with and without it) against the monitor's own change and
the scaling law. One case's ratio is not the drive's: the twin's changes include the search's
scatter between two recordings.
"""

from __future__ import annotations

import argparse
import dataclasses as dc
import sys
from pathlib import Path


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--case", type=int, default=8)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--case-seed", type=int, default=3307)
    parser.add_argument("--across", type=int, default=8, help="random cases for F_D0 -2 %% alone (0: none)")
    args = parser.parse_args(argv)
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
    from _cases import CALIBRATION_COMMANDS, draw_cases, drawn_actuator, noise_seed_of, resolve_params

    import emaphm
    from emaphm.constants import apply
    from emaphm.models import MonitorEma
    from emaphm.models.lf import resolve_calibration

    nameplate = resolve_params(None)
    k = draw_cases(args.case + 1, args.case_seed)[args.case]
    drawn = drawn_actuator(nameplate, 7919 * args.case + args.seed, tolerance=0.02, drive_tolerance=0.1,
                           steps=(5e-7, 1e-6, 2e-6))  # fmt: skip

    def only(transmission: tuple[str, ...] = (), motor: tuple[str, ...] = ()):  # noqa: ANN202
        tr = dc.replace(nameplate.transmission, **{n: getattr(drawn.transmission, n) for n in transmission})
        mo = dc.replace(nameplate.motor, **{n: getattr(drawn.motor, n) for n in motor})
        return dc.replace(nameplate, transmission=tr, motor=mo, inverter=drawn.inverter, controller=drawn.controller)

    ratio = {n: getattr(drawn.transmission, n) / getattr(nameplate.transmission, n) - 1 for n in ("F_S0", "F_D0", "J_m", "J_u")}
    ratio |= {n: getattr(drawn.motor, n) / getattr(nameplate.motor, n) - 1 for n in ("psi_m", "R_s", "L_s")}
    print("drawn: " + ", ".join(f"{n} {100 * v:+.2f} %" for n, v in ratio.items()))
    variants = {
        "all drawn": drawn, "the step only": only(), "F_S0": only(("F_S0",)), "F_D0": only(("F_D0",)),
        "J_m, J_u": only(("J_m", "J_u")), "psi_m": only(motor=("psi_m",)), "R_s, L_s": only(motor=("R_s", "L_s")),
    }  # fmt: skip
    for name, plant in variants.items():
        trace = emaphm.HighFidelityEma(plant, CALIBRATION_COMMANDS["chirp"]).simulate(k, seed=noise_seed_of(args.seed))
        r = emaphm.identify(reference=trace, seed=args.seed)
        lo, hi = r.uncertainty.ci90_low[0], r.uncertainty.ci90_high[0]
        print(f"{name:<14} k1 {r.estimate[0]:.4f} ({r.estimate[0] - k[0]:+.4f}) on [{lo:.4f}, {hi:.4f}]  "
              f"k8 {r.estimate[7]:+.4f} ({r.estimate[7] - k[7]:+.4f})  %err {emaphm.percent_error(r.estimate, k):.2f}",
              flush=True)  # fmt: skip
    calibration = resolve_calibration(None)
    params, cal = apply(nameplate, calibration, {"F_D0": 1.0 + ratio["F_D0"]})
    record = {**cal.record, "settings": {**cal.record.get("settings", {}), "params": params.to_dict()}}
    run = MonitorEma(params, calibration=dc.replace(cal, record=record)).simulate(k)
    r = emaphm.identify(reference=run, seed=1, last_stage="none", uncertainty="none")
    print(f"the monitor's own current with F_D0 {100 * ratio['F_D0']:+.2f} %: k1 {r.estimate[0]:.4f} "
          f"({r.estimate[0] - k[0]:+.4f}; the scaling F_D = F_D0 (1 + 2 k1) gives "
          f"{ratio['F_D0'] * (1 + 2 * k[0]) / 2:+.4f})")
    _across(args.across, nameplate, calibration)


def _across(n: int, nameplate, calibration) -> None:  # noqa: ANN001
    """F_D0 −2 % alone on `n` random cases: the twin's change of k1 against the monitor's (the docstring)."""
    import numpy as np
    from _cases import CALIBRATION_COMMANDS, draw_cases, noise_seed_of

    import emaphm
    from emaphm.constants import apply
    from emaphm.models import MonitorEma

    params, cal = apply(nameplate, calibration, {"F_D0": 0.98})
    lowered = MonitorEma(params, calibration=dc.replace(cal, record={
        **cal.record, "settings": {**cal.record.get("settings", {}), "params": params.to_dict()}}))  # fmt: skip
    plant = dc.replace(nameplate, transmission=dc.replace(nameplate.transmission, F_D0=0.98 * nameplate.transmission.F_D0))
    ratios = []
    for j, k in enumerate(draw_cases(n, 4401) if n else []):
        def k1(reference, **kw):  # noqa: ANN001, ANN003, ANN202
            return emaphm.identify(reference=reference, seed=1, uncertainty="none", **kw).estimate[0]

        twin = [k1(emaphm.HighFidelityEma(p, CALIBRATION_COMMANDS["chirp"]).simulate(k, seed=noise_seed_of(1)))
                for p in (nameplate, plant)]  # fmt: skip
        mon = [k1(m.simulate(k), last_stage="none") for m in (MonitorEma(nameplate), lowered)]
        d_twin, d_mon = twin[1] - twin[0], mon[1] - mon[0]
        ratios.append(d_twin / d_mon)
        print(f"case {j} (k1 {k[0]:.3f}): F_D0 -2 % moves k1 by {d_twin:+.4f} on the twin, {d_mon:+.4f} in the "
              f"monitor (scaling {-0.02 * (1 + 2 * k[0]) / 2:+.4f}): {ratios[-1]:.2f} x", flush=True)  # fmt: skip
    if ratios:
        print(f"twin / monitor over {len(ratios)} cases: median {np.median(ratios):.2f}, {min(ratios):.2f} to {max(ratios):.2f}")


if __name__ == "__main__":
    main()
