"""The interface every reach controller implements: given the end-effector and the human hand now,
plan Cartesian end-effector velocities (seed 3.2: "The control input is given as the robot's
end-effector velocity"); the first one is applied for one control period, then the controller
plans again (receding horizon)."""

from __future__ import annotations

import math
import time
from abc import ABC, abstractmethod
from dataclasses import dataclass, field

import numpy as np

from gazebot.apps.controllers.config import ControllersConfig, SpeedLimit

INFEASIBLE_MESSAGE = "I will not be able to reach in the specified time limit"


@dataclass(frozen=True)
class ReachObservation:
    """What a controller sees at one control step (base frame, m; times from the handover's start).

    Attributes:
        t: Time since the handover's start (s): the seed's "Don't move until" and "Reach before"
            count from here.
        x: End-effector position.
        hand: The human hand (the point to hand over at) now.
        target: A predetermined handover location (STL ``predetermined`` strategies), else None.
        robot_holds_object: The object state ``o == o_r`` (STL).
        zone_center: The robot's base, the centre of the STL handover zone.
        object_free: The object state ``o == o_g`` (on the ground: nobody holds it; STL giver
            pick-up, Table 4.2's t_5).
        object_position: Where the object is (``p_o``), for the pick-up; None: not sensed.
        dropoff: The object's drop-off location (``p_d``) of a receiving robot (Table 4.2's
            t_3); None: the task ends with the object held.
    """

    t: float
    x: np.ndarray
    hand: np.ndarray
    target: np.ndarray | None = None
    robot_holds_object: bool = False
    zone_center: np.ndarray = field(default_factory=lambda: np.zeros(3))
    object_free: bool = False
    object_position: np.ndarray | None = None
    dropoff: np.ndarray | None = None

    def __post_init__(self) -> None:
        optional = ("target", "object_position", "dropoff")
        names = ("x", "hand") + tuple(n for n in optional if getattr(self, n) is not None)
        for name in names:
            v = np.asarray(getattr(self, name), float)
            if v.shape != (3,) or not np.all(np.isfinite(v)):
                raise ValueError(f"{name} must be a finite 3D point, got {getattr(self, name)}")
        if not math.isfinite(self.t):
            raise ValueError(f"t must be finite, got {self.t}")


@dataclass(frozen=True)
class VelocityPlan:
    """A planned end-effector velocity sequence from ``t0`` (s since the handover's start).

    ``velocities[i]`` (m/s) holds over ``[t0 + i dt, t0 + (i + 1) dt)``; ``positions`` are the
    planned end-effector positions at ``t0 + i dt`` (one more than velocities). ``feasible`` is
    False when no input meets the timing; the velocities are then what the robot does instead
    (zero for ``stl``: it stops; a best effort for ``mcj``/``mce``, which report it).
    """

    t0: float
    dt: float
    velocities: np.ndarray
    positions: np.ndarray
    feasible: bool
    solve_ms: float
    status: str = "optimal"

    @classmethod
    def integrated(
        cls,
        t0: float,
        dt: float,
        x0: np.ndarray,
        velocities: np.ndarray,
        feasible: bool,
        started: float,
        status: str = "optimal",
    ) -> VelocityPlan:
        """The plan of ``velocities`` from ``x0`` (its positions by :func:`integrate`), solved
        since ``started`` (a ``time.perf_counter()`` reading)."""
        return cls(
            t0=t0,
            dt=dt,
            velocities=velocities,
            positions=integrate(x0, velocities, dt),
            feasible=feasible,
            solve_ms=(time.perf_counter() - started) * 1e3,
            status=status,
        )

    @property
    def command(self) -> np.ndarray:
        """The velocity to apply now (m/s)."""
        return self.velocities[0] if len(self.velocities) else np.zeros(3)


class ReachController(ABC):
    """A reach-to-handover controller with the seed's timing parameters.

    Subclasses implement :meth:`plan`; they may keep state between calls (applied velocities,
    hand history), cleared by :meth:`reset`.

    Args:
        config: Speed cap, control period, reach and stall times and per-controller values.
    """

    name: str = ""

    def __init__(self, config: ControllersConfig) -> None:
        self.config = config

    @property
    def dt(self) -> float:
        return self.config.dt_s

    def reset(self) -> None:
        """Forget everything from an earlier handover (stateless controllers: nothing)."""
        return None

    @abstractmethod
    def plan(self, obs: ReachObservation) -> VelocityPlan:
        """Plan from ``obs``; the caller applies ``plan.command`` for one period ``dt``."""

    # ------------------------------------------------------------------ helpers for subclasses
    def cap(self, u: np.ndarray) -> np.ndarray:
        """``u`` within the speed limit (per axis: clipped; norm: scaled down)."""
        u = np.asarray(u, float)
        u_max = self.config.u_max_m_s
        if self.config.speed_limit is SpeedLimit.PER_AXIS:
            return np.clip(u, -u_max, u_max)
        n = float(np.linalg.norm(u))
        return u if n <= u_max else u * (u_max / n)

    def steps(self, seconds: float) -> int:
        """Control steps in ``seconds``, rounded down (a deadline: never later than asked;
        2.0 s at 0.2 s is 10 steps, 2.5 s is 12)."""
        return int(math.floor(seconds / self.dt + 1e-6))

    def steps_up(self, seconds: float) -> int:
        """Control steps in ``seconds``, rounded up (a wait: never shorter than asked)."""
        return int(math.ceil(seconds / self.dt - 1e-6))


def integrate(x0: np.ndarray, velocities: np.ndarray, dt: float) -> np.ndarray:
    """Positions of ``x_{i+1} = x_i + u_i dt`` (eq. 3.3a / 4.2) from ``x0``: shape (N + 1, 3)."""
    steps = np.asarray(velocities, float).reshape(-1, 3) * dt
    return np.vstack([x0, np.asarray(x0, float) + np.cumsum(steps, axis=0)])
