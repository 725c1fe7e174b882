"""Every threshold of the measured-data reader in one place (next-features §D.3–§D.4).

The values are *choices*; each line says why. They are recorded in each reference's report.
"""

from __future__ import annotations

__all__ = [
    "ALIGNMENT_RESIDUAL_MAX",
    "ANGLE_RATIO_TOLERANCE",
    "ANGLE_RATIO_TOLERANCE_CMD",
    "CURRENT_FACTOR",
    "FEW_SAMPLES",
    "FROZEN_MIN_S",
    "FROZEN_MIN_SAMPLES",
    "GAP_FACTOR",
    "MAX_SAMPLES",
    "MAX_SPAN",
    "MIN_DURATION",
    "MIN_RATE_FAST",
    "MIN_RATE_SLOW",
    "OFFSET_DISAGREE_DEG",
    "OUTLIER_FACTOR",
    "POSITION_FACTOR",
    "REST_SPREAD",
    "REST_WINDOW_S",
    "SATURATION_RUN",
    "SPREAD_FLOOR",
    "ZERO_SEQUENCE_MAX",
    "as_dict",
]

MAX_SAMPLES = 200_000_000  # per channel: 1.6 GB of float64, refused before reading where possible
MAX_SPAN = 100.0  # [s] a record longer than this is almost surely a time axis in ms declared as s
MIN_DURATION = 0.2  # [s] shortest clean segment worth identifying on (2000 samples at 10 kHz)
GAP_FACTOR = 1.5  # a time step above 1.5 × the median step is a gap (DESIGN note §D.3 item 4)
MIN_RATE_FAST = 2_000.0  # [Hz] currents and angles: the hysteresis/PWM dynamics and θ_e at 50 Hz
MIN_RATE_SLOW = 50.0  # [Hz] theta_cmd, theta_u: the FDI chirp ends at 10 Hz, interpolated linearly
CURRENT_FACTOR = 1.5  # |i| above 1.5 × I_max on more than FEW_SAMPLES samples: a unit error
POSITION_FACTOR = 1.5  # |θ| above 1.5 × theta_max on more than FEW_SAMPLES samples: a unit error
FEW_SAMPLES = 3  # isolated excursions tolerated by the range checks
OUTLIER_FACTOR = 100.0  # a sample this many robust spreads away from the median is an outlier
SPREAD_FLOOR = 0.01  # the robust spread is at least this fraction of I_max or theta_max (a long hold)
SATURATION_RUN = 5  # equal samples at a channel's extreme: the sensor or ADC saturated
ZERO_SEQUENCE_MAX = 0.05  # low-passed RMS(i_a + i_b + i_c) over the phase RMS (§D.3 item 6)
ALIGNMENT_RESIDUAL_MAX = 0.25  # mean(i_d²)/mean(i_d² + i_q²) at the best θ0: the angle fits
# [deg, electrical] a map's θ0 this far from the estimate is questioned: the estimate's own error is
# 0.03-0.3° on the twin (bench_reader), and 5° mechanical written for 20° electrical under-read a
# short by 20 % (the newcomer's m4b)
OFFSET_DISAGREE_DEG = 3.0
# a recording starts at rest when its position command moves by at most REST_SPREAD of its whole
# range over its first REST_WINDOW_S: the FDI chirp moves 0.26 % in its first 5 ms, 1.7 % at
# 0.1 s into it and about 4 % from 0.25 s on; the monitor starts at rest (the newcomer's logger
# started 0.10-0.75 s into the chirp)
REST_WINDOW_S = 0.005
REST_SPREAD = 0.01
# a current that holds exactly one value this long (and over this many samples) while the command
# moves is a dropout logged as zeros or held values (on the twin's chirp, 12 bits and 20 mA of
# noise, no current repeats a value 10 times running while the command moves: tests/measured)
FROZEN_MIN_S = 0.002
FROZEN_MIN_SAMPLES = 10
ANGLE_RATIO_TOLERANCE = 2.0  # std θ_e / std θ_u within a factor 2 of p·τ (twin: 0.99–1.23 over k1..k8)
ANGLE_RATIO_TOLERANCE_CMD = 3.0  # against θ_cmd, which the loop tracks with lag (twin: 0.89–1.44)


def as_dict() -> dict[str, float]:
    """The thresholds, for a report."""
    return {name: float(globals()[name]) for name in __all__ if name != "as_dict"}
