"""Simulation benchmarks: the handover simulation's real-time factor against bare ``mj_step`` of
the same model, and off-screen frames per second of the handover scene with new eyes on the display
every frame (eye drawing + texture upload + render + read-back) against a plain ``mujoco.Renderer``
drawing the same model and state from the same camera at the same size (no eye texture upload);
and the simulation with the seed's MCE / STL reach controllers against the joint-space reach."""

from __future__ import annotations

import mujoco
import numpy as np

from benchmarks.common import Result, median_time

CONTROL_DT = 1.0 / 120.0
SIM_SECONDS = 4.0  # covers the giver's reach, the robot's reach and the grasp
W, H = 640, 480


def _real_time_factor() -> Result:
    from gazebot.apps.sim.simulation import HandoverSimulation

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
    from gazebot.apps.sim.simulation import HandoverSimulation

    sim = HandoverSimulation("sawyer", "default", seed=0)
    for _ in range(int(3.0 / CONTROL_DT)):  # mid-handover: arm out, object in hand
        sim.step(CONTROL_DT)
    yaws = np.linspace(-0.3, 0.3, 8)
    state = {"i": 0}

    def ours() -> None:
        state["i"] += 1
        sim.apply_eyes(float(yaws[state["i"] % len(yaws)]), 0.2)  # new eyes every frame
        sim.render(width=W, height=H)

    from gazebot.apps.sim.scene import OBSERVER

    # The same handover model and state, seen by the same camera, with whatever the display
    # texture holds (no eyes drawn, no texture upload).
    renderer = mujoco.Renderer(sim.model, H, W)

    def peer() -> None:
        renderer.update_scene(sim.data, OBSERVER)
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
        peer_name="plain mujoco.Renderer, same model/state/camera, no eye upload",
        higher_is_better=True,
        note=f"{t_ours * 1e3:.1f} ms vs {t_peer * 1e3:.1f} ms per frame",
    )


def _cartesian_reach_rtf(controller: str) -> Result:
    """The simulation with one of the seed's reach controllers (planning every 0.2 s, arm
    differential IK every tick) against the joint-space reach of the same handover."""
    from gazebot.apps.sim.scene_config import SceneConfig, load_scene
    from gazebot.apps.sim.simulation import HandoverSimulation

    data = load_scene("default").model_dump()
    data["controller"].update(reach_controller=controller, reach_time_s=2.5)
    scene = SceneConfig.model_validate(data)
    n_ticks = int(SIM_SECONDS / CONTROL_DT)
    repeat = 3

    def runner(spec):
        sims = [HandoverSimulation("sawyer", spec, seed=0) for _ in range(repeat + 1)]

        def go() -> None:
            sim = sims.pop()
            for _ in range(n_ticks):
                sim.step(CONTROL_DT)

        return go

    t_ours = median_time(runner(scene), repeat=repeat)
    t_peer = median_time(runner("default"), repeat=repeat)
    return Result(
        name=f"simulation with the {controller} reach (plan every 0.2 s + arm IK at 120 Hz)",
        ours=SIM_SECONDS / t_ours,
        peer=SIM_SECONDS / t_peer,
        unit="x real time",
        peer_name="the joint-space reach, same handover",
        higher_is_better=True,
        note=f"{SIM_SECONDS:g} s simulated",
    )


def run() -> list[Result]:
    return [
        _real_time_factor(),
        _cartesian_reach_rtf("mce"),
        _cartesian_reach_rtf("stl"),
        _render_fps(),
    ]
