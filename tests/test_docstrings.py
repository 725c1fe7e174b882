"""Every parameter of the public API is documented (docs/conventions.md, "Public names").

The public callables are the functions and classes in the ``__all__`` of `emaphm` and of the public
subpackages (`PUBLIC`); a class is checked on its constructor's parameters, against the class's and
``__init__``'s docstrings together (a dataclass's fields are its constructor's parameters). A
parameter counts as documented when its docstring names it as ``name :`` (numpydoc's
"Parameters" section, the house's ``name : type  what [unit]`` lines, or the compact
``a : ...; b : ...`` form), alone on a line (numpydoc without a type), in a line listing several
(``params, command, duration``), as ``**name`` or in backticks (`` `name` ``). ``self``, ``cls``
and ``*args`` are skipped; a ``**options`` must be named as the others are. Numpydoc is not a
dependency: a regular expression does the parsing (python-control's ``docstrings_test.py`` uses
numpydoc for the same check).
"""

from __future__ import annotations

import importlib
import inspect
import re
from pathlib import Path

import pytest

# the packages whose __all__ is public API (docs/conventions.md)
PUBLIC = (
    "emaphm",
    "emaphm.identification",
    "emaphm.calibration",
    "emaphm.measured",
    "emaphm.campaign",
    "emaphm.prognostics",
    "emaphm.models",
)


def _public_callables() -> dict[str, object]:
    """Qualified name -> callable, each object once (under the first package that exports it)."""
    found: dict[str, object] = {}
    seen: set[int] = set()
    for package in PUBLIC:
        module = importlib.import_module(package)
        for name in module.__all__:
            obj = getattr(module, name)
            if (inspect.isfunction(obj) or inspect.isclass(obj)) and id(obj) not in seen:
                seen.add(id(obj))
                found[f"{package}.{name}"] = obj
    return found


def _documented(name: str, doc: str) -> bool:
    """Whether `doc` names parameter `name` (see the module docstring for the accepted forms)."""
    n = re.escape(name)
    if re.search(rf"`{n}`|\*\*{n}\b|(?<![\w.]){n}\s*:(?!:)|^\s*{n}\s*$", doc, re.M):
        return True
    # a numpydoc line listing several: "params, command, duration" or "a, b : type"
    for line in doc.splitlines():
        head = line.split(":", 1)[0].strip()
        if "," in head and name in [part.strip(" *") for part in head.split(",")]:
            return True
    return False


def _missing(obj: object) -> list[str]:
    """The parameters of `obj` (its constructor for a class) that its docstrings do not name."""
    doc = inspect.getdoc(obj) or ""
    init = obj.__dict__.get("__init__") if inspect.isclass(obj) else None
    if init is not None:
        doc += "\n" + (inspect.getdoc(init) or "")
    try:
        signature = inspect.signature(obj)  # a class: its constructor's
    except (TypeError, ValueError):  # a builtin-backed class: nothing to check
        return []
    return [
        p.name
        for p in signature.parameters.values()
        if p.name not in ("self", "cls") and p.kind is not p.VAR_POSITIONAL and not _documented(p.name, doc)
    ]


CALLABLES = _public_callables()


def test_the_public_api_is_not_empty() -> None:
    assert len(CALLABLES) > 50  # the scope of the test below; a broken collection would pass it


@pytest.mark.parametrize("name", sorted(CALLABLES))
def test_every_parameter_is_documented(name: str) -> None:
    assert _missing(CALLABLES[name]) == [], f"{name}: parameters missing from the docstring"


def test_the_check_finds_an_undocumented_parameter() -> None:
    def documented(faults, *, seed=0, **options):
        """Parameters
        ----------
        faults : array_like
            k1..k8.
        seed : int
            The seed.
        """

    assert _missing(documented) == ["options"]
    documented.__doc__ += "options\n    Settings' fields as keywords.\n"
    assert _missing(documented) == []


def test_the_conventions_page_names_the_public_packages():
    page = (Path(__file__).resolve().parents[1] / "docs" / "conventions.md").read_text()
    section = page.split("## Public names", 1)[1].split("\n## ", 1)[0]
    assert all(f"`{package}`" in section for package in PUBLIC), "docs/conventions.md: Public names"
