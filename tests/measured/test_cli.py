"""The reader's command line (issue 10, item 4): inspect, convert, identify --map."""

from __future__ import annotations

import json

import numpy as np
import pytest

import emaphm
from emaphm.io import read_trace, sha256_of
from tests.helpers import run_cli
from tests.measured.helpers import write_csv

OFFSET_DEG = 71.3
MAP = """[channels]
t         = { name = "time", unit = "ms" }
theta_cmd = { name = "cmd",  unit = "deg" }
theta_u   = { name = "pos",  unit = "deg" }
i_a       = { name = "Ia",   unit = "%s" }
i_b       = { name = "Ib",   unit = "%s" }
theta_e   = { name = "elec", unit = "deg" }
"""


@pytest.fixture
def rig(twin, tmp_path):
    """A rig's CSV: phase currents in mA, angles in degrees (the rotor's wrapped, with an offset), ms."""
    theta_e = np.degrees(np.mod(twin["theta_e"] - np.radians(OFFSET_DEG), 2 * np.pi))
    columns = {
        "time": twin.t * 1e3, "cmd": np.degrees(twin.theta_cmd), "pos": np.degrees(twin.theta_u),
        "Ia": twin["i_a"] * 1e3, "Ib": twin["i_b"] * 1e3, "elec": theta_e,
    }  # fmt: skip
    write_csv(tmp_path / "rig.csv", columns)
    (tmp_path / "rig.toml").write_text(MAP % ("mA", "mA"))
    (tmp_path / "wrong.toml").write_text(MAP % ("A", "A"))  # mA declared as A
    return tmp_path


def test_inspect_says_usable_or_not(rig, capsys):
    code, out, _ = run_cli(["inspect", str(rig / "rig.csv"), "--map", str(rig / "rig.toml")], capsys)
    assert code == 0 and "theta_e" in out and out.rstrip().endswith("usable")
    code, out, _ = run_cli(
        ["inspect", str(rig / "rig.csv"), "--map", str(rig / "rig.toml"), "--json"], capsys
    )
    assert code == 0 and json.loads(out)["usable"] is True
    code, out, _ = run_cli(["inspect", str(rig / "rig.csv"), "--map", str(rig / "wrong.toml")], capsys)
    assert code == 2 and "is the current in mA" in out and "not usable" in out
    code, out, _ = run_cli(["inspect", str(rig / "rig.csv")], capsys)  # no map: what the file holds
    assert code == 0 and all(name in out for name in ("time", "Ia", "elec"))


def test_convert_writes_a_reference_with_its_provenance(rig, twin, capsys):
    out_file = rig / "ref.h5"
    code, _, err = run_cli(
        ["convert", str(rig / "rig.csv"), "--map", str(rig / "rig.toml"), "-o", str(out_file)], capsys
    )
    assert code == 0 and "angle offset" in err
    ref = read_trace(out_file)
    report = ref.metadata["measured"]
    assert report["source"]["sha256"] == sha256_of(rig / "rig.csv")
    assert abs((report["angle"]["offset_deg"] - OFFSET_DEG + 180) % 360 - 180) < 1.0
    assert set(("t", "theta_cmd", "i_q")) <= set(ref.names)
    # the converted i_q is the twin's own, to the noise of two phases (A, after the comparison filter)
    from emaphm.identification.signals import lowpass, nrmse

    assert nrmse(lowpass(twin.i_q, 1e4), lowpass(ref.i_q, 1e4)) < 0.03


def test_convert_refuses_bad_input_in_one_line_and_writes_nothing(rig, capsys):
    out_file = rig / "ref.h5"
    for args, match in (
        (["--map", str(rig / "wrong.toml")], "is the current in mA"),
        (["--map", str(rig / "none.toml")], "none.toml"),
    ):
        code, _, err = run_cli(["convert", str(rig / "rig.csv"), *args, "-o", str(out_file)], capsys)
        assert code == 2 and match in err and err.count("\n") == 1 and not out_file.exists()
    code, _, err = run_cli(
        ["identify", "--map", str(rig / "rig.toml"), "--true-faults", "0,0,0,0,0,0,0,0.5"], capsys
    )
    assert code == 2 and "--map reads a recording" in err


def test_identify_reads_a_recording_through_its_map(rig, capsys):
    args = ["identify", "--reference", str(rig / "rig.csv"), "--map", str(rig / "rig.toml"), "--json",
            "--pop-size", "16", "--generations", "3", "--no-polish", "--uncertainty", "none"]  # fmt: skip
    code, out, _ = run_cli(args, capsys)
    data = json.loads(out)
    # a 16 x 3 search fits poorly: doubtful (exit 4) for that reason alone, the recording being clean
    assert code == 4 and data["verdict"] == "doubtful" and data["fit_nrmse"] > data["settings"]["doubtful_above"]["nrmse"]
    assert "explained less well" in data["doubts"][0] and set(data["doubts"]) <= set(data["warnings"])
    conversion = data["settings"]["conversion"]
    assert abs((conversion["angle"]["offset_deg"] - OFFSET_DEG + 180) % 360 - 180) < 1.0
    assert conversion["source"]["sha256"] == sha256_of(rig / "rig.csv")


@pytest.mark.slow  # two healthy twin runs, a baseline and a small identification from the shell, ~10 s
def test_a_baseline_from_rig_files_through_their_map_then_identify_with_it(tmp_path, capsys):
    # issue 33's contract: emaphm baseline H1.csv H2.csv --map H1.toml --output DIR, then identify
    # --reference REC.csv --map REC.toml --baseline DIR
    for name, faults, seed in (("h1", emaphm.HEALTHY, 61), ("h2", emaphm.HEALTHY, 62), ("rec", [0.2, 0, 0, 0.3, 0, 0, 0, 0.5], 63)):
        twin = emaphm.simulate(faults, seed=seed)
        theta_e = np.degrees(np.mod(twin["theta_e"] - np.radians(OFFSET_DEG), 2 * np.pi))
        write_csv(tmp_path / f"{name}.csv", {"time": twin.t * 1e3, "cmd": np.degrees(twin.theta_cmd),
                                              "pos": np.degrees(twin.theta_u), "Ia": twin["i_a"] * 1e3,
                                              "Ib": twin["i_b"] * 1e3, "elec": theta_e})  # fmt: skip
    (tmp_path / "rig.toml").write_text(MAP % ("mA", "mA"))
    code, _, err = run_cli(["baseline", str(tmp_path / "h1.csv"), str(tmp_path / "h2.csv"), "--map",
                            str(tmp_path / "rig.toml"), "--output", str(tmp_path / "DIR")], capsys)  # fmt: skip
    assert code == 0 and "identify --baseline" in " ".join(err.split())
    code, out, _ = run_cli(["identify", "--reference", str(tmp_path / "rec.csv"), "--map", str(tmp_path / "rig.toml"),
                            "--baseline", str(tmp_path / "DIR"), "--json", "--pop-size", "16", "--generations", "3",
                            "--no-polish", "--uncertainty", "none"], capsys)  # fmt: skip
    data = json.loads(out)
    assert code in (0, 4) and data["settings"]["baseline"]["directory"] == str(tmp_path / "DIR")
    assert data["settings"]["params"]["source"].endswith("actuator.toml")
