"""Phase-detection thresholds (``configs/phases.yaml``), defaults from the seed.

The transfer rule is the seed's (section 7.2.5): the hands are within 20 cm of their minimum
distance and their relative speed is under 15 cm/s. Typical phase durations come from the seed's
human-human annotations (section 6.2, Fig. 6.1: the giver's reach lasts 8.10 frames at 8 fps;
transfer and retreat means of the published annotations). Load-share thresholds are the seed's
delta_1/delta_2 (section 4.3, Table 4.1), which the seed leaves unnumbered.
"""

from __future__ import annotations

from pathlib import Path

from pydantic import BaseModel, ConfigDict, Field, model_validator

from gazebot.config import configs_dir, load_model


class PhaseConfig(BaseModel):
    """Every threshold of the offline segmenter and the online detector (SI units).

    Attributes:
        transfer_distance_margin: Transfer needs the hands within this distance of their minimum
            distance (m; seed 0.20). Online, the minimum so far in the current reach is used.
        transfer_speed_max: Transfer needs the hands' relative speed below this (m/s; seed 0.15).
        transfer_exit_speed: Hysteresis: a transfer candidate survives until the relative speed
            exceeds this (m/s).
        release_distance: The release (end of transfer) needs the hands' relative position to
            move this far from the held pose (m)...
        release_speed: ... while they separate faster than this (m/s).
        reach_onset_speed: Giver hand speed marking a reach onset or retreat end (m/s).
        approach_ratio: A reach brings the hands together: their closing speed must be at least
            this fraction of the giver hand's speed.
        reach_confirm_distance: An online reach is confirmed once the hands closed by this (m).
        early_fraction: Online, a reach (or release) whose start looks like a minimum-jerk
            start (aimed at the receiver, or away from the held pose, and still accelerating) is
            confirmed already at this fraction of ``reach_onset_speed`` and
            ``reach_confirm_distance`` (``release_speed`` and ``release_distance``).
        early_speed_margin: Online, an early reach also needs the hand's speed *now* (the
            filter lags: 3 x / a for a minimum-jerk start at x from rest and age a) above this
            many times ``reach_onset_speed``: fidgets of 1-2 cm at rest peak near 0.12 m/s.
        noise_speed_factor: Online, those early speed thresholds are at least this many times
            the RMS speed noise the filter shows while the giver's hand rests (measured live).
        noise_distance_factor: ... and the early distance thresholds at least this many times
            the RMS fluctuation of the hands' distance at rest.
        noise_tau: Time constant of that live noise measurement (s).
        min_approach: Offline, a handover is a dip of the hands' distance at least this deep;
            online, the giver's hand must move this far before its retreat can end (m).
        contact_distance_max: Hands (tracked points) farther apart than this never share an
            object, whatever their speed (m).
        rest_speed: The giver's hand is at rest below this speed (m/s).
        rest_hold: Online, the hand must stay at rest this long to end the retreat (s).
        done_fraction: Online, the retreat ends once the giver's decelerating hand has fallen
            below this fraction of its peak speed (the mirrored bell-shaped profile says it is
            almost at rest), without waiting for ``rest_hold``.
        retreat_far_distance: The retreat also ends once the giver's hand is this far from
            where the transfer happened (m).
        min_transfer: Shortest transfer kept (s); also the online confirmation time.
        settle_speed: Relative speed marking the end of the approach (m/s): the transfer starts
            where the hands settle below it (the seed's 15 cm/s is crossed earlier, on the
            minimum-jerk tail).
        settle_floor_speed: Offline, an approach whose relative speed stops falling below
            this (m/s; never below ``settle_speed``) has settled too: with a few mm of tracking
            noise the speed's floor lies above ``settle_speed``.
        settle_timeout: Online, a transfer candidate that never settles is confirmed after this
            long anyway (if the hands stopped closing), dated at the seed-rule crossing (s).
        stop_extrapolation: The approach's stop is extrapolated past the settle time from the
            two threshold crossings of a parabolic speed tail, times this factor (0: no
            extrapolation; 0.5 calibrated on the synthetic minimum-jerk handovers).
        max_refine: Largest correction applied when extrapolating a motion's start or end from
            the minimum-jerk profile (s).
        smoothing: Offline Gaussian smoothing window (s, two standard deviations).
        offline_rate: Offline analysis grid rate (Hz).
        filter_bandwidth: Online tracking-filter bandwidth (Hz); the velocity estimate lags
            accelerations by about ``1 / (pi * filter_bandwidth)``.
        max_gap_hold: Missing samples are bridged (last value held) for up to this long (s);
            longer gaps emit ``tracking_lost``.
        load_share_shared: Load share above which the object is shared (seed delta_1).
        load_share_robot: Load share above which the robot holds the object alone, i.e. the
            giver released it (seed delta_2).
        reach_duration: Typical giver reach duration (s; seed Fig. 6.1: 8.10 frames at 8 fps).
        transfer_duration: Typical transfer duration (s; seed annotations mean).
        retreat_duration: Typical retreat duration (s; seed annotations mean).
        max_retreat: Longest retreat before ``handover_done`` is forced (s).
    """

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    transfer_distance_margin: float = Field(0.20, gt=0)
    transfer_speed_max: float = Field(0.15, gt=0)
    transfer_exit_speed: float = Field(0.20, gt=0)
    release_distance: float = Field(0.015, ge=0)
    release_speed: float = Field(0.08, gt=0)
    reach_onset_speed: float = Field(0.15, gt=0)
    approach_ratio: float = Field(0.3, ge=-1, le=1)
    reach_confirm_distance: float = Field(0.015, gt=0)
    early_fraction: float = Field(0.5, gt=0, le=1)
    early_speed_margin: float = Field(1.67, ge=1)
    noise_speed_factor: float = Field(2.5, ge=0)
    noise_distance_factor: float = Field(5.0, ge=0)
    noise_tau: float = Field(1.0, gt=0)
    min_approach: float = Field(0.10, gt=0)
    contact_distance_max: float = Field(0.35, gt=0)
    rest_speed: float = Field(0.05, gt=0)
    rest_hold: float = Field(0.15, ge=0)
    done_fraction: float = Field(0.15, ge=0, lt=1)
    retreat_far_distance: float = Field(0.60, gt=0)
    min_transfer: float = Field(0.08, ge=0)
    settle_speed: float = Field(0.05, gt=0)
    settle_floor_speed: float = Field(0.075, gt=0)
    settle_timeout: float = Field(0.3, ge=0)
    stop_extrapolation: float = Field(0.5, ge=0, le=2)
    max_refine: float = Field(0.4, ge=0)
    smoothing: float = Field(0.08, gt=0)
    offline_rate: float = Field(100.0, gt=0, le=2000)
    filter_bandwidth: float = Field(5.0, gt=0)
    max_gap_hold: float = Field(0.25, ge=0)
    load_share_shared: float = Field(0.1, ge=0, le=1)
    load_share_robot: float = Field(0.9, ge=0, le=1)
    reach_duration: float = Field(1.01, gt=0)
    transfer_duration: float = Field(0.59, gt=0)
    retreat_duration: float = Field(1.05, gt=0)
    max_retreat: float = Field(4.0, gt=0)

    @model_validator(mode="after")
    def _consistent(self) -> PhaseConfig:
        if self.transfer_exit_speed < self.transfer_speed_max:
            raise ValueError("transfer_exit_speed >= transfer_speed_max (hysteresis)")
        if self.load_share_robot < self.load_share_shared:
            raise ValueError("load_share_robot >= load_share_shared")
        if self.settle_speed >= self.transfer_speed_max:
            raise ValueError("settle_speed < transfer_speed_max")
        if self.rest_speed > self.reach_onset_speed:
            raise ValueError("rest_speed <= reach_onset_speed")
        return self


def default_phase_config_path() -> Path:
    """The shipped ``configs/phases.yaml``."""
    return configs_dir() / "phases.yaml"


def load_phase_config(path: str | Path | None = None) -> PhaseConfig:
    """Load phase thresholds from YAML (``None``: the shipped ``configs/phases.yaml``).

    Raises:
        ConfigError: The file is unreadable, not YAML, or a field is invalid (names the field).
    """
    return load_model(PhaseConfig, default_phase_config_path() if path is None else path)
