"""`inspect_file` and `plausibility`: reports that never raise for a readable file."""

from __future__ import annotations

import json

import numpy as np
import pytest

import emaphm
from emaphm.errors import InputError
from emaphm.measured import inspect_file, plausibility
from emaphm.measured.inspection import saturation

from .helpers import cmap, si_map, twin_columns, write_csv

SIGNALS = ("t", "theta_cmd", "theta_u", "i_q")


def test_a_good_file_is_usable(tmp_path, twin):
    c = twin_columns(twin)
    path = write_csv(tmp_path / "good.csv", {k: c[k] for k in SIGNALS})
    info = inspect_file(path, cmap(si_map()))
    json.dumps(info, allow_nan=False)
    assert info["usable"] is True and info["problems"] == []
    assert info["format"] == "csv"
    assert [v["name"] for v in info["variables"]] == list(SIGNALS)
    i_q = info["channels"]["i_q"]
    assert i_q["rate_hz"] == pytest.approx(1e4) and i_q["duration_s"] == pytest.approx(1.0)
    assert i_q["min_si"] == pytest.approx(c["i_q"].min()) and i_q["max_si"] == pytest.approx(c["i_q"].max())
    assert i_q["saturation"] is None
    assert info["reference"]["samples"] == len(c["t"])


def test_a_bad_file_is_not_usable_and_says_why(tmp_path, twin):
    c = twin_columns(twin)
    path = write_csv(tmp_path / "ma.csv", {**{k: c[k] for k in SIGNALS}, "i_q": c["i_q"] * 1e3})
    info = inspect_file(path, cmap(si_map()))
    assert info["usable"] is False
    assert len(info["problems"]) == 1 and "is the current in mA?" in info["problems"][0]
    assert info["channels"]["i_q"]["max_si"] == pytest.approx(c["i_q"].max() * 1e3)


def test_a_missing_channel_is_a_problem_not_an_exception(tmp_path, twin):
    c = twin_columns(twin)
    path = write_csv(tmp_path / "m.csv", {k: c[k] for k in SIGNALS})
    info = inspect_file(path, cmap(si_map(i_q={"name": "Iq", "unit": "A"})))
    assert info["usable"] is False and "no column or variable 'Iq'" in info["problems"][0]


def test_saturation_is_reported(tmp_path, twin):
    c = twin_columns(twin)
    i_q = np.clip(c["i_q"], None, 0.3)  # an ADC clipping at 0.3 A
    path = write_csv(tmp_path / "sat.csv", {**{k: c[k] for k in SIGNALS}, "i_q": i_q})
    info = inspect_file(path, cmap(si_map()))
    sat = info["channels"]["i_q"]["saturation"]
    assert sat["at"] == "max" and sat["value"] == pytest.approx(0.3) and sat["run"] >= 5
    assert any("saturated" in w for w in info["warnings"])
    assert saturation(np.array([1.0, 2.0, 3.0, 2.0, 1.0] * 4)) is None


def test_without_a_map_lists_the_variables(tmp_path, twin):
    path = emaphm.write_trace(twin, tmp_path / "t.h5")
    info = inspect_file(path)
    names = {v["name"]: v for v in info["variables"]}
    assert names["i_q"]["unit"] == "A" and names["i_q"]["length"] == len(twin.t)
    assert info["usable"] is True and "channels" not in info


def test_an_unreadable_file_raises(tmp_path):
    with pytest.raises(InputError, match="no such file"):
        inspect_file(tmp_path / "none.h5")
    (tmp_path / "empty.csv").write_text("")
    with pytest.raises(InputError, match="the file is empty"):
        inspect_file(tmp_path / "empty.csv")


def test_plausibility_of_native_traces(twin):
    assert plausibility(twin) == []
    t = twin.t
    bad = emaphm.SimResult(t=t, signals={**twin.signals, "i_q": twin.i_q * 1e3})
    problems = plausibility(bad)
    assert len(problems) == 1 and "is the current in mA?" in problems[0]
    surface = emaphm.SimResult(t=t, signals={**twin.signals, "theta_e": twin.theta_u})
    assert any("is it the surface angle?" in p for p in plausibility(surface))
    spike = twin.i_a.copy()
    spike[77] = 1e30
    assert (
        "at sample 77 (t = 0.0077 s)"
        in plausibility(emaphm.SimResult(t=t, signals={**twin.signals, "i_a": spike}))[0]
    )
    assert (
        "is the time axis in seconds?" in plausibility(emaphm.SimResult(t=t * 1e3, signals=twin.signals))[0]
    )


def test_a_surface_dwelling_at_its_peak_is_not_called_saturated_and_the_table_names_units(tmp_path, twin, capsys):
    # the newcomer's note A: a false "saturated?" on a surface that sticks at its peak (friction),
    # SI values under the file's unit, and a raw dict in the saturation cell
    c = twin_columns(twin)
    theta_u = c["theta_u"].copy()
    peak = int(np.argmax(theta_u))
    theta_u[peak : peak + 7] = theta_u[peak]  # stuck at the top for 7 samples
    columns = {**{k: c[k] for k in SIGNALS}, "theta_u": theta_u, "i_q": c["i_q"] * 1e3}
    path = write_csv(tmp_path / "stuck.csv", columns)
    info = inspect_file(path, cmap(si_map(i_q={"name": "i_q", "unit": "mA"})))
    assert info["channels"]["theta_u"]["saturation"]["run"] >= 7  # still in the table
    assert not any("saturated" in w for w in info["warnings"])  # but no warning for a position
    assert info["channels"]["i_q"]["si_unit"] == "A" and info["channels"]["i_q"]["unit"] == "mA"
    from emaphm.cli.render import print_inspection

    print_inspection(info)
    out = " ".join(capsys.readouterr().out.split())
    assert "file unit" in out and f"{c['i_q'].max():.4g} A" in out and "{'value'" not in out
    assert "7 at the max" in out
