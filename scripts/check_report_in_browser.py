"""Open an emaphm report in a real headless browser and check what a person would see (issue 10).

    python scripts/check_report_in_browser.py REPORT_DIR [--screenshot shot.png]

Loads REPORT_DIR/index.html in headless Chromium (Debian's `chromium` package; `apt install
chromium`), after its scripts ran, and checks that every figure decoded (the page's own count
of images with a natural width, `data-images-loaded`), that the verdict is in the rendered page
with its word, that a page that fits (or is doubtful) shows the per-fault table and the faults
figure while one that does not fit shows neither (no fault values, no fault bars) but says that no
faults are reported, that the result's JSON is there as a download, and that the page asked for
nothing outside itself. Prints what it found; exit 0 when all hold, 1 otherwise, 2 when no
browser is installed.
"""

from __future__ import annotations

import argparse
import re
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path

FLAGS = [
    "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
    "--virtual-time-budget=5000",
]  # fmt: skip


def browser() -> str | None:
    return next(
        (shutil.which(b) for b in ("chromium", "chromium-browser", "google-chrome") if shutil.which(b)), None
    )


def rendered_dom(page: Path, exe: str) -> str:
    with tempfile.TemporaryDirectory() as profile:
        res = subprocess.run(
            [exe, *FLAGS, f"--user-data-dir={profile}", "--dump-dom", page.resolve().as_uri()],
            capture_output=True, text=True, timeout=120,
        )  # fmt: skip
    return res.stdout


def require_browser() -> str:
    """The headless browser's executable, or FileNotFoundError saying how to install one."""
    exe = browser()
    if exe is None:
        raise FileNotFoundError("no headless browser: apt install chromium")
    return exe


def take_screenshot(page: Path, exe: str, screenshot: Path, width: int) -> None:
    """Save the rendered page as a PNG, `width` × 1800 pixels."""
    with tempfile.TemporaryDirectory() as profile:
        subprocess.run(
            [exe, *FLAGS, f"--user-data-dir={profile}", f"--screenshot={screenshot}", f"--window-size={width},1800",
             page.resolve().as_uri()],
            capture_output=True, timeout=120, check=False,
        )  # fmt: skip


def run_main(check: Callable[[Path, Path | None], list[str]], name: str, argument: str, what: str) -> None:
    """A checker's command line: ``name ARGUMENT [--screenshot PNG]``; exit 0 when `what` is fine,
    1 with a line per problem, 2 without a browser or the page."""
    parser = argparse.ArgumentParser(description=(sys.modules["__main__"].__doc__ or name).splitlines()[0])
    parser.add_argument(argument, type=Path)
    parser.add_argument("--screenshot", type=Path, default=None)
    args = parser.parse_args()
    try:
        problems = check(getattr(args, argument), args.screenshot)
    except FileNotFoundError as exc:
        print(f"{name}: {exc}", file=sys.stderr)
        sys.exit(2)
    for p in problems:
        print(f"problem: {p}")
    print(f"{what} OK in headless Chromium" if not problems else f"{len(problems)} problem(s)")
    sys.exit(1 if problems else 0)


def check(report: Path, screenshot: Path | None = None) -> list[str]:
    """The problems found in the rendered report (empty when it is fine)."""
    exe = require_browser()
    page = report / "index.html"
    source = page.read_text(encoding="utf-8")
    dom = rendered_dom(page, exe)
    problems = []
    loaded = re.search(r'data-images-loaded="(\d+)/(\d+)"', dom)
    if loaded is None:
        problems.append("the page's script did not run (no data-images-loaded)")
    elif loaded.group(1) != loaded.group(2) or loaded.group(2) == "0":
        problems.append(f"figures decoded: {loaded.group(1)} of {loaded.group(2)}")
    problems += _content_problems(dom)
    outside = re.findall(r'(?:src|href)="(?!data:)([^"]+)"', source)
    if outside:
        problems.append(f"the page refers to files or addresses outside itself: {outside[:3]}")
    if screenshot is not None:
        take_screenshot(page, exe, screenshot, 1100)
    return problems


WORDS = {"fits": "fits", "doubt": "doubtful", "nofit": "does not fit"}


def _content_problems(dom: str) -> list[str]:
    """What the rendered page lacks, or shows though it must not, for its verdict."""
    verdict = re.search(r'class="verdict (fits|doubt|nofit)"><p class="word">([^<]*)</p>', dom)
    if verdict is None:
        return ["no verdict in the rendered page"]
    problems = []
    kind, word = verdict.groups()
    if word != WORDS[kind]:
        problems.append(f"the verdict block {kind!r} says {word!r}")
    table = "k1 friction" in dom and "k8 kp_drift" in dom
    bars = "distance from healthy" in " ".join(re.findall(r'<img alt="([^"]*)"', dom))
    if kind == "nofit":
        if table or bars:
            problems.append("a page that does not fit shows fault values or fault bars")
        if "no faults are reported" not in dom:
            problems.append("a page that does not fit does not say that no faults are reported")
    elif not (table and bars):
        problems.append("the per-fault table or the faults figure is not in the rendered page")
    if not re.search(r'<a id="result-json" download="result.json" href="data:application/json;base64,', dom):
        problems.append("no result.json download in the rendered page")
    return problems


def main() -> None:
    run_main(check, "check_report_in_browser", "report", "report")


if __name__ == "__main__":
    main()
