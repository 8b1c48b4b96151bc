"""A study file's items in a posted form: each answer checked against its item (a Likert point
in range, an option of the list, an integer in range, text cut to its length), with one message
per missing or bad answer naming the question, and the attention checks failed."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from gazebot.apps.study.study_file import (
    AttentionItem,
    ChoiceItem,
    Item,
    LikertItem,
    NumberItem,
    TextItem,
)


@dataclass
class ItemForm:
    """What a form gave for a list of items: ``values`` (item id -> the answer as stored),
    ``failed`` (attention item id -> (given, expected)) and ``errors`` (one per item to fix)."""

    values: dict[str, str] = field(default_factory=dict)
    failed: dict[str, tuple[str, str]] = field(default_factory=dict)
    errors: list[str] = field(default_factory=list)


def _check(item: Item, raw: str) -> str | None:
    """The stored value of a non-empty answer ``raw``, ``None`` if it is not one ``item``
    takes."""
    if isinstance(item, LikertItem):
        ok = raw.isascii() and raw.isdigit() and 1 <= int(raw) <= item.points
        return str(int(raw)) if ok else None
    if isinstance(item, ChoiceItem):  # an attention check too
        return raw if raw in item.options else None
    if isinstance(item, NumberItem):
        digits = raw[1:] if raw.startswith("-") else raw
        ok = digits.isascii() and digits.isdigit() and item.min <= int(raw) <= item.max
        return str(int(raw)) if ok else None
    assert isinstance(item, TextItem)
    return raw[: item.max_length]


def _expected(item: Item) -> str:
    if isinstance(item, LikertItem):
        return f"a point from 1 to {item.points}"
    if isinstance(item, ChoiceItem):
        return "one of the options"
    if isinstance(item, NumberItem):
        return f"a whole number from {item.min} to {item.max}"
    return "an answer"


def parse_items(items: list[Item], form: Mapping[str, str], first_number: int = 1) -> ItemForm:
    """Check the answers ``form`` gives to ``items`` (numbered from ``first_number`` on the page,
    as the messages name them)."""
    out = ItemForm()
    for k, item in enumerate(items, start=first_number):
        raw = form.get(item.id, "").strip()
        if not raw:
            if item.required:
                out.errors.append(f"Question {k} ({item.text}) needs an answer.")
            continue
        value = _check(item, raw)
        if value is None:
            out.errors.append(f"Question {k} ({item.text}): expected {_expected(item)}.")
            continue
        out.values[item.id] = value
        if isinstance(item, AttentionItem) and value != item.answer:
            out.failed[item.id] = (value, item.answer)
    return out
