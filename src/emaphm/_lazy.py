"""Names a package imports on first use (PEP 562), so that importing it stays cheap; a
dependency imported without the modules it loads for nothing (`imports_without`)."""

from __future__ import annotations

import contextlib
import importlib
import sys
import types
from collections.abc import Callable, Iterable, Iterator, Mapping
from typing import Any

__all__ = ["imports_without", "lazy_names"]


def lazy_names(
    package: str, where: Mapping[str, str], namespace: dict[str, Any]
) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """The `__getattr__` and `__dir__` of `package` whose public names `where` maps to the submodule
    (relative to it) that defines them; a name, once loaded, is kept in `namespace` (its globals)."""

    def __getattr__(name: str) -> Any:  # noqa: N807 (the PEP 562 hook's name)
        module = where.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(f".{module}", package), name)
        namespace[name] = value  # later lookups skip __getattr__
        return value

    def __dir__() -> list[str]:  # noqa: N807
        return sorted({*namespace, *where})

    return __getattr__, __dir__


@contextlib.contextmanager
def imports_without(blocked: Iterable[str], stand_ins: Mapping[str, types.ModuleType] | None = None) -> Iterator[None]:
    """While the block imports: each module of `blocked` not loaded yet unimportable (None in
    ``sys.modules``, which an optional import catches as ImportError), each of `stand_ins` not
    loaded yet stood in for by its object; afterwards both taken out again, so that anyone imports
    the real modules (what the block's imports bound keeps the stand-in). For a dependency's
    import that loads modules a command never uses (`identification.cmaes`, `_lean_numba`); the
    caller makes sure no other thread imports meanwhile."""
    absent = [name for name in blocked if name not in sys.modules]
    stood = {name: module for name, module in (stand_ins or {}).items() if name not in sys.modules}
    for name in absent:
        sys.modules[name] = None  # type: ignore[assignment]
    sys.modules.update(stood)
    try:
        yield
    finally:
        for name in absent:
            if name in sys.modules and sys.modules[name] is None:
                del sys.modules[name]
        for name, module in stood.items():
            if sys.modules.get(name) is module:
                del sys.modules[name]
