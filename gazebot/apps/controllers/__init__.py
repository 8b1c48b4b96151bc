"""The seed's reach-to-handover controllers (chapters 3 and 4): each plans Cartesian end-effector
velocities (:class:`~gazebot.apps.controllers.base.ReachController`); the arm tracks them with
differential IK (:mod:`gazebot.apps.controllers.arm_ik`).

- ``pv``: proportional velocity baseline (eq. 3.6)
- ``mcj``: minimum cumulative jerk with a reach time (eqs. 3.2-3.3)
- ``mce``: minimum cumulative error with stall and reach times (eqs. 3.4-3.5)
- ``stl``: STL specification synthesized as a MILP in receding horizon (eqs. 4.1-4.5)
- ``gps``: a learned Guided Policy Search policy (chapter 5): joint torques, not velocities
  (:mod:`gazebot.apps.controllers.gps`; the simulator's :mod:`gazebot.apps.sim.policy_reach` runs
  it)

Entry point: :func:`make_controller`; the registry :data:`CONTROLLERS` (one line per controller).
"""

from __future__ import annotations

from gazebot.apps.controllers.base import (
    INFEASIBLE_MESSAGE,
    ReachController,
    ReachObservation,
    VelocityPlan,
)
from gazebot.apps.controllers.config import ControllersConfig, load_controllers_config
from gazebot.core.registry import Registry

#: The reach controllers by name: CLI choices, scene validation and the README's table come from
#: here. A new controller is one file plus one line (imported on first use).
CONTROLLERS: Registry[ReachController] = Registry("controller", group="gazebot.controllers")
CONTROLLERS.register(
    "pv", "gazebot.apps.controllers.pv:PVController", "proportional velocity baseline (eq. 3.6)"
)
CONTROLLERS.register(
    "mcj", "gazebot.apps.controllers.mcj:MCJController",
    "minimum cumulative jerk with a reach time (eqs. 3.2-3.3)",
)
CONTROLLERS.register(
    "mce", "gazebot.apps.controllers.mce:MCEController",
    "minimum cumulative error with stall and reach times (eqs. 3.4-3.5)",
)
CONTROLLERS.register(
    "stl", "gazebot.apps.controllers.stl:STLController",
    "STL specification as a MILP in receding horizon (eqs. 4.1-4.5)",
)
#: The learned reach's registry name (the simulator's scenes and the demo use this one).
GPS = "gps"
CONTROLLERS.register(
    GPS, "gazebot.apps.controllers.gps:GPSController",
    "learned GPS policy (chapter 5): Panda joint torques; needs `--policy DIR`, runs on `panda`",
)


#: Registered controllers that command joint torques and plan no Cartesian velocities: they run
#: only in the simulator, on a robot with their arm, and ``gazebot reach-plan`` does not offer them.
TORQUE_CONTROLLERS: tuple[str, ...] = (GPS,)


def planner_names() -> tuple[str, ...]:
    """The registered controllers that plan Cartesian end-effector velocities."""
    return tuple(n for n in CONTROLLERS.names() if n not in TORQUE_CONTROLLERS)


def controller_names() -> tuple[str, ...]:
    """The registered controllers' names (the built-ins and any registered since)."""
    return CONTROLLERS.names()


#: The built-in controllers' names (for code written before the registry; prefer
#: :func:`controller_names`, which includes registered ones).
CONTROLLER_NAMES = controller_names()

__all__ = [
    "CONTROLLERS",
    "CONTROLLER_NAMES",
    "INFEASIBLE_MESSAGE",
    "ControllersConfig",
    "ReachController",
    "ReachObservation",
    "VelocityPlan",
    "TORQUE_CONTROLLERS",
    "controller_names",
    "load_controllers_config",
    "make_controller",
    "planner_names",
]


def make_controller(name: str, config: ControllersConfig | None = None) -> ReachController:
    """The controller registered as ``name`` with ``config`` (default:
    ``configs/controllers.yaml``).

    Raises:
        ValueError: an unknown name (the message lists the registered ones).
    """
    CONTROLLERS.check(name)
    return CONTROLLERS.make(name, config or load_controllers_config())
