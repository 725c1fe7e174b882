"""Issue 36, fourteenth session: the in-process timings behind its steps (BENCHMARKS.md, "Exact
cuts: kernel loads, ..."), measured on the current code.

    python studies/step_timings.py [--repeats 5]

Prints, each as the median (min-max) over --repeats:
1. the Table 1 case's kernel loads in a fresh process (the overloads its diagnosis used in this
   process, each loaded by ``dispatcher.compile``), with numba's events on LLVM's lock off during
   a load (`kernels._jit._llvm_lock_events_off`, the code as it is) and on (that block replaced by
   a no-op in the subprocess);
2. what the `moocore` stand-in spares `import_cmaes` in a fresh process after the identification's
   imports: ``import moocore`` there;
3. `lm_descent.gram` against ``np.einsum("ik,jk->ij")`` for an 8 × 10 001 Jᵀ (the same numbers);
4. the fused residual kernel per batch size on two threads, random rows against the Table 1
   case's recording, with the batch plan (`kernels.batches`);
5. the monitor's parameter rows for 8 fault rows: built whole (`lf.monitor_rows`) and from the
   monitor's template row (`MonitorEma.rows`);
6. (fifteenth session) one monitor run (`monitor.simulate_lf`) and an interleaved pair
   (`simulate_lf2`) of the Table 1 case's row over the chirp's 10 001 samples, on one thread;
7. (fifteenth session) the cyclic collector's work in one ``emaphm identify <Table 1>`` process
   (``gc.callbacks``, from the process's entry to its end), with the start's raised threshold
   (`emaphm._gc`) and without it (`quiet_start` made a no-op), where the tree has it.
8. (sixteenth session) the switching model's twin runs (`last_stage.SwitchingModel`, the Table 1
   case): each of its three runs alone, the three one after the other, the three on two threads
   as the last stage runs them, and one run (the finest step) alone against two of it side by
   side on two threads: what the two cores give two runs of compiled code at once.
10. (eighteenth session) the comparison filter on four currents of 10 001 samples: as two
    interleaved pairs (`sosfiltfilt_inplace` twice) and all four at once (`sosfiltfilt_inplace4`);
11. (eighteenth session) the start table's ranking of the Table 1 case (`StartTable.ranked`) on one
    numba thread and on two.
Run on an older tree (``PYTHONPATH=<worktree>/src``) it times what that tree has: no events'
block, no `gram`, the fused kernel without its thread count (then its pairs alone).
Not a benchmark of the whole process: the paired figures are `farm-bench`'s.
"""

from __future__ import annotations

import argparse
import functools
import inspect
import os
import pickle
import subprocess
import sys
import tempfile
import time

import numpy as np

TABLE1 = [0.2383, 0.5003, 0.0, 0.4503, 0.0404, 0.0028, 0.2785, 0.5]

LOADS = """
import contextlib, importlib, pickle, sys, time
import emaphm.identification.api
from emaphm.kernels import _jit
if sys.argv[2] == "on" and hasattr(_jit, "_llvm_lock_events_off"):
    _jit._llvm_lock_events_off = contextlib.nullcontext
with open(sys.argv[1], "rb") as f:
    sigs = [(getattr(importlib.import_module(m), n), s) for m, n, s in pickle.load(f)]
t = time.perf_counter()
for k, s in sigs:
    k.compile(s)
print(time.perf_counter() - t, len(sigs))
"""

COLLECTOR = """
import gc, os, sys, time
n, spent, t0 = [0, 0, 0], [0.0], [0.0]
def watch(phase, info):
    if phase == "start":
        t0[0] = time.perf_counter()
    else:
        n[info["generation"]] += 1
        spent[0] += time.perf_counter() - t0[0]
gc.callbacks.append(watch)
end = os._exit
def report(status):
    print(spent[0], *n)
    sys.stdout.flush()
    end(status)
os._exit = report
if sys.argv[1] == "off":
    try:
        import emaphm._gc
        emaphm._gc.quiet_start = lambda: None
    except ImportError:
        pass
sys.argv = ["emaphm", "identify", "--true-faults", "0.2383,0.5003,0,0.4503,0.0404,0.0028,0.2785,0.5", "--seed", "1"]
from emaphm.cli import main
main()
"""

LOADS_LAZY = """
import sys, time
import emaphm.identification.api
from emaphm.kernels import _jit
if sys.argv[1] == "off":
    _jit.LAZY_LINKING = False  # numba's own loading (a tree before the seventeenth session has no switch)
from numba.core.registry import cpu_target
from numba.core.runtime import rtsys
from emaphm.commands import Chirp
from emaphm.identification import cmaes, warm
from emaphm.models import HighFidelityEma, MonitorEma
cmaes.import_polish()
monitor, twin = MonitorEma(), HighFidelityEma(command=Chirp())
t0 = time.perf_counter()
rtsys.initialize(cpu_target.target_context)
t1 = time.perf_counter()
twin.simulate([0.2383, 0.5003, 0.0, 0.4503, 0.0404, 0.0028, 0.2785, 0.5], seed=5, duration=0.002)
t2 = time.perf_counter()
warm.load_search_kernels(monitor)
print(t1 - t0, t2 - t1, time.perf_counter() - t2)
"""

MOOCORE = """
import time
import emaphm.identification.api
t = time.perf_counter()
import moocore
print(time.perf_counter() - t)
"""


def spread(values: list[float], scale: float = 1e3) -> str:
    v = np.asarray(values) * scale
    return f"{np.median(v):.2f} ({v.min():.2f}-{v.max():.2f})"


def per_call(way, repeats: int, calls: int) -> list[float]:  # type: ignore[no-untyped-def]
    """`repeats` times, the mean time of one of `calls` calls of `way()` [s]."""
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        for _ in range(calls):
            way()
        times.append((time.perf_counter() - t) / calls)
    return times


def fresh(code: str, *args: str) -> list[str]:
    return subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True, check=True).stdout.split()


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args(argv)
    import numba

    import emaphm
    from emaphm.identification.fitness import Fitness
    from emaphm.identification.signals import Comparison
    from emaphm.kernels import _jit, fitness, hf_twin, monitor, pmsm_abc, sensors, transforms
    from emaphm.kernels.fitness import residuals_lf_many

    numba.set_num_threads(2)
    emaphm.identify(true_faults=TABLE1, seed=1)  # the kernels cached and loaded, the table built
    # the kernels a diagnosis loads, in whichever tree runs this (after the fifteenth session the
    # fused kernels and the filters are Python wrappers around `*_kernel` dispatchers, and the
    # twin's measured i_q takes `transforms.q_error` instead of clarke and park)
    names = ((pmsm_abc, "ecc_harmonics"), (sensors, "adc"), (transforms, "clarke"), (transforms, "park"),
             (transforms, "q_error"), (hf_twin, "simulate_hf"), (fitness, "sosfiltfilt_one_kernel"),
             (fitness, "sosfiltfilt_one"), (fitness, "sosfiltfilt_many_kernel"), (fitness, "sosfiltfilt_many"),
             (fitness, "fitness_lf_kernel"), (fitness, "fitness_lf_many"), (fitness, "residuals_lf_kernel"),
             (fitness, "residuals_lf_many"), (monitor, "simulate_lf"), (monitor, "simulate_lf_many_kernel"),
             (monitor, "simulate_lf_many"))  # fmt: skip
    kernels = [k for m, n in names if hasattr(k := getattr(m, n, None), "signatures")]
    used = [(k.py_func.__module__, k.__name__, s) for k in kernels for s in k.signatures]
    with tempfile.NamedTemporaryFile(suffix=".pkl", delete=False) as f:
        pickle.dump(used, f)
    try:
        modes = ("off", "on") if hasattr(_jit, "_llvm_lock_events_off") else ("on",)
        for mode in modes:
            runs = [fresh(LOADS, f.name, mode) for _ in range(args.repeats)]
            print(f"1. kernel loads, events {mode}: {spread([float(r[0]) for r in runs])} ms ({runs[0][1]} overloads)")
    finally:
        os.unlink(f.name)
    print(f"2. import moocore after the identification's imports: {spread([float(fresh(MOOCORE)[0]) for _ in range(args.repeats)])} ms")
    from emaphm.identification import lm_descent  # (a module of the thirteenth session on)

    Jt = np.random.default_rng(36).standard_normal((8, 10_001))
    ways = {"einsum": lambda: np.einsum("ik,jk->ij", Jt, Jt)}
    if hasattr(lm_descent, "gram"):
        ways["gram"] = lambda: lm_descent.gram(Jt)
    for name, way in ways.items():
        print(f"3. J^T J of 8 x 10 001 by {name}: {spread(per_call(way, args.repeats, 100))} ms")
    monitor = emaphm.MonitorEma()
    trace = emaphm.HighFidelityEma().simulate(TABLE1, seed=1)
    fit = Fitness(Comparison.from_signal(trace.t, trace.i_q, monitor.params.controller.f_s))
    keep, root_w, reference = fit.weighed()
    _, theta_cmd = monitor.sample_grid(None)
    K = np.random.default_rng(1).uniform(0, 1, (18, 8))
    threads = ((2,) if "n_threads" in inspect.signature(getattr(residuals_lf_many, "py_func", residuals_lf_many)).parameters else ())
    for n in (1, 2, 4, 6, 8, 9, 18):
        rows, out = monitor.rows(K[:n]), np.empty((n, len(keep)))
        times = per_call(functools.partial(residuals_lf_many, theta_cmd, rows, fit.sos, fit.zi, fit.padlen, keep,
                                           reference, root_w, out, *threads), args.repeats, 10)  # fmt: skip
        print(f"4. the fused residual kernel, {n} rows on 2 threads: {spread(times)} ms")
    from emaphm.models.lf import monitor_rows

    cal = monitor.calibration
    ways = {"monitor_rows": lambda: monitor_rows(K[:8], monitor.params, [cal.coefficients], cal.n_lf, cal.monitor),
            "MonitorEma.rows": lambda: monitor.rows(K[:8])}  # fmt: skip
    for name, way in ways.items():
        print(f"5. 8 parameter rows by {name}: {spread(per_call(way, args.repeats, 1000), 1e6)} us")
    from emaphm.kernels.monitor import N_AUX, simulate_lf, simulate_lf2

    row = monitor.rows(np.array([TABLE1]))[0]
    no_aux, a, b = np.empty((0, N_AUX)), np.empty(len(theta_cmd)), np.empty(len(theta_cmd))
    pair_args = (no_aux,) if "no_aux" in inspect.signature(simulate_lf2.py_func).parameters else ()
    runs = {"one run": lambda: simulate_lf(theta_cmd, row, a, no_aux),
            "an interleaved pair": lambda: simulate_lf2(theta_cmd, row, row, a, b, *pair_args)}  # fmt: skip
    for name, way in runs.items():
        print(f"6. the monitor, {name}: {spread(per_call(way, args.repeats, 50))} ms")
    switching_runs(args.repeats)
    filter_and_ranking(args.repeats)
    if hasattr(_jit, "LAZY_LINKING"):
        for mode in ("on", "off"):
            runs = np.array([[float(v) for v in fresh(LOADS_LAZY, mode)] for _ in range(args.repeats)])
            print(f"9. fresh process, lazy linking {mode}: the runtime {spread(list(runs[:, 0]))} ms, the twin's "
                  f"kernels {spread(list(runs[:, 1]))} ms, the search's {spread(list(runs[:, 2]))} ms")
    for mode in ("on", "off"):
        runs = [fresh(COLLECTOR, mode)[-4:] for _ in range(args.repeats)]
        counts = "/".join(str(int(np.median([int(r[g]) for r in runs]))) for g in (1, 2, 3))
        print(f"7. the collector in an identify process, the start's threshold {mode}: "
              f"{spread([float(r[0]) for r in runs])} ms, collections young/middle/full {counts} (medians)")



def switching_runs(repeats: int) -> None:
    """Item 8: the switching model's twin runs alone, in turn, on two threads, and side by side."""
    from concurrent.futures import ThreadPoolExecutor

    from emaphm.commands import Chirp
    from emaphm.identification.last_stage import SwitchingModel
    from emaphm.params import EmaParams

    model = SwitchingModel(EmaParams(), Chirp())
    k = np.array(TABLE1)
    runs = [functools.partial(m.simulate, k, noise=False, duration=1.0) for m in model.models]
    for run in runs:
        run()  # loaded
    for step, run in zip(model.steps, runs, strict=True):
        print(f"8. the twin at {step * 1e6:g} us, one run: {spread(per_call(run, repeats, 3))} ms")
    print(f"8. the three in turn: {spread(per_call(lambda: [r() for r in runs], repeats, 1))} ms")
    three = functools.partial(model.current, k, duration=1.0, workers=2)
    print(f"8. the three on two threads (SwitchingModel.current): {spread(per_call(three, repeats, 1))} ms")
    finest = runs[int(np.argmin(model.steps))]
    with ThreadPoolExecutor(2) as pool:
        pair = per_call(lambda: list(pool.map(lambda _: finest(), range(2))), repeats, 1)
    print(f"8. the finest step's run, two side by side on two threads: {spread(pair)} ms")




def filter_and_ranking(repeats: int) -> None:
    """Items 10 and 11: four currents filtered as two pairs and at once; the table's ranking on one
    numba thread and on two (where the tree has them)."""
    import numba

    from emaphm.identification import api, start_table
    from emaphm.identification.signals import comparison_filter
    from emaphm.kernels import fitness

    if hasattr(fitness, "sosfiltfilt_inplace4"):
        sos, zi, pad = comparison_filter(10_000.0)
        X = np.random.default_rng(0).normal(size=(4, 10_001 + 2 * pad)).cumsum(axis=1)
        A = X.copy()
        ways = {"two pairs": lambda: (fitness.sosfiltfilt_inplace(A[0], A[1], pad, sos, zi),
                                      fitness.sosfiltfilt_inplace(A[2], A[3], pad, sos, zi)),
                "four at once": lambda: fitness.sosfiltfilt_inplace4(A[0], A[1], A[2], A[3], pad, sos, zi)}  # fmt: skip
        for name, way in ways.items():
            print(f"10. the filter, 4 currents as {name}: {spread(per_call(way, repeats, 200), 1e6)} us")
    seen = []
    original = start_table.StartTable.ranked
    start_table.StartTable.ranked = lambda self, *a: seen.append((self, a)) or original(self, *a)
    try:
        api.identify(TABLE1, seed=1, uncertainty="none")
    finally:
        start_table.StartTable.ranked = original
    table, call = seen[0]
    threads = numba.get_num_threads()
    for n in (1, threads):
        numba.set_num_threads(n)
        print(f"11. the start table's ranking on {n} numba thread(s): {spread(per_call(lambda: original(table, *call), repeats, 20))} ms")
    numba.set_num_threads(threads)


if __name__ == "__main__":
    main()
