"""emaphm's own modules byte-compiled once where Python is told not to write bytecode (issue 36).

Python writes a module's bytecode (``__pycache__/*.pyc``) the first time it imports it, and reads
it afterwards, unless ``PYTHONDONTWRITEBYTECODE`` is set (common in containers, and set on the
machines of BENCHMARKS.md). Then an install that pip did not compile (an editable one,
``pip install -e``, or a checkout on ``PYTHONPATH``) compiles emaphm's ~170 modules from source
in every process: 0.1 s of each ``emaphm identify`` on machine G (0.91x without it, 9 pairs). pip
compiles a regular install itself, whatever that variable says; the command line does the same
for emaphm's own folder, once: when Python would not write bytecode, the folder's first
module has none and the folder can be written. ``EMAPHM_NO_BYTECODE=1`` keeps it from writing.
Nothing else changes: Python reads bytecode whose source is newer as stale, as always.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

__all__ = ["OPT_OUT", "compile_package"]

OPT_OUT = "EMAPHM_NO_BYTECODE"
PACKAGE = Path(__file__).resolve().parent


def compile_package(package: Path = PACKAGE) -> bool:
    """Byte-compile `package` (every module below it) where Python would not and nobody did yet
    (the module docstring); whether it compiled. Errors are left to the imports, which compile
    in memory as before."""
    if not sys.dont_write_bytecode or os.environ.get(OPT_OUT, "") not in ("", "0"):
        return False
    import importlib.util

    marker = Path(importlib.util.cache_from_source(str(package / "__init__.py")))
    if marker.exists() or not os.access(marker.parent if marker.parent.exists() else package, os.W_OK):
        return False
    import compileall

    try:
        return bool(compileall.compile_dir(package, quiet=2, workers=1))
    except (OSError, ValueError):
        return False
