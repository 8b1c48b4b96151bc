"""The study file, ``DIR/study.yaml``: what a study asks besides the seed's five questions.

Without the file a served study is the seed's: consent, instructions, the practice and the plan's
sessions, each with the five 1st/2nd questions and a comment. The file adds (documented with a
complete example in ``docs/study-file.md``):

- ``session_items``: items asked after every pair, below the seed's questions;
- ``pages``: pages of items shown ``before`` the instructions (a demographics page) or ``after``
  the last session;
- items of five kinds: ``likert`` (``points`` and ``anchors``), ``text`` (free text), ``choice``
  (one of ``options``), ``number`` (an integer in ``min``..``max``) and ``attention`` (one of
  ``options`` with a required ``answer``: a failure is recorded and exported and, with
  ``on_failure: end``, ends the participant's study);
- ``entry``: a public entry link ``/start?PARAM=ID`` that gives each new external participant id
  the next free plan row (in participant order, so full counterbalanced blocks fill first);
- ``completion``: the completion code shown at the end, or a redirect to ``redirect_url`` with
  the code in it (as online recruiting services expect).

Errors name the file, the line and the field (:class:`~gazebot.core.config.ConfigError`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Literal
from urllib.parse import quote, urlsplit

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from gazebot.core.config import load_model

STUDY_FILE = "study.yaml"  # in the study folder, beside consent.txt
ITEM_ID = r"^[a-z][a-z0-9_]{0,39}$"
# Names the export and the session form already use: an item may not take them.
RESERVED_IDS = frozenset(
    {"q1", "q2", "q3", "q4", "q5", "comment", "comments", "csrf_token", "session"}
    | {"participant", "condition", "level", "first", "second", "group", "mode", "scene"}
    | {"robot", "gaze_mode", "shown_at", "submitted_at", "seconds", "external_id"}
    | {"attention_failures", "first_reach_start_time", "second_reach_start_time"}
)
MAX_TEXT = 4000  # characters a free-text answer keeps at most


class _Item(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)

    id: str = Field(pattern=ITEM_ID, description="the item's export column")
    text: str = Field(min_length=1, description="the question as shown")
    required: bool = True


class LikertItem(_Item):
    """A rating on ``points`` points (1..points); ``anchors``: the labels of both ends, or one
    label per point."""

    kind: Literal["likert"]
    points: int = Field(default=7, ge=2, le=11)
    anchors: list[str] = Field(min_length=2)

    @model_validator(mode="after")
    def _anchors(self) -> LikertItem:
        if len(self.anchors) not in (2, self.points):
            raise ValueError(
                f"anchors: 2 labels (both ends) or {self.points} (one per point), "
                f"got {len(self.anchors)}"
            )
        return self

    def labels(self) -> list[str]:
        """The label under each point ("" for a point between the two anchors)."""
        if len(self.anchors) == self.points:
            return list(self.anchors)
        return [self.anchors[0], *[""] * (self.points - 2), self.anchors[1]]


class TextItem(_Item):
    """A free-text answer of at most ``max_length`` characters."""

    kind: Literal["text"]
    max_length: int = Field(default=1000, ge=1, le=MAX_TEXT)
    rows: int = Field(default=2, ge=1, le=20)


class ChoiceItem(_Item):
    """One of ``options`` (stored as the option's text)."""

    kind: Literal["choice"]
    options: list[str] = Field(min_length=2)

    @model_validator(mode="after")
    def _distinct(self) -> ChoiceItem:
        if len(set(self.options)) != len(self.options):
            raise ValueError("options must be distinct")
        return self


class NumberItem(_Item):
    """An integer in ``min``..``max`` (an age, years of experience)."""

    kind: Literal["number"]
    min: int = 0
    max: int = 150

    @model_validator(mode="after")
    def _range(self) -> NumberItem:
        if self.min > self.max:
            raise ValueError(f"min ({self.min}) must not exceed max ({self.max})")
        return self


class AttentionItem(ChoiceItem):
    """A check that the participant reads: one of ``options`` is the required ``answer``.
    Another answer is recorded as a failure (and exported); ``on_failure: end`` also ends the
    participant's study there (with the screen-out code, if any)."""

    kind: Literal["attention"]  # type: ignore[assignment]
    answer: str
    on_failure: Literal["record", "end"] = "record"

    @model_validator(mode="after")
    def _answer_is_an_option(self) -> AttentionItem:
        if self.answer not in self.options:
            raise ValueError(f"answer {self.answer!r} is not one of the options {self.options}")
        return self


Item = Annotated[
    LikertItem | TextItem | ChoiceItem | NumberItem | AttentionItem,
    Field(discriminator="kind"),
]


class Page(BaseModel):
    """A page of items, shown once: ``before`` the instructions or ``after`` the last session."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    id: str = Field(pattern=ITEM_ID)
    title: str = Field(min_length=1)
    at: Literal["before", "after"] = "before"
    intro: str = ""
    items: list[Item] = Field(min_length=1)


class Entry(BaseModel):
    """The public entry link ``/start?PARAM=ID``: ``param`` names the URL parameter holding the
    recruiting service's participant id (Prolific's ``PROLIFIC_PID`` by default)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    param: str = Field(default="PROLIFIC_PID", pattern=r"^[A-Za-z][A-Za-z0-9_]{0,63}$")


class Completion(BaseModel):
    """The end of the study: ``code`` shown to the participant, or with ``redirect_url`` the
    browser sent there (``{code}`` in the URL replaced by the code); ``screen_out_code`` and
    ``screen_out_url`` likewise for a participant an attention check ended."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    code: str | None = Field(default=None, pattern=r"^[A-Za-z0-9_-]{1,64}$")
    redirect_url: str | None = None
    screen_out_code: str | None = Field(default=None, pattern=r"^[A-Za-z0-9_-]{1,64}$")
    screen_out_url: str | None = None

    @field_validator("redirect_url", "screen_out_url")
    @classmethod
    def _http_url(cls, url: str | None) -> str | None:
        if url is not None:
            parts = urlsplit(url)
            if parts.scheme not in ("https", "http") or not parts.netloc:
                raise ValueError(f"an http(s) URL with a host, got {url!r}")
        return url

    def url(self, screened_out: bool = False) -> str | None:
        """Where the browser goes at the end (``None``: stay on the closing page)."""
        url = self.screen_out_url if screened_out else self.redirect_url
        code = self.screen_out_code if screened_out else self.code
        return None if url is None else url.replace("{code}", quote(code or "", safe=""))


class StudyFile(BaseModel):
    """A study file (see the module doc)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    session_items: list[Item] = Field(default_factory=list)
    pages: list[Page] = Field(default_factory=list)
    entry: Entry | None = None
    completion: Completion = Completion()  # frozen: one shared default is safe

    @model_validator(mode="after")
    def _unique(self) -> StudyFile:
        pages = [p.id for p in self.pages]
        dup = sorted({p for p in pages if pages.count(p) > 1})
        if dup:
            raise ValueError(f"page ids must be unique, repeated: {dup}")
        ids = [i.id for i in self.items()]
        dup = sorted({i for i in ids if ids.count(i) > 1})
        if dup:
            raise ValueError(f"item ids must be unique across the study, repeated: {dup}")
        taken = sorted(set(ids) & RESERVED_IDS)
        if taken:
            raise ValueError(f"item ids {taken} are the export's own columns: rename them")
        return self

    def items(self) -> list[Item]:
        """Every item: the session items, then each page's in order."""
        return [*self.session_items, *(i for p in self.pages for i in p.items)]

    def pages_at(self, at: str) -> list[Page]:
        """The pages shown ``before`` the instructions or ``after`` the last session."""
        return [p for p in self.pages if p.at == at]

    def ends_on(self, failed_items: tuple[str, ...] | list[str]) -> bool:
        """Whether failing the attention checks ``failed_items`` ends the study."""
        ending = {
            i.id for i in self.items() if isinstance(i, AttentionItem) and i.on_failure == "end"
        }
        return bool(ending & set(failed_items))


DEFAULT = StudyFile()  # no study file: the seed's study


def load_study_file(path: str | Path) -> StudyFile:
    """Read and validate a study file; a bad one raises :class:`ConfigError` naming the file,
    the line and the field (``study.yaml:5: pages[0].items[0]: ...``)."""
    return load_model(StudyFile, path)


def study_file_of(study_root: str | Path) -> StudyFile:
    """The study file of a study folder (``DIR/study.yaml``), else :data:`DEFAULT`."""
    path = Path(study_root) / STUDY_FILE
    return load_study_file(path) if path.is_file() else DEFAULT
