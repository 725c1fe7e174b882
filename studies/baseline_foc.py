# Study, not a benchmark (issue 33): a baseline of an FOC actuator, from its own calibration or warm-started
# from the packaged one; the closing note of 2026-11-27 quotes it.
"""An FOC actuator (the textbook drive, drawn within ±2 % and its PI gains within ±10 %) identified
with its nameplate's calibration, with a baseline warm-started from the packaged (hysteresis)
calibration (no --calibration given), and with a baseline from its own calibration.

    python studies/baseline_foc.py

Prints each baseline's wall time, then per random case (a third of the faults absent) the %err
and verdict of the three.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import emaphm
from emaphm.baseline import baseline
from emaphm.faults import random_faults
from emaphm.models import HighFidelityEma
from emaphm.tolerances import drawn_actuator

A = Path(__file__).resolve().parents[1] / "benchmarks" / "actuators"


def main(argv: list[str] | None = None) -> None:
    argparse.ArgumentParser(description=__doc__.splitlines()[0]).parse_args(argv)
    files = {k: str(A / f"foc-textbook.{s}") for k, s in (("params", "toml"), ("calibration", "cal.json"),
                                                          ("uq_calibration", "uq.json"), ("detection", "det.json"))}  # fmt: skip
    plant = drawn_actuator(emaphm.load_params(files["params"]), 77, tolerance=0.02, drive_tolerance=0.1)
    work = Path(tempfile.mkdtemp(prefix="baseline-foc-"))
    paths = []
    for s in range(3):
        paths.append(work / f"h{s}.h5")
        emaphm.write_trace(HighFidelityEma(plant).simulate(emaphm.HEALTHY, seed=300 + s), paths[-1])
    t0 = time.perf_counter()
    warm = baseline(paths, work / "warm", params=files["params"])
    t1 = time.perf_counter()
    own = baseline(paths, work / "own", **files)
    print(f"baseline warm-started {t1 - t0:.1f} s, from its own calibration {time.perf_counter() - t1:.1f} s")
    for j, k in enumerate(random_faults(4, 78, absent=1 / 3)):
        trace = HighFidelityEma(plant).simulate(k, seed=400 + j)
        runs = (
            emaphm.identify(reference=trace, seed=1, params=files["params"], calibration=files["calibration"],
                            uq_calibration=files["uq_calibration"]),
            emaphm.identify(reference=trace, seed=1, baseline=warm),
            emaphm.identify(reference=trace, seed=1, baseline=own),
        )  # fmt: skip
        print(f"case {j}: %err nameplate {emaphm.percent_error(runs[0].estimate, k):.2f}, warm-started baseline "
              f"{emaphm.percent_error(runs[1].estimate, k):.2f}, own-calibration baseline "
              f"{emaphm.percent_error(runs[2].estimate, k):.2f}; verdicts {', '.join(r.verdict for r in runs)}",
              flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
