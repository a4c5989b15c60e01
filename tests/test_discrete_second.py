"""Second discrete curvature (Cheng & Yu, Definitions 1-2), Theorem 2, bad points.

Independent references:
* Theorem 2 / Corollary 1: the curve's curvature at the joints computed from ``curve(u, 1)``,
  ``curve(u, 2)`` (power form of the B-spline) and, separately, from central finite differences
  of curve positions only;
* Proposition 5 (differences expressed through first differences and chord lengths);
* a slow per-index loop written from the paper's text for the bad-point criteria.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from curvefair import (
    BSplineCurve,
    InputError,
    bad_points,
    interpolate_bspline,
    second_discrete_curvature,
)
from curvefair.analysis.discrete import bad_point_count, cheng_yu_figures, fairing_indicator


def random_open(rng, n=10, dim=2, uniform=False):
    P = rng.normal(size=(n, dim))
    if uniform:
        inner = np.arange(1.0, n - 3)
    else:
        inner = np.cumsum(rng.uniform(0.2, 2.0, n - 4))
    end = (inner[-1] if inner.size else 0.0) + (1.0 if uniform else rng.uniform(0.2, 2.0))
    knots = np.r_[[0.0] * 4, inner, [end] * 4]
    return BSplineCurve(P, knots, 3)


def random_closed(rng, n=9, dim=2, uniform=False):
    P = rng.normal(size=(n, dim))
    period = np.arange(n + 1.0) if uniform else np.r_[0.0, np.cumsum(rng.uniform(0.2, 2.0, n))]
    return BSplineCurve(P, period, 3, closed=True)


def joint_curvature(curve, u, side=0):
    """Signed (2-D) or unsigned (3-D) curvature from the derivatives (one-sided if ``side``)."""
    uu = np.clip(u + side * 1e-11 * max(1.0, abs(u)), *curve.domain)
    d1, d2 = curve(uu, 1), curve(uu, 2)
    if d1.shape[-1] == 2:
        cr = d1[..., 0] * d2[..., 1] - d1[..., 1] * d2[..., 0]
    else:
        cr = np.linalg.norm(np.cross(d1, d2), axis=-1)
    return cr / np.linalg.norm(d1, axis=-1) ** 3


def fd_curvature(curve, u, h):
    """Curvature from positions only (central differences, Richardson-extrapolated because the
    third derivative jumps at a knot, which makes the plain second difference first order), 2-D."""

    def diffs(h):
        a, b, c = curve(u - h), curve(u), curve(u + h)
        return (c - a) / (2 * h), (c - 2 * b + a) / (h * h)

    d1h, d2h = diffs(h)
    d12, d22 = diffs(2 * h)
    d1 = (4 * d1h - d12) / 3
    d2 = 2 * d2h - d22
    return (d1[..., 0] * d2[..., 1] - d1[..., 1] * d2[..., 0]) / np.linalg.norm(d1, axis=-1) ** 3


def theorem2_factor(u, i):
    return 3 * (u[i + 3] - u[i]) * (u[i + 4] - u[i + 1]) / (4 * (u[i + 3] - u[i + 1]) ** 2)


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("dim", [2, 3])
def test_theorem2_open_nonuniform(seed, dim):
    rng = np.random.default_rng(seed)
    c = random_open(rng, n=11, dim=dim)
    s = second_discrete_curvature(c)
    u = np.asarray(c.knots)
    n = c.n_ctrl
    for i in range(1, n - 1):  # joints u_3 .. u_{n}: the whole domain including its ends
        k = joint_curvature(c, u[i + 2])
        assert s.params[i] == u[i + 2]
        np.testing.assert_allclose(s.K[i], theorem2_factor(u, i) * k, rtol=1e-9, atol=1e-12)
    assert s.K[0] == 0.0 and s.K[-1] == 0.0


@pytest.mark.parametrize("seed", range(4))
def test_theorem2_closed_nonuniform_and_finite_differences(seed):
    rng = np.random.default_rng(100 + seed)
    c = random_closed(rng, n=9)
    s = second_discrete_curvature(c)
    u = np.asarray(c.knots)
    n = c.n_ctrl
    for i in range(1, n + 1):  # control point i mod n <-> joint u_{i+2} of the periodic vector
        k = joint_curvature(c, u[i + 2])
        np.testing.assert_allclose(s.K[i % n], theorem2_factor(u, i) * k, rtol=1e-9)
        kfd = fd_curvature(c, u[i + 2], 1e-3)  # positions only; C2 at a simple knot
        np.testing.assert_allclose(s.K[i % n], theorem2_factor(u, i) * kfd, rtol=1e-5)


@pytest.mark.parametrize("closed", [False, True])
def test_corollary1_uniform_27_over_16(closed):
    rng = np.random.default_rng(7)
    c = random_closed(rng, 12, uniform=True) if closed else random_open(rng, 12, uniform=True)
    s = second_discrete_curvature(c)
    # open: u_i .. u_{i+4} equally spaced only away from the clamped ends
    idx = range(c.n_ctrl) if closed else range(3, c.n_ctrl - 3)
    for i in idx:
        k = joint_curvature(c, s.params[i])
        np.testing.assert_allclose(s.K[i], 27 * k / 16, rtol=1e-9)


def test_double_knot_sides():
    # at u_j = u_{j+1}: K_{j-2} is the left curvature, K_{j-1} the right one (docstring claim)
    rng = np.random.default_rng(3)
    knots = np.r_[0, 0, 0, 0, 1, 2, 2, 3.5, 4.2, 5, 5, 5, 5.0]
    c = BSplineCurve(rng.normal(size=(9, 2)), knots, 3)
    s = second_discrete_curvature(c)
    kl = joint_curvature(c, 2.0, -1)
    kr = joint_curvature(c, 2.0, +1)
    assert abs(kl - kr) > 1e-3 * abs(kl)
    np.testing.assert_allclose(s.K[3], theorem2_factor(knots, 3) * kl, rtol=1e-8)
    np.testing.assert_allclose(s.K[4], theorem2_factor(knots, 4) * kr, rtol=1e-8)


def test_circle_polygon_constant_and_no_bad_points():
    a = np.linspace(0, 2 * np.pi, 17)[:-1]
    c = BSplineCurve(3.0 * np.c_[np.cos(a), np.sin(a)], np.arange(17.0), 3, closed=True)
    s = second_discrete_curvature(c)
    np.testing.assert_allclose(s.K, s.K[0], rtol=1e-12)
    assert s.K[0] > 0
    assert np.max(np.abs(s.second_difference)) < 1e-12 * s.K[0]
    assert all(b.value < 1e-24 for b in bad_points(c))  # only round-off "extrema"


@pytest.mark.parametrize("closed", [False, True])
def test_differences_definition2_and_proposition5(closed):
    rng = np.random.default_rng(11)
    c = random_closed(rng, 10) if closed else random_open(rng, 10)
    s = second_discrete_curvature(c)
    Q = np.asarray(c.control_points)
    n = len(Q)
    K = s.K
    for i in range(n):
        if not closed and i in (0, n - 1):
            assert s.second_difference[i] == 0.0
            continue
        Li = np.linalg.norm(Q[i] - Q[(i - 1) % n])
        Li1 = np.linalg.norm(Q[(i + 1) % n] - Q[i])
        dKi = K[i] - K[(i - 1) % n]
        dKi1 = K[(i + 1) % n] - K[i]
        # Proposition 5: D_i = L_i L_{i+1} / (L_i + L_{i+1}) (dK_{i+1}/L_{i+1} - dK_i/L_i)
        prop5 = Li * Li1 / (Li + Li1) * (dKi1 / Li1 - dKi / Li)
        np.testing.assert_allclose(s.second_difference[i], prop5, rtol=1e-10,
                                   atol=1e-12 * np.abs(K).max())
        np.testing.assert_allclose(s.first_difference[i], dKi, rtol=1e-14)
    if not closed:
        assert s.first_difference[0] == 0.0
        assert s.valid.tolist() == [False, False] + [True] * (n - 4) + [False, False]
    else:
        assert s.valid.all()
    np.testing.assert_allclose(s.indicator, np.sum(s.second_difference[s.valid] ** 2), rtol=1e-14)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), angle=st.floats(0, 2 * np.pi),
       scale=st.floats(0.05, 20.0), closed=st.booleans())
def test_similarity_invariance(seed, angle, scale, closed):
    rng = np.random.default_rng(seed)
    c = random_closed(rng, 8) if closed else random_open(rng, 9)
    s = second_discrete_curvature(c)
    R = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    moved = c.replace(control_points=scale * np.asarray(c.control_points) @ R.T + [3.0, -1.0])
    s2 = second_discrete_curvature(moved)
    tol = 1e-9 * np.abs(s.K).max() / scale
    np.testing.assert_allclose(s2.K, s.K / scale, rtol=1e-8, atol=tol)
    mirrored = second_discrete_curvature(c.replace(control_points=np.asarray(c.control_points)
                                                   * [1, -1]))
    np.testing.assert_allclose(mirrored.K, -s.K, rtol=1e-12, atol=1e-14 * np.abs(s.K).max())
    # the bad points do not depend on the orientation or the scale
    b1 = [(b.index, b.kinds) for b in bad_points(c)]
    b2 = [(b.index, b.kinds) for b in bad_points(c.replace(
        control_points=np.asarray(c.control_points) * [-scale, scale]))]
    assert sorted(b1) == sorted(b2)


def test_reversal_flips_sign():
    rng = np.random.default_rng(9)
    c = random_open(rng, 10)
    u = np.asarray(c.knots)
    rev = BSplineCurve(np.asarray(c.control_points)[::-1], (u[-1] - u)[::-1], 3)
    np.testing.assert_allclose(second_discrete_curvature(rev).K,
                               -second_discrete_curvature(c).K[::-1], rtol=1e-12, atol=1e-15)


# ------------------------------------------------------------------------------------------
# bad points
# ------------------------------------------------------------------------------------------
def slow_bad_points(K, t, closed):
    """Section 'Smoothing criterion', one index at a time (orientation-free kind 3)."""
    n = len(K)
    found = []
    idx = range(n) if closed else range(2, n - 2)
    for i in idx:
        km, k0, kp = K[(i - 1) % n], K[i], K[(i + 1) % n]
        kinds = []
        if k0 * kp <= 0 and km * k0 > 0:
            kinds.append(1)
        if (k0 - km) * (kp - k0) < 0:
            kinds.append(2)
        if (min(km, k0, kp) > 0 or max(km, k0, kp) < 0) and not (
                abs(k0) > ((1 - t[i]) * abs(km) + t[i] * abs(kp)) / 2):
            kinds.append(3)
        if kinds:
            D = t[i] * km + (1 - t[i]) * kp - k0
            found.append((i, tuple(kinds), D * D))
    found.sort(key=lambda f: (-f[2], f[0]))
    return found


@pytest.mark.parametrize("seed", range(8))
@pytest.mark.parametrize("closed", [False, True])
def test_bad_points_against_slow_reference(seed, closed):
    rng = np.random.default_rng(seed)
    c = random_closed(rng, 14) if closed else random_open(rng, 14)
    s = second_discrete_curvature(c)
    Q = np.asarray(c.control_points)
    n = len(Q)
    t = np.full(n, 0.5)
    for i in range(n) if closed else range(1, n - 1):
        Li = np.linalg.norm(Q[i] - Q[(i - 1) % n])
        Li1 = np.linalg.norm(Q[(i + 1) % n] - Q[i])
        t[i] = Li1 / (Li + Li1)
    np.testing.assert_allclose(s.weights, t, rtol=1e-14)
    ref = slow_bad_points(s.K, t, closed)
    got = bad_points(c)
    assert [(b.index, b.kinds) for b in got] == [(r[0], r[1]) for r in ref]
    np.testing.assert_allclose([b.value for b in got], [r[2] for r in ref], rtol=1e-12)
    assert all(b.kind == b.kinds[0] for b in got)
    assert all(got[j].value >= got[j + 1].value for j in range(len(got) - 1))
    assert bad_point_count(c) == len(ref)


def test_bad_point_kinds_on_constructed_curves():
    x = np.linspace(0, 2 * np.pi, 25)
    # kind 1: an S curve changes curvature sign once inside (x = pi); the natural end
    # conditions make the end curvatures 0, which counts as a sign change next to the ends
    s_curve = interpolate_bspline(np.c_[x, np.sin(x)])
    n = s_curve.n_ctrl
    ones = [b.index for b in bad_points(s_curve) if 1 in b.kinds]
    K = second_discrete_curvature(s_curve).K
    inner = [i for i in ones if 3 <= i <= n - 5]
    assert len(inner) == 1 and K[inner[0]] * K[inner[0] + 1] <= 0
    assert abs(s_curve(second_discrete_curvature(s_curve).params[inner[0]])[0] - np.pi) < 0.3
    assert set(ones) - set(inner) <= {2, n - 4, n - 3}
    # kind 2: a bump on a circle is a curvature extreme and the worst point
    a = np.linspace(0, 2 * np.pi, 21)[:-1]
    P = np.c_[np.cos(a), np.sin(a)]
    P[6] *= 1.15
    bumped = BSplineCurve(P, np.arange(21.0), 3, closed=True)
    top = bad_points(bumped)[0]
    assert top.index == 6 and 2 in top.kinds
    # kind 3: flattening a circle locally (curvature dip below half its neighbours)
    P = np.c_[np.cos(a), np.sin(a)]
    P[6] = 0.5 * (P[5] + P[7]) * 1.01  # nearly on the chord: K_6 ~ K_5 / 7
    dipped = BSplineCurve(P, np.arange(21.0), 3, closed=True)
    kinds = {b.index: b.kinds for b in bad_points(dipped)}
    assert 3 in kinds[6]


def test_bad_input():
    c = interpolate_bspline(np.c_[np.arange(6.0), np.arange(6.0) ** 2], degree=2)
    with pytest.raises(InputError, match="cubic"):
        second_discrete_curvature(c)
    with pytest.raises(InputError, match="BSplineCurve"):
        bad_points(np.zeros((5, 2)))
    # a triple knot with a true corner: the value does not exist
    knots = np.r_[0, 0, 0, 0, 1, 1, 1, 2, 2, 2, 2.0]
    P = np.array([[0, 0], [1, 0], [2, 0], [3, 0], [3, 1], [3, 2], [3, 3.0]])
    with pytest.raises(InputError, match="multiplicity 3"):
        second_discrete_curvature(BSplineCurve(P, knots, 3))
    with pytest.raises(InputError, match="control point 3 does not exist"):
        bad_point_count(BSplineCurve(P, knots, 3))
    with pytest.raises(InputError, match="control point 3 does not exist"):
        fairing_indicator(BSplineCurve(P, knots, 3))
    with pytest.raises(InputError, match="control point 3 does not exist"):
        cheng_yu_figures(BSplineCurve(P, knots, 3))


@pytest.mark.parametrize("block", [1, 2, 3, 7, 65_536])
def test_counts_and_indicator_in_blocks_are_the_whole_curves(monkeypatch, block):
    # an open curve is counted block by block (each point's kinds depend on control points
    # i-2 .. i+2 only): every block size gives the length of bad_points(), whose list is
    # checked against the slow one-index-at-a-time reference above
    from curvefair.analysis import discrete

    monkeypatch.setattr(discrete, "COUNT_BLOCK", block)
    rng = np.random.default_rng(block)
    curves = [random_open(rng, n, dim) for n in (4, 5, 6, 9, 17, 40) for dim in (2, 3)]
    x = np.linspace(0, 60, 3000)
    noisy = np.c_[x, np.sin(x)] + 0.01 * rng.normal(size=(3000, 2))
    curves += [interpolate_bspline(noisy), random_closed(rng, 30), random_closed(rng, 7, 3)]
    for c in curves:
        assert bad_point_count(c) == len(bad_points(c))
        # the indicator summed from blocks: the same bits as from the whole arrays
        assert fairing_indicator(c) == second_discrete_curvature(c).indicator
        # both in one pass (what the cheng-yu method reports)
        assert cheng_yu_figures(c) == (second_discrete_curvature(c).indicator,
                                       len(bad_points(c)))
    assert bad_point_count(curves[-3]) > 500
