"""What a job's answer depends on besides its inputs: the code, the packaged data, the settings.

A job's key (`spec.Job.key`) names the job: its campaign, actuator, flight, seed and input files.
Its fingerprint names what would compute it: the source of every emaphm module and packaged data
file (the LF, interval and detection calibrations ship there), the identification's settings
after defaults (`IdentifySettings`), its tuned constants (`identification.limits`) and the files
the job names (calibration, interval calibration, actuator). A stored row whose fingerprint is
not the job's was made by other code or data: `campaign run` redoes it (review H1: the version
string had not moved in 204 commits while the packaged calibration changed nine times).
"""

from __future__ import annotations

import functools
import hashlib
import json
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

__all__ = ["code_hash", "fingerprint"]

PACKAGE = Path(__file__).resolve().parent.parent  # src/emaphm


@functools.lru_cache(maxsize=1)
def code_hash() -> str:
    """SHA-256 of every module and packaged data file of the installed emaphm (names and bytes)."""
    h = hashlib.sha256()
    for path in sorted(PACKAGE.rglob("*")):
        relative = path.relative_to(PACKAGE)
        if not path.is_file() or "__pycache__" in relative.parts:
            continue
        if path.suffix == ".py" or relative.parts[0] == "data":
            h.update(relative.as_posix().encode() + b"\0")
            h.update(path.read_bytes())
    return h.hexdigest()


def fingerprint(settings: Mapping[str, Any], digest: Callable[[Path], str], files: tuple[str, ...]) -> str:
    """The fingerprint of a job with these `[identify]` settings (its file keys hashed by `digest`),
    20 hex digits (module docstring)."""
    from ..identification import limits
    from ..identification.settings import IdentifySettings

    options = {k: v for k, v in settings.items() if k not in files}
    resolved = IdentifySettings.from_mapping(options, where="[identify]").to_json()
    for name in ("seed", "workers"):  # the job's own seed; threads do not change the answer
        resolved.pop(name)
    content = {
        "code": code_hash(),
        "settings": resolved,
        "limits": limits.as_dict(),
        "files": {k: (digest(Path(settings[k])) if settings.get(k) is not None else None) for k in files},
    }
    text = json.dumps(content, sort_keys=True, separators=(",", ":"), default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:20]
