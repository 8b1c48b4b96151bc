"""The project's documentation as tests read it."""

from __future__ import annotations

from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def documentation_text() -> str:
    """The README and every page of the documentation site (``docs/``), as one text: tests that
    pin what the documentation says look here, wherever a section lives."""
    pages = [REPO / "README.md", *sorted((REPO / "docs").rglob("*.md"))]
    return "\n".join(p.read_text(encoding="utf-8") for p in pages)
