"""How a batch of monitor runs is shared among threads (`kernels.batches`): every row once, the
plans' loads, and the same numbers whatever the plan."""

import numpy as np
import pytest

from emaphm.kernels.batches import PAIR, PAIR_COST, QUAD, SINGLE, batch_plan, thread_jobs
from emaphm.kernels.fitness import fitness_lf_many, residuals_lf_many

from .test_fitness_kernel import population


def rows_of(owner, n_pairs):
    """Each task's rows, in task order."""
    return [[2 * q, 2 * q + 1] if q < n_pairs else [n_pairs + q] for q in range(len(owner))]


@pytest.mark.parametrize("n_threads", [1, 2, 3, 4, 8])
def test_every_row_is_run_once_by_a_thread_that_exists(n_threads):
    for n_runs in range(1, 60):
        owner, n_pairs = batch_plan(n_runs, n_threads)
        rows = sorted(r for task in rows_of(owner, n_pairs) for r in task)
        assert rows == list(range(n_runs))
        assert owner.min() >= 0 and owner.max() < min(n_threads, n_runs)


def test_the_plans_end_no_later_than_pairs_alone_and_split_a_pair_where_that_ends_sooner():
    def span(owner, n_pairs, n_threads):
        load = np.zeros(n_threads)
        for q, t in enumerate(owner):
            load[t] += PAIR_COST if q < n_pairs else 1.0
        return load.max()

    for n_threads in (1, 2, 4):
        for n_runs in range(1, 60):
            owner, n_pairs = batch_plan(n_runs, n_threads)
            pairs_alone = np.ceil((n_runs // 2 + n_runs % 2) / n_threads) * PAIR_COST  # an odd row costs a pair's slot
            assert span(owner, n_pairs, n_threads) <= pairs_alone + 1e-9, (n_runs, n_threads)
    assert batch_plan(8, 1)[1] == 4  # one thread: pairs, the cheaper per row
    assert batch_plan(2, 2)[1] == 0  # two rows on two threads: one each
    owner, n_pairs = batch_plan(6, 2)  # 3 pairs would take two pairs' time on one thread
    assert n_pairs == 2 and sorted(owner) == [0, 0, 1, 1]


@pytest.mark.parametrize("n_threads", [0, 1, 2, 3])  # 0: as one (every row still written)
def test_the_kernels_give_the_same_numbers_whatever_the_plan(n_threads):
    theta_cmd, rows, _, f = population(n_rows=13, duration=0.1)
    keep = np.flatnonzero(f.weights > 0)
    for n in (1, 2, 3, 5, 6, 9, 13):
        fit_ref, fit = np.empty(n), np.empty(n)
        res_ref, res = np.empty((n, len(keep))), np.empty((n, len(keep)))
        for out, threads in ((fit_ref, 1), (fit, n_threads)):
            fitness_lf_many(theta_cmd, rows[:n], f.sos, f.zi, f.padlen, f.comparison.reference, f.weights, out, threads)
        for out, threads in ((res_ref, 1), (res, n_threads)):
            residuals_lf_many(theta_cmd, rows[:n], f.sos, f.zi, f.padlen, keep, f.comparison.reference[keep],
                              np.sqrt(f.weights[keep]), out, threads)  # fmt: skip
        np.testing.assert_array_equal(fit, fit_ref)
        np.testing.assert_array_equal(res, res_ref)
        # and each row as alone (a batch of one)
        for r in range(n):
            one = np.empty(1)
            fitness_lf_many(theta_cmd, rows[r : r + 1], f.sos, f.zi, f.padlen, f.comparison.reference, f.weights, one, 1)
            assert one[0] == fit_ref[r]
            alone = np.empty((1, len(keep)))
            residuals_lf_many(theta_cmd, rows[r : r + 1], f.sos, f.zi, f.padlen, keep, f.comparison.reference[keep],
                              np.sqrt(f.weights[keep]), alone, 1)  # fmt: skip
            np.testing.assert_array_equal(alone[0], res_ref[r])


def test_each_thread_runs_its_planned_rows_once_two_pairs_at_a_time():
    for n_threads in (1, 2, 3):
        for n_runs in range(1, 40):
            owner, n_pairs = batch_plan(n_runs, n_threads)
            jobs = thread_jobs(n_runs, n_threads)
            seen = []
            for t in range(jobs.shape[0]):
                kinds = [int(k) for k in jobs[t, :, 0] if k]
                assert jobs[t, len(kinds):, 0].sum() == 0  # the list ends with its first empty job
                assert kinds == sorted(kinds, reverse=True)  # quads, then a pair left over, then rows alone
                assert kinds.count(PAIR) <= 1
                for kind, a, b in jobs[t, : len(kinds)]:
                    rows = {QUAD: [a, a + 1, b, b + 1], PAIR: [a, a + 1], SINGLE: [a]}[int(kind)]
                    task_of = [r // 2 if r < 2 * n_pairs else r - n_pairs for r in rows]
                    assert all(owner[q] == t for q in task_of)  # the plan's thread
                    seen += rows
            assert sorted(seen) == list(range(n_runs)), (n_runs, n_threads)
