"""Recordings through the reader (issue 10): the same diagnosis from any format, and from phase currents.

    python benchmarks/bench_reader.py [--cases 6] [--case-seed 3301] [--part formats|phases|both]

Smallest run (the smoke test): ``--cases 1 --pop-size 4 --generations 1 --no-polish``. Reported in
BENCHMARKS.md, "Recordings through the reader".

Cases: random multi-fault actuators in the DESIGN §7 ranges (`emaphm.faults.random_faults`, the
script's own seed), each simulated once on the HF twin with noise on (noise seed = case index).

formats: the twin's trace is written as our HDF5 and re-expressed three ways, each read through a
channel map: CSV with renamed columns in ms, mA and deg; MATLAB .mat v5 (variables in mA and
deg, a 10 kHz rate instead of a time vector); Parquet in SI with other names (needs pyarrow).
Each is identified with the same seed as the native file; printed: the largest difference per
fault from the native estimate (target: <= 0.005).

phases: i_q is not given; the map gives two phase currents (mA) and the electrical angle (deg,
wrapped, with a random offset the reader must find). At 5 kHz (every other sample of the 10 kHz
twin), and at 20 kHz (the twin of benchmarks/actuators/fs20k.toml, whose electronics sample at
20 kHz, with its own calibration fs20k.cal.json; the native i_q of that twin is the reference).
Printed: %err native vs from the phases (target: within 1 point) and the offset error (target:
within 1 deg).
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np
from _cases import (  # benchmarks/ first
    add_settings,
    budget,
    budget_text,
    draw_cases,
    load_params,
    machine_line,
)

import emaphm

HERE = Path(__file__).resolve().parent
FS20K, FS20K_CAL = HERE / "actuators" / "fs20k.toml", HERE / "actuators" / "fs20k.cal.json"


def write_csv(path: Path, columns: dict[str, np.ndarray]) -> Path:
    rows = np.column_stack(list(columns.values()))
    np.savetxt(path, rows, delimiter=",", header=",".join(columns), comments="", fmt="%.17g")
    return path


def write_map(path: Path, entries: dict[str, str]) -> Path:
    path.write_text("[channels]\n" + "".join(f"{role} = {{ {e} }}\n" for role, e in entries.items()))
    return path


BUDGET: dict[str, object] = {}  # the identification's budget, set by main from --pop-size etc.


def identify(
    reference: Path, seed: int, channel_map: Path | None = None, **kw: object
) -> emaphm.IdentificationResult:
    return emaphm.identify(reference=reference, seed=seed, channel_map=channel_map, **BUDGET, **kw)  # type: ignore[arg-type]


def formats(cases: np.ndarray, tmp: Path) -> None:
    import scipy.io

    print(
        "\nformats: the same trace, native and re-expressed; largest |difference| per fault from the native estimate"
    )
    worst = np.zeros(8)
    for j, k in enumerate(cases):
        r = emaphm.simulate(k, seed=j)
        native = identify(emaphm.write_trace(r, tmp / f"c{j}.h5"), seed=1)
        csv = write_csv(tmp / f"c{j}.csv", {"time_ms": r.t * 1e3, "demand_deg": np.degrees(r.theta_cmd),
                                             "surface_deg": np.degrees(r.theta_u), "Iq_mA": r.i_q * 1e3})  # fmt: skip
        csv_map = write_map(tmp / "csv.toml", {
            "t": 'name = "time_ms", unit = "ms"', "theta_cmd": 'name = "demand_deg", unit = "deg"',
            "theta_u": 'name = "surface_deg", unit = "deg"', "i_q": 'name = "Iq_mA", unit = "mA"',
        })  # fmt: skip
        scipy.io.savemat(tmp / f"c{j}.mat", {"cmd": np.degrees(r.theta_cmd)[:, None], "pos": np.degrees(r.theta_u)[:, None],
                                             "iq": (r.i_q * 1e3)[:, None]})  # fmt: skip
        mat_map = write_map(tmp / "mat.toml", {
            "theta_cmd": 'name = "cmd", unit = "deg", fs = 10000', "theta_u": 'name = "pos", unit = "deg", fs = 10000',
            "i_q": 'name = "iq", unit = "mA", fs = 10000',
        })  # fmt: skip
        runs = {"csv": identify(csv, 1, csv_map), "mat v5": identify(tmp / f"c{j}.mat", 1, mat_map)}
        try:
            import pyarrow as pa
            import pyarrow.parquet as pq

            pq.write_table(pa.table({"time": r.t, "demand": r.theta_cmd, "surface": r.theta_u, "current": r.i_q}),
                           tmp / f"c{j}.parquet")  # fmt: skip
            pq_map = write_map(tmp / "pq.toml", {
                "t": 'name = "time", unit = "s"', "theta_cmd": 'name = "demand", unit = "rad"',
                "theta_u": 'name = "surface", unit = "rad"', "i_q": 'name = "current", unit = "A"',
            })  # fmt: skip
            runs["parquet"] = identify(tmp / f"c{j}.parquet", 1, pq_map)
        except ImportError:
            print("  (no pyarrow: Parquet skipped)")
        for name, run in runs.items():
            diff = np.abs(run.estimate - native.estimate)
            worst = np.maximum(worst, diff)
            print(f"  case {j} {name:>8}: max |diff| {diff.max():.2e} (fault k{int(np.argmax(diff)) + 1}), "
                  f"%err {emaphm.percent_error(run.estimate, k):.2f} vs native {emaphm.percent_error(native.estimate, k):.2f}",
                  flush=True)  # fmt: skip
    print("largest |difference| per fault over all cases and formats: " + " ".join(f"{v:.1e}" for v in worst))


def phase_files(r: emaphm.SimResult, every: int, offset_deg: float, path: Path) -> Path:
    """i_a, i_b (mA) and the wrapped electrical angle (deg) minus `offset_deg`, every `every`-th sample."""
    s = slice(None, None, every)
    theta_e = np.degrees(np.mod(r["theta_e"][s] - np.radians(offset_deg), 2 * np.pi))
    return write_csv(path, {"t_ms": r.t[s] * 1e3, "cmd": np.degrees(r.theta_cmd[s]), "pos": np.degrees(r.theta_u[s]),
                            "Ia": r["i_a"][s] * 1e3, "Ib": r["i_b"][s] * 1e3, "elec": theta_e})  # fmt: skip


def phases(cases: np.ndarray, tmp: Path, seed: int) -> None:
    print("\nphases: %err from two phase currents + the electrical angle (unknown offset) vs the native i_q")
    cmap = write_map(tmp / "phases.toml", {
        "t": 'name = "t_ms", unit = "ms"', "theta_cmd": 'name = "cmd", unit = "deg"', "theta_u": 'name = "pos", unit = "deg"',
        "i_a": 'name = "Ia", unit = "mA"', "i_b": 'name = "Ib", unit = "mA"', "theta_e": 'name = "elec", unit = "deg"',
    })  # fmt: skip
    rng = np.random.default_rng(seed)
    setups = [("5 kHz", None, 2)]
    if FS20K_CAL.is_file():
        setups.append(("20 kHz", load_params(FS20K), 1))
    else:
        print(
            f"  (no {FS20K_CAL.name}: run 'emaphm calibrate --params {FS20K} --output {FS20K_CAL}' for 20 kHz)"
        )
    table: dict[str, list[tuple[float, float, float]]] = {name: [] for name, _, _ in setups}
    for j, k in enumerate(cases):
        for name, params, every in setups:
            kw = {} if params is None else {"params": params, "calibration": FS20K_CAL}
            r = emaphm.HighFidelityEma(params).simulate(k, seed=j)
            native = identify(emaphm.write_trace(r, tmp / "native.h5"), 1, **kw)
            offset = float(rng.uniform(0.0, 360.0))
            t0 = time.perf_counter()
            run = identify(phase_files(r, every, offset, tmp / "phases.csv"), 1, cmap, **kw)
            wall = time.perf_counter() - t0
            found = run.settings["conversion"]["angle"]["offset_deg"]
            off_err = abs((found - offset + 180.0) % 360.0 - 180.0)
            e_nat, e_ph = emaphm.percent_error(native.estimate, k), emaphm.percent_error(run.estimate, k)
            table[name].append((e_nat, e_ph, off_err))
            print(f"  case {j} {name:>6}: %err native {e_nat:.2f}, from phases {e_ph:.2f} (diff {e_ph - e_nat:+.2f}); "
                  f"offset {offset:.1f} deg found to {off_err:.3f} deg; {wall:.1f} s", flush=True)  # fmt: skip
    for name, rows in table.items():
        d = [b - a for a, b, _ in rows]
        print(f"{name}: %err native median {statistics.median(a for a, _, _ in rows):.2f}, from phases "
              f"{statistics.median(b for _, b, _ in rows):.2f}; diff max {max(d, key=abs):+.2f} points; "
              f"offset error max {max(c for _, _, c in rows):.3f} deg")  # fmt: skip


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=6)
    parser.add_argument("--case-seed", type=int, default=3301)
    parser.add_argument("--part", choices=("formats", "phases", "both"), default="both")
    add_settings(parser)
    args = parser.parse_args(argv)
    BUDGET.clear()
    BUDGET.update(budget(args))
    print(machine_line(f"{args.cases} cases (seed {args.case_seed}), {budget_text(args)}"))
    cases = draw_cases(args.cases, args.case_seed)
    with tempfile.TemporaryDirectory() as name:
        if args.part in ("formats", "both"):
            formats(cases, Path(name))
        if args.part in ("phases", "both"):
            phases(cases, Path(name), args.case_seed)


if __name__ == "__main__":
    main()
