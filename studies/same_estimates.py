# Study, not a benchmark (issue 31): the check that the reorganisation kept every estimate to the
# bit. Run it at two commits and compare the files (`cmp`, or the diff of their JSON).
"""The identifications whose numbers a refactor must keep: Table 1 seed 1 and the first five random
cases of `benchmarks/bench_multifault.py` (case seed 2611, seed 1), default settings.

    python studies/same_estimates.py OUT.json

Writes each run's estimate, fitness, fit NRMSE, evaluations and 90 % bounds.
"""

from __future__ import annotations

import argparse
import json

import emaphm
from emaphm.faults import TABLE1_REFERENCE, random_faults
from emaphm.identification.recording import split_seed

FIELDS = ("estimate", "fitness", "fit_nrmse", "evaluations", "ci90_low", "ci90_high")


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("output", help="JSON file to write")
    parser.add_argument("--cases", type=int, default=5)
    args = parser.parse_args(argv)
    runs = {"table1_seed1": emaphm.identify(true_faults=TABLE1_REFERENCE, seed=1).to_json()}
    twin = emaphm.HighFidelityEma()
    for c, k in enumerate(random_faults(args.cases, 2611)):
        trace = twin.simulate(k, noise=True, seed=split_seed(1)[0])
        runs[f"case{c}"] = emaphm.identify(reference=trace, seed=1).to_json()
    out = {name: {f: data[f] for f in FIELDS} for name, data in runs.items()}
    with open(args.output, "w") as fh:
        json.dump(out, fh, indent=1)
    print(f"wrote {args.output} ({len(out)} identifications)")


if __name__ == "__main__":
    main()
