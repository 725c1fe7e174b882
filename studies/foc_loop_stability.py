# Study, not a benchmark (issue 32): where shorts destabilise an FOC drive's current loop.
# docs/theory/hf-model.md §4b quotes it.
"""Where two shorted phases make an FOC drive's PI current loop unstable (docs/theory/hf-model.md §4b).

    python studies/foc_loop_stability.py [--params benchmarks/actuators/foc-textbook.toml]

The twin (noise off, the FDI chirp) with equal shorts k in two phases (B and C), k from 0 to 0.5;
printed per k: the RMS of the filtered (i_q − i_q,ref) and the largest |i_b| (the ringing pair's
current), and the estimate of the sampled loop's stability: a = K_p·T_u/L_pair with
L_pair = (1 − k)²·L_s the pair's inductance in the dq loop's units. With the proportional part
alone and a one-update delay the loop's roots (z² − z + a = 0) leave the unit circle at a = 1;
the integral action moves the edge a little lower.
"""

from __future__ import annotations

import argparse

import numpy as np

import emaphm
from emaphm.identification import lowpass


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--params", default="benchmarks/actuators/foc-textbook.toml")
    args = parser.parse_args(argv)
    params = emaphm.load_params(args.params)
    inv, motor = params.inverter, params.motor
    twin = emaphm.HighFidelityEma(params)
    print(f"{args.params}: K_p_i {inv.K_p_i:g} V/A, K_i_i {inv.K_i_i:g} V/(A·s), T_u {inv.T_update * 1e6:g} us, "
          f"delay {inv.computation_delay}")  # fmt: skip
    print(f"{'k (B, C)':>9} {'a':>6} {'rms(i_q - i_q,ref)':>19} {'max |i_b|':>10}")
    for k in np.arange(0.0, 0.501, 0.025):
        r = twin.simulate([0, 0, 0, k, k, 0, 0, 0.5], noise=False)
        err = lowpass(r.i_q - r["i_q_ref"], params.controller.f_s)
        a = inv.K_p_i * inv.T_update / ((1 - k) ** 2 * motor.L_s)
        print(f"{k:>9.3f} {a:>6.2f} {np.sqrt(np.mean(err**2)):>17.4f} A {np.max(np.abs(r['i_b'])):>8.2f} A",
              flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
