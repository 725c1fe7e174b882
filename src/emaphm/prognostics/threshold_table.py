"""The ``[thresholds]`` table of the actuator file, from a `derive_thresholds` result.

`emaphm.actuator.load_thresholds` (and ``emaphm rul --params``) reads it back.
"""

from __future__ import annotations

import math
from typing import Any

__all__ = ["thresholds_toml"]


def _decimals(resolution: float) -> int:
    """Decimals that show a distance to `resolution`: 3 for 0.005, 2 for 0.01."""
    return max(1, math.ceil(-math.log10(resolution) - 1e-9))


def _round_down(value: float, resolution: float) -> str:
    """`value` rounded down to the decimals of `resolution` (a threshold errs early), as TOML."""
    decimals = _decimals(resolution)
    rounded = math.floor(value * 10**decimals + 1e-9) / 10**decimals
    if rounded <= 0.0:  # a threshold below the resolution's last decimal: two significant digits
        decimals = 1 - math.floor(math.log10(value))
        rounded = math.floor(value * 10**decimals) / 10**decimals
    text = f"{rounded:.{decimals}f}".rstrip("0")
    return text + "0" if text.endswith(".") else text


def _show(req: dict[str, Any], value: float) -> str:
    return f"{value / req['scale']:.4g} {req['unit']}"


def thresholds_toml(result: dict[str, Any]) -> str:
    """The ``[thresholds]`` table of a `derive_thresholds` result, to paste into the actuator file.

    Only the faults with a threshold, each rounded down to the decimals of the resolution (a
    threshold that errs, errs early) and commented with the requirement that limits it; the
    header names the actuator, the command, the requirements, and the faults left out (for which
    ``emaphm rul`` falls back to its placeholders). `emaphm.actuator.load_thresholds` reads it.

    Parameters
    ----------
    result : dict
        What `derive_thresholds` returned.
    """
    reqs = {r["kind"]: r for r in result["requirements"]}
    given = ", ".join(f"{r['kind']} = {r['text']}" for r in result["requirements"])
    lines = [
        f"# failure thresholds derived by 'emaphm thresholds' (emaphm {result['version']}), actuator "
        f"{result['params_hash']}, {result['command']['type']} command",
        f"# requirements: {given}",
        f"# distances from healthy in fault units, rounded down to {_decimals(result['resolution'])} decimals "
        f"(resolution {result['resolution']:g})",
    ]
    left_out = [name for name, f in result["faults"].items() if f["threshold"] is None]
    if left_out:
        lines.append(
            "# no threshold derived (emaphm rul uses its placeholders there, not limits): "
            + ", ".join(left_out)
        )
    lines.append("[thresholds]")
    entries = []
    for name, f in result["faults"].items():
        if f["threshold"] is None:
            continue
        req = reqs[f["limited_by"]]
        reached = _show(req, f["at_threshold"][req["kind"]])
        comment = f"limited by {req['kind']} < {req['text']} ({reached} there)" + (
            f", worst case {f['case']}" if f["case"] else ""
        )
        entries.append((f"{name} = {_round_down(f['threshold'], result['resolution'])}", comment))
    width = max((len(e) for e, _ in entries), default=0)
    lines += [f"{e.ljust(width)}  # {c}" for e, c in entries]
    return "\n".join(lines) + "\n"
