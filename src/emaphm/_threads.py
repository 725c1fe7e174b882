"""How many threads numba's parallel kernels (the LF population kernel) may use, and BLAS's one.

Inside `numba_threads` the BLAS library numpy and scipy call (OpenBLAS in their wheels) runs on
one thread. Its own thread pool otherwise wakes on every call (scipy's least squares, CMA-ES's
eigendecomposition) and keeps spinning while numba's pool runs the next kernel: on 2 cores the
two pools fight, and the least-squares polish took 0.56 s instead of 0.07 s (Table 1 case, the
same numbers). The matrices here are small (8 columns), so one BLAS thread loses nothing.
`threadpoolctl` sets and restores the limit; it reaches the BLAS libraries loaded when a
block is entered (numpy's), and those a module imported inside the block loads, where that
import is followed by `blas_loaded` (scipy's, which the polish loaded through `scipy.optimize`
until issue 36's tenth session; without the call, the Table 1 case took 0.5 s more wall and 1 s
more CPU; a diagnosis no longer imports scipy.optimize or scipy.linalg). The limit is the
process's, and threadpoolctl lets one thread at a time control it (the others' calls do
nothing): where several threads run blocks at once, those other than the first may run beside
BLAS's own pool, slower.
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import TypeVar

from .errors import InputError

T = TypeVar("T")
R = TypeVar("R")

# the name prefix of emaphm's own helper threads (`runtime_meanwhile`'s, `warm.meanwhile`'s), which
# import nothing `cmaes`'s lean import blocks: they do not keep that import from being lean
HELPER_THREADS = "emaphm-"

_OPEN = threading.local()  # .blocks: this thread's open numba_threads blocks, innermost last


@contextlib.contextmanager
def numba_threads(workers: int | None, *, name: str = "workers") -> Iterator[None]:
    """Use `workers` numba threads inside the block (None or 0: all), and one BLAS thread;
    `name` is used in the error."""
    import numba
    from threadpoolctl import threadpool_limits

    available = int(numba.config.NUMBA_NUM_THREADS)  # type: ignore[attr-defined]
    if workers is not None and not 0 <= workers <= available:
        raise InputError(f"{name} must be 0..{available}, got {workers}")
    previous = numba.get_num_threads()
    numba.set_num_threads(workers or available)
    blocks: list[contextlib.ExitStack] = _OPEN.__dict__.setdefault("blocks", [])
    try:
        with contextlib.ExitStack() as block:
            block.enter_context(threadpool_limits(limits=1, user_api="blas"))
            blocks.append(block)
            try:
                yield
            finally:
                blocks.pop()
    finally:
        numba.set_num_threads(previous)


def blas_loaded() -> None:
    """Inside a `numba_threads` block, give the BLAS libraries loaded since it was entered the
    block's one thread too, until it ends (outside a block: nothing). Call it after an import
    inside the block that may load one (module docstring)."""
    blocks = getattr(_OPEN, "blocks", None)
    if blocks:
        from threadpoolctl import threadpool_limits

        blocks[-1].enter_context(threadpool_limits(limits=1, user_api="blas"))


def thread_map(
    fn: Callable[[T], R], items: Sequence[T], workers: int, *, costs: Sequence[float] | None = None
) -> list[R]:
    """`fn` of each item, in order, side by side on up to `workers` Python threads (serially on
    one): for compiled kernels that release the GIL (`HighFidelityEma.simulate_batch`).

    With `costs` (one per item, any unit) the items are started costliest first and the results
    still come back in the items' order (the longest-processing-time rule). On 2 threads the
    switching model's runs at 2, 2.5 and 1.25 µs (`last_stage.SwitchingModel`; 36, 30 and 42 ms on
    the Table 1 case, machine E) then end after about 66 ms (42 beside 36 + 30), not 72 (30 + 42
    beside 36) in the given order."""
    threads = max(1, min(workers, len(items)))
    if threads == 1:
        return [fn(item) for item in items]
    order = list(range(len(items)))
    if costs is not None:
        if len(costs) != len(items):
            raise InputError(f"costs has {len(costs)} values for {len(items)} items")
        order.sort(key=lambda j: -costs[j])  # a stable sort: equal costs keep their order
    with ThreadPoolExecutor(threads) as pool:
        done = list(pool.map(fn, [items[j] for j in order]))
    out: list[R] = [None] * len(items)  # type: ignore[list-item]
    for j, result in zip(order, done, strict=True):
        out[j] = result
    return out


def usable_cores() -> int:
    """The cores this process may run on (its affinity where the OS tells it, else the count)."""
    import os

    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


def others_run() -> bool:
    """Whether a Python thread runs beside this one that is not one of emaphm's helpers."""
    me = threading.current_thread()
    return any(t is not me and not t.name.startswith(HELPER_THREADS) for t in threading.enumerate())


def runtime_meanwhile() -> threading.Thread:
    """Start initialising numba's runtime (NRT) on a daemon thread, and return the thread.

    The first kernel a process loads initialises the runtime first (`kernels._jit.QuickLoadCache`):
    numba compiles the runtime's own functions (its atomic reference counts), 17-25 ms on machine G,
    most of it inside LLVM, whose calls (through ctypes) release the GIL. A command that will load
    kernels starts this as soon as numba is imported, so that the compilation runs while the
    command's own thread imports the rest (issue 36). The initialisation is numba's own: it holds
    numba's compiler lock (a kernel load that comes first waits for it) and does nothing when
    called again. An error here is left to that first load, which initialises again and raises it
    where it belongs. The target context is made on the calling thread first (a command imports
    numba lean before, `_lean_numba.import_numba`)."""
    from numba.core.registry import cpu_target
    from numba.core.runtime import rtsys

    context = cpu_target.target_context

    def initialise() -> None:
        with contextlib.suppress(Exception):
            rtsys.initialize(context)

    thread = threading.Thread(target=initialise, name=f"{HELPER_THREADS}runtime", daemon=True)
    thread.start()
    return thread
