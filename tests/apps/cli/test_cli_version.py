"""``gazebot --version``: one fact, ``gazebot.__version__``, which the package metadata is built
from (pyproject's version is dynamic, read from ``gazebot/__init__.py``)."""

from __future__ import annotations

import importlib.metadata
import re
from pathlib import Path

import pytest

import gazebot
from gazebot.apps.cli import main

ROOT = Path(gazebot.__file__).resolve().parents[1]


def test_version_prints_the_packages_version(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["--version"])
    assert exit_.value.code == 0
    assert capsys.readouterr().out == f"gazebot {gazebot.__version__}\n"
    assert re.fullmatch(r"\d+\.\d+\.\d+", gazebot.__version__)


def test_the_metadata_version_is_read_from_gazebot_init():
    tomllib = pytest.importorskip("tomllib")  # Python 3.11+
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    assert "version" not in project["project"] and "version" in project["project"]["dynamic"]
    assert project["tool"]["hatch"]["version"]["path"] == "gazebot/__init__.py"


def test_the_installed_metadata_agrees():
    try:
        installed = importlib.metadata.version("gazebot")
    except importlib.metadata.PackageNotFoundError:
        pytest.skip("gazebot is not installed (run from a source tree)")
    assert installed == gazebot.__version__
