"""The ``emaphm`` command line: argument parsing and printing only (DESIGN §8).

Exit status: 0 success, 2 bad input or usage (one-line reason on stderr), 1 failure.
"""

from __future__ import annotations

import sys
from contextlib import nullcontext
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.console import Console

from . import __version__
from .commands import COMMANDS, make_command
from .errors import InputError
from .faults import HEALTHY, describe, parse_faults

app = typer.Typer(
    name="emaphm",
    help="Model-based prognostics of PMSM-driven electromechanical actuators.",
    add_completion=False,
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
)
err = Console(stderr=True, highlight=False)

HEALTHY_TEXT = ",".join(f"{v:g}" for v in HEALTHY)


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
    model: Annotated[str, typer.Option(help="Model fidelity: hf.")] = "hf",
    noise: Annotated[bool, typer.Option("--noise/--no-noise", help="Seeded measurement noise.")] = True,
    seed: Annotated[int, typer.Option(help="Seed of every random choice.")] = 0,
    command: Annotated[str, typer.Option(help=f"Position command: {', '.join(COMMANDS)}.")] = "chirp",
    duration: Annotated[
        float | None, typer.Option(help="Simulated time [s]; default: the command's.")
    ] = None,
) -> None:
    """Simulate the actuator with a fault vector and write the sampled signals."""
    from .io import check_trace_path, write_trace
    from .models import simulate as run

    k = parse_faults(faults)
    check_trace_path(output)  # fail before the work, not after it
    cmd = make_command(command)
    with _status(f"simulating {model.upper()} twin ({describe(k)})"):
        result = run(k, model=model, noise=noise, seed=seed, command=cmd, duration=duration)
    write_trace(result, output)
    err.print(f"wrote {output} ({len(result.t)} samples, model {model}, seed {seed})")


@app.command()
def demo(
    output_dir: Annotated[Path, typer.Option(help="Folder for the figures.")] = Path("emaphm-demo"),
    seed: Annotated[int, typer.Option(help="Seed of the measurement noise.")] = 0,
) -> None:
    """The main job on its built-in default: the paper's Table 1 actuator on the high-fidelity twin."""
    from .demo import run_demo

    run_demo(output_dir, seed=seed, console=Console(highlight=False), status=_status)


def _fail(message: str, status: int) -> None:
    """One line on stderr (never wrapped), then exit with `status`."""
    sys.stderr.write("emaphm: error: " + " ".join(message.split()) + "\n")
    sys.exit(status)


def main(argv: list[str] | None = None) -> None:
    """Entry point: runs the app and maps errors to exit status and a one-line reason."""
    try:
        app(args=argv, standalone_mode=False)
    except InputError as exc:
        _fail(str(exc), 2)
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


if __name__ == "__main__":  # pragma: no cover
    main()
