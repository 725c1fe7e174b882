"""Exceptions raised by emaphm.

`InputError` marks a problem with what the user asked for (a bad fault vector, an unknown
command, an unsupported file type). The command line turns it into exit status 2 with a one-line
reason; anything else is a failure (exit status 1).
"""

from __future__ import annotations

__all__ = ["InputError"]


class InputError(ValueError):
    """Invalid user input: the message is one line that says what is wrong and how to fix it."""
