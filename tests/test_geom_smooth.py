"""Issue 11, "geometry damaged": smooth joins stay smooth, corners and straight pieces stay,
the g2 clamp is exact, and a default run never makes the fairness counts worse unannounced.

Every check measures the result independently of curvefair's own code paths: scipy's
``CubicHermiteSpline`` / ``BSpline`` for derivatives, numpy for angles.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import CubicHermiteSpline

from curvefair import CubicHermite, fair


def _kappa_hermite(c, u):
    s = CubicHermiteSpline(np.asarray(c.params), np.asarray(c.points), np.asarray(c.tangents))
    d1, d2 = s(u, 1), s(u, 2)
    return (d1[0] * d2[1] - d1[1] * d2[0]) / np.hypot(*d1) ** 3


# ------------------------------------------------------------------------------------------
# 3. clamp="g2" on a cubic Hermite curve that is not a C2 spline
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("seed", [0, 3])
def test_g2_clamp_exact_on_non_c2_hermite(seed):
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 10.0, 12)
    P = np.c_[t, np.sin(t) + 0.05 * rng.normal(size=12)]
    T = np.c_[np.ones(12), np.cos(t) + 0.3 * rng.normal(size=12)]
    c = CubicHermite(P, T, t)
    res = fair(c, clamp="g2")  # default method and mode ("spline")
    assert res.report["steps"] > 0
    for u in (0.0, 10.0):
        k0, k1 = _kappa_hermite(c, u), _kappa_hermite(res.curve, u)
        assert abs(k1 - k0) <= 1e-12 * abs(k0)
    # the curve changed, and the report says the points moved
    assert res.report["n_moved"] > 0


def test_zero_steps_returns_the_input_unchanged():
    rng = np.random.default_rng(5)
    t = np.linspace(0.0, 4.0, 5)
    P = np.c_[t, np.cos(t)]
    T = np.c_[np.ones(5), -np.sin(t) + 0.2 * rng.normal(size=5)]
    c = CubicHermite(P, T, t)
    res = fair(c, clamp="g2", protect=[2])  # every interior point held or protected
    assert res.report["steps"] == 0
    u = np.linspace(0.0, 4.0, 401)
    assert np.array_equal(res.curve(u), c(u))
    assert res.report["max_deviation"] == 0.0
