"""The final check against an eccentricity trapped at zero with its direction lost (issue 8, item 3)."""

from __future__ import annotations

import numpy as np

from emaphm.identification.checks import try_eccentricity_directions
from emaphm.identification.limits import ECC_AT_BOUND, ECC_DIRECTIONS, ECC_PROBE, ECC_PROBE_GAIN
from emaphm.identification.optimizers import OptimizerRun
from emaphm.identification.problem import search_to_faults

OTHERS = np.array([0.2, 0.1, 0.05, 0.4, 0.0, 0.5])  # k1..k5 and k8


def polar(zeta: float, direction: float):
    """A fitness of the eccentricity as a vector ζ·e^(2πi·k7), the others in a bowl: at ζ = 0 the
    direction has no effect, and from the opposite direction a small ζ makes it worse."""
    target = zeta * np.exp(2j * np.pi * direction)

    def f(X):
        K = search_to_faults(np.atleast_2d(X))
        z = K[:, 5] * np.exp(2j * np.pi * K[:, 6])
        rest = np.sum((K[:, [0, 1, 2, 3, 4, 7]] - OTHERS) ** 2, axis=1)
        return np.abs(z - target) ** 2 + rest

    return f


def point(zeta: float, k7: float) -> np.ndarray:
    x = np.r_[OTHERS[:5], zeta, (k7 + 0.5) / 2.0, OTHERS[5]]
    return x


def test_a_trapped_eccentricity_is_restarted_in_the_best_direction():
    f = polar(0.05, 0.6)
    trapped = point(0.0, 0.1)  # ζ at its bound, the direction opposite-ish
    run = OptimizerRun(trapped, float(f(trapped)[0]), 100, [1.0])
    out, move = try_eccentricity_directions(f, run, polish_it=False)
    k = search_to_faults(out.x[None, :])[0]
    assert move == "eccentricity from k7 = 0.625" and out.evaluations == 100 + ECC_DIRECTIONS
    assert k[5] == ECC_PROBE and abs(k[6] - 0.625) < 1e-12 and out.f < 0.2 * run.f
    np.testing.assert_array_equal(k[[0, 1, 2, 3, 4, 7]], OTHERS)  # the other faults untouched


def test_the_restart_is_polished_when_asked():
    f = polar(0.05, 0.6)
    trapped = point(0.0, 0.1)
    run = OptimizerRun(trapped, float(f(trapped)[0]), 0, [])
    plain, _ = try_eccentricity_directions(f, run, polish_it=False)
    polished, move = try_eccentricity_directions(f, run, seed=2, polish_it=True)
    k = search_to_faults(polished.x[None, :])[0]
    assert move is not None and polished.f < plain.f and polished.evaluations > plain.evaluations
    assert abs(k[5] - 0.05) < 0.01 and abs(k[6] - 0.6) < 0.05


def test_a_healthy_eccentricity_is_kept():
    f = polar(0.0, 0.0)  # the truth has no eccentricity: every restart fits worse
    x = point(0.0, 0.3)
    run = OptimizerRun(x, float(f(x)[0]), 10, [])
    out, move = try_eccentricity_directions(f, run, polish_it=False)
    assert move is None and out.f == run.f and out.evaluations == 10 + ECC_DIRECTIONS
    np.testing.assert_array_equal(out.x, x)


def test_an_eccentricity_off_its_bound_costs_nothing():
    f = polar(0.05, 0.6)
    x = point(2 * ECC_AT_BOUND, 0.1)
    run = OptimizerRun(x, float(f(x)[0]), 10, [])
    out, move = try_eccentricity_directions(f, run)
    assert move is None and out is run


def test_a_small_gain_is_not_a_basin_change():
    # the restart must beat the run by ECC_PROBE_GAIN: a slightly better (noise) fit is not taken
    f = polar(0.05, 0.5)
    x = point(0.0, 0.0)
    best_restart = float(f(point(ECC_PROBE, 0.5))[0])  # (0.05 - 0.03)² = 4e-4
    for run_f, taken in ((1.05 * best_restart, False), (1.0 / (0.95 * ECC_PROBE_GAIN) * best_restart, True)):
        out, move = try_eccentricity_directions(f, OptimizerRun(x, run_f, 0, []), polish_it=False)
        assert (move is not None) is taken and out.f == (best_restart if taken else run_f)


def test_a_restart_far_worse_than_the_run_is_not_polished():
    # healthy actuators whose ζ ended at the bound: every direction fits ECC_PROBE_WORTH x worse
    f = polar(0.0, 0.0)
    x = point(0.0, 0.3)
    run = OptimizerRun(x, float(f(x)[0]) + 1e-6, 10, [])
    calls = []

    def counted(X):
        calls.append(len(np.atleast_2d(X)))
        return f(X)

    out, move = try_eccentricity_directions(counted, run, polish_it=True)
    assert move is None and calls == [ECC_DIRECTIONS] and out.evaluations == 10 + ECC_DIRECTIONS


def test_the_restart_is_polished_with_the_whole_budget():
    # gains far below the early stop's tolerance (1e-3 relative) around the restart: the usual
    # polish would stop after 15 generations without gain; the restart's runs on (up to its whole
    # budget, or until CMA-ES's own tolerances end it)
    from emaphm.identification.limits import POLISH_BUDGET
    from emaphm.identification.polish import polish

    bowl = polar(0.05, 0.6)

    def shallow(X):
        return 1.0 + 1e-6 * bowl(X)

    trapped = point(0.0, 0.1)
    run = OptimizerRun(trapped, 1.2, 0, [])
    out, move = try_eccentricity_directions(shallow, run, seed=1, polish_it=True)
    probe = point(ECC_PROBE, 0.625)
    usual = polish(shallow, OptimizerRun(probe, float(shallow(probe)[0]), 0, []), seed=1)
    assert move is not None and out.f < float(shallow(probe)[0])
    assert usual.evaluations <= POLISH_BUDGET[0] * 17  # stopped by the 15-generation rule
    assert out.evaluations - ECC_DIRECTIONS > 2 * usual.evaluations


def test_the_final_checks_take_the_best_finite_candidate_and_count_its_evaluations():
    from emaphm.identification.checks import best_candidate

    run = OptimizerRun(point(0.0, 0.3), 1.0, 100, [])
    X = np.repeat(run.x[None, :], 4, axis=0)
    X[:, 0] = [0.1, 0.2, 0.3, 0.4]
    f, best, evaluations = best_candidate(lambda X: np.array([np.nan, 0.7, 0.2, -np.inf]), run, X)
    assert best == 2  # NaN and -inf are failures, not the best candidate
    assert np.isinf(f[0]) and np.isinf(f[3]) and f[2] == 0.2
    assert evaluations == 104
