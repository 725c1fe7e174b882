"""The package's structure (issue 31): no module over 300 lines and no function over 80 outside
``kernels/``, no import cycle, deferred imports included (scripts/structure_check.py)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _structure_check():
    spec = importlib.util.spec_from_file_location("structure_check", ROOT / "scripts" / "structure_check.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["structure_check"] = module  # its dataclass looks itself up there
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def report():
    return _structure_check().check(ROOT / "src" / "emaphm")


def test_no_module_over_300_lines(report):
    assert report.modules == []


def test_no_function_over_80_lines(report):
    assert report.functions == []


def test_no_import_cycle(report):
    assert report.cycles == []


def test_the_check_sees_a_deferred_cycle_through_a_package_init(tmp_path):
    # pkg.a imports pkg.sub.b inside a function; pkg/sub/__init__ imports .c, which imports pkg.a
    pkg = tmp_path / "pkg"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text("def f():\n    from .sub import b\n")
    (pkg / "sub" / "__init__.py").write_text("from . import c\n")
    (pkg / "sub" / "b.py").write_text("")
    (pkg / "sub" / "c.py").write_text(
        "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from ..x import y\nfrom .. import a\n"
    )
    (pkg / "x.py").write_text("")
    check = _structure_check()
    graph = check.import_graph(pkg)
    assert graph["pkg.sub.c"] == {"pkg.a"}  # the TYPE_CHECKING import is left out
    assert check.cycles(graph) == [["pkg.a", "pkg.sub", "pkg.sub.c"]]
