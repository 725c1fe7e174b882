"""The final check against shorts put in the wrong phases (issue 8, item 3)."""

from __future__ import annotations

import numpy as np

from emaphm.identification.identify import try_short_permutations
from emaphm.identification.optimizers import OptimizerRun

TRUTH = np.array([0.2, 0.1, 0.05, 0.4, 0.0, 0.1, 0.3, 0.5])


def bowl(X):
    return np.sum((np.atleast_2d(X) - TRUTH) ** 2, axis=1)


def test_shorts_in_the_wrong_phases_are_moved_to_the_right_ones():
    wrong = TRUTH.copy()
    wrong[2:5] = [0.4, 0.0, 0.05]  # the right magnitudes, the wrong phases
    run = OptimizerRun(wrong, float(bowl(wrong)[0]), 100, [1.0])
    out, order, move = try_short_permutations(bowl, run, polish_it=False)
    np.testing.assert_array_equal(out.x, TRUTH)
    assert out.f == 0.0 and out.evaluations == 108 and move == f"order {order}"
    assert [wrong[2 + o] for o in order] == list(TRUTH[2:5])
    assert out.history == [1.0]  # the optimiser's generations only


def test_a_right_answer_is_kept_as_it_is():
    run = OptimizerRun(TRUTH.copy(), 0.0, 50, [0.0])
    out, order, move = try_short_permutations(bowl, run, polish_it=False)
    assert order is None and move is None and out.f == 0.0 and out.evaluations == 58
    np.testing.assert_array_equal(out.x, TRUTH)


def test_a_better_permutation_is_polished_when_asked():
    near = TRUTH.copy()
    near[2:5] = [0.42, 0.0, 0.04]  # a permutation of nearly the right magnitudes
    near[0] = 0.25
    run = OptimizerRun(near, float(bowl(near)[0]), 0, [])
    plain, _, _ = try_short_permutations(bowl, run, polish_it=False)
    polished, order, _ = try_short_permutations(bowl, run, seed=3, polish_it=True)
    assert order is not None and polished.f < plain.f < run.f
    assert polished.evaluations > plain.evaluations


def test_non_finite_permutations_are_never_taken():
    wrong = TRUTH.copy()
    wrong[2:5] = [0.4, 0.0, 0.05]

    def nan_elsewhere(X):
        f = bowl(X)
        return np.where(np.all(np.atleast_2d(X) == wrong, axis=1), f, np.nan)

    run = OptimizerRun(wrong, float(bowl(wrong)[0]), 0, [])
    out, order, move = try_short_permutations(nan_elsewhere, run, polish_it=False)
    assert order is None and move is None and out.f == run.f


def test_a_spurious_short_is_zeroed():
    spurious = TRUTH.copy()
    spurious[4] = 0.3  # the truth has no short in phase C
    run = OptimizerRun(spurious, float(bowl(spurious)[0]), 10, [])
    out, order, move = try_short_permutations(bowl, run, polish_it=False)
    assert move == "k5 zeroed" and order is None and out.f == 0.0
    np.testing.assert_array_equal(out.x, TRUTH)


def test_the_phase_is_moved_off_a_bound_of_the_box_without_changing_the_faults():
    from emaphm.identification.identify import recentre_phase, search_to_faults

    for x7 in (0.0, 0.1, 0.3, 0.5, 0.74, 0.9, 1.0):
        x = TRUTH.copy()
        x[6] = x7
        out = recentre_phase(OptimizerRun(x, 0.5, 7, [1.0]))
        assert 0.25 <= out.x[6] < 0.75 and (out.f, out.evaluations, out.history) == (0.5, 7, [1.0])
        np.testing.assert_allclose(search_to_faults(out.x[None]), search_to_faults(x[None]), atol=1e-12)
        np.testing.assert_array_equal(np.delete(out.x, 6), np.delete(x, 6))
