"""The ensemble BIP: it converges on a demonstration from the training distribution; without the
constraint its predicted wrist distance stays near the training mean (the seed's Fig. 7.10);
with either constraint of the seed's 7.5 the predicted wrists keep the object's width."""

from __future__ import annotations

import numpy as np
import pytest

from gazebot.apps.bip.constraint import constrain_members, grip_constraint, project_gaussian
from gazebot.apps.bip.demos import GIVER_DOFS
from gazebot.apps.bip.enbip import EnsembleBIP, FilterConfig
from gazebot.apps.bip.evaluate import evaluate

ALL_DOFS = FilterConfig(observed=tuple(range(13)))


def test_filter_converges_on_a_demonstration_from_the_training_distribution(prior, generator):
    for d in generator.draw_many(3, seed=7):
        f = EnsembleBIP(prior, ALL_DOFS, seed=1)
        prior_now = f.predict(np.zeros(1), GIVER_DOFS)[0]
        for k in range(60):
            f.step(d.y[k], 1.0 / 120.0)
        assert f.phase == pytest.approx(d.phase[59], abs=0.05)
        now = f.predict(np.zeros(1), GIVER_DOFS)[0]
        truth = d.y[59, list(GIVER_DOFS)]
        assert np.abs(now - truth).max() < 0.02
        assert np.abs(now - truth).max() < np.abs(prior_now - d.y[0, list(GIVER_DOFS)]).max() + 0.02


def test_unconstrained_wrist_distance_stays_near_the_training_mean(prior, off_mean_tests):
    res = evaluate(prior, off_mean_tests, observe=10, modes=("none",))["modes"]["none"]
    # The width error is most of the objects' deviation from the training mean (seed 7.4.2).
    assert res["width_error_over_deviation"] >= 0.7
    assert res["width_error_mean_m"] > 0.05


@pytest.mark.parametrize("mode", ["projection", "filter"])
def test_constrained_predictions_meet_the_width(prior, off_mean_tests, mode):
    res = evaluate(prior, off_mean_tests, observe=10, modes=("none", mode))["modes"]
    assert res[mode]["width_error_mean_m"] <= 0.01
    assert res[mode]["position_error_m"] <= 1.2 * res["none"]["position_error_m"]


def test_projection_is_exact_on_the_constraint(prior):
    c = grip_constraint(prior, 0.25)
    mean, cov = project_gaussian(prior.mean, prior.cov, c)
    np.testing.assert_allclose(c.residual(mean), 0.0, atol=1e-8)
    np.testing.assert_allclose(c.A @ cov @ c.A.T, 0.0, atol=1e-8)


def test_member_projection_meets_the_constraint(prior):
    c = grip_constraint(prior, 0.25)
    members = EnsembleBIP(prior, seed=2).members
    assert np.abs(c.residual(members)).max() > 0.01
    out = constrain_members(members, c, noise_sd=0.0)
    assert np.abs(c.residual(out)).max() < 1e-3


def test_constraint_modes_need_a_width(prior):
    with pytest.raises(ValueError, match="width"):
        EnsembleBIP(prior, mode="filter")


@pytest.mark.parametrize("mode", ["projection", "filter"])
def test_constraints_hold_with_the_seeds_eight_demonstrations(generator, mode):
    # A prior from 8 demonstrations has spurious correlations (the grip axis's yaw with the
    # width); the constraint must hold the whole separation, not only its component on the axis
    # (which left the 7th of these tests 3.8 cm off).
    from gazebot.apps.bip.prior import train

    prior8 = train(generator.draw_many(8, seed=1))
    tests = generator.draw_many(8, seed=99, widths=[0.20, 0.45, 0.24, 0.40, 0.22, 0.42])
    res = evaluate(prior8, tests, observe=10, modes=("none", mode))["modes"]
    assert res[mode]["width_error_max_m"] <= 0.01
    assert res[mode]["position_error_m"] <= 1.2 * res["none"]["position_error_m"]


def test_ensemble_and_exact_bip_agree_on_the_phase(prior, generator):
    from gazebot.apps.bip.ekf import ExtendedBIP

    d = generator.draw_many(1, seed=7)[0]
    ens, ekf = EnsembleBIP(prior, ALL_DOFS, seed=1), ExtendedBIP(prior, ALL_DOFS)
    for k in range(60):
        ens.step(d.y[k], 1.0 / 120.0)
        ekf.step(d.y[k], 1.0 / 120.0)
    assert ekf.mu[0] == pytest.approx(d.phase[59], abs=0.05)
    assert ens.phase == pytest.approx(ekf.mu[0], abs=0.05)
