# Study, not a benchmark (issue 34): how well the measured surface motion agrees with the monitor's
# at the truth; `identification/limits.py` (MOTION_LAG_MAX_S, POSITION_SCALE_TOLERANCE) quotes it.
"""The lag and scale of the measured surface position against the monitor's, at the truth.

    python studies/motion_agreement.py [--cases 12] [--seed 77] [--params FILE --calibration CAL] [--tolerance 0.02]

For random twin actuators (noise on, the FDI chirp) the monitor runs at the true faults under the
recorded command; `preconditions.lag_and_scale` gives the lag and the scale of the measured θ_u
against its θ_u. Also printed: the same with the command stamped 5 ms late (the monitor driven by
it) and with the measured positions × 0.9 (a lever-arm slip), the two rig mistakes it must see.
With --tolerance the twin is drawn about the actuator (`tolerances.drawn_actuator`).
"""

from __future__ import annotations

import argparse

import numpy as np

import emaphm
from emaphm.commands import SampledCommand
from emaphm.faults import random_faults
from emaphm.identification.preconditions import lag_and_scale
from emaphm.models import HighFidelityEma, MonitorEma
from emaphm.tolerances import drawn_actuator


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=12)
    parser.add_argument("--seed", type=int, default=77)
    parser.add_argument("--params", default=None)
    parser.add_argument("--calibration", default=None)
    parser.add_argument("--tolerance", type=float, default=0.0)
    args = parser.parse_args(argv)
    params = emaphm.load_params(args.params) if args.params else emaphm.EmaParams()
    rows = []
    for j, k in enumerate(random_faults(args.cases, args.seed)):
        plant = drawn_actuator(params, j, tolerance=args.tolerance) if args.tolerance else params
        trace = HighFidelityEma(plant).simulate(k, seed=j)
        t, cmd, measured = trace.t, trace.signals["theta_cmd"], trace.signals["theta_u"]
        agreement = []
        for command, scale in ((cmd, 1.0), (np.interp(t - 0.005, t, cmd, left=cmd[0]), 1.0), (cmd, 0.9)):
            run = MonitorEma(params, SampledCommand(t - t[0], command), args.calibration).simulate(k)
            model = np.interp(t, run.t, run.signals["theta_u"])
            agreement.append(lag_and_scale(t, scale * measured, model, 0.008))
        rows.append(agreement)
        (l0, a0), (l1, _), (_, a2) = agreement
        print(f"{j:3d}  twin: lag {1e3 * l0:+.3f} ms scale {a0:.4f} | command 5 ms late: lag {1e3 * l1:+.3f} ms "
              f"| positions x 0.9: scale {a2:.4f}", flush=True)  # fmt: skip
    r = np.array(rows)
    print(f"twin: |lag| <= {1e3 * np.abs(r[:, 0, 0]).max():.2f} ms, |scale - 1| <= {100 * np.abs(r[:, 0, 1] - 1).max():.2f} %; "
          f"5 ms late: lag {1e3 * r[:, 1, 0].min():.2f} to {1e3 * r[:, 1, 0].max():.2f} ms; "
          f"x 0.9: scale {r[:, 2, 1].min():.3f} to {r[:, 2, 1].max():.3f}")  # fmt: skip


if __name__ == "__main__":
    main()
