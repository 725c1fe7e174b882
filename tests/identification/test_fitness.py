"""eq. (3) and the comparison pipeline."""

import numpy as np
import pytest

from emaphm import InputError
from emaphm.commands import Chirp
from emaphm.identification.fitness import Fitness
from emaphm.identification.signals import Comparison, lowpass, nrmse

F_S = 1e4
T = np.arange(5001) / F_S


def test_lowpass_is_zero_phase_and_passes_the_fault_band():
    x = np.sin(2 * np.pi * 40 * T)  # a 2θ_e-like 40 Hz component
    y = lowpass(x, F_S)
    inner = slice(500, -500)
    # forward-backward 2nd-order Butterworth at 150 Hz: gain |H|² = 1/(1 + (40/150)⁴) = 0.995 at
    # 40 Hz, so the error is 0.005 (measured 0.0050) if there is no lag; a one-sample (100 µs)
    # lag alone would add 0.026
    assert np.max(np.abs(y[inner] - x[inner])) < 0.01
    ripple = np.sin(2 * np.pi * 2000 * T)  # hysteresis ripple is removed: |H|² ≈ 3e-5 at 2 kHz
    assert np.max(np.abs(lowpass(ripple, F_S)[inner])) < 1e-4  # measured 1.7e-5


def test_nrmse_definition():
    ref = np.sin(2 * np.pi * 4 * T)  # two whole cycles: zero mean (to one sample)
    assert nrmse(ref, ref) == 0.0
    assert nrmse(ref, np.full_like(ref, ref.mean())) == pytest.approx(1.0)
    assert nrmse(ref, 1.1 * ref) == pytest.approx(0.1, rel=1e-3)


def test_fitness_is_zero_for_a_perfect_match_and_grows_with_error():
    i = 0.3 * np.sin(2 * np.pi * 4 * T)
    f = Fitness(Comparison.from_signal(T, i, F_S))
    assert f(i) == pytest.approx(0.0, abs=1e-20)
    errs = f(np.stack([i + 0.01, i + 0.02]))
    assert errs[1] == pytest.approx(4 * errs[0], rel=1e-6)  # quadratic in the residual


def test_slope_weighting_discounts_steep_samples():
    # the same residual counts less where the measured current is steep (A/s)
    i = np.where(T < 0.25, 0.0, 1.0) * 0.5  # a step: steep after filtering
    f = Fitness(Comparison.from_signal(T, i, F_S))
    steep = int(np.argmin(f.weights))
    assert f.weights[steep] < 0.1 and f.weights[100] == pytest.approx(1.0)
    assert Fitness(Comparison.from_signal(T, i, F_S), "ms").weights.min() > 0.9  # A/ms: ~plain LS
    with pytest.raises(InputError, match="slope unit"):
        Fitness(Comparison.from_signal(T, i, F_S), "h")


def test_reference_on_another_grid_is_interpolated():
    # a 3 kHz trace (its samples fall between the 10 kHz model samples) of a 3 Hz + 40 Hz signal:
    # the reference must equal the exact signal sampled on the model grid, through the same filter.
    # Measured max |difference| 1.2e-4 over the whole grid (linear interpolation error); the
    # tolerance 1e-3 (of a ~1.2 A peak) is 8x that, and 10x below what a zero-order hold (1.0e-2)
    # or a one-sample shift of the source (2.3e-2) gives
    def signal(t):
        return np.sin(2 * np.pi * 3 * t) + 0.2 * np.sin(2 * np.pi * 40 * t)

    t_src = np.arange(1502) / 3e3  # 0..0.5003 s
    c = Comparison.from_trace(t_src, signal(t_src), T, F_S)
    assert c.reference.shape == T.shape
    np.testing.assert_allclose(c.reference, lowpass(signal(T), F_S), rtol=0, atol=1e-3)
    with pytest.raises(InputError, match="covers"):
        Comparison.from_trace(t_src[:100], np.zeros(100), T, F_S)


def test_the_moving_mask_leaves_out_a_park_and_the_rests_of_a_staircase():
    from emaphm.commands import ChirpHold, Steps
    from emaphm.identification.weights import PARK_SETTLE_S, REST_BAND, moving_mask

    f_s = 1e4
    t = np.arange(20001) / f_s
    hold = ChirpHold()(t)  # the chirp to 1 s, back to zero by 1.05 s, then held (a park)
    stop = 1.05 + PARK_SETTLE_S
    at_rest = 0.3 * REST_BAND * np.sin(2 * np.pi * 50 * t)  # noise within the band
    slipping = at_rest + np.where(t > 1.2, 100 * REST_BAND * (t - 1.2), 0.0)  # 5 bands per 50 ms
    for position in (None, at_rest, slipping):  # a park is left out whatever the surface does
        m = moving_mask(hold, f_s, theta_u=position)
        assert np.all(m[t <= stop] == 1.0) and np.all(m[t > stop + 2e-4] == 0.0)
    assert np.all(moving_mask(Chirp()(t), f_s) == 1.0)  # a chirp never holds
    # steps of 0.2 s: without a position the dwells stay whole (the surface hunts through them);
    # with it, a dwell is cut only where the surface rests, 50 ms after the step
    steps = Steps(dwell=0.2)(t)
    assert np.all(moving_mask(steps, f_s) == 1.0)
    hunting = 3 * REST_BAND * np.sin(2 * np.pi * 20 * t)
    assert np.all(moving_mask(steps, f_s, theta_u=hunting) == 1.0)
    resting = moving_mask(steps, f_s, theta_u=np.zeros_like(t))
    assert 0.2 < resting.mean() < 0.3 and np.all(resting[(t > 0.2) & (t <= 0.25)] == 1.0)


def test_the_moving_mask_leaves_out_rests_whose_current_is_below_the_ring_edge():
    from emaphm.commands import Chirp, Steps
    from emaphm.identification.weights import HOLD_SETTLE_S, REST_SETTLE_S, moving_mask

    f_s = 1e4
    t = np.arange(10001) / f_s
    steps = Steps(dwell=0.2)(t)
    # the surface moves for 20 ms after each step, then rests; the current is 60 mA at rest in the
    # first dwells and 300 mA (the loop running against the breakaway friction) in the later ones
    since = np.mod(t, 0.2)
    position = np.where(since < 0.02, 0.1 * since, 2e-3) + np.floor(t / 0.2)
    small = np.where(t < 0.6, 0.06, 0.3)
    edge = 0.1
    base = moving_mask(steps, f_s, theta_u=position)
    m = moving_mask(steps, f_s, theta_u=position, i_meas=small, rest_current=edge)
    assert np.all(m <= base)  # only ever leaves more out
    dwell = (t > 0.2) & (t < 0.4)  # the second dwell, small current
    early = dwell & (since > 0.02 + REST_SETTLE_S + 2e-4) & (since < HOLD_SETTLE_S)
    assert early.any() and np.all(m[early] == 0.0) and np.all(base[early] == 1.0)
    moving = dwell & (since < 0.02)
    assert np.all(m[moving] == 1.0)  # the surface still moves: kept
    late = (t > 0.6) & (since > 0.02 + REST_SETTLE_S + 2e-4) & (since < HOLD_SETTLE_S)
    assert late.any() and np.all(m[late] == 1.0)  # a rest carrying more than the edge: kept
    # off without a current or an edge, and a command that never holds keeps every sample
    assert np.array_equal(moving_mask(steps, f_s, theta_u=position, i_meas=small), base)
    assert np.array_equal(moving_mask(steps, f_s, theta_u=position, rest_current=edge), base)
    assert np.array_equal(moving_mask(steps, f_s, i_meas=small, rest_current=edge), moving_mask(steps, f_s))
    chirp = Chirp()(t)
    assert np.all(moving_mask(chirp, f_s, theta_u=np.zeros_like(t), i_meas=0 * t, rest_current=edge) == 1.0)
    with pytest.raises(ValueError, match="i_meas"):
        moving_mask(steps, f_s, theta_u=position, i_meas=small[:-1], rest_current=edge)


def test_a_masked_fitness_ignores_the_left_out_samples():
    current = 0.3 * np.sin(2 * np.pi * 4 * T)
    ref = Comparison.from_signal(T, current, F_S)
    mask = (T < 0.25).astype(float)
    fit = Fitness(ref, "s", mask)
    noisy_tail = current + np.where(T >= 0.3, 0.3, 0.0)
    # a difference only where the mask is 0 costs nothing (up to the filter's spread at the edge)
    assert fit(noisy_tail) < 1e-3 * Fitness(ref, "s")(noisy_tail)
    with pytest.raises(ValueError, match="mask"):
        Fitness(ref, "s", mask[:-1])


def test_the_weighed_samples_are_kept_and_a_shifted_copy_takes_its_own():
    current = 0.3 * np.sin(2 * np.pi * 4 * T)
    fit = Fitness(Comparison.from_signal(T, current, F_S), "s", (T < 0.25).astype(float))
    keep, root_w, reference = fit.weighed()
    assert fit.weighed()[2] is reference  # kept, not taken again
    assert np.array_equal(keep, np.flatnonzero(fit.weights > 0)) and np.array_equal(root_w, np.sqrt(fit.weights[keep]))
    offset = np.full_like(T, 0.1)
    shifted = fit.shifted(offset)
    assert np.array_equal(shifted.weighed()[2], reference - 0.1)  # its own reference, not the kept one
    assert fit.weighed()[2] is reference


def test_a_fast_recording_is_low_passed_before_it_is_resampled():
    """Issue 10: a 64 kHz current with inverter ripple wandering 12-20 kHz. Interpolated straight
    onto the 10 kHz grid, the ripple folds into the comparison band (7.3 mA RMS measured);
    filtered on its own grid first, with its edges smoothed, 0.008 mA (studies/bench_resample.py).
    A source on the grid or slower is interpolated as it is."""
    from emaphm.identification.signals import resample

    rate = 64_000.0
    t_src = np.arange(int(rate)) / rate
    grid = np.arange(10_000) / F_S

    def signal(t):
        return 0.3 * np.sin(2 * np.pi * 3 * t) + 0.1 * np.sin(2 * np.pi * 40 * t)

    ripples = {
        "wandering 12-20 kHz": 0.05 * np.sin(2 * np.pi * (16e3 * t_src - 4e3 / (2 * np.pi * 7) * np.cos(2 * np.pi * 7 * t_src))),
        # a fixed tone: the interior is clean either way, the edges decide (2x without `_smooth_edges`)
        "16 kHz tone, phase 1 rad": 0.05 * np.sin(2 * np.pi * 16e3 * t_src + 1.0),
    }  # fmt: skip
    truth = lowpass(signal(grid), F_S)
    for name, ripple in ripples.items():
        old = lowpass(np.interp(grid, t_src, signal(t_src) + ripple), F_S) - truth
        new = Comparison.from_trace(t_src, signal(t_src) + ripple, grid, F_S).reference - truth
        assert np.sqrt(np.mean(old**2)) > 10 * np.sqrt(np.mean(new**2)), name
        assert np.sqrt(np.mean(new**2)) < 0.05e-3, name  # A: 0.006-0.008 mA measured
    for t_same in (grid, np.arange(5000) / 5e3):  # the grid's rate, and slower: unchanged
        x = signal(t_same)
        np.testing.assert_array_equal(
            resample(t_same, x, grid[: len(grid) - 1], F_S), np.interp(grid[:-1], t_same, x)
        )


def test_command_frequency_reads_a_sine_a_chirp_and_ignores_noise():
    from emaphm.commands import Steps
    from emaphm.identification.weights import command_frequency

    f_s = 1e4
    t = np.arange(20001) / f_s
    sine = 0.05 * np.sin(2 * np.pi * 3.0 * t)
    f = command_frequency(sine, f_s)
    np.testing.assert_allclose(f, 3.0, rtol=0.01)
    # a recorded command's quantisation (16 bits over ±0.3 rad) and a noise of one LSB make no reversals
    rng = np.random.default_rng(0)
    lsb = 0.6 / 2**16
    noisy = lsb * np.round(sine / lsb) + lsb * rng.standard_normal(t.shape)
    np.testing.assert_allclose(command_frequency(noisy, f_s), 3.0, rtol=0.02)
    # the chirp run on to 2 s: each half period's frequency lies within its span of the sweep
    chirp = Chirp(T=2.0, f1=19.5)
    fc = command_frequency(chirp(t), f_s)
    inner = (t > 0.3) & (t < 1.9)
    half = 0.5 / fc[inner]  # the half period each sample lies in
    sweep = lambda when: chirp.f0 + (chirp.f1 - chirp.f0) * when / chirp.T  # noqa: E731
    assert np.all(fc[inner] > 0.97 * sweep(t[inner] - half)) and np.all(
        fc[inner] < 1.03 * sweep(t[inner] + half)
    )
    # a staircase reverses every dwell or two at most; a hold or a ramp does not oscillate
    assert 0 < command_frequency(Steps(dwell=0.2)(t), f_s).max() <= 2.5 + 1e-9
    assert np.all(command_frequency(np.zeros_like(t), f_s) == 0.0)
    assert np.all(command_frequency(0.01 * t, f_s) == 0.0)


def test_the_band_mask_leaves_out_only_motion_faster_than_the_fdi_chirp():
    from emaphm.commands import ChirpHold, Steps
    from emaphm.identification.weights import BAND_HZ, band_mask

    f_s = 1e4
    t = np.arange(20001) / f_s
    assert BAND_HZ == Chirp().f1  # the fastest motion the monitor was fitted on
    for command in (Chirp(), ChirpHold(), Steps()):  # what the monitor was fitted and checked on
        assert np.all(band_mask(command(t[t <= command.duration]), f_s) == 1.0)
    m = band_mask(Chirp(T=2.0, f1=19.5)(t), f_s)  # the chirp run on to 19.5 Hz: from about 1 s
    first = t[np.argmin(m)]
    assert 0.95 < first < 1.08 and np.all(m[t > first] == 0.0) and np.all(m[t < first] == 1.0)
    assert np.all(band_mask(0.005 * np.sin(2 * np.pi * 15 * t), f_s) == 0.0)


def test_error_weights_follow_the_command_frequency_and_the_emphasis_scales_eq3():
    from emaphm.identification.weights import error_weights

    f_s = 1e4
    t = np.arange(10001) / f_s
    # a 3 Hz sine at a 3 Hz corner: 1/2; a hold or a ramp (no reversal): 1; no corner: 1
    np.testing.assert_allclose(error_weights(0.05 * np.sin(2 * np.pi * 3 * t), f_s, 3.0), 0.5, rtol=0.02)
    np.testing.assert_array_equal(error_weights(np.zeros_like(t), f_s), 1.0)
    np.testing.assert_array_equal(error_weights(0.01 * t, f_s), 1.0)
    np.testing.assert_array_equal(error_weights(np.sin(40 * t), f_s, None), 1.0)
    with pytest.raises(InputError, match="corner"):
        error_weights(np.sin(40 * t), f_s, 0.0)
    # fast motion's weight outlasts it by ERROR_MEMORY_S: the chirp's ramp back and the stop that
    # follows it weigh as the chirp's 10 Hz end, the hold after them as slow; the rising sweep alone
    # is unchanged by that memory
    from emaphm.commands import ChirpHold
    from emaphm.identification.weights import ERROR_CORNER_HZ, ERROR_MEMORY_S, command_frequency

    hold = ChirpHold()
    th = np.arange(int(hold.duration * f_s) + 1) / f_s
    w = error_weights(hold(th), f_s)
    end = w[int(0.99 * f_s)]
    after = (th > hold.T) & (th < hold.T + ERROR_MEMORY_S - 1e-3)
    assert end < 0.1 and np.all(w[after] == end) and np.all(w[th > hold.T + ERROR_MEMORY_S + 1e-3] > 0.9)
    chirp = Chirp()(th[th <= 1.0])
    np.testing.assert_array_equal(
        error_weights(chirp, f_s), 1 / (1 + (command_frequency(chirp, f_s) / ERROR_CORNER_HZ) ** 2)
    )
    # the emphasis multiplies eq. 3's weights: a difference where it is 0 costs nothing
    current = 0.3 * np.sin(2 * np.pi * 4 * T)
    ref = Comparison.from_signal(T, current, F_S)
    emphasis = np.where(T < 0.25, 1.0, 0.0)
    np.testing.assert_array_equal(Fitness(ref, emphasis=emphasis).weights, Fitness(ref).weights * emphasis)
    worse = current + np.where(T >= 0.3, 0.3, 0.0)
    assert Fitness(ref, emphasis=emphasis)(worse) < 1e-3 * Fitness(ref)(worse)
    with pytest.raises(ValueError, match="emphasis"):
        Fitness(ref, emphasis=emphasis[:-1])
    with pytest.raises(ValueError, match="emphasis"):
        Fitness(ref, emphasis=-emphasis)
