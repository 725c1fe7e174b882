"""The running maxima and minima (identification/windows.py) against scipy.ndimage's filters,
which they replace on the diagnosis's path (issue 36), and pymoo's duplicate check against
`NumpyDuplicates`."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.ndimage import maximum_filter1d, minimum_filter1d

from emaphm.identification.optimizers import NumpyDuplicates
from emaphm.identification.windows import running_max, running_min


@pytest.mark.parametrize("mode", ["nearest", "reflect"])
def test_trailing_windows_equal_scipy_to_the_bit(mode: str) -> None:
    rng = np.random.default_rng(7)
    for _ in range(400):
        n, w = int(rng.integers(1, 50)), int(rng.integers(0, 70))  # windows longer than the signal too
        x = rng.normal(size=n).round(1)  # ties
        origin = w // 2  # scipy's trailing window of w + 1 samples
        assert np.array_equal(running_max(x, w, mode=mode), maximum_filter1d(x, w + 1, origin=origin, mode=mode))
        assert np.array_equal(running_min(x, w, mode=mode), minimum_filter1d(x, w + 1, origin=origin, mode=mode))


def test_centred_window_equals_scipy() -> None:
    rng = np.random.default_rng(8)
    for _ in range(200):
        n, h = int(rng.integers(1, 40)), int(rng.integers(0, 30))
        x = rng.normal(size=n)
        assert np.array_equal(running_max(x, h, h), maximum_filter1d(x, 2 * h + 1, mode="nearest"))


def test_a_window_of_one_and_empty_signals() -> None:
    x = np.array([3.0, -1.0, 2.0])
    assert np.array_equal(running_max(x, 0), x) and running_max([], 5).shape == (0,)
    assert np.array_equal(running_max(x, 1), [3.0, 3.0, 2.0])  # trailing: [i-1, i]
    assert np.array_equal(running_max(x, 0, 1), [3.0, 2.0, 2.0])  # ahead: [i, i+1]


def test_bad_windows_are_refused() -> None:
    with pytest.raises(ValueError, match="1-D"):
        running_max(np.zeros((2, 2)), 1)
    with pytest.raises(ValueError, match=">= 0"):
        running_min(np.zeros(3), -1)


def test_numpy_duplicates_flag_what_pymoo_flags() -> None:
    from pymoo.core.duplicate import DefaultDuplicateElimination
    from pymoo.core.population import Population

    rng = np.random.default_rng(3)
    X = rng.uniform(size=(40, 8))
    X[10] = X[3]
    X[25] = X[3]
    X[31] = X[7] + 1e-17  # rounds to X[7]: the same point
    Y = np.vstack([X[:5], rng.uniform(size=(5, 8))])
    pop, other = Population.new(X=X), Population.new(X=Y)
    ours, theirs = NumpyDuplicates(), DefaultDuplicateElimination()
    assert np.array_equal(ours.calc_dist(pop) <= 1e-16, theirs.calc_dist(pop) <= 1e-16)
    assert np.allclose(ours.calc_dist(pop, other), theirs.calc_dist(pop, other), rtol=1e-12, atol=0)
    assert len(ours.do(pop)) == len(theirs.do(pop)) == 37  # rows 10, 25 and 31 dropped
    assert len(ours.do(pop, other)) == len(theirs.do(pop, other)) == 32  # and rows 0-4, as in `other`
