"""One registry per extension kind: the names the CLI offers, the configs accept and the README
lists all come from it.

Two kinds of registry:

- :class:`Registry`, for code: reach **controllers** (:data:`gazebot.apps.controllers.CONTROLLERS`)
  and **phase methods** (:data:`gazebot.core.phases.methods.PHASE_METHODS`). Adding one is a new
  file plus one :meth:`Registry.register` line, inside the package or from a user's own code
  (``examples/register_extensions.py``)::

      from gazebot.apps.controllers import CONTROLLERS
      CONTROLLERS.register("mine", MyController, "what it does")

  An installed package reaches the registry (and so the real ``gazebot`` command) through an
  entry point: group ``gazebot.controllers`` or ``gazebot.phase_methods``, the entry's name the
  extension's name, its value the ``module:attribute`` that builds it. Entry points are read
  when the registry is first read (no import until the extension is chosen); a built-in or an
  earlier registration keeps its name (the entry point is skipped with a warning)::

      [project.entry-points."gazebot.controllers"]
      mine = "my_package.controllers:MyController"

- :class:`FolderRegistry`, for YAML: **robots**, **behaviors**, **eye styles** and **scenes**
  are files in ``configs/<kind>/`` (behaviors also in user folders); the folder is the registry.

:func:`gazebot.apps.cli.registries.registries` returns all six by kind.
"""

from __future__ import annotations

import importlib
import importlib.metadata
import warnings
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
        """The factory, importing ``"module:attribute"`` on first use."""
        if isinstance(self.factory, str):
            module, _, attr = self.factory.partition(":")
            obj: object = importlib.import_module(module)
            for part in attr.split(".") if attr else ():
                obj = getattr(obj, part)
            return obj  # type: ignore[return-value]
        return self.factory


class NameRegistry(Protocol):
    """What every registry offers: its kind, its names and a check of a name."""

    kind: str

    def names(self) -> tuple[str, ...]:
        """Every name the registry knows."""

    def check(self, name: str) -> str:
        """``name`` if known, else the one ``ValueError`` listing the known names."""


def unknown(kind: str, name: object, known: tuple[str, ...]) -> ValueError:
    """The one error for a name no registry knows."""
    return ValueError(f"unknown {kind} {name!r} (known: {', '.join(known)})")


class Registry(Generic[T]):
    """Names -> factories of one code extension kind, in registration order.

    Args:
        kind: What an entry is (``controller``), for messages and the table's heading.
        group: The entry-point group installed packages register in (e.g.
            ``gazebot.controllers``), read when the registry is first read; ``None``: none.
    """

    def __init__(self, kind: str, group: str | None = None) -> None:
        self.kind = kind
        self.group = group
        self._entries: dict[str, Entry[T]] = {}
        self._installed: set[str] = set()  # names that came from entry points
        self._read_entry_points = group is None

    def _ensure(self) -> None:
        if not self._read_entry_points:
            self._read_entry_points = True
            self._add_entry_points()

    def _add_entry_points(self) -> None:
        if self.group is None:
            return
        for ep in importlib.metadata.entry_points(group=self.group):
            if ep.name in self._entries:
                warnings.warn(f"{self.kind} {ep.name!r} of entry point {ep.value!r} ignored: "
                              "the name is already registered", stacklevel=3)
                continue
            dist = getattr(ep, "dist", None)
            where = f"{dist.name}, {ep.value}" if dist is not None else ep.value
            self.register(ep.name, ep.value, f"installed extension ({where})")
            self._installed.add(ep.name)

    def reload_entry_points(self) -> None:
        """Forget the entries that came from entry points and read the group again (after
        installing a package into a running process; tests)."""
        for name in self._installed:
            self._entries.pop(name, None)
        self._installed.clear()
        self._read_entry_points = self.group is None

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
        self._installed.discard(name)

    def names(self) -> tuple[str, ...]:
        """Every registered name: the built-ins, then installed and user extensions."""
        self._ensure()
        return tuple(self._entries)

    def check(self, name: str) -> str:
        """``name`` if registered, else the one ``ValueError`` listing the known names."""
        self._ensure()
        if name not in self._entries:
            raise unknown(self.kind, name, self.names())
        return name

    def entry(self, name: str) -> Entry[T]:
        """The :class:`Entry` of ``name`` (``ValueError`` if unknown)."""
        return self._entries[self.check(name)]

    def make(self, name: str, *args: object, **kwargs: object) -> T:
        """Build the extension ``name`` with the given arguments.

        Raises:
            ValueError: ``name`` is unknown, or its ``module:attribute`` cannot be imported.
        """
        entry = self.entry(name)
        try:
            factory = entry.load()
        except (ImportError, AttributeError) as exc:
            raise ValueError(f"{self.kind} {name!r}: cannot load {entry.factory!r} "
                             f"({type(exc).__name__}: {exc})") from None
        return factory(*args, **kwargs)

    def table(self, builtin_only: bool = False) -> str:
        """The registry as a Markdown table (the README's is this text, ``builtin_only``:
        without installed extensions)."""
        self._ensure()
        rows = [f"| `{e.name}` | {e.description} |" for e in self._entries.values()
                if not (builtin_only and e.name in self._installed)]
        return "\n".join([f"| {self.kind} | what it is |", "| --- | --- |", *rows])


class FolderRegistry:
    """A YAML extension kind whose registry is a folder listing (``names`` calls ``lister``)."""

    def __init__(self, kind: str, lister: Callable[[], list[str] | tuple[str, ...]]) -> None:
        self.kind = kind
        self._lister = lister

    def names(self) -> tuple[str, ...]:
        """The names the folder lists now."""
        return tuple(self._lister())

    def check(self, name: str) -> str:
        """``name`` if the folder lists it, else the one ``ValueError`` listing the known names."""
        if name not in self.names():
            raise unknown(self.kind, name, self.names())
        return name
