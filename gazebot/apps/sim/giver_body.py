"""The giver's body in the scene: capsules for torso, legs and arms, a head with a face looking at
the robot, and a right arm whose shoulder-elbow-hand chain follows the simulated hand (a two-link
inverse kinematics with the elbow down and out). The giver faces -x (toward the robot), so the
giver's right is +y."""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from gazebot.apps.sim.objects.base import visual_geom
from gazebot.apps.sim.scene_config import Posture

SKIN = (0.87, 0.7, 0.58, 1.0)
SHIRT = (0.2, 0.42, 0.62, 1.0)
TROUSERS = (0.2, 0.2, 0.26, 1.0)
HAIR = (0.25, 0.17, 0.1, 1.0)
CAPSULE, SPHERE, BOX, ELLIPSOID = (
    mujoco.mjtGeom.mjGEOM_CAPSULE,
    mujoco.mjtGeom.mjGEOM_SPHERE,
    mujoco.mjtGeom.mjGEOM_BOX,
    mujoco.mjtGeom.mjGEOM_ELLIPSOID,
)


@dataclass(frozen=True)
class GiverDims:
    """Body dimensions (m) scaled from standard anthropometric ratios of the body height."""

    height: float
    upper_arm: float
    forearm: float  # elbow to palm center
    shoulder_half_width: float
    head_radius: float
    hip_height: float
    seat_height: float = 0.47

    @classmethod
    def for_height(cls, height: float) -> GiverDims:
        return cls(
            height=height,
            upper_arm=0.186 * height,
            forearm=0.175 * height,
            shoulder_half_width=0.11 * height,
            head_radius=0.057 * height,
            hip_height=0.53 * height,
        )

    @property
    def arm_length(self) -> float:
        return self.upper_arm + self.forearm

    @property
    def trunk(self) -> float:
        """Hip to shoulder."""
        return 0.818 * self.height - self.hip_height

    def hip_z(self, posture: Posture) -> float:
        return self.seat_height + 0.05 if posture is Posture.SITTING else self.hip_height

    def shoulder_height(self, posture: Posture) -> float:
        return self.hip_z(posture) + self.trunk


def elbow_position(shoulder: np.ndarray, hand: np.ndarray, upper: float, fore: float) -> np.ndarray:
    """Elbow of a two-link arm reaching from ``shoulder`` to ``hand``, bent down and outward.

    Out-of-reach hands are met with a straight arm pointing at them.
    """
    d_vec = hand - shoulder
    d = float(np.linalg.norm(d_vec))
    u = d_vec / d if d > 1e-9 else np.array([-1.0, 0.0, 0.0])
    d = float(np.clip(d, abs(upper - fore) + 1e-4, upper + fore - 1e-4))
    a = (upper**2 - fore**2 + d**2) / (2 * d)
    h = float(np.sqrt(max(upper**2 - a**2, 0.0)))
    pole = np.array([0.35, 0.55, -1.0])  # elbow back, out (to the giver's right) and down
    b = pole - pole.dot(u) * u
    b /= np.linalg.norm(b)
    return shoulder + a * u + h * b


def segment_pose(p0: np.ndarray, p1: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Center and quaternion of a capsule (local +z axis) from ``p0`` to ``p1``."""
    axis = p1 - p0
    n = float(np.linalg.norm(axis))
    quat = np.array([1.0, 0.0, 0.0, 0.0])
    if n > 1e-9:
        mujoco.mju_quatZ2Vec(quat, axis / n)
    return (p0 + p1) / 2, quat


class GiverBody:
    """Adds the giver to a spec and poses its right arm from the hand position."""

    ARM_BODIES = ("giver_upper_arm", "giver_forearm", "giver_hand")

    def __init__(self, dims: GiverDims, posture: Posture, shoulder: np.ndarray) -> None:
        self.dims = dims
        self.posture = posture
        self.shoulder = np.asarray(shoulder, float)
        w = dims.shoulder_half_width
        # Torso center line under the neck (the right shoulder is at +y of it).
        self.root = self.shoulder - np.array([0.0, w, 0.0])
        self.head_center = self.root + np.array([0.0, 0.0, 0.08 * dims.height])
        self.face_point = self.head_center + np.array([-dims.head_radius, 0.0, 0.01])
        self._mocap: dict[str, int] = {}

    def add_to(self, spec: mujoco.MjSpec) -> None:
        d, w = self.dims, self.dims.shoulder_half_width
        body = spec.worldbody.add_body(name="giver", pos=self.root.tolist())
        hip = d.hip_z(self.posture) - self.root[2]
        # Torso: an ellipsoid, flatter front to back than wide, from the hips to the shoulders.
        half_z = (0.02 - hip) / 2
        visual_geom(
            body,
            type=ELLIPSOID,
            size=[0.11, 0.9 * w, half_z + 0.06],
            pos=[0.0, 0.0, hip + half_z - 0.02],
            rgba=SHIRT,
        )
        visual_geom(
            body, type=CAPSULE, fromto=[0, -w, -0.02, 0, w, -0.02], size=[0.055], rgba=SHIRT
        )
        visual_geom(body, type=CAPSULE, fromto=[0, 0, 0, 0, 0, 0.07], size=[0.045], rgba=SKIN)
        self._add_head(body)
        self._add_legs(body, hip)
        # Left arm hangs relaxed at the side.
        visual_geom(
            body,
            type=CAPSULE,
            size=[0.045],
            fromto=[0.0, -w, -0.02, 0.02, -w - 0.03, -d.upper_arm],
            rgba=SHIRT,
        )
        visual_geom(
            body,
            type=CAPSULE,
            size=[0.038],
            fromto=[
                0.02,
                -w - 0.03,
                -d.upper_arm,
                -0.02,
                -w - 0.03,
                -d.upper_arm - d.forearm + 0.06,
            ],
            rgba=SKIN,
        )
        if self.posture is Posture.SITTING:
            chair = spec.worldbody.add_body(
                name="giver_chair", pos=[self.root[0] + 0.05, self.root[1], 0]
            )
            grey = (0.3, 0.3, 0.33, 1.0)
            visual_geom(
                chair,
                type=BOX,
                size=[0.23, 0.22, 0.025],
                pos=[0, 0, d.seat_height - 0.025],
                rgba=grey,
            )
            visual_geom(
                chair,
                type=BOX,
                size=[0.025, 0.22, 0.25],
                pos=[0.24, 0, d.seat_height + 0.25],
                rgba=grey,
            )
            visual_geom(
                chair,
                type=CAPSULE,
                fromto=[0, 0, 0.02, 0, 0, d.seat_height - 0.05],
                size=[0.03],
                rgba=grey,
            )
        upper = spec.worldbody.add_body(name=self.ARM_BODIES[0], mocap=True)
        visual_geom(upper, type=CAPSULE, size=[0.045, d.upper_arm / 2, 0], rgba=SHIRT)
        fore = spec.worldbody.add_body(name=self.ARM_BODIES[1], mocap=True)
        visual_geom(fore, type=CAPSULE, size=[0.036, d.forearm / 2 - 0.03, 0], rgba=SKIN)
        hand = spec.worldbody.add_body(name=self.ARM_BODIES[2], mocap=True)
        visual_geom(hand, type=ELLIPSOID, size=[0.03, 0.05, 0.06], rgba=SKIN)

    def _add_head(self, body: mujoco.MjsBody) -> None:
        r = self.dims.head_radius
        c = self.head_center - self.root
        visual_geom(body, type=ELLIPSOID, size=[r, 0.9 * r, 1.15 * r], pos=c.tolist(), rgba=SKIN)
        # Hair on the back and top of the head; the face (-x side) stays free.
        visual_geom(
            body,
            type=ELLIPSOID,
            size=[0.9 * r, 0.95 * r, 1.05 * r],
            pos=(c + [0.025, 0, 0.03]).tolist(),
            rgba=HAIR,
        )
        for side in (-1, 1):
            eye = c + np.array([-0.88 * r, side * 0.36 * r, 0.18 * r])
            visual_geom(
                body, type=SPHERE, size=[0.016], pos=eye.tolist(), rgba=(0.97, 0.97, 0.97, 1)
            )
            visual_geom(
                body,
                type=SPHERE,
                size=[0.008],
                pos=(eye + [-0.012, 0, 0]).tolist(),
                rgba=(0.12, 0.08, 0.05, 1),
            )
            brow = eye + np.array([0.0, 0.0, 0.03])
            visual_geom(body, type=BOX, size=[0.004, 0.02, 0.004], pos=brow.tolist(), rgba=HAIR)
        visual_geom(
            body,
            type=CAPSULE,
            size=[0.012],
            fromto=(c + [-0.95 * r, 0, 0.1 * r]).tolist()
            + (c + [-1.12 * r, 0, -0.15 * r]).tolist(),
            rgba=SKIN,
        )
        visual_geom(
            body,
            type=BOX,
            size=[0.004, 0.025, 0.005],
            pos=(c + [-0.9 * r, 0, -0.5 * r]).tolist(),
            rgba=(0.7, 0.3, 0.3, 1),
        )

    def _add_legs(self, body: mujoco.MjsBody, hip: float) -> None:
        floor = -self.root[2] + 0.05
        for side in (-0.09, 0.09):
            if self.posture is Posture.SITTING:
                knee = [-0.45, side, hip]
                visual_geom(
                    body,
                    type=CAPSULE,
                    fromto=[0, side, hip, *knee[:2], hip],
                    size=[0.07],
                    rgba=TROUSERS,
                )
                visual_geom(
                    body,
                    type=CAPSULE,
                    fromto=[*knee, knee[0], side, floor],
                    size=[0.055],
                    rgba=TROUSERS,
                )
            else:
                visual_geom(
                    body,
                    type=CAPSULE,
                    fromto=[0, side, hip, 0.0, side * 1.1, floor],
                    size=[0.07],
                    rgba=TROUSERS,
                )
            foot = [-0.06 if self.posture is Posture.STANDING else -0.51, side, floor - 0.025]
            visual_geom(body, type=BOX, size=[0.12, 0.045, 0.03], pos=foot, rgba=(0.1, 0.1, 0.1, 1))

    def bind(self, model: mujoco.MjModel) -> None:
        """Remember the mocap ids of the arm bodies in the compiled ``model``."""
        self._mocap = {n: int(model.body(n).mocapid[0]) for n in self.ARM_BODIES}

    def pose_arm(self, data: mujoco.MjData, hand: np.ndarray) -> None:
        """Place upper arm, forearm and hand for the hand position ``hand``."""
        d = self.dims
        elbow = elbow_position(self.shoulder, hand, d.upper_arm, d.forearm)
        for name, (p0, p1) in zip(
            self.ARM_BODIES[:2], ((self.shoulder, elbow), (elbow, hand)), strict=True
        ):
            pos, quat = segment_pose(p0, p1)
            data.mocap_pos[self._mocap[name]] = pos
            data.mocap_quat[self._mocap[name]] = quat
        pos, quat = segment_pose(elbow, hand)
        data.mocap_pos[self._mocap["giver_hand"]] = hand
        data.mocap_quat[self._mocap["giver_hand"]] = quat
