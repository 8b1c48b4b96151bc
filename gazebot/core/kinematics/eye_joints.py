"""Eyes that are joints of the robot's model: a pan joint per eye and a tilt joint per eye or
one shared by both.

The gaze controller points "the eyes" as one direction ``(yaw, pitch)`` in the gaze frame, as
for eyes drawn on a display (:mod:`gazebot.core.kinematics.eyes`); this module turns that
direction into joint positions. At zero eye joints the eyes look along the gaze frame's +x;
pan axes lie along the gaze frame's z and tilt axes along its y (either sign), which is checked
when the model is built. Both eyes turn parallel (no vergence): the gaze frame sits between them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from gazebot.core.config import ConfigError
from gazebot.core.kinematics.eyes import eye_direction

# |cos| of the angle between a joint axis and the gaze frame axis it must turn about.
_AXIS_ALIGNED = math.cos(math.radians(1.0))


@dataclass(frozen=True)
class EyeChain:
    """One eye's joints.

    Attributes:
        pan, tilt: Joint names (the tilt may be shared with the other eye).
        pan_sign, tilt_sign: +1 when the joint turns about the gaze frame's +z (pan) / +y
            (tilt), -1 about -z / -y.
        tilt_outer: The tilt joint carries the pan joint (else the pan carries the tilt).
        pan_limits, tilt_limits: Position limits (rad) from the model.
    """

    pan: str
    tilt: str
    pan_sign: float
    tilt_sign: float
    tilt_outer: bool
    pan_limits: tuple[float, float]
    tilt_limits: tuple[float, float]


def eye_chains_of(
    model: pin.Model,
    yaw_joints: Sequence[str],
    pitch_joints: Sequence[str],
    gaze_frame_id: int,
    source: Path,
) -> tuple[EyeChain, ...]:
    """The eye chains of ``model``: each yaw joint paired with the pitch joint in its chain.

    Raises:
        ConfigError: a joint that is not in an eye's chain or turns about the wrong axis.
    """
    data = model.createData()
    q = pin.neutral(model)
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    to_gaze = data.oMf[gaze_frame_id].rotation.T

    def axis(name: str) -> np.ndarray:
        jid = model.getJointId(name)
        J = pin.getJointJacobian(model, data, jid, pin.LOCAL_WORLD_ALIGNED)
        return to_gaze @ J[3:, model.joints[jid].idx_v]

    def limits(name: str) -> tuple[float, float]:
        i = model.joints[model.getJointId(name)].idx_q
        return float(model.lowerPositionLimit[i]), float(model.upperPositionLimit[i])

    def sign(name: str, about: int, field: str) -> float:
        a = axis(name)
        if abs(a[about]) < _AXIS_ALIGNED:
            what = "z (left/right)" if about == 2 else "y (up/down)"
            raise ConfigError(
                source, f"eye_joints.{field}",
                f"joint {name!r} turning about the gaze frame's {what} axis at rest",
                [round(float(v), 3) for v in a],
            )
        return 1.0 if a[about] > 0 else -1.0

    chains = []
    used_tilts: set[str] = set()
    for pan in yaw_joints:
        pan_id = model.getJointId(pan)
        paired = [
            t for t in pitch_joints
            if model.getJointId(t) in model.supports[pan_id]
            or pan_id in model.supports[model.getJointId(t)]
        ]
        if len(paired) != 1:
            raise ConfigError(
                source, "eye_joints.pitch",
                f"exactly one pitch joint in the chain of the yaw joint {pan!r}", paired,
            )
        tilt = paired[0]
        used_tilts.add(tilt)
        chains.append(
            EyeChain(
                pan=pan,
                tilt=tilt,
                pan_sign=sign(pan, 2, "yaw"),
                tilt_sign=sign(tilt, 1, "pitch"),
                tilt_outer=model.getJointId(tilt) in model.supports[pan_id],
                pan_limits=limits(pan),
                tilt_limits=limits(tilt),
            )
        )
    unused = [t for t in pitch_joints if t not in used_tilts]
    if unused:
        raise ConfigError(source, "eye_joints.pitch", "pitch joints carrying an eye", unused)
    return tuple(chains)


def _signed(limits: tuple[float, float], sign: float) -> tuple[float, float]:
    lo, hi = limits
    return (lo, hi) if sign > 0 else (-hi, -lo)


def eye_ranges(
    chains: Sequence[EyeChain], source: Path
) -> tuple[tuple[float, float], tuple[float, float]]:
    """The ``(yaw, pitch)`` ranges (rad) every eye can reach (the joints' limits intersected).

    Raises:
        ConfigError: the eyes cannot all look straight ahead (zero not within a range).
    """
    yaw = [_signed(c.pan_limits, c.pan_sign) for c in chains]
    pitch = [_signed(c.tilt_limits, c.tilt_sign) for c in chains]
    ranges = []
    for field, spans in (("yaw", yaw), ("pitch", pitch)):
        lo, hi = max(s[0] for s in spans), min(s[1] for s in spans)
        if not lo <= 0.0 <= hi:
            raise ConfigError(
                source, f"eye_joints.{field}", "joint limits that include the straight-ahead 0",
                (lo, hi),
            )
        ranges.append((lo, hi))
    return ranges[0], ranges[1]


def eye_joint_positions(
    chains: Sequence[EyeChain], yaw: float, pitch: float
) -> dict[str, float]:
    """Joint positions (rad, clipped to their limits) pointing every eye along
    ``eye_direction(yaw, pitch)``."""
    dx, dy, dz = eye_direction(yaw, pitch).tolist()
    out: dict[str, float] = {}
    for c in chains:
        if c.tilt_outer:  # direction = Ry(tilt) Rz(pan) x
            pan, tilt = math.asin(max(-1.0, min(1.0, dy))), math.atan2(-dz, dx)
        else:  # direction = Rz(pan) Ry(tilt) x, the eye angles themselves
            pan, tilt = yaw, pitch
        out[c.pan] = float(np.clip(c.pan_sign * pan, *c.pan_limits))
        out[c.tilt] = float(np.clip(c.tilt_sign * tilt, *c.tilt_limits))
    return out
