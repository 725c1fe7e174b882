"""How a batch of monitor runs is shared among the threads (`fitness.fitness_lf_many`,
`fitness.residuals_lf_many`).

A thread runs two rows at once faster than one after the other (`monitor.simulate_lf2`, and the
comparison filter of two currents interleaved): on machine G a pair took 1.06-1.22 ms where one row
took 0.65-0.77 ms (10 001 samples; 4 rows and 1 row on two threads, `studies/step_timings.py`), so a
batch goes in pairs. But pairs alone leave threads idle at the
end of a batch whose pairs do not divide among them: 6 rows as 3 pairs on 2 threads take two
pairs' time where 2 pairs and 2 single rows take a pair and a row on each (2.11 -> 1.67-1.80 ms
on machine G, `studies/step_timings.py`).
`batch_plan` turns up to one pair per thread into two single rows where that ends the batch
sooner, by the longest-processing-time rule with a pair costing `PAIR_COST` rows. Which thread
runs a row does not change its numbers (a row alone is `monitor.simulate_lf`'s, in a pair
`simulate_lf2`'s, the same to the bit).
"""

from __future__ import annotations

import numpy as np

from ._jit import jit

# a pair of rows on one thread, in single rows' time (machine G: 1.06-1.22 / 0.65-0.77 ms; E: 1.2-1.6)
PAIR_COST = 1.7


@jit
def _makespan(n_pairs, n_singles, n_threads, owner):  # type: ignore[no-untyped-def]
    """The longest thread's load (in single rows) of `n_pairs` pairs then `n_singles` rows, each
    given to the least loaded thread (the first of equals); `owner` (length ≥ the tasks) gets
    each task's thread."""
    load = np.zeros(n_threads)
    for task in range(n_pairs + n_singles):
        t = 0  # the least loaded, by hand: np.argmin's and max's code would make loading this
        for u in range(1, n_threads):  # kernel import numba.np.arraymath (and its linalg)
            if load[u] < load[t]:
                t = u
        owner[task] = t
        load[t] += PAIR_COST if task < n_pairs else 1.0
    span = 0.0
    for u in range(n_threads):
        span = max(span, load[u])
    return span


@jit
def batch_plan(n_runs, n_threads):  # type: ignore[no-untyped-def]
    """(owner, n_pairs): rows 2q and 2q + 1 are task q for q < n_pairs, row n_pairs + q is task q
    alone after them; owner[q] is the thread (0 … n_threads − 1) that runs task q. Of the plans
    with up to `n_threads` pairs split into single rows, the one that ends soonest (ties: more
    pairs)."""
    n_threads = max(1, min(n_threads, n_runs))
    most = n_runs // 2
    trial = np.empty(n_runs, np.int64)
    best_owner = np.empty(n_runs, np.int64)
    best_pairs, best_span = most, np.inf
    for n_pairs in range(most, max(-1, most - n_threads - 1), -1):
        span = _makespan(n_pairs, n_runs - 2 * n_pairs, n_threads, trial)
        if span < best_span - 1e-9:
            best_pairs, best_span = n_pairs, span
            best_owner[:] = trial
    return best_owner[: n_runs - best_pairs], best_pairs


@jit(inline=True)
def planned_task(task, n_pairs):  # type: ignore[no-untyped-def]
    """Task `task` of a `batch_plan` with `n_pairs` pairs: (its first row, whether it is a pair)."""
    pair = task < n_pairs
    return (2 * task if pair else n_pairs + task), pair

