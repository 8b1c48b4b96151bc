"""The one exception a command raises for a wrong command-line input."""

from __future__ import annotations


class UsageError(ValueError):
    """A command-line input is wrong (a bad option value, an output path of the wrong kind).

    ``gazebot`` prints it as ``gazebot: error: ...`` and exits with status 2, like a malformed
    input file (:class:`gazebot.config.ConfigError`); any other ``ValueError`` is a bug and
    keeps its traceback.
    """
