"""Each actuator's own baseline (issue 33): its constants and monitor from recordings of it when healthy.

`baseline` fits them (`fit`: the constants that move the healthy current, with priors from the
nameplate's tolerances; `make`: the recordings read and checked to be of one healthy actuator)
and writes the folder `identify --baseline DIR` reads (`files`). docs/your-actuator.md §1.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from .files import FILES, baseline_files, baseline_inputs, check_output_dir, write_baseline
from .fit import CONSTANTS, PRIOR_TOLERANCE, BaselineFit
from .make import Baseline, make_baseline

__all__ = [
    "CONSTANTS", "FILES", "PRIOR_TOLERANCE", "Baseline", "BaselineFit", "baseline", "baseline_files", "baseline_inputs",
    "check_output_dir", "make_baseline", "write_baseline",
]  # fmt: skip


def baseline(
    recordings: Sequence[str | os.PathLike[str]],
    output: str | os.PathLike[str],
    *,
    channel_map: Any = None,
    params: Any = None,
    calibration: Any = None,
    uq_calibration: Any = None,
    detection: Any = None,
    progress: Any = None,
) -> Path:
    """Fit the baseline of one actuator from its healthy `recordings` and write its folder `output`
    (`files`): ``emaphm baseline REC... --map MAP [--params NAMEPLATE] --output DIR``. `params`,
    `calibration`, `uq_calibration`, `detection`: the nameplate's files (default: the nominal
    actuator and the packaged files)."""
    check_output_dir(output)
    made = make_baseline(
        recordings, channel_map=channel_map, params=params, calibration=calibration, progress=progress
    )
    return write_baseline(made, output, uq_calibration=uq_calibration, detection=detection)
