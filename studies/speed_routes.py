"""Issue 36, first look: what the identification's stages cost and what dropping each does to accuracy.

    python studies/speed_routes.py ROUTE [bench_multifault options ...]

Runs `benchmarks/bench_multifault.py` (its cases, seeds and figures: %err median / p90 / max, wrong
basins, wall time per identification) with one route of issue 36 applied in this process:

- ``default``: today's pipeline (GA search, the CMA-ES polish of the best point and its runner-up,
  the least-squares polish, the switching last stage);
- ``no-cmaes``: the CMA-ES polish skipped (`polish.polish_two` returns its start), the least-squares
  polish kept: the profile's 43 % of the CPU;
- ``small-cmaes``: the CMA-ES polish of the best point only, budget (16, 20);
- ``small-two``: the CMA-ES polish of the best point and its runner-up, budget (16, 20) each.

Example: ``python studies/speed_routes.py no-cmaes --cases 20 --seeds 2 --restarts 0``. Figures
(BENCHMARKS.md, "Issue 36, first measurements") at 635ecde.
"""

from __future__ import annotations

import sys
from pathlib import Path

ROUTES = ("default", "no-cmaes", "small-cmaes", "small-two")


def apply(route: str) -> None:
    from emaphm.identification import limits, polish

    if route == "no-cmaes":
        polish.polish_two = lambda evaluate, run, **kw: (run, False)  # type: ignore[assignment]
    elif route == "small-cmaes":
        limits.POLISH_BUDGET = (16, 20)  # type: ignore[misc]
        polish.polish_two = lambda evaluate, run, **kw: (polish.polish(evaluate, run, seed=kw.get("seed", 0)), False)  # type: ignore[assignment]
    elif route == "small-two":
        limits.POLISH_BUDGET = (16, 20)  # type: ignore[misc]
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
