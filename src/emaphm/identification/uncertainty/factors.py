"""The interval calibration for the monitor's discrepancy (`Factors`), its files and its fit.

σ_j = √((c_j·σ_raw,j)² + b_j²), a scale c_j and a floor b_j per fault, fitted on simulated HF
cases that no benchmark uses (`fit_factors`, ``emaphm calibrate-uq``) and shipped per last stage
(`PACKAGED_FACTORS`), each tied to the LF calibration it was fitted with.
"""

from __future__ import annotations

import functools
import json
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..._data import read_package_json, record_copy
from ...errors import InputError
from ...faults import FAULT_NAMES
from .intervals import N_PARAMS, PHASE, ZETA, covers, half_widths, intervals

if TYPE_CHECKING:
    from ...calibration import Calibration

from ..limits import FIT_COVERAGE

__all__ = [
    "FIT_COVERAGE",
    "PACKAGED_FACTORS",
    "UQ_FORMAT",
    "UQ_FORMAT_VERSION",
    "Factors",
    "fit_factors",
    "load_factors",
]

UQ_FORMAT = "emaphm-uq-calibration"
UQ_FORMAT_VERSION = 1


@dataclass(frozen=True)
class Factors:
    """Calibration of the intervals for the model discrepancy: σ_j = √((scale_j·σ_raw,j)² + floor_j²)."""

    scale: NDArray[np.float64]
    floor: NDArray[np.float64]
    record: dict[str, Any] = field(default_factory=dict)

    @classmethod
    def identity(cls) -> Factors:
        """Noise-only intervals (no calibration for the model discrepancy)."""
        return cls(np.ones(N_PARAMS), np.zeros(N_PARAMS), {})

    def apply(self, raw_std: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.sqrt((self.scale * raw_std) ** 2 + self.floor**2)  # type: ignore[no-any-return]

    def to_json(self) -> dict[str, Any]:
        return {
            "format": UQ_FORMAT,
            "format_version": UQ_FORMAT_VERSION,
            "factors": {
                name: {"scale": float(self.scale[j]), "floor": float(self.floor[j])}
                for j, name in enumerate(FAULT_NAMES)
            },
            **{k: v for k, v in self.record.items() if k not in ("format", "format_version", "factors")},
        }

    @classmethod
    def from_json(cls, data: Any, where: str) -> Factors:
        if not isinstance(data, dict) or data.get("format") != UQ_FORMAT:
            raise InputError(f"{where} is not an emaphm interval calibration (from 'emaphm calibrate-uq')")
        if data.get("format_version") != UQ_FORMAT_VERSION:
            raise InputError(
                f"{where} has format version {data.get('format_version')}, this emaphm reads "
                f"{UQ_FORMAT_VERSION}: run 'emaphm calibrate-uq' again"
            )
        factors: Any = data.get("factors")
        try:
            scale = np.array([float(factors[n]["scale"]) for n in FAULT_NAMES])
            floor = np.array([float(factors[n]["floor"]) for n in FAULT_NAMES])
        except (KeyError, TypeError, ValueError):
            raise InputError(
                f"{where} must give a scale and a floor for each of {', '.join(FAULT_NAMES)}"
            ) from None
        if not (
            np.all(np.isfinite(scale))
            and np.all(scale > 0)
            and np.all(np.isfinite(floor))
            and np.all(floor >= 0)
        ):
            raise InputError(f"{where}: scales must be positive and floors non-negative")
        return cls(scale, floor, dict(data))

    def save(self, path: str | Path) -> None:
        from ...io import atomic_path

        with atomic_path(Path(path)) as tmp:
            tmp.write_text(json.dumps(self.to_json(), indent=2) + "\n")

    def matches(self, calibration: Calibration) -> bool:
        """Whether these factors were fitted with this LF calibration (its monitor, date and actuator)."""
        key = self.record.get("lf_calibration") or {}
        return bool(
            key.get("monitor") == calibration.monitor
            and key.get("created") == calibration.record.get("created")
            and key.get("params_hash") == calibration.params_hash
        )

    def mismatch(self, calibration: Calibration, last_stage: str, start: str) -> tuple[str | None, bool]:
        """What keeps these factors from holding for an identification with this LF `calibration`
        that ran `last_stage` ("switching", "none") from `start` (its search record's: "random",
        "table"): a warning or None, and whether they belong to another calibration (then the
        intervals show the measurement noise only). Files before issue 36 record no start: uniform."""
        if not self.record:
            return None, False
        if not self.matches(calibration):
            return (
                "the interval calibration was fitted with another LF calibration or monitor: the "
                "intervals show the measurement noise only, not the model's bias (run 'emaphm calibrate-uq')"
            ), True
        made_with = self.record.get("last_stage", "none")
        if made_with != last_stage:
            return (
                f"the interval calibration was fitted on identifications with the last stage {made_with!r}, this "
                f"one ran {last_stage!r}: its intervals may not hold (run 'emaphm calibrate-uq' with the same settings)"
            ), False
        # the table's end points need wider factors than the uniform start's (BENCHMARKS.md, issue 36);
        # the other way round the intervals are only wider than they need be
        if start == "table" and self.record.get("start", "random") == "random":
            return (
                "the interval calibration was fitted on identifications from a uniform start, this one started "
                "from the start table: its intervals may be too narrow (run 'emaphm calibrate-uq --start auto')"
            ), False
        return None, False


# the packaged interval calibrations, by the identification's last stage (`choices.LAST_STAGES`):
# the switching stage leaves estimates about half as far from the truth, so its intervals are
# narrower; the other file was fitted without it (both with the packaged LF calibration)
PACKAGED_FACTORS = {"switching": "uq_calibration.json", "none": "uq_calibration_no_last_stage.json"}


@functools.lru_cache(maxsize=2)
def _packaged(last_stage: str) -> Factors:
    name = PACKAGED_FACTORS[last_stage]
    factors = Factors.from_json(read_package_json(name), f"emaphm/data/{name}")
    for array in (factors.scale, factors.floor):
        array.setflags(write=False)  # shared by every caller (review L8)
    return factors


def load_factors(path: str | os.PathLike[str] | None = None, *, last_stage: str = "switching") -> Factors:
    """The interval calibration: a file from ``emaphm calibrate-uq``, or the packaged one for
    identifications with that last stage ("switching" or "none", `PACKAGED_FACTORS`)."""
    if path is None:
        if last_stage not in PACKAGED_FACTORS:
            raise InputError(f"no packaged interval calibration for the last stage {last_stage!r}")
        shared = _packaged(last_stage)  # its arrays read-only; the record each caller's own copy
        return Factors(shared.scale, shared.floor, record_copy(shared.record))
    p = Path(path)
    try:
        data = json.loads(p.read_text())
    except FileNotFoundError:
        raise InputError(f"{p}: no such interval calibration file") from None
    except OSError as exc:
        raise InputError(f"{p}: cannot read the interval calibration ({exc.strerror or exc})") from None
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"{p} is not a JSON interval calibration ({exc})") from None
    return Factors.from_json(data, str(p))


def fit_factors(
    estimates: ArrayLike,
    raw_std: ArrayLike,
    truths: ArrayLike,
    *,
    coverage: float = FIT_COVERAGE,
    added: ArrayLike | None = None,
    balanced: float = 0.0,
) -> tuple[Factors, dict[str, Any]]:
    """The scale and floor per fault that give `coverage` of the 90 % intervals on these cases with
    the narrowest median interval (a grid search; k7 scored only where the true ζ ≥ 0.05, on the
    circle). `added`: each case's σ from the actuator's constants (`constants.shift_covariance`),
    which the intervals add in quadrature to the calibrated one; `balanced`: the shorts' allowance
    β for a ψ_m off its nameplate that the intervals then carry (`balanced.allowed`). Returns the
    factors and, per fault, the coverage and median half-width reached."""
    from .balanced import allowed

    E, S, T = (np.array(a, dtype=np.float64, ndmin=2) for a in (estimates, raw_std, truths))
    A = np.zeros_like(S) if added is None else np.array(added, dtype=np.float64, ndmin=2)
    if not (E.shape == S.shape == T.shape and E.shape[1] == N_PARAMS):
        raise ValueError("estimates, raw_std and truths must all have shape (m, 8)")
    scales = np.geomspace(0.3, 30.0, 61)
    floors = np.concatenate([[0.0], np.geomspace(1e-4, 0.2, 60)])
    scale, floor = np.ones(N_PARAMS), np.zeros(N_PARAMS)
    report: dict[str, Any] = {}
    for j in range(N_PARAMS):  # ζ before its direction: the direction's definition needs ζ's σ
        best: tuple[float, float, float, float] | None = None
        rows = T[:, ZETA] >= 0.05 if j == PHASE else np.ones(len(E), dtype=bool)
        grid = [(c, b) for c in scales for b in floors] if rows.any() else []  # no case to score: none
        for c, b in grid:
            trial_s, trial_b = scale.copy(), floor.copy()
            trial_s[j], trial_b[j] = c, b
            _, lo, hi, _ = intervals(
                E, np.sqrt(Factors(trial_s, trial_b).apply(S) ** 2 + A**2), with_flags=False
            )
            lo, hi, _ = allowed(E, lo, hi, balanced)
            cov = float(covers(lo, hi, T)[rows, j].mean())
            width = float(np.median(half_widths(lo, hi)[rows, j]))
            if cov >= coverage and (best is None or width < best[2]):
                best = (float(c), float(b), width, cov)
        if best is None:
            raise InputError(
                f"no scale and floor up to {scales[-1]:g} and {floors[-1]:g} make the intervals of "
                f"{FAULT_NAMES[j]} cover {coverage:.0%} of these cases: are the estimates from this monitor?"
            )
        scale[j], floor[j] = best[0], best[1]
        report[FAULT_NAMES[j]] = {"coverage": round(best[3], 4), "median_half_width": round(best[2], 5)}
    return Factors(scale, floor), report
