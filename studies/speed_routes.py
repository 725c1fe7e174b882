"""Issue 36: what the identification's stages cost and what changing each does to accuracy.

    python studies/speed_routes.py ROUTE [bench_multifault options ...]

Runs `benchmarks/bench_multifault.py` (its cases, seeds and figures: %err median / p90 / max, wrong
basins, wall time per identification) with one route applied in this process:

- ``default``: today's pipeline (GA search, the least-squares polish of the best point and up to
  four distinct runner-ups, the CMA-ES polish of the best of them, the final checks, the last
  least-squares polish, the switching last stage);
- ``lm-only``: the polish stage without its CMA-ES (least squares of the candidates alone).

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

ROUTES = ("default", "lm-only")


def lm_only_stage(state, context):  # type: ignore[no-untyped-def]
    """The polish stage as the least squares of the candidates alone (`polish.polish_candidates`)."""
    from emaphm.identification.polish import polish_candidates

    if not context.settings.polish:
        return state, {"stage": "polish", "ran": False}
    run, won, count = polish_candidates(context.residuals(), context.evaluate, state.run)
    return state.with_run(run), {"stage": "polish", "ran": True, "runner_up": won > 0, "candidate": won,
                                 "candidates": count, "fitness": run.f}  # fmt: skip


def apply(route: str) -> None:
    from emaphm.identification import polish, search

    if route == "lm-only":
        search.SEARCH_STAGES = tuple(
            lm_only_stage if stage is polish.polish_stage else stage for stage in search.SEARCH_STAGES
        )
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
