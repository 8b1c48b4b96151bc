"""Gaze kinematics: robot head models, look-at IK, display eyes and human-like gaze shifts.

Entry points: :meth:`RobotModel.load`, :func:`solve_ik` (one look-at solve) and
:class:`GazeController` (timed neck + eye commands for a stream of targets).
"""

from gazebot.core.kinematics.eyes import DisplayEyes, eye_angles, eye_direction
from gazebot.core.kinematics.gaze_controller import GazeController, HeadEyeState
from gazebot.core.kinematics.look_at import IKConfig, LookAtSolution, solve_ik
from gazebot.core.kinematics.robot import GazePose, RobotModel
from gazebot.core.kinematics.robot_config import (
    GAZE_MODES,
    GazeMode,
    IKSettings,
    RobotConfig,
    load_robot_config,
    with_gaze_mode,
)
from gazebot.core.kinematics.shifts import GazeShiftConfig, MinJerkTrajectory

__all__ = [
    "GAZE_MODES",
    "GazeMode",
    "DisplayEyes",
    "GazeController",
    "GazePose",
    "GazeShiftConfig",
    "HeadEyeState",
    "IKConfig",
    "IKSettings",
    "LookAtSolution",
    "MinJerkTrajectory",
    "RobotConfig",
    "RobotModel",
    "eye_angles",
    "eye_direction",
    "load_robot_config",
    "solve_ik",
    "with_gaze_mode",
]
