"""Eye styles: colors, sizes and shapes of the eyes drawn on a robot's head screen.

A style is a pydantic model loaded from ``configs/eyes/<name>.yaml``. Sizes are fractions of the
display HEIGHT (so one style fits any resolution of about the same aspect); positions are relative
to the display center. Colors are ``[r, g, b]`` (0..255) or ``"#rrggbb"``.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

from pydantic import BaseModel, BeforeValidator, ConfigDict, Field

from gazebot.core.config import configs_dir, load_model
from gazebot.core.defaults import DEFAULT_ROBOT

RGB = tuple[int, int, int]


def _parse_color(value: object) -> RGB:
    """Accept ``"#rrggbb"`` or a 3-sequence of 0..255 integers."""
    if isinstance(value, str):
        text = value.strip().lstrip("#")
        if len(text) != 6:
            raise ValueError("a color '#rrggbb' or [r, g, b] with 0..255 values")
        try:
            return (int(text[0:2], 16), int(text[2:4], 16), int(text[4:6], 16))
        except ValueError as exc:
            raise ValueError("a color '#rrggbb' or [r, g, b] with 0..255 values") from exc
    if isinstance(value, (list, tuple)) and len(value) == 3:
        out = []
        for v in value:
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                raise ValueError("a color '#rrggbb' or [r, g, b] with 0..255 values")
            if not 0 <= v <= 255:
                raise ValueError("a color '#rrggbb' or [r, g, b] with 0..255 values")
            out.append(int(round(v)))
        return (out[0], out[1], out[2])
    raise ValueError("a color '#rrggbb' or [r, g, b] with 0..255 values")


# A color field: "#rrggbb" or [r, g, b] in the YAML, an (r, g, b) tuple in Python.
Color = Annotated[RGB, BeforeValidator(_parse_color)]


class _Part(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


class FaceStyle(_Part):
    """The static face behind the eyes."""

    background: Color = (20, 22, 28)
    # Optional vertical gradient: ``background`` at the top, this color at the bottom.
    background_bottom: Color | None = None
    # Soft cheeks below the eyes (a cartoon touch); radius 0 = none.
    blush_color: Color = (255, 140, 150)
    blush_radius: float = Field(0.0, ge=0.0, le=1.0)
    blush_opacity: float = Field(0.35, ge=0.0, le=1.0)
    blush_dy: float = Field(0.32, ge=-1.0, le=1.0)


class ScleraStyle(_Part):
    """The white of each eye: a superellipse (exponent 2 = ellipse, 4+ = rounded rectangle)."""

    color: Color = (245, 245, 240)
    width: float = Field(0.34, gt=0.0, le=2.0)
    height: float = Field(0.46, gt=0.0, le=2.0)
    exponent: float = Field(2.0, ge=1.5, le=12.0)
    spacing: float = Field(0.78, ge=0.0, le=3.0, description="center-to-center distance")
    center_dy: float = Field(
        0.04, ge=-1.0, le=1.0, description="eye centers below the display center"
    )
    outline_color: Color = (0, 0, 0)
    outline_width: float = Field(0.0, ge=0.0, le=0.2)


class PupilStyle(_Part):
    """Iris (optional ring around the pupil), pupil and the specular highlights."""

    pupil_color: Color = (15, 15, 18)
    pupil_radius: float = Field(0.11, gt=0.0, le=1.0)
    iris_color: Color = (60, 70, 90)
    iris_radius: float = Field(0.0, ge=0.0, le=1.0, description="0 = no iris ring")
    highlight_color: Color = (255, 255, 255)
    highlight_radius: float = Field(0.03, ge=0.0, le=0.5, description="0 = no highlight")
    # Highlight center relative to the pupil center, in pupil radii (x right, y down).
    highlight_offset: tuple[float, float] = (-0.38, -0.4)
    highlight2_radius: float = Field(0.012, ge=0.0, le=0.5)
    highlight2_offset: tuple[float, float] = (0.35, 0.35)
    # Fraction of the free room (sclera half-size minus iris/pupil radius) the pupil may travel.
    travel: float = Field(0.92, ge=0.0, le=1.5)
    # Draw the pupil as a disc on the eyeball: it narrows along the direction it turns.
    foreshorten: bool = True


class LidStyle(_Part):
    """Upper and lower lids: they follow the pitch and meet when the eye blinks."""

    color: Color = (20, 22, 28)
    line_color: Color = (0, 0, 0)
    line_width: float = Field(0.0, ge=0.0, le=0.1)
    # Where the upper lid edge rests, in sclera half-heights above the eye center (1 = hidden).
    upper_open: float = Field(0.95, ge=-1.0, le=1.5)
    # Where the lower lid edge rests, in sclera half-heights below the eye center (1 = hidden).
    lower_open: float = Field(1.05, ge=-1.0, le=1.5)
    # Gain of the upper lid on the pupil's vertical offset (1 = moves as much as the pupil).
    follow: float = Field(0.6, ge=0.0, le=2.0)
    lower_follow: float = Field(0.15, ge=0.0, le=2.0)
    # Where the lids meet in a blink, in sclera half-heights below the eye center.
    closed_at: float = Field(0.25, ge=-1.0, le=1.0)
    # Sag of the lid edge (sclera half-heights): corners below (upper) / above (lower) the middle.
    curve_open: float = Field(0.25, ge=-1.0, le=1.0)
    curve_closed: float = Field(-0.08, ge=-1.0, le=1.0)
    lower_curve: float = Field(0.2, ge=-1.0, le=1.0)


class BrowStyle(_Part):
    """Eyebrows: thick arcs above the eyes that rise when the eyes look up; width 0 = none."""

    color: Color = (230, 230, 225)
    width: float = Field(0.035, ge=0.0, le=0.3, description="stroke thickness")
    length: float = Field(0.9, gt=0.0, le=3.0, description="in sclera widths")
    gap: float = Field(0.07, ge=-0.5, le=1.0, description="above the sclera top")
    arc: float = Field(0.04, ge=-0.5, le=0.5, description="middle above the ends")
    tilt_deg: float = Field(6.0, ge=-45.0, le=45.0, description="outer end up (+) or down (-)")
    follow: float = Field(0.35, ge=0.0, le=2.0, description="gain on the pupil's vertical offset")
    blink_drop: float = Field(0.02, ge=-0.2, le=0.2, description="brow lowers this much in a blink")


class EyeStyle(_Part):
    """A complete eye style. Every size is a fraction of the display height."""

    name: str = "default"
    description: str = ""
    face: FaceStyle = FaceStyle()
    sclera: ScleraStyle = ScleraStyle()
    pupil: PupilStyle = PupilStyle()
    lids: LidStyle = LidStyle()
    brows: BrowStyle = BrowStyle()
    # Virtual distance between the eyes (m) used for vergence: each eye turns inward by
    # atan(baseline / 2 / distance) for a target at ``distance``.
    vergence_baseline_m: float = Field(0.065, ge=0.0, le=1.0)


def eye_styles_dir() -> Path:
    """The folder of shipped eye styles (``configs/eyes``)."""
    return configs_dir() / "eyes"


def available_eye_styles() -> list[str]:
    """Names of the shipped eye styles."""
    folder = eye_styles_dir()
    return sorted(p.stem for p in folder.glob("*.yaml")) if folder.is_dir() else []


def load_eye_style(name_or_path: str | Path | EyeStyle | None = None) -> EyeStyle:
    """Load an eye style by shipped name (``sawyer``) or from a YAML path; ``None``: the style
    of the default robot (:data:`~gazebot.core.defaults.DEFAULT_ROBOT`).

    Raises ``ConfigError`` for a malformed file and ``FileNotFoundError`` (listing the shipped
    styles) for an unknown name.
    """
    if isinstance(name_or_path, EyeStyle):
        return name_or_path
    if name_or_path is None:
        from gazebot.apps.render.eyes_display import robot_display

        name_or_path = robot_display(DEFAULT_ROBOT).style
    path = Path(name_or_path)
    if path.suffix in (".yaml", ".yml") or path.is_file():
        if not path.is_file():
            raise FileNotFoundError(f"eye style file not found: {path}")
        return load_model(EyeStyle, path)
    candidate = eye_styles_dir() / f"{name_or_path}.yaml"
    if not candidate.is_file():
        known = ", ".join(available_eye_styles()) or "none"
        raise FileNotFoundError(f"unknown eye style {str(name_or_path)!r} (shipped: {known})")
    return load_model(EyeStyle, candidate)
