"""The eye renderer: output format, gaze conventions (yaw right / pitch down), vergence, blinks,
bad inputs, styles and robot displays."""

from __future__ import annotations

import math

import numpy as np
import pytest
from eyes_helpers import count_color, marked_renderer, pupil_centroids
from hypothesis import given, settings
from hypothesis import strategies as st

from gazebot.apps.render import EyeRenderer, available_eye_styles, load_eye_style
from gazebot.core.config import ConfigError

STYLES = ["sawyer", "jaco2-head", "cartoon"]


@pytest.fixture(scope="module")
def marked() -> EyeRenderer:
    return marked_renderer("sawyer")


def test_shipped_styles_include_sawyer_jaco2_head_and_cartoon():
    assert set(STYLES) <= set(available_eye_styles())
    for name in STYLES:
        assert load_eye_style(name).name == name


@pytest.mark.parametrize("robot,shape", [("sawyer", (600, 1024, 3)), ("jaco2", (480, 800, 3))])
def test_for_robot_renders_rgb_uint8_at_the_screen_resolution(robot, shape):
    img = EyeRenderer.for_robot(robot).render(0.1, -0.05, blink=0.2, distance=1.2)
    assert img.shape == shape
    assert img.dtype == np.uint8
    assert img.flags["C_CONTIGUOUS"]


def test_render_returns_a_fresh_image_each_call(marked):
    a = marked.render(0.0, 0.0)
    b = marked.render(0.4, 0.2)
    assert not np.shares_memory(a, b)
    assert np.array_equal(a, marked.render(0.0, 0.0))


def test_render_into_out_fills_the_given_array(marked):
    out = np.zeros(marked.shape, np.uint8)
    res = marked.render(0.2, 0.1, out=out)
    assert res is out
    assert np.array_equal(out, marked.render(0.2, 0.1))
    with pytest.raises(ValueError, match="out must be"):
        marked.render(0.0, 0.0, out=np.zeros((10, 10, 3), np.uint8))


def test_edges_are_antialiased():
    r = EyeRenderer(512, 300, "jaco2-head")
    img = r.render(0.0, 0.0)
    # A hard-edged drawing holds only the handful of style colors; antialiasing adds blends.
    assert len(np.unique(img.reshape(-1, 3), axis=0)) > 100


def test_positive_yaw_moves_both_pupils_right_monotonically(marked):
    xs = [[c[0] for c in pupil_centroids(marked.render(y, 0.0))] for y in np.linspace(-0.5, 0.5, 9)]
    for eye in (0, 1):
        seq = [x[eye] for x in xs]
        assert all(b > a + 0.5 for a, b in zip(seq, seq[1:], strict=False)), seq


def test_positive_pitch_moves_both_pupils_down_monotonically(marked):
    ys = [
        [c[1] for c in pupil_centroids(marked.render(0.0, p))] for p in np.linspace(-0.35, 0.35, 8)
    ]
    for eye in (0, 1):
        seq = [y[eye] for y in ys]
        assert all(b > a + 0.5 for a, b in zip(seq, seq[1:], strict=False)), seq


def test_pitch_does_not_move_pupils_sideways_and_yaw_does_not_move_them_vertically(marked):
    c0 = pupil_centroids(marked.render(0.0, 0.0))
    down = pupil_centroids(marked.render(0.0, 0.3))
    right = pupil_centroids(marked.render(0.3, 0.0))
    for eye in (0, 1):
        assert abs(down[eye][0] - c0[eye][0]) < 1.0
        assert abs(right[eye][1] - c0[eye][1]) < 1.0


def test_pupil_offset_follows_the_eyeball_sine_model(marked):
    (u1, _), _ = marked.pupil_offsets(0.2, 0.0)
    (u2, _), _ = marked.pupil_offsets(0.4, 0.0)
    assert u2 / u1 == pytest.approx(math.sin(0.4) / math.sin(0.2), rel=1e-9)
    (_, v1), _ = marked.pupil_offsets(0.0, 0.1)
    assert v1 > 0


def test_angles_beyond_the_eye_range_are_clamped_to_it(marked):
    edge = marked.pupil_offsets(marked.yaw_range, 0.0)
    assert marked.pupil_offsets(10.0, 0.0) == edge
    assert np.array_equal(marked.render(10.0, 0.0), marked.render(marked.yaw_range, 0.0))
    low = marked.pupil_offsets(0.0, -marked.pitch_range)
    assert marked.pupil_offsets(0.0, -3.0) == low


def test_near_target_converges_the_pupils_toward_the_nose(marked):
    far_l, far_r = pupil_centroids(marked.render(0.0, 0.0))
    near_l, near_r = pupil_centroids(marked.render(0.0, 0.0, distance=0.3))
    nearer_l, nearer_r = pupil_centroids(marked.render(0.0, 0.0, distance=0.15))
    assert far_l[0] < near_l[0] < nearer_l[0]  # image-left eye moves right (inward)
    assert far_r[0] > near_r[0] > nearer_r[0]  # image-right eye moves left (inward)
    assert marked.pupil_offsets(0.0, 0.0, distance=math.inf) == marked.pupil_offsets(0.0, 0.0)


@pytest.mark.parametrize("style", STYLES)
def test_full_blink_hides_the_sclera(style):
    r = EyeRenderer(512, 300, style)
    sclera = r.style.sclera.color
    open_count = count_color(r.render(0.0, 0.0, blink=0.0), sclera)
    half_count = count_color(r.render(0.0, 0.0, blink=0.5), sclera)
    closed_count = count_color(r.render(0.0, 0.0, blink=1.0), sclera)
    assert open_count > 5000
    assert closed_count < half_count < open_count
    assert closed_count <= 0.002 * open_count


@pytest.mark.parametrize("pitch", [-0.4, 0.0, 0.4])
def test_full_blink_closes_the_eyes_at_any_pitch(pitch):
    r = EyeRenderer(512, 300, "sawyer")
    img = r.render(0.3, pitch, blink=1.0, distance=0.3)
    assert count_color(img, r.style.sclera.color) == 0


def test_upper_lid_follows_pitch(marked):
    # The lid hides the top of the eye: looking down lowers it, so less sclera shows above.
    sclera = marked.style.sclera.color
    img_up = marked.render(0.0, -0.3)
    img_down = marked.render(0.0, 0.3)
    col = int(round(marked.eyes[0].cx))

    def first_sclera_row(img):
        rows = np.nonzero(np.abs(img[:, col].astype(int) - sclera).max(axis=1) <= 12)[0]
        return rows.min()

    assert first_sclera_row(img_down) > first_sclera_row(img_up) + 5


@pytest.mark.parametrize(
    "kwargs,match",
    [
        ({"eye_yaw": math.nan, "eye_pitch": 0.0}, "eye_yaw must be finite"),
        ({"eye_yaw": 0.0, "eye_pitch": math.inf}, "eye_pitch must be finite"),
        ({"eye_yaw": 0.0, "eye_pitch": 0.0, "blink": math.nan}, "blink must be finite"),
        ({"eye_yaw": 0.0, "eye_pitch": 0.0, "distance": 0.0}, "distance must be > 0"),
        ({"eye_yaw": 0.0, "eye_pitch": 0.0, "distance": -1.0}, "distance must be > 0"),
        ({"eye_yaw": 0.0, "eye_pitch": 0.0, "distance": math.nan}, "distance must be > 0"),
        ({"eye_yaw": "left", "eye_pitch": 0.0}, "eye_yaw must be a real number"),
    ],
)
def test_bad_inputs_raise_a_clear_value_error(marked, kwargs, match):
    with pytest.raises(ValueError, match=match):
        marked.render(**kwargs)


def test_blink_outside_0_1_is_clamped(marked):
    assert np.array_equal(marked.render(0.0, 0.0, blink=3.0), marked.render(0.0, 0.0, blink=1.0))
    assert np.array_equal(marked.render(0.0, 0.0, blink=-1.0), marked.render(0.0, 0.0, blink=0.0))


def test_numpy_scalars_are_accepted(marked):
    a = marked.render(np.float32(0.2), np.float64(0.1), np.float32(0.3), np.float64(0.8))
    assert np.array_equal(
        a, marked.render(float(np.float32(0.2)), 0.1, float(np.float32(0.3)), 0.8)
    )


@pytest.mark.parametrize(
    "args,kwargs",
    [
        ((0, 300), {}),
        ((512.0, 300), {}),
        ((512, 300), {"yaw_range": 0.0}),
        ((512, 300), {"pitch_range": math.nan}),
    ],
)
def test_bad_construction_raises_value_error(args, kwargs):
    with pytest.raises(ValueError):
        EyeRenderer(*args, **kwargs)


def test_unknown_style_and_robot_raise_clear_errors():
    with pytest.raises(FileNotFoundError, match="shipped: .*sawyer"):
        EyeRenderer(512, 300, "no-such-style")
    with pytest.raises(FileNotFoundError, match="unknown robot 'r2d2'"):
        EyeRenderer.for_robot("r2d2")


def test_malformed_style_yaml_names_the_file_and_field(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: bad\nsclera:\n  color: '#12345'\n")
    with pytest.raises(ConfigError, match=r"bad.yaml.*sclera\.color"):
        load_eye_style(bad)
    bad.write_text("name: bad\npupil:\n  pupil_radius: -1\n")
    with pytest.raises(ConfigError, match=r"pupil\.pupil_radius"):
        load_eye_style(bad)
    bad.write_text("name: bad\nsclera:\n  colour: [1, 2, 3]\n")
    with pytest.raises(ConfigError, match=r"sclera\.colour"):
        load_eye_style(bad)


def test_style_from_yaml_path_and_explicit_size(tmp_path):
    path = tmp_path / "mine.yaml"
    path.write_text("name: mine\nface:\n  background: [10, 200, 30]\nbrows:\n  width: 0\n")
    r = EyeRenderer(320, 200, path)
    img = r.render(0.0, 0.0)
    assert img.shape == (200, 320, 3)
    assert tuple(img[2, 2]) == (10, 200, 30)


def test_for_robot_keyword_overrides():
    r = EyeRenderer.for_robot("sawyer", width=256, height=150, style="cartoon")
    assert r.shape == (150, 256, 3)
    assert r.style.name == "cartoon"


@pytest.mark.parametrize("size", [(8, 8), (8, 1000), (1000, 8), (40, 300), (1600, 1000)])
@pytest.mark.parametrize("style", STYLES)
def test_tiny_huge_and_off_frame_layouts_still_render(size, style):
    r = EyeRenderer(*size, style)
    for args in [(0.0, 0.0), (1.0, 1.0, 1.0, 0.1), (-1.0, -1.0, 0.5, 100.0)]:
        assert r.render(*args).shape == (size[1], size[0], 3)


_R = EyeRenderer(256, 150, "sawyer")
_angle = st.floats(-10.0, 10.0, allow_nan=False)
_dist = st.one_of(st.none(), st.floats(0.01, 100.0))


@settings(max_examples=200, deadline=None)
@given(yaw=_angle, pitch=_angle, distance=_dist)
def test_pupil_centers_stay_within_their_travel_for_any_finite_gaze(yaw, pitch, distance):
    ux, uy = _R.travel_px
    for u, v in _R.pupil_offsets(yaw, pitch, distance):
        assert (u / ux) ** 2 + (v / uy) ** 2 <= 1.0 + 1e-9


@settings(max_examples=200, deadline=None)
@given(y1=_angle, y2=_angle, pitch=_angle)
def test_pupil_x_never_decreases_with_yaw_at_any_pitch(y1, y2, pitch):
    lo, hi = sorted((y1, y2))
    for (u_lo, _), (u_hi, _) in zip(
        _R.pupil_offsets(lo, pitch), _R.pupil_offsets(hi, pitch), strict=True
    ):
        assert u_lo <= u_hi + 1e-9


@pytest.mark.parametrize("style", ["sawyer", "jaco2-head", "cartoon"])
def test_a_lowered_lid_covers_the_eye_outline_above_it(style):
    # Issue 32: looking down, a grey arc of the outline showed above the lowered upper lid.
    r = EyeRenderer(384, 224, style)
    s = load_eye_style(style)
    lid, outline = np.asarray(s.lids.color), np.asarray(s.sclera.outline_color)
    assert np.abs(lid - outline).max() > 30  # the two are told apart below
    for g in r.eyes:
        x, y = int(round(g.cx)), int(round(g.cy - g.b - 0.5 * r._outline))  # the ring's top
        up = r.render(0.0, -math.radians(40)).astype(int)[y, x]
        down = r.render(0.0, math.radians(40)).astype(int)[y, x]
        assert np.abs(up - outline).max() <= 12  # open lid: the outline is there
        assert np.abs(down - lid).max() <= 12  # lowered lid: the lid, not the outline
