"""Two files of `benchmarks/bench_multifault.py` on the same cases, compared run by run.

    python studies/paired_runs.py BEFORE.txt AFTER.txt [BEFORE2.txt AFTER2.txt ...]

Reads each run's case, seed, %err and search fitness (f_run) from the per-run lines, pairs the
runs of the same case and seed, and prints for AFTER against BEFORE: %err median / p90 / max of
each side, the paired %err difference (mean ± standard error), and the runs whose search fitness
is above 1.2x the other side's (a wrong basin, as the benchmark counts them) with their cases.
Issue 36 used it for the start table against the uniform GA (BENCHMARKS.md).
"""

from __future__ import annotations

import argparse
import statistics
import sys
from pathlib import Path


def runs(path: Path) -> dict[tuple[int, int], tuple[float, float]]:
    """(case, seed) -> (%err, f_run) from a bench_multifault output file."""
    out: dict[tuple[int, int], tuple[float, float]] = {}
    for line in path.read_text().splitlines():
        parts = line.split()
        if len(parts) < 7 or not parts[0].isdigit() or not parts[3].isdigit():
            continue
        out[(int(parts[0]), int(parts[3]))] = (float(parts[4]), float(parts[5]))
    return out


def p90(values: list[float]) -> float:
    return statistics.quantiles(values, n=10, method="inclusive")[-1]


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("files", nargs="+", type=Path, help="BEFORE AFTER pairs")
    args = parser.parse_args(argv)
    if len(args.files) % 2:
        sys.exit("paired_runs: give the files as BEFORE AFTER pairs")
    before_err, after_err, diffs, wrong = [], [], [], []
    for a, b in zip(args.files[::2], args.files[1::2], strict=True):
        ra, rb = runs(a), runs(b)
        for key in sorted(set(ra) & set(rb)):
            (ea, fa), (eb, fb) = ra[key], rb[key]
            before_err.append(ea)
            after_err.append(eb)
            diffs.append(eb - ea)
            if fb > 1.2 * fa or fa > 1.2 * fb:
                wrong.append(f"{b.name} case {key[0]} seed {key[1]}: f {fa:.4f} -> {fb:.4f} ({fb / fa:.2f}x)")
    if len(diffs) < 2:
        sys.exit("paired_runs: fewer than 2 runs in common")
    se = statistics.stdev(diffs) / len(diffs) ** 0.5
    for name, e in (("before", before_err), ("after", after_err)):
        print(f"{name}: %err median {statistics.median(e):.2f}, p90 {p90(e):.2f}, max {max(e):.2f} ({len(e)} runs)")
    print(f"paired %err difference (after - before): {statistics.mean(diffs):+.3f} +- {se:.3f}")
    print(f"search fitness more than 1.2x apart: {len(wrong)} of {len(diffs)}")
    for line in wrong:
        print("  " + line)


if __name__ == "__main__":
    main()
