"""The seed's least-squares linear human-motion model (eq. 4.5)."""

from __future__ import annotations

import numpy as np
import pytest

from gazebot.apps.controllers.human_model import LinearHandModel


def test_fit_recovers_a_linear_system_and_predicts_eq_4_5():
    A = np.array([[-0.5, 0.1, 0.0], [0.0, -0.3, 0.2], [0.05, 0.0, -0.4]])
    dt = 0.2
    model = LinearHandModel(dt, history=6)
    p = np.array([1.0, 0.5, 1.2])
    for _ in range(6):
        model.observe(p)
        p = p + dt * A @ p  # Euler steps of p_dot = A p
    assert model.fit() == pytest.approx(A, abs=1e-9)
    last = model._samples[-1]
    pred = model.predict(3)
    assert pred[0] == pytest.approx(last)
    assert pred[3] == pytest.approx(last + 3 * dt * A @ last)  # p(t0) + (t dt) A p(t0)


def test_a_still_or_single_sample_hand_is_predicted_still():
    model = LinearHandModel(0.2, history=4)
    model.observe([0.8, 0.0, 1.0])
    assert np.allclose(model.predict(5), [0.8, 0.0, 1.0])
    for _ in range(3):
        model.observe([0.8, 0.0, 1.0])
    assert np.allclose(model.predict(5), [0.8, 0.0, 1.0])


def test_predict_before_any_sample_is_an_error():
    with pytest.raises(ValueError, match="no hand"):
        LinearHandModel(0.2).predict(3)
