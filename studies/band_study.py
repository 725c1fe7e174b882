# Study, not a benchmark: moved from benchmarks/ at dae85bf (last changed at f132a4b); rerun it at that
# commit to reproduce its figures: BENCHMARKS history §"Why the hysteresis band is 0.1 A"
# (benchmarks/results/HISTORY.md); docs/theory/hf-model.md §4, docs/design.md.
"""Why the hysteresis band is h = 0.1 A (docs/theory/hf-model.md §4): floors of the FDI signal vs h.

    python studies/band_study.py

For each band h (with the same absolute sub-step bound, 0.04 A), on the FDI chirp, noise off:
- chaotic floor: NRMSE between the filtered HF i_q and that of the same case with k1 + 1e-5;
- current-loop error: RMS of the filtered (i_q − i_q,ref), the part of the measured current that
  the three-phase hysteresis loop adds and a single-phase monitor model cannot reproduce;
- LF vs HF: NRMSE of the shipped calibrated LF model (calibrated at h = 0.1 A);
- HF wall time per simulated second (one run, includes nothing but the simulation).
"""

from __future__ import annotations

import argparse
import dataclasses
import time

import numpy as np

import emaphm
from emaphm.identification import Comparison
from emaphm.models import MonitorEma

CASES = {
    "healthy": emaphm.HEALTHY,
    "short A k3=0.3": np.array([0, 0, 0.3, 0, 0, 0, 0, 0.5]),
    "Table 1": emaphm.TABLE1_REFERENCE,
    "mix": np.array([0.4, 0.2, 0.2, 0, 0.35, 0.1, 0.6, 0.4]),
}


def main(argv: list[str] | None = None) -> None:
    argparse.ArgumentParser(description=__doc__.splitlines()[0]).parse_args(argv)  # --help only
    print(f"{'h [A]':>6} {'case':<16} {'floor %':>8} {'loop err mA':>12} {'LF vs HF %':>11} {'HF s/s':>7}")
    for h in (0.2, 0.1, 0.05):
        p = dataclasses.replace(
            emaphm.EmaParams(),
            inverter=emaphm.InverterParams(h=h),
            integration=emaphm.IntegrationParams(ripple_fraction=min(1.0, 0.04 / h)),
        )
        lf = MonitorEma(params=p, allow_mismatch=True)  # the study measures exactly that mismatch (M5)
        for name, k in CASES.items():
            t0 = time.perf_counter()
            hf = emaphm.simulate(k, noise=False, params=p)
            wall = time.perf_counter() - t0
            ref = Comparison.from_signal(hf.t, hf.i_q, 1e4)
            k2 = np.array(k, dtype=float)
            k2[0] += 1e-5
            floor = ref.nrmse(emaphm.simulate(k2, noise=False, params=p).i_q)
            loop = np.sqrt(np.mean(ref.filtered(hf.i_q[1:] - hf.i_q_ref[:-1]) ** 2))
            mismatch = ref.nrmse(lf.simulate(k).i_q)
            print(
                f"{h:>6.2f} {name:<16} {100 * floor:>8.1f} {1e3 * loop:>12.1f} {100 * mismatch:>11.1f} {wall:>7.2f}"
            )


if __name__ == "__main__":
    main()
