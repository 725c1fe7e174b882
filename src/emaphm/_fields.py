"""The field-metadata mechanism of the parameter dataclasses (`emaphm.params`, `emaphm.drive`).

A field carries its symbol, unit, meaning and check in its metadata: a number field is made with
`_p` (its check one of `_CHECKS`), a string choice with `_choice` (check "choice", with its
"choices"), a boolean with `_flag` (check "flag"). `_Validated` checks every field on construction
and raises a one-line `InputError` naming the class and the field.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import field
from typing import Any

from .errors import InputError

__all__ = ["choice_problem", "format_value"]

# the checks of a number field (metadata "check"); "choice" and "flag" fields are checked apart
_CHECKS = {
    "positive": (lambda v: v > 0, "must be > 0"),
    "nonnegative": (lambda v: v >= 0, "must be >= 0"),
    "fraction": (lambda v: 0 < v <= 1, "must be in (0, 1]"),
    "cycle": (lambda v: 0 <= v < 1, "must be in [0, 1)"),
}


def _p(default: float, symbol: str, unit: str, doc: str, check: str = "positive") -> Any:
    """A number field with its symbol, unit, meaning and validity check in the metadata."""
    return field(default=default, metadata={"symbol": symbol, "unit": unit, "doc": doc, "check": check})


def _choice(default: str, symbol: str, doc: str, choices: tuple[str, ...]) -> Any:
    """A string field that must be one of `choices` (metadata check "choice"; unit "-")."""
    return field(
        default=default,
        metadata={"symbol": symbol, "unit": "-", "doc": doc, "check": "choice", "choices": choices},
    )


def _flag(default: bool, symbol: str, doc: str) -> Any:
    """A boolean field (metadata check "flag"; unit "-")."""
    return field(default=default, metadata={"symbol": symbol, "unit": "-", "doc": doc, "check": "flag"})


def choice_problem(metadata: Any, value: Any, quote: Any = repr) -> str | None:
    """What is wrong with `value` for a choice or flag field (its `metadata`), None if nothing or
    if the field is a number: "must be one of …, got …" (each choice through `quote`) or "must be
    true or false, got …". The dataclasses and the actuator file's reader word it alike."""
    check = metadata["check"]
    if check == "choice" and (not isinstance(value, str) or value not in metadata["choices"]):
        return f"must be one of {', '.join(quote(c) for c in metadata['choices'])}, got {value!r}"
    if check == "flag" and not isinstance(value, bool):
        return f"must be true or false, got {value!r}"
    return None


def format_value(value: Any) -> str:
    """A parameter value as text: numbers with ``:g``, booleans as ``true``/``false``, strings as they are."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return value
    return f"{value:g}"


class _Validated:
    """Checks every field against its metadata on construction (a number: finite, and its `check`;
    a choice: one of its choices; a flag: a bool)."""

    def __post_init__(self) -> None:
        name = type(self).__name__
        for f in dataclasses.fields(self):  # type: ignore[arg-type]
            value = getattr(self, f.name)
            if isinstance(value, _Validated):
                continue
            if f.metadata["check"] in ("choice", "flag"):
                problem = choice_problem(f.metadata, value)
                if problem:
                    raise InputError(f"{name}.{f.name} {problem}")
                continue
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise InputError(f"{name}.{f.name} must be a number, got {value!r}")
            if not math.isfinite(value):
                raise InputError(f"{name}.{f.name} must be finite, got {value!r}")
            ok, what = _CHECKS[f.metadata["check"]]
            if not ok(value):
                raise InputError(f"{name}.{f.name} {what}, got {value!r}")
        self._check()

    def _check(self) -> None:
        """Cross-field checks of a group (overridden where needed)."""

    def fields_in_use(self) -> tuple[str, ...]:
        """The names of the fields that describe this actuator (all of them, but see `InverterParams`)."""
        return tuple(f.name for f in dataclasses.fields(self))  # type: ignore[arg-type]

    def to_dict(self) -> dict[str, Any]:
        """The fields in use (`fields_in_use`), by name."""
        return {name: getattr(self, name) for name in self.fields_in_use()}
