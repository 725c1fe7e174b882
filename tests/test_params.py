"""Nominal parameters against the design spec, validation, and the generated parameter table."""

import dataclasses
import re

import pytest

from emaphm import EmaParams, InputError, IntegrationParams, MotorParams, SensorParams, TransmissionParams
from emaphm.params import _GROUPS, parameter_table_markdown

# The nominal values as written in the design spec (DESIGN §7 table, §3.9 for the ADC bits, §7
# "no load" for T_load), by hand, NOT from the code. The hysteresis band is the project's 0.1 A,
# not DESIGN's original 0.2 A (docs/theory/hf-model.md §4). Sensor ranges, noise and r_h are
# not in DESIGN: their values are the hand-written prose of docs/theory/hf-model.md §8 and §9.
SPEC = {
    "MotorParams": {"p": (4, "-"), "R_s": (0.5, "Ω"), "L_s": (1.5e-3, "H"), "psi_m": (0.025, "Wb")},
    "InverterParams": {"V_dc": (48.0, "V"), "h": (0.1, "A")},
    "TransmissionParams": {
        "J_m": (5e-5, "kg·m²"), "J_u": (0.05, "kg·m²"), "tau": (200.0, "-"), "eta": (0.9, "-"),
        "C": (1e-5, "N·m·s/rad"), "F_S0": (0.02, "N·m"), "F_D0": (0.014, "N·m"), "B0": (2e-4, "rad"),
        "theta_max": (0.5, "rad"), "T_load": (0.0, "N·m"),
    },
    "ControllerParams": {
        "K_P0": (60.0, "A/rad"), "K_I": (200.0, "A/(rad·s)"), "K_D": (3.5, "A·s/rad"),
        "tau_D": (1e-3, "s"), "I_max": (10.0, "A"), "f_s": (1e4, "Hz"),
    },
    "SensorParams": {
        "bits_current": (12, "bit"), "full_scale_current": (20.0, "A"), "sigma_current": (0.02, "A"),
        "bits_position": (16, "bit"), "full_scale_position": (0.6, "rad"), "sigma_position": (1e-5, "rad"),
    },
    "IntegrationParams": {"dt": (1e-6, "s"), "ripple_fraction": (0.4, "-")},
}  # fmt: skip


def test_groups_and_fields_are_those_of_the_spec():
    # a new, renamed or dropped parameter must be checked against the spec here as well
    assert {g.__name__: {f.name for f in dataclasses.fields(g)} for g in _GROUPS} == {
        g: set(fields) for g, fields in SPEC.items()
    }
    assert {type(getattr(EmaParams(), f.name)) for f in dataclasses.fields(EmaParams)} == set(_GROUPS)


@pytest.mark.parametrize("group", _GROUPS, ids=lambda g: g.__name__)
def test_default_values_and_units_match_the_spec(group):
    instance = group()
    for f in dataclasses.fields(group):
        value, unit = SPEC[group.__name__][f.name]
        assert getattr(instance, f.name) == pytest.approx(value, rel=1e-12, abs=0), f.name
        assert f.metadata["unit"] == unit, f.name
        assert f.metadata["symbol"] and f.metadata["doc"], f.name


def test_derived_constants():
    p = EmaParams()
    assert p.motor.k_e == pytest.approx(0.10)  # V·s/rad, DESIGN §7
    assert p.motor.k_t == pytest.approx(0.15)  # N·m/A
    assert p.transmission.J == pytest.approx(5.125e-5)  # kg·m²
    assert p.steps_per_sample == 100  # 1/(f_s·Δt)
    # DESIGN §7: output capacity τ·η·k_t·I_max = 270 N·m
    assert p.transmission.tau * p.transmission.eta * p.motor.k_t * p.controller.I_max == pytest.approx(270)
    # docs/theory/hf-model.md §8: 9.8 mA and 18 µrad ADC steps
    assert p.sensors.lsb_current == pytest.approx(9.8e-3, rel=0.01)
    assert p.sensors.lsb_position == pytest.approx(18e-6, rel=0.02)
    assert SensorParams(bits_current=0).lsb_current == 0.0  # 0 bits: ideal converter


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


def test_parameter_table_shows_the_spec_values():
    # every row of the generated table, parsed back, against the spec (not against the code)
    rows = re.findall(
        r"^\| (\w+) \| `(\w+)` \(.+?\) \| .+? \| (\S+) \| (.+?) \|$", parameter_table_markdown(), re.M
    )
    assert len(rows) == sum(len(fields) for fields in SPEC.values())
    for group, name, value, unit in rows:
        assert (float(value), unit) == (pytest.approx(SPEC[group][name][0], rel=1e-6), SPEC[group][name][1])
