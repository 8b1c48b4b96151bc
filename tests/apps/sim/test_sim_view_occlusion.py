"""The Jaco-2's head screen is seen, not hidden behind the arm, by the observer camera of the
seed's 6.3 study (robot-initiated scene, head-only gaze): measured by rays from the camera to a
grid of points on the screen's face, at every 0.1 s of whole handovers."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from gazebot.apps.sim.record import record_handover
from gazebot.apps.sim.scene import DISPLAY_GEOM, OBSERVER
from gazebot.core.kinematics.robot_config import with_gaze_mode


def screen_seen(model, data, n: int = 5) -> tuple[float, float]:
    """(share of an n x n grid on the screen's face that a ray from the observer camera reaches
    first, cosine between the screen's normal and the direction to the camera)."""
    g = model.geom(DISPLAY_GEOM).id
    cam = data.cam_xpos[model.camera(OBSERVER).id]
    rot = data.geom_xmat[g].reshape(3, 3)
    size = model.geom_size[g]
    normal = rot[:, 0]  # the +x face shows the eyes
    face = data.geom_xpos[g] + normal * size[0]
    hit = np.zeros(1, np.int32)
    seen = 0
    for a in np.linspace(-0.8, 0.8, n):
        for b in np.linspace(-0.8, 0.8, n):
            p = face + rot[:, 1] * size[1] * a + rot[:, 2] * size[2] * b
            ray = (p - cam) / np.linalg.norm(p - cam)
            if normal @ ray < 0:  # the face turned toward the camera
                mujoco.mj_ray(model, data, cam, ray, None, 1, -1, hit)
                seen += int(hit[0] == g)
    to_cam = (cam - face) / np.linalg.norm(cam - face)
    return seen / n**2, float(normal @ to_cam)


@pytest.mark.parametrize("behavior", ["face", "hand"])
def test_jaco2_screen_is_seen_while_the_arm_is_at_home_in_the_robot_initiated_study_scene(
    behavior,
):
    samples: list[tuple[float, float, float]] = []

    def on_tick(sim, tick):
        if not samples or sim.t >= samples[-1][0] + 0.1 - 1e-9:
            samples.append((sim.t, *screen_seen(sim.model, sim.data)))

    robot = with_gaze_mode("jaco2", "head-only")  # the seed's 6.3 head: head movement only
    record_handover(robot, behavior, "robot-initiated", None, progress=False, on_tick=on_tick)
    s = np.array(samples)
    home = s[s[:, 0] <= 1.3]  # the arm at home; its reach starts at 1.0 s and sweeps past later
    # "hand" looks down at the giver's hand: the old view (beside the robot) saw none of the
    # screen through the folded arm for the first 1.5 s.
    assert home[:, 1].min() >= 0.8, home[:, :2].round(2).tolist()
    assert home[:, 2].min() >= 0.5  # facing the camera, not edge-on
    assert np.mean(s[:, 1] >= 0.5) >= 0.85  # over the whole handover, the arm passing by aside
