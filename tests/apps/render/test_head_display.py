"""The head screen's eyes between and without engine updates (``EyeAnimator``), and the screen
drawing them headless."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from gazebot.apps.render.head_display import EyeAnimator, EyeAnimatorConfig, status_text


def state(yaw=0.3, pitch=-0.1, blink=0.0, distance=1.2):
    return SimpleNamespace(yaw=yaw, pitch=pitch, blink=blink, distance=distance)


def test_live_eyes_follow_the_engine_with_only_a_small_drift():
    anim = EyeAnimator(EyeAnimatorConfig(drift_deg=0.4), seed=1)
    poses = [anim.update(i / 60, state(), age=0.01) for i in range(600)]
    assert all(p.state == "live" and p.distance == 1.2 and p.blink == 0.0 for p in poses)
    yaw = np.array([p.yaw for p in poses])
    assert np.max(np.abs(yaw - 0.3)) < math.radians(2.0)  # a drift, not a gaze shift
    assert np.std(yaw) > math.radians(0.05)  # but never perfectly still


def test_the_engines_blink_is_shown_as_sent():
    anim = EyeAnimator()
    assert anim.update(0.0, state(blink=0.7), age=0.0).blink == pytest.approx(0.7)


def test_silence_eases_to_neutral_says_so_blinks_on_its_own_and_recovers():
    cfg = EyeAnimatorConfig(silent_after=0.5, neutral_s=0.4, drift_deg=0.0)
    anim = EyeAnimator(cfg, seed=2)
    anim.update(0.0, state(yaw=0.4, pitch=0.2), age=0.0)
    silent = [anim.update(0.6 + i / 60, state(yaw=0.4, pitch=0.2), age=0.6 + i / 60)
              for i in range(60 * 20)]
    assert all(p.state == "silent" and p.distance is None for p in silent)
    assert 0.0 < silent[5].yaw < 0.4  # easing, not jumping
    settled = [p for i, p in enumerate(silent) if i / 60 >= cfg.neutral_s]
    assert all(p.yaw == 0.0 and p.pitch == 0.0 for p in settled)
    blinks = sum(1 for a, b in zip(silent, silent[1:], strict=False) if a.blink == 0 < b.blink)
    assert 3 <= blinks <= 12  # its own spontaneous blinks, ~17 a minute over 20 s
    back = anim.update(30.0, state(yaw=-0.2), age=0.01)
    assert back.state == "live" and back.yaw == pytest.approx(-0.2)


def test_no_eye_state_yet_is_waiting_with_neutral_eyes():
    anim = EyeAnimator(EyeAnimatorConfig(drift_deg=0.0))
    pose = anim.update(1.0, None, math.inf)
    assert pose.state == "waiting" and (pose.yaw, pose.pitch) == (0.0, 0.0)
    assert "waiting for the engine" in status_text("sawyer", "gazebot/sim/eyes", pose, math.inf)
    silent = SimpleNamespace(state="silent")
    assert "engine silent for 2.5 s" in status_text("sawyer", "k", silent, 2.5)


@pytest.mark.parametrize("bad", [{"silent_after": 0.0}, {"neutral_s": math.nan},
                                 {"drift_deg": -1.0}])
def test_bad_animator_config_is_a_clear_error(bad):
    with pytest.raises(ValueError, match=next(iter(bad))):
        EyeAnimatorConfig(**bad)


def test_head_screen_draws_the_renderers_eyes_and_a_status_line_headless():
    from gazebot.apps.render import EyeRenderer
    from gazebot.apps.render.head_display import EyePose, HeadScreen

    renderer = EyeRenderer.for_robot("jaco2")
    screen = HeadScreen(renderer)
    try:
        pose = EyePose(0.3, 0.0, 0.0, None, "live")
        screen.show(pose, "jaco2 | k | engine live")
        img = screen.image()
        want = renderer.render(0.3, 0.0)
        assert img.shape == want.shape
        h = want.shape[0]
        # the eyes are the renderer's; only the status line at the bottom differs
        np.testing.assert_array_equal(img[: h - h // 10], want[: h - h // 10])
        assert np.any(img[h - h // 10 :] != want[h - h // 10 :])
        assert not screen.closed()
    finally:
        screen.close()
