"""HDF5 files (emaphm traces, plain datasets in nested groups) and MATLAB v7.3 ``.mat`` files.

A variable is a dataset reached by its path (``"group/ds"``). When the root holds a single group
(a MATLAB struct saved with ``-v7.3``), paths may start inside it. MATLAB stores arrays
transposed (an n×1 column as a 1×n dataset) and text as uint16 with ``MATLAB_class = "char"``:
vectors are squeezed, text is listed but not readable as a channel. MATLAB's internal groups
(``#refs#``, ``#subsystem#``) and struct *arrays* (object references) are not read: save those
with ``-v7`` or as plain vectors. A dataset's ``unit``/``units`` attribute is recorded.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ...errors import InputError
from ..limits import MAX_SAMPLES
from .base import Column, TreeSource, as_vector

__all__ = ["Hdf5Source"]

_INTERNAL = ("#refs#", "#subsystem#")


def _text(value: Any) -> str | None:
    if isinstance(value, bytes):
        return value.decode(errors="replace")
    if isinstance(value, str):
        return value
    return None


class Hdf5Source(TreeSource):
    """HDF5 or MATLAB v7.3 (see the module docstring); the file stays open until `close`."""

    thing = "dataset"

    def __init__(self, path: Path, fmt: str = "hdf5") -> None:
        import h5py

        self.path = path
        self.format = fmt
        try:
            self._file = h5py.File(path, "r")
        except Exception as exc:  # truncated or corrupt: h5py says OSError with a long text
            raise InputError(f"{path}: cannot read it as HDF5 ({_reason(exc)})") from None
        self._h5py = h5py

    def close(self) -> None:
        self._file.close()

    def _datasets(self) -> list[tuple[str, Any]]:
        found: list[tuple[str, Any]] = []

        def visit(name: str, obj: Any) -> None:
            if isinstance(obj, self._h5py.Dataset) and not name.startswith(_INTERNAL):
                found.append((name, obj))

        try:
            self._file.visititems(visit)
        except Exception as exc:
            raise InputError(f"{self.path}: cannot read it as HDF5 ({_reason(exc)})") from None
        return found

    def _matlab_class(self, ds: Any) -> str | None:
        return _text(ds.attrs.get("MATLAB_class"))

    def listing(self) -> list[dict[str, Any]]:
        out = []
        for name, ds in self._datasets():
            cls = self._matlab_class(ds)
            numeric = ds.dtype.kind in "biuf" and cls != "char" and "MATLAB_empty" not in ds.attrs
            entry: dict[str, Any] = {
                "name": name,
                "length": int(ds.size),
                "dtype": "char" if cls == "char" else str(ds.dtype),
                "numeric": numeric,
            }
            if ds.ndim > 1 and sum(d > 1 for d in ds.shape) > 1:
                entry["shape"] = list(ds.shape)
            unit = _text(ds.attrs.get("unit", ds.attrs.get("units")))
            if unit:
                entry["unit"] = unit
            out.append(entry)
        return out

    def _resolve(self, name: str) -> Any:
        f = self._file
        candidates = [name.strip("/")]
        groups = [k for k in f if k not in _INTERNAL and isinstance(f[k], self._h5py.Group)]
        others = [k for k in f if k not in _INTERNAL and not isinstance(f[k], self._h5py.Group)]
        if len(groups) == 1 and not others:
            candidates.append(f"{groups[0]}/{name.strip('/')}")
        for path in candidates:
            try:
                obj = f.get(path)
            except Exception:
                obj = None
            if obj is not None and isinstance(obj, self._h5py.Dataset):
                return obj
        return None

    def _column(self, name: str, ds: Any, where: str) -> Column:
        if self._matlab_class(ds) == "char":
            raise InputError(f"{where} is MATLAB text, not numbers")
        if ds.size > MAX_SAMPLES:  # refused before the data are read
            raise InputError(
                f"{where} has {ds.size:.3g} samples, more than {MAX_SAMPLES:.0e}: split the record"
            )
        try:
            raw = ds[()]
        except Exception as exc:  # truncated data: the header opened, the chunks are gone
            raise InputError(
                f"{self.path}: cannot read {name!r} ({_reason(exc)}): truncated or corrupt file"
            ) from None
        unit = _text(ds.attrs.get("unit", ds.attrs.get("units")))
        return Column(values=as_vector(raw, where), unit=unit or None)


def _reason(exc: BaseException) -> str:
    text = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
    return text[:160]
