"""Readers of measured files, chosen by content (magic bytes) before the suffix (next-features §D.3).

====================  ==============================================  =====================
format                recognised by                                   reader
====================  ==============================================  =====================
HDF5                  ``\\x89HDF\\r\\n\\x1a\\n`` at 0 (or a user block)   `hdf5file` (h5py)
MATLAB v7.3           text ``MATLAB 7.3 MAT-file``, HDF5 at 512         `hdf5file` (h5py)
MATLAB v5/v7          text ``MATLAB 5.0 MAT-file``                      `matfile` (scipy)
MATLAB v4             suffix ``.mat``, no header                        `matfile` (scipy)
Parquet               ``PAR1``                                          `parquetfile` (pyarrow)
CSV                   anything else that is text                        `csvfile`
====================  ==============================================  =====================

Every reader is a `Source`: ``listing()`` describes the variables (name, length, dtype),
``has(name)`` and ``read(names)`` give `Column` objects with the raw samples (float64, file
units), the channel's own time raster when the file carries one, and a unit when the file declares
one. Malformed content raises `InputError` naming the file and the variable or row.
"""

from __future__ import annotations

import os
from pathlib import Path

from ...errors import InputError
from .base import Column, Source

__all__ = ["FORMATS", "Column", "Source", "open_source", "sniff"]

HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
FORMATS = ("hdf5", "mat-v7.3", "mat-v5", "mat-v4", "parquet", "csv")
_HEAD = 2048


def sniff(path: str | os.PathLike[str]) -> str:
    """The format of `path` from its first bytes (and the suffix for MATLAB v4), one of `FORMATS`.

    `InputError` for a missing, empty or unreadable file and for binary content of no known format.
    """
    p = Path(path)
    if p.is_dir():
        raise InputError(f"{p}: is a folder, not a measurement file")
    if not p.is_file():
        raise InputError(f"{p}: no such file")
    try:
        with p.open("rb") as fh:
            head = fh.read(_HEAD)
    except OSError as exc:
        raise InputError(f"{p}: cannot read it ({exc.strerror or exc})") from None
    if not head:
        raise InputError(f"{p}: the file is empty")
    if head.startswith(b"MATLAB 7.3 MAT-file"):
        return "mat-v7.3"
    if any(head[k : k + 8] == HDF5_SIGNATURE for k in (0, 512, 1024)):
        return "hdf5"
    if head.startswith(b"MATLAB 5.0 MAT-file"):
        return "mat-v5"
    if head.startswith(b"PAR1"):
        return "parquet"
    if p.suffix.lower() == ".mat":
        return "mat-v4"
    if b"\0" in head:
        raise InputError(
            f"{p}: unknown format: binary content that is not HDF5, MATLAB .mat or Parquet (CSV must be text)"
        )
    return "csv"


def open_source(path: str | os.PathLike[str]) -> Source:
    """Open `path` with the reader its content asks for (see the module docstring)."""
    p = Path(path)
    fmt = sniff(p)
    if fmt in ("hdf5", "mat-v7.3"):
        from .hdf5file import Hdf5Source

        return Hdf5Source(p, fmt)
    if fmt in ("mat-v5", "mat-v4"):
        from .matfile import MatSource

        return MatSource(p, fmt)
    if fmt == "parquet":
        from .parquetfile import ParquetSource

        return ParquetSource(p)
    from .csvfile import CsvSource

    return CsvSource(p)
