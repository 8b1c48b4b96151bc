"""The handover scene as ``visualization_msgs/MarkerArray`` (``markers``), for rviz2 and
Foxglove: the gaze ray (from the ``gaze`` frame to the target), the gaze target, the giver's
hand, the giver's face, the receiver's hand and the phase as text above the head.

All in the robot's base frame (m). Each marker has a fixed namespace and id (:data:`IDS`); a
part that is not known this tick (not tracked, no target) is sent as ``DELETE`` of its id, so a
viewer never shows a stale hand.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
from rosbags.typesys.stores import ros2_jazzy as jazzy

from gazebot.io.ros2 import convert as cv

RosMarker = jazzy.visualization_msgs__msg__Marker
RosMarkerArray = jazzy.visualization_msgs__msg__MarkerArray
ColorRGBA = jazzy.std_msgs__msg__ColorRGBA
MARKER_ARRAY = RosMarkerArray.__msgtype__
#: Namespace of gazebot's markers.
NAMESPACE = "gazebot"
#: Marker id by part.
IDS = {"gaze_ray": 0, "gaze_target": 1, "giver_hand": 2, "giver_face": 3, "receiver_hand": 4,
       "phase": 5}
_COLORS = {  # RGBA
    "gaze_ray": (1.0, 0.85, 0.1, 0.9), "gaze_target": (1.0, 0.85, 0.1, 1.0),
    "giver_hand": (0.2, 0.6, 1.0, 1.0), "giver_face": (0.3, 0.9, 0.4, 1.0),
    "receiver_hand": (1.0, 0.35, 0.3, 1.0), "phase": (1.0, 1.0, 1.0, 1.0),
}
SPHERE_M = 0.06
TEXT_M = 0.08
#: Height of the phase text above the gaze origin (m).
TEXT_ABOVE_M = 0.25


@dataclass(frozen=True)
class Scene:
    """What one tick shows (base frame, m; a missing point is ``None`` or not finite).

    Attributes:
        t: Robot time (s).
        phase: The handover phase.
        gaze_origin: Origin of the ``gaze`` frame.
        target: The point looked at.
        giver_hand, giver_face, receiver_hand: Tracked points.
    """

    t: float
    phase: str
    gaze_origin: npt.ArrayLike | None
    target: npt.ArrayLike | None = None
    giver_hand: npt.ArrayLike | None = None
    giver_face: npt.ArrayLike | None = None
    receiver_hand: npt.ArrayLike | None = None


def _finite(p: npt.ArrayLike | None) -> np.ndarray | None:
    if p is None:
        return None
    a = np.asarray(p, dtype=float).reshape(-1)
    return a if a.shape == (3,) and np.all(np.isfinite(a)) else None


def _point(p: np.ndarray) -> cv.RosPoint:
    return cv.RosPoint(x=float(p[0]), y=float(p[1]), z=float(p[2]))


def _marker(scene: Scene, frame_id: str, part: str, kind: int, at: np.ndarray | None = None,
            scale: tuple[float, float, float] = (SPHERE_M,) * 3, points: list | None = None,
            text: str = "") -> RosMarker:
    """One ``ADD`` marker of ``part`` (``at``: its pose's position; identity orientation)."""
    pos = at if at is not None else np.zeros(3)
    r, g, b, a = _COLORS[part]
    return RosMarker(
        header=cv.header(scene.t, frame_id), ns=NAMESPACE, id=IDS[part], type=kind,
        action=RosMarker.ADD,
        pose=cv.RosPose(position=_point(pos), orientation=cv.Quaternion(x=0.0, y=0.0, z=0.0,
                                                                        w=1.0)),
        scale=cv.Vector3(x=scale[0], y=scale[1], z=scale[2]),
        color=ColorRGBA(r=r, g=g, b=b, a=a), lifetime=cv.to_duration(0.0), frame_locked=False,
        points=points or [], colors=[], texture_resource="",
        texture=cv.RosCompressedImage(header=cv.header(scene.t, frame_id), format="",
                                      data=np.zeros(0, dtype=np.uint8)),
        uv_coordinates=[], text=text, mesh_resource="",
        mesh_file=jazzy.visualization_msgs__msg__MeshFile(filename="",
                                                          data=np.zeros(0, dtype=np.uint8)),
        mesh_use_embedded_materials=False)


def _delete(scene: Scene, frame_id: str, part: str) -> RosMarker:
    m = _marker(scene, frame_id, part, RosMarker.SPHERE)
    m.action = RosMarker.DELETE
    return m


def marker_array(scene: Scene, frame_id: str) -> RosMarkerArray:
    """The scene's markers in ``frame_id`` (the robot's base frame)."""
    origin, target = _finite(scene.gaze_origin), _finite(scene.target)
    out: list[Any] = []  # rosbags types the field with an older distribution's Marker
    if origin is not None and target is not None:
        # An arrow from two points: scale x is the shaft diameter, y the head's, z its length.
        out.append(_marker(scene, frame_id, "gaze_ray", RosMarker.ARROW, scale=(0.01, 0.03, 0.05),
                           points=[_point(origin), _point(target)]))
    else:
        out.append(_delete(scene, frame_id, "gaze_ray"))
    for part, p in (("gaze_target", target), ("giver_hand", _finite(scene.giver_hand)),
                    ("giver_face", _finite(scene.giver_face)),
                    ("receiver_hand", _finite(scene.receiver_hand))):
        kind = RosMarker.SPHERE
        out.append(_marker(scene, frame_id, part, kind, at=p) if p is not None
                   else _delete(scene, frame_id, part))
    if origin is not None:
        above = origin + np.array([0.0, 0.0, TEXT_ABOVE_M])
        out.append(_marker(scene, frame_id, "phase", RosMarker.TEXT_VIEW_FACING, at=above,
                           scale=(TEXT_M, TEXT_M, TEXT_M), text=scene.phase))
    else:
        out.append(_delete(scene, frame_id, "phase"))
    return RosMarkerArray(markers=out)
