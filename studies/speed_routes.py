"""Issue 36: what the identification's stages cost and what changing each does to accuracy.

    python studies/speed_routes.py ROUTE [bench_multifault options ...]

Runs `benchmarks/bench_multifault.py` (its cases, seeds and figures: %err median / p90 / max, wrong
basins, wall time per identification) with one route applied in this process:

- ``default``: today's pipeline (GA search, the least-squares polish of the best point and up to
  four distinct runner-ups, the CMA-ES polish of the best of them, the final checks, the last
  least-squares polish, the switching last stage);
- ``lm-only``: the polish stage without its CMA-ES (least squares of the candidates alone);
- ``cmaes-only``: the polish stage as the CMA-ES of the best point alone: with
  ``--optimizer multistart`` (whose own polish stage does nothing) a CMA-ES after its descents;
- ``descents``: the polish stage as eight least-squares descents from the search's best point
  and its best population members 0.1 apart (`descents.descend_from`), no CMA-ES: with
  ``--generations 20`` the "GA 96 x 20 + descents" of BENCHMARKS.md, issue 36.

With ``--pop-size`` / ``--generations`` (bench_multifault's) the GA's budget changes too. The
routes measured before issue 36's change (the two CMA-ES polishes, smaller ones, none) ran at
635ecde, the pipeline they changed at 8967746 (``git worktree add W 8967746``, then
``env PYTHONPATH=W/src python W/studies/speed_routes.py default ...``).

Example: ``python studies/speed_routes.py lm-only --cases 40 --seeds 2 --restarts 0 --case-seed 7``.
Figures: BENCHMARKS.md, "Issue 36".
"""

from __future__ import annotations

import sys
from pathlib import Path

ROUTES = ("default", "lm-only", "cmaes-only", "descents")


def lm_only_stage(state, context):  # type: ignore[no-untyped-def]
    """The polish stage as the least squares of the candidates alone: the best point's
    (`descents.lm_polish`) in place of its CMA-ES, then its runner-ups' (`polish.polish_runner_ups`)."""
    from emaphm.identification.descents import lm_polish
    from emaphm.identification.polish import polish_runner_ups
    from emaphm.identification.problem import recentre_phase

    if not context.settings.polish:
        return state, {"stage": "polish", "ran": False}
    search = state.run
    best = lm_polish(context.residuals(), recentre_phase(search))
    run, won = polish_runner_ups(context.residuals(), context.evaluate, search, best)
    return state.with_run(run), {"stage": "polish", "ran": True, "runner_up": won > 0, "candidate": won,
                                 "fitness": run.f}  # fmt: skip


def cmaes_only_stage(state, context):  # type: ignore[no-untyped-def]
    """The polish stage as the CMA-ES of the best point alone (`polish.polish`)."""
    from emaphm.identification.polish import polish
    from emaphm.identification.problem import recentre_phase

    if not context.settings.polish:
        return state, {"stage": "polish", "ran": False}
    run = polish(context.evaluate, recentre_phase(state.run), seed=context.seed, on_generation=context.on_generation)
    return state.with_run(run), {"stage": "polish", "ran": True, "runner_up": False, "candidate": 0, "fitness": run.f}


def descents_stage(state, context):  # type: ignore[no-untyped-def]
    """The polish stage as eight descents from the search's distinct best points (0.1 apart)."""
    from emaphm.identification.descents import descend_from
    from emaphm.identification.optimizers import OptimizerRun

    if not context.settings.polish:
        return state, {"stage": "polish", "ran": False}
    search = state.run
    end, start = descend_from(search, context.residuals(), context.evaluate, 8, 0.1)
    if not end.f < search.f:  # the search's point stands, the descents' evaluations counted
        end, start = OptimizerRun(search.x, search.f, end.evaluations, search.history), -1
    return state.with_run(end), {"stage": "polish", "ran": True, "candidate": start, "fitness": end.f}


def apply(route: str) -> None:
    from emaphm.identification import polish, search

    def swap(old, new):  # type: ignore[no-untyped-def]
        search.SEARCH_STAGES = tuple(new if stage is old else stage for stage in search.SEARCH_STAGES)

    if route == "lm-only":
        swap(polish.polish_stage, lm_only_stage)
    elif route == "cmaes-only":
        swap(polish.polish_stage, cmaes_only_stage)
    elif route == "descents":
        swap(polish.polish_stage, descents_stage)
    elif route != "default":
        raise SystemExit(f"unknown route {route!r}; one of {', '.join(ROUTES)}")


def main(argv: list[str] | None = None) -> None:
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     epilog="Other options go to benchmarks/bench_multifault.py.")  # fmt: skip
    parser.add_argument("route", choices=ROUTES)
    args, rest = parser.parse_known_args(argv)
    apply(args.route)
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "benchmarks"))
    import bench_multifault

    print(f"route: {args.route}")
    bench_multifault.main(rest)


if __name__ == "__main__":
    main()
