"""Issue 36: the multistart search against the GA on the random twin cases where it failed.

    python studies/multistart_cases.py [--configs ga,256/8,1024/8,...] [--cases 6061/1/2,7/2/1,...]

Each case (case seed / case / seed, `bench_multifault.py`'s numbering) is measured once as
``emaphm identify --true-faults K --seed S`` measures it, then identified by each configuration
(``ga``: the default pipeline; ``N/D``: ``--optimizer multistart --pop-size N --generations D``),
without the last stage and intervals (the search's basin is what is compared). Prints per case
each configuration's search fitness over the best any of them found (1.2 and above: a wrong
basin, as bench_multifault counts them) and its monitor evaluations.

The default cases are the six where 256/8 or other budgets ended above 1.04 x in the runs of
BENCHMARKS.md, issue 36; they were chosen by those failures, so a configuration that passes them
has to pass fresh seeds too (bench_multifault.py --optimizer multistart).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

HARD = "6061/1/2,6061/34/1,7/2/2,7/9/2,6061/19/2,7/2/1"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--configs", default="ga,256/8,512/8,1024/8")
    parser.add_argument("--cases", default=HARD)
    args = parser.parse_args(argv)
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "benchmarks"))
    from _cases import machine_line, measure

    import emaphm
    from emaphm.faults import random_faults

    configs = args.configs.split(",")
    print(machine_line(f"cases {args.cases}; configurations {args.configs}; last stage none, no intervals"))
    for case in args.cases.split(","):
        case_seed, j, seed = (int(v) for v in case.split("/"))
        k = random_faults(max(j + 1, 40), seed=case_seed)[j]
        trace = measure(k, seed)
        row = []
        for config in configs:
            kw: dict[str, object] = {"uncertainty": "none", "last_stage": "none"}
            if config != "ga":
                sample, descents = config.split("/")
                kw.update(optimizer="multistart", pop_size=int(sample), generations=int(descents))
            run = emaphm.identify(reference=trace, seed=seed, **kw)
            row.append((run.settings["search_fitness"], run.evaluations))
        best = min(f for f, _ in row)
        print(f"{case:>10}: " + "  ".join(f"{c} {f / best:.3f} ({n})" for c, (f, n) in zip(configs, row, strict=True)),
              flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
