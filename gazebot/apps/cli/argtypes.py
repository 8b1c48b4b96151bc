"""argparse ``type=`` converters the commands share: each rejects a bad value with one line
saying what was expected, which argparse prints as ``gazebot ...: error: argument --x: ...``."""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable


def positive(value: str) -> float:
    """A finite number > 0 (durations, speeds, masses)."""
    try:
        x = float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number > 0, got {value!r}") from None
    if not (x > 0 and math.isfinite(x)):
        raise argparse.ArgumentTypeError(f"expected a finite number > 0, got {value!r}")
    return x


def int_at_least(minimum: int) -> Callable[[str], int]:
    """A converter accepting integers >= ``minimum``."""

    def convert(value: str) -> int:
        try:
            n = int(value)
        except ValueError:
            n = None
        if n is None or n < minimum:
            raise argparse.ArgumentTypeError(f"expected an integer >= {minimum}, got {value!r}")
        return n

    convert.__name__ = f"integer >= {minimum}"
    return convert


#: A ``--seed``: a non-negative integer, what NumPy's generators accept.
seed_value = int_at_least(0)
