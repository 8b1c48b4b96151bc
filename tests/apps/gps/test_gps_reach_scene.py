"""The chapter-5 scene: the Panda learner from its DH table, the tester, eq. 5.12, the shell."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gazebot.apps.gps import panda
from gazebot.apps.gps.config import load_gps_config
from gazebot.apps.gps.reach_scene import HandoverScene
from gazebot.apps.gps.shell import shell_grid, training_targets
from gazebot.apps.gps.state import DIMS, StateKind, gap_selector, state_vector
from gazebot.apps.gps.tester import (
    UnreachableTarget,
    hand_position,
    human_like,
    motion_to,
    planar_fk,
    planar_ik,
)

CFG = load_gps_config()


@pytest.fixture(scope="module")
def scene() -> HandoverScene:
    return HandoverScene(CFG.scene)


def _dh_tcp(q: np.ndarray) -> np.ndarray:
    """The TCP by chaining Craig's modified DH transforms, independently of the MJCF."""
    T = np.eye(4)
    for (a, d, alpha), qi in zip(panda.DH, q, strict=True):
        ca, sa, cq, sq = math.cos(alpha), math.sin(alpha), math.cos(qi), math.sin(qi)
        T = T @ np.array([[cq, -sq, 0, a], [sq * ca, cq * ca, -sa, -d * sa],
                          [sq * sa, cq * sa, ca, d * ca], [0, 0, 0, 1]])
    return (T @ np.array([0, 0, panda.FLANGE_D_M + panda.TCP_OFFSET_M, 1.0]))[:3]


def test_learner_gripper_follows_franka_dh_table(scene):
    motion = motion_to(training_targets(CFG.shell, 8)[0], False, CFG.scene.tester)
    rng = np.random.default_rng(1)
    for q in [np.zeros(7), np.array(CFG.scene.home_rad), rng.uniform(-1, 1, 7)]:
        scene.reset(motion)
        scene.data.qpos[scene._arm_q] = q
        import mujoco

        mujoco.mj_forward(scene.model, scene.data)
        np.testing.assert_allclose(scene.observe().p_r, _dh_tcp(q), atol=1e-9)
    # At zero angles the flange points down from 0.333 + 0.316 + 0.384 - 0.107 m.
    np.testing.assert_allclose(_dh_tcp(np.zeros(7)), [0.088, 0, 1.033 - 0.107 - 0.1034], atol=1e-12)


def test_learner_has_published_masses_and_the_seed_end_effector_mass(scene):
    m = scene.model
    masses = [m.body_mass[m.body(f"link{i + 1}").id] for i in range(7)]
    np.testing.assert_allclose(masses, [link.mass for link in panda.LINKS])
    assert m.body_mass[m.body("hand").id] == pytest.approx(2.0)
    assert HandoverScene(CFG.scene, 8.0).model.body_mass[m.body("hand").id] == pytest.approx(8.0)


def test_commands_are_clipped_to_torque_and_force_bounds_and_never_non_finite(scene):
    scene.reset(motion_to(training_targets(CFG.shell, 8)[0], False, CFG.scene.tester))
    u = scene.clip(np.array([1e3, -1e3, np.nan, np.inf, 50, -50, 5, 1e4]))
    lo, hi = scene.u_bounds
    assert np.all(u >= lo) and np.all(u <= hi) and np.all(np.isfinite(u))
    np.testing.assert_allclose(u[:7], [87, -87, 0, 0, 12, -12, 5])
    assert u[7] == pytest.approx(CFG.scene.gripper_force_n)
    scene.step(np.full(8, np.nan))
    assert np.all(np.isfinite(scene.data.ctrl))


def test_robot_gravity_compensation_holds_the_nominal_arm_and_not_a_heavier_one(scene):
    motion = motion_to(training_targets(CFG.shell, 8)[0], False, CFG.scene.tester)
    start = scene.reset(motion).p_r
    for _ in range(20):
        obs = scene.step(np.zeros(8))
    assert np.linalg.norm(obs.p_r - start) < 1e-3
    heavy = HandoverScene(CFG.scene, 8.0)
    heavy.reset(motion)
    for _ in range(20):
        obs_h = heavy.step(np.zeros(8))
    assert obs_h.p_r[2] < start[2] - 0.05


def test_eq_5_12_endpoints_and_shape():
    tc = CFG.scene.tester
    th0, thf = np.array([0.0, 0.0]), np.array([1.0, -0.5])
    q0, _ = human_like(0.0, th0, thf, tc)
    qf, qdf = human_like(tc.t_f_s, th0, thf, tc)
    q_late, qd_late = human_like(5.0, th0, thf, tc)
    np.testing.assert_allclose(q0, (thf - th0) * 9.05e-4 / (8.908e-4 + 1.0), rtol=1e-12)
    np.testing.assert_allclose(qf, (thf - th0) * 9.05e-4 / (8.908e-4 + math.exp(-12.87)))
    np.testing.assert_allclose(q_late, (thf - th0) * 9.05e-4 / 8.908e-4, rtol=1e-6)
    assert np.all(np.abs(qd_late) < 1e-6)
    ts = np.linspace(0, 2, 201)
    q, qd = human_like(ts, th0, thf, tc)
    assert np.all(np.diff(q[:, 0]) > 0) and np.all(np.diff(q[:, 1]) < 0)
    # The velocity is the derivative of the position.
    np.testing.assert_allclose(qd[1:-1, 0], (q[2:, 0] - q[:-2, 0]) / (ts[2] - ts[0]), atol=5e-3)
    # Half of the motion happens near t = t_f ln(1/b) / c ~ 0.55 s.
    half = ts[np.argmax(q[:, 0] >= 0.5 * q[-1, 0])]
    assert half == pytest.approx(tc.t_f_s * math.log(1 / 8.908e-4) / 12.87, abs=0.02)


def test_tester_ik_puts_its_hand_on_every_shell_location():
    tc = CFG.scene.tester
    for p in shell_grid(CFG.shell, 3):
        m = motion_to(p, True, tc)
        np.testing.assert_allclose(hand_position(m.azimuth, *m.thetaf, tc), p, atol=1e-9)
        assert m.thetaf[1] >= 0  # the elbow flexes forwards
    sh, el = planar_ik(0.3, -0.6, tc)
    assert planar_fk(sh, el, tc) == pytest.approx((0.3, -0.6))
    with pytest.raises(UnreachableTarget, match="cannot reach"):
        planar_ik(2.0, 0.0, tc)


def test_scene_places_the_tester_hand_where_the_ik_says(scene):
    p = training_targets(CFG.shell, 8)[3]
    obs = scene.reset(motion_to(p, False, CFG.scene.tester))
    np.testing.assert_allclose(obs.p_h, p, atol=1e-9)
    # Moving tester: starts at its rest posture (eq. 5.12's theta_0), ends near the target
    # (eq. 5.12 settles 1.6% beyond theta_f).
    m = motion_to(p, True, CFG.scene.tester)
    obs = scene.reset(m)
    rest = np.radians(CFG.scene.tester.rest_deg)
    np.testing.assert_allclose(obs.p_h, hand_position(m.azimuth, *rest, CFG.scene.tester),
                               atol=0.002)  # eq. 5.12 has moved 0.09% of the way at t = 0
    assert np.linalg.norm(obs.p_h - p) > 0.1
    for _ in range(CFG.scene.horizon):
        obs = scene.step(np.zeros(8))
    assert np.linalg.norm(obs.p_h - p) < 0.03


def test_shell_has_the_seeds_2299_locations_and_training_targets_at_its_corners():
    pts = shell_grid(CFG.shell)
    assert pts.shape == (2299, 3)
    assert shell_grid(CFG.shell, 3).shape == (19 * 9, 3)
    r = np.linalg.norm(pts, axis=1)
    assert r.min() == pytest.approx(CFG.shell.radius_m[0])
    assert r.max() == pytest.approx(CFG.shell.radius_m[1])
    t8, t12 = training_targets(CFG.shell, 8), training_targets(CFG.shell, 12)
    assert len(t8) == 8 and len(t12) == 12
    assert np.all(np.min(np.linalg.norm(pts[:, None] - t8[None], axis=2), axis=0) < 1e-12)
    np.testing.assert_allclose(t12[8:, 1], 0.0, atol=1e-12)  # the middle vertical plane
    with pytest.raises(ValueError, match="8 or 12"):
        training_targets(CFG.shell, 10)


@pytest.mark.parametrize("kind", list(StateKind))
def test_state_dimensions_and_gap_to_the_hand(scene, kind):
    p = training_targets(CFG.shell, 8)[5]
    obs = scene.reset(motion_to(p, True, CFG.scene.tester))
    obs = scene.step(np.r_[5.0, -5.0, 3.0, 2.0, 1.0, 0.5, 0.5, 10.0])
    x = state_vector(obs, kind)
    assert x.shape == (DIMS[kind],)
    gap = gap_selector(kind) @ x
    assert np.linalg.norm(gap) == pytest.approx(np.linalg.norm(obs.p_r - obs.p_h))
    np.testing.assert_allclose(x[:7], obs.theta_r)
    assert x[-1] == pytest.approx(obs.g_r)


def test_trial_error_is_the_mean_gap_over_the_last_half_second():
    from gazebot.apps.gps.trial import Trial

    n = 41  # 2 s at 20 Hz, both ends included
    p_h = np.zeros((n, 3))
    p_r = np.zeros((n, 3))
    p_r[:, 0] = np.linspace(1.0, 0.0, n)  # gap shrinks linearly from 1 m to 0
    trial = Trial(np.zeros((40, 1)), np.zeros((40, 1)), p_r, p_h, np.zeros(n), 0.05)
    # t = 1.5 .. 2.0 s: gaps 0.25, 0.225, ..., 0 (11 samples), mean 0.125 m.
    assert trial.final_error() == pytest.approx(0.125)


def test_the_moving_tester_starts_at_the_seeds_theta_0_with_the_arm_hanging_straight_down(scene):
    """Seed 5.4: "We set theta_0,1 = theta_0,2 = 0" in eq. 5.12; our zero hangs the arm down."""
    tc = CFG.scene.tester
    assert tc.rest_deg == (0.0, 0.0)
    p = training_targets(CFG.shell, 8)[0]
    m = motion_to(p, True, tc)
    assert m.theta0 == (0.0, 0.0)
    obs = scene.reset(m)
    below_shoulder = hand_position(m.azimuth, 0.0, 0.0, tc)
    assert below_shoulder[2] == pytest.approx(tc.shoulder_height_m - tc.upper_arm_m - tc.forearm_m)
    np.testing.assert_allclose(obs.p_h, below_shoulder, atol=0.002)
