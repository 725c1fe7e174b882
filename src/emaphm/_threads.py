"""How many threads numba's parallel kernels (the LF population kernel) may use."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

from .errors import InputError


@contextlib.contextmanager
def numba_threads(workers: int | None, *, name: str = "workers") -> Iterator[None]:
    """Use `workers` numba threads inside the block (None or 0: all); `name` is used in the error."""
    import numba

    available = int(numba.config.NUMBA_NUM_THREADS)  # type: ignore[attr-defined]
    if workers is not None and not 0 <= workers <= available:
        raise InputError(f"{name} must be 0..{available}, got {workers}")
    previous = numba.get_num_threads()
    numba.set_num_threads(workers or available)
    try:
        yield
    finally:
        numba.set_num_threads(previous)
