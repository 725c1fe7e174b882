# Study, not a benchmark: moved from benchmarks/ at dae85bf (last changed at ceb9152); rerun it at that
# commit to reproduce its figures: HISTORY.md §"Fault signatures of the HF twin"; docs/theory/hf-model.md
# §6, §10.
"""What each fault does to the HF current: the figures quoted in docs/theory/hf-model.md §6 and §10.

    python studies/fault_signatures.py

Part 1, the FDI chirp, noise off: change of the filtered i_q (2nd-order Butterworth, 150 Hz,
zero phase) in % of the healthy RMS; the chaotic floor (friction changed by 1e-5) and the noise
floor (noise on, seed 1) for scale. Part 2, a constant-speed ramp (0.1 rad/s): amplitude and phase of
the 1θ_e and 2θ_e components of i_q, fitted after 0.2 s, and how far the eccentricity's 1θ_e
component turns when φ_e turns by 90° (k7 0 → 0.25).
"""

from __future__ import annotations

import argparse

import numpy as np
from scipy.signal import butter, sosfiltfilt

import emaphm

SOS = butter(2, 150.0, fs=1e4, output="sos")


def k(**changes: float) -> np.ndarray:
    out = np.array(emaphm.HEALTHY)
    for name, value in changes.items():
        out[int(name[1:]) - 1] = value
    return out


def rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(x**2)))


def harmonic(r: emaphm.SimResult, order: int) -> tuple[float, float]:
    m = r.t > 0.2
    th, t = r.theta_e[m], r.t[m]
    X = np.column_stack([np.ones_like(t), t, np.cos(order * th), np.sin(order * th)])
    c, *_ = np.linalg.lstsq(X, r.i_q[m], rcond=None)
    return float(np.hypot(c[2], c[3])), float(np.degrees(np.arctan2(c[3], c[2])))


def main(argv: list[str] | None = None) -> None:
    argparse.ArgumentParser(description=__doc__.splitlines()[0]).parse_args(argv)  # --help only
    healthy = sosfiltfilt(SOS, emaphm.simulate(emaphm.HEALTHY, noise=False).i_q)
    print("Part 1: FDI chirp, filtered i_q change in % of healthy RMS (noise off)")
    cases = {
        "friction k1=0.3": k(k1=0.3), "backlash k2=0.3": k(k2=0.3), "short A k3=0.3": k(k3=0.3),
        "short B k4=0.3": k(k4=0.3), "short C k5=0.3": k(k5=0.3), "eccentricity k6=0.3": k(k6=0.3),
        "gain k8=0.2": k(k8=0.2), "gain k8=0.8": k(k8=0.8), "chaotic floor k1=1e-5": k(k1=1e-5),
    }  # fmt: skip
    for name, vec in cases.items():
        f = sosfiltfilt(SOS, emaphm.simulate(vec, noise=False).i_q)
        print(f"  {name:<24} {100 * rms(f - healthy) / rms(healthy):6.1f} %")
    noisy = sosfiltfilt(SOS, emaphm.simulate(emaphm.HEALTHY, noise=True, seed=1).i_q)
    print(f"  {'noise floor (seed 1)':<24} {100 * rms(noisy - healthy) / rms(healthy):6.1f} %")

    print("Part 2: ramp 0.1 rad/s, harmonics of i_q (amplitude mA, phase deg)")
    ramp = emaphm.Ramp(rate=0.1, t_0=0.0, duration=0.6)
    phase_1 = {}
    for name, vec in {
        "healthy": emaphm.HEALTHY, "short A k3=0.3": k(k3=0.3), "short B k4=0.3": k(k4=0.3),
        "short C k5=0.3": k(k5=0.3), "ecc k6=0.3 k7=0": k(k6=0.3), "ecc k6=0.3 k7=0.25": k(k6=0.3, k7=0.25),
    }.items():  # fmt: skip
        r = emaphm.simulate(vec, noise=False, command=ramp)
        (a1, p1), (a2, p2) = harmonic(r, 1), harmonic(r, 2)
        phase_1[name] = p1
        print(f"  {name:<20} 1θ_e {1e3 * a1:6.2f} mA {p1:7.1f}°   2θ_e {1e3 * a2:6.2f} mA {p2:7.1f}°")
    turn = (phase_1["ecc k6=0.3 k7=0.25"] - phase_1["ecc k6=0.3 k7=0"] + 180.0) % 360.0 - 180.0
    print(f"  eccentricity 1θ_e component turns by {turn:.1f}° when φ_e turns by 90°")


if __name__ == "__main__":
    main()
