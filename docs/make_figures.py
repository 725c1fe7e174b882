"""Regenerate the figures of the docs (paper Fig. 4 counterparts) from the package.

    python docs/make_figures.py

- docs/figures/hf_table1.png: the HF response to the FDI chirp, healthy and with the Table 1 faults
  (also what `emaphm demo` draws);
- docs/figures/lf_calibration.png: HF i_q vs the LF current before and after calibration, on a
  fitted scenario and two held-out ones (noise off, both filtered at 150 Hz).
"""

from __future__ import annotations

from pathlib import Path

import emaphm
from emaphm.calibration import Calibration, Coefficients
from emaphm.calibration.scenarios import CHECK_SCENARIOS, FIT_SCENARIOS
from emaphm.models import MonitorEma
from emaphm.plots import plot_calibration, plot_response

FIGURES = Path(__file__).parent / "figures"


def main() -> None:
    FIGURES.mkdir(exist_ok=True)
    runs = {
        "healthy": emaphm.simulate(emaphm.HEALTHY, noise=True, seed=0),
        "Table 1 faults": emaphm.simulate(emaphm.TABLE1_REFERENCE, noise=True, seed=0),
    }
    print(plot_response(runs, FIGURES / "hf_table1.png", "High-fidelity EMA twin, FDI chirp (noise on)"))
    before, after = MonitorEma(calibration=Calibration(Coefficients())), MonitorEma()
    by_name = {s.name: s for s in (*FIT_SCENARIOS, *CHECK_SCENARIOS)}
    cases = {}
    for name, label in (
        ("combined", "fitted: combined mechanical + electrical"),
        ("short B k4=0.45 + friction k1=0.2", "held out: short B 0.45 + friction 0.2"),
        ("paper Table 1 reference", "held out: the paper's Table 1 vector"),
    ):
        k = by_name[name].faults
        cases[label] = (emaphm.simulate(k, noise=False), before.simulate(k), after.simulate(k))
    print(plot_calibration(cases, FIGURES / "lf_calibration.png"))


if __name__ == "__main__":
    main()
