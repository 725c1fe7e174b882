# Study, not a benchmark: moved from benchmarks/ at dae85bf (last changed at 52dedda); rerun it at that
# commit to reproduce its figures: HISTORY.md §"The dead zone's ring"; docs/theory/monitor-model.md.
"""Where the twin's hysteresis loop comes to rest on a locked rotor (issue 8; monitor-model.md §1).

    python studies/loop_rest_study.py [--trials 800] [--seed 2] [--span 0.02]

The twin's three hysteresis comparators (`kernels.hf_twin._comparators`, the twin's own) drive a
star-connected R-L stator with an isolated neutral from the nominal actuator's V_dc, R_s, L_s and
band h, with the rotor locked (no back-EMF: the motor stuck in friction). A demand i_q,ref = I at
an electrical angle θ_e sets the phase references i_x,ref = I·u_x. The loop has come to rest when
every phase current is within 5 mA of zero (an inverter on a zero vector: all legs up or all
down). A zero vector holds once reached while no phase current, decaying to zero, leaves its band
on the far side: all legs up while min_x i_x,ref > −h/2, all legs down while max_x i_x,ref < h/2.

Two ways into each region of the demand (both zero vectors hold, exactly one does, none does):

- **from running**: each trial draws θ_e, I (up to 1.1·h over max|u_x|) and the legs' switching
  state, starts the currents at their references and runs `--span` seconds (0.1 µs Euler);
- **from rest**: the same, but the loop first runs `--span` at a demand inside every band (I/3 at
  that angle, where both hold: it always comes to rest), then the demand ramps to I over 5 ms and
  holds for `--span`.

Printed: per region and way, the fraction of trials at rest at the end. The monitor's dead zone
(`kernels.monitor.standstill_dead_zone`) follows it: it rests where both hold, runs where none
does, and where exactly one does carries the expected current, (1 − that fraction) of the demand
(`kernels.monitor.MAY_REST_CARRY`), whichever way the loop came in.
"""

from __future__ import annotations

import argparse
import math

import numpy as np
from numba import njit

from emaphm.actuator import resolve_params
from emaphm.kernels.hf_twin import _comparators
from emaphm.kernels.transforms import phase_directions

RAMP_S = 0.005  # the demand's ramp from rest to the trial's demand [s]


@njit(cache=False)
def run_loop(I_0, I, theta_e, s0, R, L, V_dc, h, span, ramp, dt):  # type: ignore[no-untyped-def]
    """The locked-rotor loop from currents at their references for I_0 in leg states s0: `span` s
    at I_0, then (when `ramp` > 0) a ramp to I over `ramp` s and `span` s at I. The final currents."""
    u_a, u_b, u_c = phase_directions(math.sin(theta_e), math.cos(theta_e))
    i_a, i_b = I_0 * u_a, I_0 * u_b
    i_c = -(i_a + i_b)
    s_a, s_b, s_c = s0[0], s0[1], s0[2]
    n_0 = int(span / dt)
    n_ramp = int(ramp / dt)
    n = n_0 if ramp <= 0.0 else 2 * n_0 + n_ramp
    for k in range(n):
        d = I_0 if k < n_0 else (I if k >= n_0 + n_ramp else I_0 + (I - I_0) * (k - n_0) / n_ramp)
        r_a, r_b, r_c = d * u_a, d * u_b, d * u_c
        s_a, s_b, s_c, _sw = _comparators(
            i_a, i_b, i_c, s_a, s_b, s_c, r_a - h / 2, r_b - h / 2, r_c - h / 2, r_a + h / 2, r_b + h / 2, r_c + h / 2
        )  # fmt: skip
        v_n = V_dc / 2 * (s_a + s_b + s_c) / 3.0  # the isolated neutral
        i_a += dt * (V_dc / 2 * s_a - v_n - R * i_a) / L
        i_b += dt * (V_dc / 2 * s_b - v_n - R * i_b) / L
        i_c = -(i_a + i_b)
    return i_a, i_b, i_c


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=800, help="trials per region of the demand and way in")
    parser.add_argument("--seed", type=int, default=2)
    parser.add_argument("--span", type=float, default=0.02, help="how long each stage runs [s]")
    args = parser.parse_args()
    p = resolve_params(None)
    R, L, V_dc, h = p.motor.R_s, p.motor.L_s, p.inverter.V_dc, p.inverter.h
    print(f"locked rotor: R_s {R} ohm, L_s {L * 1e3} mH, V_dc {V_dc} V, h {h * 1e3:.0f} mA; "
          f"{args.trials} trials per region and way in, seed {args.seed}, {args.span * 1e3:.0f} ms per stage")  # fmt: skip
    rng = np.random.default_rng(args.seed)
    regions = ("both", "one", "none")
    counts = {(region, way): [0, 0] for region in regions for way in ("running", "rest")}
    while min(n for n, _ in counts.values()) < args.trials:
        theta_e = rng.uniform(0.0, 2.0 * math.pi)
        u = np.array(phase_directions(math.sin(theta_e), math.cos(theta_e)))
        I = rng.uniform(0.0, 1.1 * h / np.abs(u).max()) * rng.choice([-1.0, 1.0])
        ref = I * u
        up, down = ref.min() > -h / 2, ref.max() < h / 2
        region = "both" if up and down else ("one" if up or down else "none")
        s0 = rng.choice([-1.0, 1.0], 3)
        for way, I_0, ramp in (("running", I, 0.0), ("rest", I / 3.0, RAMP_S)):
            c = counts[(region, way)]
            if c[0] < args.trials:
                i = run_loop(I_0, I, theta_e, s0, R, L, V_dc, h, args.span, ramp, 1e-7)
                c[0] += 1
                c[1] += max(abs(x) for x in i) < 0.005
    labels = {"both": "both zero vectors hold", "one": "exactly one holds", "none": "none holds"}
    for region in regions:
        for way in ("running", "rest"):
            n, rest = counts[(region, way)]
            f = rest / n
            print(f"{labels[region]:>24}, from {way:>7}: at rest in {rest:>3} of {n} trials, "
                  f"{f:.3f} ± {math.sqrt(f * (1 - f) / n):.3f}")  # fmt: skip


if __name__ == "__main__":
    main()
