"""`ChannelMap`: the TOML format, and every mistake refused naming the key and the file."""

from __future__ import annotations

import math

import pytest

from emaphm.errors import InputError
from emaphm.measured import ChannelMap
from emaphm.units import CHANNEL_UNITS, factor

from .helpers import si_map

GOOD = """
[channels]
t         = { name = "time", unit = "ms" }
theta_cmd = { name = "cmd",  unit = "deg" }
theta_u   = { name = "pos",  unit = "deg", scale = -1 }
i_a       = { name = "Ia",   unit = "mA" }
i_b       = { name = "Ib",   unit = "mA", fs = 20000, t0 = 0.5 }
theta_e   = { name = "elec", unit = "deg", time = "t_enc", time_unit = "us" }

[angle]
offset = 12.5
"""


def test_load_a_good_map(tmp_path):
    path = tmp_path / "rig.toml"
    path.write_text(GOOD)
    m = ChannelMap.load(path)
    assert m["t"].unit == "ms" and m["theta_u"].scale == -1.0
    assert m["i_b"].fs == 20000.0 and m["i_b"].t0 == 0.5
    assert m["theta_e"].time == "t_enc" and m["theta_e"].time_unit == "us"
    assert m.angle_offset_deg == 12.5 and m.from_phases and m.angle_role == "theta_e"
    assert ChannelMap.from_dict(m.to_dict()) == m  # to_dict is the TOML structure


def test_unit_table_factors():
    assert factor("mA") == 1e-3 and factor("kA") == 1e3
    assert factor("deg") == pytest.approx(math.pi / 180) and factor("rev") == pytest.approx(2 * math.pi)
    assert factor("µs") == factor("us") == 1e-6 and factor("mrad") == 1e-3
    assert set(CHANNEL_UNITS) == {"current", "angle", "time"}


@pytest.mark.parametrize(
    ("changes", "top", "message"),
    [
        (
            {"i_q": {"name": "Iq", "unit": "amps"}},
            {},
            r"unknown unit 'amps' in channels\.i_q\.unit; current units: A, mA, kA",
        ),
        (
            {"i_q": {"name": "Iq", "unit": "deg"}},
            {},
            r"channels\.i_q\.unit = 'deg' is an angle unit, i_q needs a current unit",
        ),
        ({"theta_cmd": {"name": "c", "unit": "ms"}}, {}, r"channels\.theta_cmd\.unit = 'ms' is a time unit"),
        (
            {"t": {"name": "time", "unit": "A"}},
            {},
            r"channels\.t\.unit = 'A' is a current unit, t needs a time unit",
        ),
        ({"i_q": {"name": "Iq", "unit": "A", "gain": 2}}, {}, r"unknown key 'gain' in \[channels\.i_q\]"),
        ({"torque": {"name": "T", "unit": "A"}}, {}, r"unknown channel 'torque' in \[channels\]"),
        ({"i_q": {"name": "Iq"}}, {}, r"channels\.i_q\.unit is missing"),
        ({"i_q": {"unit": "A"}}, {}, r"channels\.i_q\.name must be"),
        ({"theta_cmd": None}, {}, r"no theta_cmd"),
        (
            {"i_q": None},
            {},
            r"needs i_q, or the phase currents i_a, i_b with theta_e or theta_m \(missing: i_a, i_b, theta_e or theta_m\)",
        ),
        (
            {"i_q": None, "i_a": {"name": "a", "unit": "A"}, "i_b": {"name": "b", "unit": "A"}},
            {},
            r"missing: theta_e or theta_m",
        ),
        ({"i_q": {"name": "Iq", "unit": "A", "fs": -5}}, {}, r"channels\.i_q\.fs must be > 0"),
        ({"i_q": {"name": "Iq", "unit": "A", "t0": 1.0}}, {}, r"channels\.i_q\.t0 needs channels\.i_q\.fs"),
        ({"i_q": {"name": "Iq", "unit": "A", "fs": 1e4, "time": "x"}}, {}, r"gives both time and fs"),
        ({"i_q": {"name": "Iq", "unit": "A", "scale": 0}}, {}, r"channels\.i_q\.scale must not be 0"),
        ({"t": {"name": "time", "unit": "s", "fs": 100}}, {}, r"unknown key 'fs' in \[channels\.t\]"),
        ({}, {"angle": {"offset": "guess"}}, r"angle\.offset must be \"estimate\" or a number"),
        ({}, {"angles": {}}, r"unknown key 'angles' in top level"),
    ],
)
def test_mistakes_are_refused_naming_the_key(changes, top, message):
    data = {**si_map(**changes), **top}
    with pytest.raises(InputError, match=message) as exc:
        ChannelMap.from_dict(data, where="channel map rig.toml")
    assert str(exc.value).startswith("channel map rig.toml: ") and "\n" not in str(exc.value)


def test_file_errors_name_the_file(tmp_path):
    with pytest.raises(InputError, match=r"nope\.toml: no such channel map"):
        ChannelMap.load(tmp_path / "nope.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[channels\nt = 1")
    with pytest.raises(InputError, match=r"bad\.toml: not a valid TOML file"):
        ChannelMap.load(bad)
    unknown = tmp_path / "unknown.toml"
    unknown.write_text(
        '[channels]\ntheta_cmd = { name = "c", unit = "deg" }\ni_q = { name = "q", unit = "Amp" }\n'
    )
    with pytest.raises(InputError, match=r"unknown\.toml: unknown unit 'Amp' in channels\.i_q\.unit"):
        ChannelMap.load(unknown)
