"""numba imported without what its import loads for nothing in a diagnosis (issue 36).

numba's own import loads scipy, only to check its version (numba needs none of it until a kernel
using scipy's LAPACK compiles); yaml, to read a config file (`NUMBA_CONFIG_FILE`) that is not
there; and ``importlib.metadata`` with the email package, for its extension entry points, whose
scan (`entry_points()` over every installed distribution) the first call of any compiled function
then runs. On machine G the first two were 16-19 ms of a diagnosis's start, the metadata's import
and scan about 15 ms more.

`import_numba` blocks scipy and yaml while numba imports (None in ``sys.modules``, which numba
catches; importable afterwards), stands in for ``importlib.metadata`` (`_LazyModule`: the real
module is imported when numba first uses it), and, where no installed distribution declares a
numba extension (`extensions_declared`), tells numba its extensions are loaded: there are none,
which is what numba's own scan would have found. Where one is declared, numba scans and loads as
always.
"""

from __future__ import annotations

import importlib
import os
import sys
import types
from typing import Any

from ._lazy import imports_without
from ._threads import others_run

__all__ = ["NUMBA_CONFIG_FILE", "NUMBA_UNUSED_IMPORTS", "extensions_declared", "import_numba"]

NUMBA_UNUSED_IMPORTS = ("scipy", "yaml")
NUMBA_CONFIG_FILE = ".numba_config.yaml"  # numba.core.config's _config_fname, read from the working folder
METADATA = "importlib.metadata"
EXTENSIONS_GROUP = b"numba_extensions"  # numba.core.entrypoints.init_all's entry-point group


def import_numba() -> None:
    """Import numba lean (the module docstring). A plain import once numba is imported, or while
    a thread other than emaphm's helpers runs (it could import the blocked modules meanwhile).
    yaml stays importable when the working folder has numba's config file, which numba then reads
    as always."""
    if "numba" in sys.modules or others_run():
        importlib.import_module("numba")
        return
    unused = [n for n in NUMBA_UNUSED_IMPORTS if not (n == "yaml" and os.path.isfile(NUMBA_CONFIG_FILE))]
    with imports_without(unused, {METADATA: _LazyModule(METADATA)}):
        importlib.import_module("numba")
    entrypoints = sys.modules.get("numba.core.entrypoints")
    if entrypoints is not None and hasattr(entrypoints, "_already_initialized") and not extensions_declared():
        entrypoints._already_initialized = True  # nothing to load: numba's scan would find none


def extensions_declared(path: list[str] | None = None) -> bool:
    """Whether a distribution installed on `path` (default ``sys.path``) may declare a numba
    extension: "numba_extensions" in the entry_points.txt of one of its ``*.dist-info`` or
    ``*.egg-info`` folders. True where that cannot be told by reading folders (a zip on the path)."""
    for entry in sys.path if path is None else path:
        folder = entry or "."
        if os.path.isfile(folder):
            return True
        try:
            names = os.listdir(folder)
        except OSError:
            continue
        for name in names:
            if not name.endswith((".dist-info", ".egg-info")):
                continue
            try:
                with open(os.path.join(folder, name, "entry_points.txt"), "rb") as f:
                    if EXTENSIONS_GROUP in f.read():
                        return True
            except OSError:
                continue
    return False


class _LazyModule(types.ModuleType):
    """A stand-in for a module while numba imports: its first attribute asked for imports the real
    module (no longer stood in for) and gives that module's attribute."""

    def __getattr__(self, name: str) -> Any:
        if name.startswith("__"):
            raise AttributeError(name)
        if sys.modules.get(self.__name__) is self:
            del sys.modules[self.__name__]
        return getattr(importlib.import_module(self.__name__), name)
