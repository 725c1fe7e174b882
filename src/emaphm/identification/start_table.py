"""The search's first population from a table of monitor runs (issue 36: the learned first guess).

A diagnosis of a given actuator under a given command always compares the measurement with the
same monitor model; only the faults change. So the monitor's filtered current can be computed
once, at `TABLE_ROWS` points of the search box (a Latin hypercube from a fixed seed), and kept:
a *start table*. For each recording the table's rows are ranked by eq. 3 between the
measurement and each stored current, on every `TABLE_STEP`-th sample with the recording's own
weights (`StartTable.ranked`: one pass over the table, no monitor run), and the best `pop_size` rows
are the GA's first population. The GA then runs `limits.TABLE_GENERATIONS` generations instead of
its 40 from a uniform population, each of `limits.TABLE_OFFSPRING` x the population new points
(half; one per member from a uniform population), and the polishes, checks, second search and last stage follow
as before. The table is only a start: every point it gives is evaluated by the monitor before the
search keeps it, and a poor fit still starts the second search, which searches from a uniform
population with the full budget (`second_search`). It is the default first population
(``start`` "auto", `uses_table`) since issue 36's fifth session; the packaged interval
calibrations are fitted for it.

Why: the GA's 40 generations carry the basin (BENCHMARKS.md, issue 36: shorter GAs, samples of a
few thousand points and least-squares multistarts each fell into wrong basins on some case). A
table of 16 384 runs is a sample 170 times the GA's first population, drawn once per actuator,
calibration and command rather than once per diagnosis; ranked against the recording it puts the
first population near the right basin.

A table depends on everything that sets the monitor's current: the monitor's parameter rows
(actuator, calibration, fault mapping), the command sampled on the monitor's grid over the
compared span, the comparison filter, the kernels' sources and the table's own layout; its key
(`table_key`) is a SHA-256 of all of them. Tables are kept in ``$EMAPHM_TABLE_DIR`` when set,
else ``$XDG_CACHE_HOME/emaphm/start-tables`` (``~/.cache/...``); one is built the first time its
key is asked for (16 384 monitor runs: 8-11 s on a shared 2-core machine) and written atomically (`start_table_files`); where no
folder can be written it is built in memory for the process. The folder is bounded (`prune`: the
least recently used tables go beyond ``$EMAPHM_TABLE_CACHE_MB``, 2 GiB by default). A baselined
actuator starts from its nameplate's table (``Context.table_monitor``), shared by its type.
"""

from __future__ import annotations

import hashlib
from collections import OrderedDict
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from .._threads import thread_map
from ..callbacks import Progress
from ..kernels.fitness import residuals_lf_many
from .multistart import latin_hypercube
from .problem import search_to_faults
from .start_table_files import TABLE_SUFFIX, cache_limit, prune, read_table, table_dir, write_table

if TYPE_CHECKING:
    from .context import Context

__all__ = [
    "StartTable",
    "build_table",
    "cache_limit",
    "first_population",
    "prune",
    "start_table",
    "table_command",
    "table_dir",
    "table_key",
    "uses_table",
]

# 2: one file of four .npy arrays (key, X, index, T as float32, memory-mapped when read); 1 was an
# .npz with T in float16, whose read, check and conversion took 45-140 ms of a diagnosis's start
TABLE_FORMAT = "emaphm-start-table-2"
TABLE_ROWS = 16384  # the table's points of the box
TABLE_STEP = 20  # every TABLE_STEP-th sample of the monitor's grid is stored (the filter passes < 150 Hz)
TABLE_SEED = 20261201  # the Latin hypercube's seed: a table is a function of its key alone
BUILD_BATCH = 1024  # monitor runs per kernel call while building (the progress steps)
# rows ranked at once: a 2 MB temporary. The whole table at once made two 66 MB ones, fresh pages in
# a new process: 0.15 s in a profile of one identification, against 8-15 ms chunked (the same numbers)
RANK_CHUNK = 512
MEMORY_TABLES = 4  # tables a process keeps in memory (33 MB each), the most recently used


@dataclass(frozen=True)
class StartTable:
    """Monitor runs kept for ranking: the box points ``X`` (n, 8), the filtered currents ``T``
    (n, m) [A] at the grid samples ``index`` (m,), and the table's ``key``. The currents are
    rounded to half precision (about 1e-3 of their size, far below a fit's residual) and held as
    float32, in the folder too (33 MB a table), which is read memory-mapped: a table read from the
    folder ranks exactly as the one just built, with no conversion at each process's start."""

    X: NDArray[np.float64]
    T: NDArray[np.float32]
    index: NDArray[np.intp]
    key: str

    def ranked(self, reference: NDArray[np.float64], weights: NDArray[np.float64], count: int) -> NDArray[np.float64]:
        """The `count` rows of the box whose stored currents are nearest the measurement by eq. 3
        on the table's samples: Σ w·(I_ref − I)² with the recording's `weights` and filtered
        `reference` (both on the whole grid), best first. The chunks are shared among numba's
        threads (numpy releases the interpreter; one chunk's numbers whichever thread): 12-14 -> 8
        ms on machine G's two (issue 36)."""
        from numba import get_num_threads

        w = np.asarray(weights, dtype=np.float64)[self.index]
        ref = np.asarray(reference, dtype=np.float64)[self.index]
        d = np.empty(len(self.T))
        starts = range(0, len(d), RANK_CHUNK)
        workers = max(1, min(get_num_threads(), len(starts)))

        def rank(first: int) -> None:
            for lo in starts[first::workers]:  # in float64, each row's sum on its own
                r = self.T[lo : lo + RANK_CHUNK] - ref
                r *= r
                d[lo : lo + RANK_CHUNK] = r @ w

        thread_map(rank, range(workers), workers)
        count = min(int(count), len(d))
        best = np.argpartition(d, count - 1)[:count]
        return np.array(self.X[best[np.argsort(d[best], kind="stable")]], dtype=np.float64)


def _probe_rows() -> NDArray[np.float64]:
    """Box points whose monitor parameter rows stand for the monitor in the key: the centre, the
    healthy corner and a point with every fault set (the fault mapping's scales)."""
    return np.array([np.full(8, 0.5), np.zeros(8), np.linspace(0.1, 0.9, 8)])


def table_command(context: Context, *, any_command: bool = False) -> NDArray[np.float64] | None:
    """The command the context's table is made under, sampled on the monitor's grid over the
    compared span: a built-in command's own samples; for a recording's command (a
    `SampledCommand`), those of the calibration command it matches (`coverage.matches`: within
    1e-3 of its peak, up to a sample early or late), so that every recording of the FDI chirp
    shares the chirp's table. None when it matches none, unless `any_command` (start "table"):
    then its own samples."""
    from ..commands import SampledCommand
    from .coverage import matches

    monitor = context.monitor
    t, theta = monitor.sample_grid(context.duration)
    if not isinstance(monitor.command, SampledCommand):
        return np.asarray(theta, dtype=np.float64)
    step = 1.0 / monitor.params.controller.f_s
    for command in monitor.calibration.commands().values():
        if float(command.duration) + step + 1e-9 >= context.duration and matches(t, theta, command, step, 0.0):
            return np.ascontiguousarray(command(t), dtype=np.float64)
    return np.asarray(theta, dtype=np.float64) if any_command else None


def table_key(context: Context, theta_cmd: NDArray[np.float64]) -> str:
    """The SHA-256 of what sets the table's currents under `theta_cmd` (the module docstring)."""
    from ..kernels._jit import KERNEL_SOURCE_HASH

    monitor, fitness = context.monitor, context.objective
    h = hashlib.sha256()
    h.update(f"{TABLE_FORMAT}\0{TABLE_ROWS}\0{TABLE_STEP}\0{TABLE_SEED}\0{KERNEL_SOURCE_HASH}\0".encode())
    h.update(np.ascontiguousarray(monitor.rows(search_to_faults(_probe_rows()))).tobytes())
    h.update(np.ascontiguousarray(theta_cmd, dtype=np.float64).tobytes())
    for a in (fitness.sos, fitness.zi):
        h.update(np.ascontiguousarray(a, dtype=np.float64).tobytes())
    h.update(str(int(fitness.padlen)).encode())
    return h.hexdigest()


def build_table(
    context: Context, theta_cmd: NDArray[np.float64], key: str | None = None, on_progress: Progress | None = None
) -> StartTable:
    """The table of `context`'s monitor under `theta_cmd` (its grid's samples; the module
    docstring): `TABLE_ROWS` monitor runs, in batches of `BUILD_BATCH` (`on_progress(label,
    done, total)` after each). Rows whose run diverges are left out."""
    monitor, fitness = context.monitor, context.objective
    theta_cmd = np.ascontiguousarray(theta_cmd, dtype=np.float64)
    index = np.arange(0, len(theta_cmd), TABLE_STEP, dtype=np.intp)
    X = latin_hypercube(TABLE_ROWS, 8, np.random.default_rng(TABLE_SEED))
    T = np.empty((TABLE_ROWS, len(index)), dtype=np.float32)
    zeros, ones = np.zeros(len(index)), np.ones(len(index))
    for start in range(0, TABLE_ROWS, BUILD_BATCH):
        rows = monitor.rows(search_to_faults(X[start : start + BUILD_BATCH]))
        out = np.empty((rows.shape[0], len(index)))
        # residuals against a zero reference with unit weights: −(the filtered current) at `index`
        residuals_lf_many(theta_cmd, rows, fitness.sos, fitness.zi, fitness.padlen, index, zeros, ones, out)
        T[start : start + len(rows)] = -out
        if on_progress is not None:
            on_progress("start table (once per actuator and command)", start + len(rows), TABLE_ROWS)
    ok = np.all(np.isfinite(T), axis=1) & np.all(np.abs(T) < np.finfo(np.float16).max, axis=1)
    T = T.astype(np.float16).astype(np.float32)  # as kept in the folder (the class docstring)
    return StartTable(X[ok], T[ok], index, key if key is not None else table_key(context, theta_cmd))


# tables of this process, most recently used last (also those that could not be written); bounded,
# so that a long-lived campaign worker diagnosing many actuators does not hold all their tables
_MEMORY: OrderedDict[str, StartTable] = OrderedDict()


def start_table(
    context: Context, theta_cmd: NDArray[np.float64], on_progress: Progress | None = None
) -> tuple[StartTable, bool]:
    """The context's table under `theta_cmd` (`table_command`), from this process, the table
    folder, or built (and kept there); and whether it was built now."""
    cache_limit()  # a bad bound is refused before any work, wherever the table comes from
    key = table_key(context, theta_cmd)
    if key in _MEMORY:
        _MEMORY.move_to_end(key)
        return _MEMORY[key], False
    path = table_dir() / f"{key[:32]}{TABLE_SUFFIX}"
    kept = read_table(path, key)
    built = kept is None
    if kept is None:
        table = build_table(context, theta_cmd, key, on_progress)
        write_table(path, key, table.X, table.index, table.T)
    else:
        table = StartTable(kept[0], kept[1], kept[2], key)
    _MEMORY[key] = table
    while len(_MEMORY) > MEMORY_TABLES:
        _MEMORY.popitem(last=False)
    return table, built


def uses_table(context: Context) -> NDArray[np.float64] | None:
    """The command of the table the search starts from (`table_command`), or None for a uniform
    start: ``start`` "table" always (with the GA); "auto" with the GA when the command is a
    built-in one or a recording of a calibration command; "random" never. A property of the
    recording and the settings alone, never of which tables happen to be kept."""
    s = context.settings
    if s.start == "random" or s.optimizer != "ga":
        return None
    return table_command(context, any_command=s.start == "table")


def first_population(
    context: Context, theta_cmd: NDArray[np.float64], pop_size: int, on_progress: Progress | None = None
) -> tuple[NDArray[np.float64], dict[str, object]]:
    """The GA's first population from the context's table under `theta_cmd` (`StartTable.ranked`;
    the table of its ``table_monitor`` when it has one: a baseline's nameplate) and what to record
    of it."""
    source = context if context.table_monitor is None else replace(context, monitor=context.table_monitor)
    table, built = start_table(source, theta_cmd, on_progress)
    X = table.ranked(context.reference.reference, context.objective.weights, pop_size)
    return X, {"table": table.key[:16], "table_rows": len(table.X), "table_built": built}

