"""A rendered study folder (``gazebot study render --out DIR``) as ``serve`` and ``export`` read
it: the plan, the gaze mode and each session's two handover videos."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from gazebot.apps.study.plan import Session, read_plan
from gazebot.apps.study.store import ResponseStore

PRACTICE = 0  # session number of the practice session


@dataclass(frozen=True)
class SessionVideos:
    """The two handover videos of one session, relative to the study folder, and their seed's
    reach-start times (s; ``None``: unknown, e.g. a study rendered before they were recorded)."""

    first: str
    second: str
    first_reach_start_time: float | None = None
    second_reach_start_time: float | None = None

    @classmethod
    def from_manifest(cls, entry: dict) -> SessionVideos:
        times = []
        for key in ("first_reach_start_time", "second_reach_start_time"):
            v = entry.get(key)
            if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float))):
                raise ValueError(f"{key!r} (expected seconds or null, got {v!r})")
            times.append(None if v is None else float(v))
        return cls(str(entry["first"]), str(entry["second"]), *times)


@dataclass(frozen=True)
class StudyFolder:
    """``root``: the folder; ``plan``: its sessions; ``videos[(participant, session)]``: what each
    session shows (session 0 = the practice, the same for everyone)."""

    root: Path
    plan: list[Session]
    gaze_mode: str
    practice: SessionVideos
    videos: dict[tuple[int, int], SessionVideos]

    @property
    def participants(self) -> list[int]:
        return sorted({s.participant for s in self.plan})

    def sessions_of(self, participant: int) -> list[Session]:
        """The participant's sessions in plan order (empty if not in the plan)."""
        return sorted(
            (s for s in self.plan if s.participant == participant), key=lambda s: s.session
        )

    def session_videos(self, participant: int, session: int) -> SessionVideos:
        """What a session shows (session 0: the practice); ``KeyError`` if none."""
        return self.practice if session == PRACTICE else self.videos[(participant, session)]

    def video_path(self, participant: int, session: int, which: int) -> Path:
        """The file of handover ``which`` (1 or 2) of a session, an absolute path inside the
        study folder; ``KeyError`` if none (or if the manifest points outside the folder)."""
        v = self.session_videos(participant, session)
        rel = v.first if which == 1 else v.second if which == 2 else None
        if rel is None:
            raise KeyError(which)
        path = (self.root / rel).resolve()
        if not path.is_relative_to(self.root):
            raise KeyError(rel)
        return path

    @property
    def database(self) -> Path:
        return self.root / "responses.sqlite"

    def store(self) -> ResponseStore:
        return ResponseStore(self.database)


def load_study(root: str | Path) -> StudyFolder:
    """Read ``root/plan.csv`` and ``root/manifest.json``; a folder that is not a rendered study,
    or was rendered by a gazebot without the session map, raises ``ValueError`` saying so.
    ``root`` is resolved: a relative folder means the one under the current directory now, not
    wherever a library later resolves it from."""
    root = Path(root).expanduser().resolve()
    if not root.is_dir():
        raise FileNotFoundError(f"study folder not found: {root}")
    plan_path, manifest_path = root / "plan.csv", root / "manifest.json"
    for p in (plan_path, manifest_path):
        if not p.is_file():
            raise ValueError(
                f"{root} is not a rendered study (no {p.name}); run "
                f"`gazebot study render PLAN.csv --out {root}` first"
            )
    plan = read_plan(plan_path)
    try:
        manifest = json.loads(manifest_path.read_text(encoding="utf-8"))
        practice = SessionVideos.from_manifest(manifest["practice"])
        videos = {
            (int(p), int(k)): SessionVideos.from_manifest(v)
            for p, sessions in manifest["participants"].items()
            for k, v in sessions.items()
        }
    except (KeyError, TypeError, ValueError) as exc:
        raise ValueError(
            f"{manifest_path}: field {exc} missing or malformed; re-render the study with "
            "`gazebot study render` (the cache makes that quick)"
        ) from None
    missing = [(s.participant, s.session) for s in plan if (s.participant, s.session) not in videos]
    if missing:
        raise ValueError(f"{manifest_path}: no videos for (participant, session) {missing[0]}")
    return StudyFolder(
        root=root,
        plan=plan,
        gaze_mode=str(manifest.get("gaze_mode", plan[0].gaze_mode)),
        practice=practice,
        videos=videos,
    )
