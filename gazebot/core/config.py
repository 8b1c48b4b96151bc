"""Loading YAML configuration into pydantic models, with errors naming file, field and expectation.

Every package validates its own YAML through :func:`load_model`; nothing reads YAML by hand.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, TypeVar

import yaml
from pydantic import BaseModel, ValidationError

M = TypeVar("M", bound=BaseModel)


class ConfigError(ValueError):
    """A configuration file (or value) is malformed.

    The message names the file, the field (dotted path) and what was expected.
    """

    def __init__(self, source: str | Path, field: str, expected: str, got: Any = None):
        self.source = str(source)
        self.field = field
        self.expected = expected
        self.got = got
        msg = f"{self.source}: field '{field}': expected {expected}"
        if got is not None:
            msg += f", got {got!r}"
        super().__init__(" ".join(msg.splitlines()))  # one line, whatever a library said


def configs_dir() -> Path:
    """The directory holding the shipped configuration (``configs/`` of the repo or the wheel)."""
    here = Path(__file__).resolve().parents[1]  # the gazebot package
    for cand in (here.parent / "configs", here / "_configs"):
        if cand.is_dir():
            return cand
    raise FileNotFoundError("gazebot's configs/ directory was not found beside the package")


MAX_YAML_BYTES = 1_000_000  # the largest shipped config is 7 kB
MAX_YAML_DEPTH = 64  # nesting levels; PyYAML's composer recurses once per level


class _BoundedLoader(yaml.SafeLoader):
    """PyYAML's safe loader without aliases and with bounded nesting: a 1 kB file of nested
    aliases ("billion laughs") expands to gigabytes, and thousands of ``[`` exhaust the stack.
    gazebot's configs use neither."""

    def __init__(self, stream: str) -> None:
        super().__init__(stream)
        self._depth = 0

    def compose_node(self, parent, index):  # noqa: ANN001, ANN201 (PyYAML's signature)
        if self.check_event(yaml.AliasEvent):
            raise yaml.composer.ComposerError(
                None,
                None,
                "an alias (*name): aliases and merge keys are not accepted in gazebot configs",
                self.peek_event().start_mark,
            )
        self._depth += 1
        try:
            if self._depth > MAX_YAML_DEPTH:
                raise yaml.composer.ComposerError(
                    None,
                    None,
                    f"more than {MAX_YAML_DEPTH} levels of nesting",
                    self.peek_event().start_mark,
                )
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1


def read_yaml(path: str | Path, max_bytes: int = MAX_YAML_BYTES) -> Any:
    """Parse a YAML file (every gazebot config, behavior, scene and robot file is read here).

    A file over ``max_bytes``, an alias, nesting deeper than :data:`MAX_YAML_DEPTH` or a syntax
    error becomes a :class:`ConfigError` naming the file (and line and column)."""
    path = Path(path)
    try:
        with path.open("rb") as fh:
            raw = fh.read(max_bytes + 1)  # never more than the cap, whatever the file is
    except OSError as exc:
        raise ConfigError(path, "<file>", "a readable YAML file", str(exc)) from exc
    if len(raw) > max_bytes:
        raise ConfigError(
            path, "<file>", f"a YAML file of at most {max_bytes} bytes", "a larger file"
        )
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ConfigError(
            path,
            "<file>",
            "UTF-8 text",
            f"byte 0x{exc.object[exc.start]:02x} at offset {exc.start}",
        ) from exc
    loader = None
    try:
        loader = _BoundedLoader(text)  # checks the characters: a control character is an error
        return loader.get_single_data()
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"line {mark.line + 1}, column {mark.column + 1}" if mark else "<document>"
        problem = getattr(exc, "problem", None) or str(exc)
        raise ConfigError(path, where, "valid YAML", problem) from exc
    except RecursionError:  # a nesting PyYAML's scanner recursed on before the composer
        raise ConfigError(path, "<document>", "valid YAML", "too deeply nested") from None
    finally:
        if loader is not None:
            loader.dispose()


def validate(model: type[M], data: Any, source: str | Path = "<config>") -> M:
    """Validate ``data`` against ``model``; the first error becomes a :class:`ConfigError`."""
    try:
        return model.model_validate(data if data is not None else {})
    except ValidationError as exc:
        err = exc.errors()[0]
        field = ".".join(str(p) for p in err["loc"]) or "<root>"
        kind = err["type"]
        got = err.get("input")
        if kind == "extra_forbidden":
            allowed = ", ".join(sorted(model.model_fields)) if len(err["loc"]) == 1 else None
            expected = f"no such field{f' (known fields: {allowed})' if allowed else ''}"
        elif kind == "missing":
            expected, got = "a value (the field is required)", None
        else:
            expected = err["msg"]
            for prefix in ("Input should be ", "Value error, "):
                if expected.startswith(prefix):
                    expected = expected[len(prefix) :]
        if isinstance(got, dict) and len(repr(got)) > 200:
            got = f"a mapping with keys {sorted(map(str, got))}"
        raise ConfigError(source, field, expected, got) from exc


def load_model(model: type[M], path: str | Path) -> M:
    """Read the YAML file at ``path`` and validate it as ``model``."""
    return validate(model, read_yaml(path), path)
