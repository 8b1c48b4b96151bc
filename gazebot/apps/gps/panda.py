"""The learner: a Franka Emika Panda arm with a two-finger gripper, as an MJCF fragment we write
from the robot's published parameters (no meshes; capsules stand in for the links' shapes).

Kinematics: Franka's published modified (Craig) Denavit-Hartenberg table, joint limits and torque
limits (Franka Control Interface documentation, "Robot and interface specifications",
frankaemika.github.io/docs/control_parameters.html). The flange sits 0.107 m along link 7's z,
the hand is turned -45 deg about it, and the fingertip centre (TCP) is 0.1034 m beyond the flange.

Inertia: the link masses, centres of mass and inertia tensors (about the centre of mass, in the
DH link frames) published with ``franka_description`` and identified by C. Gaz, M. Cognetti,
A. Oliva, P. Robuffo Giordano, A. De Luca, "Dynamic Identification of the Franka Emika Panda
Robot With Retrieval of Feasible Parameters Using Penalty-Based Optimization", IEEE RA-L 4(4),
2019. The hand's mass is the seed's end-effector mass (2 kg baseline, section 5.4); its inertia is
that of a 0.1 x 0.2 x 0.06 m box of that mass (ours).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

# Modified DH rows (a_{i-1} [m], d_i [m], alpha_{i-1} [rad]), joints 1..7 (Franka's table).
DH: tuple[tuple[float, float, float], ...] = (
    (0.0, 0.333, 0.0),
    (0.0, 0.0, -math.pi / 2),
    (0.0, 0.316, math.pi / 2),
    (0.0825, 0.0, math.pi / 2),
    (-0.0825, 0.384, -math.pi / 2),
    (0.0, 0.0, math.pi / 2),
    (0.088, 0.0, math.pi / 2),
)
FLANGE_D_M = 0.107
TCP_OFFSET_M = 0.1034
Q_MIN = (-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973)
Q_MAX = (2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973)
TAU_MAX_NM = (87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0)
FINGER_RANGE_M = (0.0, 0.04)  # each finger; the gripper opens to 0.08 m


@dataclass(frozen=True)
class LinkInertia:
    """Mass [kg], centre of mass [m] and inertia (ixx, iyy, izz, ixy, ixz, iyz) [kg m^2]."""

    mass: float
    com: tuple[float, float, float]
    inertia: tuple[float, float, float, float, float, float]


# franka_description / Gaz et al. 2019, links 1..7 (MJCF fullinertia order: xx yy zz xy xz yz).
LINKS: tuple[LinkInertia, ...] = (
    LinkInertia(4.970684, (3.875e-3, 2.081e-3, -4.762e-2),
                (7.0337e-1, 7.0661e-1, 9.117e-3, -1.39e-4, 6.772e-3, 1.9169e-2)),
    LinkInertia(0.646926, (-3.141e-3, -2.872e-2, 3.495e-3),
                (7.962e-3, 2.811e-2, 2.5995e-2, -3.925e-3, 1.0254e-2, 7.04e-4)),
    LinkInertia(3.228604, (2.7518e-2, 3.9252e-2, -6.6502e-2),
                (3.7242e-2, 3.6155e-2, 1.083e-2, -4.761e-3, -1.1396e-2, -1.2805e-2)),
    LinkInertia(3.587895, (-5.317e-2, 1.04419e-1, 2.7454e-2),
                (2.5853e-2, 1.9552e-2, 2.8323e-2, 7.796e-3, -1.332e-3, 8.641e-3)),
    LinkInertia(1.225946, (-1.1953e-2, 4.1065e-2, -3.8437e-2),
                (3.5549e-2, 2.9474e-2, 8.627e-3, -2.117e-3, -4.037e-3, 2.29e-4)),
    LinkInertia(1.666555, (6.0149e-2, -1.4117e-2, -1.0517e-2),
                (1.964e-3, 4.354e-3, 5.433e-3, 1.09e-4, -1.158e-3, 3.41e-4)),
    LinkInertia(0.735522, (1.0517e-2, -4.252e-3, 6.1597e-2),
                (1.2516e-2, 1.0027e-2, 4.815e-3, -4.28e-4, -1.196e-3, -7.41e-4)),
)
FINGER_MASS_KG = 0.015


def _fmt(values: tuple[float, ...] | list[float]) -> str:
    return " ".join(f"{v:.17g}" for v in values)


def _link_geom(i: int) -> str:
    """A capsule from this link's origin towards the next joint's origin (visual only)."""
    if i + 1 < len(DH):
        a, d, alpha = DH[i + 1]
        end = (a, -d * math.sin(alpha), d * math.cos(alpha))
    else:
        end = (0.0, 0.0, FLANGE_D_M)
    if math.hypot(*end) < 1e-6:
        return '<geom type="sphere" size="0.06" class="learner"/>'
    return f'<geom type="capsule" fromto="0 0 0 {_fmt(end)}" size="0.05" class="learner"/>'


def panda_mjcf(ee_mass_kg: float, damping: tuple[float, ...], gravcomp_hand: float,
               pos: tuple[float, float, float] | None = None) -> str:
    """The Panda's kinematic tree as MJCF (body ``link0``, at ``pos`` in its parent, default the
    parent's origin), with the site ``tcp`` (fingertip centre) on the body ``hand``.

    ``gravcomp_hand`` is the fraction of the hand's weight the robot's own gravity compensation
    cancels (the nominal end-effector mass over the actual one); the links are fully compensated.
    The handover scene's ``panda`` robot (:mod:`gazebot.apps.gps.handover_robot`) mounts this same
    tree.
    """
    w, h, dz = 0.1, 0.2, 0.06
    hand_inertia = (
        ee_mass_kg * (h * h + dz * dz) / 12,
        ee_mass_kg * (w * w + dz * dz) / 12,
        ee_mass_kg * (w * w + h * h) / 12,
    )
    at = "" if pos is None else f' pos="{_fmt(pos)}"'
    xml = [f'<body name="link0"{at} childclass="learner">',
           '<geom type="cylinder" size="0.09 0.07" pos="0 0 0.07" class="learner"/>',
           f'<geom type="capsule" fromto="0 0 0 0 0 {DH[0][1]}" size="0.06" class="learner"/>']
    for i, ((a, d, alpha), link) in enumerate(zip(DH, LINKS, strict=True)):
        pos = (a, -d * math.sin(alpha), d * math.cos(alpha))
        xml.append(
            f'<body name="link{i + 1}" pos="{_fmt(pos)}" euler="{alpha:.17g} 0 0" gravcomp="1">'
        )
        xml.append(
            f'<inertial pos="{_fmt(link.com)}" mass="{link.mass}" '
            f'fullinertia="{_fmt(link.inertia)}"/>'
        )
        xml.append(
            f'<joint name="joint{i + 1}" axis="0 0 1" range="{Q_MIN[i]} {Q_MAX[i]}" '
            f'damping="{damping[i]}"/>'
        )
        xml.append(_link_geom(i))
    xml.append(
        f'<body name="hand" pos="0 0 {FLANGE_D_M}" euler="0 0 {-math.pi / 4:.17g}" '
        f'gravcomp="{gravcomp_hand:.9g}">'
    )
    xml.append(
        f'<inertial pos="0 0 0.03" mass="{ee_mass_kg}" diaginertia="{_fmt(hand_inertia)}"/>'
    )
    xml.append(f'<geom type="box" size="{w / 2} {h / 2} {dz / 2}" pos="0 0 0.03" class="learner"/>')
    xml.append(f'<site name="tcp" pos="0 0 {TCP_OFFSET_M}" size="0.01"/>')
    for side, sign in (("left", 1), ("right", -1)):
        xml.append(f'<body name="finger_{side}" pos="0 0 0.0584" gravcomp="1">')
        xml.append(
            f'<inertial pos="0 {sign * 0.01} 0.025" mass="{FINGER_MASS_KG}" '
            'diaginertia="2e-6 2e-6 1e-6"/>'
        )
        xml.append(
            f'<joint name="finger_{side}" type="slide" axis="0 {sign} 0" '
            f'range="{FINGER_RANGE_M[0]} {FINGER_RANGE_M[1]}" damping="5"/>'
        )
        xml.append(f'<geom type="box" size="0.01 0.01 0.025" pos="0 {sign * 0.01} 0.025" '
                   'class="learner"/>')
        xml.append("</body>")
    xml.append("</body>")  # hand
    xml.extend("</body>" for _ in DH)
    xml.append("</body>")  # link0
    return "\n".join(xml)


def fingers_tendon() -> str:
    """The tendon ``fingers`` (the mean of the two finger slides) the gripper actuates."""
    return ('<fixed name="fingers"><joint joint="finger_left" coef="0.5"/>'
            '<joint joint="finger_right"\n      coef="0.5"/></fixed>')


def arm_motors() -> list[str]:
    """Seven joint torque motors ``tau1``..``tau7`` within Franka's torque limits."""
    return [
        f'<motor name="tau{i + 1}" joint="joint{i + 1}" ctrlrange="{-t} {t}" ctrllimited="true"/>'
        for i, t in enumerate(TAU_MAX_NM)
    ]


def panda_actuators(gripper_force_n: float) -> str:
    """Seven joint torque motors within Franka's torque limits, and the gripper's force motor
    (positive force opens the fingers; both fingers share it through a tendon)."""
    motors = arm_motors()
    motors.append(
        f'<motor name="gripper" tendon="fingers" ctrlrange="{-gripper_force_n} {gripper_force_n}" '
        'ctrllimited="true"/>'
    )
    return "\n".join(motors)
