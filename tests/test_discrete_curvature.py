"""Discrete curvature of polygons (Cheng & Yu eq. (2), ERRATA factor 4).

References used here, none a copy of eq. (2):
* eq. (1) as the curvature of chord-length difference quotients (x', x'' of Carmel & Cohen-Or),
  evaluated point by point in a plain loop;
* circles: chords from the law of sines (2 R sin(angle / 2)), analytic 1/R;
* smooth curves (ellipse, helix): analytic curvature, second-order convergence.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from curvefair import InputError, discrete_curvature


def _eq1_reference(P, closed=False):
    """Eq. (1) read as the planar curvature of chord-length difference quotients (slow loop)."""
    n = len(P)
    out = np.zeros(n)
    rng = range(n) if closed else range(1, n - 1)
    for i in rng:
        a, b, c = P[(i - 1) % n], P[i], P[(i + 1) % n]
        L0 = np.hypot(*(b - a))
        L1 = np.hypot(*(c - b))
        d1 = (c - a) / (L0 + L1)  # first derivative w.r.t. arc length
        d2 = ((c - b) / L1 - (b - a) / L0) / ((L0 + L1) / 2)  # second derivative
        out[i] = (d1[0] * d2[1] - d1[1] * d2[0]) / (d1[0] ** 2 + d1[1] ** 2) ** 1.5
    return out


@pytest.mark.parametrize("closed", [False, True])
def test_matches_difference_quotient_curvature(closed):
    rng = np.random.default_rng(5)
    P = rng.normal(size=(40, 2))
    np.testing.assert_allclose(discrete_curvature(P, closed=closed), _eq1_reference(P, closed),
                               rtol=1e-11, atol=1e-12)


@pytest.mark.parametrize("R", [0.3, 1.0, 7.5])
def test_circle_random_spacing_law_of_sines(R):
    # On a circle C_i = (L_i + L_{i+1})^2 / (M_i^2 R): 1/R only in the limit (ERRATA factor 4;
    # the printed factor 2 would give half). Chords from the central angles, not from the points.
    rng = np.random.default_rng(int(R * 10))
    th = np.sort(rng.uniform(0, 2 * np.pi, 30))
    P = R * np.c_[np.cos(th), np.sin(th)]
    C = discrete_curvature(P, closed=True)
    dth = np.diff(np.r_[th, th[0] + 2 * np.pi])  # dth[i] = angle from point i to i+1
    L_next = 2 * R * np.sin(dth / 2)
    L_prev = np.roll(L_next, 1)
    M = 2 * R * np.sin((dth + np.roll(dth, 1)) / 2)
    np.testing.assert_allclose(C * R * M**2 / (L_prev + L_next) ** 2, 1.0, rtol=1e-11)
    assert np.all(C >= 1 / R * (1 - 1e-12))  # always overestimates a circle


def test_circle_converges_second_order_and_is_signed():
    R = 2.0
    errs = []
    for n in (16, 32, 64, 128):
        th = np.linspace(0, 2 * np.pi, n, endpoint=False)
        P = R * np.c_[np.cos(th), np.sin(th)]
        C = discrete_curvature(P, closed=True)
        errs.append(np.max(np.abs(C - 1 / R)))
        # clockwise traversal: negative curvature
        np.testing.assert_allclose(discrete_curvature(P[::-1], closed=True), -C[::-1], rtol=1e-12)
    ratios = np.array(errs[:-1]) / np.array(errs[1:])
    assert np.all(ratios > 3.8) and np.all(ratios < 4.2)
    assert errs[-1] < 1.01 / R * (np.pi / 128) ** 2  # relative error ~ (pi / n)^2


def test_ellipse_converges_second_order():
    a, b = 2.0, 1.0
    errs = []
    for n in (50, 100, 200, 400):
        t = np.linspace(0, 2 * np.pi, n, endpoint=False)
        P = np.c_[a * np.cos(t), b * np.sin(t)]
        k = a * b / (a * a * np.sin(t) ** 2 + b * b * np.cos(t) ** 2) ** 1.5
        errs.append(np.max(np.abs(discrete_curvature(P, closed=True) - k)))
    ratios = np.array(errs[:-1]) / np.array(errs[1:])
    assert np.all(ratios > 3.5), ratios


def test_helix_3d_unsigned():
    a, c = 1.5, 0.4
    k_exact = a / (a * a + c * c)
    t = np.linspace(0, 4 * np.pi, 801)
    P = np.c_[a * np.cos(t), a * np.sin(t), c * t]
    C = discrete_curvature(P)
    assert C[0] == 0.0 and C[-1] == 0.0
    np.testing.assert_allclose(C[1:-1], k_exact, rtol=1e-4)
    # mirrored helix: same unsigned value
    np.testing.assert_allclose(discrete_curvature(P * [1, -1, 1]), C, rtol=1e-12)


def test_planar_curve_in_3d_is_absolute_value():
    rng = np.random.default_rng(2)
    P2 = rng.normal(size=(25, 2))
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    P3 = np.c_[P2, np.zeros(25)] @ Q.T + [1.0, -2.0, 3.0]
    np.testing.assert_allclose(discrete_curvature(P3), np.abs(discrete_curvature(P2)),
                               rtol=1e-10, atol=1e-12)


def test_open_ends_are_zero_remark1():
    rng = np.random.default_rng(3)
    P = rng.normal(size=(10, 2))
    C = discrete_curvature(P)
    assert C[0] == 0.0 and C[-1] == 0.0
    # Remark 1 literally: append the reflected points, use the interior formula
    ext = np.vstack([2 * P[0] - P[1], P, 2 * P[-1] - P[-2]])
    np.testing.assert_allclose(discrete_curvature(ext)[1:-1], C, atol=1e-12)
    assert discrete_curvature(P[:2]).tolist() == [0.0, 0.0]


def test_closed_is_cyclic_and_accepts_repeated_first_point():
    rng = np.random.default_rng(4)
    P = rng.normal(size=(12, 2))
    C = discrete_curvature(P, closed=True)
    # cyclic: the open interior of the wrapped polygon
    wrapped = np.vstack([P[-1:], P, P[:1]])
    np.testing.assert_allclose(C, discrete_curvature(wrapped)[1:-1], rtol=1e-13)
    # shifting the start does not change the values
    np.testing.assert_allclose(discrete_curvature(np.roll(P, 3, axis=0), closed=True),
                               np.roll(C, 3), rtol=1e-13)
    Crep = discrete_curvature(np.vstack([P, P[:1]]), closed=True)
    assert Crep.shape == (13,)
    np.testing.assert_allclose(Crep[:-1], C, rtol=1e-13)
    assert Crep[-1] == Crep[0]


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), angle=st.floats(0, 2 * np.pi),
       scale=st.floats(0.01, 100.0), closed=st.booleans())
def test_similarity_invariance(seed, angle, scale, closed):
    rng = np.random.default_rng(seed)
    P = rng.uniform(-1, 1, size=(12, 2))
    C = discrete_curvature(P, closed=closed)
    R = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    P2 = scale * P @ R.T + rng.normal(size=2)
    np.testing.assert_allclose(discrete_curvature(P2, closed=closed), C / scale,
                               rtol=1e-7, atol=1e-9 * np.abs(C).max() / scale)
    # reflection flips the sign; reversing the order flips it too
    np.testing.assert_allclose(discrete_curvature(P * [1, -1], closed=closed), -C, rtol=1e-12,
                               atol=1e-12 * np.abs(C).max())
    np.testing.assert_allclose(discrete_curvature(P[::-1], closed=closed), -C[::-1], rtol=1e-12,
                               atol=1e-12 * np.abs(C).max())


def test_straight_line_is_zero_and_shapes():
    P = np.c_[np.linspace(0, 1, 7) ** 2, np.linspace(0, 1, 7) ** 2]
    C = discrete_curvature(P)
    assert C.shape == (7,) and np.all(np.abs(C) < 1e-12)


@pytest.mark.parametrize(
    "points, closed, match",
    [
        ([[0, 0], [1, 0], [1, 0], [2, 1]], False, "coincident"),
        ([[0, 0], [1, 0], [0, 0], [2, 1]], False, "index 1"),
        ([[0, 0], [1, np.nan], [2, 0]], False, "non-finite"),
        ([[0, 0, 0, 0], [1, 1, 1, 1]], False, "columns"),
        ([[0, 0], [1, 1]], True, "at least 3"),
        ([[0, 0], [1, 1], [0, 0]], True, "3 distinct"),
        ([0.0, 1.0], False, "2-D"),
    ],
)
def test_bad_input(points, closed, match):
    with pytest.raises(InputError, match=match):
        discrete_curvature(points, closed=closed)
