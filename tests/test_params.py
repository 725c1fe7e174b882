"""Nominal parameters against the design spec, validation, and the generated parameter table."""

import dataclasses
import math
import re

import pytest

from emaphm import (
    EmaParams,
    InputError,
    IntegrationParams,
    InverterParams,
    MotorParams,
    SensorParams,
    TransmissionParams,
)
from emaphm.calibration.files import params_hash
from emaphm.params import _GROUPS, MODE_KEYS, parameter_table_markdown

# The nominal values as written in the design spec (DESIGN §7 table, §3.9 for the ADC bits, §7
# "no load" for T_load), by hand, NOT from the code. The hysteresis band is the project's 0.1 A,
# not DESIGN's original 0.2 A (docs/theory/hf-model.md §4). Sensor ranges, noise and r_h are
# not in DESIGN: their values are the hand-written prose of docs/theory/hf-model.md §8 and §9.
# The field-oriented-control drive (control = "foc") is not the paper's: its keys and defaults are
# those of docs/your-actuator.md ("The drive"), K_p_i = L_s·ω_c and K_i_i = R_s·ω_c at
# ω_c = 2π·1 kHz.
SPEC = {
    "MotorParams": {"p": (4, "-"), "R_s": (0.5, "Ω"), "L_s": (1.5e-3, "H"), "psi_m": (0.025, "Wb")},
    "InverterParams": {
        "V_dc": (48.0, "V"), "h": (0.1, "A"), "control": ("hysteresis", "-"),
        "f_pwm": (20e3, "Hz"), "dead_time": (1e-6, "s"), "dead_time_compensation": (True, "-"),
        "K_p_i": (9.42, "V/A"), "K_i_i": (3141.6, "V/(A·s)"), "modulation": ("svpwm", "-"),
        "update": ("single", "-"), "computation_delay": (1, "-"), "decoupling": (True, "-"),
        "emf_feedforward": (True, "-"), "angle_compensation": (False, "-"), "voltage_limit": (1.0, "-"),
        "pwm_phase": (0.0, "-"),
    },
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
        if isinstance(value, (str, bool)):  # a choice or a flag: the value and its type
            assert type(getattr(instance, f.name)) is type(value), f.name
            assert getattr(instance, f.name) == value, f.name
        else:
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
        spec, spec_unit = SPEC[group][name]
        if isinstance(spec, bool):
            assert (value, unit) == (str(spec).lower(), spec_unit)
        elif isinstance(spec, str):
            assert (value, unit) == (spec, spec_unit)
        else:
            assert (float(value), unit) == (pytest.approx(spec, rel=1e-6), spec_unit)
    # the keys of one control mode say so
    assert (
        "| hysteresis band, total width (control = hysteresis only) | 0.1 | A |" in parameter_table_markdown()
    )
    assert "`K_p_i` (K_p,i) | dq current-loop PI, proportional gain (control = foc only) |" in (
        parameter_table_markdown()
    )


# the params hash of the nominal actuator, measured before the FOC keys were added: the packaged
# calibrations record it, so adding a drive mode must not move it
NOMINAL_HASH = "9400227a7dd94ce8"


def test_a_hysteresis_actuator_records_the_same_parameters_as_before_foc():
    assert params_hash(EmaParams()) == NOMINAL_HASH
    assert EmaParams().to_dict()["inverter"] == {"V_dc": 48.0, "h": 0.1}
    # naming the default drive changes nothing
    assert params_hash(EmaParams(inverter=InverterParams(control="hysteresis"))) == NOMINAL_HASH


def test_a_foc_actuator_records_its_drive_and_not_h():
    foc = EmaParams(inverter=InverterParams(control="foc", f_pwm=10e3, modulation="sine"))
    inverter = foc.to_dict()["inverter"]
    assert list(inverter) == ["control", "V_dc", *MODE_KEYS["foc"]]
    assert inverter["control"] == "foc" and inverter["f_pwm"] == 10e3 and inverter["modulation"] == "sine"
    assert inverter["dead_time_compensation"] is True and inverter["angle_compensation"] is False
    assert "h" not in inverter
    assert set(MODE_KEYS["foc"]) == {
        "f_pwm", "dead_time", "dead_time_compensation", "K_p_i", "K_i_i", "modulation", "update",
        "computation_delay", "decoupling", "emf_feedforward", "angle_compensation", "voltage_limit",
        "pwm_phase",
    }  # fmt: skip
    assert EmaParams.from_dict(foc.to_dict()) == foc
    assert params_hash(foc) != NOMINAL_HASH
    assert params_hash(EmaParams(inverter=InverterParams(control="foc"))) not in (
        NOMINAL_HASH,
        params_hash(foc),
    )
    # both forms are read, missing keys take their defaults
    assert EmaParams.from_dict({"inverter": {"V_dc": 48.0, "h": 0.1}}) == EmaParams()
    assert EmaParams.from_dict({"inverter": {"control": "foc", "f_pwm": 10e3, "modulation": "sine"}}) == foc


def test_derived_drive_quantities():
    inv = InverterParams(control="foc", f_pwm=16e3)
    assert inv.foc and not InverterParams().foc
    assert inv.T_pwm == pytest.approx(62.5e-6) and inv.T_update == pytest.approx(62.5e-6)
    assert dataclasses.replace(inv, update="double").T_update == pytest.approx(31.25e-6)
    assert inv.V_linear == pytest.approx(48.0 / math.sqrt(3.0))
    assert dataclasses.replace(inv, modulation="sine").V_linear == pytest.approx(24.0)
    # the defaults are the pole-zero-cancellation tuning of the nominal motor at 2π·1 kHz
    motor, w_c = MotorParams(), 2 * math.pi * 1e3
    assert inv.K_p_i == pytest.approx(motor.L_s * w_c, rel=1e-3)
    assert inv.K_i_i == pytest.approx(motor.R_s * w_c, rel=1e-4)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"control": "pid"}, "InverterParams.control must be one of 'hysteresis', 'foc', got 'pid'"),
        ({"control": 1}, "InverterParams.control must be one of 'hysteresis', 'foc', got 1"),
        (
            {"control": "foc", "modulation": "SVPWM"},
            "InverterParams.modulation must be one of 'svpwm', 'sine'",
        ),
        ({"control": "foc", "update": "triple"}, "InverterParams.update must be one of 'single', 'double'"),
        ({"control": "foc", "decoupling": 1}, "InverterParams.decoupling must be true or false, got 1"),
        ({"control": "foc", "emf_feedforward": "yes"}, "emf_feedforward must be true or false, got 'yes'"),
        ({"control": "foc", "f_pwm": 0.0}, "InverterParams.f_pwm must be > 0, got 0.0"),
        ({"control": "foc", "f_pwm": "20 kHz"}, "InverterParams.f_pwm must be a number"),
        ({"control": "foc", "dead_time": -1e-9}, "InverterParams.dead_time must be >= 0"),
        (
            {"control": "foc", "dead_time": 12.5e-6},
            r"dead_time = 1.25e-05 s must be less than a quarter of the PWM period, T_pwm/4 = 1.25e-05 s",
        ),
        ({"control": "foc", "K_p_i": 0.0}, "InverterParams.K_p_i must be > 0"),
        ({"control": "foc", "K_i_i": -1.0}, "InverterParams.K_i_i must be >= 0"),
        ({"control": "foc", "computation_delay": 3}, "computation_delay must be a whole number 0..2, got 3"),
        ({"control": "foc", "computation_delay": 0.5}, "computation_delay must be a whole number 0..2"),
        ({"control": "foc", "voltage_limit": 1.1}, r"InverterParams.voltage_limit must be in \(0, 1\]"),
        ({"control": "foc", "pwm_phase": 1.0}, r"InverterParams.pwm_phase must be in \[0, 1\)"),
        # the other mode's fields keep their defaults: they describe nothing and are not recorded
        ({"f_pwm": 10e3}, 'f_pwm = 10000.0 belongs to control = "foc", but control is "hysteresis"'),
        ({"control": "foc", "h": 0.2}, 'h = 0.2 belongs to control = "hysteresis", but control is "foc"'),
    ],
)
def test_invalid_drive_parameters_are_rejected_in_one_line(kwargs, message):
    with pytest.raises(InputError, match=message) as exc:
        InverterParams(**kwargs)
    assert "\n" not in str(exc.value)
