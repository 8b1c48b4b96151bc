"""The one exception a command raises for a wrong command-line input, and the checks of inputs
several commands share."""

from __future__ import annotations

from typing import Any


class UsageError(ValueError):
    """A command-line input is wrong (a bad option value, an output path of the wrong kind).

    ``gazebot`` prints it as ``gazebot: error: ...`` and exits with status 2, like a malformed
    input file (:class:`gazebot.core.config.ConfigError`); any other ``ValueError`` is a bug and
    keeps its traceback.
    """


def robot_with_gaze_mode(robot: Any, mode: str | None) -> Any:
    """``robot`` in the ``--gaze-mode`` ``mode``
    (:func:`gazebot.core.kinematics.robot_config.with_gaze_mode`);
    an unknown mode is a :class:`UsageError` naming the known ones."""
    from gazebot.core.kinematics.robot_config import GAZE_MODES, with_gaze_mode

    if mode is not None and mode not in GAZE_MODES:
        raise UsageError(f"--gaze-mode must be one of {', '.join(GAZE_MODES)}, not {mode!r}")
    return with_gaze_mode(robot, mode)


def option_error(exc: Exception, options: dict[str, str], what: str) -> UsageError:
    """A failed validation of command-line overrides as one readable :class:`UsageError`.

    A pydantic error on a field becomes ``--OPTION: expected ..., got ...`` (``options`` maps
    field names to the options that set them; another field keeps its dotted name); an error of
    the whole model keeps its own sentence. pydantic's full report (input dicts, links to its
    docs) is not for a command-line user.
    """
    from pydantic import ValidationError

    if not isinstance(exc, ValidationError):
        return UsageError(f"{what}: {exc}")
    err = exc.errors()[0]
    loc = [str(p) for p in err["loc"]]
    msg = err["msg"].removeprefix("Value error, ")
    if not loc:
        return UsageError(f"{what}: {msg}")
    name = options.get(loc[-1], ".".join(loc))
    expected = msg.removeprefix("Input should be ")
    return UsageError(f"{name}: expected {expected}, got {err.get('input')!r}")
