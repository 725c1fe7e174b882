"""A benchmark run with other values of the identification's tuned constants (`limits`).

    python studies/limits_variant.py NAME=VALUE [NAME=VALUE ...] -- SCRIPT [ARGS ...]
    python studies/limits_variant.py "SWITCHING_STEP_FACTORS=(2.0, 2.5)" -- benchmarks/bench_multifault.py --cases 40 --seeds 2 --restarts 0 --case-seed 2611

Sets each `emaphm.identification.limits` constant NAME to VALUE (a Python literal) in this process
and runs SCRIPT (a benchmark of `benchmarks/`) with ARGS as ``python SCRIPT ARGS`` would; compare
its output with `studies/paired_runs.py`. The thirteenth session of issue 36 measured two cheaper
last stages this way and took neither (BENCHMARKS.md, issue 36, thirteenth session): the switching
model on two steps, ``SWITCHING_STEP_FACTORS=(2.0, 2.5)``, and two space-mapping iterations,
``SWITCHING_ITERATIONS=2`` (8bcfe83's estimates; `studies/ga_offspring.py` does the same for the
GA's offspring alone).
"""

from __future__ import annotations

import argparse
import ast
import runpy
import sys
from pathlib import Path


def main(argv: list[str] | None = None) -> None:
    argv = sys.argv[1:] if argv is None else argv
    parser = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0], usage="%(prog)s NAME=VALUE [NAME=VALUE ...] [--] SCRIPT [ARGS ...]"
    )
    if not argv or argv[0] in ("-h", "--help"):
        parser.parse_args(["--help"] if argv else [])
        parser.error("give at least one NAME=VALUE and a SCRIPT")
    from emaphm.identification import limits

    n = next((i for i, a in enumerate(argv) if "=" not in a or a.startswith("-")), len(argv))
    settings, rest = argv[:n], argv[n + 1 :] if argv[n : n + 1] == ["--"] else argv[n:]
    if not settings or not rest:
        parser.error("give at least one NAME=VALUE and a SCRIPT")
    for setting in settings:
        name, _, text = setting.partition("=")
        if not hasattr(limits, name):
            parser.error(f"{name!r} is not a constant of emaphm.identification.limits")
        try:
            value = ast.literal_eval(text)
        except (ValueError, SyntaxError):
            parser.error(f"{text!r} is not a Python literal")
        setattr(limits, name, value)
    script, args = rest[0], rest[1:]
    sys.argv = [script, *args]
    sys.path.insert(0, str(Path(script).resolve().parent))  # the benchmarks' own `_cases`
    runpy.run_path(script, run_name="__main__")


if __name__ == "__main__":
    main()
