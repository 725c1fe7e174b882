"""The fused population fitness (kernels.fitness): the same numbers as the Python path
(LF population kernel, scipy's sosfiltfilt, eq. 3 in numpy), on any number of threads."""

import numba
import numpy as np
import pytest
from scipy.signal import butter, sosfilt_zi, sosfiltfilt

from emaphm import MonitorEma
from emaphm._threads import numba_threads
from emaphm.identification.fitness import Fitness
from emaphm.identification.identifier import FaultIdentifier
from emaphm.identification.signals import Comparison, sosfiltfilt_padlen
from emaphm.kernels.fitness import (
    filtered_fitness,
    fitness_lf_many,
    pairwise_sum,
    residuals_lf_many,
    stack_for,
)
from emaphm.kernels.monitor import IDX

# measured on x86-64 (numpy 2.4, scipy 1.17, numba 0.68): bit-identical. The tolerance leaves
# room for a platform whose scipy build fuses multiply-adds (FMA); a wrong pad, extension, initial
# state or weight is off by > 1e-6 relative
RTOL = 1e-12


@pytest.mark.parametrize("n", [*range(1, 300, 7), 1000, 1023, 1024, 1025, 9997, 10001, 65537])
def test_pairwise_sum_is_numpys_sum(n):
    # numpy's order: blocks of 8 partial sums up to 128 terms, halves (multiples of 8) above.
    # Terms over 12 decades, so that another order (a plain loop, other splits) changes the last bits
    rng = np.random.default_rng(n)
    a = rng.normal(size=n) * 10.0 ** rng.uniform(-6, 6, n)
    padded = np.concatenate([rng.normal(size=3), a])
    assert pairwise_sum(a, 0, n) == np.sum(a)
    assert pairwise_sum(padded, 3, n) == np.sum(a)  # an offset start


def test_a_plain_loop_would_not_pass_the_pairwise_test():
    # the test above can fail: for these sizes a left-to-right sum differs from numpy's
    differs = 0
    for n in (129, 1000, 9997, 10001):
        rng = np.random.default_rng(n)
        a = rng.normal(size=n) * 10.0 ** rng.uniform(-6, 6, n)
        plain = 0.0
        for v in a:
            plain += v
        differs += plain != np.sum(a)
    assert differs >= 3


@pytest.mark.parametrize("f_s", [1e4, 3e3])
@pytest.mark.parametrize("n", [20, 500, 9997, 10001])
def test_filter_and_sum_equal_scipy_and_numpy(f_s, n):
    sos = butter(2, 150, fs=f_s, output="sos")
    pad = sosfiltfilt_padlen(sos)
    assert pad == 9  # one biquad: 3 x (2·1 + 1) taps
    rng = np.random.default_rng(n)
    ref = sosfiltfilt(sos, np.cumsum(rng.normal(size=n)) * 0.05)
    weights = rng.uniform(0.05, 1.0, n)
    # random walks plus white noise, with starts and ends far from zero (the odd extension and the
    # initial states sosfilt_zi·x then matter); the kernel filters two signals at once
    x = 3.0 + np.cumsum(rng.normal(size=(2, n)), axis=1) * 0.05 + rng.normal(size=(2, n))
    e = np.empty((2, n + 2 * pad))
    e[:, pad : pad + n] = x
    got = filtered_fitness(e[0], e[1], pad, sos, sosfilt_zi(sos), ref, weights, stack_for()[0])
    want = np.sum(weights * (ref - sosfiltfilt(sos, x)) ** 2, axis=-1)
    np.testing.assert_allclose(got, want, rtol=RTOL, atol=0)
    assert got[0] != got[1]


@pytest.mark.parametrize("where", [0, 250, 499])
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_a_non_finite_current_gives_a_non_finite_fitness(where, bad):
    n, pad = 500, 9
    sos = butter(2, 150, fs=1e4, output="sos")
    x = np.sin(np.arange(n) / 50.0)
    e = np.zeros((2, n + 2 * pad))
    e[:, pad : pad + n] = x
    e[0, pad + where] = bad
    for first in (0, 1):  # the broken signal as the first or the second of the pair
        pair = e[[first, 1 - first]].copy()
        got = filtered_fitness(pair[0], pair[1], pad, sos, sosfilt_zi(sos), np.zeros(n), np.ones(n), stack_for()[0])
        assert not np.isfinite(got[first])
        assert got[1 - first] == pytest.approx(np.sum(sosfiltfilt(sos, x) ** 2), rel=RTOL)  # untouched


def monitor_reference(lf, k, noise, duration=None):
    res = lf.simulate(k, noise=noise, seed=3, duration=duration)
    return Comparison.from_signal(res.t, res.i_q, lf.params.controller.f_s)


def three_khz_reference(lf, k):
    # a measured trace at 3 kHz over 1 s (last sample 0.99967 s): the model grid is 9997 samples
    res = lf.simulate(k, noise=True, seed=4)
    t_src = np.arange(3000) / 3e3
    grid, _ = lf.sample_grid(t_src[-1])
    return Comparison.from_trace(t_src, np.interp(t_src, res.t, res.i_q), grid, lf.params.controller.f_s)


CASES = {  # name: (reference builder, duration, samples)
    "noise off, 10001": (lambda lf, k: monitor_reference(lf, k, False), None, 10001),
    "noise on, 10001": (lambda lf, k: monitor_reference(lf, k, True), None, 10001),
    "3 kHz trace, 9997": (three_khz_reference, 2999 / 3e3, 9997),
    "noise on, 500": (lambda lf, k: monitor_reference(lf, k, True, 0.0499), 0.0499, 500),
    "noise off, 500": (lambda lf, k: monitor_reference(lf, k, False, 0.0499), 0.0499, 500),
}


@pytest.mark.parametrize("slope_unit", ["s", "ms"])
@pytest.mark.parametrize("case", CASES)
def test_fused_fitness_equals_the_python_path(case, slope_unit):
    build, duration, samples = CASES[case]
    lf = MonitorEma()
    rng = np.random.default_rng(len(case))
    reference = build(lf, rng.uniform(0, 0.6, 8))
    assert len(reference.t) == samples
    fitness = Fitness(reference, slope_unit)
    K = rng.uniform(0, 1, (13, 8))  # an odd number: the kernel pairs rows
    K[0] = [0.2, 0.5, 0.0, 0.45, 0.04, 0.0, 0.28, 0.5]  # near a realistic fit: small residuals
    got = fitness.of_monitor(lf, K, duration=duration)
    want = fitness(lf.simulate_many(K, duration=duration, check=False))
    assert got.shape == (13,) and np.all(np.isfinite(want))
    np.testing.assert_allclose(got, want, rtol=RTOL, atol=0)


def test_fused_fitness_needs_the_reference_grid():
    lf = MonitorEma()
    fitness = Fitness(monitor_reference(lf, np.zeros(8), False, 0.0499))
    with pytest.raises(ValueError, match="500"):
        fitness.of_monitor(lf, np.zeros((2, 8)), duration=0.1)


def population(n_rows=23, duration=0.2):
    """(θ_cmd, LF rows, their fault rows K, Fitness) of random rows against a noisy reference."""
    lf = MonitorEma()
    fitness = Fitness(monitor_reference(lf, [0.2, 0.5, 0, 0.45, 0.04, 0, 0.28, 0.5], True, duration))
    _, theta_cmd = lf.sample_grid(duration)
    K = np.random.default_rng(5).uniform(0, 1, (n_rows, 8))
    return theta_cmd, lf.rows(K), K, fitness


def run_kernel(theta_cmd, rows, fitness):
    out = np.full(rows.shape[0], -1.0)
    f = fitness
    fitness_lf_many(theta_cmd, rows, f.sos, f.zi, f.padlen, f.comparison.reference, f.weights, out, numba.get_num_threads())
    return out


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="needs 2 numba threads")
def test_same_numbers_on_one_and_two_threads():
    theta_cmd, rows, K, fitness = population()
    results = []
    for threads in (1, 2, 1, 2):
        with numba_threads(threads):
            results.append(run_kernel(theta_cmd, rows, fitness))
    for r in results[1:]:
        np.testing.assert_array_equal(r, results[0])
    # and each row as the Python path scores it alone
    want = [fitness(MonitorEma().simulate_many(k[None], duration=0.2)[0]) for k in K]
    np.testing.assert_allclose(results[0], want, rtol=RTOL, atol=0)


def test_a_diverged_row_gets_a_non_finite_fitness_and_the_others_do_not_change():
    theta_cmd, rows, _, fitness = population(n_rows=7)
    clean = run_kernel(theta_cmd, rows, fitness)
    broken = rows.copy()
    broken[1, IDX["J"]] = np.nan  # NaN once static friction breaks (measured: from sample 285 of 2001)
    broken[6, IDX["V_H"]] = 0.0  # tanh((R·i + k_e·ω_m)/V_H) = tanh(0/0): NaN from the first sample on
    got = run_kernel(theta_cmd, broken, fitness)
    assert np.all(np.isfinite(clean))
    assert not np.isfinite(got[1]) and not np.isfinite(got[6])  # 6: the odd row out, paired with zeros
    keep = [0, 2, 3, 4, 5]
    np.testing.assert_array_equal(got[keep], clean[keep])


def test_identification_runs_on_the_fused_kernel(monkeypatch):
    # FaultIdentifier.fit must score its populations by the fused kernel, not the Python path
    def python_path(*args, **kwargs):
        raise AssertionError("the Python fitness path was used")

    monkeypatch.setattr(Fitness, "__call__", python_path)
    monkeypatch.setattr(MonitorEma, "simulate_many", python_path)
    calls = []
    fused = Fitness.of_monitor

    def counted(self, *args, **kwargs):
        calls.append(1)
        return fused(self, *args, **kwargs)

    monkeypatch.setattr(Fitness, "of_monitor", counted)
    res = MonitorEma().simulate([0.3, 0, 0, 0, 0, 0, 0, 0.5], noise=True, duration=0.05)
    ident = FaultIdentifier(seed=1, pop_size=8, generations=2, polish=False)
    ident.fit(res.t, res.i_q)
    assert len(calls) >= 2 and np.isfinite(ident.fitness_)


def python_residuals(fitness, lf, K, duration):
    """eq. 3's residual vectors by the Python path: LF runs, the comparison filter, numpy."""
    keep = np.flatnonzero(fitness.weights > 0)
    filtered = fitness.comparison.filtered(lf.simulate_many(K, duration=duration, check=False))
    return np.sqrt(fitness.weights[keep]) * (fitness.comparison.reference[keep] - filtered[:, keep])


@pytest.mark.parametrize("case", ["noise on, 10001", "3 kHz trace, 9997", "noise off, 500"])
def test_fused_residuals_equal_the_python_path_and_sum_to_the_fitness(case):
    build, duration, samples = CASES[case]
    lf = MonitorEma()
    rng = np.random.default_rng(len(case) + 1)
    reference = build(lf, rng.uniform(0, 0.6, 8))
    mask = (np.arange(samples) % 7 != 3).astype(float)  # samples left out: only the weighed ones come back
    fitness = Fitness(reference, mask=mask)
    K = rng.uniform(0, 1, (9, 8))  # an odd number: the kernel pairs rows
    got = fitness.residuals_of_monitor(lf, K, duration=duration)
    assert got.shape == (9, int(mask.sum()))
    np.testing.assert_array_equal(got, python_residuals(fitness, lf, K, duration))
    np.testing.assert_allclose(np.sum(got**2, axis=1), fitness.of_monitor(lf, K, duration=duration), rtol=1e-12)


def test_two_rows_one_per_thread_give_the_residuals_of_every_batch():
    # two rows run one on each thread (a descent's trial point and its spare), other batches in
    # interleaved pairs: each row's residual is the same to the bit however it is batched
    lf = MonitorEma()
    fitness = Fitness(monitor_reference(lf, [0.2, 0.5, 0, 0.45, 0.04, 0, 0.28, 0.5], True, 0.2))
    K = np.random.default_rng(11).uniform(0, 1, (4, 8))
    whole = fitness.residuals_of_monitor(lf, K, duration=0.2)
    for rows in ([0, 1], [2, 3], [3, 0]):
        np.testing.assert_array_equal(fitness.residuals_of_monitor(lf, K[rows], duration=0.2), whole[rows])
    np.testing.assert_array_equal(fitness.residuals_of_monitor(lf, K[:1], duration=0.2), whole[:1])
    np.testing.assert_array_equal(python_residuals(fitness, lf, K[:2], 0.2), whole[:2])


def test_a_diverged_row_gets_non_finite_residuals_and_the_others_do_not_change():
    lf = MonitorEma()
    fitness = Fitness(monitor_reference(lf, [0.2, 0.5, 0, 0.45, 0.04, 0, 0.28, 0.5], True, 0.2))
    K = np.random.default_rng(6).uniform(0, 1, (5, 8))
    clean = fitness.residuals_of_monitor(lf, K, duration=0.2)
    broken = lf.rows(K)
    broken[4, IDX["V_H"]] = 0.0  # NaN from the first sample on; row 4 is the odd one out
    out = np.empty_like(clean)
    _, theta_cmd = lf.sample_grid(0.2)
    keep = np.flatnonzero(fitness.weights > 0)
    residuals_lf_many(theta_cmd, broken, fitness.sos, fitness.zi, fitness.padlen, keep,
                      fitness.comparison.reference[keep], np.sqrt(fitness.weights[keep]), out, numba.get_num_threads())  # fmt: skip
    assert np.all(np.isfinite(clean)) and np.isnan(out[4]).all()
    np.testing.assert_array_equal(out[:4], clean[:4])
    with pytest.raises(ValueError, match="500"):
        Fitness(monitor_reference(lf, np.zeros(8), False, 0.0499)).residuals_of_monitor(lf, K, duration=0.1)
