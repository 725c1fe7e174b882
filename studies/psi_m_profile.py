"""Issue 34: can the recording itself tell a magnet flux off its nameplate from balanced shorts?

    python studies/psi_m_profile.py [--factors 0.97,0.98,0.99,1,1.01,1.02] [--seed 5]

Each twin below is recorded with noise (twin seed `--seed`) and identified, from a uniform start,
with monitors whose ψ_m (k_t,eq, k_e,eq and the actuator's psi_m together, `constants.apply`) is
the nameplate's × each of `--factors`. Prints the fit NRMSE and the shorts per factor: where the
NRMSE's minimum sits against the true ψ_m says whether the recording holds the flux.
"""

from __future__ import annotations

import argparse
import dataclasses


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--factors", default="0.97,0.98,0.99,1,1.01,1.02")
    parser.add_argument("--seed", type=int, default=5)
    args = parser.parse_args(argv)
    import numpy as np

    import emaphm
    from emaphm.actuator import resolve_params
    from emaphm.constants import apply
    from emaphm.models import HighFidelityEma
    from emaphm.models.lf import resolve_calibration

    nameplate = resolve_params(None)
    calibration = resolve_calibration(None)
    healthy = np.array(emaphm.HEALTHY, dtype=float)

    def psi(f: float):  # noqa: ANN202
        return dataclasses.replace(nameplate, motor=dataclasses.replace(nameplate.motor, psi_m=nameplate.motor.psi_m * f))

    def faults(shorts: tuple[float, float, float]):  # noqa: ANN202
        k = healthy.copy()
        k[2:5] = shorts
        return k

    twins = [
        ("psi -1.6 %, healthy", psi(0.984), faults((0, 0, 0))),
        ("psi -1.6 %, 0/.3/0", psi(0.984), faults((0, 0.3, 0))),
        ("balanced .025", nameplate, faults((0.025, 0.025, 0.025))),
        ("nominal .03/.33/.03", nameplate, faults((0.03, 0.33, 0.03))),
    ]
    monitors = []
    for f in (float(v) for v in args.factors.split(",")):
        p, cal = apply(nameplate, calibration, {"k_t_eq": f, "k_e_eq": f})
        record = {**cal.record, "settings": {**cal.record.get("settings", {}), "params": p.to_dict()}}
        monitors.append((f, p, dataclasses.replace(cal, record=record)))
    for name, plant, k in twins:
        trace = HighFidelityEma(plant).simulate(k, seed=args.seed)
        print(name, flush=True)
        for f, p, cal in monitors:
            r = emaphm.identify(reference=trace, seed=1, params=p, calibration=cal, start="random", uncertainty="none")
            shorts = " ".join(f"{v:.4f}" for v in r.estimate[2:5])
            print(f"  psi x {f:.3f}: NRMSE {100 * r.fit_nrmse:.4f} %  shorts {shorts}  friction {r.estimate[0]:.4f}", flush=True)


if __name__ == "__main__":
    main()
