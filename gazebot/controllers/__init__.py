"""The seed's reach-to-handover controllers (chapters 3 and 4): each plans Cartesian end-effector
velocities (:class:`~gazebot.controllers.base.ReachController`); the arm tracks them with
differential IK (:mod:`gazebot.controllers.arm_ik`).

- ``pv``: proportional velocity baseline (eq. 3.6)
- ``mcj``: minimum cumulative jerk with a reach time (eqs. 3.2-3.3)
- ``mce``: minimum cumulative error with stall and reach times (eqs. 3.4-3.5)
- ``stl``: STL specification synthesized as a MILP in receding horizon (eqs. 4.1-4.5)

Entry point: :func:`make_controller`.
"""

from __future__ import annotations

from gazebot.controllers.base import (
    INFEASIBLE_MESSAGE,
    ReachController,
    ReachObservation,
    VelocityPlan,
)
from gazebot.controllers.config import ControllersConfig, load_controllers_config

CONTROLLER_NAMES = ("pv", "mcj", "mce", "stl")

__all__ = [
    "CONTROLLER_NAMES",
    "INFEASIBLE_MESSAGE",
    "ControllersConfig",
    "ReachController",
    "ReachObservation",
    "VelocityPlan",
    "load_controllers_config",
    "make_controller",
]


def make_controller(name: str, config: ControllersConfig | None = None) -> ReachController:
    """The controller called ``name`` (one of :data:`CONTROLLER_NAMES`) with ``config``
    (default: ``configs/controllers.yaml``).

    Raises:
        ValueError: an unknown name.
    """
    config = config or load_controllers_config()
    if name == "pv":
        from gazebot.controllers.pv import PVController

        return PVController(config)
    if name == "mcj":
        from gazebot.controllers.mcj import MCJController

        return MCJController(config)
    if name == "mce":
        from gazebot.controllers.mce import MCEController

        return MCEController(config)
    if name == "stl":
        from gazebot.controllers.stl import STLController

        return STLController(config)
    raise ValueError(f"unknown controller {name!r} (known: {', '.join(CONTROLLER_NAMES)})")
