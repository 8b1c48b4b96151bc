"""The behavior YAML format, the registry and their error messages."""

from __future__ import annotations

import json
import textwrap

import pytest

from gazebot.core.behaviors import (
    AtEvent,
    AtFraction,
    AtNever,
    BehaviorSpec,
    behavior_path,
    list_behaviors,
    load_behavior,
    seed_behaviors,
)
from gazebot.core.config import ConfigError
from gazebot.core.types import EventKind

BUILTINS = {
    "face",
    "hand",
    "short-face-hand",
    "long-face-hand",
    "hand-face",
    "hand-face-as-studied",
    "face-hand-face",
    "face-hand-face-as-studied",
    "human-receiver",
}


def write(tmp_path, name: str, text: str):
    path = tmp_path / f"{name}.yaml"
    path.write_text(textwrap.dedent(text), encoding="utf-8")
    return path


def test_every_builtin_behavior_is_listed_and_loads():
    names = {info.name for info in list_behaviors([])}
    assert BUILTINS <= names
    for name in BUILTINS:
        spec = load_behavior(name)
        assert spec.name == name and spec.description


def test_the_seed_behaviors_are_the_builtins_whose_source_is_the_seed():
    # Every test that runs "the seed's behaviors" takes them from seed_behaviors(); here they are
    # pinned: the eight of chapter 6, not the data-driven human-receiver.
    assert set(seed_behaviors()) == BUILTINS - {"human-receiver"}
    assert all(load_behavior(n).source.startswith("seed ") for n in seed_behaviors())


def test_at_accepts_fraction_mapping_event_offset_never_and_parameters(tmp_path):
    path = write(
        tmp_path,
        "mixed",
        """
        parameters:
          later: {after: robot_retreat_started, delay: 0.3}
        segments:
          - {phase: reach, at: 0.25, target: face}
          - {phase: reach, at: {fraction: 0.5}, target: hand}
          - {phase: transfer, at: never, target: object}
          - {phase: retreat, at: $later, target: my_shelf}
          - {phase: retreat, target: rest}
        """,
    )
    spec = load_behavior(path)
    ats = [spec.resolve(s) for s in spec.segments]
    assert ats[0] == AtFraction(fraction=0.25) and ats[1] == AtFraction(fraction=0.5)
    assert isinstance(ats[2], AtNever)
    assert ats[3] == AtEvent(after=EventKind.ROBOT_RETREAT_STARTED, delay=0.3)
    assert ats[4] == AtFraction(fraction=0.0)  # default: the phase start
    assert spec.before == "face" and spec.after == "face"
    assert "my_shelf" in spec.targets()


@pytest.mark.parametrize(
    ("body", "field"),
    [
        ("segments:\n  - {phase: reach, at: 1.5, target: face}\n", "segments[0].at"),
        (
            "segments:\n  - {phase: reach, at: {after: lunch}, target: face}\n",
            "segments[0].at.after",
        ),
        ("segments:\n  - {phase: reach, at: 0.1, target: 'Face!'}\n", "segments[0].target"),
        ("segments:\n  - {phase: idle, at: 0.1, target: face}\n", "segments[0].phase"),
        ("segments:\n  - {phase: reach, at: $nope, target: face}\n", "segments[0].at"),
        ("segments: []\n", "<root>"),
        ("segments:\n  - {phase: reach, target: face, when: 2}\n", "segments[0].when"),
        ("before: 3\nsegments:\n  - {phase: reach, target: face}\n", "before"),
    ],
)
def test_malformed_behaviors_name_file_and_field(tmp_path, body, field):
    path = write(tmp_path, "bad", body)
    with pytest.raises(ConfigError) as err:
        load_behavior(path)
    assert err.value.source == str(path)
    assert err.value.field == field


def test_yaml_syntax_error_is_a_config_error(tmp_path):
    path = write(tmp_path, "broken", "segments: [\n")
    with pytest.raises(ConfigError, match="valid YAML"):
        load_behavior(path)


def test_unknown_behavior_lists_the_available_ones():
    with pytest.raises(FileNotFoundError, match="face-hand-face"):
        load_behavior("no-such-behavior")


def test_user_folder_adds_and_shadows_behaviors(tmp_path):
    write(tmp_path, "glance", "segments:\n  - {phase: reach, at: 0.3, target: hand}\n")
    write(tmp_path, "face", "description: my face\nsegments:\n  - {phase: reach, target: face}\n")
    infos = {i.name: i for i in list_behaviors([tmp_path])}
    assert not infos["glance"].builtin and infos["face"].description == "my face"
    assert behavior_path("glance", [tmp_path]) == tmp_path / "glance.yaml"
    assert load_behavior("glance", [tmp_path]).segments[0].target == "hand"


def test_user_folder_from_the_environment(tmp_path, monkeypatch):
    write(tmp_path, "glance", "segments:\n  - {phase: reach, at: 0.3, target: hand}\n")
    monkeypatch.setenv("GAZEBOT_BEHAVIORS_PATH", str(tmp_path))
    assert load_behavior("glance").name == "glance"


def test_a_variant_may_only_change_known_parameters(tmp_path):
    write(tmp_path, "v1", "extends: face-hand-face\nparameters: {reach_hand: 0.25}\n")
    spec = load_behavior("v1", [tmp_path])
    assert spec.parameters["reach_hand"] == AtFraction(fraction=0.25)
    assert spec.segments == load_behavior("face-hand-face").segments
    write(tmp_path, "v1b", "extends: hand-face\nparameters: {retreat_face: 0.5}\n")
    assert isinstance(load_behavior("v1b", [tmp_path]).parameters["transfer_face"], AtNever)
    write(tmp_path, "v2", "extends: face-hand-face\nparameters: {speed: 0.25}\n")
    with pytest.raises(ConfigError) as err:
        load_behavior("v2", [tmp_path])
    assert err.value.field == "parameters.speed"
    write(tmp_path, "v3", "extends: face-hand-face\nsegments: []\n")
    with pytest.raises(ConfigError, match="variant"):
        load_behavior("v3", [tmp_path])
    write(tmp_path, "v4", "extends: v5\n")
    write(tmp_path, "v5", "extends: v4\n")
    with pytest.raises(ConfigError, match="cycles"):
        load_behavior("v4", [tmp_path])


def test_with_parameters_builds_a_variant_in_code():
    base = load_behavior("face-hand-face")
    early = base.with_parameters(reach_hand=0.2)
    assert early.parameters["reach_hand"] == AtFraction(fraction=0.2)
    with pytest.raises(ValueError, match="unknown parameters"):
        base.with_parameters(nope=0.1)


def test_spec_round_trips_through_json():
    spec = load_behavior("human-receiver")
    again = BehaviorSpec.model_validate(json.loads(json.dumps(spec.model_dump(mode="json"))))
    assert again == spec
