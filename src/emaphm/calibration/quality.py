"""Is a calibration good? Its held-out scenarios' NRMSE judged against what is normal (issue 34).

`emaphm calibrate` used to end at "held out: NRMSE 0.8 to 12.5 %" with no verdict. `judge` reads a
calibration's record (the held-out scenarios, noise off) and says "good", "usable" or "poor" by
the median NRMSE against the issue-5 targets the packaged calibration is held to (≤ 2 % goal,
≤ 5 % target; it reaches 1.1–3.1 % on the chirp), and names the scenarios the monitor does not
explain at all (above `UNEXPLAINED`): a poor calibration, or actuators beyond the monitor (an
FOC drive made unstable by shorts, docs/theory/hf-model.md §4b).
"""

from __future__ import annotations

import statistics
from typing import Any

__all__ = ["GOOD", "POOR", "UNEXPLAINED", "judge", "summary_lines"]

GOOD = 0.03  # median held-out NRMSE at most this: "good" (the packaged calibration: 2.0 % on the chirp)
POOR = 0.05  # above this: "poor" (the calibration target, BENCHMARKS.md "Summary against the targets")
UNEXPLAINED = 0.10  # a held-out scenario above this is one the monitor does not explain


def judge(record: dict[str, Any]) -> dict[str, Any]:
    """{"verdict", "median_nrmse", "unexplained": [{"name", "nrmse"}...], "limits"} of a calibration's
    record (its ``check_scenarios``); verdict "unknown" when it records none."""
    scenarios = record.get("check_scenarios") or []
    values = [float(s["nrmse"]) for s in scenarios]
    if not values:
        return {"verdict": "unknown", "median_nrmse": None, "unexplained": [], "limits": _limits()}
    median = statistics.median(values)
    verdict = "good" if median <= GOOD else "usable" if median <= POOR else "poor"
    unexplained = [
        {"name": s["name"], "nrmse": float(s["nrmse"])} for s in scenarios if float(s["nrmse"]) > UNEXPLAINED
    ]
    return {"verdict": verdict, "median_nrmse": median, "unexplained": unexplained, "limits": _limits()}


def _limits() -> dict[str, float]:
    return {"good": GOOD, "poor": POOR, "unexplained": UNEXPLAINED}


def summary_lines(quality: dict[str, Any]) -> list[str]:
    """The verdict in words, a line each (for `emaphm calibrate`)."""
    if quality["verdict"] == "unknown":
        return ["quality: unknown (no held-out scenarios)"]
    median = 100 * quality["median_nrmse"]
    words = {
        "good": f"good (median held-out NRMSE {median:.1f} %, at most {100 * GOOD:g} %)",
        "usable": f"usable (median held-out NRMSE {median:.1f} %, above {100 * GOOD:g} %, at most {100 * POOR:g} %)",
        "poor": f"this calibration is poor: median held-out NRMSE {median:.1f} %, above {100 * POOR:g} %; "
        "check the actuator file, or calibrate with more generations",
    }
    lines = [f"quality: {words[quality['verdict']]}"]
    if quality["unexplained"]:
        named = ", ".join(f"{u['name']} ({100 * u['nrmse']:.0f} %)" for u in quality["unexplained"][:4])
        more = len(quality["unexplained"]) - 4
        lines.append(
            f"{len(quality['unexplained'])} held-out scenario(s) above {100 * UNEXPLAINED:g} %, which the monitor "
            f"explains poorly or not at all: {named}{f' and {more} more' if more > 0 else ''}"
        )
    return lines
