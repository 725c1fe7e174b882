# Study, not a benchmark (issue 32): where the FOC monitor's error comes from. Quoted in
# docs/theory/monitor-model.md §6 and the issue-32 closing note; rerun at the commit that added it.
"""Where an FOC drive's monitor errs (docs/theory/monitor-model.md §6).

    python studies/foc_monitor_error.py

With the committed files of benchmarks/actuators (foc-textbook, foc-stiff), the twin noise off,
the 150 Hz filtered NRMSE between the twin's i_q and the monitor's at the true faults:
1. the healthy textbook twin as it is, without dead time, and with dead time uncompensated,
   against its own calibrated monitor (the dead time's share of the error);
2. each tuning's twin against each tuning's calibration, 30 cases of seed 2027, the chirp
   (what a calibration of one tuning is worth for the other);
3. the structure alone: the textbook twin against the monitor with the hysteresis drive's
   packaged coefficients, its loop the FOC one or the hysteresis lag, the healthy case and five
   cases of seed 7;
4. the share of DESIGN §7 random cases (20 000 of seed 123) with two phases shorted by at least
   0.45 and 0.475, where the textbook drive's loop rings (studies/foc_loop_stability.py).
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

import numpy as np

import emaphm
from emaphm.faults import random_faults
from emaphm.identification import Comparison

ACTUATORS = Path(__file__).resolve().parent.parent / "benchmarks" / "actuators"


def nrmse(twin: emaphm.HighFidelityEma, monitor: emaphm.MonitorEma, k: np.ndarray) -> float:
    r = twin.simulate(k, noise=False)
    reference = Comparison.from_signal(r.t, r.i_q, twin.params.controller.f_s)
    return 100 * float(reference.nrmse(monitor.simulate(k).i_q))


def spread(values: list[float]) -> str:
    v = np.array(values)
    return f"median {np.median(v):.2f} p90 {np.percentile(v, 90):.2f} max {v.max():.2f} %"


def main(argv: list[str] | None = None) -> None:
    argparse.ArgumentParser(description=__doc__.splitlines()[0]).parse_args(argv)
    files = {t: (ACTUATORS / f"foc-{t}.toml", ACTUATORS / f"foc-{t}.cal.json") for t in ("textbook", "stiff")}
    params = {t: emaphm.load_params(p) for t, (p, _) in files.items()}
    healthy = np.array(emaphm.HEALTHY, dtype=float)

    print("1. healthy textbook twin against its calibrated monitor")
    text = params["textbook"]
    monitor = emaphm.MonitorEma(text, calibration=files["textbook"][1])
    for label, inv in (
        ("as it is (1 us dead time, compensated)", text.inverter),
        ("without dead time", dataclasses.replace(text.inverter, dead_time=0.0)),
        ("dead time uncompensated", dataclasses.replace(text.inverter, dead_time_compensation=False)),
    ):
        twin = emaphm.HighFidelityEma(dataclasses.replace(text, inverter=inv))
        print(f"   {label:40s} {nrmse(twin, monitor, healthy):.2f} %")

    print("2. each tuning's twin against each tuning's calibration (30 cases of seed 2027, chirp)")
    cases = random_faults(30, 2027)
    for t_twin in files:
        twin = emaphm.HighFidelityEma(params[t_twin])
        for t_cal in files:
            lf = emaphm.MonitorEma(params[t_twin], calibration=files[t_cal][1], allow_mismatch=True)
            print(f"   twin {t_twin:8s} calibration {t_cal:8s} {spread([nrmse(twin, lf, k) for k in cases])}")

    print("3. textbook twin, the hysteresis drive's packaged coefficients: FOC loop / hysteresis lag")
    twin = emaphm.HighFidelityEma(text)
    foc_loop = emaphm.MonitorEma(text, allow_mismatch=True)
    lag = emaphm.MonitorEma(emaphm.EmaParams())
    for k in [healthy, *random_faults(5, 7)]:
        print(f"   {np.round(k, 2)}  {nrmse(twin, foc_loop, k):5.2f} %  /  {nrmse(twin, lag, k):5.2f} %")

    print("4. DESIGN §7 random cases with two phases shorted at least this much (20 000 of seed 123)")
    shorts = random_faults(20000, 123)[:, 2:5]
    for edge in (0.45, 0.475):
        print(f"   k >= {edge}: {100 * np.mean((shorts >= edge).sum(axis=1) >= 2):.2f} %")


if __name__ == "__main__":
    main()
