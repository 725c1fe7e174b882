"""Exceptions raised by emaphm.

`InputError` marks a problem with what the user asked for (a bad fault vector, an unknown
command, an unsupported file type). The command line turns it into exit status 2 with a one-line
reason. `SimulationError` marks a simulation that produced NaN or inf (exit status 1 with a
one-line reason); anything else is a failure (exit status 1).
"""

from __future__ import annotations

__all__ = ["Doubt", "InputError", "SimulationError"]


class Doubt(str):
    """A warning that makes a diagnosis doubtful: a precondition of it not met (the recording
    starts in motion, the given angle offset disagrees with the currents, ...). It is a warning
    like any other; `identify` reports a result with one as verdict "doubtful"."""


class InputError(ValueError):
    """Invalid user input: the message is one line that says what is wrong and how to fix it."""


class SimulationError(RuntimeError):
    """A kernel produced NaN or inf: the message names the model and the fault vector."""
