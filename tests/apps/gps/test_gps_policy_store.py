"""A policy folder that does not hold what its meta.json says is one clear error at load time,
not a broadcasting failure in the middle of a rollout or a demo."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

pytest.importorskip("jax", reason="gazebot gps needs the optional extra gazebot[gps]")
pytest.importorskip("sklearn", reason="gazebot gps needs the optional extra gazebot[gps]")

from gazebot.apps.gps.policy_store import load  # noqa: E402
from gazebot.core.config import ConfigError  # noqa: E402


def _copy(trained, tmp_path):
    out = tmp_path / "policy"
    shutil.copytree(trained, out)
    return out


def test_a_policy_loads_with_the_state_it_was_trained_for(trained):
    assert load(trained).kind.value == "reduced"


def test_a_state_in_meta_json_that_the_network_does_not_fit_names_the_array(trained, tmp_path):
    d = _copy(trained, tmp_path)
    meta = json.loads((d / "meta.json").read_text(encoding="utf-8"))
    meta["state"] = "relative"
    (d / "meta.json").write_text(json.dumps(meta), encoding="utf-8")
    with pytest.raises(ConfigError, match=r"policy\.npz: field 'w1': expected shape \(39, "):
        load(d)


def test_non_finite_weights_are_refused(trained, tmp_path):
    d = _copy(trained, tmp_path)
    with np.load(d / "policy.npz") as z:
        arrays = {k: z[k] for k in z.files}
    arrays["w2"][0, 0] = np.nan
    np.savez(d / "policy.npz", **arrays)
    with pytest.raises(ConfigError, match="field 'w2': expected finite floats"):
        load(d)


def test_a_policy_file_that_is_not_an_archive_is_named(trained, tmp_path):
    d = _copy(trained, tmp_path)
    (d / "policy.npz").write_bytes(b"PK\x03\x04 not really a zip")
    with pytest.raises(ConfigError, match=r"policy\.npz: field '<file>'"):
        load(d)
