"""Signal Temporal Logic (seed section 4.2.1) with quantitative robustness, and the seed's handover
specifications (section 4.3, Tables 4.1-4.3) to monitor a run.

A formula's robustness at a sample is positive when the signal satisfies it there and negative
when it violates it; its magnitude says by how much (m for distances, load-share units for
object states). Time bounds are seconds on a uniformly sampled signal; a bounded window running
past the end of the recording sees only the recorded samples (so a missing "eventually" near the
end counts as violated).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

from gazebot.apps.controllers.config import Role, STLConfig, Strategy


@dataclass(frozen=True)
class Signal:
    """Uniformly sampled signals: ``values[name]`` has one row per sample, ``dt`` s apart."""

    dt: float
    values: Mapping[str, np.ndarray]

    def __post_init__(self) -> None:
        lengths = {len(v) for v in self.values.values()}
        if len(lengths) != 1:
            raise ValueError(f"signals of different lengths: {sorted(lengths)}")
        if not self.dt > 0:
            raise ValueError("dt must be positive")

    @property
    def n(self) -> int:
        return len(next(iter(self.values.values())))

    def __getitem__(self, name: str) -> np.ndarray:
        return np.asarray(self.values[name], float)


class Formula(ABC):
    """An STL formula; :meth:`rho` is its robustness at every sample."""

    @abstractmethod
    def rho(self, s: Signal) -> np.ndarray:
        """Robustness at each sample (shape (n,))."""

    def robustness(self, s: Signal) -> float:
        """Robustness at the first sample: ``s |= phi`` iff it is positive."""
        return float(self.rho(s)[0])

    def __and__(self, other: Formula) -> Formula:
        return And(self, other)

    def __or__(self, other: Formula) -> Formula:
        return Or(self, other)

    def __invert__(self) -> Formula:
        return Not(self)


@dataclass(frozen=True)
class Predicate(Formula):
    """``gamma(s(t)) > 0`` with ``gamma`` given on the whole signal at once."""

    name: str
    gamma: Callable[[Signal], np.ndarray]

    def rho(self, s: Signal) -> np.ndarray:
        return np.asarray(self.gamma(s), float).reshape(s.n)


@dataclass(frozen=True)
class Not(Formula):
    phi: Formula

    def rho(self, s: Signal) -> np.ndarray:
        return -self.phi.rho(s)


@dataclass(frozen=True)
class And(Formula):
    a: Formula
    b: Formula

    def rho(self, s: Signal) -> np.ndarray:
        return np.minimum(self.a.rho(s), self.b.rho(s))


@dataclass(frozen=True)
class Or(Formula):
    a: Formula
    b: Formula

    def rho(self, s: Signal) -> np.ndarray:
        return np.maximum(self.a.rho(s), self.b.rho(s))


def implies(a: Formula, b: Formula) -> Formula:
    """``a => b`` as ``not a or b``."""
    return Or(Not(a), b)


def _window(values: np.ndarray, s: Signal, a: float, b: float | None, fn) -> np.ndarray:
    n = len(values)
    lo = int(round(a / s.dt))
    hi = n if b is None else int(round(b / s.dt))
    out = np.empty(n)
    for k in range(n):
        seg = values[k + lo : min(n, k + hi + 1)]
        # An empty window (past the recording) is vacuous for "always", impossible for "eventually".
        out[k] = fn(seg) if len(seg) else (np.inf if fn is np.min else -np.inf)
    return out


@dataclass(frozen=True)
class Always(Formula):
    """``[]_[a, b] phi`` (``b`` None: to the end)."""

    phi: Formula
    a: float = 0.0
    b: float | None = None

    def rho(self, s: Signal) -> np.ndarray:
        return _window(self.phi.rho(s), s, self.a, self.b, np.min)


@dataclass(frozen=True)
class Eventually(Formula):
    """``<>_[a, b] phi`` (``b`` None: to the end)."""

    phi: Formula
    a: float = 0.0
    b: float | None = None

    def rho(self, s: Signal) -> np.ndarray:
        return _window(self.phi.rho(s), s, self.a, self.b, np.max)


# --------------------------------------------------------------------------- handover specs
# Signals used below (base frame, m): p_r (robot end effector), p_h (human hand), p_o (object),
# p_star (predetermined handover location), p_d (drop-off), p_home (robot home), alpha (the
# robot's load share 0..1), g_r / g_h (gripper / hand openness 0 closed .. 1 open), e (1 once
# the handover signal is given). Orientations (q) are left out: gazebot synthesizes positions
# only, as the seed's simulations do (4.4: "we only consider the position trajectory").


def _l1(s: Signal, a: str, b: str) -> np.ndarray:
    return np.abs(s[a] - s[b]).sum(axis=1)


def near(a: str, b: str, eps: float) -> Formula:
    """``||a - b||_1 < eps`` (the seed's l1 norm, 4.4.1)."""
    return Predicate(f"|{a}-{b}|<{eps}", lambda s: eps - _l1(s, a, b))


def object_states(cfg: STLConfig, eps_p: float) -> dict[str, Formula]:
    """``o_r, o_s, o_h, o_g`` (Table 4.1): from the load share ``alpha`` (``cfg.force_sensor``),
    else from the object's distance to the gripper and the hand and their openness ``g_r``,
    ``g_h`` (within ``cfg.eps_g`` of the grip width ``g*``)."""
    if not cfg.force_sensor:
        return _object_states_without_force(cfg, eps_p)
    d1, d2 = cfg.delta_1, cfg.delta_2
    alpha = Predicate  # alias for brevity below
    o_r = alpha("o_r", lambda s: s["alpha"] - d2)
    o_s = alpha("o_s", lambda s: np.minimum(s["alpha"] - d1, d2 - s["alpha"]))
    released = alpha("alpha<=d1", lambda s: d1 - s["alpha"])
    o_h = And(released, near("p_o", "p_h", eps_p))
    o_g = And(released, Not(near("p_o", "p_h", eps_p)))
    return {"o_r": o_r, "o_s": o_s, "o_h": o_h, "o_g": o_g}


def _object_states_without_force(cfg: STLConfig, eps_p: float) -> dict[str, Formula]:
    """Table 4.1, left column: who grips the object, ``||p_o - p_i|| <= eps_p`` and
    ``|g_i - g*| <= eps_g`` for the robot (``r``) and the human (``h``)."""

    def grips(i: str) -> Formula:
        closed = Predicate(
            f"|g_{i}-g*|<={cfg.eps_g}",
            lambda s: cfg.eps_g - np.abs(s[f"g_{i}"] - cfg.grip_width),
        )
        return And(near("p_o", f"p_{i}", eps_p), closed)

    robot, human = grips("r"), grips("h")
    return {
        "o_r": And(robot, Not(human)),
        "o_h": And(Not(robot), human),
        "o_s": And(robot, human),
        "o_g": And(Not(robot), Not(human)),
    }


def in_zone(radius: float) -> Formula:
    """The human hand in the handover zone, ``||p_h - c|| <= l_h`` (c: the robot's base)."""
    return Predicate(
        "in_zone", lambda s: radius - np.linalg.norm(s["p_h"] - s["zone_center"], axis=1)
    )


def reach_spec(
    cfg: STLConfig, reach_time_s: float, strategy: Strategy | None = None, role: Role | None = None
) -> Formula:
    """Table 4.3: the reach phase for the strategy and the robot's role (t_1 or t_7)."""
    strategy = strategy or cfg.strategy
    role = role or cfg.role
    o = object_states(cfg, cfg.eps_p_m)
    holds = o["o_r"] if role is Role.GIVER else Not(o["o_r"])
    trigger = And(holds, in_zone(cfg.zone_radius_m)) if strategy.reactive else holds
    goal = near("p_h" if strategy.towards_human else "p_star", "p_r", cfg.eps_p_m)
    return Always(implies(trigger, Eventually(goal, 0.0, reach_time_s)))


def _gripper_at(name: str, level: float, tol: float) -> Formula:
    """``|g_r - level| < eps_g``: the gripper's openness at ``level`` (1 open, ``g*`` holding)."""
    return Predicate(name, lambda s: tol - np.abs(s["g_r"] - level))


def transfer_spec(cfg: STLConfig, t_s: float, role: Role) -> Formula:
    """Table 4.2 transfer: receiver grasps (``|g_r - g*| < eps_g``) within t_2 of reaching the
    shared/held object; giver opens within t_8 once the object is shared."""
    o = object_states(cfg, cfg.eps_p_m)
    tol, width = cfg.eps_g, cfg.grip_width
    if role is Role.RECEIVER:
        at_obj = near("p_o", "p_r", cfg.eps_p_m)
        grasped = Predicate("g_r=g*", lambda s: tol - np.abs(s["g_r"] - width))
        return Always(implies(And(at_obj, Or(o["o_h"], o["o_s"])), Eventually(grasped, 0, t_s)))
    return Always(implies(o["o_s"], Eventually(_gripper_at("g_r=1", 1.0, tol), 0, t_s)))


def release_spec(cfg: STLConfig, t_s: float) -> Formula:
    """Table 4.2, receiver retreat, second formula (t_4): at the drop-off holding the object,
    the gripper is open (``|g_r - 1| < eps_g``) within ``t_s``:
    ``[]((||p_r - p_d|| < eps_p and o == o_r) => <>_[0, t_4] |g_r - 1| < eps_g)``."""
    o = object_states(cfg, cfg.eps_p_m)
    at_dropoff = And(near("p_r", "p_d", cfg.eps_p_m), o["o_r"])
    return Always(implies(at_dropoff, Eventually(_gripper_at("g_r=1", 1.0, cfg.eps_g), 0, t_s)))


def pickup_reach_spec(cfg: STLConfig, t_s: float) -> Formula:
    """Table 4.2, giver pick-up, first formula (t_5): while the object is on the ground the
    gripper gets to it within ``t_s``: ``[](o == o_g => <>_[0, t_5] ||p_o - p_r|| < eps_p)``."""
    o = object_states(cfg, cfg.eps_p_m)
    return Always(implies(o["o_g"], Eventually(near("p_o", "p_r", cfg.eps_p_m), 0, t_s)))


def pickup_grasp_spec(cfg: STLConfig, t_s: float) -> Formula:
    """Table 4.2, giver pick-up, second formula (t_6): at the object on the ground, the gripper
    closes to the grip width within ``t_s``:
    ``[]((||p_o - p_r|| < eps_p and o == o_g) => <>_[0, t_6] |g_r - g*| < eps_g)``."""
    o = object_states(cfg, cfg.eps_p_m)
    at_object = And(near("p_o", "p_r", cfg.eps_p_m), o["o_g"])
    grasped = _gripper_at("g_r=g*", cfg.grip_width, cfg.eps_g)
    return Always(implies(at_object, Eventually(grasped, 0, t_s)))


def retreat_spec(cfg: STLConfig, t_s: float, role: Role) -> Formula:
    """Table 4.2 retreat: receiver at the drop-off within t_3 of holding the object; giver home
    within t_9 of the human holding it."""
    o = object_states(cfg, cfg.eps_p_m)
    if role is Role.RECEIVER:
        return Always(implies(o["o_r"], Eventually(near("p_r", "p_d", cfg.eps_p_m), 0, t_s)))
    return Always(implies(o["o_h"], Eventually(near("p_r", "p_home", cfg.eps_p_m), 0, t_s)))


def table_4_2(cfg: STLConfig, reach_time_s: float, role: Role) -> dict[str, Formula]:
    """Every Table 4.2 specification of ``role`` with ``cfg``'s times, keyed by its time bound
    in the order of the task: receiver ``t1``-``t4``, giver ``t5``-``t9``. The reach (``t1`` /
    ``t7``) is Table 4.3's row for ``cfg.strategy``, which "replaces the reach phase
    specification in Table 4.2"."""
    reach = reach_spec(cfg, reach_time_s, role=role)
    if role is Role.RECEIVER:
        return {
            "t1": reach,
            "t2": transfer_spec(cfg, cfg.transfer_time_s, role),
            "t3": retreat_spec(cfg, cfg.retreat_time_s, role),
            "t4": release_spec(cfg, cfg.release_time_s),
        }
    return {
        "t5": pickup_reach_spec(cfg, cfg.pickup_time_s),
        "t6": pickup_grasp_spec(cfg, cfg.pickup_grasp_time_s),
        "t7": reach,
        "t8": transfer_spec(cfg, cfg.transfer_time_s, role),
        "t9": retreat_spec(cfg, cfg.retreat_time_s, role),
    }
