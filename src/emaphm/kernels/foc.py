"""Field-oriented control (FOC) drive of the high-fidelity twin: sampled dq PI current loops, PWM.

The drive most production EMAs run, instead of the paper's hysteresis comparators
(`pmsm_abc.hysteresis`). Every update instant (the carrier peak, or the peak and the valley with
a double update; T_u = T_pwm or T_pwm/2) the drive

  1. samples the phase currents and the rotor angle and forms i_d, i_q (amplitude-invariant
     Clarke–Park, DESIGN §3.9);
  2. runs two PI loops with the nameplate decoupling and back-EMF feed-forward:

         v_d = K_p·(0 − i_d) + I_d − ω_e·L_s·i_q
         v_q = K_p·(i_q,ref − i_q) + I_q + ω_e·L_s·i_d + ω_e·ψ_m,     I_x += K_i·T_u·e_x

     limited to the circle |v_dq| ≤ V_lim (the modulation's linear range times `voltage_limit`),
     the integrators held while the vector is limited (conditional integration, anti-windup);
  3. turns v_dq into three duties d_x ∈ [0, 1] (inverse Park with the angle optionally advanced
     over the delay, inverse Clarke, and the min–max zero sequence of space-vector PWM or none
     for sine-triangle), plus ±t_d/T_pwm by the sign of the sampled phase current when dead-time
     compensation is on;
  4. hands them to the PWM `computation_delay` update periods later.

The PWM compares each duty with a centre-aligned triangle carrier (1 at the peak, 0 at the
valley); a leg is high while the carrier is below its duty: over one period from a peak
[(1 − d)·T/2, (1 + d)·T/2], over a half period from a peak [(1 − d)·T/2, T/2], from a valley
[0, d·T/2] (`window`). During the dead time t_d after each edge both switches are off and the
free-wheeling diode sets the leg by the phase current's sign: the rising edge comes t_d late
when the current flows out of the leg (i_x > 0), the falling edge t_d late when it flows in
(`leg_state`). An edge at an update instant, or one whose dead time runs past it (a duty near 1,
or with a double update near 0), carries its dead time into the next interval (`carried`).

The twin's fixed step Δt (1 µs) is finer than the carrier but coarser than an edge's timing: a
leg enters a step as its high-time fraction over that step, s_x = 2·f_x − 1 ∈ [−1, 1], so the
step's volt-seconds are exact wherever the edge falls (the hysteresis twin's s_x = ±1 are the
special case f_x ∈ {0, 1}).
"""

from __future__ import annotations

import math
from typing import NamedTuple

from ._jit import jit
from .transforms import HALF_SQRT3, SQRT3


class FocPack(NamedTuple):
    """The FOC drive's run constants; build it with `models.hf.foc_pack` (on = 0: hysteresis)."""

    on: float  # 1: FOC drive, 0: the hysteresis comparators (the other fields unused)
    T_pwm: float  # PWM carrier period [s]
    T_u: float  # update period: T_pwm (single update) or T_pwm/2 (double) [s]
    double: float  # 1: double update (peak and valley), 0: single (peak)
    t_first: float  # the first update instant at or after t = 0 [s]
    first_peak: float  # 1: that instant is a carrier peak, 0: a valley
    delay: float  # computation delay [update periods]: 0, 1 or 2
    t_d: float  # dead time [s]
    comp: float  # 1: dead-time compensation on
    K_p: float  # PI proportional gain [V/A]
    K_i: float  # PI integral gain [V/(A·s)]
    svpwm: float  # 1: space-vector (min–max zero sequence), 0: sine-triangle
    decouple: float  # 1: dq decoupling with the nameplate L_s
    feedforward: float  # 1: back-EMF feed-forward ω_e·ψ_m (nameplate ψ_m)
    advance: float  # angle advance of the inverse Park, in update periods (0: none)
    V_lim: float  # dq voltage limit [V]
    V_dc: float  # DC bus [V]
    L_s: float  # nameplate inductance, for the decoupling [H]
    psi_m: float  # nameplate flux linkage, for the feed-forward [Wb]
    p: float  # pole pairs [-]


@jit
def dq_currents(i_a, i_b, sin_e, cos_e):  # type: ignore[no-untyped-def]
    """(i_d, i_q) of phase currents with i_c = −(i_a + i_b): i_α = i_a, i_β = (i_a + 2·i_b)/√3."""
    i_alpha = i_a
    i_beta = (i_a + 2.0 * i_b) / SQRT3
    return i_alpha * cos_e + i_beta * sin_e, -i_alpha * sin_e + i_beta * cos_e


@jit
def pi_voltages(i_d, i_q, i_q_ref, omega_m, I_d, I_q, fp):  # type: ignore[no-untyped-def]
    """One sample of the two PI loops: returns (v_d, v_q, I_d, I_q) after the limit and anti-windup."""
    omega_e = fp.p * omega_m
    e_d = -i_d
    e_q = i_q_ref - i_q
    v_d = fp.K_p * e_d + I_d
    v_q = fp.K_p * e_q + I_q
    if fp.decouple != 0.0:
        v_d -= omega_e * fp.L_s * i_q
        v_q += omega_e * fp.L_s * i_d
    if fp.feedforward != 0.0:
        v_q += omega_e * fp.psi_m
    mag = math.sqrt(v_d * v_d + v_q * v_q)
    if mag > fp.V_lim:
        scale = fp.V_lim / mag
        v_d *= scale
        v_q *= scale
    else:
        I_d += fp.K_i * fp.T_u * e_d
        I_q += fp.K_i * fp.T_u * e_q
    return v_d, v_q, I_d, I_q


@jit
def duties(v_d, v_q, sin_e, cos_e, i_a, i_b, fp):  # type: ignore[no-untyped-def]
    """Leg duties (d_a, d_b, d_c) ∈ [0, 1] for the dq voltage at the angle (sin_e, cos_e)."""
    v_alpha = v_d * cos_e - v_q * sin_e
    v_beta = v_d * sin_e + v_q * cos_e
    v_a = v_alpha
    v_b = -0.5 * v_alpha + HALF_SQRT3 * v_beta
    v_c = -0.5 * v_alpha - HALF_SQRT3 * v_beta
    if fp.svpwm != 0.0:
        v_0 = -0.5 * (max(v_a, v_b, v_c) + min(v_a, v_b, v_c))
    else:
        v_0 = 0.0
    inv = 1.0 / fp.V_dc
    d_a = 0.5 + (v_a + v_0) * inv
    d_b = 0.5 + (v_b + v_0) * inv
    d_c = 0.5 + (v_c + v_0) * inv
    if fp.comp != 0.0:
        step = fp.t_d / fp.T_pwm
        i_c = -(i_a + i_b)
        d_a += step if i_a > 0.0 else (-step if i_a < 0.0 else 0.0)
        d_b += step if i_b > 0.0 else (-step if i_b < 0.0 else 0.0)
        d_c += step if i_c > 0.0 else (-step if i_c < 0.0 else 0.0)
    return min(max(d_a, 0.0), 1.0), min(max(d_b, 0.0), 1.0), min(max(d_c, 0.0), 1.0)


@jit
def drive_update(i_a, i_b, sin_e, cos_e, omega_m, i_q_ref, I_d, I_q, fp):  # type: ignore[no-untyped-def]
    """Steps 1–3 of the module docstring: returns (d_a, d_b, d_c, I_d, I_q)."""
    i_d, i_q = dq_currents(i_a, i_b, sin_e, cos_e)
    v_d, v_q, I_d, I_q = pi_voltages(i_d, i_q, i_q_ref, omega_m, I_d, I_q, fp)
    if fp.advance != 0.0:  # the voltage acts later than it was computed: rotate it ahead
        a = fp.advance * fp.T_u * fp.p * omega_m
        s, c = math.sin(a), math.cos(a)
        sin_e, cos_e = sin_e * c + cos_e * s, cos_e * c - sin_e * s
    d_a, d_b, d_c = duties(v_d, v_q, sin_e, cos_e, i_a, i_b, fp)
    return d_a, d_b, d_c, I_d, I_q


@jit
def window(d, peak, fp):  # type: ignore[no-untyped-def]
    """(lo, hi): the leg's high interval for duty d, relative to the update instant [s].

    Single update, from a peak: [(1 − d)·T/2, (1 + d)·T/2]. Double update, from a peak:
    [(1 − d)·T/2, T/2]; from a valley: [0, d·T/2].
    """
    half = 0.5 * fp.T_pwm
    if fp.double == 0.0:
        return (1.0 - d) * half, (1.0 + d) * half
    if peak:
        return (1.0 - d) * half, half
    return 0.0, d * half


@jit
def overlap(a, b, lo, hi):  # type: ignore[no-untyped-def]
    """Length of [a, b] ∩ [lo, hi] (0 when they do not meet)."""
    return max(0.0, min(b, hi) - max(a, lo))


@jit
def carried(lo_old, hi_old, lo_new, hi_new, fp):  # type: ignore[no-untyped-def]
    """(c_end, c_kind): the dead time that runs into a new update interval from its start, up to
    c_end, after a falling edge (c_kind = +1: the leg stays high while its current is negative)
    or a rising one (c_kind = −1: it stays low while its current is positive); (0, 0) for none.

    An edge at the update instant itself (the gate high at the old interval's end and low at the
    new one's start, or the reverse) has its whole dead time in the new interval; otherwise an
    edge of the old interval whose dead time overruns its end carries the rest: a falling edge
    near full duty, or with a double update a rising one just before the valley.
    """
    high_end = hi_old >= fp.T_u and hi_old > lo_old  # the gate at the old interval's end
    high_start = lo_new <= 0.0 and hi_new > lo_new  # and at the new one's start
    if high_end != high_start:
        return fp.t_d, (1.0 if high_end else -1.0)
    if not high_end and lo_old < hi_old < fp.T_u and hi_old + fp.t_d > fp.T_u:
        return hi_old + fp.t_d - fp.T_u, 1.0
    if high_end and 0.0 < lo_old < fp.T_u and lo_old + fp.t_d > fp.T_u:
        return lo_old + fp.t_d - fp.T_u, -1.0
    return 0.0, 0.0


@jit
def leg_state(tau, dt, lo, hi, c_end, c_kind, i_x, fp):  # type: ignore[no-untyped-def]
    """s_x = 2·f − 1, f the fraction of the step [τ, τ + Δt] the leg is high (τ from the update instant).

    The gate is high over the window [lo, hi]; for t_d after each of its edges both switches are
    off and the diode holds the leg by the current's sign: after a rising edge (lo > 0) the leg
    is still low while i_x > 0, after a falling edge (hi < T_u) still high while i_x < 0. The dead
    time an edge at or before the update instant carries in (`carried`: up to c_end) counts too.
    """
    a = tau
    b = tau + dt
    f = overlap(a, b, lo, hi) if hi > lo else 0.0
    if i_x > 0.0:
        if 0.0 < lo < hi:  # rising edge: low for t_d more (within the pulse)
            f -= overlap(a, b, lo, min(lo + fp.t_d, hi))
        if c_kind < 0.0 and lo <= 0.0 and hi > lo:  # a rising edge's dead time carried in
            f -= overlap(a, b, 0.0, min(c_end, hi))
    elif i_x < 0.0:
        if lo < hi < fp.T_u:  # falling edge: high for t_d more (within the interval)
            f += overlap(a, b, hi, min(hi + fp.t_d, fp.T_u))
        if c_kind > 0.0:  # a falling edge's dead time carried in, where the gate is low
            gate_low_end = lo if hi > lo else c_end
            f += overlap(a, b, 0.0, min(c_end, max(gate_low_end, 0.0)))
    return 2.0 * f / dt - 1.0
