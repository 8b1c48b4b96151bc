"""A transform buffer fed by ``/tf`` and ``/tf_static``, as tf2 keeps one: each frame has one
parent, so the frames form a tree and a transform between any two frames of the same tree is
the chain through their common ancestor.

Static transforms (``/tf_static``) hold at every time. Dynamic ones (``/tf``) are kept for
``cache_s`` seconds of their own stamps (at most ``max_per_frame`` per frame) and looked up at a
time: between two kept stamps the transform is interpolated (position linearly, rotation by
slerp); after the newest the newest holds for at most ``hold_s`` (a sample stamped a little
after the last ``/tf`` of a moving frame), and before the oldest or further after the newest
there is no transform: the buffer never extrapolates. A frame id's leading ``/`` is ignored
(ROS 1 style ids name the same frame). At most ``max_frames`` frames are kept: a transform for
a new frame beyond them is refused (counted in ``refused``).
"""

from __future__ import annotations

import bisect
import math
import threading
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from gazebot.io.drivers.rmw.node import Received, RosNode
from gazebot.io.ros2 import topics
from gazebot.io.ros2.convert import RosTFMessage

#: Seconds of dynamic transforms kept per frame (tf2's default cache time).
CACHE_S = 10.0
#: Seconds the newest dynamic transform of a frame holds after its stamp.
HOLD_S = 0.1


class TransformError(LookupError):
    """No transform between two frames (unknown frame, other tree, or not at that time)."""


@dataclass(frozen=True)
class Transform:
    """A rigid transform: a point ``p`` in the child frame is ``rotation @ p + translation`` in
    the parent frame (m; ``rotation`` 3x3)."""

    translation: np.ndarray
    rotation: np.ndarray

    def apply(self, point: np.ndarray) -> np.ndarray:
        """``point`` (3,) in the child frame, expressed in the parent frame."""
        return self.rotation @ np.asarray(point, dtype=float) + self.translation

    def compose(self, inner: Transform) -> Transform:
        """``self * inner``: first ``inner`` (child of child -> child), then ``self``."""
        return Transform(self.rotation @ inner.translation + self.translation,
                         self.rotation @ inner.rotation)

    def inverse(self) -> Transform:
        """The transform from the parent frame to the child frame."""
        rt = self.rotation.T
        return Transform(-rt @ self.translation, rt)


IDENTITY = Transform(np.zeros(3), np.eye(3))


def frame_name(frame_id: str) -> str:
    """A frame id as the buffer keys it (leading ``/`` dropped)."""
    return frame_id.lstrip("/")


def quaternion_matrix(xyzw: Iterable[float]) -> np.ndarray:
    """The rotation matrix of a quaternion ``(x, y, z, w)`` (normalised here).

    Raises:
        ValueError: the quaternion is not finite or has no length.
    """
    q = np.asarray(list(xyzw), dtype=float)
    n = float(np.linalg.norm(q)) if q.shape == (4,) else math.nan
    if not (math.isfinite(n) and n > 1e-9):
        raise ValueError(f"a finite non-zero quaternion (x, y, z, w), got {q.tolist()}")
    x, y, z, w = q / n
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def _slerp(a: np.ndarray, b: np.ndarray, s: float) -> np.ndarray:
    """Rotation ``s`` (0..1) of the way from matrix ``a`` to matrix ``b`` (about the axis of
    ``a.T @ b``)."""
    rel = a.T @ b
    cos = max(-1.0, min(1.0, (float(np.trace(rel)) - 1.0) / 2.0))
    angle = math.acos(cos)
    if angle < 1e-9:
        return a
    axis = np.array([rel[2, 1] - rel[1, 2], rel[0, 2] - rel[2, 0], rel[1, 0] - rel[0, 1]])
    norm = float(np.linalg.norm(axis))
    if norm < 1e-9:  # a half turn: the axis from the symmetric part
        sym = (rel + np.eye(3)) / 2.0
        axis = sym[:, int(np.argmax(np.diag(sym)))]
        norm = float(np.linalg.norm(axis))
    k = axis / norm
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    phi = s * angle
    return a @ (np.eye(3) + math.sin(phi) * K + (1.0 - math.cos(phi)) * (K @ K))


@dataclass
class _Edge:
    """A frame's link to its parent: static, or dynamic with stamped transforms."""

    parent: str
    static: Transform | None
    stamps: list[float]
    transforms: list[Transform]


class TfBuffer:
    """Transforms between frames from ``/tf`` and ``/tf_static`` (thread-safe).

    Args:
        cache_s: Seconds of dynamic transforms kept per frame.
        hold_s: Seconds the newest dynamic transform of a frame holds after its stamp.
        max_frames: Most frames kept.
        max_per_frame: Most dynamic transforms kept per frame.
    """

    def __init__(self, cache_s: float = CACHE_S, hold_s: float = HOLD_S,
                 max_frames: int = 10_000, max_per_frame: int = 10_000) -> None:
        if not (cache_s > 0 and hold_s >= 0 and max_frames > 0 and max_per_frame > 0):
            raise ValueError("cache_s > 0, hold_s >= 0, max_frames > 0 and max_per_frame > 0")
        self.cache_s = cache_s
        self.hold_s = hold_s
        self.max_frames = max_frames
        self.max_per_frame = max_per_frame
        self.refused = 0
        self._edges: dict[str, _Edge] = {}
        self._lock = threading.Lock()

    def add(self, parent: str, child: str, t: float, transform: Transform,
            static: bool = False) -> bool:
        """Keep ``transform`` (``child`` in ``parent``) stamped ``t`` (s); a static one holds
        at every time. A child given a new parent (or switching between static and dynamic)
        drops its earlier transforms. Returns whether it was kept (refused: a self-loop, a
        non-finite value, a new frame beyond ``max_frames``, a stamp older than the newest kept
        of its frame)."""
        parent, child = frame_name(parent), frame_name(child)
        ok = (parent != child and math.isfinite(t)
              and bool(np.all(np.isfinite(transform.translation)))
              and bool(np.all(np.isfinite(transform.rotation))))
        with self._lock:
            edge = self._edges.get(child)
            if ok and edge is None and len(self._edges) >= self.max_frames:
                ok = False
            if not ok:
                self.refused += 1
                return False
            if edge is None or edge.parent != parent or (edge.static is not None) != static:
                edge = self._edges[child] = _Edge(parent, None, [], [])
            if static:
                edge.static = transform
                return True
            if edge.stamps and t < edge.stamps[-1]:
                self.refused += 1  # /tf keeps each frame's order; an older stamp is stale
                return False
            if edge.stamps and t == edge.stamps[-1]:
                edge.transforms[-1] = transform
                return True
            edge.stamps.append(t)
            edge.transforms.append(transform)
            cut = bisect.bisect_left(edge.stamps, t - self.cache_s)
            cut = max(cut, len(edge.stamps) - self.max_per_frame)
            if cut > 0:
                del edge.stamps[:cut], edge.transforms[:cut]
            return True

    def refuse(self) -> None:
        """Count a transform refused before it reached :meth:`add` (a bad quaternion)."""
        with self._lock:
            self.refused += 1

    def frames(self) -> set[str]:
        """Every frame known (as a child or a parent)."""
        with self._lock:
            return set(self._edges) | {e.parent for e in self._edges.values()}

    def lookup(self, target: str, source: str, t: float | None = None) -> Transform:
        """The transform taking points in ``source`` to ``target`` at time ``t`` (s; ``None``:
        each link's newest transform).

        Raises:
            TransformError: a frame is unknown, the two are in different trees, or a dynamic
                link has no transform at ``t`` (before its oldest kept, or more than ``hold_s``
                after its newest).
        """
        target, source = frame_name(target), frame_name(source)
        if target == source:
            return IDENTITY
        with self._lock:
            up_source = self._chain(source)
            up_target = self._chain(target)
            roots = {f for f, _ in up_source} | {source}
            common = next((f for f in [target, *(p for p, _ in up_target)] if f in roots), None)
            if common is None:
                known = set(self._edges) | {e.parent for e in self._edges.values()}
                missing = [f for f in (source, target) if f not in known]
                what = (f"no transform for frame {missing[0]!r}" if missing
                        else f"frames {source!r} and {target!r} are not connected")
                raise TransformError(what)
            to_common = self._compose(source, common, t)
            target_to_common = self._compose(target, common, t)
        return target_to_common.inverse().compose(to_common)

    def _chain(self, frame: str) -> list[tuple[str, _Edge]]:
        """``(parent, edge)`` from ``frame`` up to its tree's root (a loop ends the walk)."""
        out: list[tuple[str, _Edge]] = []
        seen = {frame}
        edge = self._edges.get(frame)
        while edge is not None and edge.parent not in seen:
            out.append((edge.parent, edge))
            seen.add(edge.parent)
            edge = self._edges.get(edge.parent)
        return out

    def _compose(self, frame: str, ancestor: str, t: float | None) -> Transform:
        """``frame`` -> ``ancestor`` (an ancestor of ``frame`` or ``frame`` itself)."""
        out = IDENTITY
        while frame != ancestor:
            edge = self._edges[frame]
            out = self._at(frame, edge, t).compose(out)
            frame = edge.parent
        return out

    def _at(self, child: str, edge: _Edge, t: float | None) -> Transform:
        if edge.static is not None:
            return edge.static
        stamps = edge.stamps
        if not stamps:
            raise TransformError(f"no transform for frame {child!r}")
        if t is None or t == stamps[-1]:
            return edge.transforms[-1]
        if t > stamps[-1]:
            if t - stamps[-1] <= self.hold_s:
                return edge.transforms[-1]
            raise TransformError(
                f"frame {child!r} in {edge.parent!r}: newest transform at {stamps[-1]:.3f} s, "
                f"{t - stamps[-1]:.3f} s before the lookup time {t:.3f} s (no extrapolation)")
        i = bisect.bisect_right(stamps, t)
        if i == 0:
            raise TransformError(
                f"frame {child!r} in {edge.parent!r}: lookup time {t:.3f} s is before the "
                f"oldest transform kept ({stamps[0]:.3f} s)")
        t0, t1 = stamps[i - 1], stamps[i]
        a, b = edge.transforms[i - 1], edge.transforms[i]
        s = (t - t0) / (t1 - t0)
        return Transform(a.translation + s * (b.translation - a.translation),
                         _slerp(a.rotation, b.rotation, s))

    def transform_point(self, target: str, source: str, point: np.ndarray,
                        t: float | None = None) -> np.ndarray:
        """``point`` (3,) in ``source`` expressed in ``target`` at time ``t`` (see
        :meth:`lookup`)."""
        return self.lookup(target, source, t).apply(point)


def add_tf_message(buffer: TfBuffer, msg: RosTFMessage, static: bool) -> int:
    """Keep every transform of a ``tf2_msgs/TFMessage`` in ``buffer``; returns how many were
    kept (one with a bad quaternion or a non-finite value is refused, counted there)."""
    kept = 0
    for tf in msg.transforms:
        tr, q = tf.transform.translation, tf.transform.rotation
        try:
            rotation = quaternion_matrix((q.x, q.y, q.z, q.w))
        except ValueError:
            buffer.refuse()
            continue
        stamp = tf.header.stamp
        kept += buffer.add(str(tf.header.frame_id), str(tf.child_frame_id),
                           float(stamp.sec) + 1e-9 * float(stamp.nanosec),
                           Transform(np.array([tr.x, tr.y, tr.z], dtype=float), rotation),
                           static=static)
    return kept


def listen(ros: RosNode, buffer: TfBuffer) -> None:
    """Feed ``buffer`` from ``/tf`` and ``/tf_static`` (transient local: the static frames the
    stack published before this node started arrive too) as ``ros`` receives them."""
    def dynamic(msg: RosTFMessage, rx: Received) -> None:
        add_tf_message(buffer, msg, static=False)

    def static(msg: RosTFMessage, rx: Received) -> None:
        add_tf_message(buffer, msg, static=True)

    ros.subscription(topics.TF.name, topics.TF.type, dynamic)
    ros.subscription(topics.TF_STATIC.name, topics.TF_STATIC.type, static)
