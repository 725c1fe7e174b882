"""emaphm byte-compiles its own folder once where Python writes no bytecode (`emaphm._bytecode`)."""

import sys

import pytest

from emaphm import _bytecode


@pytest.fixture
def package(tmp_path):
    """A small package without bytecode."""
    folder = tmp_path / "pkg"
    (folder / "sub").mkdir(parents=True)
    (folder / "__init__.py").write_text("X = 1\n")
    (folder / "sub" / "__init__.py").write_text("")
    (folder / "sub" / "mod.py").write_text("def f():\n    return 2\n")
    return folder


def pycs(folder):
    return sorted(p.name.split(".")[0] for p in folder.rglob("*.pyc"))


def test_compiled_once_where_python_writes_no_bytecode(package, monkeypatch):
    monkeypatch.setattr(sys, "dont_write_bytecode", True)
    monkeypatch.delenv(_bytecode.OPT_OUT, raising=False)
    assert _bytecode.compile_package(package)
    assert pycs(package) == ["__init__", "__init__", "mod"]
    assert not _bytecode.compile_package(package)  # done: nothing the second time


def test_nothing_written_where_python_writes_it_or_the_user_opts_out(package, monkeypatch):
    monkeypatch.setattr(sys, "dont_write_bytecode", False)
    assert not _bytecode.compile_package(package)
    monkeypatch.setattr(sys, "dont_write_bytecode", True)
    monkeypatch.setenv(_bytecode.OPT_OUT, "1")
    assert not _bytecode.compile_package(package)
    assert pycs(package) == []


def test_a_folder_that_cannot_be_written_is_left_alone(package, monkeypatch):
    monkeypatch.setattr(sys, "dont_write_bytecode", True)
    monkeypatch.delenv(_bytecode.OPT_OUT, raising=False)
    monkeypatch.setattr(_bytecode.os, "access", lambda path, mode: False)
    assert not _bytecode.compile_package(package)
    assert pycs(package) == []
