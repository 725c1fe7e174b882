"""The settings of one identification, in one frozen object (`IdentifySettings`).

One list of the identification's options, used by the API (`emaphm.identify(..., settings=)` or
its keywords), `FaultIdentifier`, the CLI (``emaphm identify``'s options are made from the
fields' metadata), campaigns (the ``[identify]`` table) and benchmarks. Defaults and checks live
here and nowhere else; a result records its settings (`IdentifySettings.to_json`) beside the
tuned constants of the stages (`identification.limits`).

Numpy-free, so that the CLI builds its options without loading the numerical stack.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from ..choices import LAST_STAGES, MONITORS, OPTIMIZERS, SLOPE_UNITS, STARTS, UQ_METHODS
from ..errors import InputError

__all__ = ["IdentifySettings", "budget_text", "parse_error_corner", "search_progress_label"]

MAX_SEED = 2**63 - 1


def _option(
    default: Any, help: str, *, flag: str | None = None, cli: bool = True, choices: Any = None
) -> Any:
    """A settings field: its default, the one-line help of its CLI option (`flag`, default
    ``--name-with-dashes``; `cli` False: API and campaign files only) and its choices."""
    return field(default=default, metadata={"help": help, "flag": flag, "cli": cli, "choices": choices})


@dataclass(frozen=True)
class IdentifySettings:
    """How an identification runs (every field checked when the object is made).

    Parameters
    ----------
    optimizer : {"ga", "de", "pso", "cmaes", "gwo", "multistart"}
        The global search (the paper's GA by default; `identification.search`). "multistart"
        (`identification.multistart`): a Latin-hypercube sample and least-squares descents from
        its best points, a third of the monitor runs but less robust (screening).
    start : {"random", "table", "auto"}
        The GA's first population: uniform ("random", the paper's: 40 generations), or the best
        rows of a table of monitor runs kept per actuator, calibration and command ("table";
        `identification.start_table`; then `limits.TABLE_GENERATIONS` generations by default, of
        `limits.TABLE_OFFSPRING` x the population new points each; about a third of the monitor
        runs, BENCHMARKS.md). "auto" (the default): the table for the
        built-in commands and for recordings of one of the calibration's commands; uniform
        otherwise, for the other optimisers and with an actuator's own baseline
        (`emaphm.identify`). The interval calibration should be fitted with the same start
        (``emaphm calibrate-uq --start``; `identify` warns where it was not).
    seed : int
        The user's seed, 0..2^63 − 1: `emaphm.identify` splits it into the twin's noise seed and
        the optimiser's; `FaultIdentifier` uses it as the optimiser's.
    workers : int
        numba threads of the population kernel (0: all cores).
    pop_size, generations : int or None
        The search's budget (None: the optimiser's default, `limits.DEFAULT_BUDGETS`); for
        "multistart" its sample size and its number of descents.
    patience, rtol
        Early stop when the best fitness improves by less than `rtol` (relative) over `patience`
        generations.
    polish : bool
        Refine the search's best point (CMA-ES, final checks polished, least squares).
    second_search : bool
        With `polish`: search again from another seed when the fit is poorer than the monitor's
        usual (`limits.SECOND_SEARCH_NRMSE`), keeping the lower eq. 3 fitness.
    last_stage : {"auto", "switching", "none"}
        With `polish`: correct the monitor's bias near the estimate by the twin's switching drive
        ("auto": with the default monitor, not the paper's).
    error_corner : float, "auto" or None
        Corner f_c [Hz] of eq. 3's weights 1/(1 + (f/f_c)²) of the command's local frequency f;
        "auto": the default monitor's measured corner (none with the paper's); None ("off" in a
        file or on the command line): the paper's eq. 3 unweighted.
    slope_unit : {"s", "ms"}
        The time unit of the slope in eq. 3's weights.
    monitor : {"default", "paper"} or None
        The monitor model (None: the calibration's).
    uncertainty : {"none", "laplace", "mcmc"}
        The 90 % interval of each fault (`identification.uncertainty`).
    """

    optimizer: str = _option(
        "ga",
        "ga (default), de, pso, cmaes, gwo, or multistart: least squares from a sample, a third of the "
        "monitor runs but less robust, for screening (docs/identification.md).",
        choices=OPTIMIZERS,
    )
    start: str = _option(
        "auto",
        "The GA's first population: 'auto' (default: 'table' for built-in commands and recordings of a "
        "calibrated one, else 'random'), 'table' (the best of 16 384 monitor runs, built once per actuator, "
        "calibration and command and kept, then 15 generations of 48 new points: about a third of the monitor "
        "runs) or 'random' (uniform, 40 generations of 96, the paper's; docs/identification.md).",
        choices=STARTS,
    )
    seed: int = _option(0, "Seed of the optimiser (and of the twin's noise).")
    workers: int = _option(0, "Threads for the population kernel (0: all cores).")
    pop_size: int | None = _option(None, "Population size (default per optimiser; multistart: its sample).")
    generations: int | None = _option(None, "Maximum generations (default per optimiser; multistart: its descents).")
    patience: int = _option(25, "Stop after this many generations without gain.", cli=False)
    rtol: float = _option(1e-3, "The relative gain that counts for --patience.", cli=False)
    polish: bool = _option(True, "Local polish of the best point.", flag="--polish/--no-polish")
    second_search: bool = _option(
        True,
        "With --polish: search again from another seed when the fit is poorer than the monitor's usual "
        "(NRMSE above 3 %; 5 % with --monitor paper), keeping the lower eq. 3 fitness (docs/identification.md).",
        flag="--second-search/--no-second-search",
    )
    last_stage: str = _option(
        "auto",
        "With --polish, after the search: 'switching' corrects the monitor's bias near the estimate by the "
        "twin's switching drive (about 0.5 s more), 'none' skips it, 'auto' (default) runs it with the default "
        "monitor, not with --monitor paper (docs/identification.md).",
        choices=LAST_STAGES,
    )
    error_corner: float | str | None = _option(
        "auto",
        "Weight eq. 3 by 1/(1 + (f/F)^2) of the command's frequency f: F in Hz, 'auto' (the default "
        "monitor's measured corner; none with --monitor paper) or 'off' (the paper's eq. 3).",
    )
    slope_unit: str = _option(
        "s", "Time unit of the slope in eq. 3's weights.", cli=False, choices=SLOPE_UNITS
    )
    monitor: str | None = _option(
        None,
        "Monitor model: 'default', or 'paper' (the paper's single-phase model, eqs. 1-2 alone); "
        "default: the calibration's.",
        choices=MONITORS,
    )
    uncertainty: str = _option(
        "laplace",
        "90 % interval per fault: laplace (fast, default), mcmc (emcee, minutes; pip install 'emaphm[uq]') or none.",
        choices=UQ_METHODS,
    )

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            choices = f.metadata["choices"]
            value = getattr(self, f.name)
            if choices is not None and not (value is None and f.default is None) and value not in choices:
                raise InputError(
                    f"unknown {f.name} {value!r}; use one of {', '.join(choices)}"
                )
        _check_int("seed", self.seed, 0, MAX_SEED, "a whole number in 0..2^63-1")
        if self.start == "table" and self.optimizer != "ga":
            raise InputError(f"start 'table' is the GA's first population; the {self.optimizer} search has none")
        if self.workers is None:  # the API's "all cores", as 0
            object.__setattr__(self, "workers", 0)
        _check_int("workers", self.workers, 0, 4096, "0 (all cores) or a number of threads")
        _check_int("pop_size", self.pop_size, 4, 10**6, "at least 4", none=True)
        _check_int("generations", self.generations, 1, 10**6, "at least 1", none=True)
        _check_int("patience", self.patience, 1, 10**6, "at least 1")
        for name in ("polish", "second_search"):
            if not isinstance(getattr(self, name), bool):
                raise InputError(f"{name} must be true or false, got {getattr(self, name)!r}")
        if not (isinstance(self.rtol, numbers.Real) and 0 <= float(self.rtol) < 1):
            raise InputError(f"rtol must be a number in [0, 1), got {self.rtol!r}")
        object.__setattr__(self, "error_corner", parse_error_corner(self.error_corner, "error_corner"))

    @classmethod
    def from_mapping(cls, values: Mapping[str, Any], *, where: str = "settings") -> IdentifySettings:
        """Settings from a mapping of field names (a campaign's ``[identify]`` table, a TOML file's
        table, JSON); an unknown key raises `InputError` naming `where` and the known keys."""
        known = [f.name for f in dataclasses.fields(cls)]
        unknown = sorted(set(values) - set(known))
        if unknown:
            raise InputError(f"{where}: unknown key(s) {', '.join(unknown)}; known: {', '.join(known)}")
        return cls(**dict(values))

    @classmethod
    def from_toml(cls, path: Any, table: str | None = "identify") -> IdentifySettings:
        """Settings from a TOML file: its `table` (None: the whole file)."""
        from ..io import read_toml

        data = read_toml(path, "settings file")
        if table is not None:
            data = data.get(table, {})
            if not isinstance(data, dict):
                raise InputError(f"{path}: [{table}] must be a table")
        return cls.from_mapping(data, where=str(path))

    @classmethod
    def resolve(cls, settings: IdentifySettings | None, options: Mapping[str, Any]) -> IdentifySettings:
        """`settings` (default: the defaults) with the keyword `options` over it, checked."""
        base = settings if settings is not None else cls()
        if not isinstance(base, IdentifySettings):
            raise InputError(f"settings must be an IdentifySettings, got {type(base).__name__}")
        return base.replace(**options) if options else base

    def replace(self, **changes: Any) -> IdentifySettings:
        """A copy with `changes` (checked); an unknown name raises `InputError`."""
        return type(self).from_mapping({**self.to_json(), **changes}, where="identification options")

    def to_json(self) -> dict[str, Any]:
        """The fields as JSON values (the error corner's None stays None: 'off')."""
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}



def _check_int(name: str, value: Any, low: int, high: int, what: str, *, none: bool = False) -> None:
    if value is None and none:
        return
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or not low <= int(value) <= high:
        raise InputError(f"{name} must be {what}, got {value!r}")


def parse_error_corner(value: Any, name: str = "the error corner") -> float | str | None:
    """A setting of the frequency weights' corner, checked: "auto" stays "auto", "off" or None
    gives None (the paper's eq. 3 unweighted), a number > 0 [Hz] (or its text) its float; anything
    else raises `InputError` naming the setting (`name`: the CLI option, the campaign key)."""
    if isinstance(value, str) and value in ("auto", "off"):
        return None if value == "off" else value
    if value is None:
        return None
    if isinstance(value, str):
        try:
            value = float(value)
        except ValueError:
            pass
    hz = float(value) if isinstance(value, numbers.Real) and not isinstance(value, bool) else math.nan
    if not (math.isfinite(hz) and hz > 0):
        raise InputError(f"{name} must be 'auto', 'off' or a frequency > 0 Hz, got {value!r}")
    return hz


def search_progress_label(optimizer: str) -> str:
    """What a progress bar counts during the search: the multistart's least-squares descents, the
    other optimisers' generations."""
    return "least-squares descents" if optimizer == "multistart" else f"{optimizer.upper()} generations"


def budget_text(optimizer: str, pop_size: int | None, generations: int | None) -> str:
    """The search's budget in words (None: the optimiser's default, `limits.DEFAULT_BUDGETS`)."""
    from .limits import DEFAULT_BUDGETS

    default_pop, default_gen = DEFAULT_BUDGETS.get(optimizer, (None, None))
    pop = default_pop if pop_size is None else pop_size
    gen = default_gen if generations is None else generations
    if optimizer == "multistart":
        return f"a sample of {pop} points, {gen} least-squares descents"
    return f"{pop} × {gen} generations"

