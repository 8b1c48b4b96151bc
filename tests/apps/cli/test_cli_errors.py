"""The command line's error contract: input errors print ``gazebot: error:`` and exit 2, a bug
keeps its traceback; and the command and transport modules import each other in one direction."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from gazebot.apps import cli
from gazebot.apps.cli.errors import UsageError

ROOT = Path(cli.__file__).resolve().parents[2]


def _fake_command(monkeypatch, exc: BaseException) -> None:
    """``gazebot boom`` raises ``exc``."""
    import argparse

    def boom(args):
        raise exc

    def parser():
        p = argparse.ArgumentParser(prog="gazebot")
        p.add_subparsers().add_parser("boom").set_defaults(func=boom)
        return p

    monkeypatch.setattr(cli, "build_parser", parser)


def test_a_usage_error_prints_gazebot_error_and_exits_2(monkeypatch, capsys):
    _fake_command(monkeypatch, UsageError("--fps must be positive"))
    assert cli.main(["boom"]) == 2
    assert capsys.readouterr().err.strip() == "gazebot: error: --fps must be positive"


def test_a_missing_file_is_an_input_error(monkeypatch, capsys):
    _fake_command(monkeypatch, FileNotFoundError("no such file: x.csv"))
    assert cli.main(["boom"]) == 2
    assert "gazebot: error: no such file: x.csv" in capsys.readouterr().err


def test_a_bugs_value_error_keeps_its_traceback(monkeypatch):
    _fake_command(monkeypatch, ValueError("math domain error"))
    with pytest.raises(ValueError, match="math domain error"):
        cli.main(["boom"])


def test_a_wrong_option_value_of_a_real_command_is_a_usage_error(tmp_path, capsys):
    rc = cli.main(["render", "eyes", "--width", "3", "--out", str(tmp_path / "e.png")])
    assert rc == 2
    assert "gazebot: error: width must be an integer" in capsys.readouterr().err


@pytest.mark.parametrize(
    "argv",
    [
        ["demo", "--seed", "-1"],
        ["render", "video", "--behavior", "face", "--out", "v.mp4", "--seed", "-1"],
        ["sim", "--headless", "--seed", "-1"],
        ["run", "--seed", "-1"],
        ["display", "--seed", "-1"],
        ["study", "plan", "--participants", "12", "--video-seed", "-2"],
        ["annotations", "replay", "DIR", "--behavior", "face", "--seed", "-1"],
    ],
)
def test_a_negative_seed_is_an_argument_error_before_any_work(argv, capsys):
    """NumPy takes no negative seed: it used to be a traceback after the scene was built."""
    with pytest.raises(SystemExit) as stop:
        cli.main(argv)
    assert stop.value.code == 2
    assert "seed: expected an integer >= 0, got '-" in capsys.readouterr().err


def test_demo_odd_video_width_is_a_usage_error(tmp_path, capsys):
    assert cli.main(["demo", "--width", "7", "--out", str(tmp_path / "d")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("gazebot: error: --width/--height: video width must be an even")
    assert not (tmp_path / "d").exists()


def _imports(path: Path) -> set[str]:
    """Every gazebot module ``path`` imports, at module level or inside functions."""
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("gazebot"):
            out.add(node.module)
            out.update(f"{node.module}.{a.name}" for a in node.names)
        elif isinstance(node, ast.Import):
            out.update(a.name for a in node.names if a.name.startswith("gazebot"))
    return out


@pytest.mark.parametrize("package", ["cli", "drivers", "runtime", "render"])
def test_modules_of_a_package_import_each_other_without_a_circle(package):
    files = {f"gazebot.{package}.{p.stem}": p for p in (ROOT / package).glob("*.py")
             if p.stem != "__init__"}
    graph = {m: _imports(p) & set(files) for m, p in files.items()}

    def visit(m, stack):
        if m in stack:
            raise AssertionError("import circle: " + " -> ".join([*stack, m]))
        for n in graph[m]:
            visit(n, [*stack, m])

    for m in graph:
        visit(m, [])


def test_run_and_display_share_the_silent_after_name_and_the_old_run_spelling_warns(capsys):
    from gazebot.apps.cli import build_parser

    parser = build_parser()
    run = parser.parse_args(["run", "--robot", "sawyer", "--silent-after", "0.3"])
    display = parser.parse_args(["display", "--robot", "sawyer", "--silent-after", "0.3"])
    assert run.silent_after == display.silent_after == 0.3
    assert "deprecated" not in capsys.readouterr().err
    old = parser.parse_args(["run", "--robot", "sawyer", "--silence-after", "0.4"])
    assert old.silent_after == 0.4
    assert "--silence-after is deprecated, use --silent-after" in capsys.readouterr().err
    assert parser.parse_args(["run", "--robot", "sawyer"]).silent_after == 0.15
