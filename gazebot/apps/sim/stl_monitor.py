"""STL robustness of the seed's handover specifications (Table 4.2) over a simulated run: the
reach ("within t_1 seconds after the handover signal e"), the transfer (grasp within t_2 of the
object reaching the gripper; a giver robot releases within t_8 of sharing it) and the retreat (at
the drop-off within t_3 of holding the object; a giver robot home within t_9 of the person
holding it). With a scene's drop-off (``controller.dropoff_m``) the receiver's release there
(t_4) is monitored too, with a pick-up (``controller.pickup_m``) the giver's pick-up (t_5, t_6).
Positive robustness: the run met the spec.

In the simulation "near" is the grasp distance (the controller grasps or releases there, seed
3.3.4), taken as an l1 bound (``sqrt(3)`` times the Euclidean grasp distance); the drop-off of a
receiving robot is the scene's drop-off, else its home gripper position (it retreats home with
the object)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from gazebot.apps.controllers.config import ControllersConfig, Role
from gazebot.apps.controllers.stl_logic import (
    Always,
    Eventually,
    Formula,
    Predicate,
    Signal,
    implies,
    near,
    pickup_grasp_spec,
    pickup_reach_spec,
    release_spec,
    retreat_spec,
    transfer_spec,
)


@dataclass
class HandoverMonitor:
    """Collects one sample per control tick (pass :meth:`on_tick` as ``record_handover``'s
    ``on_tick``, or call :meth:`sample`) and evaluates the specs at the end."""

    config: ControllersConfig | None = None  # None: the simulated robot's own
    rows: dict[str, list] = field(default_factory=lambda: {k: [] for k in _KEYS})
    start_t: float | None = None
    role: Role = Role.RECEIVER
    eps: float = 0.05 * math.sqrt(3)
    home: np.ndarray | None = None
    dt: float | None = None
    dropoff: np.ndarray | None = None
    pickup: bool = False
    _last_t: float | None = None

    def on_tick(self, sim, _tick=None) -> None:
        self.sample(sim)

    def sample(self, sim) -> None:
        """Record the simulation's state now."""
        ctrl = sim.controller
        if self.config is None:
            self.config = robot_timing(sim)
        self.role = Role.GIVER if getattr(sim, "robot_to_human", False) else Role.RECEIVER
        self.eps = math.sqrt(3) * sim.config.controller.grasp_distance_m
        gripper = sim.data.site_xpos[sim._gripper_site].copy()
        if self.home is None:
            self.home = gripper.copy()
        whole = sim.config.controller
        if whole.dropoff_m is not None:
            self.dropoff = np.asarray(whole.dropoff_m, float)
        self.pickup = whole.pickup_m is not None
        if self.start_t is None and ctrl.handover_start is not None:
            self.start_t = float(ctrl.handover_start)
        if self._last_t is not None and self.dt is None:
            self.dt = sim.t - self._last_t
        self._last_t = sim.t
        person = sim.giver.holds_object
        alpha = sim.robot_load_share
        obj = sim.data.mocap_pos[sim.scene.object_mocap].copy()
        row = {
            "t": sim.t,
            "p_r": gripper,
            "p_h": sim.giver.hand + sim.layout.object_offset,  # where the object sits in the hand
            "p_o": obj,
            "alpha": alpha,
            "g_r": 1.0 - float(ctrl._gripper),
            # The person's hand: closed on the object (g*) while holding it, else open.
            "g_h": self.config.stl.grip_width if person else 1.0,
            "p_d": self.home if self.dropoff is None else self.dropoff,
            "p_home": self.home,
        }
        for k in _KEYS:
            self.rows[k].append(row[k])

    def signal(self) -> Signal:
        values = {k: np.asarray(v, float) for k, v in self.rows.items() if k != "t"}
        t = np.asarray(self.rows["t"], float)
        e = np.zeros(len(t))
        if self.start_t is not None and len(t):
            e[int(np.argmin(np.abs(t - self.start_t)))] = 1.0
        values["e"] = e
        return Signal(dt=self.dt or 1.0, values=values)

    def specs(self) -> dict[str, Formula]:
        """Table 4.2's specs for the robot's role, with this run's tolerances: the reach as
        triggered by the handover signal ``e``, the transfer and retreat as
        :func:`~gazebot.apps.controllers.stl_logic.transfer_spec` and ``retreat_spec`` state
        them."""
        assert self.config is not None, "sample a run first"
        stl = self.config.stl.model_copy(update={"eps_p_m": self.eps})
        e = Predicate("e", lambda s: s["e"] - 0.5)
        reach = Always(
            implies(e, Eventually(near("p_h", "p_r", self.eps), 0, self.config.reach_time_s))
        )
        specs = {
            "reach": reach,
            "transfer": transfer_spec(stl, stl.transfer_time_s, self.role),
            "retreat": retreat_spec(stl, stl.retreat_time_s, self.role),
        }
        if self.role is Role.RECEIVER and self.dropoff is not None:
            specs["release"] = release_spec(stl, stl.release_time_s)  # t_4
        if self.role is Role.GIVER and self.pickup:
            specs["pickup"] = pickup_reach_spec(stl, stl.pickup_time_s)  # t_5
            specs["pickup_grasp"] = pickup_grasp_spec(stl, stl.pickup_grasp_time_s)  # t_6
        return specs

    def robustness(self) -> dict[str, float]:
        """Each spec's robustness over the run (positive: met)."""
        if len(self.rows["t"]) < 2:
            raise ValueError("no run recorded")
        sig = self.signal()
        return {name: float(f.robustness(sig)) for name, f in self.specs().items()}


def robot_timing(sim) -> ControllersConfig:
    """The timing the simulated robot works to: its reach controller's, else the controllers
    YAML with the scene's reach time."""
    reach = sim.controller.reach
    if reach is not None:
        return reach.controller.config
    from gazebot.apps.controllers import load_controllers_config

    ctrl = sim.config.controller
    cfg = load_controllers_config(ctrl.controllers)
    if ctrl.reach_time_s is not None:
        cfg = cfg.model_copy(update={"reach_time_s": ctrl.reach_time_s})
    return cfg


_KEYS = ("t", "p_r", "p_h", "p_o", "alpha", "g_r", "g_h", "p_d", "p_home")
