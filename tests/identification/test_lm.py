"""The bounded Levenberg–Marquardt solver of the polishes (`identification.lm`), against scipy's
`least_squares` as the independent reference."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import least_squares

from emaphm.identification.lm import levenberg_marquardt, levenberg_marquardt_many

T = np.linspace(0.0, 1.0, 400)


def _decay(x):
    """A damped-oscillation fit, m = 400 samples of 3 parameters in [0, 1], rows of x → rows of r."""
    x = np.atleast_2d(x)
    a, k, w = x[:, :1], x[:, 1:2], x[:, 2:3]
    truth = 0.7 * np.exp(-3.0 * 0.4 * T) * np.cos(20.0 * 0.55 * T)
    return a * np.exp(-3.0 * k * T) * np.cos(20.0 * w * T) - truth


def _solve(fun, x0, **kw):
    x0 = np.asarray(x0, dtype=float)
    return levenberg_marquardt(fun, x0, fun(x0[None, :])[0], **kw)


@pytest.mark.parametrize("scaling", ["marquardt", "identity"])
@pytest.mark.parametrize("x0", [(0.5, 0.5, 0.5), (0.2, 0.8, 0.6), (0.9, 0.1, 0.45)])
def test_reaches_the_minimum_scipy_reaches(x0, scaling):
    res = _solve(_decay, x0, step=1e-6, max_nfev=200, scaling=scaling)
    ref = least_squares(lambda x: _decay(x)[0], x0, bounds=(0.0, 1.0), method="trf")
    assert res.f == pytest.approx(2.0 * ref.cost, abs=1e-12)
    np.testing.assert_allclose(res.x, ref.x, atol=1e-5)
    np.testing.assert_allclose(res.x, [0.7, 0.4, 0.55], atol=1e-5)  # the truth: a zero residual
    assert res.status in ("ftol", "xtol")


def test_a_minimum_outside_the_box_ends_on_its_bound_as_scipys():
    # the truth's amplitude 0.7 is out of reach when the box stops at 0.5: the fit is held there
    def fun(x):
        return _decay(np.atleast_2d(x) * np.array([0.5 / 1.0, 1.0, 1.0]))

    res = _solve(fun, (0.4, 0.5, 0.5), step=1e-6, max_nfev=200)
    ref = least_squares(lambda x: fun(x)[0], (0.4, 0.5, 0.5), bounds=(0.0, 1.0), method="trf")
    assert res.x[0] == 1.0  # on the bound exactly, not near it
    assert res.f == pytest.approx(2.0 * ref.cost, rel=1e-6)
    assert np.all((res.x >= 0.0) & (res.x <= 1.0))


@pytest.mark.parametrize(("broyden", "budget"), [(False, 3), (True, 3), (True, 7)])
def test_never_worse_than_its_start_and_keeps_to_the_budget(broyden, budget):
    calls = []

    def counted(X):
        calls.append(len(X))
        return _decay(X)

    x0 = np.array([0.1, 0.9, 0.2])
    f0 = float(np.sum(_decay(x0) ** 2))
    res = _solve(counted, x0, step=1e-4, max_nfev=budget, broyden=broyden)
    assert res.nfev <= budget and res.status == "budget"
    assert res.f <= f0 * (1.0 + 1e-12)
    # the trial points counted by nfev, the Jacobians in batches of n rows by njev, the spare trial
    # points never taken by spared (and the start)
    assert sum(calls) == 1 + res.nfev + 3 * res.njev + res.spared


def test_a_rejected_step_damps_and_retries_without_a_new_jacobian():
    # r = atan(20 (x - 0.5)) from x = 0.99: the Gauss-Newton step (-2.4) leaves the box, its
    # projection onto 0 fits no better; the damped retries, without new Jacobians, then get there
    sizes = []

    def atan(X):
        sizes.append(len(X))
        return np.arctan(20.0 * (np.atleast_2d(X) - 0.5))

    res = _solve(atan, (0.99,), step=1e-7, max_nfev=100, spare_trials=False)
    assert res.x[0] == pytest.approx(0.5, abs=1e-6)
    trials = sizes[1:]  # after the start: a Jacobian is one row here too, so count by order
    assert res.nfev > res.njev  # some Jacobian was followed by more than one trial point
    assert len(trials) == res.nfev + res.njev


def test_descents_in_lockstep_take_each_the_path_it_takes_alone():
    # several starts served in one batch per round: the same end points, values, counts and
    # stops as one by one, in fewer calls of the residuals (the rows are independent)
    starts = np.array([(0.5, 0.5, 0.5), (0.2, 0.8, 0.6), (0.9, 0.1, 0.45), (0.1, 0.9, 0.2)])
    calls = []

    def counted(X):
        calls.append(len(X))
        return _decay(X)

    together = levenberg_marquardt_many(counted, starts, _decay(starts), step=1e-4, max_nfev=40)
    n_together = len(calls)
    alone = [_solve(counted, x0, step=1e-4, max_nfev=40) for x0 in starts]
    assert n_together < len(calls) - n_together
    for a, b in zip(together, alone, strict=True):
        np.testing.assert_array_equal(a.x, b.x)
        assert (a.f, a.nfev, a.njev, a.status) == (b.f, b.nfev, b.njev, b.status)
    assert {a.status for a in together} <= {"ftol", "xtol", "budget"}
    assert len({a.nfev for a in together}) > 1  # they stopped at different rounds


@pytest.mark.parametrize("x0", [(0.5, 0.5, 0.5), (0.2, 0.8, 0.6), (0.9, 0.1, 0.45)])
def test_secant_updates_reach_the_same_minimum_with_fewer_jacobians(x0):
    # Broyden's updates replace most difference Jacobians; the descent still ends at scipy's
    # minimum (a zero residual here), and on a difference Jacobian, not on a secant one
    full = _solve(_decay, x0, step=1e-6, max_nfev=200)
    secant = _solve(_decay, x0, step=1e-6, max_nfev=200, broyden=True)
    np.testing.assert_allclose(secant.x, [0.7, 0.4, 0.55], atol=1e-5)
    assert secant.f == pytest.approx(full.f, abs=1e-10)
    assert secant.njev < full.njev
    assert secant.njev * 3 + secant.nfev < full.njev * 3 + full.nfev  # fewer residual rows in all
    assert secant.status in ("ftol", "xtol")


def test_secant_descents_in_lockstep_take_each_the_path_it_takes_alone():
    starts = np.array([(0.5, 0.5, 0.5), (0.2, 0.8, 0.6), (0.9, 0.1, 0.45)])
    together = levenberg_marquardt_many(_decay, starts, _decay(starts), step=1e-4, max_nfev=40, broyden=True)
    for a, x0 in zip(together, starts, strict=True):
        b = _solve(_decay, x0, step=1e-4, max_nfev=40, broyden=True)
        np.testing.assert_array_equal(a.x, b.x)
        assert (a.f, a.nfev, a.njev, a.status) == (b.f, b.nfev, b.njev, b.status)


def test_steps_shorter_than_min_secant_leave_the_jacobian_alone():
    # with every step below min_secant no secant update happens: the path is plain
    # Levenberg-Marquardt on Jacobians reused between refreshes, never a corrupted one, and the
    # descent still reaches the minimum (each stop is checked on a fresh difference Jacobian)
    x0 = (0.2, 0.8, 0.6)
    res = _solve(_decay, x0, step=1e-6, max_nfev=400, broyden=True, min_secant=10.0)
    np.testing.assert_allclose(res.x, [0.7, 0.4, 0.55], atol=1e-5)
    assert res.status in ("ftol", "xtol")



def test_isotropic_damping_differs_from_marquardts_and_an_unknown_one_is_refused():
    # the same start, two dampings: different paths (D = max diag·I against diag(JᵀJ)) to one minimum
    x0 = np.array([0.2, 0.8, 0.6])
    a = _solve(_decay, x0, step=1e-6, max_nfev=200)
    b = _solve(_decay, x0, step=1e-6, max_nfev=200, scaling="identity")
    assert (a.nfev, a.njev) != (b.nfev, b.njev)
    np.testing.assert_allclose(a.x, b.x, atol=1e-5)
    with pytest.raises(ValueError, match="scaling"):
        _solve(_decay, x0, step=1e-6, max_nfev=5, scaling="levenberg")


@pytest.mark.parametrize("broyden", [False, True])
@pytest.mark.parametrize("x0", [(0.5, 0.5, 0.5), (0.2, 0.8, 0.6), (0.9, 0.1, 0.45), (0.1, 0.9, 0.2)])
def test_a_spare_trial_point_gives_the_same_path_in_fewer_rounds(x0, broyden):
    # a lone descent's trial point goes with its spare (the trial after a rejection): the same end
    # point, value, counts and stop as without, to the bit; fewer calls where a step was rejected;
    # every row evaluated is counted (the spares never taken in `spared`)
    def run(spare_trials):
        calls = []

        def counted(X):
            calls.append(len(X))
            return np.arctan(5.0 * _decay(X))  # a rough valley: many rejected steps

        x = np.asarray(x0, dtype=float)
        res = levenberg_marquardt(counted, x, counted(x[None, :])[0], step=1e-4, max_nfev=60, broyden=broyden,
                                  spare_trials=spare_trials)  # fmt: skip
        return res, calls[1:]

    plain, plain_calls = run(False)
    spared, spare_calls = run(True)
    np.testing.assert_array_equal(spared.x, plain.x)
    assert (spared.f, spared.nfev, spared.njev, spared.status) == (plain.f, plain.nfev, plain.njev, plain.status)
    assert plain.spared == 0 and max(plain_calls) <= 3
    assert sum(spare_calls) == spared.nfev + 3 * spared.njev + spared.spared
    taken = spare_calls.count(2) - spared.spared  # each spare taken is a round saved
    assert len(spare_calls) == len(plain_calls) - taken


def test_a_spare_taken_saves_the_round_of_a_rejected_step():
    # the atan fit of the rejected-step test: its damped retries come from the spares
    def atan(X):
        sizes.append(len(X))
        return np.arctan(20.0 * (np.atleast_2d(X) - 0.5))

    ends = {}
    for spare in (False, True):
        sizes: list[int] = []
        ends[spare] = (_solve(atan, (0.99,), step=1e-7, max_nfev=100, spare_trials=spare), len(sizes))
    (plain, plain_calls), (spared, spare_calls) = ends[False], ends[True]
    assert (spared.x[0], spared.nfev, spared.njev) == (plain.x[0], plain.nfev, plain.njev)
    assert spare_calls < plain_calls


def test_a_spare_goes_only_with_a_lone_trial_point():
    # descents in lockstep already fill the batch: no spares there, the same calls as before
    starts = np.array([(0.5, 0.5, 0.5), (0.2, 0.8, 0.6)])
    sizes = {True: [], False: []}
    for spare in (True, False):
        def counted(X, spare=spare):
            sizes[spare].append(len(X))
            return np.arctan(5.0 * _decay(X))

        levenberg_marquardt_many(counted, starts, counted(starts), step=1e-4, max_nfev=40, spare_trials=spare)
    # while both run, every round is the same; spares appear only once one of them has stopped
    both = next(i for i, (a, b) in enumerate(zip(sizes[True], sizes[False], strict=False)) if a != b)
    assert sizes[True][:both] == sizes[False][:both]
    assert sizes[True][both] == 2 and sizes[False][both] == 1


def test_gram_is_einsums_product_to_the_bit_on_random_shapes_and_views():
    # lm_descent.gram takes each row of JᵀJ from its diagonal on and mirrors it; einsum's own
    # product is the reference, bit for bit (a Jacobian's columns are differences over ~1e-2)
    from emaphm.identification.lm_descent import gram

    rng = np.random.default_rng(36)
    for trial in range(600):
        n, m = int(rng.integers(1, 11)), int(rng.integers(1, 12_000))
        Jt = rng.standard_normal((n, m)) * 10 ** rng.uniform(-6, 6, size=(n, 1))
        if trial % 3 == 0:
            Jt = (rng.standard_normal((n, m)) - rng.standard_normal((1, m))) / 1e-2
        if trial % 4 == 0:
            Jt = Jt[:, : max(1, m // 2)]  # rows with a stride longer than their length
        expected = np.einsum("ik,jk->ij", Jt, Jt)
        assert np.array_equal(gram(Jt), expected), (n, m)
    one_row = rng.standard_normal((1, 5))
    assert gram(one_row).shape == (1, 1) and np.array_equal(gram(one_row), np.einsum("ik,jk->ij", one_row, one_row))
