"""The accuracy metric of an identification (paper eq. 4, DESIGN §5).

As printed, eq. 4 weights (k7 − k̄7)² by k̄6:

    %err_printed = 100·sqrt( Σ_{i=1..6} (k_i − k̄_i)² + k̄6·(k7 − k̄7)² + (k8 − k̄8)² )

That does not reproduce the paper's own Table 1. The reading that reproduces all five %err values
of Table 1 to two decimals weights the phase error by k̄6 *inside* the square:

    %err = 100·sqrt( Σ_{i∈{1..6,8}} (k_i − k̄_i)² + (k̄6·(k7 − k̄7))² )

It is also the physically sensible one: the eccentricity phase k7 only matters in proportion to the
eccentricity k̄6 (a direction error of a vanishing eccentricity is no error), and the term has
the units of the others. It is the default (`form="table1"`); `form="printed"` gives eq. 4 as printed.

In both forms k7 − k̄7 is taken on the circle, wrapped to [−0.5, 0.5): k7 is a direction
φ_e = 2π·k7, so 0.99 against 0.01 is a 0.02 error, not 0.98. The five Table 1 rows are
unaffected (their phase errors are below 0.5).
"""

from __future__ import annotations

from typing import Literal, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ..faults import as_fault_vector

__all__ = ["absolute_errors", "percent_error", "wrap_phase"]


def percent_error(
    estimate: ArrayLike, truth: ArrayLike, *, form: Literal["table1", "printed"] = "table1"
) -> float:
    """%err of an identified fault vector against the true one (both 8 values in [0, 1]).

    Parameters
    ----------
    estimate : array_like of 8 floats in [0, 1]
        The identified fault vector k1..k8.
    truth : array_like of 8 floats in [0, 1]
        The true fault vector.
    form : {"table1", "printed"}
        "table1": the reading of eq. 4 that reproduces the paper's Table 1; "printed": eq. 4 as
        printed (docs/identification.md says why they differ).
    """
    k = as_fault_vector(estimate, name="estimate")
    kt = as_fault_vector(truth, name="truth")
    d = k - kt
    d[6] = wrap_phase(d[6])
    core = float(np.sum(d[[0, 1, 2, 3, 4, 5, 7]] ** 2))
    if form == "table1":
        return 100.0 * float(np.sqrt(core + (kt[5] * d[6]) ** 2))
    if form == "printed":
        return 100.0 * float(np.sqrt(core + kt[5] * d[6] ** 2))
    raise InputError(f"unknown %err form {form!r}; use 'table1' or 'printed'")


@overload
def wrap_phase(dk7: float) -> float: ...
@overload
def wrap_phase(dk7: NDArray[np.float64]) -> NDArray[np.float64]: ...
def wrap_phase(dk7: float | NDArray[np.float64]) -> float | NDArray[np.float64]:
    """A difference of k7 (a phase in turns) wrapped to [−0.5, 0.5); elementwise for an array."""
    wrapped = (np.asarray(dk7, dtype=np.float64) + 0.5) % 1.0 - 0.5
    return wrapped if np.ndim(dk7) else float(wrapped)


def absolute_errors(estimate: ArrayLike, truth: ArrayLike) -> NDArray[np.float64]:
    """|k_i − k̄_i| per fault (k7's difference taken on the circle: the phase wraps at 1).

    Parameters
    ----------
    estimate : array_like of 8 floats in [0, 1]
        The identified fault vector k1..k8.
    truth : array_like of 8 floats in [0, 1]
        The true fault vector.
    """
    d = np.abs(as_fault_vector(estimate, name="estimate") - as_fault_vector(truth, name="truth"))
    d[6] = abs(wrap_phase(d[6]))
    return d
