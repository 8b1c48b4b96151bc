"""``filtering.smooth_seen_prefix`` (the online cache's smoothing when only the rows past the
newest sample are unknown) gives what ``smooth`` gives with that mask, bit for bit."""

from __future__ import annotations

import numpy as np

from gazebot.core.phases.filtering import smooth, smooth_seen_prefix


def _bits(a: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(a).view(np.int64)


def test_smoothing_a_seen_prefix_is_smooth_with_the_unknown_rows_masked() -> None:
    rng = np.random.default_rng(11)
    for rows in (1, 2, 3, 5, 20, 47, 90):
        for sigma in (0.0, 0.7, 2.5, 6.0):
            for seen in sorted({0, 1, rows // 2, rows - 1, rows, rows + 3}):
                if seen < 0:
                    continue
                x = rng.normal(size=(rows, 6)) * 0.3 + 1.0
                x[rng.random((rows, 6)) < 0.05] = -0.0  # (signed zeros kept as they are)
                ref = x.copy()
                ref[seen:] = np.nan  # what the cache's rows past the newest sample held
                fin = np.isfinite(ref)
                m = fin[:, 0::3] & fin[:, 1::3] & fin[:, 2::3]
                want_x, want_share = smooth(ref, m, sigma)
                got_x, got_share = smooth_seen_prefix(x, seen, sigma)
                assert got_x.shape == want_x.shape and got_share.shape == want_share.shape
                np.testing.assert_array_equal(_bits(got_x), _bits(want_x))
                np.testing.assert_array_equal(_bits(got_share), _bits(want_share))
