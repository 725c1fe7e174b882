import numpy as np
import pytest

from emaphm import Chirp, InputError, make_command


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


@pytest.mark.parametrize("name", ["chirp", "step", "ramp", "sine"])
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
