"""`gazebot gps train --add-controllers 4 --from DIR`: the seed's 12-controller run as the
8-controller run with four local controllers added ("adding four additional local
controllers"), its controllers, policy and BADMM state kept."""

from __future__ import annotations

import json

import numpy as np
import pytest

from gazebot.apps.cli import main

pytest.importorskip("jax", reason="gazebot gps needs the optional extra gazebot[gps]")
pytest.importorskip("sklearn", reason="gazebot gps needs the optional extra gazebot[gps]")


def test_a_run_saves_what_continuing_it_needs(trained):
    from gazebot.apps.gps.policy_store import load_checkpoint

    prev, cfg = load_checkpoint(trained)
    assert len(prev.state.controllers) == 8 and prev.state.lam.shape[0] == 8
    assert len(prev.state.log) == 4 and len(prev.buffer) == min(4, cfg.gps.prior_iterations)
    assert prev.rng_state is not None


def test_continuing_keeps_the_eight_controllers_and_the_policy_and_adds_four_fresh_ones(trained):
    from gazebot.apps.gps.badmm import continue_training
    from gazebot.apps.gps.policy_store import load_checkpoint
    from gazebot.apps.gps.shell import training_targets

    prev, cfg = load_checkpoint(trained)
    twelve = training_targets(cfg.shell, 12)
    res = continue_training(cfg, prev, twelve[8:], iterations=0)
    st = res.state
    assert len(st.controllers) == 12 and st.lam.shape[0] == 12 and st.nu.shape[0] == 12
    for old, kept in zip(prev.state.controllers, st.controllers[:8], strict=True):
        assert np.array_equal(old.K, kept.K) and np.array_equal(old.k, kept.k)
    assert np.array_equal(st.lam[:8], prev.state.lam) and np.array_equal(st.nu[:8], prev.state.nu)
    assert not st.lam[8:].any() and np.all(st.nu[8:] == cfg.gps.nu_init)
    assert st.policy is prev.policy
    assert np.allclose(res.targets, twelve)
    # The new controllers start as a fresh run's do: the initial PD law.
    assert not np.array_equal(st.controllers[8].K, prev.state.controllers[0].K)


def test_train_add_controllers_continues_the_run_and_writes_twelve(trained, tmp_path, capsys):
    out = tmp_path / "twelve"
    assert main(["gps", "train", "--add-controllers", "4", "--from", str(trained),
                 "--iterations", "1", "--out", str(out), "--quiet"]) == 0
    meta = json.loads((out / "meta.json").read_text())
    before = json.loads((trained / "meta.json").read_text())
    assert meta["controllers"] == 12
    assert meta["targets_m"][:8] == before["targets_m"]
    assert len(meta["log"]) == 5 and meta["log"][:4] == before["log"]
    assert meta["log"][4]["iteration"] == 4
    assert (meta["trainer"], meta["state"]) == (before["trainer"], before["state"])
    assert (out / "state.npz").is_file()


@pytest.mark.parametrize(
    "extra, message",
    [
        (["--add-controllers", "4"], "--add-controllers and --from go together"),
        (["--add-controllers", "4", "--from", "{run}", "--state", "full"],
         "--state full: the run in"),
        (["--add-controllers", "4", "--from", "{run}", "--controllers", "12"],
         "--controllers does not go with --from"),
    ],
)
def test_add_controllers_misuse_is_a_usage_error(trained, tmp_path, capsys, extra, message):
    argv = ["gps", "train", "--out", str(tmp_path / "o"), "--quiet",
            *[a.format(run=trained) for a in extra]]
    assert main(argv) == 2
    assert message in capsys.readouterr().err


def test_a_run_without_its_state_is_named(trained, tmp_path, capsys):
    import shutil

    old = tmp_path / "old"
    shutil.copytree(trained, old)
    (old / "state.npz").unlink()
    assert main(["gps", "train", "--add-controllers", "4", "--from", str(old), "--out",
                 str(tmp_path / "o"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "state.npz" in err and "retrain" in err
