"""The read side of a fleet at scale: `emaphm fleet` and `campaign status` on a large store (issue 35).

    python benchmarks/bench_fleet.py [--actuators 10000] [--flights 20] [--runs 3] [--keep DIR]

Writes a synthetic results store (`emaphm.campaign.synthetic`: one part file per actuator, as a
campaign's batched writes leave it; estimates that degrade with noise, 5 % doubtful, 1 % not
fitting) and a campaign file of the same actuators and flights, then times whole processes
(start included) and their peak memory (the process and its children, sampled every 20 ms):

- `emaphm fleet STORE --json` on the store as written: the first run compacts its part files;
- the same again `--runs` times (compacted), and once with `--output DIR` (the page, CSV, JSON);
- `emaphm campaign status SPEC STORE` `--runs` times.

Targets (issue 35): fleet <= 10 s and <= 2 GB, campaign status <= 5 s on 10 000 x 20.
Smallest run (the smoke test): ``--actuators 30 --flights 4 --runs 1``. BENCHMARKS.md, "Fleet".
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _cases import machine_line  # benchmarks/ is the script's folder, first on sys.path

from emaphm.campaign.synthetic import write_synthetic_store

SPEC = """[campaign]
name = "synthetic"
[identify]
uncertainty = "none"
[[fleet]]
prefix = "A"
count = {count}
seed = 1
flights = {flights}
start = [[0, 0.05], 0, 0, 0, 0, 0, 0, 0.5]
growth = [[0, 0.01], 0, 0, 0, 0, 0, 0, 0]
usage = {{ hours = 2.5, first_date = 2026-01-01, days = 3 }}
"""


def timed(args: list[str]) -> tuple[float, float]:
    """Wall seconds and peak memory [MB] (the process tree's RSS, sampled) of `emaphm ARGS`."""
    import psutil

    start = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-m", "emaphm", *args], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    peak = 0
    parent = psutil.Process(proc.pid)
    while proc.poll() is None:
        try:
            tree = [parent, *parent.children(recursive=True)]
            peak = max(peak, sum(p.memory_info().rss for p in tree))
        except psutil.Error:
            pass
        time.sleep(0.02)
    wall = time.perf_counter() - start
    if proc.returncode != 0:
        raise SystemExit(f"emaphm {' '.join(args)} failed: {proc.stderr.read().decode()[-500:]}")
    return wall, peak / 1e6


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--actuators", type=int, default=10_000)
    parser.add_argument("--flights", type=int, default=20)
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--keep", type=Path, help="Write the store here and keep it (default: a temporary folder).")
    a = parser.parse_args(argv)
    print(machine_line())
    with tempfile.TemporaryDirectory() as tmp:
        root = a.keep or Path(tmp)
        store, spec, page = root / "store", root / "fleet.toml", root / "page"
        t0 = time.perf_counter()
        rows = write_synthetic_store(store, a.actuators, a.flights, seed=0)
        spec.write_text(SPEC.format(count=a.actuators, flights=a.flights))
        print(f"store: {a.actuators} actuators x {a.flights} flights = {rows} rows, written in "
              f"{time.perf_counter() - t0:.1f} s (one part file per actuator)")  # fmt: skip
        first = timed(["fleet", str(store), "--json"])
        print(f"fleet --json, first run (compacts {a.actuators} part files): {first[0]:.2f} s, {first[1]:.0f} MB")
        report("fleet --json, compacted", [timed(["fleet", str(store), "--json"]) for _ in range(a.runs)])
        report("fleet --output DIR", [timed(["fleet", str(store), "--output", str(page)])])
        report("campaign status", [timed(["campaign", "status", str(spec), str(store)]) for _ in range(a.runs)])


def report(what: str, runs: list[tuple[float, float]]) -> None:
    walls = [w for w, _ in runs]
    print(f"{what}: wall min / median / max {min(walls):.2f} / {statistics.median(walls):.2f} / "
          f"{max(walls):.2f} s over {len(runs)} run(s), peak {max(m for _, m in runs):.0f} MB")  # fmt: skip


if __name__ == "__main__":
    main()
