"""How many threads numba's parallel kernels (the LF population kernel) may use, and BLAS's one.

Inside `numba_threads` the BLAS library numpy and scipy call (OpenBLAS in their wheels) runs on
one thread. Its own thread pool otherwise wakes on every call (scipy's least squares, CMA-ES's
eigendecomposition) and keeps spinning while numba's pool runs the next kernel: on 2 cores the
two pools fight, and the least-squares polish took 0.56 s instead of 0.07 s (Table 1 case, the
same numbers). The matrices here are small (8 columns), so one BLAS thread loses nothing.
`threadpoolctl` sets and restores the limit; it reaches the BLAS libraries loaded when a
block is entered (numpy's, and scipy's, which `emaphm.identification` loads through
`scipy.optimize`). The limit is the process's, and threadpoolctl lets one thread at a time
control it (the others' calls do nothing): where several threads run blocks at once, those
other than the first may run beside BLAS's own pool, slower.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import TypeVar

from .errors import InputError

T = TypeVar("T")
R = TypeVar("R")


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
    try:
        with threadpool_limits(limits=1, user_api="blas"):
            yield
    finally:
        numba.set_num_threads(previous)


def thread_map(fn: Callable[[T], R], items: Sequence[T], workers: int) -> list[R]:
    """`fn` of each item, in order, side by side on up to `workers` Python threads (serially on
    one): for compiled kernels that release the GIL (`HighFidelityEma.simulate_batch`)."""
    threads = max(1, min(workers, len(items)))
    if threads == 1:
        return [fn(item) for item in items]
    with ThreadPoolExecutor(threads) as pool:
        return list(pool.map(fn, items))


def usable_cores() -> int:
    """The cores this process may run on (its affinity where the OS tells it, else the count)."""
    import os

    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
