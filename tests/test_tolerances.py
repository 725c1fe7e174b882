"""`emaphm.tolerances.drawn_actuator`: actuators drawn about a nameplate, reproducible from a seed."""

import dataclasses

import pytest

from emaphm.params import EmaParams, InverterParams
from emaphm.tolerances import TOLERANCED, drawn_actuator

FOC = EmaParams(inverter=InverterParams(control="foc"))


def test_the_same_seed_draws_the_same_actuator_and_another_seed_another():
    a = drawn_actuator(FOC, 7, tolerance=0.02, drive_tolerance=0.1, steps=(5e-7, 1e-6, 2e-6))
    assert a == drawn_actuator(FOC, 7, tolerance=0.02, drive_tolerance=0.1, steps=(5e-7, 1e-6, 2e-6))
    assert a != drawn_actuator(FOC, 8, tolerance=0.02, drive_tolerance=0.1, steps=(5e-7, 1e-6, 2e-6))


@pytest.mark.parametrize("seed", range(20))
def test_every_draw_lies_within_its_tolerance(seed):
    a = drawn_actuator(FOC, seed, tolerance=0.02, drive_tolerance=0.1, steps=(5e-7, 2e-6))
    for group, names in TOLERANCED.items():
        for name in names:
            ratio = getattr(getattr(a, group), name) / getattr(getattr(FOC, group), name)
            assert 0.98 <= ratio <= 1.02 and ratio != 1.0, name
    for name in ("K_p_i", "K_i_i"):
        ratio = getattr(a.inverter, name) / getattr(FOC.inverter, name)
        assert 0.9 <= ratio <= 1.1 and ratio != 1.0, name
    assert 0.0 <= a.inverter.pwm_phase < 1.0 and a.integration.dt in (5e-7, 2e-6)
    # what is not drawn stays the nameplate's
    assert a.inverter.f_pwm == FOC.inverter.f_pwm and a.motor.p == FOC.motor.p
    assert a.transmission.tau == FOC.transmission.tau and a.controller == FOC.controller


def test_no_spread_is_the_nameplate_and_a_hysteresis_drive_keeps_its_drive():
    assert drawn_actuator(FOC, 3) == FOC
    nominal = EmaParams()
    drawn = drawn_actuator(nominal, 3, drive_tolerance=0.1)
    assert drawn == nominal  # no PI to draw, no carrier
    assert dataclasses.replace(drawn_actuator(nominal, 3, tolerance=0.05), motor=nominal.motor,
                               transmission=nominal.transmission) == nominal  # fmt: skip
