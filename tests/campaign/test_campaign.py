"""Fleet campaigns (issue 11): the file, the job keys, the store, resuming after any interruption, Dask."""

from __future__ import annotations

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
from emaphm.campaign import ResultStore, campaign_status, history_seed, load_campaign, run_campaign
from emaphm.errors import InputError
from emaphm.faults import random_faults
from tests.helpers import run_cli

# a budget that makes a job ~0.1 s: the plumbing is tested here, not the accuracy
FAST = 'pop_size = 6\ngenerations = 2\npolish = false\nuncertainty = "none"\n'
SPEC = """[campaign]
name = "fleet-t"
seeds = [1, 2]

[identify]
{identify}
[[actuator]]
id = "A001"
faults = [0.2, 0.1, 0, 0, 0, 0, 0, 0.5]

[[actuator]]
id = "007"
faults = [0, 0, 0.3, 0, 0, 0, 0, 0.5]

[[actuator]]
id = "H1"
flights = 4
start  = [0.05, 0.02, 0, 0, 0, 0, 0, 0.5]
growth = [0.01, 0.004, 0, 0, 0, 0, 0, -0.02]
"""


def write_spec(folder: Path, identify: str = FAST, extra: str = "") -> Path:
    path = folder / "c.toml"
    path.write_text(SPEC.format(identify=identify) + extra)
    return path


def test_a_history_expands_to_one_job_per_flight_and_seed(tmp_path):
    spec = load_campaign(write_spec(tmp_path, extra='\n[[actuator]]\nid = "E"\nflights = 3\n'
                                    'start = [0, 0, 0.1, 0, 0, 0, 0, 0.5]\ngrowth = [0.5, 0, 0.2, 0, 0, 0, 0, 0]\n'
                                    'law = "exponential"\n'))  # fmt: skip
    jobs = spec.jobs()
    assert len(jobs) == 2 * (1 + 1 + 4 + 3) and len({j.key for j in jobs}) == len(jobs)
    h1 = [j for j in jobs if j.actuator == "H1" and j.seed == 1]
    assert [j.flight for j in h1] == [1, 2, 3, 4]
    np.testing.assert_allclose(
        [j.truth[0] for j in h1], [0.05, 0.06, 0.07, 0.08]
    )  # linear: start + growth (n - 1)
    np.testing.assert_allclose([j.truth[7] for j in h1], [0.5, 0.48, 0.46, 0.44])
    e = [j for j in jobs if j.actuator == "E" and j.seed == 1]
    np.testing.assert_allclose([j.truth[2] for j in e], 0.1 * np.exp(0.2 * np.arange(3)))  # exponential
    assert [j.truth[0] for j in e] == [0.0, 0.0, 0.0]  # a fault at 0 stays at 0 under the exponential law
    # a one-off measurement is identified with the campaign seed itself (as `emaphm identify --seed S`);
    # each flight of a history with its own seed
    assert [j.identify_seed for j in jobs if j.actuator == "A001"] == [1, 2]
    assert len({j.identify_seed for j in h1}) == 4 and h1[2].identify_seed == history_seed(1, 3)


def test_a_fleet_expands_reproducibly_into_drawn_actuators(tmp_path):
    # 1 000 jobs from a file of 18 lines: 200 random actuators and 40 drawn histories of 20 flights
    text = (
        '[campaign]\nname = "fleet"\nseeds = [1]\n\n[[fleet]]\nprefix = "R"\ncount = 200\nseed = 7\n'
        'faults = "random"\nabsent = 0.3\n\n[[fleet]]\nprefix = "H"\ncount = 40\nseed = 8\nflights = 20\n'
        "start  = [0.05, 0.02, 0, 0, 0, 0, 0, 0.5]\ngrowth = [[0.01, 0.02], [0.004, 0.009], 0, 0, 0, 0, 0, 0]\n"
    )
    (tmp_path / "f.toml").write_text(text)
    assert text.count("\n") == 18  # <= 20
    spec = load_campaign(tmp_path / "f.toml")
    jobs = spec.jobs()
    assert len(jobs) == 1000 and len({j.key for j in jobs}) == 1000
    assert [a.id for a in spec.actuators][:2] == ["R000", "R001"] and spec.actuators[200].id == "H00"
    random = np.array([a.truths[0] for a in spec.actuators[:200]])
    np.testing.assert_array_equal(random, random_faults(200, 7, absent=0.3))  # the documented draw
    histories = [a for a in spec.actuators if a.kind == "history"]
    growth = np.array([np.subtract(a.truths[1], a.truths[0]) for a in histories])
    assert (
        np.all((growth[:, 0] >= 0.01 - 1e-12) & (growth[:, 0] <= 0.02 + 1e-12))
        and np.ptp(growth[:, 0]) > 0.005
    )
    assert np.all(growth[:, 2:] == 0)  # the other faults hold their start
    # the same file is the same fleet: the same keys
    assert [j.key for j in jobs] == [j.key for j in load_campaign(tmp_path / "f.toml").jobs()]
    (tmp_path / "g.toml").write_text(text.replace("seed = 8", "seed = 9"))
    # flight 1 is the common start (the same job, the same key); every later flight is drawn anew
    other = {
        j.key
        for j in load_campaign(tmp_path / "g.toml").jobs()
        if j.actuator.startswith("H") and j.flight > 1
    }
    assert len(other) == 40 * 19 and not other & {j.key for j in jobs}


def test_job_keys_are_content_keys(tmp_path):
    keys = [j.key for j in load_campaign(write_spec(tmp_path)).jobs()]
    assert keys == [j.key for j in load_campaign(write_spec(tmp_path)).jobs()]  # stable
    moved = tmp_path / "elsewhere"
    moved.mkdir()
    assert keys == [j.key for j in load_campaign(write_spec(moved)).jobs()]  # not the file's place
    other = [
        j.key
        for j in load_campaign(write_spec(tmp_path, FAST.replace("pop_size = 6", "pop_size = 7"))).jobs()
    ]
    assert not set(keys) & set(other)  # another setting: every key changes
    # a recording's key follows its content, not its name
    trace = emaphm.simulate(seed=1, duration=0.3)
    emaphm.write_trace(trace, tmp_path / "r.h5")
    ref = write_spec(tmp_path, extra='\n[[actuator]]\nid = "R"\nreference = "r.h5"\n')
    before = [j.key for j in load_campaign(ref).jobs() if j.actuator == "R"]
    emaphm.write_trace(emaphm.simulate(seed=2, duration=0.3), tmp_path / "r.h5")
    assert not set(before) & {j.key for j in load_campaign(ref).jobs() if j.actuator == "R"}


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ('[campaign]\nname = "x"\nseed = [1]\n[[actuator]]\nid = "a"\nfaults = [0,0,0,0,0,0,0,0.5]', "unknown key"),
        ('[campaign]\nname = "x"\n[[actuator]]\nid = "a b"\nfaults = [0,0,0,0,0,0,0,0.5]', "id must be"),
        ('[campaign]\nname = "x"\n[[actuator]]\nid = "a"\nfaults = [0,0,0,0,0,0,0,0.5]\n[[actuator]]\n'
         'id = "a"\nfaults = [0,0,0,0,0,0,0,0.5]', "given twice: a"),
        ('[campaign]\nname = "x"\n[[actuator]]\nid = "a"\nfaults = [0,0,0,0,0,0,0,0.5]\nflights = 3', "exactly one of"),
        ('[campaign]\nname = "x"\n[[actuator]]\nid = "a"\nfaults = [0,0,0,0,0,0,0,1.5]', "faults"),
        ('[campaign]\nname = "x"\n[[actuator]]\nid = "a"\nreference = "nope.h5"', "no such file"),
        ('[campaign]\nname = "x"\n[[actuator]]\nid = "a"\nflights = 3\nstart = [0,0,0,0,0,0,0,0.5]\n'
         'growth = [0,0,0,0,0,0,0,0]\nlaw = "cubic"', "law must be"),
        ('[campaign]\nname = "x"\n[identify]\noptimiser = "ga"\n[[actuator]]\nid = "a"\n'
         'faults = [0,0,0,0,0,0,0,0.5]', r"\[identify\] unknown key"),
        ('[campaign]\nname = "x"\n[identify]\noptimizer = "sa"\n[[actuator]]\nid = "a"\n'
         'faults = [0,0,0,0,0,0,0,0.5]', "optimizer"),
        ('[campaign]\nname = "x"\n[identify]\nerror_corner = -2.0\n[[actuator]]\nid = "a"\n'
         'faults = [0,0,0,0,0,0,0,0.5]', "error_corner"),
        ('[campaign]\nname = "x"\n[identify]\nerror_corner = "fast"\n[[actuator]]\nid = "a"\n'
         'faults = [0,0,0,0,0,0,0,0.5]', "error_corner"),
        ('[campaign]\nname = "x"\n', "no \\[\\[actuator\\]\\]"),
        ('[campaign]\nname = "x"\n[[fleet]]\nprefix = "R"\ncount = 0\nseed = 1\nfaults = "random"', "count must be"),
        ('[campaign]\nname = "x"\n[[fleet]]\nprefix = "R"\ncount = 3\nfaults = "random"', "seed must be"),
        ('[campaign]\nname = "x"\n[[fleet]]\nprefix = "R"\ncount = 3\nseed = 1\nfaults = "random"\nflights = 2',
         "exactly one of"),
        ('[campaign]\nname = "x"\n[[fleet]]\nprefix = "R"\ncount = 3\nseed = 1\nfaults = [[0, 2],0,0,0,0,0,0,0.5]',
         "faults"),
        ('[campaign]\nname = "x"\n[[fleet]]\nprefix = "R"\ncount = 3\nseed = 1\nfaults = [[0.3, 0.1],0,0,0,0,0,0,0.5]',
         "low <= high"),
        ('[campaign]\nname = "x"\n[[fleet]]\nprefix = "R"\ncount = 3\nseed = 1\nfaults = "random"\nsize = 2',
         "unknown key"),
        ('[campaign]\nname = "x"\n[[actuator]]\nid = "R1"\nfaults = [0,0,0,0,0,0,0,0.5]\n[[fleet]]\nprefix = "R"\n'
         'count = 3\nseed = 1\nfaults = "random"', "given twice: R1"),
        ("[campaign\n", "not a valid TOML"),
    ],
)  # fmt: skip
def test_a_bad_campaign_file_is_refused_in_one_line(tmp_path, text, match):
    (tmp_path / "c.toml").write_text(text + "\n")
    with pytest.raises(InputError, match=match) as exc:
        load_campaign(tmp_path / "c.toml")
    assert "\n" not in str(exc.value)


def _check_store(out: Path, spec: Path) -> set[str]:
    """Every part file readable, no key twice; the keys."""
    table = ResultStore(out).read()
    keys = table.column("job_key").to_pylist()
    assert len(keys) == len(set(keys)), "a job stored twice"
    assert set(table.column("actuator").to_pylist()) <= {"A001", "007", "H1"}  # "007" stays a string
    assert set(keys) <= {j.key for j in load_campaign(spec).jobs()}
    return set(keys)


def test_a_campaign_resumes_after_an_interruption_with_every_job_exactly_once(tmp_path):
    spec = write_spec(tmp_path)
    out = tmp_path / "store"
    calls = []

    def stop_after_five(done, failed, todo, elapsed):
        calls.append(done)
        if done == 5:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_campaign(spec, out, workers=1, progress=stop_after_five, flush_rows=3)
    assert len(_check_store(out, spec)) == 5  # the rows done before Ctrl-C were kept
    summary = run_campaign(spec, out, workers=1)
    assert summary.already_done == 5 and summary.submitted == 7 and summary.done == 7
    assert len(_check_store(out, spec)) == 12
    status = campaign_status(spec, out)
    assert (status["done"], status["missing"], status["failed"], status["stored_rows"]) == (12, 0, 0, 12)


RUNNER = """
import sys
from emaphm.campaign import run_campaign
run_campaign(sys.argv[1], sys.argv[2], workers=1, flush_rows=1)
"""


@pytest.mark.slow  # ~4-7 s: four subprocesses, each importing emaphm, killed mid-campaign
def test_kill_9_at_any_moment_then_rerun_gives_every_job_once(tmp_path):
    spec = write_spec(tmp_path)
    out = tmp_path / "store"
    rng = np.random.default_rng(11)
    env = {**os.environ, "PYTHONHASHSEED": "0"}
    stored = []
    for target in (2, 5, 8, 10):  # kill once the store holds this many rows, then a random instant later
        proc = subprocess.Popen([sys.executable, "-c", RUNNER, str(spec), str(out)], env=env)
        deadline = time.monotonic() + 120
        while proc.poll() is None and time.monotonic() < deadline:
            if len(list(out.rglob("part-*.parquet"))) >= target:  # flush_rows=1: one file per job
                time.sleep(float(rng.uniform(0.0, 0.15)))  # inside a job, or inside a write
                break
            time.sleep(0.01)
        if proc.poll() is None:
            os.kill(proc.pid, signal.SIGKILL)
        proc.wait()
        stored.append(len(_check_store(out, spec)))
    assert any(0 < n < 12 for n in stored), f"no kill landed inside the campaign: {stored}"
    run_campaign(spec, out, workers=1)
    assert len(_check_store(out, spec)) == 12
    assert not list(out.rglob(".part-*.tmp"))  # the next run removed what a kill left


def test_a_failing_job_is_recorded_and_the_campaign_goes_on(tmp_path, capsys):
    trace = emaphm.simulate(seed=1, duration=0.3)
    signals = dict(trace.signals)
    emaphm.write_trace(emaphm.SimResult(t=trace.t, signals={**signals, "i_q": 1000 * signals["i_q"]}),
                       tmp_path / "mA.h5")  # fmt: skip
    spec = write_spec(tmp_path, extra='\n[[actuator]]\nid = "BAD"\nreference = "mA.h5"\n')
    code, _, err = run_cli(
        ["campaign", "run", str(spec), "--out", str(tmp_path / "s"), "--workers", "1"], capsys
    )
    assert code == 1 and "2 job(s) failed" in err
    failures = ResultStore(tmp_path / "s").read("failures").to_pylist()
    assert {f["actuator"] for f in failures} == {"BAD"} and "is the current in mA" in failures[0]["message"]
    # each failed job in one line (review: no traceback over the progress), the traceback in the store
    lines = [line for line in err.splitlines() if line.startswith("emaphm: failed: actuator BAD flight")]
    assert len(lines) == 2 and all("InputError" in line for line in lines)
    assert "Traceback (most recent call last)" not in err
    assert all(f["traceback"].startswith("Traceback (most recent call last)") for f in failures)
    assert all("InputError" in f["traceback"].splitlines()[-1] for f in failures)
    code, out, _ = run_cli(["campaign", "status", str(spec), str(tmp_path / "s"), "--json"], capsys)
    data = json.loads(out)
    assert code == 0 and (data["done"], data["failed"], data["missing"]) == (12, 2, 0)


def test_a_campaign_job_gives_the_estimate_of_a_lone_identification(tmp_path):
    spec = write_spec(tmp_path)
    run_campaign(spec, tmp_path / "s", workers=1)
    rows = {
        (r["actuator"], r["flight"], r["seed"]): r for r in ResultStore(tmp_path / "s").read().to_pylist()
    }
    for (actuator, flight, seed), truth in (
        (("007", 0, 2), [0, 0, 0.3, 0, 0, 0, 0, 0.5]),
        (("H1", 3, 1), None),
    ):
        row = rows[(actuator, flight, seed)]
        k = truth if truth is not None else [row[f"true_k{i}"] for i in range(1, 9)]
        alone = emaphm.identify(true_faults=k, seed=row["identify_seed"], pop_size=6, generations=2,
                                polish=False, uncertainty="none")  # fmt: skip
        assert [row[f"k{i}"] for i in range(1, 9)] == alone.estimate.tolist()
        # and its verdict with the reasons for it (a 6 x 2 search fits poorly: doubtful)
        assert row["verdict"] == alone.verdict and json.loads(row["doubts"]) == alone.doubts


@pytest.mark.slow  # ~3-4 s: a local dask cluster started and stopped
def test_dask_runs_the_same_jobs_on_one_numba_thread_per_worker(tmp_path):
    pytest.importorskip("distributed")
    spec = write_spec(tmp_path)
    serial = run_campaign(spec, tmp_path / "serial", workers=1)
    before = dict(os.environ)
    dask = run_campaign(spec, tmp_path / "dask", workers=2)
    # Dask's nannies put NUMBA_NUM_THREADS=1 into this process's environment to hand it to the
    # workers; left there, the next numba compile here failed (every later test, on a cold cache)
    assert dict(os.environ) == before
    assert serial.done == dask.done == 12 and "dask" in dask.backend
    a = {r["job_key"]: r for r in ResultStore(tmp_path / "serial").read().to_pylist()}
    b = {r["job_key"]: r for r in ResultStore(tmp_path / "dask").read().to_pylist()}
    assert a.keys() == b.keys()
    for key in a:
        assert [a[key][f"k{i}"] for i in range(1, 9)] == [b[key][f"k{i}"] for i in range(1, 9)]
    assert {r["numba_threads"] for r in b.values()} == {1}  # workers x threads within the cores
    assert len({r["worker"] for r in b.values()}) == 2


def test_a_store_written_before_a_column_existed_still_reads(tmp_path):
    import pyarrow as pa
    import pyarrow.parquet as pq

    old = tmp_path / "results" / "campaign=c" / "actuator=007"
    old.mkdir(parents=True)
    pq.write_table(pa.table({"job_key": ["k-old"], "flight": [1], "k1": [0.2]}), old / "part-old.parquet")
    ResultStore(tmp_path).write("results", [{"job_key": "k-new", "campaign": "c", "actuator": "007", "flight": 2,
                                             "uq_flags": "[]"}])  # fmt: skip
    rows = {r["job_key"]: r for r in ResultStore(tmp_path).read().to_pylist()}
    assert (
        rows["k-old"]["uq_flags"] is None and rows["k-old"]["k1"] == 0.2 and rows["k-new"]["uq_flags"] == "[]"
    )
    assert rows["k-old"]["actuator"] == "007"


def test_a_campaign_sets_the_error_corner_as_identify_does(tmp_path):
    """[identify] error_corner reaches `emaphm.identify` as identify takes it ("off": None)."""
    from emaphm.campaign.jobs import identify_kwargs

    for given, passed in (('"off"', None), ('"auto"', "auto"), ("3", 3.0), ("1.5", 1.5)):
        (tmp_path / "c.toml").write_text(
            f'[campaign]\nname = "x"\n[identify]\nerror_corner = {given}\n'
            '[[actuator]]\nid = "a"\nfaults = [0,0,0,0,0,0,0,0.5]\n'
        )
        (job,) = load_campaign(tmp_path / "c.toml").jobs()
        kwargs = identify_kwargs(job.to_dict())
        assert kwargs["error_corner"] == passed


def test_a_campaign_sets_the_last_stage_as_identify_does(tmp_path):
    """[identify] last_stage reaches `emaphm.identify`; an unknown stage is refused in one line."""
    from emaphm.campaign.jobs import identify_kwargs

    for given in ("auto", "switching", "none"):
        (tmp_path / "c.toml").write_text(
            f'[campaign]\nname = "x"\n[identify]\nlast_stage = "{given}"\n'
            '[[actuator]]\nid = "a"\nfaults = [0,0,0,0,0,0,0,0.5]\n'
        )
        (job,) = load_campaign(tmp_path / "c.toml").jobs()
        assert identify_kwargs(job.to_dict())["last_stage"] == given
    for bad in ('"fast"', "true"):
        (tmp_path / "c.toml").write_text(
            f'[campaign]\nname = "x"\n[identify]\nlast_stage = {bad}\n'
            '[[actuator]]\nid = "a"\nfaults = [0,0,0,0,0,0,0,0.5]\n'
        )
        with pytest.raises(InputError, match="last_stage"):
            load_campaign(tmp_path / "c.toml")


def test_a_campaign_can_turn_the_second_search_off_as_identify_does(tmp_path):
    """[identify] second_search reaches `emaphm.identify`; not a bool: refused in one line."""
    from emaphm.campaign.jobs import identify_kwargs

    for given, passed in (("false", False), ("true", True)):
        (tmp_path / "c.toml").write_text(
            f'[campaign]\nname = "x"\n[identify]\nsecond_search = {given}\n'
            '[[actuator]]\nid = "a"\nfaults = [0,0,0,0,0,0,0,0.5]\n'
        )
        (job,) = load_campaign(tmp_path / "c.toml").jobs()
        assert identify_kwargs(job.to_dict())["second_search"] is passed
    (tmp_path / "c.toml").write_text(
        '[campaign]\nname = "x"\n[identify]\nsecond_search = "no"\n[[actuator]]\nid = "a"\nfaults = [0,0,0,0,0,0,0,0.5]\n'
    )
    with pytest.raises(InputError, match="second_search"):
        load_campaign(tmp_path / "c.toml")


def test_a_results_row_records_the_second_search(tmp_path, monkeypatch):
    import json

    from emaphm.campaign.jobs import run_job
    from emaphm.identification import limits

    # a trigger every fit exceeds and a tiny polish: each job searches twice
    monkeypatch.setitem(limits.SECOND_SEARCH_NRMSE, "default", 0.0)
    monkeypatch.setattr(limits, "POLISH_BUDGET", (8, 2))
    rows = {}
    for second in ("true", "false"):
        (tmp_path / "c.toml").write_text(
            f'[campaign]\nname = "x"\n[identify]\npop_size = 6\ngenerations = 2\nuncertainty = "none"\n'
            f'second_search = {second}\nlast_stage = "none"\n[[actuator]]\nid = "a"\nfaults = [0.2,0,0,0,0,0,0,0.5]\n'
        )
        (job,) = load_campaign(tmp_path / "c.toml").jobs()
        rows[second] = run_job(job.to_dict())
    record = json.loads(rows["true"]["second_search"])
    assert (
        record["trigger"] == 0.0
        and record["first_evaluations"] + record["second_evaluations"] == (rows["true"]["evaluations"])
    )
    assert rows["false"]["second_search"] is None


def test_a_change_of_code_data_or_settings_redoes_the_jobs_and_says_so(tmp_path, monkeypatch):
    # review H1: the key hashed a version string that never moved, so an upgrade (a new packaged
    # calibration, a new default) left every stored result "done"
    from emaphm.campaign import fingerprint
    from emaphm.identification import limits

    spec = write_spec(tmp_path)
    out = tmp_path / "store"
    first = run_campaign(spec, out, scheduler="serial")
    jobs = load_campaign(spec).jobs()
    assert first.done == 12 and first.stale == 0 and len({j.fingerprint for j in jobs}) == 1
    rows = ResultStore(out).read().to_pylist()
    assert {r["fingerprint"] for r in rows} == {jobs[0].fingerprint}
    # other code or packaged data (here: another source hash); the keys stay, the fingerprints move
    monkeypatch.setattr(fingerprint, "code_hash", lambda: "another version")
    moved = load_campaign(spec).jobs()
    assert [j.key for j in moved] == [j.key for j in jobs] and moved[0].fingerprint != jobs[0].fingerprint
    assert campaign_status(spec, out)["stale"] == 12
    kept = run_campaign(spec, out, scheduler="serial", keep_stale=True)
    assert (kept.submitted, kept.stale, kept.kept_stale) == (0, 12, True)
    redone = run_campaign(spec, out, scheduler="serial")
    assert (redone.submitted, redone.done, redone.stale) == (12, 12, 12)
    rows = ResultStore(out).read().to_pylist()  # one row per job, the latest: never two fingerprints
    assert len(rows) == 12 and {r["fingerprint"] for r in rows} == {moved[0].fingerprint}
    assert campaign_status(spec, out)["stale"] == 0
    # a tuned constant of the stages moves it too (it is recorded in every result)
    monkeypatch.setattr(limits, "FIT_NRMSE_WARN", 0.07)
    assert load_campaign(spec).jobs()[0].fingerprint != moved[0].fingerprint


def test_a_job_written_twice_is_read_once_the_latest(tmp_path):
    # review M2: a retried flush wrote a result row twice and rul counted the flight twice
    store = ResultStore(tmp_path)
    row = {"job_key": "k1", "campaign": "c", "actuator": "A", "flight": 1, "seed": 1, "finished": "2026-01-01T00:00:00"}
    store.write("results", [row])
    store.write("results", [{**row, "fitness": 2.0, "finished": "2026-01-02T00:00:00"}])
    store.write("results", [{**row, "job_key": "k2"}])
    table = store.read()
    assert table.num_rows == 2 and sorted(table.column("job_key").to_pylist()) == ["k1", "k2"]
    latest = {r["job_key"]: r for r in table.to_pylist()}
    assert latest["k1"]["fitness"] == 2.0 and store.keys() == {"k1", "k2"}


def test_a_failed_store_write_neither_fails_a_done_job_nor_writes_it_twice(tmp_path, monkeypatch):
    # review M2: one failed write recorded a job that had succeeded as failed and wrote its row twice
    from emaphm.campaign import runner

    spec = write_spec(tmp_path)
    out = tmp_path / "store"
    monkeypatch.setattr(runner, "run_job", lambda job: {
        "job_key": job["key"], "campaign": job["campaign"], "actuator": job["actuator"], "flight": job["flight"],
        "seed": job["seed"], "finished": "2026-01-01T00:00:00", "fingerprint": job["fingerprint"],
    })  # fmt: skip
    original, calls = ResultStore.write, []

    def write_once_failing(self, kind, rows):  # type: ignore[no-untyped-def]
        calls.append(kind)
        if kind == "failures" and calls.count("failures") == 1:
            raise OSError(28, "No space left on device")
        return original(self, kind, rows)

    monkeypatch.setattr(ResultStore, "write", write_once_failing)
    with pytest.raises(OSError, match="No space left"):
        run_campaign(spec, out, scheduler="serial", flush_rows=3)
    summary = run_campaign(spec, out, scheduler="serial", flush_rows=3)
    rows = ResultStore(out).read().to_pylist()
    assert summary.failed == 0 and len(rows) == 12 and len({r["job_key"] for r in rows}) == 12
    assert ResultStore(out).read("failures").num_rows == 0


def test_serial_and_dask_treat_a_jobs_programming_error_alike(tmp_path, monkeypatch):
    # review L9: the serial path aborted the campaign on a KeyError that Dask recorded and skipped
    from emaphm.campaign import runner

    def broken(job):  # type: ignore[no-untyped-def]
        raise KeyError("a bug in one job")

    monkeypatch.setattr(runner, "run_job", broken)
    summary = run_campaign(write_spec(tmp_path), tmp_path / "store", scheduler="serial")
    failures = ResultStore(tmp_path / "store").read("failures").to_pylist()
    assert summary.failed == 12 and {f["error"] for f in failures} == {"KeyError"}


@pytest.mark.slow  # starts a Dask cluster (~3 s)
def test_a_cluster_whose_workers_run_several_threads_is_refused(tmp_path):
    # review M3: two jobs in one worker process both call numba's parallel kernels
    from distributed import LocalCluster

    with LocalCluster(n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None) as cluster:
        with pytest.raises(InputError, match=r"run 2 threads each.*--nthreads 1"):
            run_campaign(write_spec(tmp_path), tmp_path / "store", scheduler=cluster.scheduler_address)
    assert not (tmp_path / "store" / "results").exists()


@pytest.mark.slow  # ~4 s: a local dask cluster started and stopped
def test_a_job_failing_on_a_dask_worker_prints_no_traceback(tmp_path, capfd):
    # issue 35: the worker's own log of a failed task printed the whole traceback over the
    # user's progress; the store keeps it, the worker is silent
    pytest.importorskip("distributed")
    trace = emaphm.simulate(seed=1, duration=0.3)
    signals = dict(trace.signals)
    emaphm.write_trace(emaphm.SimResult(t=trace.t, signals={**signals, "i_q": 1000 * signals["i_q"]}),
                       tmp_path / "mA.h5")  # fmt: skip
    spec = write_spec(tmp_path, extra='\n[[actuator]]\nid = "BAD"\nreference = "mA.h5"\n')
    summary = run_campaign(spec, tmp_path / "s", workers=2)
    err = capfd.readouterr().err
    assert summary.failed == 2 and len(summary.failures) == 2
    assert "Compute Failed" not in err and "Traceback" not in err
    failures = ResultStore(tmp_path / "s").read("failures").to_pylist()
    assert all("InputError" in f["traceback"] for f in failures)
