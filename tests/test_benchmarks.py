"""Every benchmark runs at its smallest arguments, every study answers --help (review M5; ProgPy's
tests/test_examples.py does the same for its examples). The figures are not checked: a smoke run
tells that a script still runs against today's package, not what it measures."""

from __future__ import annotations

import importlib
import runpy
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BENCHMARKS = ROOT / "benchmarks"
STUDIES = sorted((ROOT / "studies").glob("*.py"))
TINY = ["--pop-size", "4", "--generations", "1", "--no-polish"]  # an identification of ~0.1 s

SMALLEST = {
    "bench_hf": [
        ["--repeats", "1"],
        ["--batch", "2", "--repeats", "1"],
        ["--control", "foc", "--repeats", "1"],
    ],
    "bench_lf": [["--repeats", "1", "--population", "4", "--evaluate", "4", "--rounds", "1"]],
    "bench_identify": [
        [
            "--cases",
            "1",
            "--repeats",
            "1",
            "--optimizers",
            "ga",
            "--table1-seeds",
            "1",
            "--uq-repeats",
            "1",
            *TINY,
        ]
    ],
    "bench_multifault": [["--cases", "1", "--seeds", "1", "--restarts", "1", "--last-stage", "none", *TINY]],
    "monitor_fidelity": [["--cases", "1", "--commands", "chirp"]],
    "bench_foc": [["--cases", "1", "--seeds", "1", "--healthy", "0", "--last-stage", "none", *TINY]],
    "uq_coverage": [["--cases", "2", "--healthy", "1", *TINY]],
    "bench_reader": [["--cases", "1", *TINY]],
    "bench_campaign": [["--jobs", "2", "--tiny", "2", *TINY], ["--load", "10"]],
    "bench_rul_speed": [["--flights", "10", "--runs", "1"]],
    "bench_fleet": [["--actuators", "30", "--flights", "4", "--runs", "1"]],
    "bench_rig_mistakes": [["--only", "control,current_gain_1.05", *TINY]],
    "bench_baseline": [["--actuators", "1", "--cases", "1", "--healthy", "0", *TINY]],
}
NEEDS = {
    "bench_campaign": ["dask.distributed", "pyarrow"],
    "bench_rul_speed": ["pyarrow"],
    "bench_fleet": ["pyarrow", "psutil"],
    "bench_reader": [],
}


@pytest.fixture
def bench(monkeypatch):
    """Import a benchmark as its command line does (benchmarks/ first on sys.path), with the process
    state the scripts touch (NUMBA_NUM_THREADS, sys.path) restored afterwards."""
    monkeypatch.syspath_prepend(str(BENCHMARKS))
    monkeypatch.delenv("NUMBA_NUM_THREADS", raising=False)  # bench_hf sets it; restored at teardown

    def load(name: str):  # type: ignore[no-untyped-def]
        return importlib.import_module(name)

    return load


def test_every_benchmark_script_has_a_smoke_run():
    scripts = {p.stem for p in BENCHMARKS.glob("*.py") if not p.stem.startswith("_")}
    scripts -= {"detection_thresholds"}  # becomes `emaphm calibrate-detection` (issue 31)
    assert scripts == set(SMALLEST) | {"bench_rul"}


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(SMALLEST))
def test_benchmark_runs_at_its_smallest_arguments(name, bench, capsys):
    for module in NEEDS.get(name, []):
        pytest.importorskip(module)
    main = bench(name).main
    for argv in SMALLEST[name]:
        main(argv)
    assert capsys.readouterr().out.startswith("emaphm ")  # the machine line comes first


@pytest.mark.slow
def test_bench_rul_runs_on_a_tiny_run_to_failure_store(bench, tmp_path, capsys):
    pytest.importorskip("pyarrow")
    from emaphm.campaign import run_campaign

    spec = tmp_path / "rtf.toml"
    spec.write_text(
        '[campaign]\nname = "rtf"\nseeds = [1]\n\n'
        "[identify]\npop_size = 24\ngenerations = 6\npolish = false\n\n"
        '[[actuator]]\nid = "R00"\nflights = 6\n'
        "start  = [0.2, 0.1, 0, 0, 0, 0, 0, 0.5]\ngrowth = [0.04, 0.025, 0, 0, 0, 0, 0, 0]\n"
    )  # six flights of ~0.2 s: backlash is detected at flight 2 and predicted at flight 4
    run_campaign(spec, tmp_path / "store", workers=1)
    # a 24 x 6 search without polish fits poorly: its diagnoses are doubtful (all, or all but one or
    # two), and left out unless asked, so that no prediction is scored
    bench("bench_rul").main([str(tmp_path / "store"), "--spec", str(spec)])
    out = capsys.readouterr().out
    assert "are doubtful" in out or ("no prediction at flight" in out and "met: 0 of 0" in out)
    bench("bench_rul").main([str(tmp_path / "store"), "--spec", str(spec), "--include-doubtful"])
    assert "relative accuracy at lambda" in capsys.readouterr().out  # a prediction was scored


@pytest.mark.slow
@pytest.mark.parametrize("path", STUDIES, ids=[p.stem for p in STUDIES])
def test_study_answers_help(path, monkeypatch, capsys):
    """Studies are not rerun (each names the commit its figures came from); --help must still
    parse, import and not start the study."""
    monkeypatch.setattr(sys, "path", list(sys.path))  # a study puts benchmarks/ on it
    monkeypatch.setattr(sys, "argv", [str(path), "--help"])
    with pytest.raises(SystemExit) as exit_:
        runpy.run_path(str(path), run_name="__main__")
    assert exit_.value.code == 0
    assert "usage:" in capsys.readouterr().out


@pytest.mark.parametrize("name", sorted(SMALLEST), ids=sorted(SMALLEST))
def test_benchmark_answers_help(name, bench, capsys):
    """--help prints the usage and exits 0 (the settings' help texts hold a "%", which argparse
    formats: bench_multifault's --help raised a TypeError until the flags escaped it)."""
    with pytest.raises(SystemExit) as exit_:
        bench(name).main(["--help"])
    assert exit_.value.code == 0
    assert "usage:" in capsys.readouterr().out
