"""Issue 36: a benchmark run with another number of the start table's GA offspring per generation.

    python studies/ga_offspring.py OFFSPRING SCRIPT [ARGS ...]
    python studies/ga_offspring.py 32 benchmarks/bench_multifault.py --cases 40 --seeds 2 --restarts 0 --case-seed 6061

Sets `limits.TABLE_OFFSPRING` to OFFSPRING / the GA's default population (96) in this process and
runs SCRIPT (a benchmark of `benchmarks/`) with ARGS as ``python SCRIPT ARGS`` would. The twelfth
session of issue 36 chose 48 (0.5) this way over 32 and 64 (BENCHMARKS.md, "Half the GA's
offspring from the start table"). It ran an equivalent scratch wrapper on ee3012a, before the
constant existed, which set pymoo's ``n_offsprings``; at 48 its output was 086c97d's to the bit
(bench_multifault seed 2611), so the figures there are this study's at 086c97d.
"""

from __future__ import annotations

import argparse
import runpy
import sys
from pathlib import Path


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("offspring", type=int, help="new points per generation (of the population of 96)")
    parser.add_argument("script", help="a benchmark script, e.g. benchmarks/bench_multifault.py")
    parser.add_argument("args", nargs=argparse.REMAINDER, help="its arguments")
    args = parser.parse_args(argv)
    from emaphm.identification import limits

    population = limits.DEFAULT_BUDGETS["ga"][0]
    if not 1 <= args.offspring <= population:
        parser.error(f"offspring must be 1 to the GA's population {population}, got {args.offspring}")
    limits.TABLE_OFFSPRING = args.offspring / population
    sys.argv = [args.script, *args.args]
    sys.path.insert(0, str(Path(args.script).resolve().parent))  # the benchmarks' own `_cases`
    runpy.run_path(args.script, run_name="__main__")


if __name__ == "__main__":
    main()
