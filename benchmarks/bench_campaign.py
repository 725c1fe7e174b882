"""Campaign throughput on this machine: Dask LocalCluster vs a plain serial loop of the same jobs (issue 11).

    python benchmarks/bench_campaign.py [--jobs 16] [--tiny 60] [--case-seed 5101]
    python benchmarks/bench_campaign.py --load 100000
    python benchmarks/bench_campaign.py --fleet 1000

Smallest run (the smoke test): ``--jobs 2 --tiny 2 --pop-size 4 --generations 1 --no-polish``,
and ``--load 10``.
Reported in BENCHMARKS.md, "Fleet campaigns".

1. Throughput. --jobs random multi-fault actuators on the twin (DESIGN §7 ranges, the script's own
   seed), each identified as ``emaphm identify --true-faults K --seed 1`` does (default budget,
   Laplace intervals), run twice: a plain serial loop in this process on one numba thread, and
   ``run_campaign`` on a LocalCluster of one worker per core (one numba thread each). Printed:
   identifications per hour of each, their ratio (target >= 1.8x on 2 cores, goal >= 1.95x),
   with and without the cluster's start.
2. Overhead per job. --tiny jobs of a few ms of work (pop 4 x 1 generation, no polish, no
   intervals, a 0.2 s chirp) through the same campaign: (loop wall x workers - the jobs' own
   wall time) / jobs, the cluster's start excluded (target <= 50 ms).
The estimates of both runs are compared (they must be identical).

--fleet N instead runs one campaign of N such actuators on the LocalCluster alone (issue 36's
fleet of 1 000 identifications): identifications per hour with and without the cluster's start, per
core, the jobs' own median time, and how many ended "fits", "doubtful" or failed.

--load N instead times reading a campaign file of N actuators (one-off twin measurements, the
script's seed), `load_campaign`, and making its jobs with their keys and fingerprints,
`CampaignSpec.jobs()`, which `campaign run` and `campaign status` do before anything else (issue
35's target: ≤ 5 s for 100 000 actuators). Printed: each of the two, best of 3, and the peak
resident memory of the process.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from _cases import add_settings, budget_text, draw_cases, machine_line  # benchmarks/ is first on sys.path

from emaphm.campaign import ResultStore, load_campaign, run_campaign, run_job


def spec_file(folder: Path, name: str, cases: np.ndarray, identify: str = "") -> Path:
    text = f'[campaign]\nname = "{name}"\nseeds = [1]\n\n[identify]\n{identify}\n'
    for j, k in enumerate(cases):
        text += f'[[actuator]]\nid = "C{j:03d}"\nfaults = [{", ".join(f"{v:.6f}" for v in k)}]\n\n'
    path = folder / f"{name}.toml"
    path.write_text(text)
    return path


def load_time(n: int, seed: int) -> None:
    """--load: the time to read a campaign file of n actuators and to make its jobs."""
    import resource

    print(machine_line(f"a campaign file of {n} actuators (seed {seed})"))
    with tempfile.TemporaryDirectory() as name:
        spec = spec_file(Path(name), "load", draw_cases(n, seed))
        reads, makes = [], []
        for _ in range(3):
            t0 = time.perf_counter()
            campaign = load_campaign(spec)
            t1 = time.perf_counter()
            jobs = campaign.jobs()
            reads.append(t1 - t0)
            makes.append(time.perf_counter() - t1)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"load_campaign: {min(reads):.2f} s; jobs(): {min(makes):.2f} s ({len(jobs)} jobs); "
          f"together {min(reads) + min(makes):.2f} s (best of 3); peak memory {peak:.0f} MB")  # fmt: skip


def fleet_throughput(n: int, seed: int) -> None:
    """--fleet: n identifications at the default budget in one campaign on a LocalCluster."""
    from collections import Counter

    cores = len(os.sched_getaffinity(0))
    print(machine_line(f"a fleet campaign of {n} actuators (seed {seed}), default budget, {cores} workers"))
    with tempfile.TemporaryDirectory() as name:
        tmp = Path(name)
        spec = spec_file(tmp, "fleet", draw_cases(n, seed))

        def progress(done: int, failed: int, todo: int, elapsed: float) -> None:  # todo: the run's jobs
            if (done + failed) % 50 == 0 or done + failed == todo:
                print(f"  {done + failed} of {todo} jobs, {elapsed:.0f} s", file=sys.stderr, flush=True)

        summary = run_campaign(spec, tmp / "store", workers=cores, progress=progress)
        rows = ResultStore(tmp / "store").read("results", "fleet").to_pylist()
    loop = summary.wall_time_s - summary.startup_s
    per_h = 3600.0 * summary.done
    verdicts = Counter(str(r.get("verdict")) for r in rows)
    print(f"campaign, {summary.backend}: {summary.done} done, {summary.failed} failed in {summary.wall_time_s:.0f} s "
          f"({summary.startup_s:.1f} s start): {per_h / summary.wall_time_s:.0f} identifications/h "
          f"({per_h / loop:.0f} without the start; {per_h / summary.wall_time_s / cores:.0f} per core)")  # fmt: skip
    walls = [r["wall_time_s"] for r in rows]
    print(f"the jobs' own time: median {np.median(walls):.2f} s, p90 {np.percentile(walls, 90):.2f} s; "
          f"verdicts {dict(sorted(verdicts.items()))}")  # fmt: skip


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jobs", type=int, default=16)
    parser.add_argument("--tiny", type=int, default=60)
    parser.add_argument("--case-seed", type=int, default=5101)
    parser.add_argument("--load", type=int, default=None, help="time reading a campaign of N actuators instead")
    parser.add_argument("--fleet", type=int, default=None, help="one campaign of N actuators on the cluster alone")
    add_settings(parser)
    args = parser.parse_args(argv)
    if args.load is not None:
        load_time(args.load, args.case_seed)
        return
    if args.fleet is not None:
        if args.fleet < 1:
            parser.error(f"--fleet needs at least 1 actuator, got {args.fleet}")
        fleet_throughput(args.fleet, args.case_seed)
        return
    cores = len(os.sched_getaffinity(0))
    print(
        machine_line(f"{args.jobs} jobs (seed {args.case_seed}), {args.tiny} tiny jobs, {budget_text(args)}")
    )
    identify = "".join(f"{key} = {value}\n" for key, value in (("pop_size", args.pop_size),
                       ("generations", args.generations)) if value is not None)  # fmt: skip
    identify += "polish = false\n" if not args.polish else ""
    with tempfile.TemporaryDirectory() as name:
        tmp = Path(name)
        spec = spec_file(tmp, "bench", draw_cases(args.jobs, args.case_seed), identify)
        jobs = load_campaign(spec).jobs()
        run_job(jobs[0].to_dict())  # compile cache loaded, as the campaign's warm-up does
        t0 = time.perf_counter()
        serial = {j.key: run_job(j.to_dict()) for j in jobs}
        t_serial = time.perf_counter() - t0
        summary = run_campaign(spec, tmp / "store", workers=cores)
        rows = {r["job_key"]: r for r in ResultStore(tmp / "store").read().to_pylist()}
        same = all(
            [rows[k][f"k{i}"] for i in range(1, 9)] == [serial[k][f"k{i}"] for i in range(1, 9)]
            for k in serial
        )
        loop = summary.wall_time_s - summary.startup_s
        per_h = 3600.0 * len(jobs)
        print(f"serial loop, 1 thread: {t_serial:.1f} s, {per_h / t_serial:.0f} identifications/h "
              f"(median job {np.median([r['wall_time_s'] for r in serial.values()]):.2f} s)")  # fmt: skip
        print(f"campaign, {summary.backend}: {summary.wall_time_s:.1f} s of which {summary.startup_s:.1f} s start, "
              f"{per_h / summary.wall_time_s:.0f} identifications/h ({per_h / loop:.0f} without the start)")  # fmt: skip
        print(f"throughput ratio campaign / serial: {t_serial / summary.wall_time_s:.2f}x with the start, "
              f"{t_serial / loop:.2f}x without; estimates identical: {same}")  # fmt: skip
        own_c = sum(r["wall_time_s"] for r in rows.values())
        own_s = sum(r["wall_time_s"] for r in serial.values())
        print(f"the jobs' own time: {own_s:.1f} s serial, {own_c:.1f} s in the campaign ({own_c / own_s:.2f}x: two "
              f"jobs at once slow each other); busy share of the {summary.workers} workers "
              f"{own_c / (loop * summary.workers):.3f}")  # fmt: skip

        tiny = spec_file(tmp, "tiny", draw_cases(args.tiny, args.case_seed + 1),
                         'pop_size = 4\ngenerations = 1\npolish = false\nuncertainty = "none"\n')  # fmt: skip
        small = run_campaign(tiny, tmp / "store", workers=cores)
        own = sum(r["wall_time_s"] for r in ResultStore(tmp / "store").read("results", "tiny").to_pylist())
        loop = small.wall_time_s - small.startup_s
        print(f"tiny jobs: {small.done} in {loop:.2f} s after a {small.startup_s:.1f} s start on {small.workers} "
              f"workers; their own time {own:.2f} s; overhead per job "
              f"{1000 * (loop * small.workers - own) / small.done:.1f} ms")  # fmt: skip


if __name__ == "__main__":
    main()
