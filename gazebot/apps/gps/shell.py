"""Test and training target locations (seed 5.4): a semi-hemispherical shell around the learner's
base, sampled at azimuths in fixed steps with an n x n grid of (radius, elevation) per azimuth,
and training targets at the shell's corners (8), plus four in its middle vertical plane (12)."""

from __future__ import annotations

import math

import numpy as np

from gazebot.apps.gps.config import ShellConfig


def _spherical(azimuth: float, elevation: float, radius: float) -> np.ndarray:
    return radius * np.array([
        math.cos(elevation) * math.cos(azimuth),
        math.cos(elevation) * math.sin(azimuth),
        math.sin(elevation),
    ])


def azimuths(cfg: ShellConfig) -> np.ndarray:
    """The azimuths [rad], ``azimuth_step_deg`` apart, both ends included."""
    lo, hi = cfg.azimuth_deg
    n = int(round((hi - lo) / cfg.azimuth_step_deg)) + 1
    return np.radians(np.linspace(lo, hi, n))


def shell_grid(cfg: ShellConfig, grid: int | None = None) -> np.ndarray:
    """All test locations [m], (n_azimuth * grid^2, 3): 2299 for the seed's 19 x 11 x 11.

    ``grid`` overrides the per-azimuth grid size for a coarser quick run.
    """
    n = cfg.grid if grid is None else grid
    if n < 2:
        raise ValueError(f"grid must be at least 2, got {n}")
    radii = np.linspace(*cfg.radius_m, n)
    elevations = np.radians(np.linspace(*cfg.elevation_deg, n))
    return np.array([
        _spherical(az, el, r) for az in azimuths(cfg) for el in elevations for r in radii
    ])


def training_targets(cfg: ShellConfig, count: int) -> np.ndarray:
    """The training locations [m]: the shell's 8 corners, and for 12 also the 4 corners of its
    middle vertical plane ("additional 4 training locations are located in a vertical plane
    dividing the workspace", seed Fig. 5.7)."""
    if count not in (8, 12):
        raise ValueError(f"the seed trains 8 or 12 local controllers, got {count}")
    az_lo, az_hi = np.radians(cfg.azimuth_deg)
    el = np.radians(cfg.elevation_deg)
    planes = [az_lo, az_hi] + ([0.5 * (az_lo + az_hi)] if count == 12 else [])
    return np.array([_spherical(az, e, r) for az in planes for e in el for r in cfg.radius_m])
