"""Every malformed or implausible input → one-line `InputError` naming the file and the thing."""

from __future__ import annotations

import numpy as np
import pytest

import emaphm
from emaphm.errors import InputError
from emaphm.measured import load_measurement, to_reference

from .helpers import cmap, si_map, twin_columns, write_csv

SIGNALS = ("t", "theta_cmd", "theta_u", "i_q")


def csv_of(tmp_path, twin, name="rig.csv", stop=5001, **replace):
    """The twin's first 0.5 s as a CSV of SI columns (line k + 2 holds sample k)."""
    c = twin_columns(twin, stop)
    cols = {k: c[k] for k in SIGNALS}
    cols.update(replace)
    return write_csv(tmp_path / name, cols)


def refused(path, mapping=None, match=""):
    with pytest.raises(InputError, match=match) as exc:
        to_reference(load_measurement(path, cmap(mapping or si_map())))
    text = str(exc.value)
    assert "\n" not in text
    return text


def test_missing_channel_lists_what_exists(tmp_path, twin):
    path = csv_of(tmp_path, twin)
    text = refused(
        path, si_map(i_q={"name": "Iq", "unit": "A"}), r"no column or variable 'Iq' \(mapped to i_q\)"
    )
    assert "the file has: 't', 'theta_cmd', 'theta_u', 'i_q'" in text and str(path) in text


def test_missing_time_column_of_a_channel(tmp_path, twin):
    path = csv_of(tmp_path, twin)
    refused(path, si_map(i_q={"name": "i_q", "unit": "A", "time": "t_iq"}), r"'t_iq' \(mapped to i_q\.time\)")


def test_no_time_base(tmp_path, twin):
    refused(
        csv_of(tmp_path, twin),
        si_map(t=None),
        r"theta_cmd \('theta_cmd'\) has no time base in .*rig\.csv: map t, or give",
    )


def test_gaps_with_no_long_segment(tmp_path, twin):
    c = twin_columns(twin)
    keep = (np.arange(len(c["t"])) // 1000) % 2 == 0  # 0.1 s on, 0.1 s off
    path = write_csv(tmp_path / "gaps.csv", {k: c[k][keep] for k in SIGNALS})
    text = refused(
        path, match=r"no clean stretch of 0\.2 s common to all channels \(longest: 0\.0999 s\); gaps: "
    )
    assert "theta_cmd: time gap 0.0999..0.2 s at line 1002" in text


def test_nan_runs_with_no_long_segment(tmp_path, twin):
    i_q = twin_columns(twin, 5001)["i_q"]
    i_q[1500::1500] = np.nan
    refused(csv_of(tmp_path, twin, i_q=i_q), match=r"gaps: i_q: 1 NaN sample\(s\) from line 1502")


def test_duplicated_time(tmp_path, twin):
    t = twin.t[:5001].copy()
    t[100] = t[99]
    refused(
        csv_of(tmp_path, twin, t=t), match=r"duplicated time at line 102 \(t = 0\.0099 s after 0\.0099 s\)"
    )


def test_non_monotonic_time(tmp_path, twin):
    t = twin.t[:5001].copy()
    t[200], t[201] = t[201], t[200]
    refused(csv_of(tmp_path, twin, t=t), match=r"time goes backwards at line 203")


def test_non_numeric_cell(tmp_path, twin):
    i_q = twin_columns(twin, 5001)["i_q"].astype(object)
    i_q[50] = "1.2.3"
    refused(
        csv_of(tmp_path, twin, i_q=i_q), match=r"rig\.csv: line 52, column 'i_q': '1\.2\.3' is not a number"
    )


def test_short_row(tmp_path):
    path = tmp_path / "short.csv"
    path.write_text("t,theta_cmd,theta_u,i_q\n0,0,0,0\n1e-4,0,0\n")
    refused(path, match=r"line 3 has 3 fields, the header has 4")


def test_truncated_hdf5(tmp_path, twin):
    path = emaphm.write_trace(twin, tmp_path / "cut.h5")
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    text = refused(path, match=r"cut\.h5: ")
    assert "truncated" in text or "cannot read it as HDF5" in text


def test_empty_files(tmp_path):
    for name in ("empty.csv", "empty.h5", "empty.mat"):
        (tmp_path / name).write_bytes(b"")
        refused(tmp_path / name, match=rf"{name}: the file is empty")
    (tmp_path / "blank.csv").write_text("\n# a comment\n\n")
    refused(tmp_path / "blank.csv", match=r"the file is empty \(no header row\)")
    (tmp_path / "header.csv").write_text("t,theta_cmd,theta_u,i_q\n")
    refused(tmp_path / "header.csv", match=r"has a header but no data rows")


def test_missing_file_and_unknown_format(tmp_path):
    refused(tmp_path / "none.csv", match=r"none\.csv: no such file")
    (tmp_path / "blob.bin").write_bytes(b"\x00\x01\x02garbage" * 10)
    refused(tmp_path / "blob.bin", match=r"blob\.bin: unknown format")
    (tmp_path / "bad.mat").write_bytes(b"MATLAB 5.0 MAT-file" + b"\x00" * 50)
    refused(tmp_path / "bad.mat", match=r"bad\.mat: cannot read it as MATLAB v5")


def test_current_in_ma_declared_as_a(tmp_path, twin):
    i_q = twin_columns(twin, 5001)["i_q"] * 1e3
    refused(
        csv_of(tmp_path, twin, i_q=i_q),
        match=r"i_q \('i_q'\) exceeds 1\.5 × I_max = 15 A on \d+ samples .*is the current in mA\?",
    )


def test_positions_in_degrees_declared_as_rad(tmp_path, twin):
    cmd = np.rad2deg(twin_columns(twin, 5001)["theta_cmd"])
    refused(
        csv_of(tmp_path, twin, theta_cmd=cmd),
        match=r"theta_cmd \('theta_cmd'\) reaches 1\.\d+ rad, beyond .*is it in degrees\?",
    )


def test_a_huge_outlier_is_named_by_its_row(tmp_path, twin):
    i_q = twin_columns(twin, 5001)["i_q"]
    i_q[1234] = 1e30
    refused(
        csv_of(tmp_path, twin, i_q=i_q),
        match=r"i_q \('i_q'\): 1e\+30 at line 1236 lies .* a corrupt sample\?",
    )


def test_an_all_zero_current(tmp_path, twin):
    refused(
        csv_of(tmp_path, twin, i_q=np.zeros(5001)), match=r"i_q \('i_q'\) is constant \(0 A .*unconnected"
    )


def test_theta_e_taken_from_the_surface_angle(tmp_path, twin):
    c = twin_columns(twin, 5001)
    path = write_csv(tmp_path / "surf.csv", {k: c[k] for k in ("t", "theta_cmd", "theta_u", "i_a", "i_b")})
    mapping = si_map(i_q=None, i_a={"name": "i_a", "unit": "A"}, i_b={"name": "i_b", "unit": "A"},
                     theta_e={"name": "theta_u", "unit": "rad"})  # fmt: skip
    refused(
        path, mapping, r"theta_e turns 1× the surface angle, expected p·tau = 800: is it the surface angle\?"
    )


def test_angle_counting_the_other_way(tmp_path, twin):
    c = twin_columns(twin, 5001)
    path = write_csv(
        tmp_path / "rev.csv",
        {**{k: c[k] for k in ("t", "theta_cmd", "theta_u", "i_a", "i_b")}, "enc": -c["theta_e"]},
    )
    mapping = si_map(i_q=None, i_a={"name": "i_a", "unit": "A"}, i_b={"name": "i_b", "unit": "A"},
                     theta_e={"name": "enc", "unit": "rad"})  # fmt: skip
    refused(path, mapping, r"theta_e turns against the surface angle .*set scale = -1 on theta_e")


def test_time_in_ms_declared_as_s(tmp_path, twin):
    refused(
        csv_of(tmp_path, twin, t=twin.t[:5001] * 1e3),
        match=r"spans 500 s \(more than 100 s\): is the time axis in seconds\?",
    )


def test_too_short(tmp_path, twin):
    refused(csv_of(tmp_path, twin, stop=1000), match=r"lasts 0\.0999 s; at least 0\.2 s are needed")


def test_currents_sampled_too_slowly(tmp_path, twin):
    c = twin_columns(twin)
    path = write_csv(tmp_path / "slow.csv", {k: c[k][::10] for k in SIGNALS})  # 1 kHz
    refused(
        path, match=r"i_q \('i_q'\) is sampled at 1000 Hz; currents and rotor angles need at least 2000 Hz"
    )
