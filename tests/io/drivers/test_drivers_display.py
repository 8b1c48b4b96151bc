"""``gazebot display`` on the bus: the pupils follow the engine's eye state, the eyes go neutral
when it falls silent and follow again when it returns; with ``gazebot sim --with-engine`` the
recording runs at 30 frames/s."""

from __future__ import annotations

import threading
import time

import numpy as np
import pytest
from drivers_fakes import wait_until

from gazebot.io.ros2.values import EyeState

pytestmark = pytest.mark.zenoh


def pupil_u(img: np.ndarray, renderer, v: float = 0.0) -> float:
    """Measured horizontal pupil offset (px) of the image-left eye: the centroid of the dark
    pixels on the row through the pupil's center, within the white of the eye."""
    g = renderer.eyes[0]
    row = img[int(round(g.cy + v))].astype(int).sum(axis=1)
    xs = np.arange(img.shape[1])
    inside = np.abs(xs - g.cx) < 0.95 * g.a
    dark = inside & (row < 200)
    assert dark.any(), "no pupil on the row"
    return float(xs[dark].mean() - g.cx)


class LoggingScreen:
    """The real head screen, logging what each frame showed; closes when told to."""

    def __init__(self, screen) -> None:
        self.screen = screen
        self.size = screen.size
        self.shown: list = []
        self.stop = threading.Event()

    def show(self, pose, status) -> None:
        self.screen.show(pose, status)
        self.shown.append((pose, status, self.screen.image().copy()))

    def image(self):
        return self.screen.image()

    def closed(self) -> bool:
        return self.stop.is_set()


def test_pupils_follow_the_eye_state_go_neutral_in_silence_and_recover(bus, tmp_path):
    from gazebot.apps.cli.display import run_display
    from gazebot.apps.render import EyeRenderer
    from gazebot.apps.render.head_display import EyeAnimator, EyeAnimatorConfig, HeadScreen
    from gazebot.apps.render.video import open_h264_writer
    from gazebot.io.drivers.zenoh_display import ZenohDisplayNode

    renderer = EyeRenderer.for_robot("jaco2")
    node = ZenohDisplayNode(bus.connector(), bus.names)
    bus.closers.append(node.close)
    from gazebot.io.drivers.rmw.node import RosNode
    from gazebot.io.ros2 import convert, topics

    publisher = RosNode(bus.listener(), bus.names, "fake_engine")
    bus.closers.append(publisher.close)
    eyes_pub = publisher.publisher(topics.EYES.name, topics.EYES.type)
    screen = LoggingScreen(HeadScreen(renderer))
    anim = EyeAnimator(EyeAnimatorConfig(silent_after=0.3, neutral_s=0.2, drift_deg=0.3))
    yaw = {"value": 0.3, "on": True}

    def publish() -> None:
        seq = 0
        while not screen.stop.is_set():
            if yaw["on"]:
                eyes_pub.publish(convert.eye_state(
                    EyeState(seq / 100, yaw=yaw["value"], pitch=0.0), "gaze"))
                seq += 1
            time.sleep(0.01)

    out = tmp_path / "display.mp4"
    result: dict = {}
    with open_h264_writer(out, 30.0, screen.size) as writer:
        loop = threading.Thread(
            target=lambda: result.update(run_display(node, screen, anim, 30.0, None, writer,
                                                     key="k", robot="jaco2")),
            daemon=True)
        pub = threading.Thread(target=publish, daemon=True)
        pub.start()
        loop.start()

        def count(pred):
            return sum(1 for pose, _, _ in screen.shown if pred(pose))

        try:
            assert wait_until(lambda: count(lambda p: p.state == "live" and p.yaw > 0.2) >= 10,
                              timeout=30)
            yaw["value"] = -0.3
            assert wait_until(lambda: count(lambda p: p.state == "live" and p.yaw < -0.2) >= 10,
                              timeout=30)
            yaw["on"] = False  # the engine falls silent
            assert wait_until(lambda: count(lambda p: p.state == "silent"
                                            and abs(p.yaw) < 0.02) >= 10, timeout=30)
            yaw.update(value=0.25, on=True)  # and comes back
            assert wait_until(lambda: count(lambda p: p.state == "live" and p.yaw > 0.2) >= 20,
                              timeout=30)
        finally:
            screen.stop.set()
            loop.join(timeout=10)
            pub.join(timeout=5)
            screen.screen.close()
    states = [pose.state for pose, _, _ in screen.shown]
    first_silent = states.index("silent")
    assert "live" in states[first_silent:]  # recovered
    assert any("engine silent" in status for _, status, _ in screen.shown)
    for pose, _, img in screen.shown:
        if pose.blink > 0.05:
            continue
        (u, _), _ = renderer.pupil_offsets(pose.yaw, pose.pitch, pose.distance)
        assert pupil_u(img, renderer, v=renderer.pupil_offsets(pose.yaw, pose.pitch)[0][1]) \
            == pytest.approx(u, abs=3.0), pose
    assert result["video_frames"] == writer.frames >= result["frames"]
    assert out.stat().st_size > 0


def test_display_records_30_frames_a_second_of_sim_with_engine_and_pupils_follow(
    bus, tmp_path, monkeypatch
):
    import imageio
    from drivers_fakes import Recorder

    from gazebot.apps.cli import display, main
    from gazebot.apps.render import EyeRenderer
    from gazebot.io.drivers.sim_node import SimNode
    from gazebot.io.drivers.zenoh_node import ZenohNode
    from gazebot.io.ros2 import convert, topics

    # The six seconds of the recording fall within the nine of the scene, however long either
    # command takes to start on a loaded machine: the display's loop (and its six seconds)
    # starts with the first eye state it receives, and the scene only once the display's
    # loop is about to start and the simulator sees the display on the bus.
    display_ready = threading.Event()
    run_display, run_sim = display.run_display, SimNode.run

    def display_from_the_first_eye_state(node, *args, **kwargs):
        display_ready.set()
        assert wait_until(lambda: node.received, timeout=60)
        return run_display(node, *args, **kwargs)

    def sim_once_the_display_listens(self, *args, **kwargs):
        def listening() -> bool:
            self.publish_state()  # the simulator's heartbeat and pose while it waits
            return display_ready.is_set() and bool(self.endpoint.peers().get("display"))

        assert wait_until(listening, timeout=60, poll=0.1)
        return run_sim(self, *args, **kwargs)

    monkeypatch.setattr(display, "run_display", display_from_the_first_eye_state)
    monkeypatch.setattr(SimNode, "run", sim_once_the_display_listens)
    watcher = ZenohNode(bus.connector(), bus.names, "watcher")
    bus.closers.append(watcher.close)
    sent = Recorder(watcher, topics.EYES, convert.eyes_of).msgs
    sim_args = ["sim", "--with-engine", "--headless", "--namespace", bus.names.namespace,
                "--listen",
                bus.endpoint, "--duration", "9", "--seed", "1"]
    sim_thread = threading.Thread(target=main, args=(sim_args,), daemon=True)
    sim_thread.start()
    out = tmp_path / "out.mp4"
    rc = main(["display", "--robot", "sawyer", "--namespace", bus.names.namespace,
               "--connect", bus.endpoint,
               "--duration", "6", "--record", str(out), "--json"])
    sim_thread.join(timeout=60)
    assert rc == 0
    reader = imageio.get_reader(out)
    assert reader.get_meta_data()["fps"] == pytest.approx(30.0)
    # Which of the poses the engine sent does a recorded frame show? Its best match among
    # renders of every distinct sent pose, on the image-left eye.
    renderer = EyeRenderer.for_robot("sawyer")
    g = renderer.eyes[0]
    box = (slice(int(g.cy - g.b), int(g.cy + g.b)), slice(int(g.cx - g.a), int(g.cx + g.a)))
    frames, n = [], 0
    for i, f in enumerate(reader):
        n += 1
        if i % 6 == 0:
            frames.append(f[box].copy())
    assert n == 180  # 6 s at 30 frames/s: the recording is real time
    poses = {(round(m.yaw, 2), round(m.pitch, 2)): m for m in sent if m.blink == 0.0}
    assert len(poses) > 5
    renders = {k: renderer.render(m.yaw, m.pitch, 0.0, m.distance)[box].astype(np.int16)
               for k, m in poses.items()}
    matched = []
    for f in frames:
        eye = f.astype(np.int16)
        err, key = min((float(np.abs(eye - r).mean()), k) for k, r in renders.items())
        matched.append((err, key))
    good = [key for err, key in matched if err < 6.0]  # H.264 and the eyes' own drift
    assert len(good) >= 0.7 * len(matched)  # the others: blinks, and moves between poses
    pitches = [pitch for _, pitch in good]
    # the pupils were seen up at the face and down at the hand, as the engine sent them
    assert min(pitches) < -0.05 and max(pitches) > 0.2, matched


class _StubNode:
    """A display node that never heard the engine."""

    received = 0

    def latest(self):
        return None, float("inf")

    def status(self, eyes, info) -> None:
        pass


class _CountingScreen:
    closed_after: int | None = None

    def __init__(self) -> None:
        self.size = (4, 4)
        self.shown = 0

    def show(self, pose, status) -> None:
        self.shown += 1

    def image(self):
        return np.full((4, 4, 3), self.shown, np.uint8)

    def closed(self) -> bool:
        return False


class _ListWriter(list):
    append = list.append


def _stepping_clock(times):
    """A clock returning ``times`` one after the other: where the display loop finds itself
    each time it looks, as on a machine too busy to keep its slots."""
    it = iter(times)
    return lambda: next(it)


def test_a_recording_ended_by_duration_lasts_that_long_even_when_the_loop_ran_late():
    from gazebot.apps.cli.display import run_display
    from gazebot.apps.render.head_display import EyeAnimator, EyeAnimatorConfig

    screen, writer = _CountingScreen(), _ListWriter()
    # start 0; iterations at 0.0, 0.5 and 0.75 s (each looking twice: slot, then sleep);
    # then woken only at 1.4 s, past the 1 s end: the loop itself never began the last slots.
    clock = _stepping_clock([0.0, 0.0, 0.0, 0.5, 0.5, 0.75, 0.75, 1.4, 1.4])
    summary = run_display(_StubNode(), screen, EyeAnimator(EyeAnimatorConfig()), 10.0, 1.0,
                          writer, clock=clock)
    assert len(writer) == summary["video_frames"] == 10  # 1 s at 10 frames/s
    assert summary["frames"] == 3 and summary["repeated_frames"] == 7
    # each slot shows the image drawn when it began (or the newest one before it)
    assert [int(f[0, 0, 0]) for f in writer] == [1, 2, 2, 2, 2, 2, 3, 3, 3, 3]
