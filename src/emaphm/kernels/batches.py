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

import functools
import math

import numpy as np

# a pair of rows on one thread, in single rows' time (machine G: 1.06-1.22 / 0.65-0.77 ms; E: 1.2-1.6)
PAIR_COST = 1.7


def _makespan(n_pairs: int, n_singles: int, n_threads: int, owner: list[int]) -> float:
    """The longest thread's load (in single rows) of `n_pairs` pairs then `n_singles` rows, each
    given to the least loaded thread (the first of equals); `owner` gets each task's thread."""
    load = [0.0] * n_threads
    for task in range(n_pairs + n_singles):
        t = min(range(n_threads), key=load.__getitem__)  # the first of the least loaded
        owner.append(t)
        load[t] += PAIR_COST if task < n_pairs else 1.0
    return max(load)


def batch_plan(n_runs: int, n_threads: int) -> tuple[np.ndarray, int]:
    """(owner, n_pairs): rows 2q and 2q + 1 are task q for q < n_pairs, row n_pairs + q is task q
    alone after them; owner[q] is the thread (0 … n_threads − 1) that runs task q. Of the plans
    with up to `n_threads` pairs split into single rows, the one that ends soonest (ties: more
    pairs). Planned in Python, once per batch size and thread count (a read-only array, shared),
    and passed to the kernels: planned in a kernel, it made the kernel allocate, and a kernel that
    allocates loads with numba's array module (`fitness.STACK_SIZE`'s note)."""
    return _plan(int(n_runs), int(n_threads))


@functools.lru_cache(maxsize=512)
def _plan(n_runs: int, n_threads: int) -> tuple[np.ndarray, int]:
    n_threads = max(1, min(n_threads, n_runs))
    most = n_runs // 2
    best_owner: list[int] = []
    best_pairs, best_span = most, math.inf
    for n_pairs in range(most, max(-1, most - n_threads - 1), -1):
        trial: list[int] = []
        span = _makespan(n_pairs, n_runs - 2 * n_pairs, n_threads, trial)
        if span < best_span - 1e-9:
            best_pairs, best_span, best_owner = n_pairs, span, trial
    owner = np.array(best_owner, dtype=np.int64)
    owner.flags.writeable = False
    return owner, best_pairs


# a thread's job (`thread_jobs`): none (the end of its list), a row alone, a pair, two pairs
NONE, SINGLE, PAIR, QUAD = 0, 1, 2, 4


def planned_task(task: int, n_pairs: int) -> tuple[int, bool]:
    """Task `task` of a `batch_plan` with `n_pairs` pairs: (its first row, whether it is a pair)."""
    pair = task < n_pairs
    return (2 * task if pair else n_pairs + task), pair


def thread_jobs(n_runs: int, n_threads: int) -> np.ndarray:
    """`batch_plan` as each thread's jobs, in order: jobs[t, j] = (kind, a, b), `QUAD` the pairs
    from rows a and b (their four currents filtered at once), `PAIR` rows a and a + 1, `SINGLE`
    row a, `NONE` the end of thread t's list; t runs 0 … max(n_threads, 1) − 1. Two of a thread's
    pairs make a quad, a pair left over stays a pair (a thread's rows alone come after its pairs).
    Which job runs a row does not change its numbers. A read-only array, cached per batch size and
    thread count."""
    return _jobs(int(n_runs), int(n_threads))


@functools.lru_cache(maxsize=512)
def _jobs(n_runs: int, n_threads: int) -> np.ndarray:
    owner, n_pairs = _plan(n_runs, n_threads)
    lists: list[list[tuple[int, int, int]]] = [[] for _ in range(max(n_threads, 1))]
    held = [-1] * len(lists)  # a pair that waits for a second one
    for task, t in enumerate(owner.tolist()):
        r, pair = planned_task(task, n_pairs)
        if pair and held[t] < 0:
            held[t] = r
            continue
        if pair:
            lists[t].append((QUAD, held[t], r))
        else:
            if held[t] >= 0:
                lists[t].append((PAIR, held[t], 0))
            lists[t].append((SINGLE, r, 0))
        held[t] = -1
    for t, r in enumerate(held):
        if r >= 0:
            lists[t].append((PAIR, r, 0))
    jobs = np.zeros((len(lists), max(1, *map(len, lists)), 3), dtype=np.int64)
    for t, items in enumerate(lists):
        if items:
            jobs[t, : len(items)] = items
    jobs.flags.writeable = False
    return jobs
