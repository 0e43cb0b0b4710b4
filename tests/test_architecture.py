"""The shape of the package (issue #13): no import cycle, no module over 500 lines of code, no function over 80.

Lines of code: lines that hold code, not blank lines, comments or docstrings; so the formatter's one argument
per line does not count as size, and neither does documentation.

Imports are read with `ast`, at any depth (inside functions too). ``import a.b.c`` also runs the
``__init__`` of ``a`` and ``a.b``: those count as imported, except the importer's own ancestor packages,
which Python has always run before the importer (``from rjcad.life.table import T`` inside
``rjcad.life.fit`` does not depend on ``rjcad/life/__init__.py``; ``from rjcad.life import T`` does).
"""

from __future__ import annotations

import ast
import io
import itertools
import tokenize
from pathlib import Path

import pytest

MAX_MODULE_LINES = 500
MAX_FUNCTION_LINES = 80


def modules(package_dir: Path) -> dict[str, Path]:
    """Dotted name → file of every module under ``package_dir`` (a package's name is its ``__init__``'s)."""
    base = package_dir.parent
    out = {}
    for path in sorted(package_dir.rglob("*.py")):
        parts = list(path.relative_to(base).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = path
    return out


def _resolve(node: ast.ImportFrom, importer: str, is_package: bool) -> str:
    """The absolute module a ``from … import`` names (relative levels resolved)."""
    if not node.level:
        return node.module or ""
    parts = importer.split(".")
    if not is_package:
        parts.pop()  # a module's relative base is its package
    if node.level > 1:
        parts = parts[: len(parts) - (node.level - 1)]
    return ".".join(parts + ([node.module] if node.module else []))


def imports(name: str, path: Path, known: dict[str, Path]) -> set[str]:
    """The modules of ``known`` that importing ``name`` (the file ``path``) runs directly."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    is_package = path.name == "__init__.py"
    ancestors = {".".join(name.split(".")[:i]) for i in range(1, name.count(".") + 1)}
    if is_package:
        ancestors.add(name)
    out: set[str] = set()

    def add(target: str, passes_through: bool) -> None:
        """``target`` and the packages on its path; a package passed through counts unless it is an ancestor."""
        parts = target.split(".")
        for i in range(1, len(parts) + 1):
            mod = ".".join(parts[:i])
            through = i < len(parts) or passes_through
            if mod in known and not (through and mod in ancestors):
                out.add(mod)

    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                add(alias.name, passes_through=False)
        elif isinstance(node, ast.ImportFrom):
            base = _resolve(node, name, is_package)
            submodules = [f"{base}.{a.name}" for a in node.names if f"{base}.{a.name}" in known]
            attributes = len(submodules) < len(node.names)
            add(base, passes_through=not attributes)  # `from pkg import submodule` only passes through pkg
            for sub in submodules:
                add(sub, passes_through=False)
    out.discard(name)
    return out


def import_graph(package_dir: Path) -> dict[str, set[str]]:
    known = modules(package_dir)
    return {name: imports(name, path, known) for name, path in known.items()}


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One import cycle as [m1, m2, …, m1], or None (depth-first search, modules in sorted order)."""
    state: dict[str, int] = {}  # 1: on the stack, 2: done
    stack: list[str] = []

    def visit(m: str) -> list[str] | None:
        state[m] = 1
        stack.append(m)
        for n in sorted(graph.get(m, ())):
            if state.get(n) == 1:
                return stack[stack.index(n) :] + [n]
            if n not in state:
                found = visit(n)
                if found:
                    return found
        stack.pop()
        state[m] = 2
        return None

    for m in sorted(graph):
        if m not in state:
            found = visit(m)
            if found:
                return found
    return None


_NOT_CODE = {tokenize.COMMENT, tokenize.NL, tokenize.NEWLINE, tokenize.INDENT, tokenize.DEDENT, tokenize.ENDMARKER}


def code_lines(source: str) -> set[int]:
    """Numbers of the lines that hold code: no blank line, comment-only line or docstring line."""
    docs: set[int] = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and node.body:
            first = node.body[0]
            if (
                isinstance(first, ast.Expr)
                and isinstance(first.value, ast.Constant)
                and isinstance(first.value.value, str)
            ):
                docs.update(range(first.lineno, first.end_lineno + 1))
    lines = set()
    for tok in tokenize.generate_tokens(io.StringIO(source).readline):
        if tok.type not in _NOT_CODE:
            lines.update(range(tok.start[0], tok.end[0] + 1))
    return lines - docs


def long_functions(path: Path, label: str, limit: int = MAX_FUNCTION_LINES) -> list[str]:
    """'label:line name (n lines)' for every function or method (nested ones too) with more than ``limit`` lines
    of code."""
    source = path.read_text(encoding="utf-8")
    code = code_lines(source)
    out = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            n = len([ln for ln in code if node.lineno <= ln <= node.end_lineno])
            if n > limit:
                out.append(f"{label}:{node.lineno} {node.name} ({n} lines of code)")
    return out


@pytest.fixture(scope="module")
def rjcad_dir(root) -> Path:
    return root / "rjcad"


# ---------------------------------------------------------------- the walker itself, on made-up packages


def write_package(tmp_path: Path, files: dict[str, str]) -> Path:
    for rel, text in files.items():
        p = tmp_path / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text)
    return tmp_path / "pkg"


def test_walker_sees_relative_nested_and_dotted_imports(tmp_path):
    pkg = write_package(
        tmp_path,
        {
            "pkg/__init__.py": "",
            "pkg/a.py": "def f():\n    from .sub import deep\n",
            "pkg/b.py": "import pkg.sub.deep\n",
            "pkg/c.py": "from . import a\nfrom .sub.deep import X\n",
            "pkg/sub/__init__.py": "from pkg.sub.deep import X\n",
            "pkg/sub/deep.py": "from .. import c\nX = 1\n",
        },
    )
    g = import_graph(pkg)
    assert g["pkg.a"] == {"pkg.sub", "pkg.sub.deep"}  # inside a function; runs pkg/sub/__init__ on the way
    assert g["pkg.b"] == {"pkg.sub", "pkg.sub.deep"}  # `import a.b.c` runs a.b's __init__ (pkg: an ancestor)
    assert g["pkg.c"] == {"pkg.a", "pkg.sub", "pkg.sub.deep"}
    assert g["pkg.sub"] == {"pkg.sub.deep"}
    assert g["pkg.sub.deep"] == {"pkg.c"}  # its own package pkg.sub is an ancestor: not an edge
    cycle = find_cycle(g)  # a → sub.deep (through sub) → c → a
    assert cycle[0] == cycle[-1] and set(cycle) == {"pkg.a", "pkg.sub", "pkg.sub.deep", "pkg.c"}
    assert all(b in g[a] for a, b in itertools.pairwise(cycle))


def test_a_re_exporting_init_is_not_a_cycle_but_importing_from_it_is(tmp_path):
    pkg = write_package(
        tmp_path,
        {
            "pkg/__init__.py": "",
            "pkg/life/__init__.py": "from pkg.life.table import T\nfrom pkg.life.fit import F\n",
            "pkg/life/table.py": "T = 1\n",
            "pkg/life/fit.py": "from pkg.life.table import T\nF = 2\n",
        },
    )
    assert find_cycle(import_graph(pkg)) is None
    (pkg / "life" / "fit.py").write_text("from pkg.life import T\nF = 2\n")
    assert find_cycle(import_graph(pkg)) == ["pkg.life", "pkg.life.fit", "pkg.life"]


def test_the_walker_reads_rjcad(rjcad_dir):
    g = import_graph(rjcad_dir)
    assert {"rjcad", "rjcad.spring", "rjcad.cli", "rjcad.identify.fit", "rjcad.errors"} <= set(g)
    assert "rjcad.errors" in g["rjcad"] and "rjcad.identify.signal" in g["rjcad.identify.fit"]
    assert all(m.startswith("rjcad") for deps in g.values() for m in deps)


# ---------------------------------------------------------------- the rules (#13)


def test_no_import_cycle_in_rjcad(rjcad_dir):
    cycle = find_cycle(import_graph(rjcad_dir))
    assert cycle is None, "import cycle: " + " -> ".join(cycle)


def test_no_module_over_500_lines(rjcad_dir):
    big = [
        f"{p.relative_to(rjcad_dir.parent)} ({n} lines of code)"
        for p in sorted(rjcad_dir.rglob("*.py"))
        if (n := len(code_lines(p.read_text(encoding="utf-8")))) > MAX_MODULE_LINES
    ]
    assert not big, big


def test_no_function_over_80_lines(rjcad_dir):
    long = [f for p in sorted(rjcad_dir.rglob("*.py")) for f in long_functions(p, str(p.relative_to(rjcad_dir.parent)))]
    assert not long, long


def test_no_hand_made_modules_private_extensions_or_collector_tricks(rjcad_dir):
    """Issue #33: nothing in rjcad puts a module into ``sys.modules`` by hand, loads a package's private
    extension by path, or pauses and freezes the garbage collector around imports."""
    found = []
    for p in sorted(rjcad_dir.rglob("*.py")):
        for node in ast.walk(ast.parse(p.read_text(encoding="utf-8"))):
            if isinstance(node, (ast.Assign, ast.AugAssign)):
                targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                if any(isinstance(t, ast.Subscript) and ast.unparse(t.value) == "sys.modules" for t in targets):
                    found.append(f"{p.name}:{node.lineno} assigns into sys.modules")
            if isinstance(node, ast.Call) and ast.unparse(node.func) in ("gc.freeze", "gc.disable"):
                found.append(f"{p.name}:{node.lineno} calls {ast.unparse(node.func)}")
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and "_flapack" in node.value:
                found.append(f"{p.name}:{node.lineno} names _flapack")
            if isinstance(node, ast.Attribute) and node.attr == "ExtensionFileLoader":
                found.append(f"{p.name}:{node.lineno} loads an extension by path")
    assert not found, found
