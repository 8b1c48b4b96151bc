"""Every public class and function of the core and I/O layers has a docstring: the API reference
(`make docs`, one page per module of ``gazebot.core`` and ``gazebot.io``) shows an object only
with its docstring. Public: a module-level ``def`` or ``class`` whose name does not start with
``_``, in a module whose name does not either (as the reference's pages); ``@overload`` stubs are
skipped."""

from __future__ import annotations

import ast
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
PACKAGES = ("gazebot/core", "gazebot/io")


def _modules() -> list[Path]:
    out = []
    for package in PACKAGES:
        for path in sorted((REPO / package).rglob("*.py")):
            parts = path.relative_to(REPO).with_suffix("").parts
            if not any(p.startswith("_") and p != "__init__" for p in parts):
                out.append(path)
    return out


def _is_overload(node: ast.FunctionDef | ast.AsyncFunctionDef) -> bool:
    for d in node.decorator_list:
        name = d.attr if isinstance(d, ast.Attribute) else getattr(d, "id", "")
        if name == "overload":
            return True
    return False


def _undocumented(path: Path) -> list[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    rel = path.relative_to(REPO)
    out = []
    for node in tree.body:
        if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            continue
        if node.name.startswith("_") or (
            not isinstance(node, ast.ClassDef) and _is_overload(node)
        ):
            continue
        if ast.get_docstring(node) is None:
            kind = "class" if isinstance(node, ast.ClassDef) else "function"
            out.append(f"{rel}:{node.lineno}: {kind} {node.name}")
    return out


def test_the_walk_finds_the_core_and_io_modules():
    names = {p.relative_to(REPO).as_posix() for p in _modules()}
    assert "gazebot/core/engine.py" in names and "gazebot/io/ros2/codec.py" in names


def test_every_public_class_and_function_of_core_and_io_has_a_docstring():
    missing = [m for path in _modules() for m in _undocumented(path)]
    assert not missing, "public, without a docstring:\n" + "\n".join(missing)
