"""Issue 36: where one identification's wall time goes, stage by stage and before the search.

    python studies/stage_times.py [--repeats 3] [--seed 1]

Runs the Table 1 case (``emaphm identify --true-faults <Table 1> --seed S``) through the CLI
--repeats times in this one process, with each stage of the search (`search.SEARCH_STAGES`) and
of the identification after it (`identifier.AFTER_SEARCH`) timed. The first run pays what a
fresh process pays (the imports after the CLI's, the kernels' first calls; until the tenth session
scipy.optimize for the last polish); later runs show the stages warm. Prints for each run the time from this script's
start (or from the run's start) to `api.identify`, to `FaultIdentifier.fit`, the fit, what follows
it, each stage's wall time and the monitor evaluations. Not a benchmark: one process, no pairing
(the paired figures are `farm-bench`'s, BENCHMARKS.md "Issue 36").
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import time

T0 = time.perf_counter()

TABLE1 = "0.2383,0.5003,0,0.4503,0.0404,0.0028,0.2785,0.5"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args(argv)
    import emaphm.cli as cli
    from emaphm.identification import api, identifier, search

    marks: dict[str, float] = {}
    stages: dict[str, float] = {}

    def timed(name, f, into):  # type: ignore[no-untyped-def]
        def run(*a, **k):  # type: ignore[no-untyped-def]
            t = time.perf_counter()
            out = f(*a, **k)
            into[name] = into.get(name, 0.0) + time.perf_counter() - t
            return out

        return run

    def marked(label, f):  # type: ignore[no-untyped-def]
        def run(*a, **k):  # type: ignore[no-untyped-def]
            marks[label] = time.perf_counter()
            out = f(*a, **k)
            marks[label + " end"] = time.perf_counter()
            return out

        return run

    search.SEARCH_STAGES = tuple(timed(s.__name__, s, stages) for s in search.SEARCH_STAGES)
    identifier.AFTER_SEARCH = tuple(timed(s.__name__, s, stages) for s in identifier.AFTER_SEARCH)
    api.identify = marked("identify", api.identify)
    identifier.FaultIdentifier.fit = marked("fit", identifier.FaultIdentifier.fit)
    argv_cli = ["identify", "--true-faults", TABLE1, "--seed", str(args.seed), "--json"]
    for r in range(args.repeats):
        marks.clear()
        stages.clear()
        start = T0 if r == 0 else time.perf_counter()
        out = io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.suppress(SystemExit):
            cli.main(argv_cli)
        end = time.perf_counter()
        evaluations = json.loads(out.getvalue())["evaluations"]
        print(f"run {r + 1}{' (from the script start)' if r == 0 else ''}: to identify {marks['identify'] - start:.3f} s, "
              f"to the fit {marks['fit'] - marks['identify']:.3f} s, the fit {marks['fit end'] - marks['fit']:.3f} s, "
              f"after it {end - marks['fit end']:.3f} s; {evaluations} evaluations")  # fmt: skip
        print("   " + ", ".join(f"{k} {v:.3f}" for k, v in stages.items()))


if __name__ == "__main__":
    main()
