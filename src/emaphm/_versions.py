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
    """A distribution's installed version: from its ``<name>-<version>.dist-info`` folder's name
    where the first folder of ``sys.path`` that has one has exactly one (scipy's, which a
    diagnosis no longer imports: the metadata reader's import would be 12 ms of it), else from
    importlib.metadata."""
    found = _dist_info_version(name)
    if found is not None:
        return found
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version(name)
    except PackageNotFoundError:
        return "not installed"


def _dist_info_version(name: str) -> str | None:
    import os

    prefix = name.lower().replace("-", "_") + "-"
    for entry in sys.path:
        try:
            names = os.listdir(entry or ".")
        except OSError:
            continue
        found = [n[len(prefix) : -len(".dist-info")] for n in names if n.lower().startswith(prefix) and n.endswith(".dist-info")]
        if found:
            return found[0] if len(found) == 1 else None
    return None
