"""The engine's speed-ups change no command: on both robots, three behaviors, a clean handover and
damaged ones (NaN points and times, out-of-order frames, an implausible point, silent ticks, a
tracking loss) with robot events (a robot-first reach, grasp, retreat, a moving arm joint under
Sawyer's head), the loop's full command stream equals the recorded one
(tests/core/data/engine_stream.npz, written by tests/core/engine_stream.py, which lists the
deliberate output changes it was re-recorded for): every label and event exactly, every number
to float round-off (1e-12)."""

from __future__ import annotations

import numpy as np
import pytest

from tests.core.engine_stream import REFERENCE, run, scenarios

ROUND_OFF = 1e-12


@pytest.fixture(scope="module")
def reference() -> dict[str, np.ndarray]:
    with np.load(REFERENCE) as data:
        return {k: data[k] for k in data.files}


def test_the_reference_holds_every_scenario(reference):
    names = [str(reference[f"{i}_name"]) for i in range(len(scenarios()))]
    assert names == scenarios()


@pytest.mark.parametrize("index", range(len(scenarios())), ids=scenarios())
def test_command_stream_equals_the_recorded_one(reference, index):
    got = run(scenarios()[index])
    want_labels = reference[f"{index}_labels"]
    assert got.labels.shape == want_labels.shape
    bad = np.flatnonzero(got.labels != want_labels)
    assert bad.size == 0, f"tick {bad[0]}: {got.labels[bad[0]]!r} != {want_labels[bad[0]]!r}"
    np.testing.assert_allclose(got.floats, reference[f"{index}_floats"], rtol=0, atol=ROUND_OFF)
    np.testing.assert_array_equal(got.event_labels, reference[f"{index}_event_labels"])
    np.testing.assert_allclose(got.event_floats, reference[f"{index}_event_floats"], rtol=0,
                               atol=ROUND_OFF)
