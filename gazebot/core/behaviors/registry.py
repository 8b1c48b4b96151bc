"""Finding and loading behaviors: built-ins in ``configs/behaviors/`` plus the user's folders.

A behavior is a YAML file; its name is the file's stem. User folders come from the
``dirs`` argument or, by default, the ``GAZEBOT_BEHAVIORS_PATH`` environment variable
(``os.pathsep``-separated folders); a user file with a built-in's name shadows the built-in.
A file with ``extends: BASE`` reuses BASE's segments and overrides its parameters (and may set its
own description, before, after, tracking_lost and phase_durations_s).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from gazebot.core.behaviors.spec import BehaviorSpec
from gazebot.core.config import ConfigError, configs_dir, read_yaml, validate

ENV_PATH = "GAZEBOT_BEHAVIORS_PATH"
#: How a built-in behavior's ``source:`` starts when it implements a gaze behavior of the seed.
SEED_SOURCE = "seed "
# Fields a variant may set besides its parameters; segments always come from the base.
_VARIANT_FIELDS = ("description", "source", "before", "after", "tracking_lost", "phase_durations_s")


@dataclass(frozen=True)
class BehaviorInfo:
    """One available behavior (``gazebot behaviors list``)."""

    name: str
    path: Path
    builtin: bool
    description: str
    source: str
    extends: str | None

    def to_json(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "path": str(self.path),
            "builtin": self.builtin,
            "description": self.description,
            "source": self.source,
            "extends": self.extends,
        }


def builtin_dir() -> Path:
    """The folder of the shipped behaviors."""
    return configs_dir() / "behaviors"


def user_dirs(env: dict[str, str] | None = None) -> list[Path]:
    """User behavior folders from ``GAZEBOT_BEHAVIORS_PATH`` (``env`` defaults to os.environ)."""
    value = (os.environ if env is None else env).get(ENV_PATH, "")
    return [Path(p).expanduser() for p in value.split(os.pathsep) if p]


def _files(dirs: Sequence[Path]) -> dict[str, tuple[Path, bool]]:
    """Behavior files by name; later folders shadow earlier ones."""
    found: dict[str, tuple[Path, bool]] = {}
    builtin = builtin_dir().resolve()
    for folder in dirs:
        folder = Path(folder)
        if not folder.is_dir():
            continue
        is_builtin = folder.resolve() == builtin
        for path in sorted(folder.glob("*.yaml")):
            found[path.stem] = (path, is_builtin)
    return found


def search_dirs(dirs: Sequence[Path] | None = None) -> list[Path]:
    """Built-in folder first, then ``dirs`` (default: :func:`user_dirs`)."""
    return [builtin_dir(), *(user_dirs() if dirs is None else [Path(d) for d in dirs])]


def list_behaviors(dirs: Sequence[Path] | None = None) -> list[BehaviorInfo]:
    """Every available behavior, sorted by name; a broken file raises :class:`ConfigError`."""
    out = []
    for name, (path, builtin) in sorted(_files(search_dirs(dirs)).items()):
        spec = load_behavior(path, dirs)
        out.append(BehaviorInfo(name, path, builtin, spec.description, spec.source, spec.extends))
    return out


def seed_behaviors() -> tuple[str, ...]:
    """The built-in behaviors that implement one of the seed's own gaze behaviors (chapter 6):
    those whose YAML says ``source: seed ...``, sorted by name."""
    return tuple(
        b.name for b in list_behaviors([]) if b.builtin and b.source.startswith(SEED_SOURCE)
    )


def behavior_path(name: str, dirs: Sequence[Path] | None = None) -> Path:
    """The YAML file of behavior ``name``; :class:`FileNotFoundError` lists what exists."""
    files = _files(search_dirs(dirs))
    if name not in files:
        raise FileNotFoundError(
            f"unknown behavior {name!r}; available: {', '.join(sorted(files))} "
            f"(or give a path to a behavior YAML file)"
        )
    return files[name][0]


def load_behavior(name_or_path: str | Path, dirs: Sequence[Path] | None = None) -> BehaviorSpec:
    """Load a behavior by name (built-in or user folder) or from a YAML file path.

    Raises:
        FileNotFoundError: unknown name or missing file.
        ConfigError: the file is malformed (names file, field and what was expected).
    """
    return _load(name_or_path, dirs, seen=())


def _load(
    name_or_path: str | Path, dirs: Sequence[Path] | None, seen: tuple[str, ...]
) -> BehaviorSpec:
    text = str(name_or_path)
    is_path = isinstance(name_or_path, Path) or text.endswith((".yaml", ".yml")) or os.sep in text
    path = Path(text).expanduser() if is_path else behavior_path(text, dirs)
    if not path.is_file():
        raise FileNotFoundError(f"behavior file not found: {path}")
    data = read_yaml(path)
    if not isinstance(data, dict):
        raise ConfigError(path, "<root>", "a mapping with 'segments' (or 'extends')", data)
    data = dict(data)
    data.setdefault("name", path.stem)
    base_name = data.get("extends")
    if base_name is None:
        return validate(BehaviorSpec, data, path)
    if not isinstance(base_name, str) or base_name in seen or base_name == path.stem:
        raise ConfigError(path, "extends", "the name of another behavior (no cycles)", base_name)
    allowed = {"name", "extends", "parameters", *_VARIANT_FIELDS}
    extra = sorted(set(data) - allowed)
    if extra:
        raise ConfigError(path, extra[0], f"only {sorted(allowed)} in a variant (extends:)")
    try:
        base = _load(base_name, dirs, (*seen, path.stem))
    except FileNotFoundError as exc:
        raise ConfigError(path, "extends", "an available behavior", base_name) from exc
    merged = base.model_dump(exclude={"human"})
    merged["human"] = base.human.model_dump() if base.human is not None else None
    merged["segments"] = [s.model_dump() for s in base.segments]
    merged.update({k: v for k, v in data.items() if k != "parameters"})
    params = data.get("parameters") or {}
    if not isinstance(params, dict):
        raise ConfigError(path, "parameters", "a mapping of parameter names to values", params)
    unknown = sorted(set(params) - set(base.parameters))
    if unknown:
        raise ConfigError(
            path,
            f"parameters.{unknown[0]}",
            f"a parameter of {base_name} {sorted(base.parameters)}",
        )
    merged["parameters"] = {**merged["parameters"], **params}
    return validate(BehaviorSpec, merged, path)
