"""Finding and loading behaviors: built-ins in ``configs/behaviors/`` plus the user's folders.

A behavior is a YAML file; its name is the file's stem. User folders come from the
``dirs`` argument or, by default, the ``GAZEBOT_BEHAVIORS_PATH`` environment variable
(``os.pathsep``-separated folders); a user file with a built-in's name shadows the built-in.
A file with ``extends: BASE`` reuses BASE's segments and overrides its parameters (and may set its
own description, before, after, tracking_lost and phase_durations_s).
"""

from __future__ import annotations

import os
from collections.abc import Collection, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from gazebot.core.behaviors.segment import TRACKED_TARGETS, check_target_name
from gazebot.core.behaviors.spec import BehaviorSpec
from gazebot.core.config import (
    ConfigError,
    config_errors,
    configs_dir,
    locate,
    read_yaml_document,
)

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
        """The entry as a JSON object (``gazebot behaviors list --json``)."""
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


def load_behavior(
    name_or_path: str | Path,
    dirs: Sequence[Path] | None = None,
    points: Collection[str] | None = None,
) -> BehaviorSpec:
    """Load a behavior by name (built-in or user folder) or from a YAML file path.

    Args:
        name_or_path: A behavior name or a YAML file.
        dirs: User behavior folders (default: ``GAZEBOT_BEHAVIORS_PATH``).
        points: The names of the robot's points (``points:`` of its YAML): when given, every
            target must be one of them or a tracked target, as the engine requires.

    Raises:
        FileNotFoundError: unknown name or missing file.
        ConfigError: the file is malformed (the first of :func:`behavior_errors`).
    """
    spec, errors = _check(name_or_path, dirs, (), points)
    if errors:
        raise errors[0]
    assert spec is not None
    return spec


def behavior_errors(
    name_or_path: str | Path,
    dirs: Sequence[Path] | None = None,
    points: Collection[str] | None = None,
) -> list[ConfigError]:
    """Every error the engine would find in a behavior (``gazebot behaviors validate``): YAML
    syntax, unknown keys, types, phases, ``at`` fractions, ``$parameter`` and ``after:`` event
    references, durations and, with ``points``, the targets. Each names the file, the line and
    the field as written (``segments[1].target``); an empty list: the behavior is valid.

    Raises:
        FileNotFoundError: unknown name or missing file.
    """
    try:
        return _check(name_or_path, dirs, (), points)[1]
    except ConfigError as exc:  # the file as a whole (unreadable, invalid YAML)
        return [exc]


def known_targets(points: Collection[str]) -> list[str]:
    """The targets a behavior may name on a robot with ``points``: tracked ones and its points."""
    return sorted(TRACKED_TARGETS | set(points))


def _path_of(name_or_path: str | Path, dirs: Sequence[Path] | None) -> Path:
    text = str(name_or_path)
    is_path = isinstance(name_or_path, Path) or text.endswith((".yaml", ".yml")) or os.sep in text
    path = Path(text).expanduser() if is_path else behavior_path(text, dirs)
    if not path.is_file():
        raise FileNotFoundError(f"behavior file not found: {path}")
    return path


def _check(
    name_or_path: str | Path,
    dirs: Sequence[Path] | None,
    seen: tuple[str, ...],
    points: Collection[str] | None,
) -> tuple[BehaviorSpec | None, list[ConfigError]]:
    """The behavior and no errors, or ``None`` and every error found."""
    path = _path_of(name_or_path, dirs)
    doc = read_yaml_document(path)
    data = doc.data
    if not isinstance(data, dict):
        return None, [
            ConfigError(path, "<root>", "a mapping with 'segments' (or 'extends')", data)
        ]
    data = dict(data)
    data.setdefault("name", path.stem)
    if data.get("extends") is None:
        params = data.get("parameters")
        context = {"parameters": set(params) if isinstance(params, dict) else set()}
        spec, errors = config_errors(BehaviorSpec, data, path, doc.node, context)
    else:
        try:
            merged = _merge_variant(path, data, doc.node, dirs, seen)
        except ConfigError as exc:
            return None, [exc]
        spec, errors = config_errors(BehaviorSpec, merged, path, doc.node)
    if points is not None:
        # Targets too when the rest has errors: every error of the file at once.
        uses = _target_uses(spec) if spec is not None else _raw_target_uses(data)
        errors = sorted(
            [*errors, *_target_errors(uses, path, doc.node, points)],
            key=lambda e: e.line if e.line is not None else 0,
        )
    return (None if errors else spec), errors


def _merge_variant(
    path: Path,
    data: dict[str, Any],
    node: yaml.Node | None,
    dirs: Sequence[Path] | None,
    seen: tuple[str, ...],
) -> dict[str, Any]:
    """A variant's data merged onto its base's (``extends:``); :class:`ConfigError` if wrong."""
    base_name = data["extends"]

    def error(loc: tuple[Any, ...], expected: str, got: Any = None) -> ConfigError:
        field, line = locate(node, loc)
        return ConfigError(path, field, expected, got, line=line)

    if not isinstance(base_name, str) or base_name in seen or base_name == path.stem:
        raise error(("extends",), "the name of another behavior (no cycles)", base_name)
    allowed = {"name", "extends", "parameters", *_VARIANT_FIELDS}
    extra = sorted(set(data) - allowed)
    if extra:
        raise error((extra[0],), f"only {', '.join(sorted(allowed))} in a variant (extends:)")
    try:
        base = _load_base(base_name, dirs, (*seen, path.stem))
    except FileNotFoundError as exc:
        raise error(("extends",), "an available behavior", base_name) from exc
    merged = base.model_dump(exclude={"human"})
    merged["human"] = base.human.model_dump() if base.human is not None else None
    merged["segments"] = [s.model_dump() for s in base.segments]
    merged.update({k: v for k, v in data.items() if k != "parameters"})
    params = data.get("parameters") or {}
    if not isinstance(params, dict):
        raise error(("parameters",), "a mapping of parameter names to values", params)
    unknown = sorted(set(params) - set(base.parameters))
    if unknown:
        raise error(
            ("parameters", unknown[0]), f"a parameter of {base_name} {sorted(base.parameters)}"
        )
    merged["parameters"] = {**merged["parameters"], **params}
    return merged


def _load_base(name: str, dirs: Sequence[Path] | None, seen: tuple[str, ...]) -> BehaviorSpec:
    spec, errors = _check(name, dirs, seen, None)
    if errors:
        raise errors[0]
    assert spec is not None
    return spec


_TargetUse = tuple[tuple[Any, ...], str]


def _target_uses(spec: BehaviorSpec) -> list[_TargetUse]:
    """Every target ``spec`` names, with where (pydantic's location)."""
    uses: list[_TargetUse] = [
        (("before",), spec.before),
        (("after",), spec.after),
        (("tracking_lost", "target"), spec.tracking_lost.target),
        *((("segments", i, "target"), seg.target) for i, seg in enumerate(spec.segments)),
    ]
    if spec.human is not None:
        uses.extend((("human",), name) for name in sorted(spec.human.targets()))
    return uses


def _raw_target_uses(data: dict[str, Any]) -> list[_TargetUse]:
    """The target names a file that did not validate writes where they can be read."""
    uses: list[_TargetUse] = [((k,), data[k]) for k in ("before", "after") if k in data]
    lost = data.get("tracking_lost")
    if isinstance(lost, dict) and "target" in lost:
        uses.append((("tracking_lost", "target"), lost["target"]))
    segments = data.get("segments")
    if isinstance(segments, list):
        for i, seg in enumerate(segments):
            if isinstance(seg, dict) and "target" in seg:
                uses.append((("segments", i, "target"), seg["target"]))
    return [(loc, t) for loc, t in uses if isinstance(t, str)]


def _target_errors(
    uses: list[_TargetUse], path: Path, node: yaml.Node | None, points: Collection[str]
) -> list[ConfigError]:
    """An error for every target in ``uses`` that is neither tracked nor one of ``points``
    (a malformed name is the model's error, not reported again)."""
    known = known_targets(points)
    errors = []
    for loc, target in uses:
        if target in known or not _is_target_name(target):
            continue
        field, line = locate(node, loc)
        errors.append(
            ConfigError(
                path,
                field,
                f"a target ({', '.join(known)})",
                target,
                line=line,
                problem=f"{target!r} is not a target (known: {', '.join(known)})",
            )
        )
    return errors


def _is_target_name(name: str) -> bool:
    try:
        check_target_name(name)
    except ValueError:
        return False
    return True
