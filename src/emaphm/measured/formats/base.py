"""`Source` (an opened measured file) and `Column` (one variable read from it)."""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ...errors import InputError
from ..limits import MAX_SAMPLES

__all__ = ["Column", "Source", "as_vector", "sample_row"]


def sample_row(i: int) -> str:
    """How a sample is named in messages for formats without lines: ``sample 12``."""
    return f"sample {i}"


@dataclass(frozen=True)
class Column:
    """One variable as stored: raw samples (float64, file units) and what the file says about them.

    values : ndarray  the samples, 1-D float64 (NaN where the file has no value)
    time : ndarray or None  the variable's own time raster, when the file attaches one (file units)
    time_unit : str or None  the raster's unit as the file declares it, if it does
    raster : str or None  the raster's name (provenance)
    unit : str or None  the unit the file declares for the samples, if any
    row : callable  index → how the sample is named in messages (``line 12`` for CSV)
    """

    values: NDArray[np.float64]
    time: NDArray[np.float64] | None = None
    time_unit: str | None = None
    raster: str | None = None
    unit: str | None = None
    row: Callable[[int], str] = sample_row


def as_vector(data: Any, where: str) -> NDArray[np.float64]:
    """A 1-D float64 copy of numeric `data` (a MATLAB row or column vector is squeezed).

    `InputError` (naming `where`) for text, a matrix, or more than `MAX_SAMPLES` values.
    """
    arr = np.asarray(data)
    if arr.dtype.kind not in "biuf":
        raise InputError(f"{where} is not numeric (dtype {arr.dtype}); map a numeric vector")
    if arr.size > MAX_SAMPLES:
        raise InputError(f"{where} has {arr.size:.3g} samples, more than {MAX_SAMPLES:.0e}: split the record")
    if arr.ndim > 1:
        squeezed = arr.squeeze()
        if squeezed.ndim > 1:
            raise InputError(f"{where} is a {'x'.join(map(str, arr.shape))} array; map a single vector")
        arr = squeezed
    return np.array(np.atleast_1d(arr), dtype=np.float64)


class Source(ABC):
    """An opened measured file. Use as a context manager; `close` releases the file."""

    format: str
    path: Path

    @abstractmethod
    def listing(self) -> list[dict[str, Any]]:
        """The variables found: dicts with ``name``, ``length`` and ``dtype`` (JSON-ready)."""

    @abstractmethod
    def has(self, name: str) -> bool:
        """Whether `name` (a column, variable or ``/`` path) can be read."""

    @abstractmethod
    def read(self, names: Sequence[str]) -> dict[str, Column]:
        """Read the named variables (each must satisfy `has`)."""

    def names(self) -> list[str]:
        """The readable names, in file order (for messages)."""
        return [str(entry["name"]) for entry in self.listing() if entry.get("numeric", True)]

    def close(self) -> None:  # noqa: B027 - most sources hold nothing open
        """Release the file."""

    def __enter__(self) -> Source:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class TreeSource(Source):
    """A file of named variables reached by ``/`` paths (HDF5, MATLAB): `has` and `read` from
    `_resolve` (the variable of a path, or None) and `_column` (a resolved variable's `Column`)."""

    thing = "variable"  # the word in "no <thing> 'name'"

    @abstractmethod
    def _resolve(self, name: str) -> Any:
        """The variable at path `name`, or None."""

    @abstractmethod
    def _column(self, name: str, found: Any, where: str) -> Column:
        """The `Column` of a resolved variable; `where` names it in messages."""

    def has(self, name: str) -> bool:
        return self._resolve(name) is not None

    def read(self, names: Sequence[str]) -> dict[str, Column]:
        out = {}
        for name in names:
            found = self._resolve(name)
            if found is None:
                raise InputError(f"{self.path}: no {self.thing} {name!r}")
            out[name] = self._column(name, found, f"{self.path}: {name!r}")
        return out
