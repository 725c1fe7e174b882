"""Where the command line writes: stderr for messages and progress, stdout for results.

Messages, warnings and progress go to `err` (stderr), so that stdout carries only the result (a
table, or one JSON object with ``--json``). Bars and spinners show on an interactive terminal only;
CI logs get a line now and then, or nothing.
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager, nullcontext
from typing import TYPE_CHECKING, Any

from ..callbacks import Progress

if TYPE_CHECKING:
    from rich.console import Console

__all__ = ["bracketed", "campaign_progress", "err", "logged", "progress", "status", "stdout_console"]

# what makes rich take a stream for a terminal whatever the stream (`Stderr.is_terminal`)
TERMINAL_SETTINGS = ("FORCE_TERMINAL", "TTY_COMPATIBLE", "FORCE_COLOR", "TTY_INTERACTIVE")


class Stderr:
    """`err`: rich's Console on stderr (messages whole, also in logs), made when first used.

    Importing rich.console was 17 ms of every command's start on machine G (issue 36), and a
    command that prints nothing to stderr (``emaphm identify --json`` of a recording that fits)
    only asks whether stderr is a terminal, for its progress bar. So `is_terminal` is answered
    without rich where stderr is plainly not one (no terminal, none of rich's `TERMINAL_SETTINGS`
    set); anything else goes to the Console, the same as before."""

    def __init__(self) -> None:
        self._console: Console | None = None

    @property
    def console(self) -> Console:
        if self._console is None:
            from rich.console import Console

            self._console = Console(stderr=True, highlight=False, soft_wrap=True)
        return self._console

    @property
    def is_terminal(self) -> bool:
        if self._console is None and not any(os.environ.get(k) is not None for k in TERMINAL_SETTINGS):
            try:
                if not sys.stderr.isatty():
                    return False
            except (AttributeError, ValueError):  # no stream, or a closed one: rich says False too
                return False
        return self.console.is_terminal

    def __getattr__(self, name: str) -> Any:
        return getattr(self.console, name)


err = Stderr()


def status(message: str) -> Any:
    """A spinner on an interactive terminal, nothing otherwise (CI logs stay clean)."""
    return err.status(message) if err.is_terminal else nullcontext()


def stdout_console() -> Console:
    """Console for results on stdout; 120 columns when not a terminal, so logs get whole tables."""
    from rich.console import Console

    return Console(highlight=False, width=None if sys.stdout.isatty() else 120)


# how long a command runs before its progress bar shows (`progress`)
PROGRESS_DELAY_S = 1.0


@contextmanager
def progress(delay: float = PROGRESS_DELAY_S) -> Iterator[Progress]:
    """A progress bar on an interactive terminal (one task per stage), shown once the block has
    run `delay` seconds; a no-op otherwise.

    A diagnosis takes about a second (issue 36), and a bar made at its start cost it 4 % on an
    interactive terminal (rich's console and bar imported, pymoo's CMA-ES imported ahead, the bar's
    refresh thread; 1.05 against 1.01 s on machine G, BENCHMARKS.md): work that ends within
    `delay` now shows no bar, imports nothing for one and asks nothing of the terminal. Longer
    work (a start table's build, a calibration) gets its bar at the first update after `delay`,
    from the stage then running."""
    bar = _LateBar(delay)
    try:
        yield bar.update
    finally:
        bar.stop()


class _LateBar:
    """`progress`'s bar, made at the first update `delay` seconds after the block began."""

    def __init__(self, delay: float) -> None:
        self._due = time.monotonic() + delay
        self._bar: Any = None  # rich's Progress once shown; False on no terminal
        self._tasks: dict[str, Any] = {}

    def update(self, stage: str, done: int, total: int) -> None:
        if self._bar is None:
            if time.monotonic() < self._due:
                return
            self._bar = self._shown()
        if self._bar is False:
            return
        if stage not in self._tasks:
            self._tasks[stage] = self._bar.add_task(stage, total=total, completed=done)
        self._bar.update(self._tasks[stage], completed=done)

    def _shown(self) -> Any:
        if not err.is_terminal:
            return False
        from rich.progress import Progress

        from ..identification.cmaes import import_cmaes

        import_cmaes()  # trims cma's imports only while one thread runs: before the bar's own thread
        bar = Progress(console=err.console, transient=True)
        bar.start()
        return bar

    def stop(self) -> None:
        if self._bar:
            self._bar.stop()


def bracketed(update: Progress) -> Progress:
    """`update` (a `progress` bar's) that also prints a line when a stage starts and one when it
    ends, when stderr is a log, not a terminal: work that is not a generation and may take seconds
    (a start table's build), which a log would otherwise pass over in silence."""
    started: set[str] = set()

    def report(stage: str, done: int, total: int) -> None:
        update(stage, done, total)
        if err.is_terminal:
            return
        if stage not in started:
            started.add(stage)
            err.print(f"emaphm: {stage}: {total} steps")
        if done >= total:
            err.print(f"emaphm: {stage}: done")

    return report


def logged(update: Progress) -> Progress:
    """`update` (a `progress` bar's) that also prints a line every 10 steps when stderr is a log,
    not a terminal (the long calibrations)."""

    def report(stage: str, done: int, total: int) -> None:
        update(stage, done, total)
        if not err.is_terminal and (done % 10 == 0 or done == total):
            err.print(f"{done}/{total} {stage}")

    return report


@contextmanager
def campaign_progress(name: str) -> Iterator[Callable[[int, int, int, float], None]]:
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
        TimeRemainingColumn(), console=err.console, transient=True,
    ) as bar:  # fmt: skip
        task = bar.add_task(f"campaign {name}", total=None, info="")

        def update(done: int, failed: int, total: int, elapsed: float) -> None:
            rate = 3600.0 * (done + failed) / elapsed if elapsed > 0 else 0.0
            info = f"{failed} failed, {total - done - failed} remaining, {rate:.0f} jobs/h"
            bar.update(task, total=total, completed=done + failed, info=info)

        yield update
