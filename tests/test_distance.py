"""The per-point move of every report (curvefair._distance, fair()'s point report) is numpy's
``np.linalg.norm(moved - original, axis=-1)`` bit for bit, computed in one compiled pass."""

from __future__ import annotations

import numpy as np
import pytest

import curvefair as cf
from curvefair._distance import exceeds, point_distances
from curvefair.fairing import point_report


@pytest.mark.parametrize("dim", [2, 3])
def test_point_distances_are_numpys_norm_bit_for_bit(dim):
    rng = np.random.default_rng(dim)
    n = 200_000
    scale = np.exp(rng.normal(size=(n, 1)) * 8)  # magnitudes over many decades
    o = rng.normal(size=(n, dim)) * scale + rng.choice([0.0, 1e3, 1e12], size=(n, 1))
    m = o + rng.normal(size=(n, dim)) * scale * rng.choice([1e-12, 1e-3, 1.0], size=(n, 1))
    got = point_distances(m, o)
    want = np.linalg.norm(m - o, axis=-1)
    assert got.dtype == np.float64 and got.tobytes() == want.tobytes()
    # strided and 1-D inputs as before
    assert point_distances(m[::3], o[::3]).tobytes() == want[::3].tobytes()
    assert point_distances(m[0], o[0]) == np.linalg.norm(m[0] - o[0])


def test_exceeds_checks_every_usual_formula_at_the_sphere():
    rng = np.random.default_rng(7)
    o = rng.normal(size=(5000, 3)) * 1e6
    u = rng.normal(size=(5000, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    tol = 0.37
    m = o + u * tol  # on the sphere, up to rounding either way
    bad = exceeds(m, o, tol)
    ok = ~bad
    d = m - o
    # every point passed is inside by each formula a user may evaluate
    assert (np.linalg.norm(d, axis=1)[ok] <= tol).all()
    assert all(np.linalg.norm(d[i]) <= tol for i in np.flatnonzero(ok))
    assert bad.any() and ok.any()


def test_point_report_is_the_numpy_formulation():
    rng = np.random.default_rng(3)
    t = np.linspace(0, 9, 400)
    c = cf.interpolate_bspline(np.c_[t, np.sin(t)] + 0.01 * rng.normal(size=(400, 2)))
    P = np.array(c.control_points)
    P[::7] += 1e-3 * rng.normal(size=P[::7].shape)
    P[5, 1] = np.nextafter(P[5, 1], np.inf)  # a move of one ulp counts
    new = c.replace(control_points=P)
    moved, disp, dmax, imax = point_report(c, new)
    p0 = np.asarray(c.control_points)
    want = np.flatnonzero(np.any(p0 != P, axis=1))
    assert np.array_equal(moved, want) and 5 in moved
    assert disp.tobytes() == np.linalg.norm(P[want] - p0[want], axis=1).tobytes()
    assert dmax == disp.max() and imax == int(moved[np.argmax(disp)])
    assert point_report(c, c)[0].size == 0
