"""``gazebot sim``: a MuJoCo handover simulation as a node on the Zenoh bus (optionally with the
gaze engine in the same process)."""

from __future__ import annotations

import argparse
import json
import sys
import threading
from typing import Any

from gazebot.apps.cli.argtypes import positive, seed_value
from gazebot.apps.cli.bus import (
    add_bus_arguments,
    add_record_argument,
    bus_config,
    robot_base_frame,
)
from gazebot.apps.cli.choices import (
    add_behavior_argument,
    add_gaze_mode_argument,
    add_robot_argument,
    add_scene_argument,
)
from gazebot.apps.cli.errors import UsageError, robot_with_gaze_mode
from gazebot.apps.cli.mcap import add_record_split_arguments, record_split
from gazebot.apps.render.video_settings import VIDEO
from gazebot.core.defaults import DEFAULT_BEHAVIOR

#: How long (s) ``gazebot sim`` waits by default for an engine to own the robot.
WAIT_TIMEOUT_S = 60.0


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "sim",
        help="run a simulated robot (MuJoCo) on the Zenoh bus",
        description="Simulate a handover in MuJoCo and serve it on the bus: tracking at 120 Hz, "
        "joint states, robot events, heartbeat; obeys head, eye and arm commands.",
    )
    add_robot_argument(p)
    add_scene_argument(p)
    p.add_argument(
        "--seed", type=seed_value, default=0, help="seed of the giver and the tracking noise"
    )
    p.add_argument("--with-engine", action="store_true", help="run a gaze engine in-process too")
    add_behavior_argument(p, default=DEFAULT_BEHAVIOR, what="behavior of --with-engine")
    add_gaze_mode_argument(p)
    p.add_argument("--headless", action="store_true", help="no window")
    p.add_argument(
        "--eye-frames",
        action="store_true",
        help="show the engine's rendered eye frames on the display (eyes/image/compressed) "
        "instead of drawing the eyes from the eye state",
    )
    p.add_argument("--duration", type=positive, default=None,
                   help="simulated seconds to run (default: until Ctrl-C)")
    p.add_argument("--speed", type=positive, default=1.0,
                   help="simulated seconds per real second (default 1: real time)")
    p.add_argument(
        "--no-wait",
        action="store_true",
        help="start the scene at once (default: its clock starts once an engine owns the "
        "robot, so an engine started later still sees the whole handover)",
    )
    p.add_argument(
        "--wait-timeout",
        type=positive,
        default=WAIT_TIMEOUT_S,
        metavar="S",
        help=f"seconds to wait for an engine before giving up with status 2 "
        f"(default {WAIT_TIMEOUT_S:g})",
    )
    p.add_argument("--json", action="store_true", help="print a JSON summary at the end")
    add_bus_arguments(p, listens_by_default=True)
    add_record_argument(p)
    add_record_split_arguments(p)
    p.set_defaults(func=handle)


class PygameView:
    """A window showing the observer camera (needs a display)."""

    def __init__(self, width: int = VIDEO.width, height: int = VIDEO.height) -> None:
        import os

        os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
        import pygame

        self.pygame = pygame
        self.size = (width, height)
        try:
            pygame.display.init()
            driver = pygame.display.get_driver()
            if driver in ("dummy", "offscreen"):
                raise pygame.error(f"no display (SDL video driver {driver!r})")
            self.screen = pygame.display.set_mode(self.size)
        except pygame.error as exc:
            pygame.display.quit()
            raise UsageError(f"cannot open a window ({exc}); use --headless") from exc
        pygame.display.set_caption("gazebot sim")

    def __call__(self, sim: Any) -> bool:
        pg = self.pygame
        for event in pg.event.get():
            if event.type == pg.QUIT:
                return False
        img = sim.render("observer", *self.size)
        self.screen.blit(pg.surfarray.make_surface(img.swapaxes(0, 1)), (0, 0))
        pg.display.flip()
        return True

    def close(self) -> None:
        self.pygame.display.quit()


def handle(args: argparse.Namespace) -> int:
    from gazebot.apps.render import LazyEyeRenderer
    from gazebot.apps.sim import HandoverSimulation
    from gazebot.io.drivers.sim_node import SimNode, SimNodeConfig
    from gazebot.io.drivers.zenoh_robot import ZenohRobotEndpoint

    cfg = bus_config(args, listens_by_default=True, base_frame=robot_base_frame(args.robot))
    view = sim = endpoint = driver = engine_node = thread = recorder = None
    stop = threading.Event()
    summary: dict[str, Any] = {}
    engine_error: list[str] = []  # why the in-process engine stopped, if it did
    waited_out = False  # no engine came within --wait-timeout

    def run_engine(node: Any) -> None:
        # The engine node survives what its inputs cause; if it stops anyway, the simulation
        # must not run on without gaze: stop it and say why.
        try:
            node.run(stop=stop)
        except Exception as exc:
            engine_error.append(" ".join(f"{type(exc).__name__}: {exc}".split())[:300])
            stop.set()
    try:
        view = None if args.headless else PygameView()
        sim = HandoverSimulation(args.robot, args.scene, seed=args.seed)
        endpoint = ZenohRobotEndpoint.open(cfg, "sim", eye_frames=args.eye_frames)
        if args.record:
            from gazebot.io.drivers.recorder import BusRecorder

            recorder = BusRecorder(endpoint.session, cfg.names, args.record,
                                   split=record_split(args))
        node = SimNode(sim, endpoint, SimNodeConfig(speed=args.speed), view=view)
        node.publish_state()
        if args.with_engine:
            from gazebot.core.runtime import GazeLoop
            from gazebot.io.drivers.engine_node import EngineNode
            from gazebot.io.drivers.zenoh_driver import ZenohRobotDriver

            driver = ZenohRobotDriver(endpoint.session, cfg.names, "engine")

            robot = robot_with_gaze_mode(args.robot, args.gaze_mode)
            loop = GazeLoop.from_config(robot, args.behavior, seed=args.seed)
            engine_node = EngineNode(loop, driver, eye_renderer=LazyEyeRenderer(loop.robot.name))
            thread = threading.Thread(target=run_engine, args=(engine_node,),
                                      name="engine-node", daemon=True)
            thread.start()
            # Start the handover once the engine listens (and has taken the head pose).
            for _ in range(600):
                if engine_node.ready.wait(0.1) or not thread.is_alive():
                    break
            else:
                raise TimeoutError("the in-process engine node did not start within 60 s")
        print(
            f"gazebot sim: robot {sim.robot.name} scene {args.scene} under {cfg.names.namespace} "
            f"(ROS domain {cfg.names.domain_id}) "
            f"(listen {list(cfg.listen)}, connect {list(cfg.connect)})"
            + (f", engine '{args.behavior}' in-process" if args.with_engine else ""),
            file=sys.stderr,
        )
        if not (args.with_engine or args.no_wait):
            print(f"gazebot sim: waiting up to {args.wait_timeout:g} s for a gaze engine "
                  "(gazebot run) to own the robot; the scene starts then", file=sys.stderr)
            waited_out = not node.wait_for_engine(args.wait_timeout, stop)
        try:
            rtf = float("nan") if waited_out else node.run(duration=args.duration, stop=stop)
        except KeyboardInterrupt:
            rtf = float("nan")
        summary = {
            "robot": sim.robot.name,
            "scene": args.scene,
            "t": round(sim.t, 4),
            "ticks": node.ticks,
            "real_time_factor": round(rtf, 3) if rtf == rtf else None,
            "handover_done": bool(sim.done),
            "applied": node.applied,
            "rejected": node.rejected,
            "dropped": endpoint.dropped(),
        }
    finally:
        stop.set()
        if thread is not None:
            thread.join(timeout=5)
        if recorder is not None:
            path = recorder.close()  # before the session closes
            if summary:
                summary["recorded"] = {"file": str(path), "messages": recorder.messages,
                                       "files": [str(f) for f in recorder.files]}
        if engine_node is not None and summary:
            summary["engine"] = {
                "frames": engine_node.frames_processed,
                "commands": engine_node.commands_sent,
                "phase": engine_node.phase,
            }
        for closable in (driver, endpoint, sim, view):  # sim before the window: shared GL
            if closable is not None:
                closable.close()
    if waited_out:
        print(f"gazebot sim: error: no gaze engine owned the robot under {cfg.names.namespace} "
              f"within {args.wait_timeout:g} s: start `gazebot run` on the same bus (or use "
              "--with-engine, or --no-wait to start the scene anyway)", file=sys.stderr)
        return 2
    if engine_error:
        print(f"gazebot sim: error: the in-process engine stopped ({engine_error[0]}); "
              "the simulation stopped with it", file=sys.stderr)
    print(json.dumps(summary) if args.json else _text(summary))
    return 1 if engine_error else 0


def _text(summary: dict[str, Any]) -> str:
    return "\n".join(f"{k}: {v}" for k, v in summary.items())
