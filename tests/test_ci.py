"""CI and the specification: .ci/run fails when no test ran; every `DESIGN §` citation resolves."""

from __future__ import annotations

import os
import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README_TEST_COMMAND = "python -m pytest"


@pytest.mark.parametrize(("pytest_status", "ci_status"), [(0, 0), (1, 1), (5, 5)])
def test_ci_script_passes_pytest_status_on_and_fails_when_no_test_ran(tmp_path, pytest_status, ci_status):
    # .ci/run with its install-and-test line replaced by a stand-in that exits like pytest would
    lines = (ROOT / ".ci" / "run").read_text().splitlines()
    command = [i for i, line in enumerate(lines) if README_TEST_COMMAND in line]
    assert len(command) == 1, "the README's test command appears once in .ci/run"
    lines[command[0]] = f"(exit {pytest_status})"
    script = tmp_path / "run"
    script.write_text("\n".join(lines).replace('cd "$(dirname "$0")/.."', "true") + "\n")
    res = subprocess.run(["bash", str(script)], capture_output=True, text=True,
                         env={**os.environ, "EMAPHM_CI_NO_SETUP": "1"})  # no chromium installed by a test
    assert res.returncode == ci_status


def _design_sections() -> dict[str, set[int]]:
    """Section number -> numbered items in it, from docs/design.md."""
    sections: dict[str, set[int]] = {}
    current = None
    for line in (ROOT / "docs" / "design.md").read_text().splitlines():
        if m := re.match(r"## (\d+)\. ", line):
            current = m.group(1)
            sections[current] = set()
        elif current and (m := re.match(r"(\d+)\. ", line)):
            sections[current].add(int(m.group(1)))
    return sections


def test_every_design_citation_resolves_in_the_vendored_spec():
    sections = _design_sections()
    assert set(sections) >= {str(n) for n in range(1, 10)}
    files = [*(ROOT / "src").rglob("*.py"), *(ROOT / "docs").rglob("*.md"), ROOT / "README.md"]
    missing = []
    for path in files:
        for sec, item in re.findall(r"DESIGN §(\d+)(?:\.(\d+))?", path.read_text()):
            if sec not in sections or (item and int(item) not in sections[sec]):
                missing.append(f"{path.relative_to(ROOT)}: DESIGN §{sec}{'.' + item if item else ''}")
    assert not missing, missing
