"""Through a whole face-hand-face handover, on both robots: the observer camera keeps the head
display (the eyes) in view, and the gaze shifts happen in the phases the behavior says."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from gazebot.apps.sim.record import record_handover
from gazebot.apps.sim.scene import OBSERVER

pytestmark = pytest.mark.slow

W, H = 320, 240
SAMPLE_EVERY = 12  # control ticks (120 Hz): ten looks per simulated second
HEAD_TURNED_S = 0.5
GEOM = int(mujoco.mjtObj.mjOBJ_GEOM)


def _display_pixels(renderer: mujoco.Renderer, display: int, alone: bool) -> int:
    """Pixels of the ``display`` geom in the segmentation image; ``alone``: with every other geom
    moved out of sight, i.e. how many it would cover if nothing were in front of it."""
    if alone:
        scn = renderer.scene
        for i in range(scn.ngeom):
            g = scn.geoms[i]
            if not (g.objtype == GEOM and g.objid == display):
                g.pos[2] += 1000.0
    seg = renderer.render()
    return int(np.count_nonzero((seg[..., 0] == display) & (seg[..., 1] == GEOM)))


def _run(robot: str):
    samples = []
    state = {}

    def look(sim, tick) -> None:
        if "renderer" not in state:
            state["renderer"] = mujoco.Renderer(sim.model, H, W)
            state["renderer"].enable_segmentation_rendering()
        state["n"] = state.get("n", -1) + 1
        if state["n"] % SAMPLE_EVERY:
            return
        m, d, r = sim.model, sim.data, state["renderer"]
        display = m.geom("display").id
        r.update_scene(d, OBSERVER)
        seen = _display_pixels(r, display, alone=False)
        r.update_scene(d, OBSERVER)
        full = _display_pixels(r, display, alone=True)
        site = d.site(sim.robot.gaze_site)
        to_cam = d.cam(OBSERVER).xpos - site.xpos
        facing = float(site.xmat.reshape(3, 3)[:, 0] @ to_cam / np.linalg.norm(to_cam))
        samples.append((tick.t, tick.phase, seen, full, facing))
        state.setdefault("vergence", []).append(
            (sim.eyes[3], float(np.linalg.norm(tick.target_point - site.xpos)))
        )

    rec = record_handover(robot, "face-hand-face", "default", None, progress=False, on_tick=look)
    state["renderer"].close()
    return rec, samples, state["vergence"]


@pytest.fixture(scope="module", params=["sawyer", "jaco2"])
def handover(request):
    rec, samples, vergence = _run(request.param)
    assert rec.completed
    return request.param, rec, samples, vergence


def test_observer_sees_the_eyes_in_every_phase_of_the_handover(handover):
    robot, _, samples, _ = handover
    assert {s[1] for s in samples} >= {"idle", "reach", "transfer", "retreat", "done"}
    # The head starts facing straight ahead (+x) and turns to the giver's face in its first
    # half second; the Jaco-2's side view sees the screen edge-on before that turn.
    for t, phase, seen, full, facing in [s for s in samples if s[0] >= HEAD_TURNED_S]:
        where = f"{robot} at t={t:.2f} s ({phase})"
        # Big enough to read the eyes, hardly covered by the arm, the object or the giver...
        assert full >= 100, f"display only {full} px at {W}x{H}: {where}"
        assert seen >= 0.9 * full, f"display {1 - seen / full:.0%} hidden: {where}"
        # ...and its screen side turned to the camera (within 70 deg), not its back or edge.
        assert facing > math.cos(math.radians(70)), f"display turned away: {where}"


def _spans(ticks, target):
    """(phase at the tick the target switched to ``target``, for each switch)."""
    return [
        (b.phase, b.t)
        for a, b in zip(ticks, ticks[1:], strict=False)
        if b.target == target and a.target != target
    ]


def test_face_hand_face_looks_at_the_hand_during_the_reach(handover):
    robot, rec, _, _ = handover
    to_hand = _spans(rec.ticks, "hand")
    assert len(to_hand) == 1, f"{robot}: {to_hand}"
    assert to_hand[0][0] == "reach", f"{robot}: face->hand at {to_hand[0]}"


def test_face_hand_face_returns_to_the_face_before_the_retreat_ends(handover):
    robot, rec, _, _ = handover
    to_face = _spans(rec.ticks, "face")
    assert len(to_face) == 1, f"{robot}: {to_face}"
    assert to_face[0][0] == "retreat", f"{robot}: hand->face at {to_face[0]}"


def test_eyes_converge_at_the_distance_of_the_gaze_target(handover):
    robot, _, _, vergence = handover
    given = np.array([v[0] for v in vergence], dtype=float)
    want = np.array([v[1] for v in vergence])
    # The distance from the display to the target the engine chose, every sampled tick.
    np.testing.assert_allclose(given, want, rtol=1e-9, err_msg=robot)
    assert 0.3 < want.min() and want.max() < 3.0
