# Study, not a benchmark: moved from benchmarks/ at dae85bf (last changed at cd4ede2); rerun it at that
# commit to reproduce its figures: HISTORY.md §"Fast recordings: filter, then resample" (26-914x);
# BENCHMARKS.md summary row.
"""Filter-then-resample against interpolate-then-filter for a fast recording with inverter ripple (issue 10).

    python studies/bench_resample.py [--rate 64000]

A current recorded at --rate: a 3 Hz + 40 Hz signal (what the comparison keeps) plus 50 mA of
hysteresis-inverter ripple whose switching frequency wanders 12-20 kHz (16 kHz ± 4 kHz at 7 Hz),
or a fixed tone at 16 kHz (two phases) or 16.1 kHz. It is brought onto the 10 kHz model grid two ways, then through the
comparison's 150 Hz filter, and compared in that band with the signal alone:
- interpolate-then-filter (`np.interp` onto the grid, the path before issue 10);
- filter-then-resample (`signals.resample`: an anti-aliasing low-pass on the source grid first).
Prints the RMS error of each in the 0-150 Hz band and their ratio.
"""

from __future__ import annotations

import argparse

import numpy as np

from emaphm.identification.signals import lowpass, resample

F_GRID = 1e4


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rate", type=float, default=64_000.0)
    args = parser.parse_args()
    t_src = np.arange(int(args.rate)) / args.rate  # 1 s
    grid = np.arange(int(F_GRID * t_src[-1]) + 1) / F_GRID

    def signal(t):
        return 0.3 * np.sin(2 * np.pi * 3 * t) + 0.1 * np.sin(2 * np.pi * 40 * t)

    ripples = {
        "ripple 12-20 kHz (wandering)": 0.05 * np.sin(2 * np.pi * (16e3 * t_src - 4e3 / (2 * np.pi * 7) * np.cos(2 * np.pi * 7 * t_src))),
        "ripple 16 kHz tone": 0.05 * np.sin(2 * np.pi * 16e3 * t_src),
        "ripple 16 kHz tone, phase 1 rad": 0.05 * np.sin(2 * np.pi * 16e3 * t_src + 1.0),
        "ripple 16.1 kHz tone": 0.05 * np.sin(2 * np.pi * 16.1e3 * t_src + 0.3),
    }  # fmt: skip
    truth = lowpass(signal(grid), F_GRID)
    for name, ripple in ripples.items():
        measured = signal(t_src) + ripple
        old = lowpass(np.interp(grid, t_src, measured), F_GRID)
        new = lowpass(resample(t_src, measured, grid, F_GRID), F_GRID)
        e_old = float(np.sqrt(np.mean((old - truth) ** 2)))
        e_new = float(np.sqrt(np.mean((new - truth) ** 2)))
        print(f"{args.rate / 1e3:g} kHz, {name}: RMS error in the band, interpolate-then-filter {1e3 * e_old:.3f} mA, "
              f"filter-then-resample {1e3 * e_new:.4f} mA, ratio {e_old / e_new:.0f}")  # fmt: skip


if __name__ == "__main__":
    main()
