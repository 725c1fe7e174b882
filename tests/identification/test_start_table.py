"""The GA's first population from a table of monitor runs (issue 36, `identification.start_table`)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import emaphm
from emaphm.commands import SampledCommand, Steps
from emaphm.errors import InputError
from emaphm.identification import start_table
from emaphm.identification.identifier import FaultIdentifier
from emaphm.identification.problem import search_to_faults
from emaphm.identification.settings import IdentifySettings

K = np.array([0.3, 0.2, 0.0, 0.35, 0.1, 0.02, 0.3, 0.5])


@pytest.fixture
def small(monkeypatch, tmp_path):
    """A table of 512 rows in a folder of the test's own (the shipped size is a tuned constant)."""
    monkeypatch.setattr(start_table, "TABLE_ROWS", 512)
    monkeypatch.setattr(start_table, "BUILD_BATCH", 128)
    monkeypatch.setenv("EMAPHM_TABLE_DIR", str(tmp_path / "tables"))
    monkeypatch.setattr(start_table, "_MEMORY", start_table.OrderedDict())
    return tmp_path / "tables"


def _context(trace, command=None, **settings):
    settings = {"start": "auto", **settings}
    ident = FaultIdentifier(IdentifySettings(**settings)).prepare(trace.t, trace.i_q, command)
    return ident.context_


def test_the_ranking_is_eq3_between_the_measurement_and_each_stored_current(small, sim):
    trace = sim(K, ideal=False)
    ctx = _context(trace)
    theta = start_table.table_command(ctx)
    table = start_table.build_table(ctx, theta)
    # brute force: eq. 3 on the table's samples, from the monitor's own filtered currents
    rows = table.X[:64]
    currents = ctx.reference.filtered(ctx.monitor.simulate_many(search_to_faults(rows), duration=ctx.duration))
    w, ref = ctx.objective.weights[table.index], ctx.reference.reference[table.index]
    d = ((ref - currents[:, table.index]) ** 2) @ w
    np.testing.assert_allclose(table.T[:64], currents[:, table.index], atol=2e-3 * np.abs(currents).max())
    sub = start_table.StartTable(rows, table.T[:64], table.index, table.key)
    got = sub.ranked(ctx.reference.reference, ctx.objective.weights, 5)
    np.testing.assert_array_equal(got, rows[np.argsort(d)[:5]])


def test_the_table_puts_the_first_population_near_the_truth(small, sim):
    trace = sim(K, ideal=False)
    ctx = _context(trace)
    table, built = start_table.start_table(ctx, start_table.table_command(ctx))
    assert built
    best = table.ranked(ctx.reference.reference, ctx.objective.weights, 16)
    rng = np.random.default_rng(0)
    uniform = rng.uniform(size=(16, 8))
    # the ranked rows fit the measurement far better than uniform ones (eq. 3, by the monitor)
    assert np.median(ctx.evaluate(best)) < 0.3 * np.median(ctx.evaluate(uniform))


def test_a_table_is_kept_by_its_key_and_read_back_the_same(small, sim):
    trace = sim(K, ideal=False)
    ctx = _context(trace)
    theta = start_table.table_command(ctx)
    first, built = start_table.start_table(ctx, theta)
    assert built and len(list(small.glob("*.table"))) == 1
    start_table._MEMORY.clear()
    again, built_again = start_table.start_table(ctx, theta)
    assert not built_again
    np.testing.assert_array_equal(first.T, again.T)
    np.testing.assert_array_equal(first.X, again.X)
    # another actuator (its monitor's rows) is another table
    base = emaphm.EmaParams()
    params = dataclasses.replace(base, transmission=dataclasses.replace(base.transmission, F_S0=1.2 * base.transmission.F_S0))
    other = FaultIdentifier(IdentifySettings(), monitor=emaphm.MonitorEma(params, allow_mismatch=True)).prepare(
        trace.t, trace.i_q).context_  # fmt: skip
    assert start_table.table_key(other, theta) != first.key
    # a file with another key at that name (a collision, a foreign file) is not taken
    path = next(small.glob("*.table"))
    with path.open("wb") as f:
        for array in (np.array("x" * 64), first.X, first.index, first.T):
            np.save(f, array)
    start_table._MEMORY.clear()
    assert start_table.start_table(ctx, theta)[1]
    # a file cut short (a copy that stopped) is built again too, and replaced by a whole one
    whole = path.read_bytes()
    path.write_bytes(whole[: len(whole) // 2])
    start_table._MEMORY.clear()
    assert start_table.start_table(ctx, theta)[1] and path.read_bytes() == whole
    start_table._MEMORY.clear()
    kept, built = start_table.start_table(ctx, theta)
    assert not built and isinstance(kept.T, np.memmap)  # read memory-mapped
    np.testing.assert_array_equal(kept.T, first.T)


def test_the_table_folder_keeps_the_most_recently_used_tables_within_its_bound(small, sim, monkeypatch, tmp_path):
    import os

    folder = tmp_path / "folder"
    folder.mkdir()
    paths = [folder / f"{c * 32}{suffix}" for c, suffix in zip("abcd", [".table", ".npz", ".table", ".table"], strict=True)]
    for age, path in enumerate(paths):
        path.write_bytes(b"x" * 2**20)  # 1 MiB each, a the oldest
        os.utime(path, (1000.0 + age, 1000.0 + age))
    os.utime(paths[0], (2000.0, 2000.0))  # a read since: now the newest
    monkeypatch.setenv("EMAPHM_TABLE_CACHE_MB", "3.5")
    assert start_table.prune(folder, keep=paths[1]) == [paths[2]]  # b kept as asked, c the oldest after it
    assert sorted(p.name[0] for p in folder.iterdir()) == ["a", "b", "d"]  # a format-1 .npz counted too
    monkeypatch.setenv("EMAPHM_TABLE_CACHE_MB", "0")  # no bound
    assert start_table.prune(folder) == []
    # through `start_table`: a table written beyond the bound removes the older ones, not itself
    monkeypatch.setenv("EMAPHM_TABLE_CACHE_MB", "1")
    small.mkdir(parents=True)
    old = small / ("e" * 32 + ".npz")
    old.write_bytes(b"x" * 2**20)
    os.utime(old, (1000.0, 1000.0))
    ctx = _context(sim(K, ideal=False))
    assert start_table.start_table(ctx, start_table.table_command(ctx))[1]
    assert not old.exists() and len(list(small.glob("*.table"))) == 1


def test_a_folder_that_cannot_be_written_builds_the_table_in_memory(small, sim, monkeypatch, tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    monkeypatch.setenv("EMAPHM_TABLE_DIR", str(blocker / "tables"))
    ctx = _context(sim(K, ideal=False))
    table, built = start_table.start_table(ctx, start_table.table_command(ctx))
    assert built and len(table.X) > 0
    assert start_table.start_table(ctx, start_table.table_command(ctx))[1] is False  # this process's


def test_a_recording_of_the_chirp_shares_the_chirps_table_and_another_command_has_none(small, sim):
    trace = sim(K, ideal=False)
    chirp_ctx = _context(trace)
    recorded = _context(trace, SampledCommand(trace.t - trace.t[0], trace.theta_cmd))
    assert isinstance(recorded.monitor.command, SampledCommand)
    theta = start_table.uses_table(recorded)
    assert theta is not None
    np.testing.assert_array_equal(theta, start_table.table_command(chirp_ctx))
    # a command none of the calibration's: a uniform start with "auto", its own table with "table"
    odd = SampledCommand(trace.t - trace.t[0], 0.5 * trace.theta_cmd)
    assert start_table.uses_table(_context(trace, odd)) is None
    own = start_table.uses_table(_context(trace, odd, start="table"))
    np.testing.assert_allclose(own, 0.5 * np.asarray(start_table.table_command(chirp_ctx)), atol=1e-12)
    assert start_table.uses_table(_context(trace, start="random")) is None
    assert start_table.uses_table(_context(trace, optimizer="de")) is None
    steps = sim(K, command=Steps(), ideal=False)
    steps_ctx = _context(steps, Steps())
    _, theta = steps_ctx.monitor.sample_grid(steps_ctx.duration)
    np.testing.assert_array_equal(start_table.uses_table(steps_ctx), theta)  # a built-in command's own


def test_an_identification_records_its_start_and_the_second_search_starts_uniform(small, sim, monkeypatch):
    from emaphm.identification import limits

    trace = sim(K, ideal=False)
    r = emaphm.identify(reference=trace, seed=1, pop_size=16, uncertainty="none", last_stage="none", start="auto")
    search = r.settings["stages"][0]
    assert search["start"] == "table" and search["table_rows"] == 512 and search["table_built"] is True
    assert search["generations_run"] == limits.TABLE_GENERATIONS
    # the table's GA makes half its population new per generation (`limits.TABLE_OFFSPRING`)
    assert search["offspring"] == 8 and search["evaluations"] == 16 + (limits.TABLE_GENERATIONS - 1) * 8
    assert r.evaluations > search["evaluations"]
    # the second search (made to run here) is the uniform GA with its full budget
    monkeypatch.setitem(limits.SECOND_SEARCH_NRMSE, "default", 1e-6)
    r2 = emaphm.identify(reference=trace, seed=1, pop_size=16, generations=None, polish=True, uncertainty="none",
                         last_stage="none", start="table")  # fmt: skip
    second = next(st for st in r2.settings["stages"] if st["stage"] == "second_search")
    assert second["ran"]
    assert second["stages"][0]["start"] == "random"
    assert second["stages"][0]["generations_run"] <= limits.DEFAULT_BUDGETS["ga"][1]
    assert second["stages"][0]["generations_run"] > limits.TABLE_GENERATIONS


def test_start_auto_is_the_default_random_a_uniform_ga_and_start_table_needs_the_ga(small, sim):
    trace = sim(K, ideal=False)
    assert IdentifySettings().start == "auto"
    r = emaphm.identify(reference=trace, seed=1, pop_size=16, generations=3, polish=False, last_stage="none",
                        uncertainty="none", start="random")  # fmt: skip
    assert r.settings["stages"][0]["start"] == "random" and not list(small.glob("*.table"))
    with pytest.raises(InputError, match="GA's first population"):
        IdentifySettings(optimizer="de", start="table")
    with pytest.raises(InputError, match="unknown start"):
        IdentifySettings(start="table-ish")


def test_the_cli_takes_start_and_refuses_an_unknown_one_in_one_line(small, tmp_path, capsys, monkeypatch):
    import json

    from tests.helpers import EXIT_OF_VERDICT, run_cli

    out = tmp_path / "r.json"
    code, _, _ = run_cli(["identify", "--true-faults", "0.3,0,0,0.3,0,0,0,0.5", "--seed", "1", "--pop-size", "8",
                          "--generations", "2", "--no-polish", "--last-stage", "none", "--uncertainty", "none",
                          "--start", "table", "--output", str(out)], capsys)  # fmt: skip
    data = json.loads(out.read_text())
    assert code == EXIT_OF_VERDICT[data["verdict"]]
    assert data["settings"]["stages"][0]["start"] == "table" and data["settings"]["identify"]["start"] == "table"
    code, _, err = run_cli(["identify", "--true-faults", "0,0,0,0,0,0,0,0.5", "--start", "sideways",
                            "--output", str(tmp_path / "no.json")], capsys)  # fmt: skip
    assert code == 2 and "start" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "no.json").exists()
    # a table folder's bound that is not a number of MiB: refused in one line, no new table, no output
    tables = sorted(small.glob("*.table"))
    for bad in ("lots", "-1"):
        monkeypatch.setenv("EMAPHM_TABLE_CACHE_MB", bad)
        code, _, err = run_cli(["identify", "--true-faults", "0,0,0,0,0,0,0,0.5", "--pop-size", "8",
                                "--generations", "2", "--output", str(tmp_path / "no.json")], capsys)  # fmt: skip
        assert code == 2 and "EMAPHM_TABLE_CACHE_MB" in err and len(err.strip().splitlines()) == 1
        assert not (tmp_path / "no.json").exists() and sorted(small.glob("*.table")) == tables


def test_a_process_keeps_only_the_most_recent_tables_in_memory(small, sim, monkeypatch):
    monkeypatch.setattr(start_table, "MEMORY_TABLES", 2)
    monkeypatch.setattr(start_table, "TABLE_ROWS", 64)
    ctx = _context(sim(K, ideal=False))
    theta = start_table.table_command(ctx)
    keys = []
    for scale in (1.0, 0.9, 0.8):  # three commands: three tables
        table, built = start_table.start_table(ctx, scale * theta)
        keys.append(table.key)
        assert built
    assert list(start_table._MEMORY) == keys[1:]
    assert start_table.start_table(ctx, 0.9 * theta)[1] is False  # kept, and now the most recent
    assert list(start_table._MEMORY) == [keys[2], keys[1]]
