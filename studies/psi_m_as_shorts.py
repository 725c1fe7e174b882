"""Issue 34: a magnet flux off its nameplate, identified without a baseline, against balanced shorts.

    python studies/psi_m_as_shorts.py [--psi -0.02,-0.01,0.01] [--shorts 0.02,0.04] [--seed 5]

A healthy twin whose ψ_m is off the nameplate by each relative `--psi`, and a nameplate twin
with the same short k3 = k4 = k5 in all three phases for each `--shorts`, each recorded with
noise (twin seed `--seed`) and identified as ``emaphm identify --reference REC --seed 1`` does
with the nameplate's files. Prints the three shorts estimated, the fit, the verdict, the faults
detected and the current's scale γ the preconditions refit. A ψ_m low by δ reads as a balanced
short of about δ (BENCHMARKS.md, "Baselines"): without a baseline the two cannot be told apart
below the nameplate's tolerance.
"""

from __future__ import annotations

import argparse
import dataclasses


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--psi", default="-0.02,-0.01,0.01", help="relative ψ_m offsets, comma-separated")
    parser.add_argument("--shorts", default="0.02,0.04", help="balanced shorts k3 = k4 = k5, comma-separated")
    parser.add_argument("--seed", type=int, default=5)
    args = parser.parse_args(argv)
    import numpy as np

    import emaphm
    from emaphm.actuator import resolve_params
    from emaphm.models import HighFidelityEma

    nameplate = resolve_params(None)
    healthy = np.array(emaphm.HEALTHY, dtype=float)
    runs = [(f"psi_m {float(d):+.3f}", dataclasses.replace(nameplate, motor=dataclasses.replace(
        nameplate.motor, psi_m=nameplate.motor.psi_m * (1 + float(d)))), healthy) for d in args.psi.split(",")]
    for k in (float(v) for v in args.shorts.split(",")):
        faults = healthy.copy()
        faults[2:5] = k
        runs.append((f"shorts {k:.3f} x 3", nameplate, faults))
    print("twin               shorts estimated           fit     verdict   gamma   detected")
    for name, plant, faults in runs:
        r = emaphm.identify(reference=HighFidelityEma(plant).simulate(faults, seed=args.seed), seed=1)
        shorts = " ".join(f"{v:.4f}" for v in r.estimate[2:5])
        print(f"{name:<18} {shorts:<26} {100 * r.fit_nrmse:5.2f}%  {r.verdict:<9} {r.settings['current_scale']['gain']:.4f}  "
              f"{','.join(r.detected) or '-'}", flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
