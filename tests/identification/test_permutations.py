"""The final check against shorts put in the wrong phases (issue 8, item 3)."""

from __future__ import annotations

import numpy as np

from emaphm.identification.checks import try_short_permutations
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
    from emaphm.identification.problem import recentre_phase, search_to_faults

    for x7 in (0.0, 0.1, 0.3, 0.5, 0.74, 0.9, 1.0):
        x = TRUTH.copy()
        x[6] = x7
        out = recentre_phase(OptimizerRun(x, 0.5, 7, [1.0]))
        assert 0.25 <= out.x[6] < 0.75 and (out.f, out.evaluations, out.history) == (0.5, 7, [1.0])
        np.testing.assert_allclose(search_to_faults(out.x[None]), search_to_faults(x[None]), atol=1e-12)
        np.testing.assert_array_equal(np.delete(out.x, 6), np.delete(x, 6))


# two basins in the search box: a shallow one at A (floor 0.05) and the deep one at B (floor 0)
A = np.array([0.6, 0.4, 0.3, 0.3, 0.3, 0.2, 0.4, 0.5])
B = np.array([0.5, 0.45, 0.2, 0.4, 0.2, 0.25, 0.45, 0.5])


def two_basins(X):
    X = np.atleast_2d(X)
    return np.minimum(np.sum((X - A) ** 2, axis=1) * 50 + 0.05, np.sum((X - B) ** 2, axis=1) * 50)


def two_basins_residuals(X):
    """Residual vectors whose Σ r² is `two_basins`: the lower bowl's, its floor as a last entry."""
    X = np.atleast_2d(X)
    in_a = np.sum((X - A) ** 2, axis=1) * 50 + 0.05 < np.sum((X - B) ** 2, axis=1) * 50
    centre = np.where(in_a[:, None], A, B)
    floor = np.where(in_a, np.sqrt(0.05), 0.0)
    return np.concatenate([np.sqrt(50.0) * (X - centre), floor[:, None]], axis=1)


def test_the_candidates_are_the_best_members_of_other_basins():
    from emaphm.identification.descents import candidates

    close = A + 0.01  # the same basin: within RUNNER_UP_DISTANCE in every fault
    same_phase = A.copy()
    same_phase[6] = A[6] + 0.5  # x7 and x7 + 0.5 give the same k7: not another candidate
    far_good, far_bad = B + 0.02, B + 0.1
    far_good_twin = far_good + 0.01  # close to far_good: not a candidate beside it
    population = np.array([A, close, same_phase, far_bad, far_good_twin, far_good])
    run = OptimizerRun(A.copy(), float(two_basins(A)[0]), 10, [1.0], population, two_basins(population))
    starts = candidates(run, 5)
    assert [c.f for c in starts] == sorted(c.f for c in starts)  # best first
    np.testing.assert_array_equal(starts[0].x, A)
    np.testing.assert_array_equal(starts[1].x, far_good)
    np.testing.assert_array_equal(starts[2].x, far_bad)
    assert len(starts) == 3 and starts[1].evaluations == 0
    assert len(candidates(run, 2)) == 2
    assert len(candidates(OptimizerRun(A.copy(), 0.05, 10, [1.0], population[:3], two_basins(population[:3])), 5)) == 1
    assert len(candidates(OptimizerRun(A.copy(), 0.05, 10, [1.0]), 5)) == 1  # no population (a polish's run)


def test_polishing_the_runner_ups_escapes_a_neighbouring_basin():
    from emaphm.identification.polish import polish_runner_ups

    population = np.array([A, A - 0.01, B + 0.05])
    run = OptimizerRun(A.copy(), float(two_basins(A)[0]), 10, [1.0], population, two_basins(population))
    kept = OptimizerRun(A.copy(), 0.05, 30, [1.0, 0.05])  # the best point, polished in its shallow basin
    out, won = polish_runner_ups(two_basins_residuals, two_basins, run, kept, 5)
    assert won == 1 and out.f < 1e-8 and np.max(np.abs(out.x - B)) < 1e-4
    assert out.evaluations > 30 + 9 and out.history == [1.0, 0.05]  # kept's history, all evaluations
    # when the best point's basin is the deep one, it stays
    swapped = OptimizerRun(B.copy(), 0.0, 10, [0.0], population[::-1], two_basins(population[::-1]))
    stays, won = polish_runner_ups(two_basins_residuals, two_basins, swapped, swapped, 5)
    assert won == 0 and stays.f == 0.0 and np.array_equal(stays.x, B)


def test_descents_from_the_candidates_escape_a_neighbouring_basin():
    from emaphm.identification.descents import descend_from

    population = np.array([A, A - 0.01, B + 0.05])
    run = OptimizerRun(A.copy(), float(two_basins(A)[0]), 10, [1.0], population, two_basins(population))
    out, start = descend_from(run, two_basins_residuals, two_basins, 5, 0.05)
    assert start == 1 and out.f < 1e-8 and np.max(np.abs(out.x - B)) < 1e-4
    # two descents (A − 0.01 is within 0.05 of A): their end points and values are the population
    assert out.population.shape == (2, 8) and abs(out.population_f[0] - 0.05) < 1e-8
    assert out.evaluations > 10 + 2 * 9 and out.history == [1.0, out.f]  # the run's, all evaluations
    # when the best point's basin is the deep one, its descent wins
    swapped = OptimizerRun(B.copy(), 0.0, 10, [0.0], population[::-1], two_basins(population[::-1]))
    stays, start = descend_from(swapped, two_basins_residuals, two_basins, 5, 0.05)
    assert start == 0 and stays.f == 0.0 and np.array_equal(stays.x, B)
