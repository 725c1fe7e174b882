"""Speed of `emaphm rul` on a 100-flight history (issue 12 target: <= 2 s, goal <= 0.3 s).

    python benchmarks/bench_rul_speed.py [--flights 100] [--runs 5]

Writes a results store with one actuator whose friction grows linearly over --flights flights
(each row as a campaign writes it, with its interval and verdicts), then times the whole command
`emaphm rul STORE --actuator A1 --threshold friction=0.45 --json` (process start included), and
once with `--plot`. Prints min / median / max wall seconds.

Smallest run (the smoke test): ``--flights 10 --runs 1``. Reported in BENCHMARKS.md, "Prognostics".
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from _cases import RESULT_COLUMNS, machine_line  # benchmarks/ is the script's folder, first on sys.path

from emaphm.campaign import ResultStore


def rows(flights: int) -> list[dict]:
    rng = np.random.default_rng(0)
    out = []
    for n in range(1, flights + 1):
        row = {c: None for c in RESULT_COLUMNS}
        row.update(job_key=f"A1-{n}", campaign="c", actuator="A1", flight=n, seed=1, identify_seed=1, verdict="fits",
                   **{f"k{i}": 0.0 for i in range(1, 9)}, **{f"std_k{i}": 0.01 for i in range(1, 9)},
                   fault_verdicts=json.dumps({"friction": "present"}), uq_flags=json.dumps([[]] * 8))  # fmt: skip
        row["k1"], row["k8"] = 0.05 + 0.004 * n + rng.normal(0.0, 0.01), 0.5
        out.append(row)
    return out


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--flights", type=int, default=100)
    parser.add_argument("--runs", type=int, default=5)
    args = parser.parse_args(argv)
    print(machine_line(f"{args.flights} flights, {args.runs} runs"))
    with tempfile.TemporaryDirectory() as name:
        store = Path(name) / "store"
        ResultStore(store).write("results", rows(args.flights))
        base = [
            sys.executable,
            "-m",
            "emaphm",
            "rul",
            str(store),
            "--actuator",
            "A1",
            "--threshold",
            "friction=0.45",
        ]
        for label, extra in (("--json", ["--json"]), ("--plot", ["--plot", str(Path(name) / "r.png")])):
            times = []
            for _ in range(args.runs + 1):  # the first run warms the file cache, not counted
                t0 = time.perf_counter()
                subprocess.run([*base, *extra], check=True, capture_output=True)
                times.append(time.perf_counter() - t0)
            t = times[1:]
            print(f"emaphm rul {label}, {args.flights} flights: min {min(t):.2f} s, median {statistics.median(t):.2f} s, "
                  f"max {max(t):.2f} s ({args.runs} runs)")  # fmt: skip


if __name__ == "__main__":
    main()
