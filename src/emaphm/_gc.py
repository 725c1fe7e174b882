"""The cyclic garbage collector while a command's process starts (issue 36).

Importing numba, numpy, scipy's pieces and emaphm makes some 60 000 objects that live as long as
the process, and the collector traverses them again and again while they are made: about 160
young, 15 middle and one full collection in one ``emaphm identify``, 40-50 ms of its 1.1 s on
machine G (``gc.callbacks``, BENCHMARKS.md issue 36, fifteenth session), and again at every full
collection after. So the command line (`cli.main`, the process's entry) raises the youngest
generation's threshold while the process starts (`quiet_start`), and a command calls `settled`
once its imports are done: what exists then is frozen out of later collections (`gc.freeze`) and
the thresholds are back. The collector is never off: a command that never calls `settled` runs
with the raised threshold, which collects as surely, less often. A library caller (a test, a
study, `emaphm.identify` from Python) keeps the interpreter's own settings: only the process's
entry calls `quiet_start`.
"""

from __future__ import annotations

import gc

__all__ = ["STARTUP_THRESHOLD", "quiet_start", "settled"]

# the youngest generation's threshold while a process starts (the interpreter's: 700)
STARTUP_THRESHOLD = 100_000

_saved: tuple[int, ...] | None = None


def quiet_start() -> None:
    """Raise the youngest generation's threshold to `STARTUP_THRESHOLD` until `settled`."""
    global _saved
    if _saved is None:
        _saved = gc.get_threshold()
        gc.set_threshold(max(STARTUP_THRESHOLD, _saved[0]), *_saved[1:])


def settled() -> None:
    """After a command's imports: freeze what exists (`gc.freeze`) and put the thresholds back.
    Nothing when `quiet_start` was not called."""
    global _saved
    if _saved is not None:
        gc.freeze()
        gc.set_threshold(*_saved)
        _saved = None
