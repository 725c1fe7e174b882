"""The one decorator every kernel goes through, and where its compiled code is cached.

numba's on-disk cache stamps a cached function with its *own* source file only: after an edit
to `mechanics.py`, `hf_twin.simulate_hf` (which inlines `mechanics_step`) would keep running the
old machine code (numba issues #8396, #9563). emaphm's kernels therefore use their own cache
locator: the cache folder and every function's source stamp are keyed by one hash of *all*
kernel sources (`KERNEL_SOURCE_HASH`), so any edit to any kernel file recompiles every kernel.

The cache lives in ``$NUMBA_CACHE_DIR/emaphm-kernels-<hash>/<package>`` when the user set
``NUMBA_CACHE_DIR``, else in ``$XDG_CACHE_HOME/emaphm/numba-<hash>/<package>`` (``~/.cache/...``);
<package> is the importing package's name (numba's index records types by module name, so a
renamed copy of the package must not read this one's entries). When
no such folder can be written, the kernels compile in memory on every run (slower start, never
stale).

Loading a cached kernel: numba's `Cache.load_overload` first refreshes the whole target context,
importing every lowering registry numba has (linalg, random, typed containers, ...: about 0.4 s
of a diagnosis's start, issue 36), which only *compiling* needs; loading machine code needs the
runtime (NRT) initialised. emaphm's kernels therefore load through `QuickLoadCache`, which
initialises the runtime and nothing else; a compilation still refreshes the context itself
(numba's `CompilerBase.__init__`), so a cache miss, or any other jitted function, compiles as
before. Where numba's cache lacks the two methods it builds on, the kernels keep numba's own. A
load also runs without numba's events on LLVM's lock (`_llvm_lock_events_off`), which time a
compilation and cost a load about a tenth of its time.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any, TypeVar

from llvmlite.binding import ffi
from numba import config, njit
from numba.core import caching
from numba.core.runtime import rtsys

from ._linking import LAZY_LINKING, rebuild_lazily

F = TypeVar("F", bound=Callable[..., Any])

KERNEL_DIR = Path(__file__).resolve().parent


def kernel_source_hash(folder: Path = KERNEL_DIR) -> str:
    """SHA-256 over the names and contents of every ``*.py`` file in the kernel folder."""
    h = hashlib.sha256()
    for path in sorted(folder.glob("*.py")):
        h.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
    return h.hexdigest()


KERNEL_SOURCE_HASH = kernel_source_hash()


def kernel_cache_dir() -> Path:
    """The folder for this set of kernel sources (see the module docstring)."""
    key = KERNEL_SOURCE_HASH[:16]
    user_dir = getattr(config, "CACHE_DIR", "")  # NUMBA_CACHE_DIR, as numba read it
    if user_dir:
        return Path(user_dir) / f"emaphm-kernels-{key}"
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "emaphm" / f"numba-{key}"


def _writable(folder: Path) -> bool:
    try:
        folder.mkdir(parents=True, exist_ok=True)
        tempfile.TemporaryFile(dir=folder).close()
    except OSError:
        return False
    return True


class KernelCacheLocator(caching._CacheLocator):  # type: ignore[misc]
    """numba cache locator for the files in this folder: stamped by the hash of all of them."""

    def __init__(self, py_func: Any, py_file: str) -> None:
        self._py_file = py_file  # where numba's "Cannot cache" warning points (its locators' attribute)
        self._lineno = py_func.__code__.co_firstlineno
        # one sub-folder per importing package name: numba's index records types by module
        # name, so a renamed copy of the package (same sources) must not share its entries
        package = str(getattr(py_func, "__module__", "") or "").split(".", 1)[0] or "unknown"
        self._cache_path = str(kernel_cache_dir() / package)

    def get_cache_path(self) -> str:
        return self._cache_path

    def get_source_stamp(self) -> str:
        return KERNEL_SOURCE_HASH

    def get_disambiguator(self) -> str:
        return str(self._lineno)

    @classmethod
    def from_function(cls, py_func: Any, py_file: str) -> KernelCacheLocator | None:
        try:
            if Path(py_file).resolve().parent != KERNEL_DIR:
                return None  # not an emaphm kernel: numba's own locators decide
        except OSError:
            return None
        return cls(py_func, py_file)


# the class that lists numba's locators: CacheImpl in recent releases, _CacheImpl in older ones
_CACHE_IMPL: Any = getattr(caching, "CacheImpl", None) or getattr(caching, "_CacheImpl")  # noqa: B009
if KernelCacheLocator not in _CACHE_IMPL._locator_classes:
    _CACHE_IMPL._locator_classes.insert(0, KernelCacheLocator)

CACHE_ENABLED = _writable(kernel_cache_dir() / __name__.split(".", 1)[0])


class QuickLoadCache(caching.FunctionCache):  # type: ignore[misc]
    """numba's function cache, loading without the target context's refresh, without numba's
    events on LLVM's lock and without parsing the bitcode kept for linking (`_linking`; module
    docstring)."""

    def load_overload(self, sig: Any, target_context: Any) -> Any:
        with _llvm_lock_events_off():
            rtsys.initialize(target_context)  # what loaded machine code needs of the context
            with self._guard_against_spurious_io_errors():
                return self._load_overload(sig, target_context)

    def _load_overload(self, sig: Any, target_context: Any) -> Any:
        """numba's own, the function's library loaded by `_linking.rebuild_lazily`."""
        if not (LAZY_LINKING and self._enabled):
            return super()._load_overload(sig, target_context)
        data = self._cache_file.load(self._index_key(sig, target_context.codegen()))
        return None if data is None else rebuild_lazily(self._impl, target_context, data)


@contextlib.contextmanager
def _llvm_lock_events_off() -> Iterator[None]:
    """Without any callback on llvmlite's lock inside the block (`QuickLoadCache`'s loads).

    numba registers two (``numba.core.base._initialize_llvm_lock_event``) that broadcast a
    "numba:llvm_lock" event before and after every one of llvmlite's calls, so that a compilation
    can time its share of LLVM's lock; loading one cached kernel makes about 300 such calls, and
    the events were about a tenth of the loads' time (3 515 calls; the Table 1 case's eleven loads
    107 ms with them, 96 ms without on machine G, `studies/step_timings.py`, issue 36). All the lock's callbacks (numba's and any other's) are off in
    the block and put back afterwards, in their order. A load times nothing, and it runs under
    numba's compiler lock, so no dispatcher's compilation runs meanwhile; the one compilation
    inside the block, the runtime's first initialisation (NRT's functions), fires no events. Another
    thread's llvmlite call while the list changes (a finaliser) may see one event without its
    pair, which only a timer listening to these events would notice. Where llvmlite keeps the
    callbacks elsewhere than ``ffi.lib._lock._cblist``, nothing changes."""
    lock = getattr(getattr(ffi, "lib", None), "_lock", None)
    callbacks = list(getattr(lock, "_cblist", ()))
    for acquire, release in callbacks:
        ffi.unregister_lock_callback(acquire, release)
    try:
        yield
    finally:
        for acquire, release in callbacks:
            ffi.register_lock_callback(acquire, release)


QUICK_LOAD = all(
    hasattr(caching.FunctionCache, name)
    for name in ("_load_overload", "_guard_against_spurious_io_errors")
)


def _quick_load(dispatcher: Any) -> Any:
    """The dispatcher with `QuickLoadCache` as its cache (what ``cache=True`` would set up with
    numba's own `FunctionCache`, built here once instead of twice: 55 kernels' locators at import)."""
    if CACHE_ENABLED and QUICK_LOAD:
        dispatcher._cache = QuickLoadCache(dispatcher.py_func)
    return dispatcher


def jit(fn: F | None = None, *, parallel: bool = False, nogil: bool = False, inline: bool = False) -> Any:
    """``numba.njit`` with the project's settings; with `nogil` the compiled function releases
    the GIL, so Python threads run it side by side (`HighFidelityEma.simulate_batch`); with
    `inline` numba inlines it into its callers itself (``inline="always"``), where LLVM would
    keep a call that passes tuples (`monitor.lf_substep`: 131 ms for 96 runs against 82 ms).

    Compiled code is kept on disk between runs (in `kernel_cache_dir`, keyed by all
    kernel sources); ``error_model="numpy"`` drops the division-by-zero checks from the hot loops
    (the API validates the divisors, and the model layer checks outputs for NaN/inf);
    ``fastmath`` stays off so results are bit-reproducible.
    """
    options = {"inline": "always"} if inline else {}
    cache = CACHE_ENABLED and not QUICK_LOAD  # else `_quick_load` gives the dispatcher its cache
    decorator = njit(cache=cache, parallel=parallel, nogil=nogil, error_model="numpy", **options)

    def cached(f: F) -> Any:
        return _quick_load(decorator(f))

    return cached if fn is None else cached(fn)
