"""Malformed configuration gets an error naming the file, the field and what was expected."""

from __future__ import annotations

import pytest
from pydantic import BaseModel, ConfigDict, Field

from gazebot.core.config import ConfigError, load_model


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid")
    rate_hz: float
    name: str = "x"


def _load(tmp_path, text: str) -> ConfigError:
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError) as err:
        load_model(_Model, path)
    assert str(path) in str(err.value)
    return err.value


def test_unknown_field_names_its_line_and_lists_the_known_fields(tmp_path):
    err = _load(tmp_path, "rate_hz: 1\nrat_hz: 2\n")
    assert err.field == "rat_hz" and err.line == 2
    assert str(err).endswith(".yaml:2: rat_hz: unknown key (known: name, rate_hz)")


def test_missing_field_says_it_is_required(tmp_path):
    err = _load(tmp_path, "name: y\n")
    assert err.field == "rate_hz" and "required" in str(err)


def test_wrong_type_names_the_expected_type_and_the_value(tmp_path):
    err = _load(tmp_path, "rate_hz: fast\n")
    assert err.field == "rate_hz" and "a valid number" in str(err) and "'fast'" in str(err)


def test_yaml_syntax_error_names_line_and_column(tmp_path):
    err = _load(tmp_path, "rate_hz: [1, 2\nname: y\n")
    assert (err.line, err.column) == (2, 5)
    assert str(err) == f"{err.source}:2:5: invalid YAML: expected ',' or ']', but got ':'"


def test_cli_reports_a_directory_given_as_a_file_without_a_traceback(tmp_path, capsys):
    from gazebot.apps.cli import main

    assert main(["phases", str(tmp_path)]) == 2
    assert capsys.readouterr().err.startswith("gazebot: error:")


def test_non_utf8_yaml_names_the_file_and_the_offending_byte(tmp_path):
    path = tmp_path / "latin1.yaml"
    path.write_bytes("name: caf\xe9\n".encode("latin-1"))
    with pytest.raises(ConfigError) as err:
        load_model(_Model, path)
    assert str(path) in str(err.value) and "UTF-8" in str(err.value) and "0xe9" in str(err.value)


@pytest.mark.parametrize(
    ("name", "text"),
    [
        ("phases", "transfer_distance_margin: .nan\n"),
        (
            "behavior",
            "segments:\n"
            "  - {phase: reach, at: {after: reach_started, delay: .nan}, target: face}\n",
        ),
    ],
)
def test_nan_and_infinity_in_yaml_are_rejected_with_the_field(tmp_path, name, text):
    from gazebot.core.behaviors import load_behavior
    from gazebot.core.phases import load_phase_config

    path = tmp_path / f"{name}.yaml"
    path.write_text(text)
    loader = load_phase_config if name == "phases" else load_behavior
    with pytest.raises(ConfigError) as err:
        loader(path)
    assert str(path) in str(err.value) and "finite" in str(err.value)


# ---- hostile YAML: bounded memory and a one-line error naming the file ----

BILLION_LAUGHS = "a: &a [x, x, x, x, x, x, x, x, x]\n" + "".join(
    f"{n}: &{n} [*{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}]\n"
    for p, n in zip("abcdefgh", "bcdefghi", strict=True)
)  # under 1 kB; expanded, 9**9 strings


def _loaders():
    from gazebot.apps.controllers.config import load_controllers_config
    from gazebot.apps.render.eye_style import load_eye_style
    from gazebot.apps.sim.scene_config import load_scene
    from gazebot.core.behaviors.registry import load_behavior
    from gazebot.core.kinematics.robot_config import load_robot_config
    from gazebot.core.phases.config import load_phase_config

    return {
        "behavior": load_behavior,
        "robot": load_robot_config,
        "scene": load_scene,
        "phases": load_phase_config,
        "controllers": load_controllers_config,
        "eye style": load_eye_style,
    }


@pytest.mark.parametrize("kind", list(_loaders()))
def test_every_config_loader_refuses_an_alias_bomb_in_bounded_memory(tmp_path, kind):
    import tracemalloc

    path = tmp_path / "bomb.yaml"
    path.write_text(BILLION_LAUGHS)
    tracemalloc.start()
    try:
        with pytest.raises(ConfigError) as err:
            _loaders()[kind](path)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 20e6, peak
    msg = str(err.value)
    assert msg.startswith(f"{path}:2:8: invalid YAML:") and "alias" in msg
    assert len(msg) < 300 and "\n" not in msg


def test_an_anchor_without_alias_still_loads(tmp_path):
    path = tmp_path / "ok.yaml"
    path.write_text("rate_hz: &r 5\n")
    assert load_model(_Model, path).rate_hz == 5


def test_a_file_over_the_size_cap_is_refused_unread(tmp_path):
    from gazebot.core.config import MAX_YAML_BYTES

    path = tmp_path / "big.yaml"
    path.write_text("rate_hz: 1\n" + "#" * MAX_YAML_BYTES + "\n")
    with pytest.raises(ConfigError, match=f"at most {MAX_YAML_BYTES} bytes") as err:
        load_model(_Model, path)
    assert str(err.value).startswith(str(path))


@pytest.mark.parametrize(
    "text", ["[" * 100_000, "a:\n" + "".join(" " * i + "b:\n" for i in range(1, 400))]
)
def test_deep_nesting_is_a_config_error_not_a_recursion_crash(tmp_path, text):
    path = tmp_path / "deep.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError) as err:
        load_model(_Model, path)
    assert str(err.value).startswith(str(path))


class _Item(BaseModel):
    model_config = ConfigDict(extra="forbid")
    kind: str
    size_m: float = 1.0


class _Nested(BaseModel):
    model_config = ConfigDict(extra="forbid")
    name: str = Field(default="x", json_schema_extra={"internal": True})
    items: list[_Item] = []


def test_an_error_deep_in_a_list_names_the_items_line_and_the_field_as_written(tmp_path):
    path = tmp_path / "nested.yaml"
    path.write_text("items:\n  - kind: a\n  - kind: b\n    size_m: big\n")
    with pytest.raises(ConfigError) as err:
        load_model(_Nested, path)
    assert str(err.value).startswith(f"{path}:4: items[1].size_m: expected a valid number")
    assert str(err.value).endswith(", got 'big'")


def test_an_unknown_nested_key_lists_only_the_keys_a_user_may_write(tmp_path):
    path = tmp_path / "nested.yaml"
    path.write_text("items:\n  - kind: a\n    sise_m: 2\n")
    with pytest.raises(ConfigError) as err:
        load_model(_Nested, path)
    assert str(err.value) == f"{path}:3: items[0].sise_m: unknown key (known: kind, size_m)"
    path.write_text("nmae: y\n")
    with pytest.raises(ConfigError) as err:
        load_model(_Nested, path)
    assert str(err.value).endswith("nmae: unknown key (known: items)")  # not the internal name


def test_a_missing_key_names_the_line_of_its_mapping(tmp_path):
    path = tmp_path / "nested.yaml"
    path.write_text("items:\n  - kind: a\n  - size_m: 2\n")
    with pytest.raises(ConfigError) as err:
        load_model(_Nested, path)
    assert str(err.value) == (
        f"{path}:3: items[1].kind: expected a value (the field is required)"
    )
