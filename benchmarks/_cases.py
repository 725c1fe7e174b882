"""What the benchmarks share: the machine line, case drawing, the twin's measurement of a case, the
identification budget flags, the summary lines; and every import of emaphm internals.

The benchmarks import emaphm's public API (`emaphm`, and the `__init__` of its subpackages) directly,
and everything else from here: when a module inside `src/emaphm` moves, only this file changes.
`benchmarks/` is each script's own folder, so it is first on `sys.path` and ``import _cases`` works
from ``python benchmarks/<script>.py`` and from the tests (which put the folder on the path).
"""

from __future__ import annotations

import argparse
import os
import platform
from typing import Any

import numba
import numpy as np
from _machine import cpu_model

import emaphm

# --- emaphm internals: the only place the benchmarks reach past the public API ------------------
from emaphm.actuator import load_params, resolve_params
from emaphm.calibration import params_hash
from emaphm.campaign.store import RESULT_COLUMNS
from emaphm.commands import SampledCommand
from emaphm.faults import random_faults
from emaphm.identification.calibrate import CALIBRATION_COMMANDS
from emaphm.identification.fitness import Fitness
from emaphm.identification.identify import SECOND_SEARCH_NRMSE, search_to_faults
from emaphm.identification.switching import LAST_STAGES, SwitchingModel
from emaphm.identification.uncertainty import covers, laplace, load_factors
from emaphm.kernels.monitor import N_AUX, simulate_lf, simulate_lf_many

__all__ = [
    "CALIBRATION_COMMANDS",
    "LAST_STAGES",
    "N_AUX",
    "RESULT_COLUMNS",
    "SECOND_SEARCH_NRMSE",
    "Fitness",
    "SampledCommand",
    "SwitchingModel",
    "add_budget",
    "budget",
    "budget_text",
    "covers",
    "draw_cases",
    "laplace",
    "load_factors",
    "load_params",
    "machine_line",
    "measure",
    "noise_seed_of",
    "params_hash",
    "progpy_model",
    "resolve_params",
    "search_to_faults",
    "simulate_lf",
    "simulate_lf_many",
    "spread",
]


def progpy_model() -> Any:
    """`emaphm.prognostics.progpy_model`, or None where ProgPy is not installed."""
    try:
        from emaphm.prognostics import progpy_model as module
    except emaphm.InputError:
        return None
    return module


# --- the machine ---------------------------------------------------------------------------------
def machine_line(what: str = "") -> str:
    """One line naming the code and the machine: emaphm, Python, numba, cores (usable), CPU; then `what`."""
    usable = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    line = (
        f"emaphm {emaphm.__version__}, Python {platform.python_version()}, numba {numba.__version__}, "
        f"{os.cpu_count()} cores ({usable} usable, {cpu_model()})"
    )
    return f"{line}; {what}" if what else line


# --- cases and their measurement -----------------------------------------------------------------
def draw_cases(n: int, seed: int, absent: float = 0.0) -> np.ndarray:
    """n random fault vectors in the DESIGN §7 ranges from `seed` (each fault but k7 healthy with
    probability `absent`): `emaphm.faults.random_faults`."""
    return random_faults(n, seed, absent=absent)


def noise_seed_of(seed: int) -> int:
    """The twin's noise seed that ``identify(true_faults=..., seed=seed)`` uses."""
    return int(np.random.SeedSequence(seed).spawn(2)[0].generate_state(1)[0])


def measure(
    k: np.ndarray, seed: int, twin: emaphm.HighFidelityEma | None = None, noise: bool = True
) -> emaphm.SimResult:
    """The twin's noisy measurement of fault vector k as ``emaphm identify --true-faults K --seed S`` makes it."""
    twin = twin if twin is not None else emaphm.HighFidelityEma()
    return twin.simulate(k, noise=noise, seed=noise_seed_of(seed))


# --- the identification's budget -----------------------------------------------------------------
def add_budget(parser: argparse.ArgumentParser) -> None:
    """--pop-size, --generations and --no-polish: the defaults are identify's; the smoke test shrinks them."""
    parser.add_argument("--pop-size", type=int, default=None, help="population (default: identify's)")
    parser.add_argument("--generations", type=int, default=None, help="generations (default: identify's)")
    parser.add_argument("--no-polish", action="store_true", help="no local polish (smoke runs only)")


def budget(args: argparse.Namespace) -> dict[str, Any]:
    """The keyword arguments of `emaphm.identify` that `add_budget`'s flags set."""
    return {"pop_size": args.pop_size, "generations": args.generations, "local_polish": not args.no_polish}


def budget_text(args: argparse.Namespace) -> str:
    """The budget as printed in a benchmark's first line."""
    if args.pop_size is None and args.generations is None and not args.no_polish:
        return "default budget"
    return f"pop {args.pop_size or 'default'} x {args.generations or 'default'} generations" + (
        ", no polish" if args.no_polish else ""
    )


# --- tables --------------------------------------------------------------------------------------
def spread(values: Any, scale: float = 1.0, unit: str = "", digits: int = 2) -> str:
    """'median M, p90 P, max X' of values x scale, each with `unit`."""
    v = scale * np.asarray(values, dtype=float)
    f = f"{{:.{digits}f}}{unit}"
    return f"median {f.format(np.median(v))}, p90 {f.format(np.percentile(v, 90))}, max {f.format(v.max())}"
