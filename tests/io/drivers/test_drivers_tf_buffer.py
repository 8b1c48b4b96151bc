"""The transform buffer of /tf and /tf_static: chains through the common ancestor, static
frames at any time, dynamic ones interpolated between their stamps and never extrapolated,
bounded memory. Expected values are written out by hand (rotations about one axis)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from rosbags.typesys import Stores, get_typestore

from gazebot.io.drivers.tf_buffer import (
    TfBuffer,
    Transform,
    TransformError,
    add_tf_message,
    quaternion_matrix,
)

JAZZY = get_typestore(Stores.ROS2_JAZZY)


def rot_z(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def tf(x: float, y: float, z: float, yaw: float = 0.0) -> Transform:
    return Transform(np.array([x, y, z]), rot_z(yaw))


def test_a_chain_of_static_frames_transforms_points_both_ways():
    buf = TfBuffer()
    buf.add("base", "torso", 0.0, tf(0.0, 0.0, 1.0), static=True)
    buf.add("torso", "camera", 0.0, tf(0.2, 0.0, 0.3, math.pi / 2), static=True)
    # camera's +x is the base's +y; the camera sits at (0.2, 0, 1.3)
    np.testing.assert_allclose(buf.transform_point("base", "camera", np.array([1.0, 0, 0])),
                               [0.2, 1.0, 1.3], atol=1e-12)
    np.testing.assert_allclose(buf.transform_point("camera", "base", np.array([0.2, 1.0, 1.3])),
                               [1.0, 0.0, 0.0], atol=1e-12)
    # statics hold at any time, and a leading / names the same frame
    np.testing.assert_allclose(buf.transform_point("/base", "camera", np.zeros(3), t=1e6),
                               [0.2, 0.0, 1.3], atol=1e-12)


def test_sibling_frames_go_through_their_common_ancestor():
    buf = TfBuffer()
    buf.add("base", "left", 0.0, tf(0.0, 0.5, 0.0), static=True)
    buf.add("base", "right", 0.0, tf(0.0, -0.5, 0.0, math.pi), static=True)
    # right's +x is the base's -x: left's origin is (0, -1, 0) in right's axes
    np.testing.assert_allclose(buf.transform_point("right", "left", np.zeros(3)),
                               [0.0, -1.0, 0.0], atol=1e-12)


def test_unknown_and_unconnected_frames_have_no_transform():
    buf = TfBuffer()
    buf.add("base", "camera", 0.0, tf(0, 0, 1), static=True)
    buf.add("map", "odom", 0.0, tf(0, 0, 0), static=True)
    with pytest.raises(TransformError, match="no transform for frame 'ghost'"):
        buf.lookup("base", "ghost")
    with pytest.raises(TransformError, match="not connected"):
        buf.lookup("base", "odom")


def test_dynamic_frames_interpolate_hold_briefly_and_never_extrapolate():
    buf = TfBuffer(hold_s=0.1)
    buf.add("base", "head", 10.0, tf(0.0, 0.0, 1.0, 0.0))
    buf.add("base", "head", 11.0, tf(1.0, 0.0, 1.0, math.pi / 2))
    mid = buf.lookup("base", "head", 10.25)
    np.testing.assert_allclose(mid.translation, [0.25, 0.0, 1.0], atol=1e-12)
    np.testing.assert_allclose(mid.rotation, rot_z(math.pi / 8), atol=1e-12)
    np.testing.assert_allclose(buf.lookup("base", "head", 11.05).translation, [1.0, 0, 1.0])
    with pytest.raises(TransformError, match="no extrapolation"):
        buf.lookup("base", "head", 11.2)
    with pytest.raises(TransformError, match="before the oldest"):
        buf.lookup("base", "head", 9.9)
    # no time: the newest
    np.testing.assert_allclose(buf.lookup("base", "head").translation, [1.0, 0.0, 1.0])


def test_memory_is_bounded_in_time_count_and_frames():
    buf = TfBuffer(cache_s=1.0, max_frames=3, max_per_frame=5)
    for i in range(100):
        buf.add("base", "head", 0.1 * i, tf(0.1 * i, 0, 0))
    edge = buf._edges["head"]
    assert len(edge.stamps) <= 5 and edge.stamps[-1] == pytest.approx(9.9)
    with pytest.raises(TransformError):
        buf.lookup("base", "head", 5.0)
    assert buf.add("base", "a", 0.0, tf(0, 0, 0), static=True)
    assert buf.add("base", "b", 0.0, tf(0, 0, 0), static=True)
    assert not buf.add("base", "c", 0.0, tf(0, 0, 0), static=True)  # a 4th frame
    assert not buf.add("base", "head", 1.0, tf(0, 0, 0))  # older than the newest kept
    assert not buf.add("base", "base", 0.0, tf(0, 0, 0), static=True)
    assert not buf.add("base", "a", 0.0, Transform(np.array([math.nan, 0, 0]), np.eye(3)))
    assert buf.refused == 4


def test_tf_messages_fill_the_buffer_and_bad_quaternions_are_refused():
    T = JAZZY.types

    def stamped(parent, child, q):
        return T["geometry_msgs/msg/TransformStamped"](
            header=T["std_msgs/msg/Header"](
                stamp=T["builtin_interfaces/msg/Time"](sec=3, nanosec=500_000_000),
                frame_id=parent),
            child_frame_id=child,
            transform=T["geometry_msgs/msg/Transform"](
                translation=T["geometry_msgs/msg/Vector3"](x=1.0, y=2.0, z=3.0),
                rotation=T["geometry_msgs/msg/Quaternion"](x=q[0], y=q[1], z=q[2], w=q[3])))

    s = math.sqrt(0.5)
    msg = T["tf2_msgs/msg/TFMessage"](transforms=[
        stamped("base", "cam", (0.0, 0.0, s, s)), stamped("base", "bad", (0.0, 0.0, 0.0, 0.0))])
    buf = TfBuffer()
    assert add_tf_message(buf, msg, static=False) == 1 and buf.refused == 1
    got = buf.lookup("base", "cam", 3.5)
    np.testing.assert_allclose(got.rotation, rot_z(math.pi / 2), atol=1e-12)
    np.testing.assert_allclose(got.translation, [1.0, 2.0, 3.0])
    np.testing.assert_allclose(quaternion_matrix((0, 0, 2 * s, 2 * s)), rot_z(math.pi / 2),
                               atol=1e-12)
