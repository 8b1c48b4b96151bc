"""The behaviors package reads the fitted human model without depending on the annotations."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import gazebot.core.behaviors


def test_no_behaviors_module_imports_annotations_anywhere():
    """Not at import time, not inside a function, not under TYPE_CHECKING: no package cycle."""
    offenders = []
    for path in Path(gazebot.core.behaviors.__file__).parent.glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom):
                names = [node.module or ""]
            elif isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            else:
                continue
            offenders += [
                f"{path.name}:{node.lineno}"
                for n in names
                if n.startswith("gazebot.apps.annotations")
            ]
    assert offenders == []


def test_behaviors_and_the_human_model_load_without_importing_annotations():
    code = (
        "import sys, gazebot.core.behaviors, gazebot.core.behaviors.human\n"
        "from gazebot.core.behaviors import load_behavior\n"
        "spec = load_behavior('human-receiver')\n"
        "assert spec.human.patterns, 'no patterns'\n"
        "bad = sorted(m for m in sys.modules if m.startswith('gazebot.apps.annotations'))\n"
        "print(','.join(bad))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout.strip()
    assert out == ""


def test_fitting_code_lives_in_annotations_not_behaviors():
    import gazebot.core.behaviors.human as human
    from gazebot.apps.annotations import fit

    assert not hasattr(human, "fit_human_model")
    assert callable(fit.fit_human_model) and callable(fit.human_behavior_document)


def test_behaviors_modules_import_each_other_without_a_cycle():
    """Every import inside the package (function-level ones too) goes one way."""
    folder = Path(gazebot.core.behaviors.__file__).parent
    graph: dict[str, set[str]] = {}
    for path in folder.glob("*.py"):
        deps = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith(
                "gazebot.core.behaviors."
            ):
                deps.add(node.module.rsplit(".", 1)[1])
        graph[path.stem] = deps - {path.stem}

    def reaches(start: str, goal: str, seen: set[str]) -> bool:
        for dep in graph.get(start, ()):
            if dep == goal or (dep not in seen and reaches(dep, goal, seen | {dep})):
                return True
        return False

    assert "spec" in graph["human"] or "segment" in graph["human"]  # the graph is read
    assert [m for m in graph if m != "__init__" and reaches(m, m, set())] == []
