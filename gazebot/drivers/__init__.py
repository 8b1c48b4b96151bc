"""Robot drivers and the Zenoh bus: the gaze engine drives a robot (simulated or real) over
versioned JSON topics under ``gazebot/<robot id>/`` (see :mod:`gazebot.drivers.keys`).

* :class:`RobotDriver` (``base.py``): the engine's view of a robot.
  :class:`ZenohRobotDriver` speaks the bus; :class:`SimRobotDriver` wraps an in-process
  :class:`gazebot.sim.HandoverSimulation`.
* :class:`ZenohRobotEndpoint`: the robot's side of the bus (simulator node, robot bridges).
* :class:`EngineNode` / :class:`SimNode`: the two node loops behind ``gazebot run`` and
  ``gazebot sim``; the engine node runs :class:`gazebot.runtime.GazeLoop`.
* :class:`ZenohDisplayNode`: the head screen's side of the bus (``gazebot display``).
* :class:`BusConfig` / :func:`open_session`: peer mode, ``tcp/127.0.0.1:7447``, no multicast.

Zenoh and MuJoCo are imported only when a session is opened or a simulation built.
"""

from __future__ import annotations

from gazebot.drivers.base import RobotDriver
from gazebot.drivers.engine_node import EngineNode, EngineNodeConfig, current_handover
from gazebot.drivers.keys import KeyLayout
from gazebot.drivers.payloads import (
    ArmCommandMsg,
    EventHistoryMsg,
    EventMsg,
    EyeFrameMsg,
    EyeStateMsg,
    HeadCommandMsg,
    JointStateMsg,
    PayloadError,
    PayloadVersionError,
    StatusMsg,
    TrackingMsg,
)
from gazebot.drivers.session import DEFAULT_ENDPOINT, EPHEMERAL_ENDPOINT, BusConfig, open_session
from gazebot.drivers.sim_driver import SimRobotDriver, apply_arm_command
from gazebot.drivers.sim_node import SimNode, SimNodeConfig
from gazebot.drivers.zenoh_display import ZenohDisplayNode
from gazebot.drivers.zenoh_driver import ZenohRobotDriver
from gazebot.drivers.zenoh_robot import ZenohRobotEndpoint

__all__ = [
    "DEFAULT_ENDPOINT",
    "EPHEMERAL_ENDPOINT",
    "ArmCommandMsg",
    "BusConfig",
    "EngineNode",
    "EngineNodeConfig",
    "EventHistoryMsg",
    "EventMsg",
    "EyeFrameMsg",
    "EyeStateMsg",
    "HeadCommandMsg",
    "JointStateMsg",
    "KeyLayout",
    "PayloadError",
    "PayloadVersionError",
    "RobotDriver",
    "SimNode",
    "SimNodeConfig",
    "SimRobotDriver",
    "StatusMsg",
    "TrackingMsg",
    "ZenohDisplayNode",
    "ZenohRobotDriver",
    "ZenohRobotEndpoint",
    "apply_arm_command",
    "current_handover",
    "open_session",
]
