"""Parquet files through pyarrow, an optional dependency (``pip install 'emaphm[data]'``).

Top-level columns are the variables; nulls become NaN; only the mapped columns are read.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import InputError
from ..limits import MAX_SAMPLES
from .base import Column, Source, as_vector

__all__ = ["ParquetSource"]


def _pyarrow_parquet() -> Any:
    try:
        import pyarrow.parquet as pq
    except ImportError:
        raise InputError("reading Parquet needs pyarrow: pip install 'emaphm[data]'") from None
    return pq


def _row(i: int) -> str:
    return f"row {i}"


class ParquetSource(Source):
    """A Parquet file (see the module docstring)."""

    format = "parquet"

    def __init__(self, path: Path) -> None:
        pq = _pyarrow_parquet()
        self.path = path
        try:
            self._file = pq.ParquetFile(path)
            self._schema = self._file.schema_arrow
        except Exception as exc:
            reason = (str(exc).splitlines() or [type(exc).__name__])[0][:160]
            raise InputError(f"{path}: cannot read it as Parquet ({reason})") from None

    def close(self) -> None:
        close = getattr(self._file, "close", None)
        if close is not None:
            close()

    def listing(self) -> list[dict[str, Any]]:
        import pyarrow as pa

        n = int(self._file.metadata.num_rows)
        out = []
        for field in self._schema:
            numeric = (
                pa.types.is_integer(field.type)
                or pa.types.is_floating(field.type)
                or pa.types.is_boolean(field.type)
            )
            out.append({"name": field.name, "length": n, "dtype": str(field.type), "numeric": numeric})
        return out

    def has(self, name: str) -> bool:
        return name in self._schema.names

    def read(self, names: Sequence[str]) -> dict[str, Column]:
        if int(self._file.metadata.num_rows) > MAX_SAMPLES:
            raise InputError(f"{self.path}: more than {MAX_SAMPLES:.0e} rows: split the record")
        try:
            table = self._file.read(columns=list(dict.fromkeys(names)))
        except Exception as exc:
            reason = (str(exc).splitlines() or [type(exc).__name__])[0][:160]
            raise InputError(f"{self.path}: cannot read the columns ({reason})") from None
        out = {}
        for name in names:
            chunked = table.column(name)
            where = f"{self.path}: column {name!r}"
            try:
                values = chunked.to_numpy(zero_copy_only=False)
            except Exception as exc:
                raise InputError(f"{where} cannot be read as numbers ({exc})".splitlines()[0]) from None
            if values.dtype == object:  # nulls in an integer column come back as objects
                values = np.array([np.nan if v is None else v for v in values], dtype=np.float64)
            out[name] = Column(values=as_vector(values, where), row=_row)
        return out
