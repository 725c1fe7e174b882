"""A campaign's ``[identify]`` table: the settings every job of the campaign identifies with.

Its keys are the fields of `IdentifySettings` but the seed (the campaign draws one per job) and the
threads (one per job), checked as the settings check them, and identify's input files, resolved
to the campaign file's folder.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

from ..errors import InputError

__all__ = ["IDENTIFY_FILES", "NOT_IN_CAMPAIGNS", "identify_keys", "parse_identify"]

IDENTIFY_FILES = ("calibration", "uq_calibration", "params")
NOT_IN_CAMPAIGNS = ("seed", "workers")


def _fail(where: str, message: str) -> InputError:
    return InputError(f"{where}: {message}")


def identify_keys() -> list[str]:
    """The keys an [identify] table may hold (`IdentifySettings`' fields and the input files)."""
    from ..identification.settings import IdentifySettings

    fields = [f.name for f in dataclasses.fields(IdentifySettings) if f.name not in NOT_IN_CAMPAIGNS]
    return [*fields, *IDENTIFY_FILES]


def parse_identify(data: Any, folder: Path, where: str) -> dict[str, Any]:
    """The [identify] table checked as `IdentifySettings` checks it; the keys given, with their
    values as identify takes them ("off" -> None) and the files' absolute paths."""
    from ..identification.settings import IdentifySettings

    if not isinstance(data, dict):
        raise _fail(where, "[identify] must be a table")
    known = identify_keys()
    unknown = sorted(set(data) - set(known))
    if unknown:
        raise _fail(where, f"[identify] unknown key(s) {', '.join(unknown)}; known: {', '.join(known)}")
    options = {k: v for k, v in data.items() if k not in IDENTIFY_FILES}
    try:
        settings = IdentifySettings.from_mapping(options, where="[identify]")
    except InputError as exc:
        raise _fail(where, f"[identify] {exc}") from None
    out: dict[str, Any] = {key: getattr(settings, key) for key in options}
    for key in IDENTIFY_FILES:
        if key in data:
            value = data[key]
            if not isinstance(value, str) or not (folder / value).is_file():
                raise _fail(where, f"[identify] {key} = {value!r}: no such file")
            out[key] = str((folder / value).resolve())
    return out
