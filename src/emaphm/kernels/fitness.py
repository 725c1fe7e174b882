"""The identification fitness fused into the LF population kernel (paper eq. 3, DESIGN §5).

`fitness_lf_many` runs, per parameter row and in parallel (pairs of rows and single rows shared
among the threads, `batches.batch_plan`), what the
Python path does in three steps (`monitor.simulate_lf_many`, `signals.lowpass`, `Fitness`):

1. the LF simulation (`monitor.simulate_lf`) into a per-row buffer;
2. the zero-phase low-pass of the comparison pipeline, exactly as
   ``scipy.signal.sosfiltfilt(sos, x)`` with its defaults: odd extension by `pad` samples at each
   end, every section's state started at ``sosfilt_zi(sos)`` times the first extended sample, the
   forward pass, the backward pass started at ``zi`` times the last forward output, the trim;
3. eq. (3), Σ_t w_t·(I_ref,t − I_t)² against the filtered reference, summed in numpy's pairwise
   order (`pairwise_sum`), so the result is the same number ``np.sum(w * r**2, axis=-1)`` gives.

Every operation is the one scipy's `_sosfilt` (direct form II transposed) and numpy perform, in
the same order and without fastmath, so the fitness equals the Python path's to the last bit on
the machines measured (the tests require 1e-12 relative). Rows are independent: the result does
not depend on the number of threads. A row whose LF current is not finite gets NaN.

The filter is a chain of dependent multiply-adds (≈ 6.5 ns per sample and pass, against ≈ 43 ns
per sample for the LF run itself): each thread filters two rows at once, interleaved, so that the
two chains overlap (measured 131 µs per row alone, 79 µs per row in pairs, 10001 samples), and
four, two of its pairs, where it has them (machine G: 4 rows 132 µs as two pairs, 73 µs at once;
issue 36, eighteenth session).

The filter (`sos`, `zi`, `pad`) is designed in Python (`signals.comparison_filter`) once per
identification and passed in. `sosfiltfilt_many` and `sosfiltfilt_one` are the same filter
alone, for `signals.lowpass`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import get_num_threads, prange

from ._jit import jit
from .batches import NONE, PAIR, QUAD, thread_jobs
from .monitor import NO_AUX, simulate_lf, simulate_lf2

PW_BLOCKSIZE = 128  # numpy's pairwise-summation block (PW_BLOCKSIZE in loops_utils.h.src)


@jit
def block_sum(a, lo, n):  # type: ignore[no-untyped-def]
    """Σ a[lo:lo+n], n ≤ `PW_BLOCKSIZE`, as numpy's pairwise sum does one block.

    Below 8 terms a plain loop; else eight interleaved partial sums combined as
    ((r0+r1)+(r2+r3))+((r4+r5)+(r6+r7)), then the remainder added one by one.
    """
    if n < 8:
        res = 0.0
        for i in range(lo, lo + n):
            res += a[i]
        return res
    r0 = a[lo]
    r1 = a[lo + 1]
    r2 = a[lo + 2]
    r3 = a[lo + 3]
    r4 = a[lo + 4]
    r5 = a[lo + 5]
    r6 = a[lo + 6]
    r7 = a[lo + 7]
    end = lo + n - n % 8
    i = lo + 8
    while i < end:
        r0 += a[i]
        r1 += a[i + 1]
        r2 += a[i + 2]
        r3 += a[i + 3]
        r4 += a[i + 4]
        r5 += a[i + 5]
        r6 += a[i + 6]
        r7 += a[i + 7]
        i += 8
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < lo + n:
        res += a[i]
        i += 1
    return res


# pairwise_sum's explicit stack: frames of (lo, n, n2, stage, left), STACK_DEPTH of each (depth
# ≤ log2(n / 64) + 1); the caller gives it as scratch (`stack_for`), for a kernel that allocates
# nothing loads without numba's array module (numba.np.arrayobj and the modules it imports: about
# 20 ms of a diagnosis's start, issue 36)
STACK_DEPTH = 64
STACK_SIZE = 5 * STACK_DEPTH


def stack_for(n_threads: int = 1) -> np.ndarray:
    """Scratch for `pairwise_sum_into`: one row of `STACK_SIZE` per thread."""
    return np.empty((max(int(n_threads), 1), STACK_SIZE))


def pairwise_sum(a: np.ndarray, lo: int, n: int) -> float:
    """Σ a[lo:lo+n] in numpy's pairwise order (`pairwise_sum_into` with its own scratch)."""
    return float(pairwise_sum_into(a, lo, n, stack_for()[0]))


@jit
def pairwise_sum_into(a, lo, n, stack):  # type: ignore[no-untyped-def]
    """Σ a[lo:lo+n] in numpy's pairwise order (`np.add.reduce` along a contiguous float64 axis).

    numpy sums a block of ≤ `PW_BLOCKSIZE` terms by `block_sum`, and a longer span as the sum of its
    two halves (the first a multiple of 8 long), recursively. The recursion runs here on an explicit
    stack (numba's cache cannot reload recursive functions) kept in `stack` (≥ `STACK_SIZE` floats;
    the frames' integers are held as floats, exact below 2⁵³): frame d covers [lo_d, lo_d + n_d),
    split at n2_d; stage 1 waits for its left half, stage 2 holds it in left_d and waits for the right.
    """
    if n <= PW_BLOCKSIZE:
        return block_sum(a, lo, n)
    f_lo = stack[0:STACK_DEPTH]
    f_n = stack[STACK_DEPTH : 2 * STACK_DEPTH]
    f_n2 = stack[2 * STACK_DEPTH : 3 * STACK_DEPTH]
    f_stage = stack[3 * STACK_DEPTH : 4 * STACK_DEPTH]
    f_left = stack[4 * STACK_DEPTH : 5 * STACK_DEPTH]
    d = 0
    f_lo[0] = lo
    f_n[0] = n
    while True:
        if f_n[d] > PW_BLOCKSIZE:  # descend into the left half
            n2 = int(f_n[d]) // 2
            n2 -= n2 % 8
            f_n2[d] = n2
            f_stage[d] = 1.0
            f_lo[d + 1] = f_lo[d]
            f_n[d + 1] = n2
            d += 1
            continue
        val = block_sum(a, int(f_lo[d]), int(f_n[d]))
        while True:  # hand val up until a frame still needs its right half
            if d == 0:
                return val
            d -= 1
            if f_stage[d] == 1.0:
                f_left[d] = val
                f_stage[d] = 2.0
                f_lo[d + 1] = f_lo[d] + f_n2[d]
                f_n[d + 1] = f_n[d] - f_n2[d]
                d += 1
                break
            val = f_left[d] + val


@jit(inline=True)
def biquad_step(x, b0, b1, b2, a1, a2, z0, z1):  # type: ignore[no-untyped-def]
    """One sample x through a second-order section (b0, b1, b2, 1, a1, a2) in direct form II
    transposed with the state (z0, z1): scipy's `_sosfilt`. Returns (y, new z0, new z1)."""
    y = b0 * x + z0
    return y, b1 * x - a1 * y + z1, b2 * x - a2 * y


@jit
def biquad_pass(e, f, start, stop, step, section, ze0, ze1, zf0, zf1):  # type: ignore[no-untyped-def]
    """One second-order section (b0, b1, b2, 1, a1, a2) over e[start], e[start+step], … (not
    e[stop]), in place, and the same over f: two independent signals, interleaved so that their
    dependency chains overlap (`biquad_step`), with initial states (ze0, ze1) and (zf0, zf1)."""
    b0, b1, b2, a1, a2 = section[0], section[1], section[2], section[4], section[5]
    for k in range(start, stop, step):
        e[k], ze0, ze1 = biquad_step(e[k], b0, b1, b2, a1, a2, ze0, ze1)
        f[k], zf0, zf1 = biquad_step(f[k], b0, b1, b2, a1, a2, zf0, zf1)


@jit
def odd_extend(e, pad):  # type: ignore[no-untyped-def]
    """Fill e[:pad] and e[-pad:] with sosfiltfilt's odd extension of x = e[pad:len(e)-pad]:
    2·x[0] − x[pad−j] on the left, 2·x[−1] − x[−2−j] on the right."""
    n = e.shape[0] - 2 * pad
    x_first = e[pad]
    x_last = e[pad + n - 1]
    for j in range(pad):
        e[j] = 2.0 * x_first - e[2 * pad - j]
        e[pad + n + j] = 2.0 * x_last - e[pad + n - 2 - j]


@jit
def sosfiltfilt_inplace(e, f, pad, sos, zi):  # type: ignore[no-untyped-def]
    """``sosfiltfilt(sos, x)`` in place for two signals of one length, x = e[pad:len(e)-pad] and
    the same in f (the pads are overwritten).

    e and f hold x with `pad` free samples on each side (len − 2·pad > pad). Afterwards
    e[pad:len(e)-pad] is the filtered x. The sections are applied one after the other over the
    whole buffer, which gives the same numbers as scipy's sample-by-sample cascade.
    """
    m = e.shape[0]
    odd_extend(e, pad)
    odd_extend(f, pad)
    xe = e[0]
    xf = f[0]
    for s in range(sos.shape[0]):  # forward, every state started at zi·(first sample)
        biquad_pass(e, f, 0, m, 1, sos[s], zi[s, 0] * xe, zi[s, 1] * xe, zi[s, 0] * xf, zi[s, 1] * xf)
    ye = e[m - 1]
    yf = f[m - 1]
    for s in range(sos.shape[0]):  # backward, started at zi·(last forward output)
        biquad_pass(e, f, m - 1, -1, -1, sos[s], zi[s, 0] * ye, zi[s, 1] * ye, zi[s, 0] * yf, zi[s, 1] * yf)


@jit
def biquad_pass4(e, f, g, h, start, stop, step, section, ze0, ze1, zf0, zf1, zg0, zg1, zh0, zh1):  # type: ignore[no-untyped-def]
    """`biquad_pass` over four signals interleaved (each signal's operations `biquad_step`'s, in
    its order): four dependency chains overlap where two left the core waiting."""
    b0, b1, b2, a1, a2 = section[0], section[1], section[2], section[4], section[5]
    for k in range(start, stop, step):
        e[k], ze0, ze1 = biquad_step(e[k], b0, b1, b2, a1, a2, ze0, ze1)
        f[k], zf0, zf1 = biquad_step(f[k], b0, b1, b2, a1, a2, zf0, zf1)
        g[k], zg0, zg1 = biquad_step(g[k], b0, b1, b2, a1, a2, zg0, zg1)
        h[k], zh0, zh1 = biquad_step(h[k], b0, b1, b2, a1, a2, zh0, zh1)


@jit
def sosfiltfilt_inplace4(e, f, g, h, pad, sos, zi):  # type: ignore[no-untyped-def]
    """`sosfiltfilt_inplace` for four signals of one length at once (`biquad_pass4`): each
    signal's numbers those of `sosfiltfilt_inplace`."""
    m = e.shape[0]
    odd_extend(e, pad)
    odd_extend(f, pad)
    odd_extend(g, pad)
    odd_extend(h, pad)
    xe, xf, xg, xh = e[0], f[0], g[0], h[0]
    for s in range(sos.shape[0]):  # forward, every state started at zi·(first sample)
        z0, z1 = zi[s, 0], zi[s, 1]
        biquad_pass4(e, f, g, h, 0, m, 1, sos[s], z0 * xe, z1 * xe, z0 * xf, z1 * xf, z0 * xg, z1 * xg, z0 * xh, z1 * xh)
    ye, yf, yg, yh = e[m - 1], f[m - 1], g[m - 1], h[m - 1]
    for s in range(sos.shape[0]):  # backward, started at zi·(last forward output)
        z0, z1 = zi[s, 0], zi[s, 1]
        biquad_pass4(e, f, g, h, m - 1, -1, -1, sos[s], z0 * ye, z1 * ye, z0 * yf, z1 * yf, z0 * yg, z1 * yg,
                     z0 * yh, z1 * yh)  # fmt: skip


def sosfiltfilt_one(x: np.ndarray, sos: np.ndarray, zi: np.ndarray, pad: int, out: np.ndarray) -> None:
    """``out = sosfiltfilt(sos, x)`` for one signal x (n > pad), serially: the numbers of
    `sosfiltfilt_many`'s rows (paired with a zero signal), without a parallel launch."""
    sosfiltfilt_one_kernel(x, sos, zi, pad, out, np.zeros((2, x.shape[0] + 2 * pad)))


@jit
def sosfiltfilt_one_kernel(x, sos, zi, pad, out, buf):  # type: ignore[no-untyped-def]
    """`sosfiltfilt_one` in the caller's zeroed buffer buf (2, n + 2·pad)."""
    n = x.shape[0]
    for k in range(n):  # loops, not slice assignments: those make a load import numba's array module
        buf[0, pad + k] = x[k]
    sosfiltfilt_inplace(buf[0], buf[1], pad, sos, zi)
    for k in range(n):
        out[k] = buf[0, pad + k]


def sosfiltfilt_many(x: np.ndarray, sos: np.ndarray, zi: np.ndarray, pad: int, out: np.ndarray) -> None:
    """``out[r] = sosfiltfilt(sos, x[r])`` for every row r of x (shape (m, n), n > pad), in parallel:
    rows 2q and 2q + 1 on one thread, filtered interleaved (`sosfiltfilt_inplace`); an odd last
    row is paired with a zero signal."""
    m, n = x.shape
    sosfiltfilt_many_kernel(x, sos, zi, pad, out, np.zeros(((m + 1) // 2, 2, n + 2 * pad)))


@jit(parallel=True)
def sosfiltfilt_many_kernel(x, sos, zi, pad, out, work):  # type: ignore[no-untyped-def]
    """`sosfiltfilt_many` with the pairs' zeroed buffers work ((m + 1) // 2, 2, n + 2·pad)."""
    m, n = x.shape
    for q in prange((m + 1) // 2):
        r = 2 * q
        pair = r + 1 < m
        buf = work[q]
        for k in range(n):
            buf[0, pad + k] = x[r, k]
        if pair:
            for k in range(n):
                buf[1, pad + k] = x[r + 1, k]
        sosfiltfilt_inplace(buf[0], buf[1], pad, sos, zi)
        for k in range(n):
            out[r, k] = buf[0, pad + k]
        if pair:
            for k in range(n):
                out[r + 1, k] = buf[1, pad + k]


@jit
def all_finite(e, lo, hi):  # type: ignore[no-untyped-def]
    """Whether e[lo:hi] holds only finite numbers."""
    for k in range(lo, hi):
        if not math.isfinite(e[k]):
            return False
    return True


@jit
def weighted_sum(e, pad, ref, weights, stack):  # type: ignore[no-untyped-def]
    """Σ weights·(ref − e[pad:len(e)-pad])² in numpy's order (e[:len(e)-2·pad] is overwritten;
    `stack`: `pairwise_sum_into`'s scratch)."""
    n = e.shape[0] - 2 * pad
    for k in range(n):  # e[k] ← w·r² reads e[pad + k] ≥ k: in place
        r = ref[k] - e[pad + k]
        e[k] = weights[k] * (r * r)
    return pairwise_sum_into(e, 0, n, stack)


@jit
def filtered_fitness(e, f, pad, sos, zi, ref, weights, stack):  # type: ignore[no-untyped-def]
    """eq. (3) of the currents x = e[pad:len(e)-pad] and the same in f (unfiltered; both are
    overwritten): the filter of `sosfiltfilt_inplace`, then Σ weights·(ref − filtered x)² in
    numpy's order (`stack`: `pairwise_sum_into`'s scratch). NaN for a current that is not finite."""
    n = e.shape[0] - 2 * pad
    finite_e = all_finite(e, pad, pad + n)
    finite_f = all_finite(f, pad, pad + n)
    sosfiltfilt_inplace(e, f, pad, sos, zi)
    fit_e = weighted_sum(e, pad, ref, weights, stack) if finite_e else np.nan
    fit_f = weighted_sum(f, pad, ref, weights, stack) if finite_f else np.nan
    return fit_e, fit_f


@jit
def filtered_fitness4(e, f, g, h, pad, sos, zi, ref, weights, stack):  # type: ignore[no-untyped-def]
    """`filtered_fitness` of four currents at once (their filters interleaved,
    `sosfiltfilt_inplace4`): each one's number `filtered_fitness`'s."""
    n = e.shape[0] - 2 * pad
    finite = (all_finite(e, pad, pad + n), all_finite(f, pad, pad + n), all_finite(g, pad, pad + n),
              all_finite(h, pad, pad + n))  # fmt: skip
    sosfiltfilt_inplace4(e, f, g, h, pad, sos, zi)
    return (
        weighted_sum(e, pad, ref, weights, stack) if finite[0] else np.nan,
        weighted_sum(f, pad, ref, weights, stack) if finite[1] else np.nan,
        weighted_sum(g, pad, ref, weights, stack) if finite[2] else np.nan,
        weighted_sum(h, pad, ref, weights, stack) if finite[3] else np.nan,
    )


@jit
def simulate_pair(theta_cmd, prm, r, pair, pad, buf, no_aux):  # type: ignore[no-untyped-def]
    """LF runs of rows r and, with `pair`, r + 1 of `prm` into buf (2 rows of len(theta_cmd) + 2·pad
    samples), each current at [pad, pad + n) (the pads are the filter's to fill); without `pair`
    the second row is zeros (a partner for the interleaved filter). no_aux: an empty (0, N_AUX)."""
    n = theta_cmd.shape[0]
    if pair:  # the two runs interleaved (`simulate_lf2`: the same currents, to the bit)
        simulate_lf2(theta_cmd, prm[r], prm[r + 1], buf[0, pad : pad + n], buf[1, pad : pad + n], no_aux)
    else:
        simulate_lf(theta_cmd, prm[r], buf[0, pad : pad + n], no_aux)
        for k in range(buf.shape[1]):
            buf[1, k] = 0.0


def _buffers(prm: np.ndarray, n: int, pad: int, n_threads: int | None) -> tuple[np.ndarray, np.ndarray]:
    """What a fused kernel's call takes besides its data: each thread's jobs
    (`batches.thread_jobs` for numba's thread count, ``numba.get_num_threads()``, asked here: a
    kernel that asks numba itself cannot be cached) and a buffer of 4 × (n + 2·pad) per thread
    (two pairs' currents, filtered at once). Allocated here, not in the kernels: a kernel that
    allocates loads with numba's array module (`STACK_SIZE`'s note)."""
    n_threads = get_num_threads() if n_threads is None else int(n_threads)
    jobs = thread_jobs(prm.shape[0], n_threads)
    return jobs, np.empty((jobs.shape[0], 4, n + 2 * pad))


@jit
def run_job(theta_cmd, prm, pad, buf, job, no_aux):  # type: ignore[no-untyped-def]
    """The monitor runs of one job (`batches.thread_jobs`) into buf (4 rows of len(theta_cmd) +
    2·pad): a quad's two pairs in rows 0-1 and 2-3, a pair or a row alone (beside zeros) in rows
    0-1 (`simulate_pair`). Returns the job (kind, a, b)."""
    kind, a, b = job[0], job[1], job[2]
    if kind == QUAD:
        simulate_pair(theta_cmd, prm, a, True, pad, buf[0:2], no_aux)
        simulate_pair(theta_cmd, prm, b, True, pad, buf[2:4], no_aux)
    elif kind != NONE:
        simulate_pair(theta_cmd, prm, a, kind == PAIR, pad, buf[0:2], no_aux)
    return kind, a, b


def fitness_lf_many(theta_cmd: np.ndarray, prm: np.ndarray, sos: np.ndarray, zi: np.ndarray, pad: int,
                    ref: np.ndarray, weights: np.ndarray, out: np.ndarray, n_threads: int | None = None) -> None:  # fmt: skip
    """eq. (3) of one LF run per row of `prm` (shape (n_runs, N_FIELDS)) into out (n_runs,), in parallel.

    = Σ weights·(ref − sosfiltfilt(sos, simulate_lf(row)))² per row; ref and weights have the
    length of theta_cmd; zi = sosfilt_zi(sos); pad = sosfiltfilt's default padlen. The rows go in
    pairs (rows 2q and 2q + 1 on one thread) whose filters run interleaved, some rows alone where
    that shares the batch better among the threads (`batches.batch_plan`); a row alone is
    filtered beside a zero signal. `n_threads`: the threads numba runs it on (default
    ``numba.get_num_threads()``).
    """
    jobs, work = _buffers(prm, theta_cmd.shape[0], pad, n_threads)
    fitness_lf_kernel(theta_cmd, prm, sos, zi, pad, ref, weights, out, jobs, work, stack_for(jobs.shape[0]), NO_AUX)


@jit(parallel=True)
def fitness_lf_kernel(theta_cmd, prm, sos, zi, pad, ref, weights, out, jobs, work, stacks, no_aux):  # type: ignore[no-untyped-def]
    """`fitness_lf_many` with its jobs and buffers (`_buffers`): thread t runs jobs[t] in work[t],
    with stacks[t]; a quad's four currents are filtered at once (`filtered_fitness4`), a pair's
    two or a row alone beside zeros (`filtered_fitness`)."""
    for t in prange(jobs.shape[0]):
        buf = work[t]
        for j in range(jobs.shape[1]):
            kind, a, b = run_job(theta_cmd, prm, pad, buf, jobs[t, j], no_aux)
            if kind == QUAD:
                out[a], out[a + 1], out[b], out[b + 1] = filtered_fitness4(
                    buf[0], buf[1], buf[2], buf[3], pad, sos, zi, ref, weights, stacks[t]
                )
            elif kind != NONE:
                fit_0, fit_1 = filtered_fitness(buf[0], buf[1], pad, sos, zi, ref, weights, stacks[t])
                out[a] = fit_0
                if kind == PAIR:
                    out[a + 1] = fit_1


def residuals_lf_many(theta_cmd: np.ndarray, prm: np.ndarray, sos: np.ndarray, zi: np.ndarray, pad: int,
                      keep: np.ndarray, ref_keep: np.ndarray, root_w: np.ndarray, out: np.ndarray,
                      n_threads: int | None = None) -> None:  # fmt: skip
    """eq. (3)'s residual vector of one LF run per row of `prm` into out (n_runs, len(keep)), in
    parallel: out[r] = root_w·(ref_keep − sosfiltfilt(sos, simulate_lf(row))[keep]).

    The least squares' view of `fitness_lf_many` (Σ out[r]² is its eq. 3 to rounding): the same
    runs and filter, rows shared among the threads alike (`batches.batch_plan`: two rows on two
    threads run one on each, so a least-squares descent's trial point and its spare,
    `identification.lm`, cost one row's time), the same numbers as filtering the currents of
    `monitor.simulate_lf_many` by `sosfiltfilt_many` and taking the residual in numpy. A row whose
    LF current is not finite gets NaN residuals. `n_threads` as in `fitness_lf_many`.
    """
    jobs, work = _buffers(prm, theta_cmd.shape[0], pad, n_threads)
    residuals_lf_kernel(theta_cmd, prm, sos, zi, pad, keep, ref_keep, root_w, out, jobs, work, NO_AUX)


@jit(parallel=True)
def residuals_lf_kernel(theta_cmd, prm, sos, zi, pad, keep, ref_keep, root_w, out, jobs, work, no_aux):  # type: ignore[no-untyped-def]
    """`residuals_lf_many` with its jobs and buffers (`_buffers`), a quad's four currents filtered
    at once as in `fitness_lf_kernel`."""
    for t in prange(jobs.shape[0]):
        buf = work[t]
        for j in range(jobs.shape[1]):
            kind, a, b = run_job(theta_cmd, prm, pad, buf, jobs[t, j], no_aux)
            if kind == QUAD:
                sosfiltfilt_inplace4(buf[0], buf[1], buf[2], buf[3], pad, sos, zi)
                for q, r in enumerate((a, a + 1, b, b + 1)):
                    kept_residuals(buf[q], pad, keep, ref_keep, root_w, out[r])
            elif kind != NONE:
                sosfiltfilt_inplace(buf[0], buf[1], pad, sos, zi)
                kept_residuals(buf[0], pad, keep, ref_keep, root_w, out[a])
                if kind == PAIR:
                    kept_residuals(buf[1], pad, keep, ref_keep, root_w, out[a + 1])


@jit
def kept_residuals(e, pad, keep, ref_keep, root_w, out):  # type: ignore[no-untyped-def]
    """out = root_w·(ref_keep − e[pad + keep]): eq. 3's residual of one filtered current."""
    for j in range(keep.shape[0]):
        out[j] = root_w[j] * (ref_keep[j] - e[pad + keep[j]])
