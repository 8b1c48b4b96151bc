"""``gazebot study render``: the videos, pair videos and questionnaire sheets of a study plan.

1. Every distinct handover video of the plan (robot, behavior, scene, seed) is rendered once, in
   parallel worker processes, into ``DIR/videos/``; its file name holds a content hash of
   (robot, behavior, scene, seed, resolution, fps, code version), so a rerun renders only what
   changed (a cached file is reused; a crashed render leaves no file behind).
2. Every distinct session (first behavior, second behavior, scene) becomes one pair video in
   ``DIR/pairs/``: a "Handover 1" title card, the first handover, a "Handover 2" title card, the
   second handover (H.264, yuv420p). Each participant's session files in
   ``DIR/participants/PNN/session-MM.mp4`` link to it (hard link, copy if linking fails).
3. ``DIR/questionnaire.csv`` is the researcher's response sheet (the responses-CSV layout of
   :mod:`gazebot.study.analysis` with blank answers), ``DIR/questionnaire.md`` the questions, and
   ``DIR/participants/PNN/index.html`` a blind per-participant page with the videos in order and
   the five questions.
"""

from __future__ import annotations

import hashlib
import json
import multiprocessing
import os
import shutil
from collections.abc import Callable
from concurrent.futures import Future, ProcessPoolExecutor
from dataclasses import asdict, dataclass
from pathlib import Path

from gazebot.study.cache import RenderFn, VideoSpec, code_version
from gazebot.study.pair_video import make_pair_video
from gazebot.study.plan import Session
from gazebot.study.questionnaire import write_participant_page, write_questionnaire

__all__ = ["RenderReport", "VideoSpec", "code_version", "default_renderer", "render_study"]


@dataclass(frozen=True)
class RenderReport:
    """What :func:`render_study` produced: ``videos`` (spec -> file), ``rendered`` (specs
    rendered in this run; the rest came from the cache), ``pairs`` ((first video, second
    video) -> pair file), ``sessions`` (participant -> session files in order) and the
    questionnaire files."""

    videos: dict[VideoSpec, Path]
    rendered: list[VideoSpec]
    pairs: dict[tuple[VideoSpec, VideoSpec], Path]
    sessions: dict[int, list[Path]]
    questionnaire_csv: Path
    questionnaire_md: Path


def default_renderer() -> RenderFn:
    """The SIM package's MuJoCo renderer (imported lazily: it pulls in MuJoCo)."""
    try:
        from gazebot.sim.record import render_handover_video
    except ImportError as exc:
        raise ValueError(
            f"the MuJoCo handover renderer is not available ({exc}); "
            "use --renderer synthetic for a dry run"
        ) from exc
    return render_handover_video


def _render_video_job(render_fn: RenderFn, spec: VideoSpec, out_path: Path) -> Path:
    """Worker: render into a temporary name, then rename, so the cache never holds a partial
    file."""
    tmp = out_path.with_name(out_path.stem + f".part{os.getpid()}.mp4")
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
        )
        if not tmp.is_file() or tmp.stat().st_size == 0:
            raise RuntimeError(f"renderer wrote no video for {spec}")
        os.replace(tmp, out_path)
    finally:
        tmp.unlink(missing_ok=True)
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
    width: int = 640,
    height: int = 480,
    fps: int = 30,
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
    workers = workers or os.cpu_count() or 1
    version = code_version_str or code_version(render_fn)
    out_dir = Path(out_dir)
    video_dir, pair_dir = out_dir / "videos", out_dir / "pairs"
    for d in (video_dir, pair_dir):
        d.mkdir(parents=True, exist_ok=True)

    def spec(s: Session, behavior: str) -> VideoSpec:
        return VideoSpec(s.robot, behavior, s.scene, s.video_seed, width, height, fps)

    specs = list(dict.fromkeys(spec(s, b) for s in plan for b in (s.first, s.second)))
    videos = {sp: video_dir / sp.file_name(version) for sp in specs}
    todo = [sp for sp in specs if not videos[sp].is_file()]
    _run_jobs(
        [(_render_video_job, (render_fn, sp, videos[sp])) for sp in todo],
        workers,
        progress,
        "handover videos",
    )

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
    for participant, files in sessions.items():
        write_participant_page(participant, files, out_dir / "participants" / f"P{participant:02d}")
    manifest = {
        "code_version": version,
        "videos": {str(p.relative_to(out_dir)): asdict(sp) for sp, p in videos.items()},
        "pairs": {
            str(p.relative_to(out_dir)): [
                str(videos[a].relative_to(out_dir)),
                str(videos[b].relative_to(out_dir)),
            ]
            for (a, b), p in pairs.items()
        },
    }
    (out_dir / "manifest.json").write_text(json.dumps(manifest, indent=2), encoding="utf-8")
    return RenderReport(videos, todo, pairs, sessions, csv_path, md_path)
