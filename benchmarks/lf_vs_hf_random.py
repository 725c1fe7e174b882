"""LF vs HF NRMSE at the true fault vector of the random benchmark cases (noise off).

    python benchmarks/lf_vs_hf_random.py [--cases 10] [--seed 7]

The same cases as `bench_identify.py` (DESIGN §7 ranges). A high value means the monitor model
cannot reproduce that actuator even with the right faults, so identification there is biased.
"""

from __future__ import annotations

import argparse

import emaphm
from emaphm.faults import random_faults
from emaphm.identification import Comparison
from emaphm.models import MonitorEma


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=10)
    parser.add_argument("--seed", type=int, default=7)
    args = parser.parse_args()
    cases = random_faults(args.cases, args.seed)
    lf = MonitorEma()
    for j, k in enumerate(cases):
        hf = emaphm.simulate(k, noise=False)
        ref = Comparison.from_signal(hf.t, hf.i_q, hf.metadata["params"]["controller"]["f_s"])
        print(f"case {j}: NRMSE {100 * ref.nrmse(lf.simulate(k).i_q):5.2f} %   shorts k3..k5 = "
              + ", ".join(f"{v:.2f}" for v in k[2:5]) + f"   k1 {k[0]:.2f} k2 {k[1]:.2f} k8 {k[7]:.2f}")  # fmt: skip


if __name__ == "__main__":
    main()
