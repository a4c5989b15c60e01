"""One Cheng-Yu step (eqs. (8)-(9), ERRATA plus sign; Theorem 3 factor from the original points).

The reference for every target position is an independent minimisation of the strain energy
E_2 = int |r''(u)|^2 du: the energy is computed by Gauss quadrature of ``curve(u, 2)`` on every
knot span (not from the Gram matrix the implementation uses), and minimised over the moved
control point(s) either by scipy.optimize or exactly from its quadratic form (central
differences of a quadratic are exact).
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import minimize

from curvefair import BSplineCurve, InputError, steps
from curvefair.fairing.cheng_yu import cheng_yu

XG, WG = np.polynomial.legendre.leggauss(4)


def energy2(curve):
    br = np.unique(np.asarray(curve.knots))
    a0, a1 = curve.domain
    br = br[(br >= a0) & (br <= a1)]
    tot = 0.0
    for a, b in zip(br[:-1], br[1:], strict=True):
        u = 0.5 * (a + b) + 0.5 * (b - a) * XG
        v = curve(u, 2)
        tot += 0.5 * (b - a) * np.sum(WG * np.sum(v * v, axis=1))
    return tot


def energy_of(curve, idx, x):
    Q = np.array(curve.control_points)
    Q[idx] = np.reshape(x, (len(idx), -1))
    return energy2(curve.replace(control_points=Q))


def quad_fit(f, x0):
    """Gradient and Hessian of the quadratic ``f`` at ``x0`` by central differences (exact)."""
    k = x0.size
    g = np.zeros(k)
    H = np.zeros((k, k))
    E = np.eye(k)
    f0 = f(x0)
    for i in range(k):
        g[i] = (f(x0 + E[i]) - f(x0 - E[i])) / 2
        H[i, i] = f(x0 + E[i]) - 2 * f0 + f(x0 - E[i])
        for j in range(i):
            H[i, j] = H[j, i] = (f(x0 + E[i] + E[j]) - f(x0 + E[i] - E[j])
                                 - f(x0 - E[i] + E[j]) + f(x0 - E[i] - E[j])) / 4
    return g, H


def exact_minimiser(curve, idx):
    Q = np.asarray(curve.control_points)
    x0 = Q[idx].reshape(-1).astype(float)
    g, H = quad_fit(lambda x: energy_of(curve, idx, x), x0)
    return (x0 - np.linalg.solve(H, g)).reshape(len(idx), -1), H


def random_open(rng, n=11, dim=2):
    inner = np.cumsum(rng.uniform(0.3, 2.0, n - 4))
    knots = np.r_[[0.0] * 4, inner, [inner[-1] + rng.uniform(0.3, 2.0)] * 4]
    return BSplineCurve(rng.normal(size=(n, dim)), knots, 3)


def random_closed(rng, n=10, dim=2):
    period = np.r_[0.0, np.cumsum(rng.uniform(0.3, 2.0, n))]
    return BSplineCurve(rng.normal(size=(n, dim)), period, 3, closed=True)


def test_exported_in_steps():
    assert steps.cheng_yu is cheng_yu


def test_d0_matches_scipy_minimisation():
    rng = np.random.default_rng(0)
    c = random_open(rng)
    m = 5
    res = minimize(lambda x: energy_of(c, [m], x), np.asarray(c.control_points)[m],
                   method="BFGS", options={"gtol": 1e-12})
    np.testing.assert_allclose(cheng_yu(c, m).control_points[m], res.x, atol=1e-6)


@pytest.mark.parametrize("seed", range(3))
@pytest.mark.parametrize("kind", ["open2", "open3", "closed2", "closed3"])
def test_d0_single_is_exact_e2_minimiser(seed, kind):
    # with d = 0, eq. (8) is the Eck-Hadenfeld l = 2 step: the minimiser of E_2 over Q_m
    rng = np.random.default_rng(seed)
    dim = int(kind[-1])
    c = random_closed(rng, 9, dim) if kind.startswith("closed") else random_open(rng, 10, dim)
    for m in range(c.n_ctrl):
        target, _ = exact_minimiser(c, [m])
        new = cheng_yu(c, m, d=0.0)
        np.testing.assert_allclose(new.control_points[m], target[0], rtol=1e-8, atol=1e-8)
        # e=None is the same full step
        np.testing.assert_array_equal(cheng_yu(c, m).control_points, new.control_points)
        others = np.arange(c.n_ctrl) != m
        np.testing.assert_array_equal(new.control_points[others], c.control_points[others])


@pytest.mark.parametrize("closed", [False, True])
def test_d0_pair_is_joint_minimiser(closed):
    rng = np.random.default_rng(4)
    c = random_closed(rng, 9) if closed else random_open(rng, 10)
    last = c.n_ctrl if closed else c.n_ctrl - 1
    for m in range(last):
        m1 = (m + 1) % c.n_ctrl
        target, _ = exact_minimiser(c, [m, m1])
        new = cheng_yu(c, m, pair=True)
        np.testing.assert_allclose(new.control_points[[m, m1]], target, rtol=1e-8, atol=1e-8)
        assert energy2(new) <= energy2(cheng_yu(c, m)) + 1e-10


def test_uniform_weights_from_errata():
    # uniform cubic, l = 2: Q* = (-Q_{m-3} + 9 Q_{m-1} + 9 Q_{m+1} - Q_{m+3}) / 16
    rng = np.random.default_rng(5)
    Q = rng.normal(size=(12, 2))
    c = BSplineCurve(Q, np.arange(13.0), 3, closed=True)
    for m in range(12):
        want = (-Q[(m - 3) % 12] + 9 * Q[(m - 1) % 12] + 9 * Q[(m + 1) % 12]
                - Q[(m + 3) % 12]) / 16
        np.testing.assert_allclose(cheng_yu(c, m).control_points[m], want, atol=1e-13)


@pytest.mark.parametrize("d", [0.0, 0.3, 0.75, 1.0])
def test_factor_is_a_penalised_minimiser(d):
    # Q~_m = d Q_m + (1 - d) Q*_m minimises (1 - d) E_2(x) + d G_mm |x - Q_m|^2,
    # with G_mm read off the quadrature energy's Hessian (H = 2 G_mm I)
    rng = np.random.default_rng(6)
    c = random_open(rng, 10)
    m = 4
    Qm = np.asarray(c.control_points)[m]
    g, H = quad_fit(lambda x: energy_of(c, [m], x), Qm.copy())
    gmm = H[0, 0] / 2
    # gradient of the penalised objective at x: (1-d)(g + H (x - Qm)) + 2 d gmm (x - Qm) = 0
    x = Qm - np.linalg.solve((1 - d) * H + 2 * d * gmm * np.eye(2), (1 - d) * g)
    np.testing.assert_allclose(cheng_yu(c, m, d=d).control_points[m], x, atol=1e-9)


def test_theorem3_factor_when_original_is_current():
    rng = np.random.default_rng(7)
    c = random_open(rng, 10)
    Q = np.asarray(c.control_points)
    for m in range(c.n_ctrl):
        target, _ = exact_minimiser(c, [m])
        dist = np.linalg.norm(Q[m] - target[0])
        for e in (0.25 * dist, 0.9 * dist, 2.0 * dist):
            new, d = cheng_yu(c, m, e=e, return_factor=True)
            d_paper = max(0.0, 1.0 - e / dist)  # Theorem 3
            assert abs(d - d_paper) < 1e-9
            moved = np.linalg.norm(new.control_points[m] - Q[m])
            assert moved <= e
            if d_paper > 0:
                assert moved > e * (1 - 1e-9)  # the bound is used fully


@pytest.mark.parametrize("closed", [False, True])
def test_pair_factor_keeps_bound_and_is_smallest(closed):
    rng = np.random.default_rng(8)
    c = random_closed(rng, 9) if closed else random_open(rng, 10)
    Q = np.asarray(c.control_points)
    n = c.n_ctrl
    for m in range(n if closed else n - 1):
        idx = [m, (m + 1) % n]
        full = cheng_yu(c, m, pair=True)
        reach = np.linalg.norm(full.control_points[idx] - Q[idx], axis=1).max()
        e = 0.4 * reach
        new, d = cheng_yu(c, m, e=e, pair=True, return_factor=True)
        dist = np.linalg.norm(new.control_points[idx] - Q[idx], axis=1)
        assert dist.max() <= e
        assert 0 < d < 1
        # a slightly smaller factor (a larger move) breaks the bound
        worse = cheng_yu(c, m, d=max(d - 1e-6, 0.0), pair=True)
        assert np.linalg.norm(worse.control_points[idx] - Q[idx], axis=1).max() > e


@pytest.mark.parametrize("d", [0.0, 0.4, 0.9])
def test_pair_is_the_fixed_point_of_eq9(d):
    # eq. (9): Q~_j = d Q_j + (1 - d) * (E_2 minimiser over Q_j with the partner at Q~_partner)
    rng = np.random.default_rng(9)
    c = random_open(rng, 10, dim=3)
    m = 4
    new = cheng_yu(c, m, d=d, pair=True)
    Q = np.asarray(c.control_points)
    for j, partner in ((m, m + 1), (m + 1, m)):
        Qp = Q.copy()
        Qp[partner] = new.control_points[partner]
        target, _ = exact_minimiser(c.replace(control_points=Qp), [j])
        np.testing.assert_allclose(new.control_points[j], d * Q[j] + (1 - d) * target[0],
                                   atol=1e-8)


@pytest.mark.parametrize("pair", [False, True])
def test_bound_from_original_holds_after_many_steps(pair):
    rng = np.random.default_rng(10)
    c0 = random_open(rng, 12)
    e = 0.05
    c = c0
    order = rng.integers(0, c0.n_ctrl - 1, 60)
    for m in order:
        c = cheng_yu(c, int(m), e=e, pair=pair, original=c0)
    disp = np.linalg.norm(np.asarray(c.control_points) - c0.control_points, axis=1)
    assert disp.max() <= e
    assert disp.max() > 0.5 * e  # it did move
    u = np.linspace(*c0.domain, 20001)
    assert np.linalg.norm(c(u) - c0(u), axis=1).max() <= e
    # without the original, the per-step bound lets the points drift beyond e
    c = c0
    for m in order:
        c = cheng_yu(c, int(m), e=e, pair=pair)
    drift = np.linalg.norm(np.asarray(c.control_points) - c0.control_points, axis=1)
    assert drift.max() > e


def test_input_not_modified_and_result_readonly():
    rng = np.random.default_rng(11)
    c = random_open(rng, 9)
    before = np.array(c.control_points)
    new = cheng_yu(c, 3, e=0.1, pair=True)
    np.testing.assert_array_equal(c.control_points, before)
    assert not new.control_points.flags.writeable
    np.testing.assert_array_equal(new.knots, c.knots)


def test_bad_input():
    rng = np.random.default_rng(12)
    c = random_open(rng, 8)
    with pytest.raises(InputError, match="out of range"):
        cheng_yu(c, 8)
    with pytest.raises(InputError, match="past the last"):
        cheng_yu(c, 7, pair=True)
    with pytest.raises(InputError, match="integer"):
        cheng_yu(c, 2.0)
    with pytest.raises(InputError, match="e must be"):
        cheng_yu(c, 2, e=0.0)
    with pytest.raises(InputError, match="d must be"):
        cheng_yu(c, 2, d=1.5)
    with pytest.raises(InputError, match="not both"):
        cheng_yu(c, 2, e=0.1, d=0.5)
    with pytest.raises(InputError, match="shape"):
        cheng_yu(c, 2, e=0.1, original=np.zeros((3, 2)))
    far = np.array(c.control_points)
    far[2] += 1.0
    with pytest.raises(InputError, match="already"):
        cheng_yu(c, 2, e=0.1, original=far)
    with pytest.raises(InputError, match="cubic"):
        cheng_yu(BSplineCurve(rng.normal(size=(6, 2)), np.r_[0, 0, 0, 1, 2, 3, 4, 4, 4.0], 2), 2)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**31), closed=st.booleans(), pair=st.booleans(),
       e=st.one_of(st.none(), st.floats(1e-3, 1.0)), dim=st.sampled_from([2, 3]))
def test_property_energy_never_rises_and_bound_holds(seed, closed, pair, e, dim):
    # eq. (8)/(9) minimise (1 - d) E_2 + d sum_j G_jj |x_j - Q_j|^2, so E_2 cannot rise
    rng = np.random.default_rng(seed)
    c = random_closed(rng, 8, dim) if closed else random_open(rng, 9, dim)
    m = int(rng.integers(0, c.n_ctrl if closed else c.n_ctrl - 1))
    new = cheng_yu(c, m, e=e, pair=pair)
    assert energy2(new) <= energy2(c) * (1 + 1e-12) + 1e-12
    if e is not None:
        disp = np.linalg.norm(np.asarray(new.control_points) - c.control_points, axis=1)
        assert disp.max() <= e
        u = np.linspace(*c.domain, 2001)
        assert np.linalg.norm(new(u) - c(u), axis=1).max() <= e
