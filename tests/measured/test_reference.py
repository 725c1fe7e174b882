"""`to_reference`: multi-rate records, segments, the report, and the written file."""

from __future__ import annotations

import json

import numpy as np
import pytest

import emaphm
from emaphm.identification.signals import lowpass, nrmse, resample
from emaphm.measured import load_measurement, to_reference, write_reference

from .helpers import close, cmap, si_map, twin_columns, write_csv


def test_multi_rate_4k8_currents_and_500_hz_positions(tmp_path, twin):
    """REPRISE-like: phase currents at 4.8 kHz, positions at 500 Hz, each with its own time base.
    The 10 kHz reference interpolates the positions linearly (a held position would be a
    staircase 2 ms wide)."""
    import h5py

    c = twin_columns(twin)
    t_fast = np.arange(0.0, 1.0, 1 / 4800)
    t_slow = np.arange(0.0, 1.0 + 1e-9, 1 / 500)
    path = tmp_path / "reprise.h5"
    with h5py.File(path, "w") as f:
        f["fast/time"] = t_fast * 1e6  # µs
        f["fast/iq"] = np.interp(t_fast, c["t"], c["i_q"])
        f["slow/cmd"] = np.interp(t_slow, c["t"], c["theta_cmd"])
        f["slow/pos"] = np.interp(t_slow, c["t"], c["theta_u"])
    mapping = {"channels": {
        "i_q": {"name": "fast/iq", "unit": "A", "time": "fast/time", "time_unit": "µs"},
        "theta_cmd": {"name": "slow/cmd", "unit": "rad", "fs": 500},
        "theta_u": {"name": "slow/pos", "unit": "rad", "fs": 500, "t0": 0.0},
    }}  # fmt: skip
    ref = to_reference(load_measurement(path, cmap(mapping)))
    tr = ref.trace
    assert tr.t[1] == pytest.approx(1e-4) and tr.t[0] == 0.0
    assert tr.t[-1] <= t_fast[-1]  # within every channel's span
    with h5py.File(path) as f:
        cmd500 = f["slow/cmd"][()]
    interpolated = np.interp(tr.t, t_slow, cmd500)
    held = cmd500[np.minimum(np.floor(tr.t * 500 + 1e-9).astype(int), len(cmd500) - 1)]
    assert close(tr.theta_cmd, interpolated, 1e-12)
    assert np.max(np.abs(tr.theta_cmd - held)) > 1e-4  # [rad]: far from a staircase
    assert ref.report["channels"]["theta_cmd"]["resampling"].startswith("interpolated linearly from 500 Hz")
    assert ref.report["channels"]["i_q"]["rate_hz"] == pytest.approx(4800.0)
    truth = lowpass(resample(c["t"], c["i_q"], tr.t, 1e4), 1e4)
    assert nrmse(truth, lowpass(tr.i_q, 1e4)) < 0.02


def test_nan_run_keeps_the_longest_clean_segment(tmp_path, twin):
    c = twin_columns(twin)
    c["i_q"][2000:2100] = np.nan  # 10 ms of missing current at 0.2 s
    path = write_csv(tmp_path / "nan.csv", {k: c[k] for k in ("t", "theta_cmd", "theta_u", "i_q")})
    ref = to_reference(load_measurement(path, cmap(si_map())))
    seg = ref.report["segments"]
    assert seg["used"] == pytest.approx([0.21, 1.0])
    assert "segment_cut" in ref.report["flags"]
    assert seg["dropped_rows"]["i_q"] == 2100  # the first 0.2 s and the NaN run
    assert any(g["kind"] == "NaN" and g["samples"] == 100 and g["row"] == "line 2002" for g in seg["gaps"])
    # the used stretch is the twin's own samples, from 0
    assert close(ref.trace.i_q, twin.i_q[2100:])
    assert ref.trace.t[0] == 0.0


def test_time_gap_splits_without_interpolating_across(tmp_path, twin):
    c = twin_columns(twin)
    keep = np.ones(len(c["t"]), bool)
    keep[3000:3050] = False  # 5 ms without samples at 0.3 s
    path = write_csv(tmp_path / "gap.csv", {k: c[k][keep] for k in ("t", "theta_cmd", "theta_u", "i_q")})
    ref = to_reference(load_measurement(path, cmap(si_map())))
    # the stretch before the gap starts at rest in the command: preferred to the longer one after
    assert ref.report["segments"]["used"] == pytest.approx([0.0, 0.2999])
    assert [g["kind"] for g in ref.report["segments"]["gaps"]] == [
        "gap"
    ] * 3  # one per channel on the time axis
    assert close(ref.trace.i_q, twin.i_q[:3000])


def test_report_is_json_and_survives_the_file(tmp_path, twin):
    c = twin_columns(twin)
    path = write_csv(tmp_path / "r.csv", {k: c[k] for k in ("t", "theta_cmd", "theta_u", "i_q")})
    ref = to_reference(load_measurement(path, cmap(si_map())))
    json.dumps(ref.report, allow_nan=False)
    assert (
        ref.report["source"]["sha256"] and ref.report["source"]["channel_map"]["channels"]["t"]["unit"] == "s"
    )
    out = write_reference(ref, tmp_path / "ref.h5")
    back = emaphm.read_trace(out)
    assert set(back.names) == set(ref.trace.names)
    for name in ref.trace.names:
        np.testing.assert_array_equal(back[name], ref.trace[name])
    assert back.metadata["measured"] == json.loads(json.dumps(ref.report))  # nested dicts intact
    assert back.metadata["model"] == "measured" and back.metadata["sha256"] == ref.report["source"]["sha256"]


def test_jittered_fast_source_is_regularised_then_filtered(tmp_path, twin20):
    """A 20 kHz logger with time-stamp jitter: interpolated to its own uniform grid first, so
    the anti-alias filter still runs before the 10 kHz grid."""
    c = twin_columns(twin20)
    rng = np.random.default_rng(1)
    t = c["t"] + rng.uniform(-2e-6, 2e-6, len(c["t"]))  # ±4 % of the 50 µs step
    path = write_csv(
        tmp_path / "j.csv", {"t": t, "theta_cmd": c["theta_cmd"], "theta_u": c["theta_u"], "i_q": c["i_q"]}
    )
    ref = to_reference(load_measurement(path, cmap(si_map())))
    assert ref.report["channels"]["i_q"]["resampling"].startswith("jittered: interpolated to a uniform")
    truth = lowpass(resample(c["t"], c["i_q"], ref.trace.t, 1e4), 1e4)
    assert nrmse(truth, lowpass(ref.trace.i_q, 1e4)) < 0.02
