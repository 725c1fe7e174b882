"""The one signature of a progress callback for long work that is not a search's generation (a
start table's build, a calibration's stages, a baseline's fit): ``(what, done, total)``, each call
saying that `done` of `total` steps of the work named `what` are done. The CLI's bar
(`cli.output.progress`) is one."""

from __future__ import annotations

from collections.abc import Callable

__all__ = ["Progress"]

Progress = Callable[[str, int, int], None]  # (what, done, total)
