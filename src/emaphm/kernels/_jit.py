"""The one decorator every kernel goes through."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar

from numba import njit

F = TypeVar("F", bound=Callable[..., Any])


def jit(fn: F | None = None, *, parallel: bool = False) -> Any:
    """``numba.njit`` with the project's settings.

    ``cache=True`` keeps compiled code on disk between runs; ``error_model="numpy"`` drops the
    division-by-zero checks from the hot loops (the API validates the divisors); ``fastmath`` stays
    off so results are bit-reproducible.
    """
    decorator = njit(cache=True, parallel=parallel, error_model="numpy")
    return decorator if fn is None else decorator(fn)
