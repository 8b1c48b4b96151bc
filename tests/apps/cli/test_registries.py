"""One registry per extension kind: CLI choices, config validation and the README's tables come
from it."""

from __future__ import annotations

import pytest

from gazebot.apps.cli.registries import registries
from gazebot.apps.controllers import CONTROLLERS, make_controller
from gazebot.core.config import ConfigError
from gazebot.core.phases import PhaseConfig, load_phase_config
from gazebot.core.phases.methods import PHASE_METHODS
from gazebot.core.registry import Registry
from tests.documentation import documentation_text


def test_every_extension_kind_has_one_registry_with_its_builtins():
    regs = registries()
    assert set(regs) == {"robots", "behaviors", "phase methods", "controllers", "eye styles",
                         "scenes"}
    assert {"sawyer", "jaco2"} <= set(regs["robots"].names())
    assert "face-hand-face" in regs["behaviors"].names()
    assert regs["phase methods"].names()[:3] == ("gazebot", "seed-7.2.5", "seed-4.4.3")
    assert regs["controllers"].names()[:4] == ("pv", "mcj", "mce", "stl")
    assert "cartoon" in regs["eye styles"].names() and "default" in regs["scenes"].names()
    for reg in regs.values():
        with pytest.raises(ValueError, match=r"unknown .* 'nope' \(known: "):
            reg.check("nope")


def test_a_name_registers_once_unless_replaced_and_loads_lazily():
    reg: Registry[object] = Registry("thing")
    reg.register("a", "collections:OrderedDict", "lazy")
    with pytest.raises(ValueError, match="already registered"):
        reg.register("a", dict)
    reg.register("a", dict, replace=True)
    assert reg.make("a", x=1) == {"x": 1}
    reg.unregister("a")
    assert reg.names() == ()


def test_an_unknown_controller_or_phase_method_is_one_clear_error(tmp_path):
    with pytest.raises(ValueError, match=r"unknown controller 'gps2' \(known: pv, mcj"):
        make_controller("gps2")
    path = tmp_path / "phases.yaml"
    path.write_text("method: nope\n", encoding="utf-8")
    with pytest.raises(ConfigError, match="method"):
        load_phase_config(path)
    assert PhaseConfig(method="seed-4.4.3").method == "seed-4.4.3"


@pytest.mark.parametrize("registry", [CONTROLLERS, PHASE_METHODS], ids=lambda r: r.kind)
def test_the_documented_table_is_the_registrys(registry):
    assert registry.table(builtin_only=True) in documentation_text()


def _fake_entry_points(monkeypatch, *eps):
    import importlib.metadata as md

    def entry_points(group=None):
        return [md.EntryPoint(name, value, g) for name, value, g in eps if g == group]

    monkeypatch.setattr("gazebot.core.registry.importlib.metadata.entry_points", entry_points)


def test_installed_extensions_are_read_from_entry_points_on_first_read_and_load_lazily(
    monkeypatch,
):
    _fake_entry_points(monkeypatch, ("ordered", "collections:OrderedDict", "demo.things"),
                       ("other", "json:dumps", "demo.elsewhere"))
    reg: Registry[object] = Registry("thing", group="demo.things")
    reg.register("builtin", dict, "a built-in")
    assert reg.names() == ("builtin", "ordered")  # other groups are not this registry's
    assert reg.entry("ordered").factory == "collections:OrderedDict"  # not imported yet
    assert reg.make("ordered", a=1) == {"a": 1}
    assert "installed extension" in reg.table() and "ordered" not in reg.table(builtin_only=True)


def test_an_entry_point_cannot_take_a_registered_name_and_a_broken_one_is_a_clear_error(
    monkeypatch,
):
    _fake_entry_points(monkeypatch, ("builtin", "json:dumps", "demo.things"),
                       ("broken", "no_such_module_xyz:Thing", "demo.things"))
    reg: Registry[object] = Registry("thing", group="demo.things")
    reg.register("builtin", dict)
    with pytest.warns(UserWarning, match="'builtin' of entry point 'json:dumps' ignored"):
        assert reg.names() == ("builtin", "broken")
    assert reg.make("builtin") == {}
    with pytest.raises(ValueError, match=r"thing 'broken': cannot load 'no_such_module_xyz:Thing'"):
        reg.make("broken")
    _fake_entry_points(monkeypatch)
    reg.reload_entry_points()
    assert reg.names() == ("builtin",)
