"""MATLAB v4 and v5/v7 ``.mat`` files, read with ``scipy.io.loadmat(simplify_cells=True)``.

Variables and struct fields are reached by ``/`` paths (``"s/field"``); when the file holds a
single struct, paths may start inside it. A struct array whose elements carry a ``Name`` field is
a *list of channels* (Paderborn KAt: ``<stem>.Y`` with ``Name``, ``Raster``, ``Data``,
``Unit``): a path part selects the element by its ``Name`` and the element's ``Data`` is read. An
element with a ``Raster`` takes its time from the element of a sibling struct array (Paderborn's
``X``) with the same ``Raster``, whose ``Data`` holds the times (``Unit`` when given, else s)::

    t0 = { name = "Y/phase_current_1", unit = "A" }   # time from X(Raster == "HostService").Data
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ...errors import InputError
from .base import Column, TreeSource, as_vector

__all__ = ["MatSource"]


def _is_channel_list(node: Any) -> bool:
    return isinstance(node, list) and any(isinstance(e, dict) and "Name" in e for e in node)


def _name(element: dict[str, Any]) -> str:
    value = element.get("Name")
    return value if isinstance(value, str) else ""


def _as_list(node: Any) -> Any:
    """A struct array of one element comes back from simplify_cells as a bare dict."""
    return [node] if isinstance(node, dict) and "Name" in node and "Data" in node else node


class MatSource(TreeSource):
    """A MATLAB v4/v5/v7 file, loaded whole (scipy reads no part of a v5 file alone)."""

    def __init__(self, path: Path, fmt: str = "mat-v5") -> None:
        from scipy.io import loadmat

        self.path = path
        self.format = fmt
        try:
            data = loadmat(path, simplify_cells=True)
        except Exception as exc:  # truncated, corrupt, or not a .mat at all
            what = "MATLAB v4" if fmt == "mat-v4" else "MATLAB v5"
            reason = (str(exc).splitlines() or [type(exc).__name__])[0][:160]
            raise InputError(f"{path}: cannot read it as {what} ({reason})") from None
        self._root: dict[str, Any] = {k: v for k, v in data.items() if not k.startswith("__")}

    # -- the tree -----------------------------------------------------------------------------

    def _walk(self) -> list[tuple[str, Any]]:
        found: list[tuple[str, Any]] = []

        def visit(prefix: str, node: Any) -> None:
            node = _as_list(node)
            if isinstance(node, dict):
                if "Data" in node and not isinstance(node["Data"], (dict, list)):
                    found.append((prefix, node["Data"]))
                    return
                for key, child in node.items():
                    visit(f"{prefix}/{key}" if prefix else key, child)
            elif _is_channel_list(node):
                for k, element in enumerate(node):
                    if isinstance(element, dict):
                        visit(f"{prefix}/{_name(element) or k}", element)
            elif isinstance(node, list):
                for k, element in enumerate(node):
                    visit(f"{prefix}/{k}", element)
            else:
                found.append((prefix, node))

        visit("", self._root)
        return found

    def listing(self) -> list[dict[str, Any]]:
        out = []
        for name, value in self._walk():
            arr = np.asarray(value)
            numeric = arr.dtype.kind in "biuf"
            out.append({"name": name, "length": int(arr.size), "dtype": str(arr.dtype) if numeric else "text",
                        "numeric": numeric})  # fmt: skip
        return out

    def _resolve(self, name: str) -> tuple[Any, dict[str, Any] | None, Any] | None:
        """(value node, channel element or None, the element's parent struct) for a path."""
        parts = [p for p in name.strip("/").split("/") if p]
        starts = [self._root]
        structs = [v for v in self._root.values() if isinstance(v, dict)]
        if len(self._root) == 1 and structs:
            starts.append(structs[0])
        for start in starts:
            node: Any = start
            parent: Any = None
            element: dict[str, Any] | None = None
            for part in parts:
                node = _as_list(node)
                if isinstance(node, dict) and part in node:
                    parent, node = node, node[part]
                    element = None
                elif _is_channel_list(node) and any(_name(e) == part for e in node if isinstance(e, dict)):
                    element = next(e for e in node if isinstance(e, dict) and _name(e) == part)
                    node = element
                elif isinstance(node, list) and part.isdigit() and int(part) < len(node):
                    node = node[int(part)]
                    element = node if isinstance(node, dict) else None
                else:
                    break
            else:
                if isinstance(node, dict) and "Data" in node:
                    return node["Data"], node, parent
                if not isinstance(node, (dict, list)):
                    return node, None, parent
        return None

    def _column(self, name: str, found: Any, where: str) -> Column:
        value, element, parent = found
        column = Column(values=as_vector(value, where))
        if element is None:
            return column
        unit = element.get("Unit")
        raster = element.get("Raster")
        time, time_unit = (None, None)
        if isinstance(raster, str) and raster and isinstance(parent, dict):
            time, time_unit = self._raster(parent, raster, element, where)
        return Column(
            values=column.values, time=time, time_unit=time_unit, raster=raster if time is not None else None,
            unit=unit if isinstance(unit, str) and unit else None,
        )  # fmt: skip

    def _raster(
        self, parent: dict[str, Any], raster: str, element: dict[str, Any], where: str
    ) -> tuple[Any, str | None]:
        """The time vector of `raster` from a sibling struct array (Paderborn's X)."""
        for key, sibling in parent.items():
            sibling = _as_list(sibling) if not isinstance(sibling, list) else sibling
            if not isinstance(sibling, list) or any(e is element for e in sibling):
                continue
            for candidate in sibling:
                if isinstance(candidate, dict) and candidate.get("Raster") == raster and "Data" in candidate:
                    unit = candidate.get("Unit")
                    return as_vector(candidate["Data"], f"{self.path}: raster {raster!r} in {key!r}"), (
                        unit if isinstance(unit, str) and unit else None
                    )
        return None, None
