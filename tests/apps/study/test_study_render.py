"""``study render``: each distinct video rendered once (in parallel, cached by content), pair
videos with title cards, per-participant session files and questionnaire sheets."""

from __future__ import annotations

import csv
import functools
import os
from pathlib import Path

import imageio.v2 as imageio
import numpy as np
import pytest

from gazebot.apps.study.pair_video import title_card
from gazebot.apps.study.plan import make_plan
from gazebot.apps.study.render import VideoSpec, code_version, render_study
from gazebot.apps.study.synthetic import render_synthetic_video
from gazebot.apps.study.video_times import (
    VideoTimes,
    read_video_times,
    times_path,
    write_video_times,
)

W, H, FPS = 32, 24, 10
CLIP_S, CARD_S = 0.5, 0.3
CALL_LOG = "GAZEBOT_STUDY_TEST_CALL_LOG"


def counting_renderer(robot, behavior, scene, out_path, **kw):
    """The synthetic renderer, logging each call (workers are processes: count via a file)."""
    with open(os.environ[CALL_LOG], "a") as fh:
        fh.write(f"{robot},{behavior},{scene},{kw['seed']},{os.getpid()},{kw['gaze_mode']}\n")
    path = render_synthetic_video(robot, behavior, scene, out_path, duration=CLIP_S, **kw)
    write_video_times(path, VideoTimes(reach_start_time=_rst(behavior, scene)))
    return path


def _rst(behavior: str, scene: str) -> float:
    """The reach-start time :func:`counting_renderer` reports: distinct per video."""
    return round(0.01 * (len(behavior) + 7 * len(scene)) - 0.3, 3)


def _calls(log: Path) -> list[list[str]]:
    return [line.split(",") for line in log.read_text().splitlines()] if log.exists() else []


def _frames(path: Path) -> list[np.ndarray]:
    with imageio.get_reader(path, format="FFMPEG") as r:
        return [f for f in r]  # list(r) asks len() = inf frames


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("study")
    log = tmp / "calls.log"
    os.environ[CALL_LOG] = str(log)
    plan = make_plan(condition="fragility", participants=24, seed=4)
    report = render_study(
        plan,
        tmp / "out",
        counting_renderer,
        W,
        H,
        FPS,
        workers=2,
        card_seconds=CARD_S,
        progress=False,
    )
    return plan, report, tmp / "out", log


def test_24_participant_plan_renders_each_distinct_video_exactly_once(rendered):
    plan, report, _, log = rendered
    calls = _calls(log)
    distinct = {(s.robot, b, s.scene) for s in plan for b in (s.first, s.second)}
    assert len(distinct) == 6  # 3 behaviors x 2 fragility levels
    assert sorted(tuple(c[:3]) for c in calls) == sorted(distinct)
    assert all(int(c[4]) != os.getpid() for c in calls)  # rendered in worker processes
    assert {c[5] for c in calls} == {"eyes-only"}  # the 6.4 plan's gaze mode reaches the renderer
    assert len(report.videos) == 6 and len(report.rendered) == 6
    assert all(p.is_file() for p in report.videos.values())


def test_rerender_uses_cache_and_renders_nothing(rendered):
    plan, _, out, log = rendered
    before = len(_calls(log))
    report = render_study(
        plan, out, counting_renderer, W, H, FPS, workers=2, card_seconds=CARD_S, progress=False
    )
    assert len(_calls(log)) == before
    assert report.rendered == []


def test_changed_resolution_or_code_version_changes_cache_key():
    spec = VideoSpec("sawyer", "hand", "default", 0, 640, 480, 30)
    other = VideoSpec("sawyer", "hand", "default", 0, 320, 240, 30)
    assert spec.content_hash("v1") != other.content_hash("v1")
    assert spec.content_hash("v1") != spec.content_hash("v2")
    assert spec.content_hash("v1") == VideoSpec(**spec.__dict__).content_hash("v1")
    assert code_version(counting_renderer) != code_version(render_synthetic_video)
    partial = functools.partial(render_synthetic_video, duration=2.0)
    assert code_version(partial) != code_version(render_synthetic_video)


def test_pair_videos_have_title_cards_then_both_handovers(rendered):
    plan, report, _, _ = rendered
    assert len(report.pairs) == 12  # 6 ordered pairings x 2 levels
    path = next(iter(report.pairs.values()))
    frames = _frames(path)
    n_card, n_clip = round(CARD_S * FPS), round(CLIP_S * FPS)
    assert len(frames) == 2 * n_card + 2 * n_clip
    assert frames[0].shape == (H, W, 3)
    card1 = frames[0].astype(int)
    card2 = frames[n_card + n_clip].astype(int)
    assert card1.mean() < 60 and card1.max() > 150  # white text on black
    assert np.abs(card1 - card2).sum() > 0  # "Handover 1" vs "Handover 2"
    assert frames[n_card].astype(int).mean() > 60  # then the (bright) handover clip


def test_every_participant_gets_session_files_in_plan_order(rendered):
    plan, report, out, _ = rendered
    assert sorted(report.sessions) == list(range(1, 25))
    for s in plan[:24]:
        f = out / "participants" / f"P{s.participant:02d}" / f"session-{s.session:02d}.mp4"
        assert f.is_file()
        specs = {(v.behavior, v.scene): v for v in report.videos}
        a, b = (specs[(x, s.scene)] for x in (s.first, s.second))
        assert (
            os.path.samefile(f, report.pairs[(a, b)])
            or f.read_bytes() == report.pairs[(a, b)].read_bytes()
        )


def test_questionnaire_sheets_list_every_session_and_the_five_questions(rendered):
    plan, report, out, _ = rendered
    with report.questionnaire_csv.open() as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == len(plan)
    assert {"q1", "q2", "q3", "q4", "q5", "first", "second", "level"} <= set(rows[0])
    assert all(r["q1"] == "" for r in rows)
    md = report.questionnaire_md.read_text()
    assert "Which handover did you like better?" in md and "humanlike" in md
    page = (out / "participants" / "P01" / "index.html").read_text()
    assert page.count("<video") == 12
    assert "hand-face" not in page  # blind: behavior names are not shown to participants


def test_title_card_centres_text():
    img = title_card("Handover 1", 320, 240)
    ys, xs = np.nonzero(img.max(axis=2))
    assert abs(xs.mean() - 160) < 20 and abs(ys.mean() - 120) < 20


def test_invalid_resolution_is_rejected(tmp_path):
    plan = make_plan(participants=12)
    with pytest.raises(ValueError, match="even"):
        render_study(plan, tmp_path, counting_renderer, 33, 24, progress=False)


@pytest.mark.slow
def test_real_renderer_at_tiny_resolution_renders_distinct_videos(tmp_path):
    from gazebot.apps.study.render import default_renderer

    plan = make_plan(
        behaviors=["hand", "face-hand-face"],
        condition="posture",
        participants=4,
        gaze_mode="head-and-eyes",
    )
    plan = [s for s in plan if s.participant == 1][:1]  # one session: 2 videos, 2 workers
    report = render_study(
        plan,
        tmp_path,
        default_renderer(),
        64,
        48,
        10,
        workers=2,
        card_seconds=0.2,
        progress=False,
    )
    assert len(report.videos) == 2 and len(report.rendered) == 2
    clips = [_frames(p) for p in report.videos.values()]
    assert all(len(c) > 5 and c[0].shape == (48, 64, 3) for c in clips)
    pair = _frames(next(iter(report.pairs.values())))
    assert len(pair) == 2 * 2 + len(clips[0]) + len(clips[1])  # 0.2 s cards at 10 fps
    for times in report.times.values():  # the real handover's times, beside each video
        assert times.reach_start_time is not None and times.robot_reach_start is not None
        assert times.giver_reach_start == pytest.approx(
            times.robot_reach_start + times.reach_start_time
        )
        assert 0 < times.phase_starts["reach"] < times.phase_starts["transfer"] < times.duration


def test_manifest_maps_every_session_and_the_practice_to_its_two_videos(rendered):
    import json

    from gazebot.apps.study.folder import load_study
    from gazebot.apps.study.plan import read_plan

    plan, report, out, _ = rendered
    assert read_plan(out / "plan.csv") == plan
    study = load_study(out)
    specs = {p: v for v, p in report.videos.items()}
    for s in plan:
        first, second = (study.video_path(s.participant, s.session, k) for k in (1, 2))
        assert (specs[first].behavior, specs[second].behavior) == (s.first, s.second)
        assert specs[first].scene == s.scene
    practice = [specs[study.video_path(1, 0, k)] for k in (1, 2)]
    assert practice[0].behavior != practice[1].behavior
    assert json.loads((out / "manifest.json").read_text())["gaze_mode"] == "eyes-only"


def test_eyes_only_instructions_name_the_eyes_and_head_only_the_head(tmp_path):
    from gazebot.apps.study.questionnaire import instructions

    assert "the robot's eyes in the video" in instructions("eyes-only")
    assert "head" not in instructions("eyes-only")
    assert "the robot's head movement in the video" in instructions("head-only")
    assert "eyes" not in instructions("head-only")


def test_edited_user_behavior_yaml_renders_a_new_video(tmp_path, monkeypatch):
    """The cache keys on the behavior's content, not its name."""
    folder = tmp_path / "behaviors"
    folder.mkdir()
    monkeypatch.setenv("GAZEBOT_BEHAVIORS_PATH", str(folder))
    mine = folder / "mine.yaml"
    mine.write_text("extends: face-hand-face\ndescription: first version\n")
    plan = make_plan(["mine", "hand"], condition=None, participants=2, gaze_mode="head-only")
    fn = functools.partial(render_synthetic_video, duration=0.2)
    first = render_study(plan, tmp_path / "out", fn, W, H, FPS, workers=1, progress=False)
    assert len(first.rendered) == 2
    again = render_study(plan, tmp_path / "out", fn, W, H, FPS, workers=1, progress=False)
    assert again.rendered == []
    mine.write_text("extends: face-hand-face\ndescription: edited\n")
    edited = render_study(plan, tmp_path / "out", fn, W, H, FPS, workers=1, progress=False)
    assert [v.behavior for v in edited.rendered] == ["mine"]


def test_plan_gaze_mode_needs_a_renderer_that_takes_it(tmp_path):
    def old_renderer(
        robot, behavior, scene, out_path, seed=0, width=640, height=480, fps=30, progress=True
    ):
        raise AssertionError("must not be called")

    plan = make_plan(["face", "hand"], condition=None, participants=2, gaze_mode="eyes-only")
    with pytest.raises(ValueError, match="gaze mode 'eyes-only'.*takes no gaze_mode"):
        render_study(plan, tmp_path, old_renderer, W, H, FPS, workers=1, progress=False)


def test_plan_gaze_mode_reaches_the_renderer_and_sets_the_robot_config(monkeypatch, tmp_path):
    """The MuJoCo study renderer gets the plan's gaze mode and renders the robot in it, and
    writes the recording's times beside the video."""
    import math

    import gazebot.apps.sim.record as record
    from gazebot.apps.render.timeline import TickRecord
    from gazebot.apps.study.render import render_handover_in_gaze_mode
    from gazebot.core.types import Event, EventKind

    seen = {}

    def tick(t, phase, rst=math.nan):
        z = np.zeros(3)
        return TickRecord(
            t=t, phase=phase, target="face", head={}, eye_yaw=0.0, eye_pitch=0.0,
            target_point=z, hand=z, face=z, reach_start_time=rst,
        )  # fmt: skip

    def fake_record(robot, behavior, scene, out_path, **kw):
        seen.update(robot=robot, behavior=behavior, scene=scene, **kw)
        Path(out_path).write_bytes(b"video")
        ticks = [tick(0.0, "idle"), tick(0.5, "reach"), tick(1.25, "transfer", -0.2)]
        ticks.append(tick(2.0, "retreat", 0.35))
        events = [Event(EventKind.ROBOT_REACH_STARTED, 0.4, 0.4)]
        events.append(Event(EventKind.ROBOT_REACH_ENDED, 1.1, 1.1))
        return record.HandoverRecording(ticks, Path(out_path), 60, 30, 64, 48, True, events)

    monkeypatch.setattr(record, "record_handover", fake_record)
    try:
        from gazebot.core.kinematics.robot_config import with_gaze_mode  # noqa: F401
    except ImportError:  # a gazebot without gaze modes in the robot config
        with pytest.raises(ValueError, match="cannot render gaze mode 'eyes-only'"):
            render_handover_in_gaze_mode(
                "sawyer", "hand", "default", tmp_path / "v.mp4", gaze_mode="eyes-only"
            )
        return
    render_handover_in_gaze_mode(
        "sawyer", "hand", "default", tmp_path / "v.mp4", seed=3, gaze_mode="eyes-only"
    )
    assert seen["robot"].gaze_mode == "eyes-only"
    assert (seen["behavior"], seen["scene"], seen["seed"]) == ("hand", "default", 3)
    times = read_video_times(tmp_path / "v.mp4")
    assert times.reach_start_time == 0.35  # the last tick's: both reaches had started by then
    assert (times.robot_reach_start, times.giver_reach_start) == (0.4, 0.75)
    assert times.phase_starts == {"reach": 0.5, "transfer": 1.25, "retreat": 2.0}
    assert times.robot_events == {"robot_reach_started": 0.4, "robot_reach_ended": 1.1}
    assert (times.duration, times.completed) == (2.0, True)


def test_each_video_has_its_reach_start_time_in_a_sidecar_videos_csv_and_the_manifest(rendered):
    import json

    from gazebot.apps.study.folder import load_study

    plan, report, out, _ = rendered
    for sp, path in report.videos.items():
        assert read_video_times(path).reach_start_time == _rst(sp.behavior, sp.scene)
        assert report.times[sp].reach_start_time == _rst(sp.behavior, sp.scene)
    with (out / "videos.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == len(report.videos)
    assert all(float(r["reach_start_time"]) == _rst(r["behavior"], r["scene"]) for r in rows)
    assert all(r["robot_reach_start"] == "" for r in rows)  # not reported: unknown, not 0
    study = load_study(out)
    for s in plan:
        shown = study.session_videos(s.participant, s.session)
        assert shown.first_reach_start_time == _rst(s.first, s.scene)
        assert shown.second_reach_start_time == _rst(s.second, s.scene)
    manifest = json.loads((out / "manifest.json").read_text())
    entry = next(iter(manifest["videos"].values()))
    assert entry["times"]["reach_start_time"] == _rst(entry["behavior"], entry["scene"])


def test_a_cached_video_without_its_times_is_rendered_again(tmp_path):
    plan = make_plan(["face", "hand"], condition=None, participants=2, gaze_mode="head-only")
    fn = functools.partial(render_synthetic_video, duration=0.2)
    first = render_study(plan, tmp_path, fn, W, H, FPS, workers=1, progress=False)
    assert len(first.rendered) == 2
    # A renderer that reports no times gets a sidecar of unknowns, and is cached with it.
    assert all(t == VideoTimes() for t in first.times.values())
    assert render_study(plan, tmp_path, fn, W, H, FPS, workers=1, progress=False).rendered == []
    lost, damaged = first.videos.values()
    times_path(lost).unlink()  # e.g. rendered before the sidecars existed
    times_path(damaged).write_text('{"reach_start_time": "soon"}')
    again = render_study(plan, tmp_path, fn, W, H, FPS, workers=1, progress=False)
    assert sorted(v.behavior for v in again.rendered) == ["face", "hand"]
    assert all(read_video_times(p) == VideoTimes() for p in again.videos.values())


def test_malformed_times_sidecar_names_the_file_and_field(tmp_path):
    video = tmp_path / "v.mp4"
    times_path(video).write_text('{"phase_starts": {"reach": "late"}}')
    with pytest.raises(ValueError, match=r"v\.json.*'reach'.*seconds"):
        read_video_times(video)
    times_path(video).write_text("[1, 2]")
    with pytest.raises(ValueError, match=r"v\.json.*JSON object"):
        read_video_times(video)


def test_a_manifest_without_reach_start_times_reads_as_unknown_and_a_bad_one_is_named():
    from gazebot.apps.study.folder import SessionVideos

    old = SessionVideos.from_manifest({"first": "videos/a.mp4", "second": "videos/b.mp4"})
    assert (old.first_reach_start_time, old.second_reach_start_time) == (None, None)
    new = SessionVideos.from_manifest(
        {"first": "a", "second": "b", "first_reach_start_time": -0.25, "second_reach_start_time": 1}
    )
    assert (new.first_reach_start_time, new.second_reach_start_time) == (-0.25, 1.0)
    with pytest.raises(ValueError, match="second_reach_start_time.*seconds or null"):
        SessionVideos.from_manifest({"first": "a", "second": "b", "second_reach_start_time": "x"})
