"""The docs and the code agree: quick start vs CI, generated tables, examples run."""

import re
import runpy
import sys
from pathlib import Path

import pytest

from emaphm.params import parameter_table_markdown

ROOT = Path(__file__).resolve().parents[1]


def quick_start_commands():
    text = (ROOT / "README.md").read_text()
    section = text.split("## Quick start", 1)[1].split("\n## ", 1)[0]
    return re.findall(r"```bash\n(.+?)\n```", section)


def test_readme_quick_start_has_two_commands_and_ci_runs_the_test_one():
    commands = quick_start_commands()
    assert len(commands) == 2
    assert commands[0].endswith("emaphm demo")
    assert "pytest" in commands[1]
    assert commands[1] in (ROOT / ".ci" / "run").read_text().splitlines()


def test_parameter_table_in_the_docs_is_generated_from_the_code():
    doc = (ROOT / "docs" / "theory" / "hf-model.md").read_text()
    block = doc.split("<!-- params:start -->\n", 1)[1].split("<!-- params:end -->", 1)[0]
    assert block == parameter_table_markdown(), "run: python docs/update_tables.py"


@pytest.mark.parametrize("script", sorted((ROOT / "examples").glob("*.py")), ids=lambda p: p.name)
def test_examples_run(script, capsys, monkeypatch):
    monkeypatch.setattr(sys, "argv", [str(script)])
    runpy.run_path(str(script), run_name="__main__")
    assert capsys.readouterr().out.strip()
