"""A tiny GPS problem trained once per session (0.5-1 s trials, four iterations, a coarse
grid): the policy the CLI tests evaluate and the handover demo tests drive the Panda with."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from gazebot.apps.gps.config import default_gps_path


@pytest.fixture(scope="session")
def tiny_config(tmp_path_factory) -> Path:
    data = yaml.safe_load(default_gps_path().read_text(encoding="utf-8"))
    data["scene"]["trial_s"] = 1.0
    data["shell"]["azimuth_step_deg"] = 45.0  # 3 azimuths
    data["gps"].update(samples=3, policy_steps=200, batch=64, gmm_clusters=2,
                       inner_iterations=2)
    path = tmp_path_factory.mktemp("cfg") / "gps.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return path


@pytest.fixture(scope="session")
def trained(tiny_config, tmp_path_factory) -> Path:
    pytest.importorskip("jax", reason="gazebot gps needs the optional extra gazebot[gps]")
    pytest.importorskip("sklearn", reason="gazebot gps needs the optional extra gazebot[gps]")
    from gazebot.apps.cli import main

    out = tmp_path_factory.mktemp("policy")
    assert main(["gps", "train", "--controllers", "8", "--trainer", "static", "--state",
                 "reduced", "--iterations", "4", "--config", str(tiny_config), "--out",
                 str(out), "--quiet"]) == 0
    return out
