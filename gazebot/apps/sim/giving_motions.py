"""The simulator's giving motions for the seed's Table 4.4
(:mod:`gazebot.apps.controllers.reach_table`): :class:`~gazebot.apps.sim.giver.SimulatedGiver`'s
minimum-jerk reach from its rest point to its offer point, held before and after, with reach
durations drawn from the seed's human-human distribution (section 6.2), in the robot's base
frame, reaching toward a robot whose gripper starts at its home pose."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gazebot.apps.controllers.giving_motions import GivingMotion, motion_from_path


@dataclass(frozen=True)
class SimulatedGivers:
    """How to draw simulated giving motions: the robot, the scenes cycled through, the giver
    heights spread over (m) and the sampling of the path (s)."""

    robot: str = "panda"
    scenes: tuple[str, ...] = ("standing", "sitting")
    heights_m: tuple[float, ...] = (1.55, 1.65, 1.75, 1.85, 1.95)
    dt_s: float = 0.01
    hold_s: float = 0.5  # at rest before the reach and at the offer point after it


def simulated_motions(
    n: int, seed: int = 0, spec: SimulatedGivers | None = None
) -> list[GivingMotion]:
    """``n`` giving motions of the simulator's giver (module doc): scene and giver height
    cycled, reach duration drawn from the scene's human-human distribution (seed 6.2), the
    hand's rest and offer points from the compiled scene; the gripper starts at its home pose.
    Motions the seed's rule cannot segment are skipped (the caller counts them)."""
    import mujoco

    from gazebot.apps.sim.motion import MinJerkSegment
    from gazebot.apps.sim.robot import load_sim_robot
    from gazebot.apps.sim.scene import build_scene
    from gazebot.apps.sim.scene_config import load_scene

    spec = spec or SimulatedGivers()
    robot = load_sim_robot(spec.robot)
    home = _gripper_at(robot, mujoco)
    rng = np.random.default_rng(seed)
    layouts: dict[tuple[str, float], tuple[np.ndarray, np.ndarray, object]] = {}
    out: list[GivingMotion] = []
    for i in range(n):
        scene_name = spec.scenes[i % len(spec.scenes)]
        height = spec.heights_m[(i // len(spec.scenes)) % len(spec.heights_m)]
        key = (scene_name, height)
        if key not in layouts:
            cfg = load_scene(scene_name)
            giver = cfg.giver.model_copy(update={"height_m": height})
            cfg = cfg.model_copy(update={"giver": giver})
            lay = build_scene(robot, cfg).layout
            layouts[key] = (lay.rest_hand, lay.offer_hand, cfg.giver.reach)
        rest, offer, reach = layouts[key]
        duration = reach.sample(rng)  # type: ignore[attr-defined]
        seg = MinJerkSegment(rest, offer, spec.hold_s, duration)
        t = np.arange(0.0, 2 * spec.hold_s + duration + 1e-9, spec.dt_s)
        hand = np.array([seg.position(x) for x in t])
        m = motion_from_path(f"sim-{i:03d}-{scene_name}-{height:.2f}m", t, hand, home)
        if m is not None:
            out.append(m)
    return out


def _gripper_at(robot, mujoco) -> np.ndarray:
    """The robot's gripper site at its home pose (base frame, m)."""
    model = mujoco.MjModel.from_xml_path(str(robot.mjcf))
    data = mujoco.MjData(model)
    for name, q in zip(robot.arm_joints, robot.home, strict=True):
        data.qpos[model.joint(name).qposadr[0]] = q
    mujoco.mj_kinematics(model, data)
    return data.site(robot.gripper_site).xpos.copy()
