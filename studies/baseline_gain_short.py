"""Issue 33's target row: a current-sensor gain of 0.90-1.10 present when the baseline is recorded,
then the newcomer's short (`../shared/notes/newcomer.md` §3.B): right with the baseline?

    python studies/baseline_gain_short.py [--gains 0.9,0.95,1.05,1.1] [--seeds 7,8]

For each gain: three healthy twin recordings (noise seeds 100-102) with the logged current scaled
by the gain, `emaphm.baseline` of them, then the newcomer's faults (k = 0.30, 0.15, 0, 0.25, 0,
0.10, 0.60, 0.42) recorded with the same gain (noise --seeds), identified (seed 1) without and
with the baseline: %err, verdict and the faults detected (the truth's present ones: friction,
backlash, short_b, eccentricity, kp_drift). Figures in BENCHMARKS.md, "Baselines", at 1d70ce5.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np

NEWCOMER = np.array([0.30, 0.15, 0.0, 0.25, 0.0, 0.10, 0.60, 0.42])


def recorded(k: np.ndarray, seed: int, gain: float):  # type: ignore[no-untyped-def]
    import emaphm
    from emaphm.results import SimResult

    trace = emaphm.simulate(k, seed=seed)
    return SimResult(t=trace.t, signals={**trace.signals, "i_q": gain * trace.signals["i_q"]}, metadata=trace.metadata)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--gains", default="0.9,0.95,1.05,1.1")
    parser.add_argument("--seeds", default="7,8")
    a = parser.parse_args(argv)
    import emaphm
    from emaphm.baseline import baseline

    with tempfile.TemporaryDirectory() as tmp:
        for gain in (float(g) for g in a.gains.split(",")):
            paths = []
            for s in range(3):
                paths.append(Path(tmp) / f"h{gain}-{s}.h5")
                emaphm.write_trace(recorded(emaphm.HEALTHY, 100 + s, gain), paths[-1])
            folder = baseline(paths, Path(tmp) / f"B{gain}")
            for seed in (int(s) for s in a.seeds.split(",")):
                r = recorded(NEWCOMER, seed, gain)
                alone = emaphm.identify(reference=r, seed=1)
                based = emaphm.identify(reference=r, seed=1, baseline=folder)
                print(f"gain {gain:g}, recording seed {seed}: without a baseline "
                      f"{emaphm.percent_error(alone.estimate, NEWCOMER):.2f} %err ({alone.verdict}), with it "
                      f"{emaphm.percent_error(based.estimate, NEWCOMER):.2f} ({based.verdict}), detected "
                      f"{','.join(based.detected)}", flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
