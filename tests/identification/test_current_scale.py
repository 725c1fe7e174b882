"""The current's scale (issue 34): a current sensor's gain is found and made a reason for "doubtful";
a balanced short of all three phases, which also raises the current, is not taken for one."""

from __future__ import annotations

import numpy as np
import pytest

import emaphm
from emaphm.commands import SampledCommand
from emaphm.errors import Doubt
from emaphm.identification import FaultIdentifier, limits
from emaphm.identification.current_scale import current_scale, scale_doubts, scale_limit
from emaphm.results import SimResult

# the newcomer's rig (bench_rig_mistakes.py): friction x1.6, free play, a 25 % short in phase B,
# eccentricity 0.1, K_P -8 %
TRUTH = np.array([0.30, 0.15, 0.0, 0.25, 0.0, 0.10, 0.60, 0.42])
BALANCED = np.array([0.20, 0.10, 0.20, 0.25, 0.30, 0.10, 0.60, 0.50])


def _scaled(trace: SimResult, gain: float) -> SimResult:
    currents = {n: gain * v for n, v in trace.signals.items() if n.startswith("i_")}
    return SimResult(t=trace.t, signals={**trace.signals, **currents})


def _context(trace: SimResult):
    command = SampledCommand(trace.t - trace.t[0], trace.theta_cmd)
    return FaultIdentifier(seed=1).prepare(trace.t, trace.i_q, command, trace.theta_u).context_


@pytest.fixture(scope="module")
def twin():
    return emaphm.simulate(TRUTH, seed=5)


@pytest.mark.parametrize("gain", [0.94, 1.07])
def test_a_sensor_gain_is_recovered_and_the_faults_with_it(twin, gain):
    # from the faults the unscaled monitor would settle on is no matter: from the truth here
    record = current_scale(_context(_scaled(twin, gain)), TRUTH, {"short_b"})
    assert record["gain"] == pytest.approx(gain, abs=0.006)
    assert record["fit_ratio"] > 1.05  # the scale explains the recording better than faults alone
    assert record["held"] == ["short_a", "short_c"]
    assert emaphm.percent_error(record["faults_if_scaled"], TRUTH) < 3.0
    doubts = scale_doubts(record, *scale_limit(None))
    assert len(doubts) == 1 and isinstance(doubts[0], Doubt) and f"{gain:.3f} x" in doubts[0]
    assert "short_b 0.2" in doubts[0]  # the faults if the gain is the cause


def test_the_twin_itself_is_within_the_monitors_own_scatter(twin):
    record = current_scale(_context(twin), TRUTH, {"short_b"})
    assert abs(record["gain"] - 1.0) < limits.CURRENT_SCALE_RATIO_GAIN
    assert record["fit_ratio"] is None  # within 1 % of 1: the unscaled refit is not needed
    assert scale_doubts(record, *scale_limit(None)) == []


@pytest.fixture(scope="module")
def balanced():
    return emaphm.simulate(BALANCED, seed=6)


def test_a_balanced_short_of_three_phases_is_not_taken_for_a_gain(balanced):
    record = current_scale(_context(balanced), BALANCED, {"short_a", "short_b", "short_c"})
    assert record["held"] == []
    assert abs(record["gain"] - 1.0) < limits.CURRENT_SCALE_SPREAD  # the shorts, not a scale
    assert scale_doubts(record, *scale_limit(None)) == []


def test_a_gain_on_top_of_three_shorts_is_still_seen(balanced):
    # γ and three shorts trade against each other: γ comes out short of the gain, the fit tells
    record = current_scale(_context(_scaled(balanced, 1.06)), BALANCED, {"short_a", "short_b", "short_c"})
    assert record["gain"] > 1.0 + limits.CURRENT_SCALE_RATIO_GAIN
    doubts = scale_doubts(record, *scale_limit(None))
    assert len(doubts) == 1 and "measured current" in doubts[0]


def test_the_limit_is_the_actuator_files_tolerances_and_the_monitors_scatter(tmp_path):
    assert scale_limit(None)[0] == pytest.approx(np.hypot(0.02, limits.CURRENT_SCALE_SPREAD))
    path = tmp_path / "actuator.toml"
    path.write_text("[tolerances]\npsi_m = 0.05\ncurrent_gain = 0.01\n")
    limit, source = scale_limit(path)
    assert limit == pytest.approx(np.hypot(0.06, limits.CURRENT_SCALE_SPREAD)) and str(path) in source


def test_an_identification_with_a_sensor_gain_is_doubtful_and_says_so(twin):
    r = emaphm.identify(reference=_scaled(twin, 0.94), seed=1, pop_size=32, generations=8, uncertainty="none")
    assert r.verdict == "doubtful"
    assert any("the measured current is 0.9" in d for d in r.doubts)
    assert r.settings["current_scale"]["gain"] == pytest.approx(0.94, abs=0.01)
    clean = emaphm.identify(reference=twin, seed=1, pop_size=32, generations=8, uncertainty="none")
    assert not any("measured current" in d for d in clean.doubts)
    assert abs(clean.settings["current_scale"]["gain"] - 1.0) < limits.CURRENT_SCALE_SPREAD
