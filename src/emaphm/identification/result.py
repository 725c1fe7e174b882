"""The result of one identification (`IdentificationResult`): the estimate and everything needed to
reproduce and judge it, and its JSON (DESIGN §8, ``emaphm identify --json``).

The record of how it was reached is ``settings``: the settings (``settings["identify"]``), the
tuned constants (``settings["limits"]``), one record per stage in the order they ran
(``settings["stages"]``, read with `stage_record`), the inputs with their sources and hashes, and
the versions.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .._version import __version__
from ..faults import FAULT_NAMES
from .metrics import absolute_errors, percent_error
from .state import stage_record
from .uncertainty import Uncertainty
from .verdict import explains, verdict_of

__all__ = ["IdentificationResult", "stage_record"]


@dataclass(frozen=True)
class IdentificationResult:
    """One identification: the estimate and everything needed to reproduce and judge it.

    estimate : ndarray of 8 floats in [0, 1]  the identified fault vector k1..k8
    fitness : float  eq. (3) at the estimate [A²]
    evaluations : int  LF model evaluations of all the stages
    wall_time_s : float  the identification's wall time [s]
    seed : int  the seed given (split into the twin's noise seed and the optimiser's)
    optimizer : str  the global search (`IdentifySettings.optimizer`)
    truth : ndarray or None  the fault vector the twin ran with (None for a recording)
    detected : list of str  the faults reported present (none when the fit fails)
    history : list of float  the search's best eq. (3) per generation [A²]
    settings : dict  the record: settings, limits, stage records, inputs and versions (`stage`)
    version : str  emaphm's version
    warnings : list of str  what the result warns of, one sentence each
    fit_nrmse : float or None  NRMSE of the fitted current against the measured one [-]
    uncertainty : Uncertainty or None  the 90 % intervals (None with ``uncertainty="none"``)
    fault_verdicts : dict or None  "present", "absent" or "cannot tell" per detectable fault
    doubts : list of str  why the verdict is "doubtful" (a subset of `warnings`; empty: it is not)
    curves : dict of ndarray or None  t, measured, fitted, compared on the model grid (not in the JSON)
    """

    estimate: NDArray[np.float64]
    fitness: float
    evaluations: int
    wall_time_s: float
    seed: int
    optimizer: str
    truth: NDArray[np.float64] | None = None
    detected: list[str] = field(default_factory=list)
    history: list[float] = field(default_factory=list)
    settings: dict[str, Any] = field(default_factory=dict)
    version: str = __version__
    warnings: list[str] = field(default_factory=list)
    fit_nrmse: float | None = None
    # the 90 % intervals and flags of each fault (`uncertainty`); None with uncertainty="none"
    uncertainty: Uncertainty | None = None
    # per detectable fault: "present", "absent" or "cannot tell" (`uncertainty.verdicts`)
    fault_verdicts: dict[str, str] | None = None
    # why the result is doubtful, one sentence per reason (each also in `warnings`; `verdict`)
    doubts: list[str] = field(default_factory=list)
    # the fit on the model grid (`FaultIdentifier.curves`), for figures and reports; not in the JSON
    curves: dict[str, NDArray[np.float64]] | None = field(default=None, repr=False, compare=False)

    @property
    def fits(self) -> bool:
        """True when the monitor explains the measurement (`FIT_NRMSE_LIMIT`; the verdict "fits"
        or "doubtful"); else no faults are reported: a result the model cannot explain is not a diagnosis."""
        return explains(self.fit_nrmse)

    @property
    def verdict(self) -> str:
        """ "fits", "doubtful" (faults reported; the reasons in `doubts`) or "does not fit" (none
        reported; `verdict.verdict_of`)."""
        return verdict_of(self.fit_nrmse, self.doubts)

    def stage(self, name: str) -> dict[str, Any] | None:
        """The record of the stage `name` ("search", "polish", "final_checks", "least_squares",
        "fit", "second_search", "last_stage"; `stage_record`), None if it is not in the result."""
        return stage_record(self.settings.get("stages", []), name)

    @property
    def percent_error(self) -> float | None:
        """%err against the truth (DESIGN §5 metric), when the truth is known."""
        return None if self.truth is None else percent_error(self.estimate, self.truth)

    def to_json(self) -> dict[str, Any]:
        """The fields of DESIGN §8 (`emaphm identify --json`) plus details."""
        truth = None if self.truth is None else [float(v) for v in self.truth]
        return {
            "estimate": [float(v) for v in self.estimate],
            "fault_names": list(FAULT_NAMES),
            "truth": truth,
            "percent_error": self.percent_error,
            "absolute_errors": None if truth is None else absolute_errors(self.estimate, truth).tolist(),
            "detected": self.detected,
            "verdict": self.verdict,
            "doubts": list(map(str, self.doubts)),
            "fit_nrmse": None
            if self.fit_nrmse is None or not np.isfinite(self.fit_nrmse)
            else self.fit_nrmse,
            "fitness": self.fitness,
            "evaluations": self.evaluations,
            "wall_time_s": self.wall_time_s,
            "seed": self.seed,
            "optimizer": self.optimizer,
            "version": self.version,
            "warnings": self.warnings,
            "settings": self.settings,
            # a generation whose best row diverged has no finite best: null, so the JSON stays valid
            "history": [float(v) if np.isfinite(v) else None for v in self.history],
            "fault_verdicts": self.fault_verdicts,
            **(
                self.uncertainty.to_json()
                if self.uncertainty is not None
                else {
                    "uq_method": "none",
                    "std": None,
                    "ci90_low": None,
                    "ci90_high": None,
                    "corr": None,
                    "uq_flags": None,
                    "uq": None,
                }
            ),
        }
