"""A small URDF head the tests write: pan and tilt, two eye pan joints and a shared eye tilt,
and its robot YAML."""

from __future__ import annotations

from pathlib import Path

HEAD_URDF = """<robot name="eyehead">
  <link name="base"/><link name="neck"/><link name="head"/>
  <link name="eye_tilt_link"/><link name="left_eye"/><link name="right_eye"/>
  <joint name="head_pan" type="revolute"><parent link="base"/><child link="neck"/>
    <origin xyz="0 0 1.2"/><axis xyz="0 0 1"/>
    <limit lower="-1.5" upper="1.5" effort="5" velocity="{pan_velocity}"/></joint>
  <joint name="head_tilt" type="revolute"><parent link="neck"/><child link="head"/>
    <origin xyz="0.02 0 0.08"/><axis xyz="0 1 0"/>
    <limit lower="-0.5" upper="0.8" effort="5" velocity="2.5"/></joint>
  <joint name="eye_tilt" type="revolute"><parent link="head"/><child link="eye_tilt_link"/>
    <origin xyz="0.09 0 0.05"/><axis xyz="0 1 0"/>
    <limit lower="-0.4" upper="0.5" effort="1" velocity="8"/></joint>
  <joint name="left_eye_pan" type="revolute"><parent link="eye_tilt_link"/>
    <child link="left_eye"/><origin xyz="0 0.03 0"/><axis xyz="0 0 1"/>
    <limit lower="-0.6" upper="0.6" effort="1" velocity="10"/></joint>
  <joint name="right_eye_pan" type="revolute"><parent link="eye_tilt_link"/>
    <child link="right_eye"/><origin xyz="0 -0.03 0"/><axis xyz="0 0 1"/>
    <limit lower="-0.6" upper="0.6" effort="1" velocity="10"/></joint>
</robot>
"""

ROBOT_YAML = """name: eyehead
urdf: {urdf}
head_joints: [head_pan, head_tilt]
gaze_frame: {{link: head, xyz: [0.09, 0.0, 0.05]}}
eye_joints: {{yaw: [left_eye_pan, right_eye_pan], pitch: [eye_tilt]}}
points: {{face: [1.2, 0.0, 1.6], handover_location: [0.6, 0.0, 0.9], rest: [1.5, 0.5, 1.3]}}
{extra}"""


def write_robot(folder: Path, urdf_ref: str | None = None, extra: str = "",
                pan_velocity: str = "3.0") -> Path:
    (folder / "eyehead.urdf").write_text(HEAD_URDF.format(pan_velocity=pan_velocity))
    path = folder / "eyehead.yaml"
    path.write_text(ROBOT_YAML.format(urdf=urdf_ref or "eyehead.urdf", extra=extra))
    return path
