"""Check the package's structure against the house goals (issue 31, STYLE "What to avoid").

    python scripts/structure_check.py [SRC]        # SRC defaults to src/emaphm next to this script

Prints three lists and exits 1 when any is non-empty (0 otherwise):

(a) modules over `MAX_MODULE_LINES` lines, outside ``kernels/`` (numba kernels are hand-scheduled
    hot loops, judged apart);
(b) functions and methods over `MAX_FUNCTION_LINES` lines, from ``def`` to their last line with
    the docstring, outside ``kernels/``;
(c) import cycles: the strongly connected groups of the import graph over the package. The graph
    counts function-level (deferred) imports as well as module-level ones, ``from . import x`` as
    an import of the submodule ``x``, and an import of ``a.b.c`` as also importing ``a`` and
    ``a.b`` (their ``__init__`` runs first). Imports under ``if TYPE_CHECKING:`` are left out (they
    never run); so are a module's imports of its own parent packages (already running when it is).

`check(src)` returns the three lists, for the tests (tests/test_structure.py).
"""

from __future__ import annotations

import ast
import sys
from dataclasses import dataclass
from pathlib import Path

MAX_MODULE_LINES = 300
MAX_FUNCTION_LINES = 80
EXEMPT = ("kernels",)  # sub-packages whose sizes are not checked

SRC = Path(__file__).resolve().parents[1] / "src" / "emaphm"


@dataclass(frozen=True)
class Report:
    """The three lists of `check`: each entry one line, as printed."""

    modules: list[str]
    functions: list[str]
    cycles: list[str]

    @property
    def ok(self) -> bool:
        return not (self.modules or self.functions or self.cycles)


def _modules(src: Path) -> dict[str, Path]:
    """Dotted module name -> file, for every module of the package at `src`."""
    out = {}
    for path in sorted(src.rglob("*.py")):
        parts = list(path.relative_to(src.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


def _exempt(src: Path, path: Path) -> bool:
    return path.relative_to(src).parts[0] in EXEMPT


def _long_modules(src: Path, modules: dict[str, Path]) -> list[str]:
    out = []
    for path in modules.values():
        lines = len(path.read_text(encoding="utf-8").splitlines())
        if lines > MAX_MODULE_LINES and not _exempt(src, path):
            out.append(f"{path.relative_to(src)}: {lines} lines")
    return out


def _long_functions(src: Path, modules: dict[str, Path]) -> list[str]:
    out = []
    for path in modules.values():
        if _exempt(src, path):
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node, qualname in _functions(tree, ""):
            lines = node.end_lineno - node.lineno + 1  # type: ignore[operator]
            if lines > MAX_FUNCTION_LINES:
                out.append(f"{path.relative_to(src)}:{node.lineno} {qualname}: {lines} lines")
    return out


def _functions(node: ast.AST, prefix: str) -> list[tuple[ast.FunctionDef | ast.AsyncFunctionDef, str]]:
    """Every function and method under `node`, nested ones included, with its qualified name."""
    out: list[tuple[ast.FunctionDef | ast.AsyncFunctionDef, str]] = []
    for child in ast.iter_child_nodes(node):
        if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
            out.append((child, prefix + child.name))
            out += _functions(child, f"{prefix}{child.name}.")
        elif isinstance(child, ast.ClassDef):
            out += _functions(child, f"{prefix}{child.name}.")
        else:
            out += _functions(child, prefix)
    return out


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"
    )


def _imports(node: ast.AST) -> list[ast.Import | ast.ImportFrom]:
    """Every import statement under `node`, at any depth, except the bodies of ``if TYPE_CHECKING:``."""
    out: list[ast.Import | ast.ImportFrom] = []
    for child in ast.iter_child_nodes(node):
        if isinstance(child, (ast.Import, ast.ImportFrom)):
            out.append(child)
        elif isinstance(child, ast.If) and _is_type_checking(child.test):
            for other in child.orelse:
                out += [other] if isinstance(other, (ast.Import, ast.ImportFrom)) else _imports(other)
        else:
            out += _imports(child)
    return out


def _with_parents(name: str) -> list[str]:
    parts = name.split(".")
    return [".".join(parts[: i + 1]) for i in range(len(parts))]


def _targets(module: str, is_package: bool, stmt: ast.Import | ast.ImportFrom, known: set[str]) -> set[str]:
    """The package modules one import statement runs (parents included)."""
    names: list[str] = []
    if isinstance(stmt, ast.Import):
        names = [alias.name for alias in stmt.names]
    else:
        if stmt.level:
            base = module.split(".") if is_package else module.split(".")[:-1]
            base = base[: len(base) - (stmt.level - 1)]
            stem = ".".join(base + ([stmt.module] if stmt.module else []))
        else:
            stem = stmt.module or ""
        names = [stem]
        names += [f"{stem}.{alias.name}" for alias in stmt.names if f"{stem}.{alias.name}" in known]
    out: set[str] = set()
    for name in names:
        out.update(n for n in _with_parents(name) if n in known)
    return out


def import_graph(src: Path = SRC) -> dict[str, set[str]]:
    """Module -> the package modules it imports (see the module docstring for what counts)."""
    modules = _modules(src)
    known = set(modules)
    graph: dict[str, set[str]] = {}
    for name, path in modules.items():
        is_package = path.name == "__init__.py"
        tree = ast.parse(path.read_text(encoding="utf-8"))
        own_parents = set(_with_parents(name)[:-1])
        edges: set[str] = set()
        for stmt in _imports(tree):
            edges |= _targets(name, is_package, stmt, known)
        graph[name] = edges - own_parents - {name}
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected groups of more than one module (Tarjan), each sorted, largest first."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    groups: list[list[str]] = []
    counter = [0]

    def visit(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                group.append(w)
                if w == v:
                    break
            if len(group) > 1:
                groups.append(sorted(group))

    sys.setrecursionlimit(max(sys.getrecursionlimit(), 10 * len(graph) + 100))
    for v in sorted(graph):
        if v not in index:
            visit(v)
    return sorted(groups, key=lambda g: (-len(g), g))


def check(src: Path = SRC) -> Report:
    """The modules too long, the functions too long and the import cycles of the package at `src`."""
    modules = _modules(src)
    return Report(
        modules=_long_modules(src, modules),
        functions=_long_functions(src, modules),
        cycles=[", ".join(group) for group in cycles(import_graph(src))],
    )


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    src = Path(args[0]).resolve() if args else SRC
    report = check(src)
    sections = [
        (f"(a) modules over {MAX_MODULE_LINES} lines (outside {', '.join(EXEMPT)}/)", report.modules),
        (f"(b) functions over {MAX_FUNCTION_LINES} lines (outside {', '.join(EXEMPT)}/)", report.functions),
        ("(c) import cycles (strongly connected groups, deferred imports included)", report.cycles),
    ]
    for title, entries in sections:
        print(f"{title}: {len(entries)}")
        for entry in entries:
            print(f"    {entry}")
    return 0 if report.ok else 1


if __name__ == "__main__":
    sys.exit(main())
