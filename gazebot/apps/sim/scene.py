"""Compose the handover scene with ``mujoco.MjSpec``: the robot MJCF, a floor, lights, a table for
the sitting posture, the giver (capsule body with a face, a right arm and hand), the object and an
observer camera at the side (like the seed's video frames, Fig. 6.2a / 6.6)."""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from gazebot.apps.sim.giver_body import GiverBody, GiverDims
from gazebot.apps.sim.objects import HandoverObject, make_object
from gazebot.apps.sim.robot import SimRobot
from gazebot.apps.sim.scene_config import Posture, SceneConfig

OBSERVER = "observer"
DISPLAY_GEOM = "display"  # the head screen box geom (its +x face shows the eyes)
FRAME_ASPECT = 4 / 3  # the framing keeps the scene in a 4:3 frame (wider frames show more)
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
    robot_points: np.ndarray  # (n, 3) the arm's bodies at the home and the handover pose
    head: np.ndarray  # the robot's gaze site at the home pose
    screen: np.ndarray  # (4, 3) corners of the head display at the home pose (may be empty)


@dataclass
class Scene:
    """The compiled model with the handles the simulation needs."""

    model: mujoco.MjModel
    layout: SceneLayout
    giver: GiverBody
    obj: HandoverObject
    object_mocap: int


def _robot_fk(
    robot: SimRobot, pose: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Gripper and gaze site positions of the bare robot model at arm ``pose``, and the points
    the observer must see: the arm's bodies and the corners of the head display."""
    model = mujoco.MjModel.from_xml_path(str(robot.mjcf))
    data = mujoco.MjData(model)
    for name, q in zip(robot.arm_joints, pose, strict=True):
        data.qpos[model.joint(name).qposadr[0]] = q
    mujoco.mj_kinematics(model, data)
    arm_roots = {int(model.jnt_bodyid[model.joint(j).id]) for j in robot.arm_joints}
    points = [data.xpos[b] for b in range(1, model.nbody) if _below(model, b, arm_roots)]
    return (
        data.site(robot.gripper_site).xpos.copy(),
        data.site(robot.gaze_site).xpos.copy(),
        np.array(points),
        display_corners(model, data),
    )


def _below(model: mujoco.MjModel, body: int, roots: set[int]) -> bool:
    """Whether ``body`` is one of ``roots`` or hangs below one."""
    while body > 0:
        if body in roots:
            return True
        body = int(model.body_parentid[body])
    return False


def display_corners(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """World positions (4, 3) of the head display's screen corners (the ``display`` box geom's
    +x face); none when the robot has no such geom."""
    try:
        g = model.geom(DISPLAY_GEOM).id
    except KeyError:
        return np.zeros((0, 3))
    s = model.geom_size[g]
    rot = data.geom_xmat[g].reshape(3, 3)
    return np.array(
        [data.geom_xpos[g] + rot @ [s[0], a * s[1], b * s[2]] for a in (-1, 1) for b in (1, -1)]
    )


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
    handover, gaze, arm_out, _ = _robot_fk(robot, robot.handover)
    _, home_gaze, arm_home, screen = _robot_fk(robot, robot.home)
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
        robot_points=np.vstack([arm_home, arm_out]),
        head=home_gaze,
        screen=screen,
    )
    return layout, gaze


# Default camera directions from the robot's head (deg). The head turns toward the giver, so the
# camera stands on that side, in front of the robot: the screen faces it while the head looks at
# the giver. A head on the arm (Sawyer) is watched from in front and to the robot's right, the
# giver in profile. A head standing beside the arm (Jaco-2) is watched from in front of it, over
# the giver's left shoulder and above: from beside the robot the folded home pose's upper arm
# hid the screen while the head looked down at the giver's hand (the first 1.5 s of the 6.3
# study's robot-initiated handover), and from the front-right the arm's reach sweeps across it.
# Measured with rays and segmentation over whole handovers
# (tests/apps/sim/test_sim_view_occlusion.py,
# tests/apps/sim/test_sim_observer_view.py).
ON_ARM_VIEW = (-60.0, 12.0, 5.0)  # azimuth, elevation (deg), distance (m)
BESIDE_VIEW = (15.0, 25.0, 5.0)


def observer_points(cfg: SceneConfig, layout: SceneLayout, giver: GiverBody, obj) -> np.ndarray:
    """What the observer camera keeps in frame (robot base frame, m): the robot's head screen
    and arm at home and at the handover pose, the giver's head and face, and the giver's hand
    and the object at rest and at the handover location."""
    r = giver.dims.head_radius
    # The head turns: keep a box around its screen in frame, not only the screen at home.
    screen = layout.screen
    reach = 0.04 + float(np.max(np.linalg.norm(screen - layout.head, axis=1), initial=0.1))
    box = layout.head + reach * np.array(
        [[a, b, c] for a in (-1, 1) for b in (-1, 1) for c in (-0.6, 0.6)]
    )
    pts = [
        layout.robot_points,
        box,
        giver.head_center + [0.0, 0.0, 1.25 * r],
        giver.face_point,
        giver.head_center + [0.0, -r, 0.0],
        giver.head_center + [0.0, r, 0.0],
    ]
    for hand in (layout.rest_hand, layout.offer_hand):
        center = hand + layout.object_offset
        pts += [hand, center + [0.0, 0.0, obj.half_height], center - [0.0, 0.0, obj.half_height]]
    return np.vstack(pts)


def _rotation(pos: np.ndarray, look: np.ndarray) -> np.ndarray:
    mat = np.zeros(9)
    mujoco.mju_quat2Mat(mat, _look_at_quat(pos, look))
    return mat.reshape(3, 3)


def _fit_fovy(points: np.ndarray, pos: np.ndarray, look: np.ndarray, margin: float) -> float:
    """The vertical field of view (deg) of a 4:3 camera at ``pos`` aimed at ``look`` that shows
    all ``points`` with ``margin`` of the half frame free."""
    v = (points - pos) @ _rotation(pos, look)
    depth = -v[:, 2]
    if np.any(depth <= 0.05):
        raise ValueError("the observer camera is too close to (or past) what it must show")
    half = max(np.abs(v[:, 1] / depth).max(), np.abs(v[:, 0] / depth).max() / FRAME_ASPECT)
    return float(2 * np.degrees(np.arctan(half / (1.0 - margin))))


def frame_points(
    points: np.ndarray, pos: np.ndarray, margin: float, fovy_deg: float | None = None
) -> tuple[np.ndarray, float]:
    """Aim a camera at ``pos`` so that ``points`` are centered in a 4:3 frame; returns the look-at
    point and the vertical field of view (deg) that fits them with ``margin`` (a fraction of the
    half frame) free at the edges, or ``fovy_deg`` when given."""
    look = points.mean(axis=0)
    dist = float(np.linalg.norm(look - pos))
    for _ in range(8):  # re-center on the angular extent (converges in a few steps)
        rot = _rotation(pos, look)
        v = (points - pos) @ rot
        depth = -v[:, 2]
        tx, ty = v[:, 0] / depth, v[:, 1] / depth
        ray = rot @ np.array([(tx.max() + tx.min()) / 2, (ty.max() + ty.min()) / 2, -1.0])
        look = pos + dist * ray / np.linalg.norm(ray)
    if fovy_deg is not None:
        return look, float(fovy_deg)
    return look, _fit_fovy(points, pos, look, margin)


def observer_camera(
    cfg: SceneConfig, layout: SceneLayout, points: np.ndarray
) -> tuple[np.ndarray, np.ndarray, float]:
    """Position, look-at point and vertical field of view (deg) of the observer camera."""
    cam = cfg.camera
    head = layout.head
    beside = abs(head[1]) > 0.15  # the head stands beside the arm, not on it
    az, el, dist = BESIDE_VIEW if beside else ON_ARM_VIEW
    if beside and head[1] < 0:  # a head on the robot's right turns left: mirror the view
        az = -az
    az = cam.azimuth_deg if cam.azimuth_deg is not None else az
    el = cam.elevation_deg if cam.elevation_deg is not None else el
    dist = cam.distance_m if cam.distance_m is not None else dist
    if cam.pos_m is not None:
        pos = np.array(cam.pos_m, float)
    else:
        a, e = np.radians(az), np.radians(el)
        pos = head + dist * np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])
    if cam.look_at_m is not None:
        look = np.array(cam.look_at_m, float)
        if cam.fovy_deg is not None:
            return pos, look, float(cam.fovy_deg)
        return pos, look, _fit_fovy(points, pos, look, cam.margin)
    look, fovy = frame_points(points, pos, cam.margin, cam.fovy_deg)
    return pos, look, fovy


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

    pos, look, fovy = observer_camera(cfg, layout, observer_points(cfg, layout, giver, obj))
    if float(np.linalg.norm(look - pos)) < 1e-6:
        raise ValueError(f"scene {cfg.name!r}: camera.look_at_m is the camera's position")
    spec.worldbody.add_camera(
        name=OBSERVER,
        pos=pos.tolist(),
        quat=_look_at_quat(pos, look).tolist(),
        fovy=min(fovy, 120.0),
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


__all__ = [
    "DISPLAY_GEOM",
    "OBSERVER",
    "Posture",
    "Scene",
    "SceneLayout",
    "build_scene",
    "display_corners",
    "observer_points",
]
