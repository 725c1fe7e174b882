"""The ``emaphm`` command line: argument parsing and printing only (DESIGN §8).

Exit status: 0 success, 2 bad input or usage (one-line reason on stderr), 1 failure (one line
too: a diverged simulation, a file system error), 3 `identify` ran but the monitor cannot explain
the recording (verdict "does not fit", no faults reported), 130 interrupted (Ctrl-C). Every check of the
input, output paths included, runs before the work, and no output is ever left half-written.

Only light modules are imported at start (`emaphm --version` and `--help` answer at once); each
command imports what it needs.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager, nullcontext
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.console import Console

from ._threads import numba_threads
from .choices import COMMAND_NAMES, HEALTHY_TEXT, LAST_STAGES, UQ_METHODS
from ._version import __version__
from .errors import InputError, SimulationError

CALIBRATION_HELP = "LF calibration file from 'emaphm calibrate' (default: the packaged one)."
PARAMS_HELP = "Actuator file (TOML, from 'emaphm params --template'); default: the paper's nominal actuator."
MONITOR_HELP = (
    "Monitor model: 'default', or 'paper' (the paper's single-phase model, eqs. 1-2 alone); "
    "default: the calibration's."
)

app = typer.Typer(
    name="emaphm",
    help="Model-based prognostics of PMSM-driven electromechanical actuators.",
    add_completion=False,
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
)
err = Console(stderr=True, highlight=False, soft_wrap=True)  # messages whole, also in logs



def _status(message: str) -> Any:
    """A spinner on an interactive terminal, nothing otherwise (CI logs stay clean)."""
    return err.status(message) if err.is_terminal else nullcontext()


def _version(value: bool) -> None:
    if value:
        typer.echo(f"emaphm {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: Annotated[
        bool, typer.Option("--version", callback=_version, is_eager=True, help="Print the version and exit.")
    ] = False,
) -> None:
    """Model-based prognostics of PMSM-driven electromechanical actuators."""


@app.command()
def simulate(
    output: Annotated[
        Path, typer.Option("--output", "-o", help="Trace to write: .h5 or .csv (+ .csv.json).")
    ],
    faults: Annotated[
        str, typer.Option(help="Fault vector k1..k8, comma separated, each in [0, 1].")
    ] = HEALTHY_TEXT,
    model: Annotated[
        str, typer.Option(help="hf: the high-fidelity twin; lf: the calibrated monitor model.")
    ] = "hf",
    noise: Annotated[bool, typer.Option("--noise/--no-noise", help="Seeded measurement noise.")] = True,
    seed: Annotated[int, typer.Option(help="Seed of every random choice.")] = 0,
    command: Annotated[str, typer.Option(help=f"Position command: {', '.join(COMMAND_NAMES)}.")] = "chirp",
    duration: Annotated[
        float | None, typer.Option(help="Simulated time [s]; default: the command's.")
    ] = None,
    calibration: Annotated[
        Path | None, typer.Option(help=CALIBRATION_HELP + " Only with --model lf.")
    ] = None,
    monitor: Annotated[str | None, typer.Option(help=MONITOR_HELP + " Only with --model lf.")] = None,
    params: Annotated[Path | None, typer.Option("--params", help=PARAMS_HELP)] = None,
) -> None:
    """Simulate the actuator with a fault vector and write the sampled signals."""
    from .actuator import resolve_params
    from .commands import make_command
    from .faults import describe, parse_faults
    from .io import TRACE_SUFFIXES, check_output_path, write_trace
    from .models import check_seed, make_model

    k = parse_faults(faults)
    check_seed(seed)
    check_output_path(output, suffixes=TRACE_SUFFIXES, inputs=(calibration, params))  # before the work
    ema = make_model(
        model, params=resolve_params(params), command=make_command(command), calibration=calibration,
        monitor=monitor,
    )  # fmt: skip
    ema.sample_grid(duration)  # a duration no run can have: before the work
    with _status(f"simulating {model.upper()} twin ({describe(k)})"):
        result = ema.simulate(k, noise=noise, seed=seed, duration=duration)
    replaced = output.exists()
    write_trace(result, output)
    note = ", replaced the existing file" if replaced else ""
    err.print(f"wrote {output} ({len(result.t)} samples, model {model}, seed {seed}{note})")


@app.command()
def identify(
    true_faults: Annotated[
        str | None,
        typer.Option(help="Simulate the HF twin (noise on) with these faults k1..k8 and identify them."),
    ] = None,
    reference: Annotated[
        Path | None,
        typer.Option(
            help="Identify from a trace ('emaphm simulate', 'emaphm convert'), or a recording with --map."
        ),
    ] = None,
    map_file: Annotated[
        Path | None,
        typer.Option(
            "--map",
            help="Channel map (TOML) that reads --reference as a rig's recording (docs/your-actuator.md).",
        ),
    ] = None,
    optimizer: Annotated[str, typer.Option(help="ga, de, pso, cmaes or gwo.")] = "ga",
    seed: Annotated[int, typer.Option(help="Seed of the optimiser (and of the twin's noise).")] = 0,
    workers: Annotated[int, typer.Option(help="Threads for the population kernel (0: all cores).")] = 0,
    pop_size: Annotated[int | None, typer.Option(help="Population size (default per optimiser).")] = None,
    generations: Annotated[
        int | None, typer.Option(help="Maximum generations (default per optimiser).")
    ] = None,
    polish: Annotated[
        bool, typer.Option("--polish/--no-polish", help="Local polish of the best point.")
    ] = True,
    second_search: Annotated[
        bool,
        typer.Option(
            "--second-search/--no-second-search",
            help="With --polish: search again from another seed when the fit is poorer than the monitor's usual "
            "(NRMSE above 3 %; 5 % with --monitor paper), keeping the lower eq. 3 fitness (docs/identification.md).",
        ),
    ] = True,
    json_out: Annotated[bool, typer.Option("--json", help="Print one JSON object to stdout.")] = False,
    output: Annotated[
        Path | None, typer.Option("--output", "-o", help="Also write the JSON result here.")
    ] = None,
    calibration: Annotated[Path | None, typer.Option(help=CALIBRATION_HELP)] = None,
    monitor: Annotated[str | None, typer.Option(help=MONITOR_HELP)] = None,
    uncertainty: Annotated[
        str,
        typer.Option(
            help="90 % interval per fault: laplace (fast, default), mcmc (emcee, minutes; "
            "pip install 'emaphm[uq]') or none."
        ),
    ] = "laplace",
    uq_calibration: Annotated[
        Path | None,
        typer.Option(help="Interval calibration from 'emaphm calibrate-uq' (default: the packaged one)."),
    ] = None,
    params: Annotated[
        Path | None, typer.Option("--params", help=PARAMS_HELP + " Needs its --calibration.")
    ] = None,
    report: Annotated[
        Path | None,
        typer.Option(help="Also write a report to this folder: figures and a self-contained index.html."),
    ] = None,
    error_corner: Annotated[
        str,
        typer.Option(
            help="Weight eq. 3 by 1/(1 + (f/F)^2) of the command's frequency f: F in Hz, 'auto' (the "
            "default monitor's measured corner; none with --monitor paper) or 'off' (the paper's eq. 3)."
        ),
    ] = "auto",
    last_stage: Annotated[
        str,
        typer.Option(
            help="With --polish, after the search: 'switching' corrects the monitor's bias near the estimate by the twin's "
            "switching drive (about 0.5 s more), 'none' skips it, 'auto' (default) runs it with the default "
            "monitor, not with --monitor paper (docs/identification.md)."
        ),
    ] = "auto",
) -> None:
    """Identify the fault vector from a measured (or simulated) quadrature current.

    Exit status 0 with a diagnosis, 2 for bad input (nothing run), 3 when the monitor cannot
    explain the recording (verdict "does not fit": no faults are reported).
    """
    import json

    from .faults import parse_faults
    from .identification.api import identify as run_identify
    from .identification.optimizers import check_optimizer
    from .io import atomic_path, check_output_path, check_trace_path
    from .models import check_seed

    if (true_faults is None) == (reference is None):
        raise InputError("give exactly one of --true-faults or --reference")
    if uncertainty not in UQ_METHODS:
        raise InputError(f"unknown --uncertainty {uncertainty!r}; use one of {', '.join(UQ_METHODS)}")
    check_optimizer(optimizer)  # before the reference is parsed, so the reason is the optimiser
    check_seed(seed)
    corner = _error_corner(error_corner)
    if last_stage not in LAST_STAGES:
        raise InputError(f"unknown --last-stage {last_stage!r}; use one of {', '.join(LAST_STAGES)}")
    truth = parse_faults(true_faults, option="--true-faults") if true_faults is not None else None
    if reference is not None and map_file is None:
        check_trace_path(reference, for_writing=False)
    if map_file is not None:
        from .measured import ChannelMap

        if reference is None:
            raise InputError("--map reads a recording: give it with --reference")
        ChannelMap.load(map_file)  # a bad map: refused before the work
    if output is not None:
        check_output_path(
            output, suffixes=(".json",), inputs=(reference, calibration, uq_calibration, params, map_file)
        )
    if report is not None:
        from .report import check_report_dir

        check_report_dir(report)
    if uncertainty == "none" and uq_calibration is not None:
        raise InputError("--uq-calibration needs --uncertainty laplace or mcmc")
    if uncertainty != "none":
        from .identification.uncertainty import load_factors

        load_factors(uq_calibration)  # a bad file: refused before the work
    with _progress() as update:
        result = run_identify(
            truth, reference, optimizer=optimizer, seed=seed, workers=workers, pop_size=pop_size,
            generations=generations, polish=polish, second_search=second_search, calibration=calibration, monitor=monitor,
            uncertainty=uncertainty, uq_calibration=uq_calibration, params=params, channel_map=map_file,
            error_corner=corner, last_stage=last_stage,
            on_generation=lambda gen, total, best: update(
                "MCMC steps" if gen < 0 else f"{optimizer.upper()} generations", abs(gen), total
            ),
        )  # fmt: skip
    data = result.to_json()
    for warning in data["warnings"]:
        err.print(f"emaphm: warning: {warning}", soft_wrap=True)
    if output is not None:
        with atomic_path(output) as tmp:
            tmp.write_text(json.dumps(data, indent=2) + "\n")
    if report is not None:
        from .io import sha256_of
        from .report import write_report

        provenance: dict[str, Any] = {
            "reference": str(reference) if reference is not None else "HF twin, noise on",
            "sha256": sha256_of(reference) if reference is not None else None,
            "true_faults": None if truth is None else truth.tolist(),
            "channel_map": str(map_file) if map_file is not None else None,
            "conversion": data["settings"].get("conversion"),
            "params": str(params) if params is not None else "nominal",
            "calibration": str(calibration) if calibration is not None else "packaged",
        }
        page = write_report(result, report, provenance=provenance)
        err.print(f"wrote the report {page}")
    if json_out:
        typer.echo(json.dumps(data))
    else:
        _print_identification(data)
    if data["verdict"] != "fits":
        raise typer.Exit(3)  # ran, but no diagnosis: scripts must not read it as one


def _error_corner(text: str) -> float | str | None:
    """--error-corner: 'auto', 'off' or a frequency > 0 [Hz] (`identify.parse_error_corner`)."""
    from .identification.settings import parse_error_corner

    try:
        value: float | str = float(text)
    except ValueError:
        value = text
    return parse_error_corner(value, name="--error-corner")


def _print_identification(data: dict[str, Any]) -> None:
    from .tables import fault_table

    title = f"identified faults ({data['optimizer']}, seed {data['seed']}"
    title += f", 90 % intervals by {data['uq_method']})" if data["ci90_low"] is not None else ")"
    table = fault_table(data, title)
    verdicts = data.get("fault_verdicts") or {}
    out = _stdout_console()
    out.print(table)
    if data["percent_error"] is not None:
        out.print(f"%err {data['percent_error']:.2f}")
    if data["fit_nrmse"] is not None:
        out.print(
            f"fit NRMSE {100 * data['fit_nrmse']:.2f} % of the filtered current (the twin's actuators: 0.3-3.9 %; "
            "above 6 % a warning, above 50 %: does not fit)"
        )
    from .identification.result import stage_record

    second = stage_record(data["settings"], "second_search")
    if second is not None and second["ran"]:
        ratio = second["fitness_ratio"]
        kept = "its result kept" if second["taken"] else "the first search's result kept"
        out.print(
            f"second search: the first fit's NRMSE {100 * second['first_fit_nrmse']:.2f} % was above the monitor's "
            f"usual ({100 * second['trigger']:g} %); the second search's fitness "
            f"{'not finite' if ratio is None else f'{ratio:.3f} x the first'}: {kept}"
        )
    stage = (stage_record(data["settings"], "last_stage") or {}).get("switching")
    if stage is not None:
        if "error" in stage:
            out.print(f"switching last stage: not run ({stage['error']}); the search's estimate stands")
        else:
            moved = (
                f"the estimate of iterate {stage['iterate']} of {stage['iterations']} kept"
                if stage["taken"]
                else "the search's estimate fitted it best and stands"
            )
            out.print(
                f"switching last stage: the switching model's eq. 3 {stage['start_fitness']:.4g} at the search's "
                f"estimate, {stage['fitness']:.4g} at the final one ({moved}); the fit above is that model's"
            )
    if data["verdict"] != "fits":
        out.print("verdict: does not fit (see the warning): no faults reported")
    else:
        out.print(f"detected: {', '.join(data['detected']) or 'none (healthy)'}")
        unsure = [n for n, v in verdicts.items() if v == "cannot tell"]
        if unsure:
            out.print(
                f"cannot tell: {', '.join(unsure)} (the estimate departs from healthy, its interval reaches back)"
            )
    out.print(
        f"fitness {data['fitness']:.4g}, {data['evaluations']} evaluations, {data['wall_time_s']:.1f} s"
    )


@app.command()
def calibrate(
    output: Annotated[Path, typer.Option("--output", "-o", help="Calibration file to write (JSON).")] = Path(
        "lf-calibration.json"
    ),
    seed: Annotated[int, typer.Option(help="Seed of the GA and of the noisy check.")] = 1,
    pop_size: Annotated[int, typer.Option(help="GA population size.")] = 60,
    generations: Annotated[int, typer.Option(help="GA generations.")] = 150,
    workers: Annotated[int, typer.Option(help="Threads for the population kernel (0: all cores).")] = 0,
    monitor: Annotated[
        str, typer.Option(help="Monitor model to calibrate: 'default', or 'paper' (eqs. 1-2 alone).")
    ] = "default",
    params: Annotated[Path | None, typer.Option("--params", help=PARAMS_HELP)] = None,
    free: Annotated[
        str | None,
        typer.Option(
            help="Fit only these coefficients (comma-separated, e.g. 'i_D'); the others are held at --start's."
        ),
    ] = None,
    start: Annotated[
        Path | None,
        typer.Option(
            help="Calibration whose coefficients --free leaves as they are (default: the packaged one)."
        ),
    ] = None,
) -> None:
    """Re-run the LF calibration against the HF twin (of the actuator file) and write the calibration file."""
    from .actuator import resolve_params
    from .calibration import load_calibration
    from .calibration.fit_monitor import calibrate as run_calibration
    from .io import check_output_path
    from .models import check_seed

    check_seed(seed)
    check_output_path(output, suffixes=(".json",), inputs=(params, start))
    if start is not None and free is None:
        raise InputError("--start needs --free: it names the coefficients the others are held for")
    names = None if free is None else [n.strip() for n in free.split(",") if n.strip()]
    actuator = resolve_params(params)
    held = None if start is None else load_calibration(start)
    with numba_threads(workers, name="--workers"), _progress() as update:
        cal = run_calibration(
            monitor=monitor, seed=seed, pop_size=pop_size, generations=generations, progress=update,
            params=actuator, free=names, start=held,
        )  # fmt: skip
    cal.save(output)
    for key, title in (("fit_scenarios", "fitted"), ("check_scenarios", "held out")):
        values = [s["nrmse"] for s in cal.record[key]]
        err.print(
            f"{title}: NRMSE {100 * min(values):.1f} to {100 * max(values):.1f} % over {len(values)} scenarios"
        )
    err.print(
        f"wrote {output} (seed {seed}, actuator {cal.params_hash}, {cal.record['settings']['wall_time_s']:.0f} s)"
    )


@app.command("calibrate-uq")
def calibrate_uq(
    output: Annotated[
        Path, typer.Option("--output", "-o", help="Interval calibration file to write (JSON).")
    ] = Path("uq-calibration.json"),
    cases: Annotated[int, typer.Option(help="Random HF actuators to identify (about 5 s each).")] = 160,
    seed: Annotated[int, typer.Option(help="Seed of the cases, their noise and the optimiser.")] = 4101,
    calibration: Annotated[Path | None, typer.Option(help=CALIBRATION_HELP)] = None,
    monitor: Annotated[str | None, typer.Option(help=MONITOR_HELP)] = None,
    workers: Annotated[int, typer.Option(help="Threads for the population kernel (0: all cores).")] = 0,
    params: Annotated[
        Path | None, typer.Option("--params", help=PARAMS_HELP + " Needs its --calibration.")
    ] = None,
) -> None:
    """Re-fit the calibration of the 90 % intervals for the monitor's bias (after 'emaphm calibrate')."""
    from .actuator import resolve_params
    from .calibration.fit_intervals import calibrate_uq as run_calibrate_uq
    from .io import check_output_path
    from .models import MonitorEma, check_seed

    check_seed(seed)
    if cases < 20:
        raise InputError(f"--cases must be >= 20 (coverage needs a sample), got {cases}")
    check_output_path(output, suffixes=(".json",), inputs=(calibration, params))
    actuator = resolve_params(params)
    MonitorEma(actuator, calibration=calibration, monitor=monitor)  # a calibration that does not fit: now
    with numba_threads(workers, name="--workers"), _progress() as update:

        def report(stage: str, done: int, total: int) -> None:
            update(stage, done, total)
            if not err.is_terminal and (done % 10 == 0 or done == total):  # a line now and then in logs
                err.print(f"{done}/{total} {stage}")

        factors = run_calibrate_uq(
            cases=cases, seed=seed, calibration=calibration, monitor=monitor, progress=report,
            params=actuator,
        )  # fmt: skip
    factors.save(output)
    for name, fit in factors.record["training"].items():
        err.print(f"{name}: coverage {fit['coverage']:.2f}, median half-width {fit['median_half_width']:.4f}")
    err.print(f"wrote {output} ({cases} cases, seed {seed}, {factors.record['wall_time_s']:.0f} s)")


def _stdout_console() -> Console:
    """Console for results on stdout; 120 columns when not a terminal, so logs get whole tables."""
    return Console(highlight=False, width=None if sys.stdout.isatty() else 120)


@contextmanager
def _progress() -> Iterator[Callable[[str, int, int], None]]:
    """A progress bar on an interactive terminal (one task per stage); a no-op otherwise."""
    if not err.is_terminal:
        yield lambda stage, done, total: None
        return
    from rich.progress import Progress

    from .identification.cmaes import import_cmaes

    import_cmaes()  # trims cma's imports only while one thread runs: before the bar's own thread

    with Progress(console=err, transient=True) as bar:
        tasks: dict[str, Any] = {}

        def update(stage: str, done: int, total: int) -> None:
            if stage not in tasks:
                tasks[stage] = bar.add_task(stage, total=total)
            bar.update(tasks[stage], completed=done)

        yield update


@app.command()
def convert(
    source: Annotated[
        Path, typer.Argument(help="A rig's recording: CSV, HDF5, MATLAB .mat (v5, v7.3) or Parquet.")
    ],
    map_file: Annotated[
        Path, typer.Option("--map", help="Channel map (TOML): which column is which signal, in which unit.")
    ],
    output: Annotated[
        Path, typer.Option("--output", "-o", help="Reference trace to write: .h5 or .csv (+ .csv.json).")
    ],
    params: Annotated[Path | None, typer.Option("--params", help=PARAMS_HELP)] = None,
    json_out: Annotated[
        bool, typer.Option("--json", help="Print the conversion report as one JSON object.")
    ] = False,
) -> None:
    """Convert a recording into a reference trace on the model grid (SI, i_q, with its provenance)."""
    import json

    from .actuator import resolve_params
    from .io import TRACE_SUFFIXES, check_output_path
    from .measured import ChannelMap, load_measurement, to_reference, write_reference

    check_output_path(output, suffixes=TRACE_SUFFIXES, inputs=(source, map_file, params))
    cmap = ChannelMap.load(map_file)
    actuator = resolve_params(params)
    with _status(f"converting {source}"):
        ref = to_reference(load_measurement(source, cmap), actuator)
    write_reference(ref, output)
    report = ref.report
    if json_out:
        typer.echo(json.dumps(report, default=str))
    for warning in report.get("warnings", []):
        err.print(f"emaphm: warning: {warning}", soft_wrap=True)
    angle = report.get("angle") or {}
    if angle.get("offset_deg") is not None:
        err.print(f"angle offset {angle['offset_deg']:.2f} deg ({angle.get('offset_method', '')})")
    used = report["segments"]["used"]
    err.print(
        f"wrote {output} ({report['grid']['samples']} samples at {report['grid']['f_s']:g} Hz, "
        f"{used[0]:g}..{used[1]:g} s of the record)"
    )


@app.command("inspect")
def inspect_command(
    source: Annotated[Path, typer.Argument(help="A recording (CSV, HDF5, MATLAB .mat, Parquet).")],
    map_file: Annotated[
        Path | None, typer.Option("--map", help="Channel map (TOML) to check it against.")
    ] = None,
    params: Annotated[Path | None, typer.Option("--params", help=PARAMS_HELP)] = None,
    json_out: Annotated[
        bool, typer.Option("--json", help="Print what was found as one JSON object.")
    ] = False,
) -> None:
    """What a recording holds (channels, rates, duration, ranges, saturation, problems); exit 0 if usable, 2 if not."""
    import json

    from .actuator import resolve_params
    from .measured import ChannelMap, inspect_file

    cmap = ChannelMap.load(map_file) if map_file is not None else None
    info = inspect_file(source, cmap, resolve_params(params))
    if json_out:
        typer.echo(json.dumps(info, default=str))
    else:
        _print_inspection(info)
    if not info["usable"]:
        raise typer.Exit(2)


def _print_inspection(info: dict[str, Any]) -> None:
    from rich.table import Table

    out = _stdout_console()
    out.print(f"{info['file']}: {info['format']}, {info.get('size_bytes', 0) / 1e6:.1f} MB")
    if info.get("channels"):
        table = Table(title="mapped channels (SI)")
        for column in (
            "channel",
            "name",
            "unit",
            "samples",
            "rate [Hz]",
            "duration [s]",
            "min",
            "max",
            "saturation",
        ):
            table.add_column(
                column, justify="left" if column in ("channel", "name", "unit", "saturation") else "right"
            )
        for role, ch in info["channels"].items():
            table.add_row(
                role, str(ch.get("name")), str(ch.get("unit")), str(ch.get("samples")),
                f"{ch['rate_hz']:.6g}" if ch.get("rate_hz") else "-",
                f"{ch['duration_s']:.4g}" if ch.get("duration_s") is not None else "-",
                f"{ch['min_si']:.4g}" if ch.get("min_si") is not None else "-",
                f"{ch['max_si']:.4g}" if ch.get("max_si") is not None else "-",
                str(ch.get("saturation") or ""),
            )  # fmt: skip
        out.print(table)
    else:
        table = Table(title="variables found")
        for column in ("name", "length", "type"):
            table.add_column(column)
        for v in info.get("variables", []):
            table.add_row(str(v.get("name")), str(v.get("length")), str(v.get("dtype")))
        out.print(table)
    for w in info.get("warnings", []):
        out.print(f"warning: {w}")
    for p in info.get("problems", []):
        out.print(f"problem: {p}")
    out.print("usable" if info["usable"] else "not usable")


@app.command()
def demo(
    output_dir: Annotated[Path, typer.Option(help="Folder for the figures.")] = Path("emaphm-demo"),
    seed: Annotated[int, typer.Option(help="Seed of the measurement noise.")] = 0,
    optimizer: Annotated[str, typer.Option(help="ga, de, pso, cmaes or gwo.")] = "ga",
    runs: Annotated[int, typer.Option(help="Identifications (optimiser seeds 1..runs).")] = 5,
    calibration: Annotated[Path | None, typer.Option(help=CALIBRATION_HELP)] = None,
    monitor: Annotated[str | None, typer.Option(help=MONITOR_HELP)] = None,
    params: Annotated[
        Path | None, typer.Option("--params", help=PARAMS_HELP + " Needs its --calibration.")
    ] = None,
) -> None:
    """The main job: the paper's Table 1 experiment (HF twin with noise, five identifications)."""
    from .demo import run_demo

    run_demo(
        output_dir, seed=seed, optimizer=optimizer, runs=runs, calibration=calibration, monitor=monitor,
        console=_stdout_console(), status=_status, params=params,
    )  # fmt: skip


@app.command("params")
def params_command(
    file: Annotated[Path | None, typer.Argument(help="An actuator file to check.")] = None,
    template: Annotated[
        bool,
        typer.Option(
            "--template",
            help="Print a complete actuator file: every parameter with its unit and meaning "
            "(the nominal values, or FILE's).",
        ),
    ] = False,
    json_out: Annotated[
        bool, typer.Option("--json", help="Print the parameters as one JSON object.")
    ] = False,
) -> None:
    """Write an actuator file (--template), or check one and show its parameters and their hash."""
    import json

    from .actuator import resolve_params
    from .calibration import params_hash

    if template and json_out:
        raise InputError("give --template or --json, not both")
    actuator = resolve_params(file)
    if template:
        from .actuator import params_template

        typer.echo(params_template(actuator), nl=False)
        return
    if json_out:
        typer.echo(json.dumps({"params": actuator.to_dict(), "params_hash": params_hash(actuator)}))
        return
    _print_params(actuator, str(file) if file is not None else "the nominal actuator")


def _print_params(actuator: Any, source: str) -> None:
    import dataclasses

    from rich.table import Table

    from .calibration import params_hash
    from .params import EmaParams

    nominal = EmaParams()
    table = Table(title=f"{source} (hash {params_hash(actuator)})")
    for column in ("block", "parameter", "value", "unit", "nominal", "meaning"):
        table.add_column(column, justify="right" if column in ("value", "nominal") else "left")
    for group in dataclasses.fields(actuator):
        mine, theirs = getattr(actuator, group.name), getattr(nominal, group.name)
        for f in dataclasses.fields(mine):
            value, base = getattr(mine, f.name), getattr(theirs, f.name)
            shown = f"{value:g}" if value == base else f"[bold]{value:g}[/bold]"
            table.add_row(group.name, f.name, shown, f.metadata["unit"], f"{base:g}", f.metadata["doc"])
    _stdout_console().print(table)


@app.command()
def thresholds(
    require: Annotated[
        list[str] | None,
        typer.Option(
            help="A requirement KIND=LIMIT (repeatable): tracking=0.5deg (max |θ_u − θ_cmd|), "
            "tracking_rms=0.2deg, current=I_max (or 0.9I_max, 8A: the current demand), free_play=1.5mrad "
            "(total at the surface). A bare number is SI."
        ),
    ] = None,
    params: Annotated[Path | None, typer.Option("--params", help=PARAMS_HELP)] = None,
    command: Annotated[str, typer.Option(help=f"Reference command: {', '.join(COMMAND_NAMES)}.")] = "chirp",
    fault: Annotated[
        list[str] | None, typer.Option(help="Derive only this fault (repeatable); default: all.")
    ] = None,
    resolution: Annotated[
        float, typer.Option(help="Width of the final bisection interval, in fault units.")
    ] = 0.005,
    json_out: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
    output: Annotated[
        Path | None,
        typer.Option(
            "--output",
            "-o",
            help="Write the [thresholds] table (TOML) here, to paste into the actuator file.",
        ),
    ] = None,
) -> None:
    """Failure thresholds per fault from the HF twin and requirements: the smallest distance from healthy that breaks one."""
    import json

    from .actuator import resolve_params
    from .io import atomic_path, check_output_path
    from .prognostics.thresholds import derive_thresholds, parse_requirement, thresholds_toml

    if not require:
        raise InputError(
            "give at least one --require KIND=LIMIT, e.g. --require tracking=1.6deg --require current=I_max"
        )
    if output is not None:
        check_output_path(output, suffixes=(".toml",), inputs=(params,))
    actuator = resolve_params(params)
    requirements = [parse_requirement(text, params=actuator) for text in require]
    with _progress() as update:
        result = derive_thresholds(
            requirements, params=actuator, command=command, faults=fault, resolution=resolution,
            progress=lambda done, total: update("HF simulations", done, total),
        )  # fmt: skip
    for warning in result["warnings"]:
        err.print(f"emaphm: warning: {warning}", soft_wrap=True, markup=False)
    if output is not None:
        with atomic_path(output) as tmp:
            tmp.write_text(thresholds_toml(result), encoding="utf-8")
        err.print(f"wrote {output}: paste its [thresholds] table into the actuator file", markup=False)
    if json_out:
        typer.echo(json.dumps(result))
        return
    _print_thresholds(result, str(params) if params is not None else "the nominal actuator")


def _print_thresholds(data: dict[str, Any], source: str) -> None:
    from rich.table import Table

    reqs = {r["kind"]: r for r in data["requirements"]}

    def show(kind: str, value: float) -> str:
        return f"{value / reqs[kind]['scale']:.4g} {reqs[kind]['unit']}"

    table = Table(title=f"failure thresholds of {source}, {data['command']['type']} command")
    for column in ("fault", "threshold", "limited by", "at threshold", "worst case", "status"):
        table.add_column(column, justify="right" if column in ("threshold", "at threshold") else "left")
    for name, f in data["faults"].items():
        if f["threshold"] is None:
            table.add_row(
                name, "none", "-", "-", "-", f"{f['status']} (rul: placeholder {f['rul_placeholder']:g})"
            )
            continue
        kind = f["limited_by"]
        table.add_row(name, f"{f['threshold']:.4g}", kind, show(kind, f["at_threshold"][kind]),
                      f["case"] or "-", f["status"])  # fmt: skip
    out = _stdout_console()
    out.print(table)
    out.print("requirements: " + ", ".join(f"{r['kind']} < {r['text']}" for r in data["requirements"]))
    out.print("healthy: " + ", ".join(f"{kind} {show(kind, v)}" for kind, v in data["healthy"].items()))
    out.print(
        f"{data['simulations']} HF simulations (noise off), {data['wall_time_s']:.1f} s; actuator {data['params_hash']}"
    )


@app.command()
def rul(
    store: Annotated[
        Path, typer.Argument(help="Folder of a campaign's results store (emaphm campaign run --out).")
    ],
    actuator: Annotated[str, typer.Option(help="The actuator's id in the store.")],
    campaign: Annotated[
        str | None, typer.Option(help="The campaign, when the actuator is in several.")
    ] = None,
    at_flight: Annotated[
        int | None, typer.Option(help="Predict as of this flight (default: the last stored).")
    ] = None,
    threshold: Annotated[
        list[str] | None,
        typer.Option(
            help="A failure threshold FAULT=DISTANCE from healthy, e.g. friction=0.45 (repeatable)."
        ),
    ] = None,
    params: Annotated[
        Path | None,
        typer.Option("--params", help="Actuator file whose [thresholds] table gives the thresholds."),
    ] = None,
    inspection_interval: Annotated[
        float, typer.Option(help="Flights to the next inspection, for the probability of failing before it.")
    ] = 10.0,
    estimator: Annotated[
        str,
        typer.Option(
            help="trend: weighted regression per fault (no dependency); ukf: ProgPy's unscented "
            "Kalman filter (pip install 'emaphm[progpy]')."
        ),
    ] = "trend",
    json_out: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
    plot: Annotated[Path | None, typer.Option(help="Write the prognosis figure here (.png).")] = None,
) -> None:
    """Remaining useful life of an actuator from its history of diagnoses: per fault and for the first failure."""
    import json

    from .io import check_output_path
    from .prognostics.rul import parse_thresholds, rul_report

    if plot is not None:
        check_output_path(plot, suffixes=(".png",), option="--plot")
    if not inspection_interval > 0:
        raise InputError(f"--inspection-interval must be > 0 flights, got {inspection_interval}")
    given: dict[str, float] = {}
    if params is not None:
        from .actuator import load_thresholds

        given.update(load_thresholds(params))
    given.update(parse_thresholds(threshold))
    report = rul_report(store, actuator, campaign=campaign, at_flight=at_flight, thresholds=given,
                        inspection_interval=inspection_interval, estimator=estimator)  # fmt: skip
    data = {k: v for k, v in report.items() if not k.startswith("_")}
    if plot is not None:
        from .plots import plot_rul

        plot_rul(report, plot)
        err.print(f"wrote {plot}")
    if json_out:
        typer.echo(json.dumps(data))
        return
    _print_rul(data)


def _print_rul(data: dict[str, Any]) -> None:
    from rich.table import Table

    def num(v: Any) -> str:
        return "beyond" if v is None else f"{v:.1f}"

    table = Table(
        title=f"actuator {data['actuator']} ({data['campaign']}), as of flight {data['at_flight']:g}"
        + (" (ProgPy UKF)" if data.get("estimator") == "ukf" else "")
    )
    for column in (
        "fault",
        "law",
        "threshold",
        "tracked from",
        "RUL median",
        "RUL 5-95 %",
        "P(fail before next)",
    ):
        table.add_column(column, justify="left" if column in ("fault", "law") else "right")
    for name, f in data["faults"].items():
        threshold = f"{f['threshold']:g}" + (" (placeholder)" if f["placeholder"] else "")
        if f["status"] != "tracked":
            table.add_row(name, f["law"], threshold, f["status"], "-", "-", "-")
            continue
        table.add_row(
            name, f["law"], threshold, str(f["tracked_from"]), num(f["rul_median"]),
            f"{num(f['rul_p05'])}-{num(f['rul_p95'])}", f"{f['prob_fail_before_next_inspection']:.2f}",
        )  # fmt: skip
    out = _stdout_console()
    out.print(table)
    first = data["first_failure"]
    if first["status"] == "tracked":
        out.print(
            f"first failure: median {num(first['rul_median'])} flights (5-95 % {num(first['rul_p05'])}-"
            f"{num(first['rul_p95'])}), most likely {first['most_likely_fault']}; P(before the next inspection in "
            f"{data['inspection_interval']:g} flights) {first['prob_fail_before_next_inspection']:.2f}"
        )
        if first["placeholder_thresholds"]:
            out.print(f"placeholder thresholds (not limits): {', '.join(first['placeholder_thresholds'])}")
    else:
        out.print("no fault is tracked yet: nothing is predicted")


campaign_app = typer.Typer(
    help="Fleet campaigns: many identifications from one file, on Dask, into a results store (docs/campaigns.md).",
    no_args_is_help=True,
)
app.add_typer(campaign_app, name="campaign")


@campaign_app.command("run")
def campaign_run(
    spec: Annotated[Path, typer.Argument(help="Campaign file (TOML).")],
    out: Annotated[Path, typer.Option("--out", help="Folder of the results store (created if missing).")],
    scheduler: Annotated[
        str | None,
        typer.Option(
            help="Dask scheduler address (default: DASK_SCHEDULER_ADDRESS, else a local cluster); 'serial': no Dask."
        ),
    ] = None,
    workers: Annotated[
        int | None,
        typer.Option(help="Local worker processes, one numba thread each (default: one per core)."),
    ] = None,
    json_out: Annotated[bool, typer.Option("--json", help="Print the summary as one JSON object.")] = False,
) -> None:
    """Run the jobs of a campaign that the store does not hold yet (a rerun completes an interrupted one).

    Exit status 0 when every job is done, 1 when some failed (recorded in the store's failures;
    a rerun tries them again).
    """
    import json

    from .campaign import load_campaign, run_campaign

    campaign = load_campaign(spec)
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {out}: exists and is not a folder")
    if not out.absolute().parent.is_dir():
        raise InputError(f"--out {out}: folder {out.absolute().parent} does not exist")
    with _campaign_progress(campaign.name) as update:
        summary = run_campaign(campaign, out, scheduler=scheduler, workers=workers, progress=update)
    data = summary.to_json()
    if json_out:
        typer.echo(json.dumps(data))
    err.print(
        f"campaign {summary.campaign}: {summary.jobs} jobs, {summary.already_done} already done, "
        f"{summary.done} done now, {summary.failed} failed ({summary.backend}, {summary.wall_time_s:.1f} s); "
        f"store {out}"
    )
    if summary.failed:
        err.print(f"emaphm: {summary.failed} job(s) failed: see 'emaphm campaign status {spec} {out}'")
        raise typer.Exit(1)


@campaign_app.command("status")
def campaign_status_command(
    spec: Annotated[Path, typer.Argument(help="Campaign file (TOML).")],
    out: Annotated[Path, typer.Argument(help="Folder of the results store.")],
    json_out: Annotated[bool, typer.Option("--json", help="Print the counts as one JSON object.")] = False,
) -> None:
    """Count the done, failed and missing jobs of a campaign in a results store."""
    import json

    from rich.table import Table

    from .campaign import campaign_status

    data = campaign_status(spec, out)
    if json_out:
        typer.echo(json.dumps(data))
        return
    table = Table(title=f"campaign {data['campaign']} in {data['store']}")
    for column in ("actuator", "jobs", "done", "failed", "missing"):
        table.add_column(column, justify="left" if column == "actuator" else "right")
    for name, c in data["actuators"].items():
        table.add_row(name, *(str(c[k]) for k in ("jobs", "done", "failed", "missing")))
    table.add_row("all", *(str(data[k]) for k in ("jobs", "done", "failed", "missing")), style="bold")
    out_console = _stdout_console()
    out_console.print(table)
    if data["other_rows"]:
        out_console.print(
            f"{data['other_rows']} stored row(s) belong to no job of this file (an older file or version)"
        )


@contextmanager
def _campaign_progress(name: str) -> Iterator[Callable[[int, int, int, float], None]]:
    """A bar with done / failed / remaining and the rate on a terminal; a line every 10 % in logs."""
    if not err.is_terminal:
        marks: set[int] = set()

        def log(done: int, failed: int, total: int, elapsed: float) -> None:
            tenth = (10 * (done + failed)) // max(total, 1)
            if total and tenth not in marks:
                marks.add(tenth)
                rate = 3600.0 * (done + failed) / elapsed if elapsed > 0 else 0.0
                err.print(
                    f"{name}: {done} done, {failed} failed, {total - done - failed} remaining ({rate:.0f} jobs/h)"
                )

        yield log
        return
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

    with Progress(
        TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TextColumn("{task.fields[info]}"),
        TimeRemainingColumn(), console=err, transient=True,
    ) as bar:  # fmt: skip
        task = bar.add_task(f"campaign {name}", total=None, info="")

        def update(done: int, failed: int, total: int, elapsed: float) -> None:
            rate = 3600.0 * (done + failed) / elapsed if elapsed > 0 else 0.0
            info = f"{failed} failed, {total - done - failed} remaining, {rate:.0f} jobs/h"
            bar.update(task, total=total, completed=done + failed, info=info)

        yield update


def _fail(message: str, status: int) -> None:
    """One line on stderr (never wrapped), then exit with `status`."""
    sys.stderr.write("emaphm: error: " + " ".join(message.split()) + "\n")
    sys.exit(status)


def main(argv: list[str] | None = None) -> None:
    """Entry point: runs the app and maps errors to exit status and a one-line reason."""
    try:
        status = app(args=argv, standalone_mode=False)
    except InputError as exc:
        _fail(str(exc), 2)
    except KeyboardInterrupt:
        _fail("interrupted", 130)
    except SimulationError as exc:
        _fail(str(exc), 1)
    except MemoryError:
        _fail("out of memory (a shorter duration or a smaller population needs less)", 1)
    except OSError as exc:  # a file system failure during the work: the reason, not a traceback
        where = f"{exc.filename}: " if getattr(exc, "filename", None) else ""
        _fail(f"{where}{exc.strerror or exc}", 1)
    except typer.Exit as exc:
        sys.exit(exc.exit_code)
    except typer.Abort:
        _fail("aborted", 1)
    except typer.TyperException as exc:  # typer's (vendored click) usage errors
        message = exc.format_message()
        if type(exc).__name__ == "NoArgsIsHelpError":
            sys.stderr.write(message + "\n")  # no arguments at all: show the help
            sys.exit(2)
        _fail(message, getattr(exc, "exit_code", 2) or 2)
    else:
        if status == 130:  # typer turns Ctrl-C into Exit(130) and returns it
            _fail("interrupted", 130)
        if isinstance(status, int) and status:
            sys.exit(status)


if __name__ == "__main__":  # pragma: no cover
    main()
