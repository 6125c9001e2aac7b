"""The size rule, enforced: no module over 400 lines, no function or method over 60.

Every ``.py`` file under libs/, apps/, benchmarks/ and tests/ is measured (generated code
and virtual environments excepted); there is no allow-list. A function's length runs from
its ``def`` line to its last line (``end_lineno - lineno + 1``), so decorators do not count.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.conftest import REPO

MODULE_LIMIT = 400
"""Most lines a module may have."""
FUNCTION_LIMIT = 60
"""Most lines a function or method may have, decorators excluded."""
ROOTS = ("libs", "apps", "benchmarks", "tests")
SKIPPED = frozenset({"generated", ".venv", "__pycache__"})

Function = ast.FunctionDef | ast.AsyncFunctionDef


def python_files(repo: Path = REPO) -> Iterator[Path]:
    """Every measured ``.py`` file, sorted, as a path under ``repo``."""
    for root in ROOTS:
        for path in sorted((repo / root).rglob("*.py")):
            if not SKIPPED.intersection(path.relative_to(repo).parts):
                yield path


def _functions(node: ast.AST, prefix: str = "") -> Iterator[tuple[str, Function]]:
    """Every function in ``node`` with its dotted name (``Class.method``, ``outer.inner``)."""
    for child in ast.iter_child_nodes(node):
        if isinstance(child, Function | ast.ClassDef):
            name = f"{prefix}{child.name}"
            if not isinstance(child, ast.ClassDef):
                yield name, child
            yield from _functions(child, f"{name}.")
        else:
            yield from _functions(child, prefix)


def violations(path: Path, text: str) -> list[str]:
    """One ``path:line: name is N lines (limit L)`` line per breach of the rule in ``text``."""
    found = []
    lines = len(text.splitlines())
    if lines > MODULE_LIMIT:
        found.append(f"{path}:1: module is {lines} lines (limit {MODULE_LIMIT})")
    for name, function in _functions(ast.parse(text, filename=str(path))):
        length = (function.end_lineno or function.lineno) - function.lineno + 1
        if length > FUNCTION_LIMIT:
            found.append(
                f"{path}:{function.lineno}: {name} is {length} lines (limit {FUNCTION_LIMIT})"
            )
    return found


def test_no_module_or_function_over_the_limit() -> None:
    found = [
        breach
        for path in python_files()
        for breach in violations(path.relative_to(REPO), path.read_text(encoding="utf-8"))
    ]
    if found:
        pytest.fail("split these at a seam:\n" + "\n".join(found), pytrace=False)


def test_the_measure_names_nested_functions_and_skips_decorators() -> None:
    body = "\n".join(f"        x = {i}" for i in range(FUNCTION_LIMIT - 1))
    text = f"class A:\n    @first\n    @second\n    def f():\n{body}\n"
    assert violations(Path("m.py"), text) == []
    text += "        return x\n"
    assert violations(Path("m.py"), text) == [
        f"m.py:4: A.f is {FUNCTION_LIMIT + 1} lines (limit {FUNCTION_LIMIT})"
    ]
    long_module = "\n" * MODULE_LIMIT + "x = 1\n"
    assert violations(Path("m.py"), long_module) == [
        f"m.py:1: module is {MODULE_LIMIT + 1} lines (limit {MODULE_LIMIT})"
    ]


def test_every_root_is_measured() -> None:
    measured = {path.relative_to(REPO).parts[0] for path in python_files()}
    assert measured == set(ROOTS)
    assert __file__ in {str(path) for path in python_files()}
