"""The optimisers on cheap batch objectives: determinism, convergence, non-finite values, the early
stop and the polish (as pymoo tests its own algorithms: small problems, small budgets, fixed seeds).
"""

from types import SimpleNamespace

import numpy as np
import pytest
from pymoo.algorithms.soo.nonconvex.ga import GA
from pymoo.core.population import Population

from emaphm import InputError
from emaphm.identification.optimizers import (
    OPTIMIZERS,
    BatchProblem,
    OptimizerRun,
    Stagnation,
    minimize_batch,
)
from emaphm.identification.polish import least_squares_polish, polish
from emaphm.identification.search import run_optimizer

CENTRE = np.array([0.2, 0.7, 0.4, 0.1, 0.9, 0.5, 0.3, 0.6])
BUDGET = {"pop_size": 20, "generations": 50}
NO_EARLY_STOP = Stagnation(patience=1000)


def bowl(X):
    """A shifted quadratic bowl in 8-D: minimum 0 at CENTRE."""
    return np.sum((X - CENTRE) ** 2, axis=1)


def bowl_residuals(X):
    """The bowl as residual vectors (Σ r² = `bowl`), for the multistart's least squares."""
    return X - CENTRE


def holes_residuals(X):
    """`bowl_with_holes` as residual vectors: NaN rows where it is not finite."""
    R = bowl_residuals(X).astype(float)
    R[~np.isfinite(bowl_with_holes(X))] = np.nan
    return R


# the optimisers that run in generations (the multistart runs least-squares descents)
GENERATIONAL = tuple(name for name in OPTIMIZERS if name != "multistart")


def run_any(name, objective, residuals, **kw):
    """`run_optimizer`, with the residuals for the multistart."""
    return run_optimizer(name, objective, residuals=residuals if name == "multistart" else None, **kw)


def finite_region(X):
    return (X[:, 0] <= 0.6) & (X[:, 1] >= 0.3) & (X[:, 2] <= 0.8)


def bowl_with_holes(X):
    """The bowl, but NaN, −inf or +inf outside `finite_region` (the minimum is inside it)."""
    f = bowl(X)
    f[X[:, 0] > 0.6] = np.nan
    f[X[:, 1] < 0.3] = -np.inf  # would be the "best" value if it were ranked as it is
    f[X[:, 2] > 0.8] = np.inf
    return f


@pytest.mark.parametrize("name", OPTIMIZERS)
def test_same_seed_same_run_other_seed_differs(name):
    a, b, c = (run_any(name, bowl, bowl_residuals, **BUDGET, seed=s) for s in (3, 3, 4))
    np.testing.assert_array_equal(a.x, b.x)
    assert a.f == b.f and a.history == b.history and a.evaluations == b.evaluations
    assert not np.array_equal(a.x, c.x) and a.history != c.history


@pytest.mark.parametrize("name", OPTIMIZERS)
def test_reaches_the_bottom_of_a_bowl(name):
    # measured with pop 20 x 50, seed 1: f ≤ 1.2e-3 for all; over seeds 1..8 the worst was 1.7e-3
    # (DE) and 2.8e-2 for the GWO (one seed stuck early), so the fixed seed 1 is checked
    run = run_any(name, bowl, bowl_residuals, **BUDGET, seed=1, stagnation=NO_EARLY_STOP)
    assert run.f < 1e-2  # within 0.1 of the minimum
    assert np.linalg.norm(run.x - CENTRE) < 0.1
    assert run.f == pytest.approx(bowl(run.x[None, :])[0], rel=1e-12)
    assert run.history[-1] == run.f and run.history == sorted(run.history, reverse=True)


@pytest.mark.parametrize("name", OPTIMIZERS)
def test_non_finite_values_never_win(name):
    run = run_any(name, bowl_with_holes, holes_residuals, **BUDGET, seed=1, stagnation=NO_EARLY_STOP)
    assert np.isfinite(run.f) and finite_region(run.x[None, :])[0]
    assert run.f == bowl(run.x[None, :])[0]
    assert run.f < 1e-2
    assert np.isfinite(run.history[-1]) and not np.isnan(run.history).any()
    polished = polish(bowl_with_holes, run, seed=1)
    assert np.isfinite(polished.f) and finite_region(polished.x[None, :])[0]
    assert polished.f <= run.f


def test_batch_problem_maps_non_finite_to_inf_clips_and_counts():
    seen = []

    def evaluate(X):
        seen.append(X.copy())
        return np.array([np.nan, -np.inf, np.inf, 2.0])

    problem = BatchProblem(evaluate, [0.0, -1.0], [1.0, 1.0])
    X = np.array([[0.5, 0.0], [2.0, -3.0], [-1.0, 0.5], [0.25, 0.25]])
    np.testing.assert_array_equal(problem.evaluate_batch(X), [np.inf, np.inf, np.inf, 2.0])
    np.testing.assert_array_equal(seen[0], [[0.5, 0.0], [1.0, -1.0], [0.0, 0.5], [0.25, 0.25]])
    assert problem.evaluations == 4
    with pytest.raises(InputError, match="bounds"):
        BatchProblem(evaluate, [0.0, 1.0], [1.0, 1.0])


def test_batch_problem_on_other_bounds_as_in_the_calibration():
    # a box that is not [0, 1]^n, with a NaN wall: the GA stays in the box and finds the minimum
    xl, xu = np.array([-5.0, 10.0, 1e-4]), np.array([5.0, 30.0, 2e-4])
    target = np.array([1.5, 12.0, 1.7e-4])
    scale = xu - xl

    def evaluate(X):
        f = np.sum(((X - target) / scale) ** 2, axis=1)
        return np.where(X[:, 0] > 4.0, np.nan, f)

    problem = BatchProblem(evaluate, xl, xu)
    calls = []
    x, f, history = minimize_batch(
        problem, GA(pop_size=20), 30, seed=2, on_generation=lambda *a: calls.append(a)
    )
    assert np.all((xl <= x) & (x <= xu)) and np.all(np.abs(x - target) / scale < 0.05)
    assert f == evaluate(x[None, :])[0] and problem.evaluations >= 20 * 30 - 20
    assert len(history) == 30 and [c[0] for c in calls] == list(range(1, 31))
    assert all(c[1] == 30 for c in calls) and [c[2] for c in calls] == history


def stops(values, patience=3, rtol=0.1, generations=100):
    """Whether pymoo's termination from `Stagnation` says stop after each best value."""
    termination = Stagnation(patience, rtol).termination(generations)
    out = []
    for gen, best in enumerate(values, start=1):
        termination.update(SimpleNamespace(n_gen=gen, opt=Population.new("F", np.array([[best]]))))
        out.append(termination.has_terminated())
    return out


def test_the_stopping_rule():
    # `patience` generations in a row within rtol·|reference| of the reference best; inclusive
    assert stops([10.0, 9.5, 9.2, 9.0]) == [False, False, False, True]
    assert stops([-10.0, -10.5, -11.0, -11.0]) == [False, False, False, True]  # |reference|
    # 8.9 improves on the reference 10 by more than 10 %: it is the new reference, 3 more to go
    assert stops([10.0, 9.5, 9.2, 8.9, 8.5, 8.3, 8.3]) == [False] * 6 + [True]
    # a non-finite best never counts as stagnant
    assert stops([np.inf] * 4 + [5.0] * 4) == [False] * 7 + [True]
    assert stops([10.0, 5.0, 2.0], generations=3) == [False, False, True]  # the budget
    with pytest.raises(InputError, match="patience"):
        Stagnation(patience=0)
    with pytest.raises(InputError, match="rtol"):
        Stagnation(rtol=np.nan)


@pytest.mark.parametrize("name", GENERATIONAL)
def test_stops_early_on_a_flat_objective(name):
    # relative changes of at most 1e-6: stagnant from the start; the first stop is at patience + 1
    def nearly_flat(X):
        return 1.0 + 1e-6 * bowl(X)

    reported = []
    run = run_optimizer(
        name, nearly_flat, pop_size=16, generations=100, seed=1, stagnation=Stagnation(patience=10),
        on_generation=lambda gen, total, best: reported.append((gen, total, best)),
    )  # fmt: skip
    assert len(run.history) == 11
    assert reported == [(g + 1, 100, best) for g, best in enumerate(run.history)]


@pytest.mark.parametrize("name", GENERATIONAL)
def test_runs_to_the_budget_while_improving(name):
    # every batch is 10 % better than the one before, whatever the points: never stagnant
    calls = [0]

    def improving(X):
        calls[0] += 1
        return 0.9 ** calls[0] * (1.0 + bowl(X))

    run = run_optimizer(
        name, improving, pop_size=16, generations=30, seed=1, stagnation=Stagnation(patience=5)
    )
    assert len(run.history) == 30


def test_the_ga_runs_the_offspring_asked_for_and_still_reaches_the_bowl():
    # the start table's GA makes half its population new each generation (`limits.TABLE_OFFSPRING`):
    # each generation evaluates that many rows, and the elitist survival still finds the bowl's bottom
    sizes = []

    def counted(X):
        sizes.append(len(X))
        return bowl(X)

    run = run_optimizer(
        "ga", counted, pop_size=20, generations=50, seed=1, stagnation=NO_EARLY_STOP, offspring=10
    )
    assert sizes[0] == 20 and set(sizes[1:]) == {10} and len(sizes) == 50
    assert run.evaluations == 20 + 49 * 10
    assert run.f < 1e-2 and np.linalg.norm(run.x - CENTRE) < 0.1
    full = run_optimizer("ga", bowl, pop_size=20, generations=50, seed=1, stagnation=NO_EARLY_STOP)
    assert full.evaluations == 20 * 50 and not np.array_equal(full.x, run.x)
    for name, offspring in (("ga", 0), ("ga", 21), ("de", 10)):
        with pytest.raises(InputError, match="offspring per generation"):
            run_optimizer(name, bowl, pop_size=20, generations=5, seed=1, offspring=offspring)


def test_the_polish_never_returns_a_worse_point():
    rng = np.random.default_rng(0)
    starts = [OptimizerRun(x, float(bowl(x[None, :])[0]), 0, [0.0]) for x in rng.uniform(0, 1, (2, 8))]
    starts.append(OptimizerRun(CENTRE.copy(), 0.0, 0, [0.0]))  # at the minimum already
    for start in starts:
        run = polish(bowl, start, seed=1)
        assert run.f <= start.f and run.f == bowl(run.x[None, :])[0]
        assert run.evaluations > start.evaluations and run.history[:1] == start.history
    # a start better than anything the polish can find (e.g. from a lower-valued measurement)
    start = OptimizerRun(CENTRE + 0.05, -1.0, 7, [-1.0])
    run = polish(bowl, start, seed=1)
    assert run.f == -1.0 and np.array_equal(run.x, start.x) and run.evaluations > 7
    # and it improves a start away from the minimum
    away = starts[0]
    assert polish(bowl, away, seed=1).f < 1e-2 * away.f


def test_the_polish_same_seed_same_point_other_seed_differs():
    # the polish's seeding on a cheap objective (an identification's polish passes its seed down)
    x0 = np.clip(CENTRE + 0.15, 0.0, 1.0)
    start = OptimizerRun(x0, float(bowl(x0[None, :])[0]), 0, [0.0])
    a, b, c = (polish(bowl, start, seed=s, budget=(8, 5)) for s in (3, 3, 4))
    np.testing.assert_array_equal(a.x, b.x)
    assert a.f == b.f and a.history == b.history and a.evaluations == b.evaluations
    assert not np.array_equal(a.x, c.x)
    assert a.f < start.f and c.f < start.f  # each ran and moved the point


def banana(X):
    """Residuals of a curved valley in the unit box (Rosenbrock's, shifted): minimum 0 at
    (0.8, 0.64), reached along x1 = x0²; the other six coordinates sit in a bowl at CENTRE."""
    X = np.atleast_2d(X)
    return np.column_stack([10.0 * (X[:, 1] - X[:, 0] ** 2), 0.8 - X[:, 0], X[:, 2:] - CENTRE[2:]])


def sum_sq(R):
    return np.sum(R**2, axis=1)


def test_the_least_squares_polish_follows_a_curved_valley_and_never_returns_worse():
    x0 = np.array([0.3, 0.09, *CENTRE[2:]])  # on the valley's floor, far from its minimum
    start = OptimizerRun(x0, float(sum_sq(banana(x0))[0]), 5, [1.0])
    run = least_squares_polish(banana, start)
    assert run.f < 1e-6 * start.f and np.allclose(run.x[:2], [0.8, 0.64], atol=1e-3)
    assert run.f == pytest.approx(float(sum_sq(banana(run.x))[0]), rel=1e-9, abs=1e-15)
    assert 5 < run.evaluations <= 5 + (1 + 8) * 30 and run.history[:1] == start.history
    # the CMA-ES polish on the same objective, the same number of evaluations, stops short of it
    cma = polish(lambda X: sum_sq(banana(X)), start, seed=1, budget=(8, max((run.evaluations - 5) // 8, 2)))
    assert cma.f > 100 * run.f
    # a start at the minimum is kept; so is one whose value is already better than any it finds
    best = np.array([0.8, 0.64, *CENTRE[2:]])
    kept = least_squares_polish(banana, OptimizerRun(best, 0.0, 0, []))
    assert kept.f == 0.0 and np.array_equal(kept.x, best)
    lower = least_squares_polish(banana, OptimizerRun(x0, -1.0, 0, []))
    assert lower.f == -1.0 and np.array_equal(lower.x, x0) and lower.evaluations > 0


def test_the_least_squares_polish_reaches_a_minimum_on_the_upper_bound():
    def edge(X):  # minimum 0 at x0 = 1 (the box's bound), the rest at CENTRE; undefined beyond
        X = np.atleast_2d(X)
        R = np.column_stack([1.0 - X[:, 0], X[:, 1:] - CENTRE[1:]])
        R[X[:, 0] > 1.0] = np.nan
        return R

    x0 = np.array([0.98, *CENTRE[1:]])
    start = OptimizerRun(x0, float(sum_sq(edge(x0))[0]), 0, [])
    run = least_squares_polish(edge, start)  # within a step of the bound: the backward difference
    assert run.x[0] == pytest.approx(1.0, abs=1e-3) and run.f < 1e-3 * start.f


def test_the_least_squares_polish_survives_residuals_that_are_not_finite():
    def holes(X):
        R = banana(X)
        R[np.atleast_2d(X)[:, 0] > 0.7, 0] = np.nan  # the way to the minimum crosses a hole
        return R

    x0 = np.array([0.3, 0.09, *CENTRE[2:]])
    start = OptimizerRun(x0, float(sum_sq(banana(x0))[0]), 0, [])
    run = least_squares_polish(holes, start)
    assert np.isfinite(run.f) and run.f <= start.f and run.x[0] <= 0.7
    # a start whose own residual is not finite is returned as it is
    bad = OptimizerRun(np.array([0.75, 0.5, *CENTRE[2:]]), 1.0, 3, [1.0])
    kept = least_squares_polish(holes, bad)
    assert np.array_equal(kept.x, bad.x) and kept.f == 1.0 and kept.evaluations == 4


def test_import_cmaes_puts_the_blocked_modules_back_when_the_import_fails(monkeypatch):
    import sys

    from emaphm.identification import cmaes
    from emaphm.identification.cmaes import CMA_UNUSED_IMPORTS, import_cmaes

    for name in ("cma", *CMA_UNUSED_IMPORTS):
        monkeypatch.delitem(sys.modules, name, raising=False)
    monkeypatch.setitem(sys.modules, "pymoo.algorithms.soo.nonconvex.cmaes", None)  # the import fails
    monkeypatch.setattr(cmaes, "_others_run", lambda: False)  # the blocking in effect
    with pytest.raises(ImportError):
        import_cmaes()
    for name in CMA_UNUSED_IMPORTS:
        assert name not in sys.modules  # not left behind as None: importable again


def in_a_fresh_process(code: str) -> list[str]:
    """What `code` prints in a new interpreter, split on whitespace."""
    import subprocess
    import sys

    return subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout.split()


def test_the_polishs_cma_es_imports_lean_beside_emaphms_helper_threads_only():
    # the twin's thread while the warm-up imports it (`warm.load_search_kernels`): still lean; any
    # other thread might import the blocked modules meanwhile, so then nothing is blocked
    code = (
        "import sys, threading, time\n"
        "from emaphm.identification import cmaes\n"
        "stop = threading.Event()\n"
        "helper = threading.Thread(target=stop.wait, name='emaphm-measure_0')\n"
        "helper.start()\n"
        "print(cmaes._others_run())\n"
        "cmaes.import_polish()\n"
        "print('matplotlib' in sys.modules, 'scipy.stats' in sys.modules, 'cma' in sys.modules)\n"
        "other = threading.Thread(target=stop.wait)\n"
        "other.start()\n"
        "print(cmaes._others_run())\n"
        "stop.set()\n"
    )
    out = in_a_fresh_process(code)
    assert out == ["False", "False", "False", "True", "True"], out


def test_import_cmaes_leaves_moocore_unimported_and_pymoos_indicators_working():
    # the stand-in `cmaes._LazyMoocore`: pymoo's hypervolume imports the real moocore when called
    code = (
        "import sys, numpy as np\n"
        "from emaphm.identification.cmaes import import_cmaes\n"
        "import_cmaes()\n"
        "print('moocore' in sys.modules)\n"
        "from pymoo.indicators.hv import Hypervolume\n"
        "print(Hypervolume(ref_point=np.ones(2)).do(np.array([[0.5, 0.5], [0.2, 0.8]])))\n"
        "import moocore\n"
        "print(type(moocore).__name__, moocore.hypervolume(np.array([[0.5, 0.5]]), ref=np.ones(2)))\n"
    )
    out = in_a_fresh_process(code)
    assert out == ["False", "0.31", "module", "0.25"], out


def test_the_relative_stop_stops_where_pymoos_objective_space_termination_with_its_delta_does():
    # optimizers.RelativeObjectiveTermination is built on pymoo's DeltaToleranceTermination with
    # SingleObjectiveSpaceTermination's _data; the same delta on pymoo's own class stops alike
    from pymoo.termination.ftol import SingleObjectiveSpaceTermination
    from pymoo.termination.robust import RobustTermination

    from emaphm.identification.optimizers import RelativeObjectiveTermination

    class Theirs(SingleObjectiveSpaceTermination):
        _delta = RelativeObjectiveTermination._delta

    rng = np.random.default_rng(5)
    for trial in range(40):
        steps = rng.choice([0.0, 1e-4, 5e-4, 2e-3, 0.05], size=30, p=[0.4, 0.2, 0.15, 0.15, 0.1])
        best = 1.0 - np.cumsum(steps) * (0.5 if trial % 2 else 1.0)
        if trial % 5 == 0:
            best[:3] = np.inf  # nothing feasible yet
        ours, theirs = (
            RobustTermination(cls(1e-3), period=4) for cls in (RelativeObjectiveTermination, Theirs)
        )
        for g, f in enumerate(best):
            feasible = np.isfinite([f, f + 1.0])
            algorithm = SimpleNamespace(
                opt=SimpleNamespace(
                    get=lambda key, f=f, feas=feasible: np.array([f, f + 1.0]) if key == "f" else feas
                )
            )
            assert ours.update(algorithm) == theirs.update(algorithm), (trial, g)
            assert ours.has_terminated() == theirs.has_terminated()


def test_the_least_squares_polish_evaluates_no_point_twice():
    # its Jacobian starts from the residual scipy has just evaluated at that point, and scipy's
    # second look at the start reuses the first: every row evaluated is a new point
    rows = []

    def counted(X):
        rows.extend(map(tuple, np.atleast_2d(X)))
        return banana(X)

    x0 = np.array([0.3, 0.09, *CENTRE[2:]])
    run = least_squares_polish(counted, OptimizerRun(x0, float(sum_sq(banana(x0))[0]), 0, [1.0]))
    assert run.f < 1e-6 and run.evaluations == len(rows) > 2 * 8
    assert len(set(rows)) == len(rows)
