"""Clean failures before the work, atomic writes, Ctrl-C, and guards for past defects (issue 7)."""

from __future__ import annotations

import dataclasses
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import emaphm
from emaphm import EmaParams, InputError, SimResult, SimulationError
from emaphm.calibration import default_calibration
from emaphm.io import atomic_path, read_trace
from tests.helpers import run_cli

ROOT = Path(__file__).resolve().parents[1]


# ---- output paths: exit 2, one line, before the work, nothing written -------------------------


@pytest.mark.parametrize(
    ("args", "reason"),
    [
        (["simulate", "--output", "missing/x.h5"], "does not exist"),
        (["simulate", "--output", "adir.h5"], "is a folder"),
        (["simulate", "--output", "side.csv"], "side.csv.json is a folder"),
        (["simulate", "--output", "ro/x.h5"], "not writable"),
        (["simulate", "--seed", str(2**63), "--output", "x.h5"], "seed"),
        (["simulate", "--seed", str(2**63), "--output", "x.csv"], "seed"),
        (["simulate", "--duration", "1e9", "--output", "x.h5"], "at most 1000 s"),
        (["simulate", "--duration", "1e-5", "--output", "x.h5"], "one sample period"),
        (["simulate", "--model", "hf", "--calibration", "cal.json", "--output", "x.h5"], "--model lf"),
        (["identify", "--reference", "good.csv", "--output", "good.csv.json"], "would overwrite the input"),
        (["identify", "--reference", "good.csv", "--output", "adir.json"], "is a folder"),
        (["identify", "--reference", "adir.h5"], "is a folder"),
        (["identify", "--reference", "empty.csv"], "empty"),
        (["identify", "--reference", "header.csv"], "no data rows"),
        (["identify", "--reference", "good.csv", "--calibration", "other.json"], "other actuator parameters"),
        (["identify", "--true-faults", "0,0,0,0,0,0,0,0.5", "--seed", str(2**64)], "seed"),
        (["calibrate", "--output", "adir.json"], "is a folder"),
    ],
)
def test_bad_paths_exit_2_in_one_line_before_the_work(tmp_path, capsys, monkeypatch, args, reason):
    monkeypatch.chdir(tmp_path)
    good = emaphm.simulate(emaphm.HEALTHY, duration=0.03, noise=False)
    emaphm.write_trace(good, tmp_path / "good.csv")
    for d in ("adir.h5", "adir.json", "side.csv.json", "ro"):
        (tmp_path / d).mkdir()
    (tmp_path / "ro").chmod(0o555)
    if os.geteuid() == 0:  # root writes anywhere: stand in for the permission check on ro/
        real_access = os.access
        monkeypatch.setattr(
            os, "access", lambda p, mode: False if Path(p).name == "ro" else real_access(p, mode)
        )
    (tmp_path / "empty.csv").write_text("")
    (tmp_path / "header.csv").write_text("t,theta_cmd,theta_u,i_q\n")
    other = default_calibration()
    params = dict(other.record["settings"]["params"])
    params["motor"] = {**params["motor"], "R_s": 0.6}  # another actuator, same nameplate k_t, k_e, J
    record = {**other.record, "settings": {**other.record["settings"], "params": params}}
    dataclasses.replace(other, record=record).save(tmp_path / "other.json")
    before = sorted(str(p.relative_to(tmp_path)) for p in tmp_path.rglob("*"))
    start = time.perf_counter()
    code, stdout, err = run_cli(args, capsys)
    assert time.perf_counter() - start < 3.0  # refused before any simulation
    assert code == 2 and reason in err and len(err.strip().splitlines()) == 1, err
    assert stdout == ""
    assert sorted(str(p.relative_to(tmp_path)) for p in tmp_path.rglob("*")) == before
    (tmp_path / "ro").chmod(0o755)


def test_files_are_created_with_the_umask(tmp_path):
    r = emaphm.simulate(emaphm.HEALTHY, duration=0.01, noise=False)
    old = os.umask(0o022)
    try:
        emaphm.write_trace(r, tmp_path / "a.h5")
        emaphm.write_trace(r, tmp_path / "a.csv")
    finally:
        os.umask(old)
    for name in ("a.h5", "a.csv", "a.csv.json"):
        assert (tmp_path / name).stat().st_mode & 0o777 == 0o644


# ---- atomic writes, Ctrl-C, kill -9 -----------------------------------------------------------


def test_ctrl_c_during_a_write_leaves_neither_target_nor_temporary(tmp_path):
    target = tmp_path / "x.h5"
    with pytest.raises(KeyboardInterrupt), atomic_path(target) as tmp:
        tmp.write_bytes(b"half")
        os.kill(os.getpid(), signal.SIGINT)  # held until the block ends
        tmp.write_bytes(b"complete")  # the write itself still runs to its end
    assert list(tmp_path.iterdir()) == []


def test_ctrl_c_during_a_write_keeps_the_old_file(tmp_path):
    r = emaphm.simulate(emaphm.HEALTHY, duration=0.01, noise=False)
    target = tmp_path / "x.h5"
    emaphm.write_trace(r, target)
    before = target.read_bytes()
    import h5py

    with pytest.raises(KeyboardInterrupt), atomic_path(target) as tmp, h5py.File(tmp, "w") as f:
        os.kill(os.getpid(), signal.SIGINT)
        f.create_dataset("t", data=np.arange(10.0))
    assert target.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["x.h5"]


def test_temporaries_of_a_killed_process_are_removed_by_the_next_write(tmp_path):
    dead = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True
    )
    pid = int(dead.stdout)  # that process has exited
    stale = tmp_path / f".x.csv.emaphm-{pid}-abc123.tmp"
    stale.write_bytes(b"x" * 1000)
    mine = tmp_path / f".x.csv.emaphm-{os.getppid()}-def456.tmp"  # a live process: kept
    mine.write_bytes(b"y")
    emaphm.write_trace(emaphm.simulate(emaphm.HEALTHY, duration=0.01, noise=False), tmp_path / "x.csv")
    assert not stale.exists() and mine.exists()


@pytest.mark.slow  # ~4.5 s: a real identification process, interrupted after 4 s
def test_ctrl_c_during_identify_exits_130_with_one_line(tmp_path):
    # a real SIGINT to a real process, as a shell's Ctrl-C would send it
    out = tmp_path / "r.json"
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    proc = subprocess.Popen(
        [sys.executable, "-m", "emaphm", "identify", "--true-faults", "0.2,0,0,0,0,0,0,0.5", "--output", str(out),
         "--pop-size", "400", "--generations", "400"],
        stderr=subprocess.PIPE, stdout=subprocess.PIPE, text=True, env=env,
        # as from a terminal: a runner started in the background of a non-interactive shell
        # (``cmd &``) passes SIGINT on as ignored, and Python then never raises KeyboardInterrupt
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )  # fmt: skip
    time.sleep(4.0)  # inside the twin or the search: a 400 x 400 search takes far longer
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130
    assert err.strip() == "emaphm: error: interrupted"
    assert list(tmp_path.iterdir()) == []


# ---- simulation guards ------------------------------------------------------------------------


def test_a_diverging_simulation_raises_simulation_error_naming_the_faults(monkeypatch):
    from emaphm.models import hf

    def nan_kernel(*args):
        args[-1][...] = np.nan

    monkeypatch.setattr(hf, "simulate_hf", nan_kernel)
    with pytest.raises(SimulationError, match=r"HF simulation diverged .*0\.25"):
        emaphm.simulate([0.25, 0, 0, 0, 0, 0, 0, 0.5], duration=0.01)


def test_simulation_error_exits_1_in_one_line(tmp_path, capsys, monkeypatch):
    from emaphm.models import hf

    monkeypatch.setattr(hf, "simulate_hf", lambda *args: args[-1].fill(np.inf))
    code, _, err = run_cli(["simulate", "--duration", "0.01", "--output", str(tmp_path / "x.h5")], capsys)
    assert code == 1 and "diverged" in err and len(err.strip().splitlines()) == 1
    assert list(tmp_path.iterdir()) == []


def test_substep_count_has_an_upper_bound():
    motor = dataclasses.replace(EmaParams().motor, L_s=1e-9)  # a mistyped inductance
    with pytest.raises(InputError, match="sub-steps"):
        emaphm.HighFidelityEma(EmaParams(motor=motor)).simulate(duration=0.01)


# ---- measured traces off the 10 kHz grid ------------------------------------------------------


def test_a_3khz_trace_of_one_second_is_identified():
    # 1 s at 3 kHz ends at 0.99967 s: not a whole number of 100 µs samples (it used to be refused)
    measured = emaphm.simulate(emaphm.TABLE1_REFERENCE, seed=2)
    t = np.arange(3000) / 3000.0
    trace = SimResult(
        t=t,
        signals={
            "theta_cmd": np.interp(t, measured.t, measured.theta_cmd),
            "theta_u": np.interp(t, measured.t, measured.theta_u),
            "i_q": np.interp(t, measured.t, measured.i_q),
        },
    )
    r = emaphm.identify(reference=trace, seed=1, pop_size=16, generations=2, polish=False)
    assert r.estimate.shape == (8,) and np.isfinite(r.fitness)


def test_a_time_axis_in_milliseconds_is_refused_before_the_work():
    t = np.arange(10001) * 0.1  # "ms" read as s: 1000 s
    trace = SimResult(
        t=t, signals={"theta_cmd": np.zeros_like(t), "theta_u": np.zeros_like(t), "i_q": np.zeros_like(t)}
    )
    with pytest.raises(InputError, match="is the time axis in seconds"):
        emaphm.identify(reference=trace, seed=1)


# ---- a calibration belongs to one actuator ----------------------------------------------------


def test_a_calibration_for_other_parameters_is_refused():
    tr = dataclasses.replace(EmaParams().transmission, J_m=1e-10, J_u=1e-10)
    with pytest.raises(InputError, match=r"transmission\.J_m"):
        emaphm.MonitorEma(EmaParams(transmission=tr))
    # the noise levels are not part of the actuator
    sens = dataclasses.replace(EmaParams().sensors, sigma_current=0.05)
    emaphm.MonitorEma(EmaParams(sensors=sens))


def test_a_calibration_file_is_used_by_identify_and_simulate(tmp_path, capsys):
    cal = default_calibration()
    faster = dataclasses.replace(cal, coefficients=dataclasses.replace(cal.coefficients, tau_i=3e-4))
    path = faster.save(tmp_path / "cal.json")
    data = json.loads(path.read_text())
    assert data["params_hash"] == cal.params_hash
    a = emaphm.MonitorEma().simulate(emaphm.TABLE1_REFERENCE, duration=0.2)
    b = emaphm.MonitorEma(calibration=path).simulate(emaphm.TABLE1_REFERENCE, duration=0.2)
    assert np.max(np.abs(a.i_q - b.i_q)) > 1e-3  # the file's coefficients were used
    code, _, _ = run_cli(
        ["simulate", "--model", "lf", "--no-noise", "--calibration", str(path), "--duration", "0.2",
         "--faults", ",".join(str(v) for v in emaphm.TABLE1_REFERENCE), "--output",
         str(tmp_path / "lf.h5")],
        capsys,
    )  # fmt: skip
    assert code == 0
    np.testing.assert_array_equal(read_trace(tmp_path / "lf.h5").i_q, b.i_q)


def test_a_calibration_file_with_a_wrong_hash_is_refused(tmp_path):
    path = default_calibration().save(tmp_path / "cal.json")
    data = json.loads(path.read_text())
    data["params_hash"] = "0" * 16
    path.write_text(json.dumps(data))
    with pytest.raises(InputError, match="params_hash"):
        emaphm.load_calibration(path)


# ---- compiled kernels never go stale ----------------------------------------------------------

_PROBE = """
import numpy as np, emaphm
k = [0, 0.5, 0, 0, 0, 0, 0, 0.5]
hf = emaphm.simulate(k, noise=False, duration=0.3).theta_u
lf = emaphm.simulate(k, model="lf", noise=False, duration=0.3).theta_u
print(repr(float(np.sum(np.abs(hf)))), repr(float(np.sum(np.abs(lf)))))
"""


@pytest.mark.slow
def test_an_edited_kernel_callee_is_seen_by_its_cached_callers(tmp_path):
    """Edit `pid_step` (controller.py) in a copy of the package: simulate_hf (hf_twin.py) and
    simulate_lf (monitor.py) must run the new code in a fresh process whose on-disk cache was
    warmed by the old code (numba alone stamps a cached function with its own file only)."""
    import shutil

    copy = tmp_path / "src"
    shutil.copytree(ROOT / "src" / "emaphm", copy / "emaphm", ignore=shutil.ignore_patterns("__pycache__"))
    # the cache this suite uses: the unedited copy hashes like the package (a warm load), the
    # edited one gets a folder of its own (compiled once, then warm in later runs)
    env = {**os.environ, "PYTHONPATH": str(copy)}

    def probe() -> list[float]:
        res = subprocess.run(
            [sys.executable, "-c", _PROBE], env=env, capture_output=True, text=True, check=True
        )
        return [float(v) for v in res.stdout.split()]

    before = probe()
    controller = copy / "emaphm" / "kernels" / "controller.py"
    text = controller.read_text()
    # sabotage: the proportional term at half gain
    sabotaged = text.replace("u = cp.K_P * e", "u = 0.5 * cp.K_P * e", 1)
    assert sabotaged != text
    controller.write_text(sabotaged)
    after = probe()
    assert after[0] != before[0], "simulate_hf ran stale machine code"
    assert after[1] != before[1], "simulate_lf ran stale machine code"


def test_the_kernel_cache_is_keyed_by_all_kernel_sources():
    from emaphm.kernels import _jit

    assert _jit.KERNEL_SOURCE_HASH == _jit.kernel_source_hash()
    assert _jit.KERNEL_SOURCE_HASH[:16] in str(_jit.kernel_cache_dir())


def test_a_non_finite_history_entry_is_written_as_valid_json():
    from emaphm.identification.result import IdentificationResult

    r = IdentificationResult(
        estimate=np.array(emaphm.HEALTHY), fitness=1.0, evaluations=1, wall_time_s=0.0, seed=0, optimizer="ga",
        history=[float("inf"), 2.0, 1.0],
    )  # fmt: skip
    text = json.dumps(r.to_json(), allow_nan=False)  # raises on Infinity / NaN
    assert json.loads(text)["history"] == [None, 2.0, 1.0]


def test_a_renamed_copy_of_the_package_gets_cache_entries_of_its_own():
    # numba's index records types by module name: a copy imported as another package, with the
    # same kernel sources, must not read or write this package's entries
    from emaphm.kernels import _jit

    def ours():  # pragma: no cover - only its metadata is read
        pass

    def theirs():  # pragma: no cover
        pass

    ours.__module__ = "emaphm.kernels.hf_twin"
    theirs.__module__ = "emaphm_copy.kernels.hf_twin"
    kernel_file = str(_jit.KERNEL_DIR / "hf_twin.py")
    a = _jit.KernelCacheLocator.from_function(ours, kernel_file).get_cache_path()
    b = _jit.KernelCacheLocator.from_function(theirs, kernel_file).get_cache_path()
    assert a != b and a.endswith("emaphm") and b.endswith("emaphm_copy")
    assert _jit.KernelCacheLocator.from_function(ours, __file__) is None  # not a kernel file
