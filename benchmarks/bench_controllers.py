"""Reach controllers (seed chapters 3-4): solve time per control step against the control period
(the budget every step must fit in; ratio = headroom), on the seed's Fig. 4.4 reach (hand 1.5 m
away, u_max 1 m/s per axis, dt 0.2 s, H 15, t_1 = 3 s); the STL step MILPs of that run assembled
directly for HiGHS against the same MILPs stated in cvxpy (same HiGHS underneath, SciPy
interface); and the STL MILP at H = 16 with 3 inputs beside the seed's figure ("approximately
0.5 s for a prediction horizon of 16 time-steps and 3 control inputs", MATLAB/BluSTL, 4.4.4).
Medians over every step of the closed-loop runs."""

from __future__ import annotations

import statistics
import time

import numpy as np

from benchmarks.common import Result

SEED_MILP_MS = 500.0
HAND = np.array([1.5, 0.0, 0.0])


def _config(horizon: int | None = None, reach_time: float = 3.0):
    from gazebot.apps.controllers import load_controllers_config

    cfg = load_controllers_config()
    update: dict = {"reach_time_s": reach_time, "u_max_m_s": 1.0, "dt_s": 0.2}
    if horizon is not None:
        update["stl"] = cfg.stl.model_copy(update={"horizon": horizon})
    return cfg.model_copy(update=update)


def _solve_ms(name: str, horizon: int | None = None, reach_time: float = 3.0):
    """Median and max solve ms per step, and the STL step problems of the last run."""
    from gazebot.apps.controllers import make_controller
    from gazebot.apps.controllers.rollout import run_reach

    controller = make_controller(name, _config(horizon, reach_time))
    problems = []
    if name == "stl":
        plan = controller.plan

        def recording(obs):
            out = plan(obs)
            if controller.last_milp is not None:
                problems.append(controller.last_milp)
            return out

        controller.plan = recording
    run_reach(controller, np.zeros(3), HAND, 1.0)  # warm-up: build problems, imports
    samples: list[float] = []
    for _ in range(2):
        problems.clear()
        run = run_reach(controller, np.zeros(3), HAND, reach_time + 1.0)
        samples.extend(run.solve_ms.tolist())
    return statistics.median(samples), max(samples), problems


def _median_ms(fn, problems) -> float:
    times = []
    for p in problems:
        t0 = time.perf_counter()
        fn(p)
        times.append((time.perf_counter() - t0) * 1e3)
    return statistics.median(times)


def run() -> list[Result]:
    from gazebot.apps.controllers.stl_milp import solve_reach_milp, solve_reach_milp_cvxpy

    period_ms = 200.0
    out = []
    problems = []
    for name in ("pv", "mcj", "mce", "stl"):
        med, worst, probs = _solve_ms(name)
        problems = probs or problems
        out.append(
            Result(
                name=f"{name} solve per control step",
                ours=med,
                peer=period_ms,
                unit="ms",
                peer_name="control period dt = 0.2 s",
                note=f"max {worst:.1f} ms",
            )
        )
    out.append(
        Result(
            name="stl step MILPs of the Fig. 4.4 run, direct HiGHS",
            ours=_median_ms(solve_reach_milp, problems),
            peer=_median_ms(solve_reach_milp_cvxpy, problems),
            unit="ms",
            peer_name="same MILPs through cvxpy",
        )
    )
    med, worst, _ = _solve_ms("stl", horizon=16)
    out.append(
        Result(
            name="stl MILP, H = 16, 3 inputs, per step",
            ours=med,
            peer=SEED_MILP_MS,
            unit="ms",
            peer_name="seed 4.4.4, MATLAB BluSTL (quoted, not measured here)",
            note=f"max {worst:.1f} ms",
        )
    )
    return out
