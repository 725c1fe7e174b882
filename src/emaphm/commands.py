"""Position command profiles θ_cmd(t) on the user (surface) side [rad].

`Chirp` is the FDI test manoeuvre of DESIGN §6/§7 and the default; `ChirpHold` (the chirp, then
a hold) and `Steps` (a staircase) are other manoeuvres a rig records, on which the monitor is
also calibrated; `Step`, `Ramp` and `Sine` are for exploring the model. Every command is a frozen dataclass with a `duration` [s] and is called
on an array of times [s] to give θ_cmd [rad].
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .choices import COMMAND_NAMES
from .errors import InputError

__all__ = [
    "COMMANDS",
    "Chirp",
    "ChirpHold",
    "Command",
    "Ramp",
    "SampledCommand",
    "Sine",
    "Step",
    "Steps",
    "command_record",
    "make_command",
]


class Command(Protocol):
    """A position command: ``command(t)`` gives θ_cmd [rad] at times t [s]."""

    @property
    def duration(self) -> float:
        """Length of the manoeuvre [s]."""

    def __call__(self, t: ArrayLike) -> NDArray[np.float64]: ...


class _Checked:
    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):  # type: ignore[arg-type]
            v = getattr(self, f.name)
            if f.name == "levels":  # a sequence field: its class checks it
                continue
            if not (isinstance(v, (int, float)) and math.isfinite(v)):
                raise InputError(f"{type(self).__name__}.{f.name} must be a finite number, got {v!r}")
            if f.name in ("duration", "T", "V_max", "f0", "f1", "frequency", "dwell", "ramp") and v <= 0:
                raise InputError(f"{type(self).__name__}.{f.name} must be > 0, got {v!r}")
            if f.name in ("t_f", "t_0", "A_max", "hold") and v < 0:
                raise InputError(f"{type(self).__name__}.{f.name} must be >= 0, got {v!r}")


@dataclass(frozen=True)
class Chirp(_Checked):
    """Velocity-limited chirp with a raised-cosine fade-in (DESIGN §7).

    θ_cmd = w(t)·A(t)·sin φ(t), φ(t) = 2π(f0·t + (f1 − f0)·t²/(2T)), f(t) = f0 + (f1 − f0)·t/T,
    A(t) = min(A_max, V_max/(2π·f(t))), w(t) = ½(1 − cos(π·t/t_f)) for t < t_f, then 1.

    A_max : float  largest amplitude [rad]
    V_max : float  velocity limit that caps the amplitude at high frequency [rad/s]
    f0, f1 : float  start and end frequency [Hz]
    T : float  sweep time, also the duration [s]
    t_f : float  fade-in time [s]
    """

    A_max: float = 0.05
    V_max: float = 0.4
    f0: float = 0.5
    f1: float = 10.0
    T: float = 1.0
    t_f: float = 0.02

    @property
    def duration(self) -> float:
        return self.T

    def __call__(self, t: ArrayLike) -> NDArray[np.float64]:
        t = np.asarray(t, dtype=np.float64)
        phase = 2.0 * np.pi * (self.f0 * t + (self.f1 - self.f0) * t**2 / (2.0 * self.T))
        f = self.f0 + (self.f1 - self.f0) * t / self.T
        A = np.minimum(self.A_max, self.V_max / (2.0 * np.pi * f))
        if self.t_f > 0.0:  # raised-cosine fade-in over t_f
            w = np.where(t < self.t_f, 0.5 * (1.0 - np.cos(np.pi * np.minimum(t, self.t_f) / self.t_f)), 1.0)
        else:
            w = np.ones_like(t)
        return w * A * np.sin(phase)


@dataclass(frozen=True)
class ChirpHold(Chirp):
    """The chirp (`Chirp`, over T), then a ramp back to zero over `ramp` [s], then a hold to T + hold.

    A rig that runs the FDI chirp and then parks the surface records this (issue 8, item 5).

    A_max, V_max, f0, f1, T, t_f : float  the chirp's (`Chirp`) [rad], [rad/s], [Hz], [Hz], [s], [s]
    hold : float  time after the sweep, the ramp back included [s]
    ramp : float  time of the ramp back to zero [s]
    """

    hold: float = 1.0
    ramp: float = 0.05

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.hold < self.ramp:
            raise InputError(f"ChirpHold.hold ({self.hold!r} s) must be at least its ramp ({self.ramp!r} s)")

    @property
    def duration(self) -> float:
        return self.T + self.hold

    def __call__(self, t: ArrayLike) -> NDArray[np.float64]:
        t = np.asarray(t, dtype=np.float64)
        end = float(Chirp.__call__(self, np.array([self.T]))[0])
        back = end * np.clip(1.0 - (t - self.T) / self.ramp, 0.0, 1.0)
        return np.where(t <= self.T, Chirp.__call__(self, np.minimum(t, self.T)), back)


@dataclass(frozen=True)
class Steps(_Checked):
    """A staircase: θ_cmd holds `levels[j]` [rad] over [j·dwell, (j + 1)·dwell), the last level to the end.

    levels : tuple of float  the positions held [rad]
    dwell : float  time each level is held [s]
    """

    levels: tuple[float, ...] = (0.0, 0.03, -0.02, 0.045, 0.0, -0.04, 0.02, -0.01, 0.035, -0.03)
    dwell: float = 0.2

    def __post_init__(self) -> None:
        super().__post_init__()
        try:
            levels = tuple(self.levels)
        except TypeError:
            levels = ()
        if not levels or not all(
            isinstance(v, numbers.Real) and not isinstance(v, bool) and math.isfinite(v) for v in levels
        ):
            raise InputError(f"Steps.levels must be a non-empty list of finite numbers, got {self.levels!r}")
        object.__setattr__(self, "levels", tuple(float(v) for v in levels))

    @property
    def duration(self) -> float:
        return self.dwell * len(self.levels)

    def __call__(self, t: ArrayLike) -> NDArray[np.float64]:
        t = np.asarray(t, dtype=np.float64)
        j = np.clip(np.floor(t / self.dwell + 1e-9), 0, len(self.levels) - 1).astype(np.intp)
        return np.asarray(self.levels, dtype=np.float64)[j]


@dataclass(frozen=True)
class Step(_Checked):
    """Step of `amplitude` [rad] at time `t_0` [s].

    duration : float  length of the command [s]
    """

    amplitude: float = 0.02
    t_0: float = 0.01
    duration: float = 0.5

    def __call__(self, t: ArrayLike) -> NDArray[np.float64]:
        t = np.asarray(t, dtype=np.float64)
        return np.where(t >= self.t_0, self.amplitude, 0.0)


@dataclass(frozen=True)
class Ramp(_Checked):
    """Ramp of `rate` [rad/s] starting at `t_0` [s].

    duration : float  length of the command [s]
    """

    rate: float = 0.1
    t_0: float = 0.01
    duration: float = 0.5

    def __call__(self, t: ArrayLike) -> NDArray[np.float64]:
        t = np.asarray(t, dtype=np.float64)
        return self.rate * np.maximum(t - self.t_0, 0.0)


@dataclass(frozen=True)
class Sine(_Checked):
    """Sine of `amplitude` [rad] and `frequency` [Hz], starting at zero position (with velocity 2π·f·A).

    duration : float  length of the command [s]
    """

    amplitude: float = 0.02
    frequency: float = 2.0
    duration: float = 1.0

    def __call__(self, t: ArrayLike) -> NDArray[np.float64]:
        t = np.asarray(t, dtype=np.float64)
        return self.amplitude * np.sin(2.0 * np.pi * self.frequency * t)


class SampledCommand:
    """θ_cmd recorded in a trace: linear interpolation of samples (t [s], theta [rad]).

    Used to replay the command of a measured or written trace through the monitor model.
    """

    def __init__(self, t: ArrayLike, theta: ArrayLike) -> None:
        self.t = np.array(t, dtype=np.float64)
        self.theta = np.array(theta, dtype=np.float64)
        if self.t.ndim != 1 or self.t.shape != self.theta.shape or len(self.t) < 2:
            raise InputError("a sampled command needs t and theta of equal length >= 2")
        if not (np.all(np.isfinite(self.t)) and np.all(np.isfinite(self.theta))):
            raise InputError("the sampled command contains NaN or inf")
        if self.t[0] != 0.0 or np.any(np.diff(self.t) <= 0):
            raise InputError("the sampled command's time must start at 0 s and increase")
        self.t.setflags(write=False)
        self.theta.setflags(write=False)

    @property
    def duration(self) -> float:
        return float(self.t[-1])

    def __call__(self, t: ArrayLike) -> NDArray[np.float64]:
        return np.interp(np.asarray(t, dtype=np.float64), self.t, self.theta)


def command_record(command: Command) -> dict[str, Any]:
    """A JSON-ready description of a command, for result metadata."""
    if isinstance(command, SampledCommand):
        return {"type": "sampled", "samples": len(command.t), "duration": command.duration}
    name = next((n for n, cls in COMMANDS.items() if type(command) is cls), type(command).__name__.lower())
    return {"type": name, **{k: list(v) if isinstance(v, tuple) else v for k, v in vars(command).items()}}


COMMANDS: dict[str, type] = dict(
    zip(COMMAND_NAMES, (Chirp, ChirpHold, Steps, Step, Ramp, Sine), strict=True)
)  # the names: `choices.COMMAND_NAMES`


def make_command(name: str, **settings: Any) -> Command:
    """Build a command by name (``chirp``, ``chirp-hold``, ``steps``, ``step``, ``ramp``, ``sine``)
    with optional settings.

    Parameters
    ----------
    name : str
        The command's name (above).
    **settings
        The command class's fields (SI: [rad], [s], [Hz]), e.g. ``make_command("sine", frequency=5.0)``.
    """
    try:
        cls = COMMANDS[name]
    except KeyError:
        raise InputError(f"unknown command {name!r}; choose one of {', '.join(COMMANDS)}") from None
    try:
        return cls(**settings)  # type: ignore[no-any-return]
    except TypeError as exc:
        raise InputError(f"bad settings for command {name!r}: {exc}") from None
