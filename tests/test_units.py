"""The one unit table (`emaphm.units`): what an actuator file, a requirement and a channel map
each accept, unchanged from the two tables it replaced (actuator.UNITS, measured.units.UNIT_TABLE)."""

from __future__ import annotations

import math
import subprocess
import sys

import pytest

from emaphm.errors import InputError
from emaphm.units import CHANNEL_UNITS, UNITS, factor, kind_of, parameter_units, to_si, units_of_kind


def test_an_actuator_file_reads_the_units_it_always_read():
    assert list(parameter_units("A")) == ["A", "mA"]
    assert list(parameter_units("rad")) == ["rad", "mrad", "deg", "°", "arcmin"]
    assert list(parameter_units("s")) == ["s", "ms", "µs", "us", "ns"]
    assert to_si("500 μs", "tau_D", "s", "a.toml") == 5e-4  # Greek mu read as the micro sign
    assert to_si("500 g cm^2", "J_m", "kg·m²", "a.toml") == 5e-5
    assert to_si("1.8 mH", "L_s", "H", "a.toml") == 0.0018  # 12 significant digits
    for text in ("1 kA", "1 rev"):
        si = "A" if text.endswith("kA") else "rad"
        with pytest.raises(
            InputError, match=rf"unit '{text[2:]}' is not one for x \(its unit is {si}; accepted: "
        ):
            to_si(text, "x", si, "a.toml")


def test_a_channel_map_names_the_units_it_always_named():
    assert units_of_kind("current") == ["A", "mA", "kA"]
    assert units_of_kind("angle") == ["rad", "mrad", "deg", "rev"]
    assert units_of_kind("time") == ["s", "ms", "us", "µs"]
    assert kind_of("μs") == "time" and factor("μs") == 1e-6
    assert factor("rev") == 2 * math.pi and factor("kA") == 1e3
    for unit in ("°", "arcmin", "ns", "Hz", "V", None):
        assert kind_of(unit) is None
    # every channel unit's factor is the one table's
    assert all(unit in UNITS[si] for kind, si in (("current", "A"), ("angle", "rad"), ("time", "s"))
               for unit in CHANNEL_UNITS[kind])  # fmt: skip


def test_the_unit_table_needs_no_numpy():
    code = "import sys, emaphm.units; sys.exit('numpy' in sys.modules)"
    assert subprocess.run([sys.executable, "-c", code], check=False).returncode == 0
