# Study, not a benchmark (issue 34): the current's scale γ the monitor refits, on the twin, on
# actuators drawn about it, on an FOC drive and with a current sensor's gain; `identification/limits.py`
# (CURRENT_SCALE_SPREAD) and `identification/current_scale.py` quote it.
"""The current's scale γ (`current_scale`) on random twin cases, with and without a sensor gain.

    python studies/current_scale.py [--cases 30] [--seed 2611] [--gains 1.0] [--tolerance 0.02 --steps 5e-7,1e-6,2e-6]
                                    [--params FILE --calibration CAL --uq-calibration UQ] [--drive-tolerance 0.1]

Random multi-fault cases (a third of the faults absent) run on the HF twin (noise on; drawn about
the actuator with --tolerance / --steps), their currents × each gain, identified with the default
settings (seed 1). Per run, from the result's ``settings["current_scale"]``: the verdict, %err, γ,
the fit ratio (the unscaled refit's Σ w·e² over the scaled one's; "-" where γ is within 1 % of 1,
not compared), the shorts' smallest estimate (their common part), %err of the scaled refit's faults, the shorts
detected ("!" where the truth has none) and whether the scale made the result doubtful. Summary per gain: the runs flagged, and |γ − 1| where the scaled
refit fits at least as well (ratio ≥ 1) and where it does not.
"""

from __future__ import annotations

import argparse

import numpy as np

import emaphm
from emaphm.faults import FAULT_NAMES, random_faults
from emaphm.identification.current_scale import SHORTS
from emaphm.models import HighFidelityEma
from emaphm.results import SimResult
from emaphm.tolerances import drawn_actuator


def shorts_said(detected: list[str], truth: np.ndarray) -> str:
    """The shorts detected, a false one (the truth's is 0) marked with '!': 'b,c!' or '-'."""
    names = [FAULT_NAMES[i] for i in SHORTS]
    said = [n[-1] + ("!" if truth[i] == 0 else "") for n, i in zip(names, SHORTS, strict=True) if n in detected]
    return ",".join(said) or "-"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=30)
    parser.add_argument("--seed", type=int, default=2611)
    parser.add_argument("--gains", default="1.0", help="comma-separated sensor gains on the currents")
    parser.add_argument("--tolerance", type=float, default=0.0)
    parser.add_argument("--steps", default="", help="the twin's integration steps to draw from [s]")
    parser.add_argument("--drive-tolerance", type=float, default=0.0, help="an FOC drive's PI gains within ±this")
    parser.add_argument("--params", default=None)
    parser.add_argument("--calibration", default=None)
    parser.add_argument("--uq-calibration", default=None)
    args = parser.parse_args(argv)
    params = emaphm.load_params(args.params) if args.params else emaphm.EmaParams()
    steps = tuple(float(s) for s in args.steps.split(",") if s)
    given = {"params": args.params, "calibration": args.calibration, "uq_calibration": args.uq_calibration}
    given = {k: v for k, v in given.items() if v is not None}
    gains = [float(g) for g in args.gains.split(",")]
    rows: dict[float, list[tuple[float, float, bool]]] = {g: [] for g in gains}
    print(f"# emaphm {emaphm.__version__}, {vars(args)}", flush=True)
    for j, k in enumerate(random_faults(args.cases, args.seed, absent=1 / 3)):
        drawn = args.tolerance or steps or args.drive_tolerance
        plant = (
            drawn_actuator(params, 1000 + j, tolerance=args.tolerance, drive_tolerance=args.drive_tolerance, steps=steps)
            if drawn
            else params
        )
        trace = HighFidelityEma(plant).simulate(k, seed=j)
        for g in gains:
            currents = {n: g * v for n, v in trace.signals.items() if n.startswith("i_")}
            recording = SimResult(t=trace.t, signals={**trace.signals, **currents})
            r = emaphm.identify(reference=recording, seed=1, **given)
            if r.settings.get("current_scale") is None:
                print(f"{j:3d} gain {g:.3f}: {r.verdict}, no scale refit", flush=True)
                continue
            s = r.settings["current_scale"]
            flagged = any("measured current is" in d for d in r.doubts)
            rows[g].append((s["gain"], s["fit_ratio"], flagged))
            print(f"{j:3d} gain {g:.3f}: {r.verdict:<12} %err {emaphm.percent_error(r.estimate, k):6.2f}  "
                  f"γ {s['gain']:.4f}  ratio {'-' if s['fit_ratio'] is None else format(s['fit_ratio'], '7.3f'):>7}  common short {min(r.estimate[list(SHORTS)]):.3f}  "
                  f"%err scaled {emaphm.percent_error(s['faults_if_scaled'], k):6.2f}  "
                  f"shorts detected {shorts_said(r.detected, k)}  "
                  f"{'SCALE DOUBTFUL' if flagged else ''}", flush=True)  # fmt: skip
    for g, got in rows.items():
        if not got:
            continue
        a = np.array([(x, np.nan if y is None else y) for x, y, _ in got], dtype=np.float64)
        near = np.isnan(a[:, 1])  # within 1 % of 1: not compared (no reason for "doubtful" can hold)
        same, worse = np.abs(a[~near & (a[:, 1] >= 1), 0] - 1), np.abs(a[~near & (a[:, 1] < 1), 0] - 1)
        print(f"gain {g:.3f}: {sum(f for *_, f in got)} of {len(got)} made doubtful by the scale; {near.sum()} within "
              f"1 %; |γ - 1| where the scaled refit fits as well: max {100 * same.max(initial=0):.2f} % ({len(same)} "
              f"runs), where it fits worse: max {100 * worse.max(initial=0):.2f} % ({len(worse)}); fit ratio max "
              f"{np.nanmax(a[:, 1], initial=0):.3f}")  # fmt: skip


if __name__ == "__main__":
    main()
