"""MkDocs hook: pages generated from their one source at build time (the CLI reference from the
argparse parsers, the topic table from the code, one API page per module of gazebot's core and
I/O). Nothing generated is written into docs/."""

from __future__ import annotations

import pkgutil

from mkdocs.structure.files import File, Files

import gazebot.core
import gazebot.io
from gazebot.apps.cli.reference import cli_markdown, topics_markdown


def _modules(package) -> list[str]:
    names = [package.__name__]
    for info in pkgutil.walk_packages(package.__path__, package.__name__ + "."):
        if not info.name.rsplit(".", 1)[-1].startswith("_"):
            names.append(info.name)
    return sorted(names)


def api_pages() -> dict[str, str]:
    """``reference/api/<module>.md`` -> a mkdocstrings page for that module."""
    pages = {}
    for package in (gazebot.core, gazebot.io):
        for name in _modules(package):
            pages[f"reference/api/{name}.md"] = f"# `{name}`\n\n::: {name}\n"
    return pages


def on_files(files: Files, config) -> Files:
    generated = {
        "reference/cli.md": cli_markdown(),
        "reference/topics.md": topics_markdown(),
        **api_pages(),
    }
    index = ["# API reference\n", "Every public class and function of gazebot's core and I/O "
             "layers, from their docstrings.\n"]
    for path in sorted(p for p in generated if p.startswith("reference/api/")):
        name = path.removeprefix("reference/api/").removesuffix(".md")
        index.append(f"- [`{name}`]({name}.md)")
    generated["reference/api/index.md"] = "\n".join(index) + "\n"
    for path, content in generated.items():
        files.append(File.generated(config, path, content=content))
    return files
