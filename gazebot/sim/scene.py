"""Compose the handover scene with ``mujoco.MjSpec``: the robot MJCF, a floor, lights, a table for
the sitting posture, the giver (capsule body with a face, a right arm and hand), the object and an
observer camera at the side (like the seed's video frames, Fig. 6.2a / 6.6)."""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from gazebot.sim.giver_body import GiverBody, GiverDims
from gazebot.sim.objects import HandoverObject, make_object
from gazebot.sim.robot import SimRobot
from gazebot.sim.scene_config import Posture, SceneConfig

OBSERVER = "observer"
MAX_RENDER = (1920, 1080)  # off-screen buffer: the largest video frame supported


@dataclass(frozen=True)
class SceneLayout:
    """Where things are (robot base frame, m)."""

    handover_location: np.ndarray  # gripper site at the robot's handover pose
    offer_hand: np.ndarray  # giver's hand when offering the object there
    rest_hand: np.ndarray  # giver's hand holding the object before/after
    object_offset: np.ndarray  # object center minus giver hand while the giver holds it
    shoulder: np.ndarray  # giver's right shoulder
    table_top: float | None  # height of the table top, None without a table


@dataclass
class Scene:
    """The compiled model with the handles the simulation needs."""

    model: mujoco.MjModel
    layout: SceneLayout
    giver: GiverBody
    obj: HandoverObject
    object_mocap: int


def _robot_fk(robot: SimRobot, pose: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Gripper and gaze site positions of the bare robot model at arm ``pose``."""
    model = mujoco.MjModel.from_xml_path(str(robot.mjcf))
    data = mujoco.MjData(model)
    for name, q in zip(robot.arm_joints, pose, strict=True):
        data.qpos[model.joint(name).qposadr[0]] = q
    mujoco.mj_kinematics(model, data)
    return data.site(robot.gripper_site).xpos.copy(), data.site(robot.gaze_site).xpos.copy()


def _look_at_quat(pos: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Quaternion of a camera at ``pos`` looking at ``target`` with world +z up (camera looks along
    its -z, image up = its +y)."""
    forward = target - pos
    forward /= np.linalg.norm(forward)
    x = np.cross(forward, [0.0, 0.0, 1.0])
    x /= np.linalg.norm(x)
    y = np.cross(x, forward)
    mat = np.column_stack([x, y, -forward]).reshape(-1)
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, mat)
    return quat


def _add_environment(spec: mujoco.MjSpec) -> None:
    spec.add_texture(
        name="scene_skybox",
        type=mujoco.mjtTexture.mjTEXTURE_SKYBOX,
        builtin=mujoco.mjtBuiltin.mjBUILTIN_GRADIENT,
        rgb1=[0.93, 0.94, 0.96],
        rgb2=[0.72, 0.75, 0.8],
        width=256,
        height=256,
    )
    spec.add_texture(
        name="scene_floor",
        type=mujoco.mjtTexture.mjTEXTURE_2D,
        builtin=mujoco.mjtBuiltin.mjBUILTIN_CHECKER,
        rgb1=[0.82, 0.82, 0.8],
        rgb2=[0.74, 0.74, 0.72],
        width=300,
        height=300,
    )
    floor_mat = spec.add_material(name="scene_floor", texrepeat=[6, 6])
    floor_mat.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = "scene_floor"
    spec.worldbody.add_geom(
        name="scene_floor",
        type=mujoco.mjtGeom.mjGEOM_PLANE,
        size=[4, 4, 0.05],
        material="scene_floor",
    )
    # Key light from above the observer's side, a fill from the other side: the arm, the head
    # display and the giver are all lit from the camera's side. Software rendering pays dearly for
    # shadow maps, floor reflections and multisampling (~4x the frame time together), so the scene
    # does without them and grounds bodies with soft blob shadows instead.
    spec.worldbody.add_light(
        name="scene_key",
        pos=[1.2, -2.0, 3.0],
        dir=[-0.3, 0.6, -1.0],
        diffuse=[0.65, 0.65, 0.62],
        specular=[0.2, 0.2, 0.2],
        castshadow=False,
        type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL,
    )
    spec.worldbody.add_light(
        name="scene_fill",
        pos=[0.5, 2.0, 2.5],
        dir=[0.0, -0.7, -1.0],
        diffuse=[0.3, 0.3, 0.32],
        specular=[0.0, 0.0, 0.0],
        castshadow=False,
        type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL,
    )
    spec.visual.headlight.ambient = [0.35, 0.35, 0.35]
    spec.visual.headlight.diffuse = [0.15, 0.15, 0.15]
    spec.visual.headlight.specular = [0.0, 0.0, 0.0]
    spec.visual.quality.offsamples = 0
    spec.visual.global_.offwidth, spec.visual.global_.offheight = MAX_RENDER


def add_blob_shadow(spec: mujoco.MjSpec, x: float, y: float, rx: float, ry: float) -> None:
    """A faint dark ellipse on the floor under a body (cheap stand-in for a shadow map)."""
    spec.worldbody.add_geom(
        type=mujoco.mjtGeom.mjGEOM_ELLIPSOID,
        size=[rx, ry, 0.001],
        pos=[x, y, 0.001],
        rgba=[0.0, 0.0, 0.0, 0.18],
        contype=0,
        conaffinity=0,
        group=1,
    )


def _add_table(spec: mujoco.MjSpec, x0: float, x1: float, y: float, top: float) -> None:
    body = spec.worldbody.add_body(name="scene_table", pos=[(x0 + x1) / 2, y, 0])
    wood = [0.55, 0.4, 0.27, 1.0]
    half_x, half_y = (x1 - x0) / 2, 0.45
    body.add_geom(
        name="scene_table_top",
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=[half_x, half_y, 0.015],
        pos=[0, 0, top - 0.015],
        rgba=wood,
        contype=0,
        conaffinity=0,
    )
    for sx in (-1, 1):
        for sy in (-1, 1):
            body.add_geom(
                type=mujoco.mjtGeom.mjGEOM_CYLINDER,
                size=[0.02, (top - 0.03) / 2, 0],
                pos=[sx * (half_x - 0.04), sy * (half_y - 0.04), (top - 0.03) / 2],
                rgba=[0.35, 0.25, 0.17, 1],
                contype=0,
                conaffinity=0,
            )


def _layout(
    cfg: SceneConfig, robot: SimRobot, obj: HandoverObject, dims: GiverDims
) -> tuple[SceneLayout, np.ndarray]:
    """Where the giver stands and holds the object, from the robot's handover pose; also
    returns the robot's gaze site at that pose."""
    handover, gaze = _robot_fk(robot, robot.handover)
    # The giver's hand is behind the object (on the giver's side, +x) at its center height.
    object_offset = np.array([-(obj.half_extent_x + 0.035), 0.0, 0.0])
    offer = handover - object_offset
    shoulder_z = dims.shoulder_height(cfg.posture)
    # Keep the offer point comfortably inside the arm's reach.
    dz = shoulder_z - offer[2]
    reach = 0.9 * dims.arm_length
    standoff = min(cfg.giver.standoff_m, float(np.sqrt(max(reach**2 - dz**2, 0.04))))
    shoulder = np.array([offer[0] + standoff, offer[1], shoulder_z])
    table_top = None
    if cfg.has_table:
        table_top = float(min(0.75, offer[2] - obj.half_height - 0.12))
        rest = shoulder + np.array([-0.27, -0.06, 0.0])
        rest[2] = table_top + obj.half_height + 0.005
    else:
        rest = shoulder + np.array([-0.25, -0.07, -0.4])
    layout = SceneLayout(
        handover_location=handover,
        offer_hand=offer,
        rest_hand=rest,
        object_offset=object_offset,
        shoulder=shoulder,
        table_top=table_top,
    )
    return layout, gaze


def _camera(
    cfg: SceneConfig, layout: SceneLayout, gaze: np.ndarray, face: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The default observer view, looking at the middle of head, handover location and giver.

    A head on the arm (Sawyer) is watched from the front right, the side the head turns to when
    it looks at the giver. A head standing beside the arm (Jaco-2) is watched from the head's own
    side and well in front of it: the arm, and the object it carries home, then stay behind the
    display, and the display still faces the camera when the head turns to the handover location.
    """
    side = float(np.sign(gaze[1])) if abs(gaze[1]) > 0.15 else 0.0
    look = np.array(cfg.camera.look_at_m) if cfg.camera.look_at_m else None
    if look is None:
        look = (gaze + layout.handover_location + face) / 3.0
        look[2] -= 0.0 if side else 0.05
    offset = np.array([1.7, side * 1.2, 0.7]) if side else np.array([0.7, -2.25, 0.2])
    pos = np.array(cfg.camera.pos_m) if cfg.camera.pos_m else look + offset
    return pos, look


def build_scene(robot: SimRobot, cfg: SceneConfig) -> Scene:
    """Compose and compile the scene for ``robot`` and scene config ``cfg``."""
    spec = mujoco.MjSpec.from_file(str(robot.mjcf))
    # Giver and object are kinematic and the grasp is a controller decision, so contacts would
    # only add jitter and cost: switch them off for the whole scene.
    spec.option.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
    spec.option.timestep = 0.002
    _add_environment(spec)

    obj = make_object(cfg.object)
    dims = GiverDims.for_height(cfg.giver.height_m)
    layout, gaze = _layout(cfg, robot, obj, dims)
    giver = GiverBody(dims, cfg.posture, layout.shoulder)
    giver.add_to(spec)
    add_blob_shadow(spec, giver.root[0] - 0.05, giver.root[1], 0.32, 0.3)
    add_blob_shadow(spec, -0.1, 0.0, 0.5, 0.42)  # the robot's pedestal or table
    if layout.table_top is not None:
        x0 = layout.handover_location[0] - 0.2
        x1 = layout.shoulder[0] - 0.12
        _add_table(spec, x0, x1, layout.shoulder[1] - 0.15, layout.table_top)
    obj.add_to(spec)

    pos, look = _camera(cfg, layout, gaze, giver.face_point)
    spec.worldbody.add_camera(
        name=OBSERVER,
        pos=pos.tolist(),
        quat=_look_at_quat(pos, look).tolist(),
        fovy=cfg.camera.fovy_deg,
    )
    model = spec.compile()
    giver.bind(model)
    return Scene(
        model=model,
        layout=layout,
        giver=giver,
        obj=obj,
        object_mocap=int(model.body(obj.name).mocapid[0]),
    )


__all__ = ["OBSERVER", "Posture", "Scene", "SceneLayout", "build_scene"]
