"""``gazebot study render``: the videos, pair videos and questionnaire sheets of a study plan.

1. Every distinct handover video of the plan (robot, behavior, scene, seed) is rendered once, in
   parallel worker processes, into ``DIR/videos/``; its file name holds a content hash of
   (robot, behavior, scene, seed, resolution, fps, code version), so a rerun renders only what
   changed (a cached file is reused; a crashed render leaves no file behind). Beside each video,
   ``NAME.json`` holds its times (:mod:`gazebot.apps.study.video_times`: the seed's reach-start
   time, the robot's events and the phase starts); a cached video without one is rendered again.
2. Every distinct session (first behavior, second behavior, scene) becomes one pair video in
   ``DIR/pairs/``: a "Handover 1" title card, the first handover, a "Handover 2" title card, the
   second handover (H.264, yuv420p). Each participant's session files in
   ``DIR/participants/PNN/session-MM.mp4`` link to it (hard link, copy if linking fails).
3. ``DIR/questionnaire.csv`` is the researcher's response sheet (the responses-CSV layout of
   :mod:`gazebot.apps.study.analysis` with blank answers), ``DIR/questionnaire.md`` the questions,
   and
   ``DIR/participants/PNN/index.html`` a blind offline page with the videos in order and the five
   questions.
4. ``DIR/plan.csv`` is the plan and ``DIR/manifest.json`` maps every participant's session (and
   the practice session) to its two handover videos and their reach-start times: what
   ``gazebot study serve`` shows. ``DIR/videos.csv`` lists every video with its times.

The practice session shows the plan's first ordered pairing in reverse order (a pair every
participant also sees as a study session): the seed names a practice session but not its content.
"""

from __future__ import annotations

import csv
import functools
import hashlib
import inspect
import json
import multiprocessing
import os
import shutil
from collections.abc import Callable
from concurrent.futures import Future, ProcessPoolExecutor
from dataclasses import asdict, dataclass
from pathlib import Path

from gazebot.apps.render.video_settings import VIDEO
from gazebot.apps.study.cache import RenderFn, VideoSpec, code_version, inputs_digest
from gazebot.apps.study.pair_video import make_pair_video
from gazebot.apps.study.plan import Session, write_plan
from gazebot.apps.study.questionnaire import write_participant_page, write_questionnaire
from gazebot.apps.study.video_times import (
    TIME_COLUMNS,
    VideoTimes,
    read_video_times,
    times_path,
    write_video_times,
)
from gazebot.io.atomic import atomic_path

__all__ = [
    "RenderReport",
    "VideoSpec",
    "code_version",
    "default_renderer",
    "render_handover_in_gaze_mode",
    "render_study",
]


@dataclass(frozen=True)
class RenderReport:
    """What :func:`render_study` produced: ``videos`` (spec -> file), ``rendered`` (specs
    rendered in this run; the rest came from the cache), ``pairs`` ((first video, second
    video) -> pair file), ``sessions`` (participant -> session files in order), the
    questionnaire files and ``times`` (spec -> the video's times)."""

    videos: dict[VideoSpec, Path]
    rendered: list[VideoSpec]
    pairs: dict[tuple[VideoSpec, VideoSpec], Path]
    sessions: dict[int, list[Path]]
    questionnaire_csv: Path
    questionnaire_md: Path
    times: dict[VideoSpec, VideoTimes]


def render_handover_in_gaze_mode(
    robot: str,
    behavior: str,
    scene: str,
    out_path: str | Path,
    seed: int = 0,
    width: int = VIDEO.width,
    height: int = VIDEO.height,
    fps: int = VIDEO.fps,
    progress: bool = True,
    gaze_mode: str = "head-and-eyes",
) -> Path:
    """The SIM package's MuJoCo handover renderer on ``robot`` with its gaze mode set to the
    plan's (the robot config's ``gaze_mode``, as ``--gaze-mode`` sets it on the other commands).
    Writes the handover's times beside the video (:func:`write_video_times`)."""
    from gazebot.apps.sim.record import record_handover

    try:
        from gazebot.core.kinematics.robot_config import with_gaze_mode
    except ImportError:  # a gazebot without gaze modes: only the robot's own mode exists
        if gaze_mode != "head-and-eyes":
            raise ValueError(f"this gazebot cannot render gaze mode {gaze_mode!r}") from None
        robot_arg = robot
    else:
        robot_arg = with_gaze_mode(robot, gaze_mode)
    rec = record_handover(
        robot_arg,
        behavior,
        scene,
        out_path,
        seed=seed,
        width=width,
        height=height,
        fps=fps,
        progress=progress,
    )
    write_video_times(out_path, VideoTimes.from_recording(rec))
    return Path(out_path)


def default_renderer() -> RenderFn:
    """The MuJoCo renderer in the plan's gaze mode (:func:`render_handover_in_gaze_mode`); MuJoCo
    is imported in the workers, when a video is rendered."""
    try:
        import gazebot.apps.sim.record  # noqa: F401 - fail here, not in a worker
    except ImportError as exc:
        raise ValueError(
            f"the MuJoCo handover renderer is not available ({exc}); "
            "use --renderer synthetic for a dry run"
        ) from exc
    return render_handover_in_gaze_mode


def _render_video_job(
    render_fn: RenderFn, spec: VideoSpec, out_path: Path, pass_mode: bool = True
) -> Path:
    """Worker: render into a temporary name, then rename, so the cache never holds a partial
    file. ``pass_mode``: give the renderer the spec's ``gaze_mode``. The renderer's times sidecar
    is moved first (a renderer that writes none gets one with unknown times), so a cached video
    always has its times."""
    extra = {"gaze_mode": spec.gaze_mode} if pass_mode else {}
    with atomic_path(out_path) as tmp:
        tmp_times = times_path(tmp)
        try:
            render_fn(
                spec.robot,
                spec.behavior,
                spec.scene,
                tmp,
                seed=spec.seed,
                width=spec.width,
                height=spec.height,
                fps=spec.fps,
                progress=False,
                **extra,
            )
            if not tmp.is_file() or tmp.stat().st_size == 0:
                raise RuntimeError(f"renderer wrote no video for {spec}")
            if read_video_times(tmp) is None:
                write_video_times(tmp, VideoTimes())
            os.replace(tmp_times, times_path(out_path))
        finally:
            tmp_times.unlink(missing_ok=True)
    return out_path


def _run_jobs(jobs: list[tuple[Callable, tuple]], workers: int, progress: bool, desc: str) -> None:
    """Run ``fn(*args)`` jobs, in ``workers`` processes (inline for 1), re-raising failures."""
    if not jobs:
        return
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(jobs), desc=desc, unit="video")
    try:
        if workers <= 1:
            for fn, args in jobs:
                fn(*args)
                if bar:
                    bar.update()
            return
        # Spawned, not forked: a forked child inherits the parent's GL (EGL/OSMesa) state and
        # can deadlock creating its own context.
        spawn = multiprocessing.get_context("spawn")
        with ProcessPoolExecutor(max_workers=min(workers, len(jobs)), mp_context=spawn) as pool:
            futures: list[Future] = [pool.submit(fn, *args) for fn, args in jobs]
            for fut in futures:
                fut.result()
                if bar:
                    bar.update()
    finally:
        if bar:
            bar.close()


def accepts_gaze_mode(render_fn: RenderFn) -> bool:
    """Whether ``render_fn`` takes a ``gaze_mode`` keyword (or ``**kwargs``)."""
    fn = render_fn.func if isinstance(render_fn, functools.partial) else render_fn
    try:
        params = inspect.signature(fn).parameters.values()
    except (TypeError, ValueError):
        return False
    return any(p.name == "gaze_mode" or p.kind is p.VAR_KEYWORD for p in params)


def _link(src: Path, dst: Path) -> None:
    dst.unlink(missing_ok=True)
    try:
        os.link(src, dst)
    except OSError:
        shutil.copyfile(src, dst)


def render_study(
    plan: list[Session],
    out_dir: str | Path,
    render_fn: RenderFn | None = None,
    width: int = VIDEO.width,
    height: int = VIDEO.height,
    fps: int = VIDEO.fps,
    workers: int | None = None,
    card_seconds: float = 1.5,
    code_version_str: str | None = None,
    progress: bool = True,
) -> RenderReport:
    """Render a study plan into ``out_dir`` (layout in the module doc).

    ``render_fn``: the handover renderer (default: :func:`default_renderer`); ``workers``: worker
    processes (default: the number of CPU cores); ``code_version_str``: overrides
    :func:`code_version` in the cache key.
    """
    if not plan:
        raise ValueError("the plan has no sessions")
    if width % 2 or height % 2 or width < 16 or height < 16:
        raise ValueError(
            f"width and height must be even and >= 16 (H.264 yuv420p), got {width}x{height}"
        )
    if fps <= 0:
        raise ValueError(f"fps must be positive, got {fps}")
    if card_seconds <= 0:
        raise ValueError(f"card_seconds must be positive, got {card_seconds}")
    render_fn = render_fn or default_renderer()
    modes = sorted({s.gaze_mode for s in plan} - {"head-and-eyes"})
    pass_mode = accepts_gaze_mode(render_fn)
    if modes and not pass_mode:
        raise ValueError(
            f"the plan asks for gaze mode {modes[0]!r}, but the renderer "
            f"{getattr(render_fn, '__name__', render_fn)!r} takes no gaze_mode"
        )
    workers = workers or os.cpu_count() or 1
    version = code_version_str or code_version(render_fn)
    out_dir = Path(out_dir)
    video_dir, pair_dir = out_dir / "videos", out_dir / "pairs"
    for d in (video_dir, pair_dir):
        d.mkdir(parents=True, exist_ok=True)

    digests: dict[tuple[str, str, str], str] = {}

    def spec(s: Session, behavior: str) -> VideoSpec:
        key = (s.robot, behavior, s.scene)
        if key not in digests:
            digests[key] = inputs_digest(*key)
        return VideoSpec(
            s.robot, behavior, s.scene, s.video_seed, width, height, fps, s.gaze_mode, digests[key]
        )

    specs = list(dict.fromkeys(spec(s, b) for s in plan for b in (s.first, s.second)))
    videos = {sp: video_dir / sp.file_name(version) for sp in specs}
    todo = [sp for sp in specs if not _cached(videos[sp])]
    _run_jobs(
        [(_render_video_job, (render_fn, sp, videos[sp], pass_mode)) for sp in todo],
        workers,
        progress,
        "handover videos",
    )
    times = {sp: read_video_times(videos[sp]) or VideoTimes() for sp in specs}

    pair_of: dict[Session, tuple[VideoSpec, VideoSpec]] = {
        s: (spec(s, s.first), spec(s, s.second)) for s in plan
    }
    pairs: dict[tuple[VideoSpec, VideoSpec], Path] = {}
    pair_jobs = []
    for s in plan:
        a, b = key = pair_of[s]
        if key in pairs:
            continue
        h = hashlib.sha256(
            f"{a.content_hash(version)}|{b.content_hash(version)}|{card_seconds}".encode()
        ).hexdigest()[:16]
        path = pair_dir / f"{s.robot}_{s.scene}_{s.first}__{s.second}_s{s.video_seed}_{h}.mp4"
        pairs[key] = path
        if not path.is_file():
            pair_jobs.append(
                (make_pair_video, (videos[a], videos[b], path, width, height, fps, card_seconds))
            )
    _run_jobs(pair_jobs, workers, progress, "pair videos")

    sessions: dict[int, list[Path]] = {}
    for s in sorted(plan, key=lambda s: (s.participant, s.session)):
        pdir = out_dir / "participants" / f"P{s.participant:02d}"
        pdir.mkdir(parents=True, exist_ok=True)
        dst = pdir / f"session-{s.session:02d}.mp4"
        _link(pairs[pair_of[s]], dst)
        sessions.setdefault(s.participant, []).append(dst)

    csv_path, md_path = write_questionnaire(plan, out_dir)
    gaze_mode = plan[0].gaze_mode
    for participant, files in sessions.items():
        write_participant_page(
            participant, files, out_dir / "participants" / f"P{participant:02d}", gaze_mode
        )
    write_plan(plan, out_dir / "plan.csv")

    def rel(p: Path) -> str:
        return p.relative_to(out_dir).as_posix()

    def entry(s: Session) -> dict:
        a, b = pair_of[s]
        return {
            "first": rel(videos[a]),
            "second": rel(videos[b]),
            "pair": rel(pairs[(a, b)]),
            "first_reach_start_time": times[a].reach_start_time,
            "second_reach_start_time": times[b].reach_start_time,
        }

    first = min(plan, key=lambda s: (s.participant, s.session))
    reverse = (first.second, first.first, first.level)
    practice = next((s for s in plan if (s.first, s.second, s.level) == reverse), first)
    manifest = {
        "code_version": version,
        "gaze_mode": gaze_mode,
        "practice": entry(practice),
        "participants": {
            str(p): {
                str(s.session): entry(s)
                for s in sorted(plan, key=lambda s: s.session)
                if s.participant == p
            }
            for p in sorted({s.participant for s in plan})
        },
        "videos": {rel(p): {**asdict(sp), "times": asdict(times[sp])} for sp, p in videos.items()},
        "pairs": {rel(p): [rel(videos[a]), rel(videos[b])] for (a, b), p in pairs.items()},
    }
    (out_dir / "manifest.json").write_text(json.dumps(manifest, indent=2), encoding="utf-8")
    write_videos_csv(out_dir / "videos.csv", {rel(p): (sp, times[sp]) for sp, p in videos.items()})
    return RenderReport(videos, todo, pairs, sessions, csv_path, md_path, times)


def _cached(video: Path) -> bool:
    """Whether ``video`` and a readable times sidecar are in the cache (a video rendered before
    the sidecars existed, or with a damaged one, is rendered again)."""
    try:
        return video.is_file() and read_video_times(video) is not None
    except ValueError:
        return False


VIDEO_COLUMNS = ("video", "robot", "behavior", "scene", "seed", "gaze_mode", *TIME_COLUMNS)


def write_videos_csv(path: Path, rows: dict[str, tuple[VideoSpec, VideoTimes]]) -> Path:
    """``videos.csv``: one row per handover video (columns :data:`VIDEO_COLUMNS`, seconds,
    empty = unknown)."""
    with path.open("w", newline="", encoding="utf-8") as fh:
        writer = csv.writer(fh)
        writer.writerow(VIDEO_COLUMNS)
        for name, (sp, t) in sorted(rows.items()):
            writer.writerow(
                [name, sp.robot, sp.behavior, sp.scene, sp.seed, sp.gaze_mode, *t.row()]
            )
    return path
