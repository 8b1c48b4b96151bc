"""Loading YAML configuration into pydantic models, with errors naming file, field and expectation.

Every package validates its own YAML through :func:`load_model`; nothing reads YAML by hand.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeVar

import yaml
from pydantic import BaseModel, ValidationError

M = TypeVar("M", bound=BaseModel)


class ConfigError(ValueError):
    """A configuration file (or value) is malformed.

    The message names the file, the field and what was expected. When the line is known it reads
    ``FILE:LINE: FIELD: PROBLEM`` (``FIELD`` as the user wrote it, ``segments[1].target``), the
    form editors and compilers use; else ``FILE: field 'FIELD': expected ...``.

    Args:
        source: The file (or what the value came from).
        field: The field, dotted, list items as ``[i]``; ``<file>``, ``<document>`` and
            ``<root>`` for the file as a whole.
        expected: What the field should have been.
        got: The value found, if any.
        line: The 1-based line of the field in the file, if known.
        column: The 1-based column, if known (YAML syntax errors).
        problem: The whole sentence after the field, instead of ``expected ..., got ...``.
    """

    def __init__(
        self,
        source: str | Path,
        field: str,
        expected: str,
        got: Any = None,
        *,
        line: int | None = None,
        column: int | None = None,
        problem: str | None = None,
    ):
        self.source = str(source)
        self.field = field
        self.expected = expected
        self.got = got
        self.line = line
        self.column = column
        if problem is None:
            problem = f"expected {expected}"
            if got is not None:
                problem += f", got {got!r}"
        self.problem = problem
        if line is None:
            msg = f"{self.source}: field '{field}': {problem}"
        else:
            where = f"{self.source}:{line}" + (f":{column}" if column is not None else "")
            msg = f"{where}: {problem}" if field.startswith("<") else f"{where}: {field}: {problem}"
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


@dataclass(frozen=True)
class YamlDocument:
    """A parsed YAML file: its data and the node tree it was built from (for line numbers)."""

    path: Path
    data: Any
    node: yaml.Node | None


def read_yaml(path: str | Path, max_bytes: int = MAX_YAML_BYTES) -> Any:
    """Parse a YAML file (every gazebot config, behavior, scene and robot file is read here).

    A file over ``max_bytes``, an alias, nesting deeper than :data:`MAX_YAML_DEPTH` or a syntax
    error becomes a :class:`ConfigError` naming the file (and line and column)."""
    return read_yaml_document(path, max_bytes).data


def read_yaml_document(path: str | Path, max_bytes: int = MAX_YAML_BYTES) -> YamlDocument:
    """Like :func:`read_yaml`, keeping the composed node tree: its marks give each field's line
    (:func:`line_of`)."""
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
        node = loader.get_single_node()
        data = loader.construct_document(node) if node is not None else None
        return YamlDocument(path, data, node)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        problem = getattr(exc, "problem", None) or str(exc)
        if mark is None:
            raise ConfigError(path, "<document>", "valid YAML", problem) from exc
        raise ConfigError(
            path,
            "<document>",
            "valid YAML",
            problem,
            line=mark.line + 1,
            column=mark.column + 1,
            problem=f"invalid YAML: {problem}",
        ) from exc
    except RecursionError:  # a nesting PyYAML's scanner recursed on before the composer
        raise ConfigError(path, "<document>", "valid YAML", "too deeply nested") from None
    finally:
        if loader is not None:
            loader.dispose()


# Names pydantic puts in an error's location for a member of a union or a type check (``int``,
# ``AtFraction``, ``function-after[...]``): not keys a user wrote.
_TYPE_TAGS = {"str", "int", "float", "bool", "none", "list", "dict", "tuple", "set"}


def _is_tag(part: str) -> bool:
    return part in _TYPE_TAGS or not part.replace("_", "a").replace("-", "a").islower() or (
        "[" in part
    )


def locate(
    node: yaml.Node | None, loc: tuple[Any, ...], missing: bool = True
) -> tuple[str, int | None]:
    """The field of pydantic's error location ``loc`` as a user wrote it (``segments[1].at``)
    and its line in the file (1-based; the deepest part of ``loc`` the file has), ``None``
    without a node tree. ``missing``: a last part the file lacks is a missing key (kept), not
    the tag of a union member (dropped)."""
    field = ""
    line = None
    for i, part in enumerate(loc):
        if isinstance(node, yaml.MappingNode):
            keys = [getattr(k, "value", None) for k, _ in node.value]
            if str(part) in keys:
                field += f".{part}" if field else str(part)
                pair = node.value[keys.index(str(part))]
                line, node = pair[0].start_mark.line + 1, pair[1]
                continue
            if i + 1 < len(loc) and str(loc[i + 1]) in keys:
                continue  # a union member's tag (``likert``): the next part is the key
            if i + 1 == len(loc) and not missing:
                break  # a union member's tag: the error is the whole mapping's
        if isinstance(node, yaml.SequenceNode) and isinstance(part, int):
            if 0 <= part < len(node.value):
                node = node.value[part]
                line = node.start_mark.line + 1
            field += f"[{part}]"
            continue
        if isinstance(part, int):
            field += f"[{part}]"
        elif not _is_tag(str(part)):
            field += f".{part}" if field else str(part)
        node = None  # beyond what the file holds: the line stays the deepest found
    return field or "<root>", line


def _is_model(annotation: Any) -> bool:
    """Whether ``annotation`` is a pydantic model class (on Python 3.10 a ``list[X]`` alias passes
    ``isinstance(_, type)`` but is no class ``issubclass`` takes)."""
    try:
        return isinstance(annotation, type) and issubclass(annotation, BaseModel)
    except TypeError:
        return False


def _sub_model(model: type[BaseModel], loc: tuple[Any, ...]) -> type[BaseModel] | None:
    """The model that holds the last key of ``loc`` (for an unknown key: whose keys to list)."""
    current: Any = model
    for part in loc[:-1]:
        if not _is_model(current):
            return None
        if isinstance(part, int) or part not in current.model_fields:
            continue
        annotation = current.model_fields[part].annotation
        models = [
            a
            for a in (annotation, *_flat_args(annotation))
            if _is_model(a)
        ]
        if not models:
            return None
        current = models[0]
    return current if _is_model(current) else None


def _flat_args(annotation: Any) -> list[Any]:
    from typing import get_args

    out = []
    for arg in get_args(annotation):
        out.append(arg)
        out.extend(_flat_args(arg))
    return out


def user_keys(model: type[BaseModel]) -> list[str]:
    """The keys a user may write in a YAML mapping of ``model``: its fields by their YAML name
    (alias), without those a loader fills in (``json_schema_extra={"internal": True}``)."""
    keys = []
    for name, info in model.model_fields.items():
        extra = info.json_schema_extra if isinstance(info.json_schema_extra, dict) else {}
        if not extra.get("internal"):
            keys.append(info.alias or name)
    return sorted(keys)


def config_errors(
    model: type[M],
    data: Any,
    source: str | Path = "<config>",
    node: yaml.Node | None = None,
    context: dict[str, Any] | None = None,
) -> tuple[M | None, list[ConfigError]]:
    """Validate ``data`` against ``model``: the model, or ``None`` and every error found, each a
    :class:`ConfigError` with the line of its field when ``node`` (the YAML node tree, see
    :func:`read_yaml_document`) is given. ``context`` reaches the model's validators."""
    try:
        return model.model_validate(data if data is not None else {}, context=context), []
    except ValidationError as exc:
        return None, [_error(model, err, source, node) for err in exc.errors()]


def _error(
    model: type[BaseModel], err: Any, source: str | Path, node: yaml.Node | None
) -> ConfigError:
    loc = tuple(err["loc"])
    field, line = locate(node, loc, missing=err["type"] == "missing")
    if node is None:  # no file to point into: pydantic's dotted location, as callers knew it
        field = ".".join(str(p) for p in loc) or "<root>"
    kind = err["type"]
    got = err.get("input")
    if kind == "extra_forbidden":
        holder = _sub_model(model, loc)
        allowed = ", ".join(user_keys(holder)) if holder is not None else None
        expected = f"no such field{f' (known fields: {allowed})' if allowed else ''}"
        problem = f"unknown key{f' (known: {allowed})' if allowed else ''}"
        return ConfigError(source, field, expected, line=line, problem=problem if line else None)
    elif kind == "missing":
        expected, got = "a value (the field is required)", None
    else:
        expected = err["msg"]
        for prefix in ("Input should be ", "Value error, "):
            if expected.startswith(prefix):
                expected = expected[len(prefix) :]
    if isinstance(got, dict) and len(repr(got)) > 200:
        got = f"a mapping with keys {sorted(map(str, got))}"
    return ConfigError(source, field, expected, got, line=line)


def validate(
    model: type[M],
    data: Any,
    source: str | Path = "<config>",
    node: yaml.Node | None = None,
    context: dict[str, Any] | None = None,
) -> M:
    """Validate ``data`` against ``model``; the first error becomes a :class:`ConfigError` (with
    its line when ``node``, the YAML node tree, is given)."""
    result, errors = config_errors(model, data, source, node, context)
    if errors:
        raise errors[0]
    assert result is not None
    return result


def load_model(model: type[M], path: str | Path) -> M:
    """Read the YAML file at ``path`` and validate it as ``model`` (errors name the line)."""
    doc = read_yaml_document(path)
    return validate(model, doc.data, path, doc.node)
