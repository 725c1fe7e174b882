"""The motion's preconditions (issue 34): a command out of step, a position scale that is not the surface's."""

from __future__ import annotations

import numpy as np
import pytest

import emaphm
from emaphm.commands import SampledCommand
from emaphm.errors import Doubt
from emaphm.identification import FaultIdentifier, limits
from emaphm.identification.preconditions import lag_and_scale, motion_doubts

TRUTH = np.array(emaphm.TABLE1_REFERENCE)


def test_the_lag_and_scale_of_a_shifted_scaled_copy_are_recovered_between_samples():
    t = np.arange(0.0, 1.0, 1e-4)
    motion = lambda s: 0.1 * np.sin(2 * np.pi * (1 + 2 * s) * s) * np.exp(-s)  # noqa: E731  a chirp
    for lag, scale in ((0.00137, 0.93), (-0.0042, 1.0), (0.0, 1.07)):
        tau, a = lag_and_scale(t, scale * motion(t - lag), motion(t), 0.008)
        assert tau == pytest.approx(lag, abs=2e-5) and a == pytest.approx(scale, rel=0.01)
    assert all(np.isnan(lag_and_scale(t, motion(t), np.zeros_like(t), 0.008)))  # a model that does not move


@pytest.fixture(scope="module")
def twin():
    return emaphm.simulate(TRUTH, seed=5)


def _doubts(trace, theta_cmd=None, theta_u=None):
    t = trace.t
    command = SampledCommand(t - t[0], trace.theta_cmd if theta_cmd is None else theta_cmd)
    ident = FaultIdentifier(seed=1).prepare(t, trace.i_q, command, trace.theta_u)
    return motion_doubts(ident.context_, TRUTH, t, trace.theta_u if theta_u is None else theta_u)


def test_the_twin_moves_as_its_monitor_says_and_two_rig_mistakes_do_not(twin):
    doubts, record = _doubts(twin)
    assert doubts == [] and abs(record["lag_s"]) < 0.5 * limits.MOTION_LAG_MAX_S and abs(record["scale"] - 1) < 0.01
    # the newcomer's m12: the command stamped 5 ms late (two loggers)
    late = np.interp(twin.t - 0.005, twin.t, twin.theta_cmd, left=0.0)
    doubts, record = _doubts(twin, theta_cmd=late)
    assert record["lag_s"] == pytest.approx(-0.005, abs=0.001)
    assert len(doubts) == 1 and isinstance(doubts[0], Doubt) and "leads" in doubts[0] and "out of step" in doubts[0]
    # m1j: the positions 10 % off (a lever arm)
    doubts, record = _doubts(twin, theta_u=0.9 * twin.theta_u)
    assert record["scale"] == pytest.approx(0.9, abs=0.005) and len(doubts) == 1 and "0.90" in doubts[0] and "position scale" in doubts[0]


def test_without_a_measured_position_nothing_is_checked(twin):
    ident = FaultIdentifier(seed=1).prepare(twin.t, twin.i_q)
    assert motion_doubts(ident.context_, TRUTH, twin.t, None) == ([], None)


def test_a_late_command_makes_the_identification_doubtful(twin):
    late = np.interp(twin.t - 0.005, twin.t, twin.theta_cmd, left=0.0)
    recording = emaphm.SimResult(t=twin.t, signals={**twin.signals, "theta_cmd": late})
    r = emaphm.identify(reference=recording, seed=1, pop_size=16, generations=2, polish=False, uncertainty="none")
    assert r.verdict == "doubtful" and any("out of step" in d for d in r.doubts)
    assert r.settings["motion"]["lag_s"] < -limits.MOTION_LAG_MAX_S
