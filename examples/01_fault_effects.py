"""Simulate the HF twin healthy and with one fault at a time; print how i_q and tracking change.

python examples/01_fault_effects.py
"""

import numpy as np

import emaphm


def rms(x):
    return float(np.sqrt(np.mean(np.square(x))))


healthy = emaphm.simulate(emaphm.HEALTHY, noise=False)
print(f"{'case':<16} {'i_q RMS [A]':>11} {'tracking RMS [mrad]':>20}")
print(f"{'healthy':<16} {rms(healthy.i_q):>11.3f} {1e3 * rms(healthy.theta_cmd - healthy.theta_u):>20.2f}")
for i, name in enumerate(emaphm.FAULT_NAMES):
    if name in ("eccentricity_phase", "kp_drift"):
        continue
    k = np.array(emaphm.HEALTHY)
    k[i] = 0.5
    r = emaphm.simulate(k, noise=False)
    print(f"{name + '=0.5':<16} {rms(r.i_q):>11.3f} {1e3 * rms(r.theta_cmd - r.theta_u):>20.2f}")
