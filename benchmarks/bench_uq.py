"""The extra wall time of the default uncertainty (Laplace) per identification (issue 9 target ≤ 0.5 s).

    python benchmarks/bench_uq.py [--repeats 20]

Identifies the Table 1 case once (seed 1), then times `uncertainty.laplace` on its fitted
identifier --repeats times (the same call `identify` makes: 33 LF rows in one population call,
the comparison filter, the sandwich), and prints the median and max next to the identification's
own wall time.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time

import numpy as np
from _machine import cpu_model  # benchmarks/ is the script's folder, first on sys.path

import emaphm
from emaphm.commands import Chirp
from emaphm.identification.identify import FaultIdentifier
from emaphm.identification.uncertainty import laplace, load_factors
from emaphm.models import HighFidelityEma, MonitorEma


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=20)
    args = parser.parse_args()
    print(
        f"emaphm {emaphm.__version__}, Python {platform.python_version()}, {os.cpu_count()} cores ({cpu_model()})"
    )
    trace = HighFidelityEma().simulate(emaphm.TABLE1_REFERENCE, noise=True, seed=1)
    t0 = time.perf_counter()
    ident = FaultIdentifier("ga", seed=1, monitor=MonitorEma()).fit(
        trace.t, trace.i_q, Chirp(), trace.theta_u
    )
    fit_s = time.perf_counter() - t0
    factors = load_factors()
    laplace(
        ident.objective_, ident.monitor_, ident.faults_, duration=ident.duration_, factors=factors
    )  # warm
    walls = []
    for _ in range(args.repeats):
        t0 = time.perf_counter()
        res = laplace(
            ident.objective_, ident.monitor_, ident.faults_, duration=ident.duration_, factors=factors
        )
        walls.append(time.perf_counter() - t0)
    print(f"identification (search + polish + checks): {fit_s:.2f} s")
    print(f"Laplace uncertainty, {args.repeats} repeats: median {1000 * statistics.median(walls):.1f} ms, "
          f"max {1000 * max(walls):.1f} ms ({res.evaluations} LF runs); "
          f"{100 * statistics.median(walls) / fit_s:.1f} % of the identification")  # fmt: skip
    print("half-widths:", np.round(res.half_width(), 4).tolist())


if __name__ == "__main__":
    main()
