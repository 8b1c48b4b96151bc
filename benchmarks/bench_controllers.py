"""Reach controllers (seed chapters 3-4): solve time per control step against the control period
(the budget every step must fit in; ratio = headroom), on the seed's Fig. 4.4 reach (hand 1.5 m
away, u_max 1 m/s per axis, dt 0.2 s, H 15, t_1 = 3 s), plus the STL MILP at H = 16 with 3
inputs beside the seed's figure ("approximately 0.5 s for a prediction horizon of 16 time-steps
and 3 control inputs", MATLAB/BluSTL, 4.4.4). Medians over every step of the closed-loop run."""

from __future__ import annotations

import statistics

import numpy as np

from benchmarks.common import Result

SEED_MILP_MS = 500.0


def _solve_ms(name: str, horizon: int | None = None, reach_time: float = 3.0) -> float:
    from gazebot.controllers import load_controllers_config, make_controller
    from gazebot.controllers.rollout import run_reach

    cfg = load_controllers_config()
    update: dict = {"reach_time_s": reach_time, "u_max_m_s": 1.0, "dt_s": 0.2}
    if horizon is not None:
        update["stl"] = cfg.stl.model_copy(update={"horizon": horizon})
    cfg = cfg.model_copy(update=update)
    controller = make_controller(name, cfg)
    run_reach(controller, np.zeros(3), np.array([1.5, 0, 0]), 1.0)  # warm-up: build problems
    samples: list[float] = []
    for _ in range(3):
        run = run_reach(controller, np.zeros(3), np.array([1.5, 0, 0]), reach_time + 1.0)
        samples.extend(run.solve_ms.tolist())
    return statistics.median(samples)


def run() -> list[Result]:
    period_ms = 200.0
    out = []
    for name in ("pv", "mcj", "mce", "stl"):
        out.append(
            Result(
                name=f"{name} solve per control step",
                ours=_solve_ms(name),
                peer=period_ms,
                unit="ms",
                peer_name="control period dt = 0.2 s",
            )
        )
    out.append(
        Result(
            name="stl MILP, H = 16, 3 inputs",
            ours=_solve_ms("stl", horizon=16),
            peer=SEED_MILP_MS,
            unit="ms",
            peer_name="seed 4.4.4, MATLAB BluSTL (quoted, not measured here)",
        )
    )
    return out
