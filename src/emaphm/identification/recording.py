"""What an identification fits: the HF twin's current under given faults, a trace, or a rig's
recording read through a channel map (`measurement`), checked before any search."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..commands import Chirp, Command, SampledCommand
from ..errors import InputError
from ..faults import as_fault_vector
from ..io import read_trace
from ..measured.checks import plausibility
from ..models import HighFidelityEma, MonitorEma
from ..params import EmaParams
from ..results import SimResult
from . import limits, warm

__all__ = ["Measurement", "measurement", "split_seed"]


def split_seed(seed: int) -> tuple[int, int]:
    """The twin's noise seed and the optimiser's seed drawn from the user's seed."""
    noise, optimizer = (int(s.generate_state(1)[0]) for s in np.random.SeedSequence(seed).spawn(2))
    return noise, optimizer


@dataclass(frozen=True)
class Measurement:
    """The trace to fit (t, theta_cmd, i_q and maybe theta_u), its command, the truth when the twin
    made it, where it came from and, for a rig's recording, the conversion's report."""

    trace: SimResult
    command: Command
    truth: NDArray[np.float64] | None
    source: str
    conversion: dict[str, Any] | None = None

    @property
    def theta_u(self) -> NDArray[np.float64] | None:
        return self.trace["theta_u"] if "theta_u" in self.trace.names else None


def measurement(
    true_faults: ArrayLike | None,
    reference: Any,
    channel_map: Any,
    actuator: EmaParams,
    noise_seed: int,
    monitor: MonitorEma | None = None,
) -> Measurement:
    """The twin run with `true_faults` (noise on, `noise_seed`), or `reference` (a trace file or
    `SimResult`, or with `channel_map` a rig's recording) checked: exactly one of the two. Given
    the `monitor` the search will run, the twin's run goes on a thread while this one loads the
    search's kernels (`warm`)."""
    if (true_faults is None) == (reference is None):
        raise InputError("give exactly one of true faults or a reference trace")
    if channel_map is not None and reference is None:
        raise InputError(
            "a channel map reads a recording: give it with a reference file, not with true faults"
        )
    if true_faults is not None:
        truth = as_fault_vector(true_faults, name="true faults")
        twin = HighFidelityEma(actuator, Chirp())
        if monitor is None:
            trace = twin.simulate(truth, noise=True, seed=noise_seed)
        else:
            twin.simulate(truth, noise=True, seed=noise_seed, duration=warm.TWIN_SPAN_S)  # its kernels loaded
            trace = warm.meanwhile(lambda: twin.simulate(truth, noise=True, seed=noise_seed),
                                   lambda: warm.load_search_kernels(monitor))  # fmt: skip
        return Measurement(trace, Chirp(), truth, "HF twin, noise on")
    conversion = None
    if channel_map is not None:
        if isinstance(reference, SimResult):
            raise InputError("a channel map reads a recording file, not a SimResult")
        from ..measured import ChannelMap, load_measurement, to_reference

        cmap = channel_map if isinstance(channel_map, ChannelMap) else ChannelMap.load(channel_map)
        converted = to_reference(load_measurement(Path(reference), cmap), actuator)
        trace, conversion = converted.trace, converted.report
    else:
        trace = reference if isinstance(reference, SimResult) else read_trace(Path(reference))
    _check(trace, actuator)
    source = str(reference) if not isinstance(reference, SimResult) else "SimResult"
    return Measurement(trace, SampledCommand(trace.t - trace.t[0], trace.theta_cmd), None, source, conversion)


def _check(trace: SimResult, actuator: EmaParams) -> None:
    for name in ("t", "theta_cmd", "i_q"):
        if name not in trace.names:
            raise InputError(f"the reference trace has no {name!r} signal")
    if len(trace.t) < limits.MIN_SAMPLES:
        raise InputError(
            f"the reference has {len(trace.t)} samples; at least {limits.MIN_SAMPLES} are needed"
        )
    span = float(trace.t[-1] - trace.t[0])
    if span < limits.MIN_SPAN:
        raise InputError(
            f"the reference spans {span:g} s; a diagnosis needs at least {limits.MIN_SPAN:g} s of the FDI command"
        )
    problems = plausibility(trace, actuator)
    if problems:  # a unit or channel mistake: refused before the search rather than fitted
        more = f" (and {len(problems) - 1} more problem(s))" if len(problems) > 1 else ""
        raise InputError(f"the reference is not plausible for this actuator: {problems[0]}{more}")
