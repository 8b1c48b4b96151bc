"""The ROS 2 type system gazebot speaks: ROS 2 Jazzy's standard messages plus ``gazebot_msgs``.

The ``gazebot_msgs`` types are read from the interface package's own ``msg/*.msg`` files (the
``gazebot_msgs/`` folder at the repository root, shipped in the wheel as
``gazebot/_gazebot_msgs``), the same files a colcon workspace builds: one source of truth.
Serialization, type hashes and message definitions all come from the rosbags
:class:`~rosbags.typesys.store.Typestore` built here.
"""

from __future__ import annotations

from functools import cache
from pathlib import Path

from rosbags.interfaces.typing import Typesdict
from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.store import Typestore

from gazebot.io.ros2.errors import MessageError

#: The ROS 2 distribution whose standard message definitions gazebot uses.
STORE = Stores.ROS2_JAZZY
PACKAGE = "gazebot_msgs"


def msgs_package_dir() -> Path:
    """The ``gazebot_msgs`` interface package: the repository's folder, else the wheel's copy."""
    here = Path(__file__).resolve().parents[2]  # the gazebot package
    for cand in (here.parent / PACKAGE, here / f"_{PACKAGE}"):
        if (cand / "msg").is_dir():
            return cand
    raise FileNotFoundError(f"the {PACKAGE} interface package was not found beside gazebot")


def read_msg_files(package_dir: Path) -> dict[str, str]:
    """ROS type name (``gazebot_msgs/msg/Name``) -> definition text, for every ``msg/*.msg``."""
    files = sorted((package_dir / "msg").glob("*.msg"))
    if not files:
        raise FileNotFoundError(f"{package_dir / 'msg'}: no .msg files")
    package = package_dir.name.removeprefix("_")  # the wheel ships it as gazebot/_gazebot_msgs
    return {f"{package}/msg/{f.stem}": f.read_text(encoding="utf-8") for f in files}


def build_typestore(package_dir: Path | None = None) -> Typestore:
    """ROS 2 Jazzy's types with the interface package at ``package_dir`` (default:
    :func:`msgs_package_dir`) registered from its ``.msg`` files.

    Raises:
        MessageError: A ``.msg`` file does not parse (names the type and the parser's reason).
    """
    store = get_typestore(STORE)
    for name, text in read_msg_files(package_dir or msgs_package_dir()).items():
        try:
            store.register(get_types_from_msg(text, name))
        except Exception as exc:  # rosbags raises its own parse errors
            raise MessageError(name, f"definition does not parse ({exc})") from None
    return store


def definition_types(type_name: str, text: str) -> Typesdict:
    """The types of a full message definition as ``ros2 bag`` embeds it in MCAP (``ros2msg``):
    ``type_name``'s own fields, then a ``===`` line and ``MSG: pkg/Name`` before each
    dependency. Returns rosbags' type dict, ready for ``Typestore.register``.

    Raises:
        MessageError: A section that does not parse.
    """
    sections: list[tuple[str, list[str]]] = [(type_name, [])]
    for line in text.splitlines():
        stripped = line.strip()
        if len(stripped) >= 3 and set(stripped) == {"="}:
            sections.append(("", []))
        elif not sections[-1][0] and stripped.startswith("MSG:"):
            name = stripped[4:].strip()
            pkg, _, short = name.rpartition("/")
            if "/msg/" not in name:
                name = f"{pkg}/msg/{short}"
            sections[-1] = (name, sections[-1][1])
        else:
            sections[-1][1].append(line)
    types: Typesdict = {}
    for name, lines in sections:
        if not name:
            raise MessageError(type_name, "a definition section without 'MSG: pkg/Name'")
        try:
            types.update(get_types_from_msg("\n".join(lines), name))
        except Exception as exc:  # rosbags raises its own parse errors
            raise MessageError(name, f"definition does not parse ({exc})") from None
    return types


@cache
def typestore() -> Typestore:
    """The shipped type system (built once per process: a pure function of the package files)."""
    return build_typestore()
