"""Where a robot's model file is: ``package://`` URIs and paths beside the robot YAML.

A robot YAML names its model as ``urdf: FILE`` or ``mjcf: FILE``. ``FILE`` is a ``package://NAME/
PATH`` URI (ROS convention) or a path: absolute, relative to the YAML, or (MJCF) one of gazebot's
own models in ``gazebot/assets/robots/``. A ``package://`` URI is looked up, in order, in the
folders given by the caller (the CLI's ``--package-path``), those of ``ROS_PACKAGE_PATH`` and the
``share/`` folders of installed cmeel prefixes (where ``pip install example-robot-data`` puts its
robots, the layout ROS 2's ament index uses).
"""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence
from pathlib import Path

PACKAGE_SCHEME = "package://"
ASSETS = Path(__file__).resolve().parents[2] / "assets" / "robots"


def package_search_path(
    extra: Sequence[str | Path] = (), environ: dict[str, str] | None = None
) -> list[Path]:
    """The folders a ``package://NAME/...`` URI is looked up in, in order.

    Args:
        extra: Folders given by the caller (``--package-path``), searched first.
        environ: The environment to read ``ROS_PACKAGE_PATH`` from (default: ``os.environ``).
    """
    env = os.environ if environ is None else environ
    folders = [Path(p) for p in extra]
    folders += [Path(p) for p in env.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
    for entry in sys.path:
        share = Path(entry or ".") / "cmeel.prefix" / "share"
        if share.is_dir():
            folders.append(share)
    return folders


def resolve_package_uri(uri: str, search: Sequence[Path]) -> Path | None:
    """The file a ``package://NAME/PATH`` URI names, or ``None`` when no folder has it.

    A folder may hold the package (``FOLDER/NAME/PATH``) or be the package itself
    (``FOLDER`` named ``NAME``: ``FOLDER/PATH``), as ``ROS_PACKAGE_PATH`` entries are either.
    """
    rest = uri.removeprefix(PACKAGE_SCHEME)
    name, _, inner = rest.partition("/")
    for folder in search:
        for cand in (folder / name / inner, folder / inner if folder.name == name else None):
            if cand is not None and cand.is_file():
                return cand.resolve()
    return None


def resolve_model_path(
    raw: str, yaml_path: Path | None, search: Sequence[Path], *, assets: bool
) -> tuple[Path | None, str]:
    """The model file ``raw`` names and, when not found, where it was looked for.

    Args:
        raw: The YAML's ``urdf:``/``mjcf:`` value.
        yaml_path: The robot YAML (relative paths are beside it), or ``None``.
        search: Folders for ``package://`` URIs (:func:`package_search_path`).
        assets: Also look in gazebot's own ``assets/robots/`` (the shipped MJCF robots).
    """
    if raw.startswith(PACKAGE_SCHEME):
        found = resolve_package_uri(raw, search)
        where = ", ".join(str(f) for f in search) or "no folders"
        package = raw.removeprefix(PACKAGE_SCHEME).partition("/")[0]
        return found, (
            f"package {package!r} in --package-path, ROS_PACKAGE_PATH or an installed cmeel "
            f"prefix (searched {where})"
        )
    path = Path(raw)
    candidates = [path] if path.is_absolute() else []
    if yaml_path is not None and not path.is_absolute():
        candidates.append(yaml_path.parent / path)
    if assets:
        candidates += [ASSETS / path, ASSETS / path.name]
    for cand in candidates:
        if cand.is_file():
            return cand, ""
    where = f"beside the YAML or in {ASSETS}" if assets else "beside the YAML"
    return None, f"an existing file ({where})"
