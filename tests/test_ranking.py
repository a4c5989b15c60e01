"""The tournament tree against a brute-force argmax over random update sequences."""

import numpy as np
import pytest

from curvefair.fairing.ranking import tt_build, tt_top, tt_update, tt_value


def _brute_top(values):
    finite = np.isfinite(values) | (values > 0)
    if not finite.any() or np.all(values == -np.inf):
        return int(np.argmax(values)) if values.size else -1, float(values.max()) if values.size else -np.inf
    m = values.max()
    return int(np.flatnonzero(values == m)[0]), float(m)


@pytest.mark.parametrize("n", [1, 2, 3, 7, 8, 9, 100, 1000])
def test_random_updates_match_argmax(n):
    rng = np.random.default_rng(n)
    values = rng.integers(0, 20, n).astype(float)  # many ties on purpose
    tv, ti = tt_build(values)
    for _ in range(3 * n + 10):
        i = int(rng.integers(n))
        v = -np.inf if rng.random() < 0.2 else float(rng.integers(0, 20))
        values[i] = v
        tt_update(tv, ti, i, v)
        assert tt_value(tv, i) == v
        idx, val = tt_top(tv, ti)
        bi, bv = _brute_top(values)
        assert val == bv
        if np.isfinite(bv):
            assert idx == bi


def test_all_ineligible():
    tv, ti = tt_build(np.full(5, -np.inf))
    idx, val = tt_top(tv, ti)
    assert val == -np.inf and idx in range(5)
