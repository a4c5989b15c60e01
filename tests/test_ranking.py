"""The tournament tree against a brute-force argmax (``tt_top_reference``) over random update
sequences."""

import numpy as np
import pytest

from curvefair._kernels.ranking import tt_build, tt_top, tt_top_reference, tt_update, tt_value


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
        bi, bv = tt_top_reference(values)
        assert val == bv
        if np.isfinite(bv):
            assert idx == bi


def test_all_ineligible():
    tv, ti = tt_build(np.full(5, -np.inf))
    idx, val = tt_top(tv, ti)
    assert val == -np.inf and idx in range(5)


@pytest.mark.parametrize("n", [1, 5, 16, 17, 33, 1000])
def test_range_updates_match_argmax(n):
    from curvefair._kernels.ranking import tt_update_range

    rng = np.random.default_rng(1000 + n)
    values = rng.integers(0, 10, n).astype(float)  # many ties
    tv, ti = tt_build(values)
    for _ in range(2 * n + 10):
        lo = int(rng.integers(n))
        hi = min(n - 1, lo + int(rng.integers(0, 40)))
        new = rng.integers(0, 10, hi - lo + 1).astype(float)
        new[rng.random(new.size) < 0.2] = -np.inf
        values[lo:hi + 1] = new
        tt_update_range(tv, ti, lo, hi, values)
        for i in (lo, hi):
            assert tt_value(tv, i) == values[i]
        idx, val = tt_top(tv, ti)
        bi, bv = tt_top_reference(values)
        assert val == bv
        if np.isfinite(bv):
            assert idx == bi


def test_empty_tree():
    tv, ti = tt_build(np.zeros(0))
    assert tt_top(tv, ti) == (-1, -np.inf)


@pytest.mark.parametrize("n", [70_000, 70_001 + 16 * 5])
def test_blocked_tree_matches_argmax(n):
    # above 65536 entries the tree holds blocks of 16: single and range updates vs brute force
    from curvefair._kernels.ranking import tt_update_range

    rng = np.random.default_rng(n)
    values = rng.integers(0, 50, n).astype(float)
    tv, ti = tt_build(values)
    assert ti[0] == 4  # blocked layout in use
    for step in range(3000):
        if step % 3:
            i = int(rng.integers(n))
            values[i] = -np.inf if rng.random() < 0.2 else float(rng.integers(0, 60))
            tt_update(tv, ti, i, values[i])
        else:
            lo = int(rng.integers(n))
            hi = min(n - 1, lo + int(rng.integers(0, 40)))
            values[lo:hi + 1] = rng.integers(0, 60, hi - lo + 1)
            tt_update_range(tv, ti, lo, hi, values)
        idx, val = tt_top(tv, ti)
        bi, bv = tt_top_reference(values)
        assert val == bv and idx == bi
    assert all(tt_value(tv, i) == values[i] for i in rng.integers(0, n, 50))
