"""The CMA-ES (the `cma` package, as pymoo 0.6.2 drives it), imported lean: the polishes
(`cmaes_minimize`, on arrays) and the search's "cmaes" (pymoo's `CMAES`, `cmaes`).

`cmaes_minimize` is ``minimize_batch(problem, cmaes(x0, σ, λ, G), G, ...)`` without pymoo's
object model: pymoo's CMAES evaluates x0 as its first generation, then sends each generation's
values to pymoo's own generator around `cma` (``pymoo.vendor.vendor_cmaes.my_fmin``, in the box
normalised to [0, 1]) and keeps the best point seen; its termination, generation log and optimum
are replayed on arrays (`ga.Termination`, `GenerationLog`). pymoo's `Algorithm`, `Population`
and display took about 10 ms of every diagnosis's imports and a few ms of bookkeeping per polish
(issue 36). Tested against pymoo's CMAES run by `minimize_batch` (tests/identification/
test_cmaes.py): the same point, value, evaluations and history to the bit.
"""

from __future__ import annotations

import contextlib
import importlib
import sys
import types
import warnings
from collections.abc import Iterator
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .._lazy import imports_without
from .._threads import others_run as _others_run
from .ga import Termination
from .optimizers import BatchProblem, GenerationLog, OnGeneration, Stagnation

__all__ = [
    "CMA_UNUSED_IMPORTS",
    "cma_seed",
    "cmaes",
    "cmaes_minimize",
    "import_cmaes",
    "import_polish",
]

# what `cma` imports at its own import for plots and surrogate models (`import_cmaes`)
CMA_UNUSED_IMPORTS = ("matplotlib", "matplotlib.pyplot", "scipy.stats")
# pymoo's CMAES options besides the population, the generations, the bounds and the seed
PYMOO_CMA_OPTIONS: dict[str, Any] = {
    "verbose": -9,
    "verb_log": 0,
    "maxfevals": np.inf,
    "tolfun": 1e-11,
    "tolx": 1e-11,
}


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
    ``platformdirs`` (14 ms on machine G, issue 36, `studies/step_timings.py`) for multi-objective indicators: while pymoo is
    imported, `moocore` is a stand-in (`_LazyMoocore`) whose functions import the real one when
    first called, so pymoo's indicators still work. Only when no other Python thread runs but
    emaphm's own helpers (`_threads.HELPER_THREADS`; another thread could import them meanwhile):
    the CLI calls this before its progress bar starts a thread.
    """
    with _lean_imports(moocore=True):
        from pymoo.algorithms.soo.nonconvex.cmaes import CMAES
    return CMAES


def import_polish() -> Any:
    """pymoo's generator around `cma` (``pymoo.vendor.vendor_cmaes.my_fmin``), which the polishes
    run (`cmaes_minimize`), imported lean as `import_cmaes` imports (14 ms on machine G the first
    time; `warm.load_search_kernels` imports it while the twin measures)."""
    with _lean_imports(moocore=False):
        from pymoo.vendor.vendor_cmaes import my_fmin
    return my_fmin


@contextlib.contextmanager
def _lean_imports(*, moocore: bool) -> Iterator[None]:
    """`CMA_UNUSED_IMPORTS` blocked and (with `moocore`) `moocore` stood in for while `cma` is
    first imported (`import_cmaes`); nothing once it is, or while a thread other than emaphm's
    helpers runs (`_others_run`)."""
    if "cma" in sys.modules or _others_run():
        yield
        return
    stand_ins = {"moocore": _LazyMoocore("moocore")} if moocore else {}
    # cma's "Could not import matplotlib.pyplot, therefore ``cma.plot()`` etc. is not available"
    warnings.filterwarnings("ignore", message="Could not import matplotlib", category=UserWarning)
    with imports_without(CMA_UNUSED_IMPORTS, stand_ins):
        yield


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


def cmaes(x0: NDArray[np.float64], sigma: float, pop_size: int, generations: int) -> Any:
    CMAES = import_cmaes()
    # pymoo passes the generation budget on to the `cma` package only when the termination is a
    # bare MaximumGenerationTermination; give it explicitly, as it is combined with the early stop
    return CMAES(x0=x0, sigma=sigma, popsize=pop_size, restarts=0, maxiter=generations)


def cma_seed(seed: int) -> int:
    """`seed` as `cma` can take it: `cma` seeds itself from the clock for 0 and numpy refuses
    2³² and above, so those become 1 + seed mod (2³² − 1); every other seed stays itself (the
    same runs as before). Without it a polish from seed 0 was not reproducible."""
    seed = int(seed)
    return seed if 0 < seed < 2**32 else 1 + seed % (2**32 - 1)


def cmaes_minimize(
    problem: BatchProblem,
    x0: NDArray[np.float64],
    sigma: float,
    pop_size: int,
    generations: int,
    *,
    seed: int,
    stagnation: Stagnation,
    on_generation: OnGeneration | None = None,
) -> tuple[NDArray[np.float64], float, list[float]]:
    """The CMA-ES from the point x0 with step `sigma` (in the box normalised to [0, 1]) and
    population `pop_size` on `problem` for at most `generations` (x0's evaluation the first; fewer
    when `stagnation` stops it or `cma` does): the best point (clipped to the box), its value and
    the best value per generation, as ``minimize_batch(problem, cmaes(...), generations, ...)``
    gives them (the module docstring) with `cma_seed`(seed) for the seed."""
    seed = cma_seed(seed)
    xl, xu = problem.xl, problem.xu
    span = xu - xl
    x_best = np.atleast_2d(np.asarray(x0, dtype=np.float64))  # pymoo's first population: x0
    f_best = float(problem.evaluate_batch(x_best)[0])
    termination, log = Termination(generations, stagnation), GenerationLog(generations, on_generation)
    options = {**PYMOO_CMA_OPTIONS, "popsize": pop_size, "maxiter": generations,
               "bounds": [np.zeros_like(xl), np.ones_like(xu)], "seed": seed}  # fmt: skip
    es = import_polish()(
        (x_best[0] - xl) / span, sigma, options=options, parallel_objective=True, restarts=0,
        restart_from_best="False", incpopsize=2, eval_initial_x=False, noise_handler=None,
        noise_change_sigma_exponent=1, noise_kappa_exponent=0, bipop=False,
        random_state=np.random.default_rng(seed),
    )  # fmt: skip
    asked = next(es)
    generation = 1
    termination.update(generation, f_best)
    log.record(generation, f_best)
    while not termination.done:
        generation += 1
        many = np.ndim(asked) > 1  # the final mean comes alone
        X = xl + np.atleast_2d(np.array(asked)) * span
        F = problem.evaluate_batch(X)
        i = int(np.argmin(F))
        if F[i] < f_best:  # pymoo's optimum: the first of the lowest, the older one on a tie
            x_best, f_best = X[i : i + 1], float(F[i])
        values = F.tolist()
        try:
            asked = es.send(values if many else values[0])
        except Exception:  # the generator's end (StopIteration) or error: pymoo's CMAES ends there too
            asked = None
        if asked is None:
            termination.forced = True
        termination.update(generation, f_best)
        log.record(generation, f_best)
    return np.clip(x_best[0], xl, xu), f_best, log.history
