"""The actuator file (issue 10): template, units, refusals, and a calibration bound to its actuator."""

from __future__ import annotations

import dataclasses
import json
import math
import re
import tomllib

import pytest

from emaphm import EmaParams, InputError
from emaphm.actuator import ACCEPTED, load_params, params_from_dict, params_template
from emaphm.calibration import COEFFICIENT_BOUNDS, Coefficients, coefficient_bounds, params_hash
from emaphm.calibration.fit_monitor import calibrate
from emaphm.calibration.scenarios import Scenario
from emaphm.commands import Sine
from emaphm.models import MonitorEma
from emaphm.params import _GROUPS, MODE_KEYS, InverterParams
from emaphm.units import UNITS
from tests.helpers import run_cli

OTHER = EmaParams(
    motor=dataclasses.replace(EmaParams().motor, R_s=0.6),
    transmission=dataclasses.replace(EmaParams().transmission, J_u=0.035),
)


# the units outside the closed table of `emaphm.units`: a number in them, or the unit written out

FOC = EmaParams(
    inverter=InverterParams(
        control="foc", V_dc=270.0, f_pwm=16e3, dead_time=5e-7, dead_time_compensation=False,
        K_p_i=5.0, K_i_i=2000.0, modulation="sine", update="double", computation_delay=2,
        decoupling=False, emf_feedforward=False, angle_compensation=True, voltage_limit=0.95,
        pwm_phase=0.25,
    )
)  # fmt: skip


def test_the_template_names_every_parameter_with_its_unit_and_reads_back_to_the_nominal_actuator():
    text = params_template()
    for group in _GROUPS:
        for f in dataclasses.fields(group):
            # one line per parameter: "name = value  # [unit] meaning", the FOC keys commented out
            prefix = "# " if f.name in MODE_KEYS["foc"] else ""
            (line,) = [ln for ln in text.splitlines() if re.match(rf"^{prefix}{f.name} = ", ln)]
            assert f"# [{f.metadata['unit']}] {f.metadata['doc']}" in line, f.name
            if f.metadata["check"] in ("choice", "flag"):
                assert f.metadata["unit"] == "-" and f.name not in ACCEPTED, f.name
            else:
                assert f.name in ACCEPTED, f.name
                assert f.metadata["unit"] in UNITS, f.name
    assert 'control = "hysteresis"' in text and "\n# dead_time_compensation = true " in text
    assert params_from_dict(tomllib.loads(text)) == EmaParams()


def test_the_template_of_a_foc_drive_writes_its_keys_and_reads_back_to_it():
    text = params_template(FOC)
    inverter = text.split("[inverter]", 1)[1].split("\n[", 1)[0]
    keys = re.findall(r"^(\w+) = ", inverter, re.M)
    assert keys == ["control", "V_dc", *MODE_KEYS["foc"]]  # h left out, nothing commented out
    assert 'control = "foc"' in inverter and 'modulation = "sine"' in inverter
    assert "dead_time_compensation = false" in inverter and "angle_compensation = true" in inverter
    assert "#" not in "".join(ln.split("  #")[0] for ln in inverter.splitlines()[1:])
    assert params_from_dict(tomllib.loads(text)) == FOC
    # and the nominal FOC drive too
    nominal_foc = EmaParams(inverter=InverterParams(control="foc"))
    assert params_from_dict(tomllib.loads(params_template(nominal_foc))) == nominal_foc


def test_a_foc_actuator_file_with_units_is_read_in_si(tmp_path):
    (tmp_path / "a.toml").write_text(
        '[inverter]\ncontrol = "foc"\nV_dc = 48.0\nf_pwm = "20 kHz"\ndead_time = "1 us"\n'
        "dead_time_compensation = true\nK_p_i = 9.42\nK_i_i = 3141.6\n"
    )
    inv = load_params(tmp_path / "a.toml").inverter
    assert inv.control == "foc" and inv.foc
    assert inv.f_pwm == 20000.0 and type(inv.f_pwm) is float
    assert inv.dead_time == 1e-6
    assert inv.dead_time_compensation is True and inv.K_p_i == 9.42 and inv.K_i_i == 3141.6
    assert load_params(tmp_path / "a.toml") == EmaParams(inverter=InverterParams(control="foc"))
    # the current-loop gains: a number, or their own unit written out; a choice or a flag as it is
    params = params_from_dict(
        tomllib.loads(
            'control = "foc"\nK_p_i = "5 V/A"\nK_i_i = "2000 V/(A*s)"\nmodulation = "sine"\n'
            'update = "double"\ncomputation_delay = 2.0\ndecoupling = false\ndead_time = "500 ns"\n'
        )
    )
    inv = params.inverter
    assert (inv.K_p_i, inv.K_i_i, inv.modulation, inv.update) == (5.0, 2000.0, "sine", "double")
    assert type(inv.computation_delay) is int and inv.decoupling is False and inv.dead_time == 5e-7


def test_the_foc_example_of_the_docs_is_the_nominal_foc_drive():
    from pathlib import Path

    doc = (Path(__file__).resolve().parents[1] / "docs" / "your-actuator.md").read_text()
    section = doc.split("### The drive: hysteresis or field-oriented control", 1)[1].split("\n## ", 1)[0]
    (example,) = re.findall(r"```toml\n(.+?)```", section, re.S)
    assert params_from_dict(tomllib.loads(example)) == EmaParams(inverter=InverterParams(control="foc"))
    # the keys table lists every FOC key with its unit and default
    rows = dict(re.findall(r"^\| `(\w+)` \| (\S+) \|", section, re.M))
    fields = {f.name: f for f in dataclasses.fields(InverterParams)}
    assert set(rows) == {"control", *MODE_KEYS["foc"]}
    assert all(rows[name] == fields[name].metadata["unit"] for name in rows)


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ('[inverter]\ncontrol = "pid"', r"""control must be one of "hysteresis", "foc", got 'pid'"""),
        ("[inverter]\ncontrol = 1", r"""control must be one of "hysteresis", "foc", got 1"""),
        ('[inverter]\ncontrol = "foc"\nmodulation = "SVPWM"', r"""modulation must be one of "svpwm", "sine", got 'SVPWM'"""),
        ('[inverter]\ncontrol = "foc"\nupdate = "20 kHz"', r"update must be one of"),
        ('[inverter]\ncontrol = "foc"\ndecoupling = 1', "decoupling must be true or false, got 1"),
        ('[inverter]\ncontrol = "foc"\ndecoupling = "true"', "decoupling must be true or false, got 'true'"),
        # the other mode's keys, both ways; control missing is hysteresis
        ("[inverter]\nK_p_i = 9.42", r"""\[inverter\] K_p_i belongs to control = "foc", but this file's control is "hysteresis"$"""),
        ('[inverter]\ncontrol = "hysteresis"\nf_pwm = 5', r"""\[inverter\] f_pwm belongs to control = "foc", but this file's control is "hysteresis"$"""),
        ('f_pwm = "20 kHz"', r"""f_pwm belongs to control = "foc", but this file's control is "hysteresis"$"""),
        ('[inverter]\ncontrol = "foc"\nh = 0.1', r"""\[inverter\] h belongs to control = "hysteresis", but this file's control is "foc"$"""),
        ('[inverter]\nh = 0.1\ncontrol = "foc"', r"""h belongs to control = "hysteresis", but this file's control is "foc"$"""),
        # numbers: range with a unit hint, units, cross checks
        ('[inverter]\ncontrol = "foc"\nf_pwm = 20', r'f_pwm = 20 is outside the range emaphm accepts, 1000 to 200000 Hz: is it in another unit\? write the unit, e.g. f_pwm = "20 kHz"'),
        ('[inverter]\ncontrol = "foc"\nf_pwm = "500 kHz"', "f_pwm = '500 kHz' is outside the range"),
        ('[inverter]\ncontrol = "foc"\ndead_time = 1', r'dead_time = 1 is outside .* e.g. dead_time = "1 us"'),
        ('[inverter]\ncontrol = "foc"\ndead_time = "15 us"', r"dead_time = 1.5e-05 s must be less than a quarter of the PWM period, T_pwm/4 = 1.25e-05 s"),
        ('[inverter]\ncontrol = "foc"\nf_pwm = "50 kHz"\ndead_time = "5 us"', r"dead_time = 5e-06 s must be less than a quarter of the PWM period"),
        ('[inverter]\ncontrol = "foc"\ndead_time = "1 mH"', "unit 'mH' is not one for dead_time"),
        ('[inverter]\ncontrol = "foc"\nK_p_i = "9 V/rad"', "unit 'V/rad' is not one for K_p_i .its unit is V/A."),
        ('[inverter]\ncontrol = "foc"\nK_p_i = "fast"', "K_p_i = 'fast' is not a number"),
        ('[inverter]\ncontrol = "foc"\nK_p_i = true', "K_p_i must be a number"),
        ('[inverter]\ncontrol = "foc"\nK_p_i = 1e5', "K_p_i = 100000.0 is outside the range emaphm accepts, 0.001 to 10000 V/A"),
        ('[inverter]\ncontrol = "foc"\ncomputation_delay = 1.5', "computation_delay must be a whole number 0..2"),
        ('[inverter]\ncontrol = "foc"\ncomputation_delay = 3', "computation_delay = 3 is outside the range"),
        ('[inverter]\ncontrol = "foc"\nvoltage_limit = 0.05', "voltage_limit = 0.05 is outside the range"),
        ('[inverter]\ncontrol = "foc"\npwm_phase = 1.0', r"pwm_phase must be in \[0, 1\)"),
    ],
)  # fmt: skip
def test_a_bad_drive_is_refused_in_one_line_naming_the_key(tmp_path, text, match):
    (tmp_path / "a.toml").write_text(text + "\n")
    with pytest.raises(InputError, match=match) as exc:
        load_params(tmp_path / "a.toml")
    assert str(exc.value).startswith(f"{tmp_path / 'a.toml'}: ") and "\n" not in str(exc.value)


def test_a_template_of_other_parameters_reads_back_to_them(tmp_path):
    (tmp_path / "a.toml").write_text(params_template(OTHER))
    assert load_params(tmp_path / "a.toml") == OTHER
    assert params_hash(OTHER) != params_hash(EmaParams())


@pytest.mark.parametrize(
    ("entry", "group", "name", "value"),
    [
        ('L_s = "1.5 mH"', "motor", "L_s", 1.5e-3),
        ('theta_max = "28.64788975654116 deg"', "transmission", "theta_max", 0.5),
        ('I_max = "12000 mA"', "controller", "I_max", 12.0),
        ('tau_D = "500 us"', "controller", "tau_D", 5e-4),
        ('J_m = "500 g cm^2"', "transmission", "J_m", 5e-5),
        ('f_s = "20 kHz"', "controller", "f_s", 2e4),
        ("[motor]\nR_s = 0.7", "motor", "R_s", 0.7),  # in its table
        ("R_s = 0.7", "motor", "R_s", 0.7),  # at the top level
    ],
)
def test_values_with_units_are_converted_to_si(entry, group, name, value):
    params = params_from_dict(tomllib.loads(entry))
    assert getattr(getattr(params, group), name) == pytest.approx(value, rel=1e-12)
    # everything else stays nominal
    others = {(g, k): v for g, d in params.to_dict().items() for k, v in d.items() if k != name}
    nominal = {(g, k): v for g, d in EmaParams().to_dict().items() for k, v in d.items() if k != name}
    assert others == nominal


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("[motor]\nR = 0.5", r"unknown parameter \[motor\] 'R'"),
        ("[motr]\nR_s = 0.5", r"unknown table \[motr\]"),
        ("[inverter]\nR_s = 0.5", r"R_s belongs in \[motor\]"),
        ("R_s = 0.5\n[motor]\nR_s = 0.6", "R_s is given twice"),
        ('R_s = "1 mH"', "unit 'mH' is not one for R_s"),
        ('R_s = "1 furlong"', "unit 'furlong' is not one for R_s"),
        ('R_s = "fast"', "R_s = 'fast' is not a number"),
        ("L_s = 1.5", r"L_s = 1.5 is outside the range .* is it in another unit"),  # 1.5 mH as H
        ("theta_max = 28.6", "theta_max = 28.6 is outside"),  # degrees as rad
        ("eta = 1.2", "eta = 1.2 is outside"),
        ("R_s = true", "R_s must be a number"),
        ("R_s = nan", "R_s must be a finite number"),
        ("p = 4.5", "whole number of pole pairs"),
        ("F_D0 = 0.05", "F_D0=0.05 exceeds static"),
        ("dt = 3e-6", "whole number of steps dt"),
    ],
)
def test_a_bad_actuator_file_is_refused_naming_the_key(tmp_path, text, match):
    (tmp_path / "a.toml").write_text(text + "\n")
    with pytest.raises(InputError, match=match) as exc:
        load_params(tmp_path / "a.toml")
    assert str(tmp_path / "a.toml") in str(exc.value) and "\n" not in str(exc.value)


def test_unreadable_actuator_files(tmp_path):
    with pytest.raises(InputError, match="no such actuator file"):
        load_params(tmp_path / "none.toml")
    (tmp_path / "a.toml").write_text("R_s = = 1\n")
    with pytest.raises(InputError, match="not a valid TOML file"):
        load_params(tmp_path / "a.toml")


def test_the_calibration_box_scales_with_the_nameplate():
    assert coefficient_bounds() == COEFFICIENT_BOUNDS  # the nominal actuator: the shipped box, exactly
    assert Coefficients.first_guess(EmaParams()) == Coefficients()
    strong = EmaParams(motor=dataclasses.replace(EmaParams().motor, psi_m=0.05))  # twice the flux
    box = coefficient_bounds(strong)
    assert box["k_t_eq"] == pytest.approx((0.2, 0.4)) and box["k_e_eq"] == pytest.approx((0.1, 0.4))
    assert box["k_FS"] == COEFFICIENT_BOUNDS["k_FS"] and box["J_eq"] == COEFFICIENT_BOUNDS["J_eq"]
    guess = Coefficients.first_guess(strong)
    assert guess.k_t_eq == pytest.approx(0.3) and box["k_t_eq"][0] < guess.k_t_eq < box["k_t_eq"][1]
    with pytest.raises(InputError, match="k_t_eq"):
        guess.check_bounds(EmaParams())  # 0.3 N·m/A is out of the nominal actuator's box
    guess.check_bounds(strong)
    # the loop's ripple and dead zone follow the hysteresis band h, and may be 0
    wide = EmaParams(inverter=dataclasses.replace(EmaParams().inverter, h=0.2))
    for name in ("i_R", "i_D"):
        assert coefficient_bounds(wide)[name] == pytest.approx((0.0, 0.2))
    with pytest.raises(InputError, match="i_D"):
        Coefficients(i_D=0.15).check_bounds(EmaParams())
    Coefficients(i_D=0.15).check_bounds(wide)
    with pytest.raises(InputError, match="i_D"):
        Coefficients(i_D=-0.01)


def test_a_calibration_is_bound_to_the_actuator_it_was_made_for(tmp_path):
    rig = {"rig": Sine(amplitude=0.01, frequency=3.0, duration=0.3)}
    fit = [Scenario("healthy on the rig", (0, 0, 0, 0, 0, 0, 0, 0.5), "rig")]
    cal = calibrate(seed=2, pop_size=4, generations=1, fit=fit, check=fit, commands=rig, params=OTHER)
    assert cal.params_hash == params_hash(OTHER)
    assert cal.record["settings"]["bounds"]["J_eq"] == pytest.approx(
        [b * OTHER.transmission.J / EmaParams().transmission.J for b in COEFFICIENT_BOUNDS["J_eq"]]
    )
    MonitorEma(OTHER, calibration=cal)  # its own actuator: accepted
    with pytest.raises(InputError, match=rf"hash {cal.params_hash}, these are {params_hash(EmaParams())}"):
        MonitorEma(EmaParams(), calibration=cal)
    cal.save(tmp_path / "cal.json")
    assert json.loads((tmp_path / "cal.json").read_text())["params_hash"] == params_hash(OTHER)


def test_cli_params_template_check_and_refusals(tmp_path, capsys):
    status, out, _ = run_cli(["params", "--template"], capsys)
    assert status == 0 and params_from_dict(tomllib.loads(out)) == EmaParams()
    (tmp_path / "a.toml").write_text(params_template(OTHER))
    status, out, _ = run_cli(["params", str(tmp_path / "a.toml"), "--json"], capsys)
    data = json.loads(out)
    assert status == 0 and data["params_hash"] == params_hash(OTHER)
    assert data["params"]["motor"]["R_s"] == 0.6
    status, out, _ = run_cli(["params", str(tmp_path / "a.toml")], capsys)
    assert status == 0 and params_hash(OTHER) in out and "J_u" in out
    assert "h " in out and "f_pwm" not in out and "hysteresis" in out
    # a FOC drive: its keys shown, h not; --json prints to_dict
    (tmp_path / "foc.toml").write_text(params_template(FOC))
    status, out, _ = run_cli(["params", str(tmp_path / "foc.toml"), "--json"], capsys)
    data = json.loads(out)
    assert status == 0 and data["params"] == FOC.to_dict() and data["params_hash"] == params_hash(FOC)
    assert data["params"]["inverter"]["control"] == "foc" and "h" not in data["params"]["inverter"]
    status, out, _ = run_cli(["params", str(tmp_path / "foc.toml")], capsys)
    shown = {ln.split("│")[2].strip() for ln in out.splitlines() if ln.count("│") > 3 and "inverter" in ln}
    assert status == 0 and shown == {"control", "V_dc", *MODE_KEYS["foc"]}
    status, out, _ = run_cli(["params", str(tmp_path / "foc.toml"), "--template"], capsys)
    assert status == 0 and params_from_dict(tomllib.loads(out)) == FOC
    # the packaged calibration is the nominal actuator's: refused, naming both hashes
    status, out, err = run_cli(
        ["identify", "--true-faults", "0.1,0,0,0,0,0,0,0.5", "--params", str(tmp_path / "a.toml")], capsys
    )
    assert status == 2 and out == ""
    assert (
        params_hash(OTHER) in err and params_hash(EmaParams()) in err and "emaphm calibrate --params" in err
    )
    (tmp_path / "bad.toml").write_text('[motor]\nR_s = "2 mH"\n')
    out_file = tmp_path / "x.h5"
    status, _, err = run_cli(
        ["simulate", "-o", str(out_file), "--params", str(tmp_path / "bad.toml")], capsys
    )
    assert status == 2 and "R_s" in err and err.count("\n") == 1 and not out_file.exists()


def test_the_twin_runs_with_the_actuator_file(tmp_path, capsys):
    (tmp_path / "a.toml").write_text("[transmission]\nJ_u = 0.035\n")
    status, _, _ = run_cli(
        [
            "simulate",
            "-o",
            str(tmp_path / "x.h5"),
            "--params",
            str(tmp_path / "a.toml"),
            "--duration",
            "0.05",
        ],
        capsys,
    )
    assert status == 0
    from emaphm.io import read_trace

    recorded = read_trace(tmp_path / "x.h5").metadata["params"]
    assert recorded["transmission"]["J_u"] == 0.035 and math.isclose(recorded["motor"]["R_s"], 0.5)


@pytest.mark.parametrize(
    "entry", ["V_dc = 48", "V_dc = 48.0", 'V_dc = "48 V"', 'p = "4"', "p = 4", "bits_current = 12"]
)
def test_one_actuator_has_one_hash_however_its_numbers_are_written(entry):
    # the hash keys a calibration to its actuator: 48 and 48.0 volts are the same actuator
    params = params_from_dict(tomllib.loads(entry))
    assert params_hash(params) == params_hash(EmaParams())
    assert type(params.motor.p) is int and type(params.inverter.V_dc) is float
