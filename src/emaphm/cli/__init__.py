"""The ``emaphm`` command line: argument parsing and printing only (DESIGN §8).

Exit status: 0 success, 2 bad input or usage (one-line reason on stderr), 1 failure (one line
too: a diverged simulation, a file system error), 3 `identify` ran but the monitor cannot explain
the recording (verdict "does not fit", no faults reported), 4 `identify` ran and its diagnosis is
doubtful (verdict "doubtful": faults reported, the reasons warned of), 130 interrupted (Ctrl-C). Every check of the
input, output paths included, runs before the work, and no output is ever left half-written.

Only light modules are imported at start (`emaphm --version` and `--help` answer at once); each
command imports what it needs.

One module per group of commands, registered below in the order ``emaphm --help`` lists them:

- `simulate`: ``simulate``, ``demo``
- `identify`: ``identify``
- `calibrate`: ``calibrate``, ``calibrate-uq``, ``calibrate-detection``
- `baseline`: ``baseline``
- `data`: ``convert``, ``inspect``
- `actuator`: ``params``, ``thresholds``
- `prognostics`: ``rul``
- `campaign`: ``campaign run``, ``campaign status``

and beside them `options` (the options several commands share), `output` (stderr, stdout,
progress bars) and `render` (the printed form of each result).
"""

from __future__ import annotations

import sys
from typing import Annotated

import typer

from .._version import __version__
from ..errors import InputError, SimulationError
from . import actuator, baseline, calibrate, campaign, data, fleet, identify, prognostics, simulate

__all__ = ["app", "main"]

app = typer.Typer(
    name="emaphm",
    help="Model-based prognostics of PMSM-driven electromechanical actuators.",
    add_completion=False,
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
)


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


app.command()(simulate.simulate)
app.command()(identify.identify)
app.command()(calibrate.calibrate)
app.command("calibrate-uq")(calibrate.calibrate_uq)
app.command("calibrate-detection")(calibrate.calibrate_detection)
app.command()(baseline.baseline)
app.command()(data.convert)
app.command("inspect")(data.inspect_command)
app.command()(simulate.demo)
app.command("params")(actuator.params_command)
app.command()(actuator.thresholds)
app.command()(prognostics.rul)
app.command()(fleet.fleet)
app.add_typer(campaign.campaign_app, name="campaign")


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
