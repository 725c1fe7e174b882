"""Cached kernels loaded without parsing the LLVM module kept for linking (issue 36).

numba caches a compiled function as its machine code and, beside it, the LLVM bitcode of its
optimised module, which it parses whenever the function is loaded (``CPUCodeLibrary._unserialize``)
for two uses only: the names the module defines, entered in the execution engine's symbol table
(``JitEngine.is_symbol_defined``), and the module a later compilation links in when the function
it compiles calls this one (``_get_module_for_linking``). A diagnosis calls its kernels from
Python and compiles nothing after them, and the fused kernels' modules are large (the monitor and
the filter inlined): loading the search's kernels took 32 ms on machine G with the parses, 10 ms
without, the twin's 24 and 19 ms (`studies/step_timings.py` item 9).

`rebuild_lazily` loads a cached function's machine code as numba does and keeps its bitcode
unparsed. The library's class becomes a subclass whose ``_get_module_for_linking`` parses the
bitcode first; the engine's ``is_symbol_defined`` parses every library still pending before it
answers no; the one name numba looks up at once, the function's Python wrapper
(``CPUContext.get_executable``), is entered in the symbol table when its machine code is loaded,
as the parse would have entered it. Where numba's classes lack what this builds on, `LAZY_LINKING`
is false and numba's own loading runs.
"""

from __future__ import annotations

import functools
import weakref
from typing import Any

from llvmlite import binding as ll
from numba.core import caching, codegen

__all__ = ["LAZY_LINKING", "rebuild_lazily"]

BITCODE = "_emaphm_linking_bitcode"  # the attribute holding a library's unparsed bitcode
PENDING = "_emaphm_pending"  # the engine's attribute: its libraries whose bitcode is unparsed

LAZY_LINKING = (
    all(hasattr(codegen.CPUCodeLibrary, name) for name in (
        "_get_module_for_linking", "_finalize_final_module", "enable_object_caching", "_set_compiled_object"))
    and all(hasattr(codegen.JitEngine, name) for name in ("is_symbol_defined", "_load_defined_symbols"))
    and all(hasattr(caching.FunctionCache, name) for name in ("_index_key", "_load_overload"))
)  # fmt: skip


class _Lazy:
    """Mixed into a loaded library's class: its bitcode parsed when a compilation links it in."""

    def _get_module_for_linking(self) -> Any:
        _parse(self)
        return super()._get_module_for_linking()  # type: ignore[misc]


@functools.cache
def _lazy_class(cls: type) -> type:
    return type(f"Lazy{cls.__name__}", (_Lazy, cls), {"__module__": __name__})


def _parse(library: Any) -> None:
    """The library's bitcode parsed and its names entered, as numba's loading does."""
    bitcode = library.__dict__.pop(BITCODE, None)
    if bitcode is not None:
        library._shared_module = ll.parse_bitcode(bitcode)
        library._codegen._engine._load_defined_symbols(library._shared_module)


def _pending(engine: Any) -> weakref.WeakSet[Any]:
    """The engine's pending libraries; on first use its ``is_symbol_defined`` is wrapped so that a
    name it does not know is looked up again after every pending library is parsed."""
    pending = engine.__dict__.get(PENDING)
    if pending is None:
        pending = engine.__dict__[PENDING] = weakref.WeakSet()
        known = engine.is_symbol_defined

        def is_symbol_defined(name: str) -> bool:
            if known(name) or not pending:
                return known(name)
            for library in list(pending):
                _parse(library)
            pending.clear()
            return known(name)

        engine.is_symbol_defined = is_symbol_defined
    return pending


def _unserialize(codegen_: Any, wrapper: str, serialized: Any) -> Any:
    """numba's ``CPUCodeLibrary._unserialize`` for machine code, the bitcode kept unparsed."""
    name, kind, data = serialized
    if kind != "object" or not (isinstance(data, tuple) and len(data) == 2):
        return codegen_._library_class._unserialize(codegen_, serialized)
    object_code, bitcode = data
    library = codegen_.create_library(name)
    library.__class__ = _lazy_class(type(library))
    library.enable_object_caching()
    library._set_compiled_object(object_code)
    library._finalize_final_module()  # the machine code loaded
    setattr(library, BITCODE, bitcode)
    engine = codegen_._engine
    _pending(engine).add(library)
    engine._defined_symbols.add(wrapper)
    return library


def rebuild_lazily(impl: Any, target_context: Any, payload: tuple[Any, ...]) -> Any:
    """``impl.rebuild(target_context, payload)`` (numba's `CompileResult._rebuild` of a cached
    function) with its library loaded by `_unserialize`. Runs under numba's compiler lock, as every
    load does, so the codegen's loader is this load's alone while it is replaced."""
    wrapper = getattr(payload[1], "llvm_cpython_wrapper_name", None)
    if not isinstance(wrapper, str):
        return impl.rebuild(target_context, payload)
    gen = target_context.codegen()
    gen.unserialize_library = functools.partial(_unserialize, gen, wrapper)
    try:
        return impl.rebuild(target_context, payload)
    finally:
        del gen.unserialize_library
