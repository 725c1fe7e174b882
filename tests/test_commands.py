import numpy as np
import pytest

from emaphm import Chirp, InputError, make_command
from emaphm.commands import ChirpHold, Steps, command_record


def test_chirp_respects_amplitude_and_velocity_limits():
    c = Chirp()
    t = np.linspace(0, c.duration, 200001)
    theta = c(t)
    assert theta[0] == 0.0
    assert np.max(np.abs(theta)) <= c.A_max
    velocity = np.gradient(theta, t)
    # V_max caps A·2πf; the amplitude and fade-in envelopes add a little on top
    assert np.max(np.abs(velocity)) < 1.15 * c.V_max


def test_chirp_frequency_sweeps_f0_to_f1():
    c = Chirp()
    t = np.linspace(0, 1, 100001)
    crossings = np.flatnonzero(np.diff(np.sign(c(t[1:]))) != 0)
    # φ(T) = 2π(f0 + f1)/2·T: (0.5 + 10)/2 = 5.25 cycles, 10 zero crossings after t = 0
    assert len(crossings) == 10


@pytest.mark.parametrize("name", ["chirp", "chirp-hold", "steps", "step", "ramp", "sine"])
def test_every_command_builds_and_starts_near_rest(name):
    cmd = make_command(name)
    assert cmd.duration > 0
    assert abs(float(cmd(np.array([0.0]))[0])) < 1e-12


def test_bad_commands():
    with pytest.raises(InputError, match="unknown command"):
        make_command("square")
    with pytest.raises(InputError, match="bad settings"):
        make_command("sine", amplitud=1)
    with pytest.raises(InputError, match="> 0"):
        Chirp(T=0.0)


def test_chirp_hold_is_the_chirp_then_a_ramp_to_zero_then_rest():
    c = ChirpHold(hold=0.5, ramp=0.05)
    assert c.duration == 1.5
    t = np.linspace(0, 1.5, 15001)
    theta = c(t)
    np.testing.assert_array_equal(theta[t <= 1.0], Chirp()(t[t <= 1.0]))
    assert np.all(theta[t >= 1.05] == 0.0)
    ramp = theta[(t > 1.0) & (t < 1.05)]
    assert np.all(np.abs(np.diff(ramp)) <= abs(float(Chirp()(np.array([1.0]))[0])) / 500 + 1e-12)


def test_the_chirp_run_on_is_a_longer_sweep():
    # `simulate --duration 2` on the 1 s chirp equals a 2 s chirp from 0.5 to 19.5 Hz (same phase law)
    t = np.linspace(0, 2, 20001)
    np.testing.assert_allclose(Chirp()(t), Chirp(T=2.0, f1=19.5)(t), rtol=0, atol=1e-12)


def test_steps_hold_each_level_for_a_dwell():
    s = Steps(levels=(0.01, -0.02, 0.03), dwell=0.1)
    assert s.duration == pytest.approx(0.3)
    t = np.arange(3001) / 1e4
    theta = s(t)
    assert np.all(theta[t < 0.1 - 1e-9] == 0.01) and np.all(theta[(t >= 0.1) & (t < 0.2 - 1e-9)] == -0.02)
    assert np.all(theta[t >= 0.2] == 0.03)


def test_new_commands_round_trip_through_their_record():
    for c in (ChirpHold(hold=0.3), Steps(levels=(0.0, 0.02), dwell=0.25)):
        rec = command_record(c)
        kind = rec.pop("type")
        assert make_command(kind, **rec) == c


def test_bad_new_commands():
    for levels in ((), None, 5, (0.1, True), ("a",)):
        with pytest.raises(InputError, match=r"Steps\.levels must be a non-empty list"):
            Steps(levels=levels)
    assert Steps(levels=np.array([0.01, -0.02])).levels == (0.01, -0.02)  # numpy values are numbers
    with pytest.raises(InputError, match="at least its ramp"):
        ChirpHold(hold=0.01, ramp=0.05)
    with pytest.raises(InputError, match="levels"):
        make_command("steps", levels=[0.0, float("nan")])
    with pytest.raises(InputError, match="dwell"):
        Steps(dwell=0.0)
    with pytest.raises(InputError, match="hold"):
        ChirpHold(hold=-1.0)
