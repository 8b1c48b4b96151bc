"""Malformed configuration gets an error naming the file, the field and what was expected."""

from __future__ import annotations

import pytest
from pydantic import BaseModel, ConfigDict

from gazebot.config import ConfigError, load_model


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


def test_unknown_field_lists_the_known_fields(tmp_path):
    err = _load(tmp_path, "rate_hz: 1\nrat_hz: 2\n")
    assert err.field == "rat_hz" and "known fields: name, rate_hz" in str(err)


def test_missing_field_says_it_is_required(tmp_path):
    err = _load(tmp_path, "name: y\n")
    assert err.field == "rate_hz" and "required" in str(err)


def test_wrong_type_names_the_expected_type_and_the_value(tmp_path):
    err = _load(tmp_path, "rate_hz: fast\n")
    assert err.field == "rate_hz" and "a valid number" in str(err) and "'fast'" in str(err)


def test_yaml_syntax_error_names_line_and_column(tmp_path):
    err = _load(tmp_path, "rate_hz: [1, 2\nname: y\n")
    assert "line" in err.field and "column" in err.field


def test_cli_reports_a_directory_given_as_a_file_without_a_traceback(tmp_path, capsys):
    from gazebot.cli import main

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
    from gazebot.behaviors import load_behavior
    from gazebot.phases import load_phase_config

    path = tmp_path / f"{name}.yaml"
    path.write_text(text)
    loader = load_phase_config if name == "phases" else load_behavior
    with pytest.raises(ConfigError) as err:
        loader(path)
    assert str(path) in str(err.value) and "finite" in str(err.value)
