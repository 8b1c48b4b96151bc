"""Which pip extra provides which missing package: ``pip install gazebot`` is the core install (the
engine and the bus), every other command names the extra it needs instead of a traceback.

The extras themselves (their packages and version ranges) are declared in ``pyproject.toml``;
``tests/apps/cli/test_cli_extras.py`` checks that this table and that file agree.
"""

from __future__ import annotations

#: Top-level import name of each package that only an extra installs -> that extra. Where a
#: package is in several extras (the ``sim`` extra includes ``render``), the smallest one.
EXTRA_OF_MODULE: dict[str, str] = {
    "cv2": "render",
    "pygame": "render",
    "imageio": "render",
    "imageio_ffmpeg": "render",
    "matplotlib": "render",
    "tqdm": "render",
    "mujoco": "sim",
    "cvxpy": "controllers",
    "clarabel": "controllers",
    "c3d": "recordings",
    "openpyxl": "study",
    "flask": "study",
    "waitress": "study",
    "jax": "gps",
    "optax": "gps",
    "sklearn": "gps",
    "threadpoolctl": "gps",
    "foxglove": "view",
}


#: Commands that need a whole extra: the extra to name when any of its packages is missing, so
#: that one install fixes the command (``gazebot sim`` needs OpenCV too, but ``[sim]`` includes
#: ``[render]``). Keyed by the words after ``gazebot``; the longest match counts.
EXTRA_OF_COMMAND: dict[str, str] = {
    "sim": "sim",
    "demo": "sim",
    "render video": "sim",
    "study": "study",
    "annotations": "study",
    "gps": "gps",
    "view": "view",
}


def extra_for(module: str | None) -> str | None:
    """The extra that installs ``module`` (a dotted name is looked up by its top level), or
    ``None`` when no extra does (a missing core package or a bug: not ours to explain)."""
    if not module:
        return None
    return EXTRA_OF_MODULE.get(module.partition(".")[0])


def extra_for_command(words: list[str], module: str | None) -> str | None:
    """The extra to name when ``module`` is missing in the command ``words`` (e.g. ``["render",
    "video"]``): the command's own extra (:data:`EXTRA_OF_COMMAND`), else the module's; ``None``
    when the module belongs to no extra."""
    if extra_for(module) is None:
        return None
    for n in range(len(words), 0, -1):
        if " ".join(words[:n]) in EXTRA_OF_COMMAND:
            return EXTRA_OF_COMMAND[" ".join(words[:n])]
    return extra_for(module)


def missing_extra_message(command: str, module: str, extra: str) -> str:
    """One line: what is missing, which extra has it and the command that installs it."""
    return (f"{command} needs the [{extra}] extra (no module {module!r}): "
            f"pip install 'gazebot[{extra}]'")
