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

import functools
import importlib
import sys
from collections.abc import Sequence
from typing import Annotated, Any

import typer

from .._version import __version__
from ..errors import InputError, SimulationError

__all__ = ["app", "main"]

def _new_app() -> typer.Typer:
    return typer.Typer(
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


def _root(
    version: Annotated[
        bool, typer.Option("--version", callback=_version, is_eager=True, help="Print the version and exit.")
    ] = False,
) -> None:
    """Model-based prognostics of PMSM-driven electromechanical actuators."""


# the commands in the order ``emaphm --help`` lists them: (name, module of this package, its function
# or sub-app), imported when an app with them is built
COMMANDS: tuple[tuple[str, str, str], ...] = (
    ("simulate", "simulate", "simulate"),
    ("identify", "identify", "identify"),
    ("calibrate", "calibrate", "calibrate"),
    ("calibrate-uq", "calibrate", "calibrate_uq"),
    ("calibrate-detection", "calibrate", "calibrate_detection"),
    ("baseline", "baseline", "baseline"),
    ("convert", "data", "convert"),
    ("inspect", "data", "inspect_command"),
    ("demo", "simulate", "demo"),
    ("params", "actuator", "params_command"),
    ("thresholds", "actuator", "thresholds"),
    ("rul", "prognostics", "rul"),
    ("fleet", "fleet", "fleet"),
    ("campaign", "campaign", "campaign_app"),
)
NAMES = frozenset(name for name, _, _ in COMMANDS)


def build_app(names: Sequence[str] | None = None) -> typer.Typer:
    """The command line with the `COMMANDS` named (None: all of them), their modules imported."""
    built = _new_app()
    built.callback()(_root)
    for name, module, attribute in COMMANDS:
        if names is None or name in names:
            command = getattr(importlib.import_module(f"{__name__}.{module}"), attribute)
            if isinstance(command, typer.Typer):
                built.add_typer(command, name=name)
            else:
                built.command(name)(command)
    return built


@functools.cache
def _full_app() -> typer.Typer:
    """The whole command line, built the first time it is asked for."""
    return build_app()


def __getattr__(name: str) -> Any:
    """`app`: `_full_app` (PEP 562: the commands' modules are imported only when it is asked for)."""
    if name == "app":
        return _full_app()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _app_for(argv: list[str] | None) -> typer.Typer:
    """The app `main` runs: for ``emaphm COMMAND ...`` one with that command alone, the same
    command line to the user (its options, help, errors), without importing the other commands'
    modules and typer building their parameters (30-45 ms of each call on machine E, issue 36);
    else `app`, all of them."""
    args = sys.argv[1:] if argv is None else argv
    if args and args[0] in NAMES:
        return build_app([args[0]])
    return _full_app()


def _fail(message: str, status: int) -> None:
    """One line on stderr (never wrapped), then exit with `status`."""
    sys.stderr.write("emaphm: error: " + " ".join(message.split()) + "\n")
    sys.exit(status)


def main(argv: list[str] | None = None) -> None:
    """Entry point: runs the app and maps errors to exit status and a one-line reason.

    Without `argv` this is the process's own entry point (the ``emaphm`` script, ``python -m
    emaphm``): it byte-compiles emaphm once where Python writes no bytecode (`emaphm._bytecode`),
    raises the collector's threshold while the process imports (`emaphm._gc`; a command settles
    it once its imports are done) and ends the process itself
    (`_process_exit`) instead of returning. With `argv` (a test, a study) it returns, or raises
    SystemExit, as any function, the collector as the caller has it."""
    if argv is not None:
        _main(argv)
        return
    from .._bytecode import compile_package
    from .._gc import quiet_start

    compile_package()  # once, where Python writes no bytecode (`emaphm._bytecode`)
    quiet_start()  # the collector while the process imports (`emaphm._gc`)
    try:
        _main(None)
    except SystemExit as exc:
        _process_exit(exc.code)
    _process_exit(0)


def _process_exit(code: object) -> None:
    """End the process with `code` as `sys.exit(code)` would, without the interpreter's
    finalisation where nothing needs it (issue 36).

    Tearing down the interpreter took 0.13-0.14 s of every ``emaphm identify`` on machine G once
    the kernels were loaded (0.05 s after the imports alone; timed from the end of `main` to the
    process's end), which serves nothing at the end of a process. So the atexit functions run
    (logging, h5py, dask and any a library registered), the streams are flushed, then `os._exit`.
    The ordinary exit stays where something may still need it: another thread that is not a
    daemon or a child process still alive, or a profiler or tracer attached (whose output is
    written at the interpreter's exit)."""
    if code is None:
        status = 0
    elif isinstance(code, int):
        status = code
    else:  # sys.exit("message"): the message on stderr, status 1
        sys.stderr.write(f"{code}\n")
        status = 1
    if not _bare_exit_safe():
        sys.exit(status)
    import atexit
    import os

    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # a closed pipe or stream: nothing more can be written to it
            pass
    os._exit(status)


def _bare_exit_safe() -> bool:
    """Whether nothing of the interpreter's own exit is needed (`_process_exit`)."""
    import threading

    if sys.getprofile() is not None or sys.gettrace() is not None:
        return False
    if any(t is not threading.main_thread() and not t.daemon and t.is_alive() for t in threading.enumerate()):
        return False
    mp = sys.modules.get("multiprocessing")
    return not (mp is not None and mp.active_children())


def _main(argv: list[str] | None) -> None:
    """`main`'s work: the app run, its errors mapped to an exit status and a one-line reason."""
    try:
        status = _app_for(argv)(args=argv, standalone_mode=False)
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
