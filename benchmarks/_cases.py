"""What the benchmarks share: the machine line, case drawing, the twin's measurement of a case, the
identification budget flags, the summary lines; and every import of emaphm internals.

The benchmarks import emaphm's public API (`emaphm`, and the `__init__` of its subpackages) directly,
and everything else from here: when a module inside `src/emaphm` moves, only this file changes.
`benchmarks/` is each script's own folder, so it is first on `sys.path` and ``import _cases`` works
from ``python benchmarks/<script>.py`` and from the tests (which put the folder on the path).
"""

from __future__ import annotations

import argparse
import dataclasses
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
from emaphm.calibration.scenarios import CALIBRATION_COMMANDS
from emaphm.campaign.store import RESULT_COLUMNS
from emaphm.choices import LAST_STAGES
from emaphm.commands import SampledCommand
from emaphm.faults import random_faults
from emaphm.identification.detection import load_thresholds
from emaphm.identification.fitness import Fitness
from emaphm.identification.last_stage import SwitchingModel
from emaphm.identification.limits import SECOND_SEARCH_NRMSE
from emaphm.identification.problem import search_to_faults
from emaphm.identification.recording import split_seed
from emaphm.identification.settings import IdentifySettings
from emaphm.identification.uncertainty import covers, laplace, load_factors
from emaphm.kernels.monitor import N_AUX, simulate_lf, simulate_lf_many
from emaphm.tolerances import drawn_actuator

__all__ = [
    "CALIBRATION_COMMANDS",
    "LAST_STAGES",
    "N_AUX",
    "RESULT_COLUMNS",
    "SECOND_SEARCH_NRMSE",
    "Fitness",
    "SampledCommand",
    "SwitchingModel",
    "add_settings",
    "budget",
    "budget_text",
    "covers",
    "draw_cases",
    "drawn_actuator",
    "laplace",
    "load_factors",
    "load_params",
    "load_thresholds",
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
    """The twin's noise seed that ``identify(true_faults=..., seed=seed)`` uses (`split_seed`)."""
    return split_seed(seed)[0]


def measure(
    k: np.ndarray, seed: int, twin: emaphm.HighFidelityEma | None = None, noise: bool = True
) -> emaphm.SimResult:
    """The twin's noisy measurement of fault vector k as ``emaphm identify --true-faults K --seed S`` makes it."""
    twin = twin if twin is not None else emaphm.HighFidelityEma()
    return twin.simulate(k, noise=noise, seed=noise_seed_of(seed))


# --- the identification's settings -------------------------------------------------------------
BUDGET = ("pop_size", "generations", "polish")


def add_settings(parser: argparse.ArgumentParser, names: tuple[str, ...] = BUDGET) -> None:
    """Flags for these fields of `IdentifySettings` (its defaults, help and choices: the one list of
    the identification's options); the smoke tests shrink the budget with them."""
    fields = {f.name: f for f in dataclasses.fields(IdentifySettings)}
    for name in names:
        f = fields[name]
        f_help = f.metadata["help"].replace("%", "%%")  # argparse formats help strings with %
        flag = "--" + name.replace("_", "-")
        if f.type in (bool, "bool"):
            parser.add_argument(flag, action=argparse.BooleanOptionalAction, default=f.default, help=f_help)
        else:
            kind = {"int | None": int, "int": int, "str": str, "str | None": str}.get(str(f.type), str)
            parser.add_argument(flag, type=kind, default=f.default, choices=f.metadata["choices"], help=f_help)


def settings_of(args: argparse.Namespace, names: tuple[str, ...] = BUDGET) -> dict[str, Any]:
    """The keyword arguments of `emaphm.identify` that `add_settings`' flags set."""
    return {name: getattr(args, name) for name in names}


def budget(args: argparse.Namespace) -> dict[str, Any]:
    """The budget flags' keywords (`settings_of` for `BUDGET`)."""
    return settings_of(args, BUDGET)


def budget_text(args: argparse.Namespace) -> str:
    """The budget as printed in a benchmark's first line."""
    if args.pop_size is None and args.generations is None and args.polish:
        return "default budget"
    return f"pop {args.pop_size or 'default'} x {args.generations or 'default'} generations" + (
        ", no polish" if not args.polish else ""
    )


# --- tables --------------------------------------------------------------------------------------
def spread(values: Any, scale: float = 1.0, unit: str = "", digits: int = 2) -> str:
    """'median M, p90 P, max X' of values x scale, each with `unit`."""
    v = scale * np.asarray(values, dtype=float)
    f = f"{{:.{digits}f}}{unit}"
    return f"median {f.format(np.median(v))}, p90 {f.format(np.percentile(v, 90))}, max {f.format(v.max())}"
