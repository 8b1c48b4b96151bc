"""Basis fit and prior: the weights reproduce a demonstration, the prior's mean reproduces the
demonstrations' mean, files round-trip and bad files are named."""

from __future__ import annotations

import numpy as np
import pytest

from gazebot.apps.bip.basis import GaussianBasis, fit_weights, reconstruct
from gazebot.apps.bip.demos import GIVER_DOFS, WIDTH_DOF, load_demo, load_demos, save_demos
from gazebot.apps.bip.prior import PHASE_GRID, BipPrior
from gazebot.io.recordings import RecordingError


def test_weights_reproduce_a_demonstration(training):
    d = training[0]
    basis = GaussianBasis()
    w = fit_weights(basis, d.phase, d.y)
    err = np.abs(reconstruct(basis, d.phase, w) - d.y)
    assert err[:, list(GIVER_DOFS)].max() < 0.01  # 1.5 mm tracker noise, smooth reach
    assert err[:, WIDTH_DOF].max() < 1e-3


def test_spaced_basis_keeps_the_default_ratio():
    assert GaussianBasis.spaced(9) == GaussianBasis()


def test_prior_mean_recovers_the_demonstrations_mean(prior, training):
    mean_demo = prior.curves.mean(axis=0)
    assert np.abs(prior.mean_trajectory(PHASE_GRID) - mean_demo).max() < 0.005
    assert prior.width_mean == pytest.approx(np.mean([d.width for d in training]))
    assert prior.mean[1] == pytest.approx(np.mean([1.0 / d.duration for d in training]))


def test_prior_round_trips(prior, tmp_path):
    prior.save(tmp_path)
    back = BipPrior.load(tmp_path)
    np.testing.assert_array_equal(back.cov, prior.cov)
    assert back.basis == prior.basis


def test_a_missing_prior_is_named(tmp_path):
    with pytest.raises(RecordingError, match="bip_prior.npz"):
        BipPrior.load(tmp_path)


def test_demos_round_trip(training, tmp_path):
    save_demos(training[:2], tmp_path)
    back = load_demos(tmp_path)
    assert [d.name for d in back] == [d.name for d in training[:2]]
    np.testing.assert_allclose(back[1].y, training[1].y, atol=1e-6)


@pytest.mark.parametrize(
    ("text", "problem"),
    [
        ("t,x\n0,1\n", "missing column"),
        ("", "empty file"),
    ],
)
def test_bad_demo_files_are_named(tmp_path, text, problem):
    path = tmp_path / "bad.csv"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(RecordingError, match=f"bad.csv: {problem}"):
        load_demo(path)


def test_a_non_finite_sample_is_named(training, tmp_path):
    (path,) = save_demos(training[:1], tmp_path)
    lines = path.read_text(encoding="utf-8").splitlines()
    cells = lines[5].split(",")
    cells[3] = "nan"
    lines[5] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    with pytest.raises(RecordingError, match="non-finite"):
        load_demo(path)


def test_basis_is_finite_far_outside_the_phase_range():
    basis = GaussianBasis()
    phases = np.array([-50.0, -2.0, 3.0, 80.0])
    assert np.all(np.isfinite(basis.values(phases)))
    assert np.all(np.isfinite(basis.derivative(phases)))
    np.testing.assert_allclose(basis.values(phases).sum(axis=-1), 1.0)


def test_basis_derivative_matches_finite_differences():
    basis = GaussianBasis()
    phi, h = np.linspace(-0.2, 1.2, 15), 1e-6
    numeric = (basis.values(phi + h) - basis.values(phi - h)) / (2 * h)
    np.testing.assert_allclose(basis.derivative(phi), numeric, atol=1e-5)
