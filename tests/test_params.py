import dataclasses

import pytest

from emaphm import EmaParams, InputError, IntegrationParams, MotorParams, SensorParams, TransmissionParams
from emaphm.params import parameter_table_markdown


def test_nominal_values_and_derived_constants():
    p = EmaParams()
    assert p.motor.k_e == pytest.approx(0.10)  # V·s/rad, DESIGN §7
    assert p.motor.k_t == pytest.approx(0.15)  # N·m/A
    assert p.transmission.J == pytest.approx(5.125e-5)  # kg·m²
    assert p.steps_per_sample == 100
    # DESIGN §7: output capacity τ·η·k_t·I_max = 270 N·m
    assert p.transmission.tau * p.transmission.eta * p.motor.k_t * p.controller.I_max == pytest.approx(270)


def test_every_field_has_symbol_unit_and_meaning():
    for group in (MotorParams, TransmissionParams, SensorParams, IntegrationParams):
        for f in dataclasses.fields(group):
            assert {"symbol", "unit", "doc", "check"} <= set(f.metadata), f.name


@pytest.mark.parametrize(
    ("build", "match"),
    [
        (lambda: MotorParams(R_s=-1.0), "R_s must be > 0"),
        (lambda: MotorParams(L_s=float("nan")), "finite"),
        (lambda: MotorParams(p=2.5), "pole pairs"),
        (lambda: TransmissionParams(F_S0=0.01, F_D0=0.02), "exceeds static"),
        (lambda: TransmissionParams(eta=1.5), "eta"),
        (lambda: SensorParams(bits_current=40), "bits_current"),
        (lambda: EmaParams(integration=IntegrationParams(dt=3e-6)), "whole number of steps"),
        (lambda: MotorParams(R_s="0.5"), "must be a number"),
    ],
)
def test_invalid_parameters_are_rejected(build, match):
    with pytest.raises(InputError, match=match):
        build()


def test_dict_round_trip():
    p = EmaParams(motor=MotorParams(R_s=0.7))
    assert EmaParams.from_dict(p.to_dict()) == p
    with pytest.raises(InputError):
        EmaParams.from_dict({"motr": {}})


def test_parameter_table_lists_every_field():
    table = parameter_table_markdown()
    for group in (MotorParams, TransmissionParams, SensorParams):
        for f in dataclasses.fields(group):
            assert f"`{f.name}`" in table
