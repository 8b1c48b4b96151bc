from __future__ import annotations

import re

import pytest

from gazebot.core.config import ConfigError
from gazebot.core.phases import PhaseConfig, default_phase_config_path, durations, load_phase_config


def test_defaults_are_the_seed_transfer_rule():
    c = PhaseConfig()
    assert c.transfer_distance_margin == pytest.approx(0.20)
    assert c.transfer_speed_max == pytest.approx(0.15)


def test_seed_text_states_the_default_thresholds(seed_text):
    text = " ".join(seed_text.split())
    m = re.search(r"within (\d+)\s?cm of the minimum distance.*?less than (\d+)\s?cm/s", text)
    assert m, "seed section 7.2.5 rule not found"
    c = PhaseConfig()
    assert int(m.group(1)) / 100 == pytest.approx(c.transfer_distance_margin)
    assert int(m.group(2)) / 100 == pytest.approx(c.transfer_speed_max)


def test_shipped_yaml_equals_the_defaults():
    assert default_phase_config_path().is_file()
    assert load_phase_config(None) == PhaseConfig()


def test_yaml_override_is_loaded(tmp_path):
    f = tmp_path / "p.yaml"
    f.write_text("transfer_speed_max: 0.1\ntransfer_exit_speed: 0.12\n")
    c = load_phase_config(f)
    assert c.transfer_speed_max == 0.1 and c.transfer_exit_speed == 0.12
    assert c.transfer_distance_margin == 0.20  # untouched fields keep the defaults


@pytest.mark.parametrize(
    ("text", "field"),
    [
        ("transfer_speed_max: fast\n", "transfer_speed_max"),
        ("transfer_speed_max: -0.1\n", "transfer_speed_max"),
        ("transfer_speeed_max: 0.1\n", "transfer_speeed_max"),
        ("transfer_speed_max: 0.3\n", "<root>"),  # above the exit speed: no hysteresis
        ("load_share_robot: 1.5\n", "load_share_robot"),
        ("rest_speed: 0.2\n", "<root>"),  # a resting hand faster than a reach onset
        ("method: seed-9\n", "method"),
    ],
)
def test_bad_yaml_names_the_field(tmp_path, text, field):
    f = tmp_path / "bad.yaml"
    f.write_text(text)
    with pytest.raises(ConfigError) as exc:
        load_phase_config(f)
    assert exc.value.field == field
    assert str(f) in str(exc.value)


def test_shipped_yaml_sets_every_field_with_a_unit_and_a_reason():
    lines = default_phase_config_path().read_text().splitlines()
    for name in PhaseConfig.model_fields:
        row = next((ln for ln in lines if ln.startswith(f"{name}:")), None)
        assert row is not None, f"{name} missing from configs/phases.yaml"
        if name == "method":
            continue
        comment = row.split("#", 1)[1].strip() if "#" in row else ""
        unit = comment.split(",")[0].split()[0] if comment else ""
        assert unit in {"m", "s", "m/s", "Hz", "1", "N"}, f"{name}: no unit in {comment!r}"
        assert len(comment) > 12, f"{name}: no reason given"


@pytest.mark.parametrize("method", ["gazebot", "seed-7.2.5", "seed-4.4.3"])
def test_method_is_selectable_in_yaml(tmp_path, method):
    f = tmp_path / "m.yaml"
    f.write_text(f"method: {method}\n")
    assert load_phase_config(f).method == method


def test_missing_file_is_a_config_error(tmp_path):
    with pytest.raises(ConfigError):
        load_phase_config(tmp_path / "nope.yaml")


def test_typical_durations_match_the_human_annotations(annotations_dir):
    """The typical phase durations are the giver's means in the published annotations
    (288 handovers at 8 fps; seed section 6.2)."""
    import openpyxl  # a required dependency: its absence is a failure, not a skip
    counts: dict[str, list[float]] = {"Reach": [], "Transfer": [], "Retreat": []}
    files = sorted(annotations_dir.glob("*/*.xlsx"))
    assert len(files) == 288
    for f in files:
        sheet = openpyxl.load_workbook(f, read_only=True).active
        labels = []
        for row in list(sheet.iter_rows(values_only=True))[1:]:
            if row[0] is None:
                break  # rows end at the first empty frame number
            labels.append(str(row[2]).strip() if row[2] is not None else "")
        for k, v in counts.items():
            v.append(labels.count(k) / 8.0)
    mean = {k: sum(v) / len(v) for k, v in counts.items()}
    assert mean["Reach"] == pytest.approx(durations.REACH_S, abs=0.05)
    assert mean["Transfer"] == pytest.approx(durations.TRANSFER_S, abs=0.02)
    assert mean["Retreat"] == pytest.approx(durations.RETREAT_S, abs=0.02)


def test_typical_durations_are_not_a_phase_setting(tmp_path):
    # One source (gazebot.core.phases.durations) for the detector and the behaviors' fallback: a
    # YAML trying to set one is refused, naming the field.
    f = tmp_path / "p.yaml"
    f.write_text("reach_duration: 0.8\n")
    with pytest.raises(ConfigError, match="reach_duration"):
        load_phase_config(f)
