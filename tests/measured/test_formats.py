"""Round trips: the same twin trace in every supported layout gives the same reference.

Tolerance: 1e-9 of the signal's peak. The conversions (mA → A, deg → rad, ms → s) of values
written with 17 significant digits round at 1e-16; the grid is the twin's own (10 kHz from 0), so
nothing is interpolated between samples.
"""

from __future__ import annotations

import numpy as np
import pytest

import emaphm
from emaphm.errors import InputError
from emaphm.measured import load_measurement, to_reference
from emaphm.measured.formats import sniff

from .helpers import close, cmap, si_map, twin_columns, write_csv, write_mat73, write_paderborn


def assert_same_reference(path, mapping, twin):
    ref = to_reference(load_measurement(path, cmap(mapping)))
    n = len(twin.t)
    assert len(ref.trace.t) == n
    assert close(ref.trace.t, twin.t, 1e-12)
    for name in ("theta_cmd", "i_q", "theta_u"):
        assert close(ref.trace[name], twin[name]), name
    return ref


def test_csv_renamed_columns_in_ms_ma_deg(tmp_path, twin):
    c = twin_columns(twin)
    path = write_csv(
        tmp_path / "rig.csv",
        {"time": c["t"] * 1e3, "cmd": np.rad2deg(c["theta_cmd"]), "pos": np.rad2deg(c["theta_u"]),
         "Iq": c["i_q"] * 1e3, "label": ["run1"] * len(c["t"])},  # an unmapped text column does no harm
        delimiter=";",
    )  # fmt: skip
    mapping = {"channels": {
        "t": {"name": "time", "unit": "ms"}, "theta_cmd": {"name": "cmd", "unit": "deg"},
        "theta_u": {"name": "pos", "unit": "deg"}, "i_q": {"name": "Iq", "unit": "mA"},
    }}  # fmt: skip
    ref = assert_same_reference(path, mapping, twin)
    assert ref.report["source"]["format"] == "csv"
    assert ref.report["channels"]["i_q"]["resampling"].startswith("interpolated at the same rate")


def test_csv_units_row_tab_and_decimal_comma(tmp_path):
    """A units row is recorded (and compared with the map); tab delimiter; decimal commas."""
    n = 50
    lines = ["time\tIq", "[s]\t[A]"] + [
        f"{k / 1000:.4f}\t{np.sin(k / 5):.6f}".replace(".", ",") for k in range(n)
    ]
    path = tmp_path / "tab.csv"
    path.write_text("\n".join(lines) + "\n")
    mapping = {"channels": {"t": {"name": "time", "unit": "s"}, "theta_cmd": {"name": "Iq", "unit": "rad"},
                            "i_q": {"name": "Iq", "unit": "mA"}}}  # fmt: skip
    m = load_measurement(path, cmap(mapping))
    assert m["i_q"].values[3] == pytest.approx(np.sin(3 / 5) * 1e-3, abs=1e-9)
    assert m["i_q"].t[10] == pytest.approx(0.010)
    assert m["i_q"].file_unit == "A"
    assert any("the file declares 'A'" in w for w in m.warnings)


@pytest.mark.parametrize("units", [True, False])
def test_csv_with_a_loggers_preamble_reads_as_without_it(tmp_path, twin, units):
    # the newcomer's m13: two logger lines before the header gave "the file has: nothing"; the
    # second has the data's width (a ';' inside it), the way a logger's date line does
    c = twin_columns(twin)
    plain = write_csv(tmp_path / "plain.csv", {"Zeit": c["t"] * 1e3, "Soll": np.rad2deg(c["theta_cmd"]),
                                               "Lage": np.rad2deg(c["theta_u"]), "Strom": c["i_q"] * 1e3},
                      delimiter=";")  # fmt: skip
    lines = plain.read_text().splitlines()
    head = ["Messsystem XY-400, Firmware 2.1", "Aufnahme 27.11.2026 08:00;Kanal 7;Prüfstand 2;frei"]
    body = [lines[0], "ms;deg;deg;mA", *lines[1:]] if units else lines
    logged = tmp_path / "logged.csv"
    logged.write_text("\n".join(head + body) + "\n")
    mapping = {"channels": {
        "t": {"name": "Zeit", "unit": "ms"}, "theta_cmd": {"name": "Soll", "unit": "deg"},
        "theta_u": {"name": "Lage", "unit": "deg"}, "i_q": {"name": "Strom", "unit": "mA"},
    }}  # fmt: skip
    ref = assert_same_reference(logged, mapping, twin)
    assert ref.report["channels"]["i_q"]["samples"] == len(twin.t)


def test_mat_v5_column_vectors(tmp_path, twin):
    from scipy.io import savemat

    c = twin_columns(twin)
    path = tmp_path / "rig.mat"
    savemat(path, {k: c[k].reshape(-1, 1) for k in ("t", "theta_cmd", "theta_u", "i_q")})
    assert sniff(path) == "mat-v5"
    assert_same_reference(path, si_map(), twin)


def test_mat_v73_struct_as_matlab_writes_it(tmp_path, twin):
    c = twin_columns(twin)
    path = write_mat73(
        tmp_path / "rig73.mat",
        {
            "rig": {"time": c["t"], "cmd": c["theta_cmd"], "pos": c["theta_u"], "iq": c["i_q"]},
            "note": "chirp",
        },
    )
    assert sniff(path) == "mat-v7.3"
    mapping = {"channels": {
        "t": {"name": "rig/time", "unit": "s"}, "theta_cmd": {"name": "rig/cmd", "unit": "rad"},
        "theta_u": {"name": "pos", "unit": "rad"},  # inside the struct: only if it is alone
        "i_q": {"name": "rig/iq", "unit": "A"},
    }}  # fmt: skip
    with pytest.raises(InputError, match="'pos'"):  # ... only when the file holds nothing else
        load_measurement(path, cmap(mapping))
    mapping["channels"]["theta_u"]["name"] = "rig/pos"
    assert_same_reference(path, mapping, twin)
    listing = {v["name"]: v for v in emaphm.measured.inspect_file(path)["variables"]}
    assert listing["note"]["dtype"] == "char" and not listing["note"]["numeric"]
    assert listing["rig/iq"]["length"] == len(c["t"])


def test_paderborn_struct_with_rasters(tmp_path, twin):
    """Paderborn KAt layout: struct <stem> with X (time rasters) and Y (Name/Raster/Data)."""
    c = twin_columns(twin)
    stem = "N15_M07_F10_K001_1"
    path = write_paderborn(
        tmp_path / f"{stem}.mat",
        stem,
        {"Mech_10kHz": c["t"], "HostService": c["t"].copy(), "Temp_1Hz": np.array([0.0, 1.0])},
        [
            ("phase_current_q", "HostService", c["i_q"]),
            ("command", "Mech_10kHz", c["theta_cmd"]),
            ("position", "Mech_10kHz", c["theta_u"]),
            ("temp_2_bearing_module", "Temp_1Hz", np.array([40.0, 40.1])),
        ],
    )
    mapping = {"channels": {
        "theta_cmd": {"name": "Y/command", "unit": "rad"}, "theta_u": {"name": "Y/position", "unit": "rad"},
        "i_q": {"name": f"{stem}/Y/phase_current_q", "unit": "A"},  # the full path works too
    }}  # fmt: skip
    ref = assert_same_reference(path, mapping, twin)
    assert ref.report["channels"]["i_q"]["time_source"] == "raster 'HostService' in s"
    assert ref.report["channels"]["theta_cmd"]["time_source"] == "raster 'Mech_10kHz' in s"


def test_parquet(tmp_path, twin):
    pa = pytest.importorskip("pyarrow")
    import pyarrow.parquet as pq

    c = twin_columns(twin)
    path = tmp_path / "rig.parquet"
    pq.write_table(pa.table({k: c[k] for k in ("t", "theta_cmd", "theta_u", "i_q")}), path)
    assert sniff(path) == "parquet"
    assert_same_reference(path, si_map(), twin)


def test_parquet_without_pyarrow_says_how_to_get_it(tmp_path, monkeypatch):
    path = tmp_path / "rig.parquet"
    path.write_bytes(b"PAR1" + b"\0" * 64 + b"PAR1")
    monkeypatch.setitem(__import__("sys").modules, "pyarrow", None)
    monkeypatch.setitem(__import__("sys").modules, "pyarrow.parquet", None)
    with pytest.raises(InputError, match=r"reading Parquet needs pyarrow: pip install 'emaphm\[data\]'"):
        load_measurement(path, cmap(si_map()))


def test_our_hdf5_trace(tmp_path, twin):
    path = emaphm.write_trace(twin, tmp_path / "twin.h5")
    ref = assert_same_reference(path, si_map(), twin)
    assert ref.report["source"]["format"] == "hdf5"
    # the trace's own unit attributes agree with the map: no warning
    assert not any("declares" in w for w in ref.report["warnings"])


def test_hdf5_nested_groups(tmp_path, twin):
    import h5py

    c = twin_columns(twin)
    path = tmp_path / "nested.hdf5"
    with h5py.File(path, "w") as f:
        f["daq/time"] = c["t"]
        f["daq/ch/cmd"] = c["theta_cmd"]
        f["daq/ch/pos"] = c["theta_u"]
        f["drive/iq"] = c["i_q"]
    mapping = {"channels": {
        "t": {"name": "daq/time", "unit": "s"}, "theta_cmd": {"name": "daq/ch/cmd", "unit": "rad"},
        "theta_u": {"name": "/daq/ch/pos", "unit": "rad"}, "i_q": {"name": "drive/iq", "unit": "A"},
    }}  # fmt: skip
    assert_same_reference(path, mapping, twin)


def test_content_decides_over_the_suffix(tmp_path, twin):
    path = emaphm.write_trace(twin, tmp_path / "twin.h5")
    renamed = path.rename(tmp_path / "twin.csv")
    assert sniff(renamed) == "hdf5"
    assert_same_reference(renamed, si_map(), twin)
