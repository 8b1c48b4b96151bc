"""Simulation benchmarks: the handover simulation's real-time factor against bare ``mj_step`` of
the same model, and off-screen frames per second of the handover scene (with eyes on the display)
against a plain ``mujoco.Renderer`` drawing an empty scene at the same size."""

from __future__ import annotations

import mujoco
import numpy as np

from benchmarks.common import Result, median_time

CONTROL_DT = 1.0 / 120.0
SIM_SECONDS = 4.0  # covers the giver's reach, the robot's reach and the grasp
W, H = 640, 480
EMPTY_SCENE = """
<mujoco><visual><quality offsamples="0"/></visual><worldbody>
  <light pos="0 0 3" castshadow="false"/><geom type="plane" size="3 3 0.1" rgba="0.8 0.8 0.8 1"/>
</worldbody></mujoco>
"""


def _real_time_factor() -> Result:
    from gazebot.sim.simulation import HandoverSimulation

    n_ticks = int(SIM_SECONDS / CONTROL_DT)

    repeat = 5
    # Fresh simulations built up front: only stepping is timed (warm-up + repeats).
    sims = [HandoverSimulation("sawyer", "default", seed=0) for _ in range(repeat + 1)]

    def ours() -> None:
        sim = sims.pop()
        for _ in range(n_ticks):
            sim.step(CONTROL_DT)
            sim.tracking()
            sim.robot_events()

    base = HandoverSimulation("sawyer", "default", seed=0)
    model = base.model
    n_steps = round(SIM_SECONDS / model.opt.timestep)

    def peer() -> None:
        data = mujoco.MjData(model)
        mujoco.mj_step(model, data, nstep=n_steps)

    t_ours = median_time(ours, repeat=repeat)
    t_peer = median_time(peer, repeat=repeat)
    return Result(
        name="simulation real-time factor (physics + giver + controller + tracking, 120 Hz)",
        ours=SIM_SECONDS / t_ours,
        peer=SIM_SECONDS / t_peer,
        unit="x real time",
        peer_name="bare mj_step of the same model",
        higher_is_better=True,
        note=f"{SIM_SECONDS:g} s simulated",
    )


def _render_fps() -> Result:
    from gazebot.sim.simulation import HandoverSimulation

    sim = HandoverSimulation("sawyer", "default", seed=0)
    for _ in range(int(3.0 / CONTROL_DT)):  # mid-handover: arm out, object in hand
        sim.step(CONTROL_DT)
    yaws = np.linspace(-0.3, 0.3, 8)
    state = {"i": 0}

    def ours() -> None:
        state["i"] += 1
        sim.apply_eyes(float(yaws[state["i"] % len(yaws)]), 0.2)  # new eyes every frame
        sim.render(width=W, height=H)

    empty = mujoco.MjModel.from_xml_string(EMPTY_SCENE)
    data = mujoco.MjData(empty)
    mujoco.mj_forward(empty, data)
    renderer = mujoco.Renderer(empty, H, W)

    def peer() -> None:
        renderer.update_scene(data)
        renderer.render()

    t_ours = median_time(ours, repeat=7, number=5)
    t_peer = median_time(peer, repeat=7, number=5)
    sim.close()
    renderer.close()
    return Result(
        name=f"off-screen render {W}x{H} (handover scene + eye texture upload)",
        ours=1.0 / t_ours,
        peer=1.0 / t_peer,
        unit="frames/s",
        peer_name="mujoco.Renderer, empty scene",
        higher_is_better=True,
        note=f"{t_ours * 1e3:.1f} ms vs {t_peer * 1e3:.1f} ms per frame",
    )


def run() -> list[Result]:
    return [_real_time_factor(), _render_fps()]
