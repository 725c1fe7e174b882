"""The search's kernels loaded while the twin measures (issue 36).

A fresh process loads each compiled kernel from numba's cache when it is first called: the
twin's with numba's own start, then, inside the search, the monitor's, the comparison filter's
and the fused fitness kernels' (10 ms on machine G since they load without their linking bitcode's
parse, `studies/step_timings.py` item 9). The twin's run that makes the measurement
(`recording.measurement`; 0.05 s per simulated second of the Table 1 case, `benchmarks/bench_hf.py`)
holds neither the interpreter nor numba's compiler (its kernel is ``nogil``) and keeps one core
busy while the other waited. So when the twin measures, its kernels are loaded first by a run over
`TWIN_SPAN_S`, the whole run goes on a thread, and meanwhile `load_search_kernels` loads the
search's by calls on a short synthetic recording through the same Python paths the search takes:
the same signatures, so the search loads nothing more (tests/identification/test_warm.py). Those
calls run on one numba thread: on two, numba's second worker took the core the twin's run needs
(the measurement 62 -> 51 ms in-process, BENCHMARKS.md, seventeenth session). Then it imports the
polishes' CMA-ES, as lean as the polish would (the twin's thread is one of emaphm's helpers,
`_threads.HELPER_THREADS`). The measurement and the search are unchanged: only when the loads
happen moves (0.959x the Table 1 case's time from the shell, BENCHMARKS.md, issue 36, sixteenth
session).
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from typing import TYPE_CHECKING, TypeVar

import numpy as np

from .._threads import HELPER_THREADS
from ..faults import HEALTHY

if TYPE_CHECKING:
    from ..models import MonitorEma

__all__ = ["LOAD_SPAN_S", "TWIN_SPAN_S", "load_search_kernels", "meanwhile"]

T = TypeVar("T")

LOAD_SPAN_S = 0.05  # the synthetic recording's span [s]: 500 samples at 10 kHz, the filter needs > 9
TWIN_SPAN_S = 0.002  # the twin's run that loads its kernels [s]


def load_search_kernels(monitor: MonitorEma) -> None:
    """Call, on a synthetic recording of `LOAD_SPAN_S` (a ramp of current), every kernel the search
    calls through its own Python path: the fused fitness and residual kernels (`Fitness`), the
    monitor's runs alone and as a population, and the comparison filter on one and on several
    signals. Their numbers are thrown away. Then import the polishes' CMA-ES (`cmaes.import_polish`),
    which the search's second stage would import: Python under the GIL, which the twin's compiled
    run beside it does not need."""
    import numba

    from .cmaes import import_polish

    threads = numba.get_num_threads()  # this thread's: the parallel kernels run on one here
    numba.set_num_threads(1)
    try:
        _load(monitor)
    finally:
        numba.set_num_threads(threads)
    import_polish()


def _load(monitor: MonitorEma) -> None:
    from .fitness import Fitness
    from .signals import Comparison

    t, _ = monitor.sample_grid(LOAD_SPAN_S)
    # any current that is not constant, writable as a measured one (a read-only array is another
    # signature); filtering it is the comparison filter's call on one signal
    comparison = Comparison.from_signal(t, np.array(t), monitor.params.controller.f_s)
    fitness = Fitness(comparison)
    K = np.array([HEALTHY, HEALTHY])
    fitness.of_monitor(monitor, K, duration=LOAD_SPAN_S)
    fitness.residuals_of_monitor(monitor, K, duration=LOAD_SPAN_S)
    monitor.simulate(HEALTHY, duration=LOAD_SPAN_S)
    monitor.simulate_many(K, duration=LOAD_SPAN_S, check=False)
    comparison.filtered(np.zeros((2, len(t))))


def meanwhile(work: Callable[[], T], other: Callable[[], None]) -> T:
    """`work()` on a thread while `other()` runs on this one; `work`'s result (or its exception,
    raised here once `other` is done)."""
    with ThreadPoolExecutor(1, thread_name_prefix=f"{HELPER_THREADS}measure") as pool:
        pending = pool.submit(work)
        other()
        return pending.result()
