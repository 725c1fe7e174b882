"""CSV text: what is accepted.

- optional comment lines starting with ``#`` before the header, and a logger's preamble: lines
  before the header whose number of fields is not the data's (`preamble` counts them);
- one header row of column names (quotes and surrounding spaces are stripped);
- delimiter ``,``, ``;`` or tab, whichever the header row holds most of;
- optionally one units row right after the header: every cell non-numeric (``A``, ``[mA]``,
  ``(deg)``); its units are recorded and compared with the map's, never used instead of them;
- data rows of numbers (``.`` as decimal point; ``,`` is also accepted with ``;`` or tab
  delimiters); an empty cell or ``nan``/``NA`` is a missing value (NaN, which splits the record
  into segments); anything else non-numeric in a mapped column is refused naming its line.

Columns that are not mapped are never parsed (a text timestamp column does no harm).
"""

from __future__ import annotations

import csv
import math
import re
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import InputError
from ..limits import MAX_SAMPLES
from .base import Column, Source

__all__ = ["CsvSource"]

DELIMITERS = (",", ";", "\t")
MISSING = {"", "nan", "NaN", "NAN", "NA", "N/A", "-nan"}
_SNIFF_LINES = 200


def _number(cell: str) -> float | None:
    try:
        return float(cell)
    except ValueError:
        return None


def _cells(line: str, delimiter: str) -> list[str]:
    """The cells of one row, stripped of spaces and quotes, without a trailing empty one."""
    cells = [c.strip().strip('"') for c in next(csv.reader([line.rstrip("\r\n")], delimiter=delimiter))]
    return cells[:-1] if len(cells) > 1 and not cells[-1] else cells  # a trailing delimiter


def _numeric(cell: str) -> bool:
    """A number (``.`` or ``,`` as the decimal point) or a missing value."""
    return cell in MISSING or _number(cell) is not None or _number(cell.replace(",", ".")) is not None


def _bare_unit(cell: str) -> str:
    """A units-row cell without its brackets: ``[mA]`` and ``(deg)`` are ``mA`` and ``deg``."""
    return re.sub(r"^[\[(](.*)[\])]$", r"\1", cell)


def _data_delimiter(line: str) -> str | None:
    """The delimiter that makes `line` a row of numbers (or missing values) in two fields or more."""
    for delimiter in sorted(DELIMITERS, key=line.count, reverse=True):
        cells = _cells(line, delimiter)
        if len(cells) >= 2 and all(_numeric(c) for c in cells):
            return delimiter
    return None


def _looks_like_units(line: str, delimiter: str) -> bool:
    """Every cell a unit of the closed table (or ``-``), bare or in brackets: a units row."""
    from ...units import UNITS

    known = {u for table in UNITS.values() for u in table} | {"-", "rev", "kA", "counts", "V", "mm"}
    return all(_bare_unit(c) in known for c in _cells(line, delimiter))


def _past_preamble(head: list[str], k: int) -> tuple[int, int]:
    """(the header's index, the number of preamble lines before it), from the first non-comment line k.

    Of the lines with as many fields as the first data row that come right before it, the header
    is the last one, or the one before it when that last one is a units row; the lines before the
    header that are not comments are a logger's preamble. Without a data row in the first lines,
    or with the header first, k itself.
    """
    rows = [i for i in range(k, len(head)) if head[i].strip() and not head[i].lstrip().startswith("#")]
    found = next(((i, d) for i in rows if (d := _data_delimiter(head[i])) is not None), None)
    if found is None or found[0] == rows[0]:
        return k, 0
    first, delimiter = found
    width = len(_cells(head[first], delimiter))
    before = [i for i in rows if i < first]
    block = []
    for i in reversed(before):
        if len(_cells(head[i], delimiter)) != width or len(block) == 2:
            break
        block.insert(0, i)
    if not block:  # no line before the data has its width: no header to find
        return k, 0
    header = block[0] if len(block) == 2 and _looks_like_units(head[block[1]], delimiter) else block[-1]
    return header, before.index(header)


class CsvSource(Source):
    """A CSV file with a header row (see the module docstring)."""

    format = "csv"

    def __init__(self, path: Path) -> None:
        self.path = path
        try:
            with path.open(encoding="utf-8-sig", newline="") as fh:
                head = [line for _, line in zip(range(_SNIFF_LINES), fh, strict=False)]
        except UnicodeDecodeError:
            raise InputError(
                f"{path}: unknown format: not UTF-8 text, HDF5, MATLAB .mat or Parquet"
            ) from None
        except OSError as exc:
            raise InputError(f"{path}: cannot read it ({exc.strerror or exc})") from None
        k = 0
        while k < len(head) and (not head[k].strip() or head[k].lstrip().startswith("#")):
            k += 1
        if k == len(head):
            raise InputError(f"{path}: the file is empty (no header row)")
        k, self.preamble = _past_preamble(head, k)
        header = head[k].rstrip("\r\n")
        self.delimiter = max(DELIMITERS, key=header.count)
        self.columns = [
            c.strip().strip('"').strip("'").strip()
            for c in next(csv.reader([header], delimiter=self.delimiter))
        ]
        if len(set(self.columns)) != len(self.columns):
            dup = sorted({c for c in self.columns if self.columns.count(c) > 1})
            raise InputError(f"{path}: line {k + 1}: duplicated column name(s) {', '.join(map(repr, dup))}")
        self.header_line = k + 1  # 1-based line numbers in messages
        self.units: dict[str, str] = {}
        self.first_data_line = self.header_line + 1
        rest = [line for line in head[k + 1 :] if line.strip() and not line.lstrip().startswith("#")]
        if rest:
            cells = _cells(rest[0], self.delimiter)
            if cells and all(c and not _numeric(c) for c in cells):
                self.units = {name: _bare_unit(c) for name, c in zip(self.columns, cells, strict=False)}
                self.first_data_line = head.index(rest[0], k + 1) + 2
        self._cache: dict[str, Column] = {}

    def listing(self) -> list[dict[str, Any]]:
        n = self._row_count()
        return [
            {"name": c, "length": n, "dtype": "text" if c in self._text_columns() else "float64",
             "numeric": c not in self._text_columns(), **({"unit": self.units[c]} if c in self.units else {})}
            for c in self.columns
        ]  # fmt: skip

    def has(self, name: str) -> bool:
        return name in self.columns

    def read(self, names: Sequence[str]) -> dict[str, Column]:
        todo = [n for n in dict.fromkeys(names) if n not in self._cache]
        if todo:
            data = self._parse([self.columns.index(n) for n in todo])
            if data.shape[0] == 0:
                raise InputError(f"{self.path}: the file has a header but no data rows")
            if data.shape[0] > MAX_SAMPLES:
                raise InputError(
                    f"{self.path}: {data.shape[0]:.3g} rows, more than {MAX_SAMPLES:.0e}: split the record"
                )
            for j, name in enumerate(todo):
                self._cache[name] = Column(
                    values=np.ascontiguousarray(data[:, j]), unit=self.units.get(name), row=self._line
                )
        return {n: self._cache[n] for n in names}

    # -- parsing ------------------------------------------------------------------------------

    def _parse(self, usecols: list[int]) -> np.ndarray:
        """Fast path numpy; on any complaint, the slow path finds the cell and says where."""
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # "input contained no data": said by the caller
                data = np.loadtxt(
                    self.path, delimiter=self.delimiter, skiprows=self.first_data_line - 1, usecols=usecols,
                    ndmin=2, comments="#", quotechar='"', encoding="utf-8-sig", dtype=np.float64,
                )  # fmt: skip
            if data.shape[0] == self._data_line_count(check_widths=True):
                return data
        except ValueError:  # a bad cell, an empty cell, a decimal comma, a short row, not UTF-8
            pass
        try:
            return self._parse_slow(usecols)
        except UnicodeDecodeError as exc:
            raise InputError(
                f"{self.path}: not UTF-8 text at byte {exc.start}: save the CSV as UTF-8"
            ) from None

    def _data_lines(self):  # type: ignore[no-untyped-def]
        with self.path.open(encoding="utf-8-sig", newline="") as fh:
            for lineno, line in enumerate(fh, start=1):
                if lineno < self.first_data_line or not line.strip() or line.lstrip().startswith("#"):
                    continue
                yield lineno, line

    def _data_line_count(self, *, check_widths: bool = False) -> int:
        """The data rows; with `check_widths`, `InputError` for a row with more or fewer fields
        than the header (numpy's reader takes the mapped columns of a shifted row as they come)."""
        if not check_widths:
            return sum(1 for _ in self._data_lines())
        n, width, delim = 0, len(self.columns), self.delimiter
        for lineno, line in self._data_lines():
            n += 1
            text = line.rstrip("\r\n")
            fields = len(next(csv.reader([text], delimiter=delim))) if '"' in text else text.count(delim) + 1
            if fields == width + 1 and text.endswith(delim):
                fields -= 1  # a trailing delimiter
            if fields != width:
                raise InputError(f"{self.path}: line {lineno} has {fields} fields, the header has {width}")
        return n

    def _parse_slow(self, usecols: list[int]) -> np.ndarray:
        rows: list[list[float]] = []
        decimal_comma = self.delimiter != ","
        width = max(usecols) + 1
        for lineno, line in self._data_lines():
            cells = next(csv.reader([line.rstrip("\r\n")], delimiter=self.delimiter))
            if len(cells) == len(self.columns) + 1 and not cells[-1].strip():
                cells = cells[:-1]  # a trailing delimiter
            if len(cells) != len(self.columns) or len(cells) < width:  # a shifted row: never read
                raise InputError(
                    f"{self.path}: line {lineno} has {len(cells)} fields, the header has {len(self.columns)}"
                )
            row = []
            for j in usecols:
                cell = cells[j].strip().strip('"').strip()
                value = math.nan if cell in MISSING else _number(cell)
                if value is None and decimal_comma:
                    value = _number(cell.replace(",", "."))
                if value is None:
                    raise InputError(
                        f"{self.path}: line {lineno}, column {self.columns[j]!r}: {cell[:40]!r} is not a number"
                    )
                row.append(value)
            rows.append(row)
        return np.array(rows, dtype=np.float64).reshape(len(rows), len(usecols))

    def _line(self, i: int) -> str:
        """Line number (1-based, in the file) of data row i: for messages, counted only then."""
        for k, (lineno, _) in enumerate(self._data_lines()):
            if k == i:
                return f"line {lineno}"
        return f"data row {i}"

    def _row_count(self) -> int:
        if not hasattr(self, "_n_rows"):
            self._n_rows = self._data_line_count()
        return self._n_rows

    def _text_columns(self) -> set[str]:
        """Columns whose first data row is not a number (listing only)."""
        if not hasattr(self, "_text"):
            self._text: set[str] = set()
            for _, line in self._data_lines():
                cells = next(csv.reader([line.rstrip("\r\n")], delimiter=self.delimiter))
                for name, cell in zip(self.columns, cells, strict=False):
                    c = cell.strip().strip('"')
                    if c not in MISSING and _number(c) is None and _number(c.replace(",", ".")) is None:
                        self._text.add(name)
                break
        return self._text
