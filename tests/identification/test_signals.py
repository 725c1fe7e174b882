"""The comparison filter without scipy.signal (signals.butterworth2, biquad_zi, lowpass): scipy's
numbers to the last bit, and scipy.signal not imported by an identification."""

import subprocess
import sys

import numpy as np
import pytest
from scipy.signal import butter, sosfilt_zi, sosfiltfilt

from emaphm.identification.signals import (
    CUTOFF_HZ,
    biquad_zi,
    butterworth2,
    comparison_filter,
    lowpass,
)


def test_butterworth2_is_scipys_butter_to_the_last_bit():
    # 1200 rates and cutoffs over the whole range, the edges included (a pole pair at z = ±1)
    for f_s in np.linspace(1000.0, 200_000.0, 40):
        for cutoff in np.geomspace(1e-3, 0.499 * f_s, 30):
            want = butter(2, cutoff, fs=f_s, output="sos")
            got = butterworth2(cutoff, f_s)
            assert np.array_equal(got, want), (f_s, cutoff, got - want)


def test_a_textbook_biquad_would_not_pass_the_last_bit_test():
    # the test above can fail: the cookbook form (K = tan(π f_c/f_s)) differs from scipy in the last bits
    differs = 0
    for f_s in (2e3, 1e4, 5e4):
        for cutoff in (10.0, 150.0, 700.0):
            k = np.tan(np.pi * cutoff / f_s)
            n = 1.0 / (1.0 + np.sqrt(2.0) * k + k * k)
            textbook = np.array(
                [
                    [
                        k * k * n,
                        2 * k * k * n,
                        k * k * n,
                        1.0,
                        2 * (k * k - 1) * n,
                        (1 - np.sqrt(2.0) * k + k * k) * n,
                    ]
                ]
            )
            differs += not np.array_equal(textbook, butter(2, cutoff, fs=f_s, output="sos"))
    assert differs >= 5


@pytest.mark.parametrize("cutoff", [0.0, -5.0, 5000.0, 6000.0, np.nan, np.inf])
def test_butterworth2_refuses_a_cutoff_outside_nyquist(cutoff):
    with pytest.raises(ValueError, match="cutoff"):
        butterworth2(cutoff, 1e4)


def test_biquad_zi_is_sosfilt_zi_and_the_steady_state():
    for f_s, cutoff in [(1e4, 150.0), (2e3, 10.0), (5e4, 3000.0), (1e4, 4900.0)]:
        sos = butter(2, cutoff, fs=f_s, output="sos")
        zi = biquad_zi(sos)
        np.testing.assert_array_equal(zi, sosfilt_zi(sos))
        # an independent check: started there, a unit step stays at the DC gain 1 (no transient)
        b0, b1, b2, _, a1, a2 = sos[0]
        z0, z1 = zi[0]
        for _ in range(5):
            y = b0 + z0
            z0, z1 = b1 - a1 * y + z1, b2 - a2 * y
            assert y == pytest.approx(1.0, abs=1e-12)
    with pytest.raises(ValueError):
        biquad_zi(butter(4, 150, fs=1e4, output="sos"))  # two sections: not this function's job


@pytest.mark.parametrize("f_s", [1e4, 3e3])
@pytest.mark.parametrize(
    "shape", [(10,), (11,), (500,), (10001,), (1, 777), (2, 777), (5, 1001), (3, 2, 400)]
)
def test_lowpass_is_scipys_sosfiltfilt(f_s, shape):
    rng = np.random.default_rng(sum(shape))
    # random walks plus white noise, with ends far from zero: the odd extension and the initial
    # states matter; odd and even numbers of rows (the kernel filters rows in pairs)
    x = 3.0 + np.cumsum(rng.normal(size=shape), axis=-1) * 0.05 + rng.normal(size=shape)
    want = sosfiltfilt(butter(2, CUTOFF_HZ, fs=f_s, output="sos"), x, axis=-1)
    got = lowpass(x, f_s)
    assert got.shape == x.shape
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-15)


def test_lowpass_of_awkward_inputs_is_scipys():
    rng = np.random.default_rng(7)
    sos = butter(2, CUTOFF_HZ, fs=1e4, output="sos")
    base = 2.0 + np.cumsum(rng.normal(size=(4, 3, 700)), axis=-1) * 0.05
    strided = base[::2, :, ::3]  # not contiguous
    np.testing.assert_allclose(lowpass(strided, 1e4), sosfiltfilt(sos, strided), rtol=1e-12, atol=1e-15)
    middle = np.ascontiguousarray(np.moveaxis(base, -1, 1))  # (4, 700, 3): filter along axis 1
    np.testing.assert_allclose(
        lowpass(middle, 1e4, axis=1), sosfiltfilt(sos, middle, axis=1), rtol=1e-12, atol=1e-15
    )
    ints = (base[0, 0] * 100).astype(np.int64)
    np.testing.assert_allclose(
        lowpass(ints, 1e4), sosfiltfilt(sos, ints.astype(float)), rtol=1e-12, atol=1e-12
    )
    single = base[0, 0].astype(np.float32)
    np.testing.assert_allclose(
        lowpass(single, 1e4), sosfiltfilt(sos, single.astype(float)), rtol=1e-12, atol=1e-12
    )
    frozen = base[1, 1].copy()
    frozen.flags.writeable = False
    np.testing.assert_allclose(lowpass(frozen, 1e4), sosfiltfilt(sos, frozen), rtol=1e-12, atol=1e-15)
    # a row with a NaN spoils itself only, whether first or second of a pair
    pair = base[2, :2].copy()
    pair[0, 350] = np.nan
    for rows in (pair, pair[::-1]):
        got = lowpass(rows, 1e4)
        bad = int(np.isnan(rows[1, 350]))
        assert np.isnan(got[bad]).all() and np.isfinite(got[1 - bad]).all()
        np.testing.assert_allclose(got[1 - bad], sosfiltfilt(sos, rows[1 - bad]), rtol=1e-12, atol=1e-15)


def test_lowpass_along_another_axis_and_input_untouched():
    rng = np.random.default_rng(3)
    x = rng.normal(size=(600, 3))
    before = x.copy()
    want = sosfiltfilt(butter(2, 80.0, fs=1e4, output="sos"), x, axis=0)
    np.testing.assert_allclose(lowpass(x, 1e4, cutoff=80.0, axis=0), want, rtol=1e-12, atol=1e-15)
    np.testing.assert_array_equal(x, before)


def test_lowpass_refuses_a_signal_the_filter_cannot_pad():
    assert comparison_filter(1e4)[2] == 9
    with pytest.raises(ValueError, match="more than 9 samples"):
        lowpass(np.ones(9), 1e4)
    np.testing.assert_allclose(lowpass(np.ones(10), 1e4), np.ones(10), rtol=1e-12)  # DC passes


def test_an_identification_imports_neither_scipy_signal_nor_matplotlib_nor_scipy_stats():
    # their imports cost 0.9 s (scipy 1.17 loads all of scipy.signal), 0.35 s and 0.46 s (`cma`
    # imports matplotlib.pyplot and scipy.stats) of every `emaphm identify`; the whole default
    # path: GA, CMA-ES polish, least squares, the switching last stage, Laplace intervals. Each
    # stage at its smallest budget: what a stage imports does not depend on how long it runs.
    code = (
        "import sys\n"
        "from emaphm.identification import limits\n"
        "from emaphm.identification.api import identify\n"
        "limits.POLISH_BUDGET, limits.LS_MAX_NFEV, limits.SWITCHING_ITERATIONS = (8, 2), 3, 1\n"
        "r = identify(true_faults=[0.1, 0.1, 0, 0.1, 0, 0, 0, 0.5], seed=1, generations=2, pop_size=8)\n"
        "assert r.uncertainty is not None and r.stage('least_squares')['ran']\n"
        "assert r.stage('polish')['ran'] and r.stage('last_stage')['switching'] is not None\n"
        "print([m for m in ('scipy.signal', 'scipy.ndimage', 'matplotlib', 'scipy.stats') if m in sys.modules])\n"
        "import matplotlib.pyplot, scipy.stats\n"  # and both are importable afterwards
        "print(matplotlib.pyplot.__name__, scipy.stats.norm.cdf(0.0))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["[]", "matplotlib.pyplot", "0.5"]
    assert "matplotlib" not in out.stderr  # cma's warning about it is not shown
