"""Reading the published xlsx layout and reporting (not dropping) oddities."""

from __future__ import annotations

import pytest
from annotation_helpers import GIVER, PHASES, RECEIVER, handover_rows, write_xlsx

from gazebot.apps.annotations import load_annotations, load_handover
from gazebot.core.config import ConfigError


def test_reads_labels_until_the_first_empty_frame_number(tmp_path):
    path = write_xlsx(tmp_path / "volunteer_1_volunteer_2 7.xlsx", handover_rows())
    h = load_handover(path)
    assert h.n_frames == len(PHASES)
    assert h.pair == "volunteer_1_volunteer_2" and h.index == 7
    assert h.receiver_gaze[:3] == ("face", "face", "face")
    assert h.receiver_gaze[9] == "own_hand" and h.giver_gaze[21 - 6] == "other"
    assert h.phase("giver")[2] == "reach" and h.gaze("receiver") == h.receiver_gaze
    assert h.issues == ()


def test_frame_numbers_stored_as_text_are_accepted(tmp_path):
    rows = [[str(r[0]), *r[1:]] for r in handover_rows()]
    h = load_handover(write_xlsx(tmp_path / "a 1.xlsx", rows))
    assert h.n_frames == len(PHASES) and h.issues == ()


def test_stray_spaces_are_normalised_and_reported(tmp_path):
    rows = handover_rows()
    rows[3][1] = " Other Person's  hand "
    h = load_handover(write_xlsx(tmp_path / "a 1.xlsx", rows))
    assert h.giver_gaze[3] == "hand"
    assert len(h.issues) == 1 and "stray spaces" in h.issues[0].message
    assert h.issues[0].row == 5 and h.issues[0].column == "Giver Gaze"


def test_unknown_and_missing_labels_are_kept_as_other_and_reported(tmp_path):
    rows = handover_rows()
    rows[4][3] = "Ceiling"
    rows[5][4] = None
    h = load_handover(write_xlsx(tmp_path / "a 1.xlsx", rows))
    assert h.n_frames == len(PHASES)  # nothing dropped
    assert h.receiver_gaze[4] == "other" and h.receiver_phase[5] == "other"
    messages = sorted(i.message for i in h.issues)
    assert messages[0].startswith("missing label") and messages[1].startswith("unknown label")


def test_stray_cells_right_of_the_table_and_frame_gaps_are_reported(tmp_path):
    rows = handover_rows()
    rows[1].append(" ")
    rows[6][0] = 99
    h = load_handover(write_xlsx(tmp_path / "a 1.xlsx", rows))
    kinds = {i.column for i in h.issues}
    assert kinds == {"beyond column E", "Frame number"}


def test_a_second_handover_in_one_file_is_reported(tmp_path):
    phases = PHASES + PHASES
    rows = handover_rows(GIVER + GIVER, RECEIVER + RECEIVER, phases)
    h = load_handover(write_xlsx(tmp_path / "a 1.xlsx", rows))
    assert {i.message for i in h.issues} == {"phase goes backwards (another handover?)"}


def test_a_wrong_header_is_a_clear_error(tmp_path):
    path = write_xlsx(tmp_path / "a 1.xlsx", handover_rows(), header=["Frame", "Gaze"])
    with pytest.raises(ConfigError, match=r"a 1\.xlsx: field 'header': expected the columns"):
        load_handover(path)


def test_a_broken_file_is_a_clear_error(tmp_path):
    path = tmp_path / "a 1.xlsx"
    path.write_bytes(b"not a zip")
    with pytest.raises(ConfigError, match=r"a 1\.xlsx: field '<file>': expected a readable xlsx"):
        load_handover(path)


def test_folder_loading_sorts_by_pair_and_number_and_caches(synthetic_dir):
    first = load_annotations(synthetic_dir)
    assert [h.path.name for h in first.handovers] == [
        "volunteer_1_volunteer_2 1.xlsx",
        "volunteer_1_volunteer_2 2.xlsx",
        "volunteer_3_volunteer_4 1.xlsx",
        "volunteer_3_volunteer_4 2.xlsx",
    ]
    assert load_annotations(synthetic_dir) is first
    assert load_annotations(synthetic_dir, cache=False) is not first


def test_missing_folder_is_a_clear_error(tmp_path):
    with pytest.raises(FileNotFoundError, match="not found"):
        load_annotations(tmp_path / "nope")
    with pytest.raises(FileNotFoundError, match="no .xlsx"):
        load_annotations(tmp_path)
