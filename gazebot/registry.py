"""One registry per extension kind: the names the CLI offers, the configs accept and the README
lists all come from it.

Two kinds of registry:

- :class:`Registry`, for code: reach **controllers** (:data:`gazebot.controllers.CONTROLLERS`)
  and **phase methods** (:data:`gazebot.phases.methods.PHASE_METHODS`). Adding one is a new
  file plus one :meth:`Registry.register` line, inside the package or from a user's own code
  (``examples/register_extensions.py``)::

      from gazebot.controllers import CONTROLLERS
      CONTROLLERS.register("mine", MyController, "what it does")

- :class:`FolderRegistry`, for YAML: **robots**, **behaviors**, **eye styles** and **scenes**
  are files in ``configs/<kind>/`` (behaviors also in user folders); the folder is the registry.

:func:`registries` returns all six by kind.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass
from typing import Generic, Protocol, TypeVar

T = TypeVar("T")


@dataclass(frozen=True)
class Entry(Generic[T]):
    """One registered extension: its name, what builds it (or ``"module:attribute"``, imported
    on first use so a heavy dependency loads only when chosen) and a one-line description."""

    name: str
    factory: Callable[..., T] | str
    description: str = ""

    def load(self) -> Callable[..., T]:
        if isinstance(self.factory, str):
            module, _, attr = self.factory.partition(":")
            return getattr(importlib.import_module(module), attr)
        return self.factory


class NameRegistry(Protocol):
    """What every registry offers: its kind, its names and a check of a name."""

    kind: str

    def names(self) -> tuple[str, ...]: ...

    def check(self, name: str) -> str: ...


def unknown(kind: str, name: object, known: tuple[str, ...]) -> ValueError:
    """The one error for a name no registry knows."""
    return ValueError(f"unknown {kind} {name!r} (known: {', '.join(known)})")


class Registry(Generic[T]):
    """Names -> factories of one code extension kind, in registration order."""

    def __init__(self, kind: str) -> None:
        self.kind = kind
        self._entries: dict[str, Entry[T]] = {}

    def register(
        self,
        name: str,
        factory: Callable[..., T] | str,
        description: str = "",
        *,
        replace: bool = False,
    ) -> None:
        """Add ``name``; ``replace`` to override an existing one (else a ``ValueError``)."""
        if not isinstance(name, str) or not name or name != name.strip():
            raise ValueError(f"a {self.kind} name must be a non-empty word, got {name!r}")
        if name in self._entries and not replace:
            raise ValueError(f"{self.kind} {name!r} is already registered")
        self._entries[name] = Entry(name, factory, description)

    def unregister(self, name: str) -> None:
        """Remove ``name`` (e.g. a test's own extension)."""
        self._entries.pop(self.check(name))

    def names(self) -> tuple[str, ...]:
        return tuple(self._entries)

    def check(self, name: str) -> str:
        """``name`` if registered, else the one ``ValueError`` listing the known names."""
        if name not in self._entries:
            raise unknown(self.kind, name, self.names())
        return name

    def entry(self, name: str) -> Entry[T]:
        return self._entries[self.check(name)]

    def make(self, name: str, *args: object, **kwargs: object) -> T:
        """Build the extension ``name`` with the given arguments."""
        return self.entry(name).load()(*args, **kwargs)

    def table(self) -> str:
        """The registry as a Markdown table (the README's is this text)."""
        rows = [f"| `{e.name}` | {e.description} |" for e in self._entries.values()]
        return "\n".join([f"| {self.kind} | what it is |", "| --- | --- |", *rows])


class FolderRegistry:
    """A YAML extension kind whose registry is a folder listing (``names`` calls ``lister``)."""

    def __init__(self, kind: str, lister: Callable[[], list[str] | tuple[str, ...]]) -> None:
        self.kind = kind
        self._lister = lister

    def names(self) -> tuple[str, ...]:
        return tuple(self._lister())

    def check(self, name: str) -> str:
        if name not in self.names():
            raise unknown(self.kind, name, self.names())
        return name


def registries() -> dict[str, NameRegistry]:
    """Every extension kind's registry: robots, behaviors, phase methods, controllers, eye
    styles and scenes."""
    from gazebot.behaviors import list_behaviors
    from gazebot.config import configs_dir
    from gazebot.controllers import CONTROLLERS
    from gazebot.phases.methods import PHASE_METHODS
    from gazebot.render.eye_style import available_eye_styles
    from gazebot.sim.scene_config import scene_names

    def robots() -> list[str]:
        return sorted(p.stem for p in (configs_dir() / "robots").glob("*.yaml"))

    return {
        "robots": FolderRegistry("robot", robots),
        "behaviors": FolderRegistry("behavior", lambda: [b.name for b in list_behaviors()]),
        "phase methods": PHASE_METHODS,
        "controllers": CONTROLLERS,
        "eye styles": FolderRegistry("eye style", available_eye_styles),
        "scenes": FolderRegistry("scene", scene_names),
    }
