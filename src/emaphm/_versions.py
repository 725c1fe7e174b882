"""Versions of the packages that determine a result, for the records written with it."""

from __future__ import annotations

import platform
from importlib.metadata import PackageNotFoundError, version

from ._version import __version__

__all__ = ["versions"]

# numpy: the random streams and the arithmetic; numba: the compiled kernels; pymoo and cma: the
# optimisers (cma runs pymoo's CMA-ES, also the identification's polish); scipy: the filters
DEPENDENCIES = ("numpy", "numba", "pymoo", "cma", "scipy")


def versions() -> dict[str, str]:
    """{"emaphm", "numpy", "numba", "pymoo", "cma", "scipy", "python"} → installed version."""
    out = {"emaphm": __version__}
    for name in DEPENDENCIES:
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            out[name] = "not installed"
    out["python"] = platform.python_version()
    return out
