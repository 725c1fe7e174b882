"""Versions of the packages that determine a result, for the records written with it."""

from __future__ import annotations

import platform
import sys

from ._version import __version__

__all__ = ["versions"]

# numpy: the random streams and the arithmetic; numba: the compiled kernels; pymoo and cma: the
# optimisers (cma runs pymoo's CMA-ES, also the identification's polish); scipy: the filters
DEPENDENCIES = ("numpy", "numba", "pymoo", "cma", "scipy")


def versions() -> dict[str, str]:
    """{"emaphm", "numpy", "numba", "pymoo", "cma", "scipy", "python"} → installed version: an
    imported package's own ``__version__`` (what runs), else its distribution's metadata (whose
    reader, importlib.metadata with the email package, was 10-15 ms of every diagnosis's start)."""
    out = {"emaphm": __version__}
    for name in DEPENDENCIES:
        loaded = getattr(sys.modules.get(name), "__version__", None)
        out[name] = loaded if isinstance(loaded, str) else _installed(name)
    out["python"] = platform.python_version()
    return out


def _installed(name: str) -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version(name)
    except PackageNotFoundError:
        return "not installed"
