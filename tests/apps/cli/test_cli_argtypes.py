"""The shared argparse converters reject what the commands cannot use, with one line."""

from __future__ import annotations

import argparse

import pytest

from gazebot.apps.cli.argtypes import int_at_least, positive, seed_value


@pytest.mark.parametrize("text", ["0", "-1", "nan", "inf", "-inf", "x", ""])
def test_positive_rejects_zero_negative_and_non_finite(text: str) -> None:
    with pytest.raises(argparse.ArgumentTypeError, match="number > 0"):
        positive(text)


def test_positive_accepts_a_finite_positive_number() -> None:
    assert positive("0.25") == 0.25


@pytest.mark.parametrize(("minimum", "text"), [(0, "-1"), (1, "0"), (2, "1"), (2, "2.5"), (0, "x")])
def test_int_at_least_names_the_minimum(minimum: int, text: str) -> None:
    with pytest.raises(argparse.ArgumentTypeError, match=f"expected an integer >= {minimum}, got"):
        int_at_least(minimum)(text)


def test_seed_value_accepts_zero_and_large_seeds() -> None:
    assert seed_value("0") == 0
    assert seed_value("123456789") == 123456789


def test_argparse_reports_a_bad_value_in_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    parser = argparse.ArgumentParser(prog="gazebot x")
    parser.add_argument("--grid", type=int_at_least(2))
    with pytest.raises(SystemExit):
        parser.parse_args(["--grid", "1"])
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err == "gazebot x: error: argument --grid: expected an integer >= 2, got '1'"
