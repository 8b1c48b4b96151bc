"""Phase-detection settings (``configs/phases.yaml``): the method and every threshold it uses.

Three methods (``method:``):

- ``gazebot`` (default): the robust detector (:mod:`gazebot.core.phases.methods.gazebot`). It has no
  absolute hand-to-hand contact distance: marker placement and object size set how close the
  tracked hand frames come (0.3-0.5 m on real motion capture), so the transfer is found from
  the dip of the hands' distance and the relative speed's own scale.
- ``seed-7.2.5``: the seed's annotation rule as published (dissertation section 7.2.5).
- ``seed-4.4.3``: the seed's split of single giving motions (section 4.4.3).

The defaults here and in the YAML are the same; the YAML says each one's unit and why.
"""

from __future__ import annotations

from pathlib import Path

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from gazebot.core.config import configs_dir, load_model
from gazebot.core.phases.catalog import PHASE_METHODS


class PhaseConfig(BaseModel):
    """The phase method and its thresholds (SI units: m, s, m/s, Hz).

    Attributes:
        method: ``gazebot``, ``seed-7.2.5`` or ``seed-4.4.3``.
        transfer_distance_margin: Seed 7.2.5: transfer needs the hands within this distance of
            their minimum distance (m; seed 0.20).
        transfer_speed_max: Seed 7.2.5: ... and their relative speed below this (m/s; seed 0.15).
        seed_speed_half_window: The seed names no speed filter: relative speed is
            ``|p(t + h) - p(t - h)| / 2h`` with this ``h`` (s) in both seed methods.
        seed_d1: Seed 4.4.3: distance-from-start fraction of its maximum (seed 0.41).
        seed_v1: Seed 4.4.3: signed-speed fraction of its maximum (seed 0.43).
        seed_min_motion: Seed 4.4.3, our addition: a giving motion moves the hand at least
            this far from its start (m); else no segments (the fractions would split noise).
        transfer_exit_speed: gazebot: seed-rule runs split by blips slower than this merge (m/s).
        turning_common_max: gazebot: between two holds, the pair turning the object together
            merges them while their common motion is under this (m/s): a careful carry (0.06-0.21
            m/s, read at up to 0.37 at 30 Hz with 5 mm of marker noise), not a pass while
            walking on together.
        min_approach: gazebot: a handover is a dip of the hands' distance at least this deep (m).
        approach_fraction: gazebot: ... closing at least this fraction of the distance the
            hands started from.
        max_hold_distance: gazebot: ... and coming this close (m): two tracked points on the
            hands (or forearms: 0.85 m on the KTH recording) holding one object are at most
            about its length apart (a giver who lifts the object and pauses 1.15 m from the
            receiver holds nothing out yet).
        min_transfer: gazebot: shortest transfer kept (s).
        pass_min_samples: gazebot: a handover without a hold (the hands pass the object on
            the move) needs this many analysis-grid samples under ``transfer_exit_speed``.
        still_closing: Online, hands that closed more than this over the last
            ``min_transfer`` are still approaching: no transfer yet (m).
        settle_fraction: gazebot: the transfer starts where the relative speed falls below this
            fraction of the approach's peak relative speed ...
        settle_floor_factor: ... or below this many times the hold's speed floor, if higher.
        hold_floor_quantile: gazebot: the hold's speed floor is this quantile of the relative
            speed over the seed-rule run (0..1).
        stop_extrapolation: gazebot: share of the parabolic-tail extrapolation from the settle
            crossing to the hold's floor applied (0: none; 1: the parabola's own).
        approach_tail_max: gazebot: the transfer starts at most this long (s) after the
            relative speed fell under ``transfer_speed_max``: hands creeping closer for longer
            hold the object already (in a hold carried together, or :attr:`creep_balance`).
        approach_fall_band: gazebot: the relative speed fell under ``transfer_speed_max`` for
            good (for :attr:`approach_tail_max`) at its last fall through it before it first
            went under this share of it: an approach hovering at the seed's speed dips under
            it before it slows (0..1).
        creep_balance: gazebot: ... also where, over that tail, the slower hand moves at least
            this share of the faster's speed (median): both hands adjusting to each other hold
            the object; one hand still arriving at a still one does not yet (0..1).
        release_tail_max: gazebot: offline, the transfer ends at most this long (s) before
            the relative speed rises over ``transfer_speed_max``: hands parting slower for
            longer still move the object together.
        release_distance: gazebot: the release needs the hands' relative position this far from
            the held pose (m) ...
        release_noise_factor: ... and at least this many times the held pose's RMS jitter.
        coupled_speed: gazebot: hands whose common motion over the hold has a median speed of
            at least this (m/s) carry the object together (issue 33's careful handovers: 0.06-
            0.21 m/s): the pair may turn with it, so their relative position swings at a
            constant distance, and the release is the distance leaving its noise band (or a
            hand moving against the other faster than ``transfer_speed_max``).
        coupled_travel: gazebot: ... or whose midpoint moved at least this far (m) from the
            hold's first to its last sample: the pair carried the object, net of marker noise
            (a careful pair slowing into the release has a median common speed under
            ``coupled_speed``; 5 mm marker noise at 30 Hz raises a still hold's median, not
            its midpoint's travel).
        young_hold: gazebot: a hold seen for less than this (s) has ended only if the hands
            are no nearer the held pose a smoothing window after the parting: online, the
            first samples of a hold just confirmed are smoothed from one side, and a marker
            lagging as the pair sets off reads as the giver letting go.
        reach_onset_speed: gazebot: giver hand speed marking a reach onset or retreat end (m/s).
        reach_confirm_distance: gazebot: a reach under way is reported once the hands have
            closed by this much (m) ...
        approach_ratio: ... and the giver's hand itself moved toward the receiver by this
            fraction of it.
        rest_speed: gazebot: the giver's hand is at rest below this speed (m/s).
        rest_hold: Online, a hand whose retreat began before the detector saw it is at rest
            after this long under ``rest_speed`` (s).
        done_fraction: Online, a retreat whose speed fell below this fraction of its peak is
            about to land: it ends at the mirrored onset.
        retreat_far_distance: gazebot: the retreat also ends once the giver's hand is this far
            from where the transfer happened (m).
        max_refine: gazebot: largest back-dating of a motion onset or release (s).
        max_retreat: Longest retreat before the handover ends anyway (s).
        smoothing: gazebot: Gaussian smoothing window (s, two standard deviations).
        analysis_rate: Analysis grid rate (Hz) for every method.
        max_gap_hold: Missing samples are bridged for up to this long (s); longer gaps are
            unknown (online: ``tracking_lost``).
        frozen_speed: A sample repeating the last position exactly while the hand was moving
            faster than this (m/s) is a frozen (stale) sample: it counts as missing.
        glitch_jump: A sample farther than this (m) beyond where the hand's last speed could
            take it from the last valid sample is a one-sample glitch (a marker swapped for a
            frame): it counts as missing, unless the next stays near it (a real step). 0: off.
        online_period: Online, the detector decides whether to re-analyse the recent samples
            on a fixed grid of this period (s): at the first sample at or after each tick (the
            ``gazebot`` trigger runs then); between ticks it only stores samples.
        online_window: Online, how much history (s) the detector keeps and analyses.
        online_refresh: Online, ``gazebot``: in a reach or retreat the full analysis runs at
            least this often (s) for the end-of-phase prediction; otherwise only when a cheap
            trigger on the recent samples says the next boundary may have passed.
        edge_guard: Online, a phase boundary closer than this to the newest sample is not yet
            reported (s): the smoothing has not seen what follows it.
        online_slack: Online, back-dated boundaries are compared with the current phase's
            start with this slack (s): one analysis may place a boundary a grid step or two
            off the previous one.
        reach_stall: Online, a reach whose giver's hand then rested (or swayed with the
            object without nearing the receiver) this long (s) and set off again toward the
            receiver was an earlier movement: it ends (``stalled``) and the final approach is
            the reach (so does a reach the hands came ``reach_confirm_distance`` apart from
            again before they closed in anew) ...
        stall_fraction: ... if the hands were then less than this fraction of their distance
            when the reach started nearer (a lift, or a movement that went away; a reach that
            closed more has closed a fifth of its gap, which is under that distance: its pause
            is a wait at the handover place).
        reach_lookback: Online, in a reach the analysis reads this many typical reaches
            before the reach's start (the rest before it dates the onset).
        predict_window: Online, ``gazebot``'s predictive reach rule
            (:mod:`~gazebot.core.phases.rules.directed`) fits the giver's hand over this long (s)
            ... predict_min_samples: ... and over at least this many samples (low rates widen it).
        predict_gap_factor: ... with no gap in the window longer than this many sampling
            intervals (the newest sample seen) ...
        predict_rest_window: ... against its mean position over this long (s) before that.
        predict_noise_window: ... measuring the marker noise over this long (s) before it ...
        predict_distance: ... a reach is confirmed once the hand moved this far (m) toward the
            receiver's hand, faster than ``reach_onset_speed``, still accelerating ...
        predict_cos: ... within ``acos`` of this of the line to the receiver's hand ...
        predict_sigmas: ... and each of distance, speed and acceleration above this many
            standard errors of the fit (the measured noise floor) ...
        predict_horizon: ... and the model, extrapolated this far ahead (s), closes ...
        predict_gap_share: ... this share of the gap the hands started from.
        sequential_window: Online, ``gazebot``'s sequential reach rule
            (:mod:`~gazebot.core.phases.rules.sequential`, a likelihood-ratio test of a reach
            against
            a fidget, beside the predictive rule) reads the giver's hand over this long (s) ...
        sequential_onset_span: ... trying onsets up to this long (s) before the newest sample ...
        sequential_onset_step: ... this far apart (s) ...
        sequential_durations: ... and minimum-jerk durations (s) from the first to the second ...
        sequential_duration_steps: ... in this many geometric steps ...
        fidget_amplitude: ... a fidget moves the hand at most this far (m), a reach at least
            ``min_approach`` ...
        sequential_evidence: ... and a reach is confirmed once it explains the window better
            than any fidget by this many noise variances (``2 ln`` of the likelihood ratio); it
            heads and closes the gap as the predictive rule's ``predict_cos`` ... ask.
        directed_support: The predictive (constant-acceleration) rule's reach stands only if
            the sequential rule confirms the same samples with this bar in place of
            ``sequential_evidence`` (1, noise variances): a reach explains the window better
            than any fidget by at least this, and the sequential rule's own checks (samples,
            travel, heading, no recent dropout) hold (its 0.2 s fit averages the acceleration
            and reads a 2 cm fidget past its midpoint as still accelerating).
        trigger_distance_factor: Online, ``gazebot``'s cheap trigger fires at this share of
            the distances its rules need (loose: it fires before the rule can).
        trigger_speed_baseline: ... speeds from mean positions this far apart (s).
        trigger_deep_fraction: ... the hands closing this share of ``min_approach`` is a deep
            dip (whoever closed it) ...
        trigger_own_fraction: ... else the giver's own share of the closing must reach this
            share of ``reach_confirm_distance``.
        trigger_still_factor: ... a reach may have ended once the hands closed less than this
            many ``still_closing`` over the recent samples.
        trigger_far_fraction: ... a retreat may have ended once the giver's hand is this share
            of ``retreat_far_distance`` away ...
        trigger_landing_fraction: ... or its speed fell below this share of its peak.
        load_share_shared: Load share above which the object is shared (seed delta_1).
        load_share_robot: Load share above which the robot holds the object alone (seed delta_2).
        peak_passed_fraction: A motion is past its speed peak once its speed has fallen below
            this fraction of the peak (end-of-phase prediction).
    """

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    method: str = "gazebot"  # a registered phase method (gazebot.core.phases.catalog.PHASE_METHODS)
    transfer_distance_margin: float = Field(0.20, gt=0)
    transfer_speed_max: float = Field(0.15, gt=0)
    seed_speed_half_window: float = Field(0.05, gt=0)
    seed_d1: float = Field(0.41, gt=0, lt=1)
    seed_v1: float = Field(0.43, gt=0, lt=1)
    seed_min_motion: float = Field(0.10, ge=0)
    transfer_exit_speed: float = Field(0.20, gt=0)
    turning_common_max: float = Field(0.40, gt=0)
    min_approach: float = Field(0.10, gt=0)
    approach_fraction: float = Field(0.3, ge=0, lt=1)
    max_hold_distance: float = Field(1.0, gt=0)
    min_transfer: float = Field(0.08, ge=0)
    pass_min_samples: int = Field(3, ge=1)
    still_closing: float = Field(0.005, ge=0)
    settle_fraction: float = Field(0.03, gt=0, lt=1)
    settle_floor_factor: float = Field(1.5, ge=1)
    hold_floor_quantile: float = Field(0.25, ge=0, le=1)
    stop_extrapolation: float = Field(1.0, ge=0, le=2)
    approach_tail_max: float = Field(0.2, ge=0)
    release_tail_max: float = Field(0.25, ge=0)
    creep_balance: float = Field(0.25, ge=0, le=1)
    approach_fall_band: float = Field(0.8, gt=0, le=1)
    release_distance: float = Field(0.010, ge=0)
    release_noise_factor: float = Field(4.0, ge=0)
    coupled_speed: float = Field(0.06, gt=0)
    coupled_travel: float = Field(0.05, gt=0)
    young_hold: float = Field(0.3, ge=0)
    reach_onset_speed: float = Field(0.15, gt=0)
    reach_confirm_distance: float = Field(0.02, gt=0)
    approach_ratio: float = Field(0.5, ge=0, le=1)
    rest_speed: float = Field(0.05, gt=0)
    rest_hold: float = Field(0.15, ge=0)
    done_fraction: float = Field(0.15, ge=0, lt=1)
    retreat_far_distance: float = Field(0.60, gt=0)
    max_refine: float = Field(0.4, ge=0)
    max_retreat: float = Field(4.0, gt=0)
    smoothing: float = Field(0.12, gt=0)
    analysis_rate: float = Field(100.0, gt=0, le=2000)
    max_gap_hold: float = Field(0.25, ge=0)
    frozen_speed: float = Field(0.05, ge=0)
    glitch_jump: float = Field(0.03, ge=0)
    online_period: float = Field(0.02, ge=0)
    online_window: float = Field(5.0, gt=1)
    online_refresh: float = Field(0.1, ge=0)
    edge_guard: float = Field(0.04, ge=0)
    online_slack: float = Field(0.03, ge=0)
    reach_stall: float = Field(0.6, gt=0)
    stall_fraction: float = Field(0.2, gt=0, lt=1)
    reach_lookback: float = Field(2.0, ge=1)
    predict_window: float = Field(0.2, gt=0)
    predict_min_samples: int = Field(5, ge=4)
    predict_rest_window: float = Field(0.2, gt=0)
    predict_gap_factor: float = Field(3.0, ge=1)
    predict_noise_window: float = Field(1.0, gt=0)
    predict_distance: float = Field(0.016, gt=0)
    predict_cos: float = Field(0.3, ge=-1, le=1)
    predict_sigmas: float = Field(3.0, ge=0)
    predict_horizon: float = Field(0.3, ge=0)
    predict_gap_share: float = Field(0.15, ge=0, lt=1)
    sequential_window: float = Field(0.8, gt=0)
    sequential_onset_span: float = Field(0.5, gt=0)
    sequential_onset_step: float = Field(0.02, gt=0)
    sequential_durations: tuple[float, float] = (0.15, 2.5)
    sequential_duration_steps: int = Field(9, ge=2)
    fidget_amplitude: float = Field(0.02, gt=0)
    sequential_evidence: float = Field(25.0, gt=0)
    directed_support: float = Field(16.0, ge=0)
    trigger_distance_factor: float = Field(0.5, gt=0, le=1)
    trigger_speed_baseline: float = Field(0.1, gt=0)
    trigger_deep_fraction: float = Field(0.8, gt=0, le=1)
    trigger_own_fraction: float = Field(0.25, ge=0, le=1)
    trigger_still_factor: float = Field(2.0, ge=1)
    trigger_far_fraction: float = Field(0.8, gt=0, le=1)
    trigger_landing_fraction: float = Field(0.5, gt=0, lt=1)
    load_share_shared: float = Field(0.1, ge=0, le=1)
    load_share_robot: float = Field(0.9, ge=0, le=1)
    peak_passed_fraction: float = Field(0.8, gt=0, lt=1)

    @field_validator("method")
    @classmethod
    def _registered_method(cls, value: str) -> str:
        return PHASE_METHODS.check(value)

    @model_validator(mode="after")
    def _consistent(self) -> PhaseConfig:
        if self.transfer_exit_speed < self.transfer_speed_max:
            raise ValueError("transfer_exit_speed >= transfer_speed_max (hysteresis)")
        if self.load_share_robot < self.load_share_shared:
            raise ValueError("load_share_robot >= load_share_shared")
        if self.rest_speed > self.reach_onset_speed:
            raise ValueError("rest_speed <= reach_onset_speed")
        lo, hi = self.sequential_durations
        if not 0 < lo < hi:
            raise ValueError("sequential_durations: (shortest, longest), 0 < shortest < longest")
        if self.fidget_amplitude >= self.min_approach:
            raise ValueError("fidget_amplitude < min_approach (a fidget is smaller than a reach)")
        if self.sequential_window <= self.sequential_onset_span:
            raise ValueError("sequential_window > sequential_onset_span (rest before each onset)")
        return self


def default_phase_config_path() -> Path:
    """The shipped ``configs/phases.yaml``."""
    return configs_dir() / "phases.yaml"


def load_phase_config(path: str | Path | None = None) -> PhaseConfig:
    """Load phase settings from YAML (``None``: the shipped ``configs/phases.yaml``).

    Raises:
        ConfigError: The file is unreadable, not YAML, or a field is invalid (names the field).
    """
    return load_model(PhaseConfig, default_phase_config_path() if path is None else path)
