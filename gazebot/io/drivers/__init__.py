"""Robot drivers and the bus: the gaze engine drives a robot (simulated or real) over ROS 2
messages on Zenoh, exactly as rmw_zenoh puts them on the network (:mod:`gazebot.io.drivers.rmw`;
topics and types in :mod:`gazebot.io.ros2.topics`), so ROS 2 nodes, ``ros2 topic echo``, rosbag2
and Foxglove see gazebot as one of theirs.

* :class:`RobotDriver` (``base.py``): the engine's view of a robot.
  :class:`ZenohRobotDriver` speaks the bus; :class:`SimRobotDriver` wraps an in-process
  :class:`gazebot.apps.sim.HandoverSimulation`.
* :class:`ZenohRobotEndpoint`: the robot's side of the bus (simulator node, robot bridges).
* :class:`EngineNode` / :class:`SimNode`: the two node loops behind ``gazebot run`` and
  ``gazebot sim``; the engine node runs :class:`gazebot.core.runtime.GazeLoop`.
* :class:`ZenohDisplayNode`: the head screen's side of the bus (``gazebot display``).
* :class:`BusConfig` / :func:`open_session`: peer mode, ``tcp/127.0.0.1:7447``, no multicast;
  ``--connect tcp/HOST:7447`` joins a Zenoh router.

Zenoh and MuJoCo are imported only when a session is opened or a simulation built.
"""

from __future__ import annotations

from gazebot.io.drivers.base import RobotDriver
from gazebot.io.drivers.engine_node import EngineNode, EngineNodeConfig, current_handover
from gazebot.io.drivers.rmw.names import Names
from gazebot.io.drivers.session import DEFAULT_ENDPOINT, EPHEMERAL_ENDPOINT, BusConfig, open_session
from gazebot.io.drivers.sim_driver import SimRobotDriver, apply_arm_command
from gazebot.io.drivers.sim_node import SimNode, SimNodeConfig
from gazebot.io.drivers.zenoh_display import ZenohDisplayNode
from gazebot.io.drivers.zenoh_driver import ZenohRobotDriver
from gazebot.io.drivers.zenoh_robot import ZenohRobotEndpoint

__all__ = [
    "DEFAULT_ENDPOINT",
    "EPHEMERAL_ENDPOINT",
    "BusConfig",
    "EngineNode",
    "EngineNodeConfig",
    "Names",
    "RobotDriver",
    "SimNode",
    "SimNodeConfig",
    "SimRobotDriver",
    "ZenohDisplayNode",
    "ZenohRobotDriver",
    "ZenohRobotEndpoint",
    "apply_arm_command",
    "current_handover",
    "open_session",
]
