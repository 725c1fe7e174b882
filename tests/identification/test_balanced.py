"""A magnet flux below its nameplate reads as shorts in every phase (issue 34, item 2:
`identification.uncertainty.balanced`)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import emaphm
from emaphm.actuator import resolve_params
from emaphm.faults import FAULT_NAMES, HEALTHY, SHORTS
from emaphm.identification.uncertainty import Uncertainty
from emaphm.identification.uncertainty.balanced import (
    BAND,
    CONSISTENT,
    SLOPE,
    allowance,
    discounted,
    doubts,
    widen,
)  # fmt: skip
from emaphm.models import HighFidelityEma

THRESHOLDS = {"short_a": 0.0074, "short_b": 0.0104, "short_c": 0.0095}


def _faults(shorts: tuple[float, float, float]) -> np.ndarray:
    k = np.array(HEALTHY, dtype=float)
    k[list(SHORTS)] = shorts
    return k


def _interval(k: np.ndarray, half: float = 0.008) -> Uncertainty:
    n = len(FAULT_NAMES)
    low, high = np.clip(k - half, 0, 1), np.clip(k + half, 0, 1)
    return Uncertainty("laplace", np.full(n, half / 1.645), low, high, np.eye(n), [[] for _ in range(n)], np.zeros(n), 0)


def test_the_allowance_follows_the_flux_tolerance_and_a_baseline_removes_it(tmp_path):
    beta, source = allowance(None, baseline=False)
    assert beta == pytest.approx(SLOPE * BAND * 0.02) and "default tolerances" in source
    path = tmp_path / "a.toml"
    path.write_text("[tolerances]\npsi_m = 0.05\n")
    assert allowance(path, baseline=False)[0] == pytest.approx(SLOPE * BAND * 0.05)
    path.write_text("[tolerances]\npsi_m = 0\n")
    assert allowance(path, baseline=False)[0] == 0.0
    assert allowance(None, baseline=True)[0] == 0.0


def test_shorts_in_every_phase_lose_their_balanced_part_one_healthy_phase_keeps_them():
    beta = 0.024
    k = _faults((0.02, 0.007, 0.03))  # what a healthy actuator with psi_m -1.6 % reads
    got = widen(_interval(k), k, beta, "test")
    low = np.array(got.ci90_low)
    # each short's lower end drops by min(k, beta): the first two reach 0, the third keeps 0.03 - 0.008 - 0.024
    assert low[list(SHORTS)] == pytest.approx([0.0, 0.0, 0.0])
    assert got.details["balanced_allowance"]["lowered_by"] == pytest.approx([0.02, 0.007, 0.024])
    assert got.details["balanced_allowance"]["low_before"] == pytest.approx([0.012, 0.0, 0.022])
    # the other faults are untouched; each short's upper end rises by beta (a flux above its nameplate)
    others = [j for j in range(8) if j not in SHORTS]
    assert np.array_equal(low[others], _interval(k).ci90_low[others])
    assert np.array_equal(got.ci90_high[others], _interval(k).ci90_high[others])
    assert got.ci90_high[list(SHORTS)] == pytest.approx(_interval(k).ci90_high[list(SHORTS)] + beta)
    # a large short keeps all but beta of its lower end
    k2 = _faults((0.02, 0.3, 0.02))
    assert widen(_interval(k2), k2, beta, "t").ci90_low[SHORTS[1]] == pytest.approx(0.3 - 0.008 - beta)
    # one phase near 0 rules a lower flux out: the lower ends stay, the upper ones still rise
    k3 = _faults((0.02, CONSISTENT / 2, 0.03))
    kept = widen(_interval(k3), k3, beta, "t")
    assert np.array_equal(kept.ci90_low, _interval(k3).ci90_low)
    assert kept.ci90_high[SHORTS[1]] == pytest.approx(CONSISTENT / 2 + 0.008 + beta)
    assert kept.details["balanced_allowance"]["lowered_by"] is None
    # no allowance (a baseline): nothing moves
    same = widen(_interval(k), k, 0.0, "t")
    assert np.array_equal(same.ci90_low, _interval(k).ci90_low) and np.array_equal(same.ci90_high, _interval(k).ci90_high)
    assert np.array_equal(discounted(k3, beta), k3)
    assert discounted(k, beta)[list(SHORTS)] == pytest.approx([0.0, 0.0, 0.006])


def test_a_result_whose_shorts_all_fit_the_flux_is_doubtful_and_only_then():
    beta = 0.024
    k = _faults((0.02, 0.007, 0.03))
    (reason,) = doubts(k, beta, "psi_m ±2 %", THRESHOLDS, None)  # the point rule would report short A
    assert isinstance(reason, emaphm.errors.Doubt) and "emaphm baseline" in reason and "1.6 %" in reason
    # with intervals: doubtful when the allowance took a "present" away (short A's 0.012 > 0.0074) ...
    assert len(doubts(k, beta, "s", THRESHOLDS, widen(_interval(k), k, beta, "s"))) == 1
    # ... not when no short was "present" before it (every lower end within its threshold)
    wide = widen(_interval(k, half=0.025), k, beta, "s")
    assert doubts(k, beta, "s", THRESHOLDS, wide) == []
    assert doubts(_faults((0.02, 0.3, 0.02)), beta, "s", THRESHOLDS, None) == []  # a real short beyond 2 beta
    assert doubts(_faults((0.005, 0.006, 0.005)), beta, "s", THRESHOLDS, None) == []  # none beyond its threshold
    assert doubts(_faults((0.02, 0.0, 0.03)), beta, "s", THRESHOLDS, None) == []  # a healthy phase
    assert doubts(k, 0.0, "s", THRESHOLDS, None) == []  # a baseline: no allowance


@pytest.mark.slow
def test_a_weaker_magnet_is_not_reported_as_three_shorts():
    nameplate = resolve_params(None)
    weak = dataclasses.replace(nameplate, motor=dataclasses.replace(nameplate.motor, psi_m=0.98 * nameplate.motor.psi_m))
    trace = HighFidelityEma(weak).simulate(np.array(HEALTHY, dtype=float), seed=5)
    r = emaphm.identify(reference=trace, seed=1)
    assert not any(n.startswith("short") for n in r.detected)  # what must hold on every machine
    allowance = r.uncertainty.details["balanced_allowance"]
    assert allowance["lowered_by"] is not None
    # doubtful exactly when the allowance took a "present" away: a short's lower end before it
    # beyond its threshold (machine D: short A's, doubtful; machine E: 0.0014, "fits")
    from emaphm.identification.detection import load_thresholds

    thresholds = load_thresholds()["thresholds"]
    present_before = any(lo > thresholds[FAULT_NAMES[i]] for i, lo in zip(SHORTS, allowance["low_before"], strict=True))
    said = any("every phase reads a small short" in d for d in r.doubts)
    assert said == present_before and r.verdict != "does not fit"
    if said:
        assert r.verdict == "doubtful"
    # the same recording with no flux tolerance: the shorts are what the monitor found
    assert doubts(r.estimate, 0.0, "s", None, r.uncertainty) == []


def test_the_interval_calibration_fits_the_factors_to_the_intervals_with_the_allowance():
    from emaphm.identification.uncertainty import fit_factors

    rng = np.random.default_rng(3)
    T = rng.uniform(0.05, 0.5, size=(60, 8))
    T[:, 6], T[:, 5] = rng.uniform(0, 1, 60), 0.2
    E = T.copy()
    E[:, list(SHORTS)] -= 0.02  # every short read low, as a flux above its nameplate reads them
    S = np.full_like(E, 0.005)
    plain, _ = fit_factors(E, S, T)
    allowed_for, _ = fit_factors(E, S, T, balanced=0.024)
    for j in SHORTS:
        # without the allowance the scale must reach 0.02 / (1.645 * 0.005) ~ 2.4 to cover the bias; with it, the grid's bottom
        assert plain.scale[j] > 2.0 and allowed_for.scale[j] == pytest.approx(0.3)
    others = [j for j in range(8) if j not in SHORTS]
    assert np.array_equal(plain.scale[others], allowed_for.scale[others])
