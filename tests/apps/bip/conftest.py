"""Shared fixtures: a prior from 30 synthetic demonstrations and held-out test demonstrations
whose objects are narrower or wider than the training mean (0.33 m)."""

from __future__ import annotations

import pytest

from gazebot.apps.bip.demos import DemoGenerator
from gazebot.apps.bip.prior import train


@pytest.fixture(scope="session")
def generator():
    return DemoGenerator()


@pytest.fixture(scope="session")
def training(generator):
    return generator.draw_many(30, seed=1)


@pytest.fixture(scope="session")
def prior(training):
    return train(training)


@pytest.fixture(scope="session")
def off_mean_tests(generator):
    return generator.draw_many(4, seed=99, widths=[0.20, 0.45, 0.24, 0.42], prefix="test")
