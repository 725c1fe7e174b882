"""pymoo's CMA-ES (the `cma` package), imported lean: the search's "cmaes" and the polish (`polish`)."""

from __future__ import annotations

import importlib
import sys
import threading
import types
import warnings
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["CMA_UNUSED_IMPORTS", "cmaes", "import_cmaes"]


def import_cmaes() -> Any:
    """pymoo's CMAES class, imported without what `cma` loads for features emaphm never uses.

    The `cma` package it wraps imports ``matplotlib.pyplot`` (``cma.s``, for its plots) and
    ``scipy.stats`` (``cma.fitness_models``, for surrogate models; it has a fallback of its own)
    when it is imported: 0.35 s and 0.46 s of every ``emaphm identify`` on machine A of
    BENCHMARKS.md. While `cma` is first imported, those of them not loaded yet are made
    unimportable (None in ``sys.modules``, which `cma` catches), then put back: anyone can import
    them afterwards, but in this process `cma`'s own plots stay unavailable and its surrogate
    models use its fallback. pymoo's CMAES imports pymoo's hypervolume (through its default
    termination), which imports `moocore` with its data sets, ``urllib.request`` and
    ``platformdirs`` (12 ms of every diagnosis on machine G, issue 36) for multi-objective
    indicators: while pymoo is imported, `moocore` is a stand-in (`_LazyMoocore`) whose functions
    import the real one when first called, so pymoo's indicators still work. Only when no other
    Python thread runs (another thread could import them meanwhile): the CLI calls this before
    its progress bar starts a thread.
    """
    if "cma" in sys.modules or threading.active_count() > 1:
        from pymoo.algorithms.soo.nonconvex.cmaes import CMAES

        return CMAES
    blocked = [name for name in CMA_UNUSED_IMPORTS if name not in sys.modules]
    for name in blocked:
        sys.modules[name] = None  # type: ignore[assignment]
    stand_in = None if "moocore" in sys.modules else _LazyMoocore("moocore")
    if stand_in is not None:
        sys.modules["moocore"] = stand_in
    # cma's "Could not import matplotlib.pyplot, therefore ``cma.plot()`` etc. is not available"
    warnings.filterwarnings("ignore", message="Could not import matplotlib", category=UserWarning)
    try:
        from pymoo.algorithms.soo.nonconvex.cmaes import CMAES
    finally:
        for name in blocked:
            if name in sys.modules and sys.modules[name] is None:
                del sys.modules[name]
        if stand_in is not None and sys.modules.get("moocore") is stand_in:
            del sys.modules["moocore"]
    return CMAES


class _LazyMoocore(types.ModuleType):
    """A stand-in for `moocore` while pymoo is imported (`import_cmaes`): ``from moocore import f``
    gives a function that imports the real `moocore` (no longer stood in for) and calls its f."""

    def __getattr__(self, name: str) -> Any:
        if name.startswith("__"):
            raise AttributeError(name)

        def forward(*args: Any, **kwargs: Any) -> Any:
            return getattr(importlib.import_module("moocore"), name)(*args, **kwargs)

        forward.__name__ = forward.__qualname__ = name
        return forward


# what `cma` imports at its own import for plots and surrogate models (`import_cmaes`)
CMA_UNUSED_IMPORTS = ("matplotlib", "matplotlib.pyplot", "scipy.stats")


def cmaes(x0: NDArray[np.float64], sigma: float, pop_size: int, generations: int) -> Any:
    CMAES = import_cmaes()
    # pymoo passes the generation budget on to the `cma` package only when the termination is a
    # bare MaximumGenerationTermination; give it explicitly, as it is combined with the early stop
    return CMAES(x0=x0, sigma=sigma, popsize=pop_size, restarts=0, maxiter=generations)
