"""`emaphm demo`: the main job on its built-in default, the paper's Table 1 experiment.

The HF twin plays an actuator with the Table 1 reference faults (DESIGN §2), measured with noise;
the fault vector is identified five times (optimiser seeds 1..5, as the paper ran its GA five
times) and printed like Table 1 with %err, mean ± sd and the wall time of each run. Figures go to
the output folder: the HF response, measured vs identified current with the residual, the
convergence of the five runs, and the identified vs the true vector.

The runs are sequential: each one already spreads its population over all cores (the LF
population kernel), so running them side by side would not be faster on a 2-core machine.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from contextlib import nullcontext
from pathlib import Path
from typing import Any

import numpy as np
from rich.console import Console
from rich.table import Table

from .actuator import resolve_params
from .calibration import Calibration
from .errors import InputError
from .faults import FAULT_NAMES, HEALTHY, TABLE1_REFERENCE
from .identification.api import identify
from .identification.detection import detect
from .identification.metrics import percent_error
from .identification.settings import IdentifySettings
from .models import MonitorEma, simulate
from .models._base import check_seed
from .params import EmaParams
from .plots import plot_convergence, plot_fit, plot_response, plot_vectors
from .tables import fault_table

__all__ = ["PAPER_TABLE1_PERCENT_ERR", "run_demo"]

PAPER_TABLE1_PERCENT_ERR = (4.46, 4.67, 4.16, 4.96, 4.93)  # the paper's Table 1, for comparison


def run_demo(
    output_dir: Path,
    *,
    seed: int = 0,
    runs: int = 5,
    settings: IdentifySettings | None = None,
    calibration: Calibration | str | os.PathLike[str] | None = None,
    console: Console | None = None,
    status: Callable[[str], Any] | None = None,
    params: EmaParams | str | os.PathLike[str] | None = None,
) -> dict[str, Any]:
    """Run the Table 1 experiment; print its table, write its figures, return its figures.

    `seed` is the measurement noise's; `runs` identifications run with optimiser seeds 1..runs
    and `settings` (`IdentifySettings`: the optimiser, the monitor, the budget; identify's
    defaults otherwise, tests use a small budget). `calibration` is the LF calibration (default:
    the packaged one of the settings' monitor); `params` the actuator (`EmaParams` or an actuator
    file; its calibration must be given too, see `emaphm.actuator`). `console` prints the table,
    `status(message)` shows what runs.
    """
    console = console or Console()
    output_dir = Path(output_dir)
    s = settings if settings is not None else IdentifySettings()
    optimizer = s.optimizer
    _check_inputs(output_dir, runs=runs, seed=seed)
    actuator = resolve_params(params)
    monitor_model = MonitorEma(actuator, calibration=calibration, monitor=s.monitor)  # refused now if it does not fit

    def stage(message: str) -> Any:
        return status(message) if status else nullcontext()

    truth = np.array(TABLE1_REFERENCE)
    with stage("simulating the actuator (HF twin, Table 1 faults, noise on)"):
        measured = simulate(truth, noise=True, seed=seed, params=actuator)
        healthy = simulate(HEALTHY, noise=True, seed=seed, params=actuator)
    results = []
    for run_seed in range(1, runs + 1):
        with stage(f"identification {run_seed}/{runs} ({optimizer.upper()}, seed {run_seed})"):
            results.append(
                identify(
                    reference=measured, settings=s, seed=run_seed, calibration=monitor_model.calibration,
                    params=actuator,
                )
            )
    errors = [percent_error(r.estimate, truth) for r in results]
    console.print(_table(truth, results, errors, title=f"The paper's Table 1 experiment on the HF twin "
                                                       f"({optimizer.upper()}, noise seed {seed})"))  # fmt: skip
    mean, sd = float(np.mean(errors)), float(np.std(errors, ddof=1)) if runs > 1 else 0.0
    times = [r.wall_time_s for r in results]
    _print_summary(console, truth, results, mean=mean, sd=sd)
    figures = _write_figures(output_dir, monitor_model, truth, results, measured=measured, healthy=healthy)
    console.print("figures: " + ", ".join(str(f) for f in figures))
    return {
        "percent_error": errors,
        "mean": mean,
        "sd": sd,
        "wall_time_s": times,
        "estimates": [r.estimate.tolist() for r in results],
        "figures": [str(f) for f in figures],
    }


def _check_inputs(output_dir: Path, *, runs: int, seed: int) -> None:
    """Refuse, before the work, an output folder that cannot be written and bad run settings."""
    if output_dir.exists() and not output_dir.is_dir():
        raise InputError(f"--output-dir {output_dir} exists and is not a folder")
    existing = next(p for p in (output_dir, *output_dir.absolute().parents) if p.exists())
    if not os.access(existing, os.W_OK | os.X_OK):
        raise InputError(f"--output-dir {output_dir}: {existing} is not writable")
    if runs < 1:
        raise InputError(f"runs must be >= 1, got {runs}")
    check_seed(seed)


def _table(truth: np.ndarray, results: list[Any], errors: list[float], *, title: str) -> Table:
    """Table 1: the reference faults, then each run's estimate, %err and wall time."""
    table = Table(title=title)
    table.add_column("")
    for i in range(len(FAULT_NAMES)):
        table.add_column(f"k{i + 1}", justify="right")
    table.add_column("%err", justify="right")
    table.add_column("time \\[s]", justify="right")  # escaped: rich reads [s] as markup
    table.add_row("Ref.", *(f"{v:.4g}" for v in truth), "", "")
    for j, (r, e) in enumerate(zip(results, errors, strict=True), start=1):
        table.add_row(str(j), *(f"{v:.4f}" for v in r.estimate), f"{e:.2f}", f"{r.wall_time_s:.1f}")
    return table


def _print_summary(
    console: Console, truth: np.ndarray, results: list[Any], *, mean: float, sd: float
) -> None:
    """%err against the paper's, the wall times, what was detected, the best run's diagnosis."""
    times = [r.wall_time_s for r in results]
    paper = np.array(PAPER_TABLE1_PERCENT_ERR)
    console.print(
        f"%err {mean:.2f} ± {sd:.2f} (mean ± sd over {len(results)} runs); the paper: {paper.mean():.2f} ± "
        f'{paper.std(ddof=1):.2f} in "minutes" per run. Wall time per run {np.mean(times):.1f} s '
        f"(min {min(times):.1f}, max {max(times):.1f})."
    )
    detected = sorted({name for r in results for name in r.detected})
    present = set(detect(truth))
    marked = [name if name in present else f"{name} (not in the truth: model bias)" for name in detected]
    console.print(f"detected in at least one run: {', '.join(marked) or 'none'}")
    best_at = int(np.argmin([r.fitness for r in results]))
    best = results[best_at]
    if best.uncertainty is not None:
        shown = {**best.to_json(), "truth": truth.tolist()}  # the demo knows the truth of its measurement
        console.print(fault_table(shown, f"Diagnosis of the best-fitting run (seed {best_at + 1})"))


def _write_figures(
    output_dir: Path, monitor_model: MonitorEma, truth: np.ndarray, results: list[Any], *, measured: Any,
    healthy: Any,
) -> list[Path]:  # fmt: skip
    """The HF response, the best run's fit, every run's convergence, the estimates vs the truth."""
    output_dir.mkdir(parents=True, exist_ok=True)
    best = results[int(np.argmin([r.fitness for r in results]))]
    lf = monitor_model.simulate(best.estimate)
    bounds = {
        f"seed {j}": (r.uncertainty.ci90_low, r.uncertainty.ci90_high)
        for j, r in enumerate(results, start=1)
        if r.uncertainty is not None
    }
    undefined = {
        f"seed {j}"
        for j, r in enumerate(results, start=1)
        if r.uncertainty is not None and "phase_undefined" in r.uncertainty.flags[6]
    }
    return [
        plot_response({"healthy": healthy, "Table 1 faults": measured}, output_dir / "hf_table1.png",
                      "High-fidelity EMA twin, FDI chirp (noise on)"),
        plot_fit(measured.t, measured.i_q, lf.i_q, output_dir / "identified_current.png"),
        plot_convergence({f"seed {j}": r.history for j, r in enumerate(results, start=1)},
                         output_dir / "convergence.png"),
        plot_vectors(truth, {f"seed {j}": r.estimate for j, r in enumerate(results, start=1)}, FAULT_NAMES,
                     output_dir / "identified_vs_true.png", intervals=bounds, phase_undefined=undefined),
    ]  # fmt: skip
