"""Amplitude-invariant Clarke and Park transforms (DESIGN §3.9).

    i_alpha = (2/3)·(i_a − i_b/2 − i_c/2),  i_beta = (i_b − i_c)/√3
    i_d = i_alpha·cos θ_e + i_beta·sin θ_e,  i_q = −i_alpha·sin θ_e + i_beta·cos θ_e

With this convention a balanced set i_x = −I·sin(θ_e − γ_x) (γ = 0, 2π/3, −2π/3) gives
i_d = 0 and i_q = I: i_q equals the phase-current amplitude. Works on floats and on arrays.
"""

from __future__ import annotations

import math

import numpy as np

from ._jit import jit

SQRT3 = math.sqrt(3.0)
HALF_SQRT3 = 0.5 * SQRT3


@jit
def clarke(i_a, i_b, i_c):  # type: ignore[no-untyped-def]
    """(i_a, i_b, i_c) -> (i_alpha, i_beta), amplitude invariant."""
    return (2.0 / 3.0) * (i_a - 0.5 * i_b - 0.5 * i_c), (i_b - i_c) / SQRT3


@jit
def inverse_clarke(i_alpha, i_beta):  # type: ignore[no-untyped-def]
    """(i_alpha, i_beta) -> (i_a, i_b, i_c) with zero homopolar component."""
    return i_alpha, -0.5 * i_alpha + 0.5 * SQRT3 * i_beta, -0.5 * i_alpha - 0.5 * SQRT3 * i_beta


@jit
def park(i_alpha, i_beta, theta_e):  # type: ignore[no-untyped-def]
    """(i_alpha, i_beta) at electrical angle theta_e [rad] -> (i_d, i_q)."""
    s = np.sin(theta_e)
    c = np.cos(theta_e)
    return i_alpha * c + i_beta * s, -i_alpha * s + i_beta * c


@jit
def inverse_park(i_d, i_q, theta_e):  # type: ignore[no-untyped-def]
    """(i_d, i_q) at electrical angle theta_e [rad] -> (i_alpha, i_beta)."""
    s = np.sin(theta_e)
    c = np.cos(theta_e)
    return i_d * c - i_q * s, i_d * s + i_q * c


@jit
def phase_directions(sin_e, cos_e):  # type: ignore[no-untyped-def]
    """u_x = −sin(θ_e − γ_x) for x = a, b, c (γ = 0, 2π/3, −2π/3) from sin θ_e and cos θ_e.

    The i_d = 0 current reference of phase x is i_q·u_x, and u_x² are the sin² terms of the
    paper's eq. (1): u_a² = sin²(θ_e + π), u_b² = sin²(θ_e + π/3), u_c² = sin²(θ_e − π/3).
    """
    return -sin_e, 0.5 * sin_e + HALF_SQRT3 * cos_e, 0.5 * sin_e - HALF_SQRT3 * cos_e


@jit
def q_error(e_a, e_b, e_c, theta_e, i_q, out):  # type: ignore[no-untyped-def]
    """out = i_q + the q component of the phase-current errors (e_a, e_b, e_c) at θ_e: `clarke`,
    then `park`'s i_q, sample by sample in a loop that allocates nothing (the twin's measured i_q,
    `models.hf`: the two on arrays made its load import numba's array and ufunc modules, about
    25 ms of a diagnosis's start, issue 36); the numbers they give on arrays."""
    for k in range(i_q.shape[0]):
        i_alpha, i_beta = clarke(e_a[k], e_b[k], e_c[k])
        out[k] = i_q[k] + park(i_alpha, i_beta, theta_e[k])[1]
