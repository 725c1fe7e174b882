import hashlib
import json
import os

import h5py
import numpy as np
import pytest

import emaphm
import emaphm.io as eio
from emaphm import InputError, read_trace, write_trace


@pytest.fixture(scope="module")
def short_run():
    return emaphm.simulate(emaphm.TABLE1_REFERENCE, seed=4, duration=0.02)


@pytest.mark.parametrize("suffix", [".h5", ".csv"])
def test_round_trip(tmp_path, short_run, suffix):
    path = write_trace(short_run, tmp_path / f"trace{suffix}")
    back = read_trace(path)
    for name in short_run.names:
        np.testing.assert_array_equal(back[name], short_run[name])  # %.17g is exact for float64
    assert back.metadata["faults"] == list(emaphm.TABLE1_REFERENCE)
    assert back.metadata["seed"] == 4 and back.metadata["noise"] is True
    assert back.metadata["version"] == emaphm.__version__
    assert back.metadata["params"]["inverter"]["V_dc"] == 48.0
    assert sorted(p.name for p in tmp_path.iterdir() if not p.name.startswith(".")) == sorted(
        [f"trace{suffix}"] + ([f"trace{suffix}.json"] if suffix == ".csv" else [])
    )


def test_hdf5_layout(tmp_path, short_run):
    path = write_trace(short_run, tmp_path / "t.h5")
    with h5py.File(path) as f:
        for name in ("t", "theta_cmd", "theta_u", "i_q", "i_a", "i_b", "i_c"):
            assert f[name].shape == short_run.t.shape
        assert f["i_q"].attrs["unit"] == "A"
        assert json.loads(f.attrs["faults"])[3] == 0.4503


def test_csv_layout(tmp_path, short_run):
    path = write_trace(short_run, tmp_path / "t.csv")
    header = path.read_text().splitlines()[0].split(",")
    assert header[:4] == ["t", "theta_cmd", "theta_u", "i_q"]
    side = json.loads((tmp_path / "t.csv.json").read_text())
    assert side["units"]["theta_u"] == "rad" and side["metadata"]["model"] == "hf"


def test_unsupported_or_missing(tmp_path, short_run):
    with pytest.raises(InputError, match="unsupported file type"):
        write_trace(short_run, tmp_path / "x.txt")
    with pytest.raises(InputError, match="does not exist"):
        write_trace(short_run, tmp_path / "no" / "x.h5")
    with pytest.raises(InputError, match="no such file"):
        read_trace(tmp_path / "missing.h5")
    assert list(tmp_path.iterdir()) == []  # nothing half-written


def test_bad_traces_are_rejected(tmp_path):
    (tmp_path / "corrupt.h5").write_bytes(b"not hdf5")
    with pytest.raises(InputError, match="cannot read"):
        read_trace(tmp_path / "corrupt.h5")
    (tmp_path / "few.csv").write_text("t,theta_cmd,theta_u\n0,0,0\n1,0,0\n")
    with pytest.raises(InputError, match="missing signal"):
        read_trace(tmp_path / "few.csv")
    (tmp_path / "nan.csv").write_text("t,theta_cmd,theta_u,i_q\n0,0,0,0\n1,0,0,nan\n")
    with pytest.raises(InputError, match="NaN"):
        read_trace(tmp_path / "nan.csv")
    (tmp_path / "back.csv").write_text("t,theta_cmd,theta_u,i_q\n0,0,0,0\n0,0,0,1\n")
    with pytest.raises(InputError, match="increasing"):
        read_trace(tmp_path / "back.csv")


def test_a_files_digest_is_read_once_while_it_stays_as_it_was(tmp_path, monkeypatch):
    path = tmp_path / "healthy.csv"
    path.write_bytes(b"t,i\n0,1\n")
    first = eio.sha256_of(path)
    assert first == hashlib.sha256(b"t,i\n0,1\n").hexdigest()

    def no_open(*args, **kwargs):
        raise AssertionError("read again")

    monkeypatch.setattr(eio, "open", no_open, raising=False)
    assert eio.sha256_of(path) == first  # a campaign keys the same recordings several times
    monkeypatch.undo()
    # rewritten (even to the same size, the times put back): read again
    st = os.stat(path)
    path.write_bytes(b"t,i\n0,2\n")
    os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns))
    assert eio.sha256_of(path) == hashlib.sha256(b"t,i\n0,2\n").hexdigest()
