"""A command whose extra is not installed says which extra, in one line, and exits 2; the table
of extras agrees with pyproject.toml."""

from __future__ import annotations

import importlib.metadata as md
import re

import pytest

import gazebot.apps.cli.ik as ik_command
from gazebot.apps.cli import main
from gazebot.apps.cli.extras import EXTRA_OF_MODULE, extra_for, extra_for_command
from tests.blocked_extras import REPO, gazebot_without_extras, run_without_extras


def test_gps_train_without_the_gps_extra_names_it_in_one_line_and_exits_2(tmp_path):
    res = gazebot_without_extras("gps", "train", "--out", str(tmp_path / "policy"))
    assert res.returncode == 2, res.stderr
    assert res.stderr.count("\n") == 1
    assert res.stderr.startswith("gazebot: error: gazebot gps train needs the [gps] extra")
    assert "pip install 'gazebot[gps]'" in res.stderr
    assert "Traceback" not in res.stderr


def test_a_missing_module_of_an_extra_is_mapped_by_its_top_level_name():
    assert extra_for("cv2") == "render"
    assert extra_for("sklearn.mixture") == "gps"
    assert extra_for("numpy") is None
    assert extra_for(None) is None


def test_a_command_that_needs_a_whole_extra_names_it_whichever_package_is_missing_first():
    assert extra_for_command(["sim"], "cv2") == "sim"  # [sim] includes [render]
    assert extra_for_command(["render", "video"], "cv2") == "sim"
    assert extra_for_command(["render", "eyes"], "cv2") == "render"
    assert extra_for_command(["gps", "demo"], "mujoco") == "gps"
    assert extra_for_command(["sim"], "gazebot_typo") is None


def test_a_missing_module_of_no_extra_keeps_its_traceback(monkeypatch):
    def handle(args):
        raise ModuleNotFoundError("No module named 'gazebot_typo'", name="gazebot_typo")

    monkeypatch.setattr(ik_command, "handle", handle)
    with pytest.raises(ModuleNotFoundError, match="gazebot_typo"):
        main(["ik", "--target", "1", "0", "0.3"])


def _extras_in_pyproject() -> dict[str, set[str]]:
    tomllib = pytest.importorskip("tomllib", reason="tomllib is in the standard library from 3.11")
    extras = tomllib.loads((REPO / "pyproject.toml").read_text())["project"][
        "optional-dependencies"]
    return {name: {re.split(r"[<>=!\[; ]", r, maxsplit=1)[0].lower() for r in reqs
                   if not r.startswith("gazebot[")}
            for name, reqs in extras.items() if name not in ("all", "test", "lint", "docs")}


def test_the_table_of_extras_agrees_with_pyproject():
    extras = _extras_in_pyproject()
    assert set(EXTRA_OF_MODULE.values()) == set(extras)
    installed = md.packages_distributions()
    for module, extra in EXTRA_OF_MODULE.items():
        if module not in installed:
            continue  # not installed here: its distribution's name cannot be looked up
        dists = {d.lower() for d in installed[module]}
        assert dists & extras[extra], f"{module} ({dists}) is not in the [{extra}] extra"
    mapped = {d.lower() for m in EXTRA_OF_MODULE for d in installed.get(m, ())}
    for extra, dists in extras.items():
        for dist in dists:
            try:
                md.distribution(dist)
            except md.PackageNotFoundError:
                continue  # not installed here: its import name cannot be looked up
            assert dist in mapped, f"{dist} of the [{extra}] extra has no entry in EXTRA_OF_MODULE"


def test_demo_without_mujoco_names_the_sim_extra_not_a_gl_package(tmp_path):
    # Without MUJOCO_GL set, the demo would otherwise probe for a GL back end first.
    env_cleared = "import os\nos.environ.pop('MUJOCO_GL', None)\n"
    res = run_without_extras(env_cleared + "from gazebot.apps.cli import main\n"
                             f"raise SystemExit(main(['demo', '--out', {str(tmp_path)!r}]))\n")
    assert res.returncode == 2, res.stderr
    assert res.stderr.startswith("gazebot: error: gazebot demo needs the [sim] extra")
    assert res.stderr.count("\n") == 1


def test_every_command_of_the_table_exists_and_its_extra_is_declared():
    from gazebot.apps.cli import build_parser, command_name
    from gazebot.apps.cli.extras import EXTRA_OF_COMMAND

    parser = build_parser()
    for words, extra in EXTRA_OF_COMMAND.items():
        assert command_name(parser, words.split()) == f"gazebot {words}"
        assert extra in set(EXTRA_OF_MODULE.values())
