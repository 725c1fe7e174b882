"""cli/output.progress: the bar shows only once the work has run its delay (issue 36)."""

import os
import subprocess
import sys

RUN = """
import sys, time
from emaphm.cli.output import progress
with progress(delay=float(sys.argv[1])) as update:
    update("early stage", 1, 4)
    time.sleep(float(sys.argv[2]))
    update("late stage", 3, 4)
print("rich.progress" in sys.modules, "cma" in sys.modules)
"""


def run(delay: str, sleep: str) -> subprocess.CompletedProcess[str]:
    env = {
        k: v for k, v in os.environ.items() if k not in ("FORCE_TERMINAL", "TTY_COMPATIBLE", "FORCE_COLOR")
    }
    env["TTY_COMPATIBLE"] = "1"  # stderr a terminal to rich, and to `err`
    return subprocess.run(
        [sys.executable, "-c", RUN, delay, sleep], capture_output=True, text=True, env=env, check=True
    )


def test_work_shorter_than_the_delay_shows_no_bar_and_imports_nothing_for_one():
    out = run("5", "0")
    assert out.stdout.split() == ["False", "False"]
    assert out.stderr == ""


def test_longer_work_gets_its_bar_from_the_stage_then_running():
    out = run("0.2", "0.3")
    assert out.stdout.split() == ["True", "True"]  # and the CMA-ES imported lean before its thread
    assert "late stage" in out.stderr and "early stage" not in out.stderr
