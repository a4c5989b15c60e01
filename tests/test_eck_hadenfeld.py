"""Eck & Hadenfeld: weights, exact minimiser, ranking numbers, the compiled ranking-list loop.

Independent references: energies by dense Gauss quadrature of scipy's BSpline derivatives
(never the Gram matrix under test), scipy.optimize minimisation, a slow pure-Python ranking
loop recomputing everything from scratch, a direct sparse solve of the normal equations.
Published numbers: seed 003 / ERRATA uniform weights.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize

from curvefair import BSplineCurve, InputError, interpolate_bspline, steps
from curvefair._kernels.eck_hadenfeld import eh_loop_reference
from curvefair.fairing.eck_hadenfeld import (
    eck_hadenfeld,
    eck_hadenfeld_fair,
    eh_weights,
    movable_mask,
    ranking_numbers,
)


def quad_energy(curve: BSplineCurve, l: int, nq: int = 10) -> float:  # noqa: E741
    """int |r^(l)|^2 dt by Gauss-Legendre on every knot span, evaluated with scipy."""
    spl = curve.to_scipy()
    t = np.unique(curve.knots[curve.degree:len(curve.knots) - curve.degree])
    xg, wg = np.polynomial.legendre.leggauss(nq)
    a, b = t[:-1, None], t[1:, None]
    x = ((a + b) / 2 + (b - a) / 2 * xg).ravel()
    w = ((b - a) / 2 * wg).ravel()
    return float(np.sum(w * np.sum(spl(x, l) ** 2, axis=1)))


def random_curve(rng, n=12, p=3, dim=2, closed=False, uniform=False):
    if closed:
        gaps = np.ones(n) if uniform else rng.uniform(0.4, 1.6, n)
        return BSplineCurve(rng.normal(size=(n, dim)), np.r_[0.0, np.cumsum(gaps)], p, closed=True)
    inner = np.arange(1.0, n - p) if uniform else np.cumsum(rng.uniform(0.4, 1.6, n - p - 1))
    end = (n - p) if uniform else inner[-1] + rng.uniform(0.4, 1.6)
    t = np.r_[[0.0] * (p + 1), inner, [end] * (p + 1)]
    return BSplineCurve(rng.normal(size=(n, dim)), t, p)


# -- weights -------------------------------------------------------------------------------
@pytest.mark.parametrize("closed", [False, True])
def test_uniform_cubic_weights_match_published(closed):
    # Eck & Hadenfeld / ERRATA: l=2: (-1, 0, 9, *, 9, 0, -1)/16; l=3: (1, -6, 15, *, 15, -6, 1)/20
    c = random_curve(np.random.default_rng(0), n=15, closed=closed, uniform=True)
    r = 7
    for l, ref in [(2, np.array([-1, 0, 9, 9, 0, -1]) / 16),  # noqa: E741
                   (3, np.array([1, -6, 15, 15, -6, 1]) / 20)]:
        idx, g = eh_weights(c, r, l)
        assert idx.tolist() == [4, 5, 6, 8, 9, 10]
        np.testing.assert_allclose(g, ref, atol=1e-13)


@pytest.mark.parametrize("p,l", [(2, 2), (3, 2), (3, 3), (4, 2), (4, 3), (5, 3)])
@pytest.mark.parametrize("closed", [False, True])
def test_gammas_sum_to_one(p, l, closed):  # noqa: E741
    rng = np.random.default_rng(10 * p + l + closed)
    c = random_curve(rng, n=13, p=p, closed=closed)
    for r in range(c.n_ctrl):
        idx, g = eh_weights(c, r, l)
        assert abs(g.sum() - 1.0) < 1e-10, (r, g.sum())
        assert r not in idx.tolist()


# -- one step ------------------------------------------------------------------------------
@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("p,l", [(3, 2), (3, 3), (4, 2), (5, 3)])
def test_step_is_exact_minimiser(closed, p, l):  # noqa: E741
    rng = np.random.default_rng(p * 7 + l + 3 * closed)
    c = random_curve(rng, n=11, p=p, closed=closed)
    for r in [0, 4, c.n_ctrl - 1]:
        new = steps.eck_hadenfeld(c, r, l=l)
        changed = np.flatnonzero(np.any(new.control_points != c.control_points, axis=1))
        assert set(changed.tolist()) <= {r}

        e0 = quad_energy(c, l)

        def f(x, r=r, e0=e0):
            d = np.array(c.control_points)
            d[r] = x
            return quad_energy(c.replace(control_points=d), l) / e0

        opt = minimize(f, c.control_points[r], method="BFGS", options={"gtol": 1e-12})
        e_new = quad_energy(new, l) / e0
        assert e_new <= opt.fun * (1 + 1e-9) + 1e-14
        # f is an exact quadratic: central differences with a unit step give its gradient and
        # Hessian exactly (up to rounding); one Newton step is the minimiser
        x0 = np.array(c.control_points[r])
        dim = x0.size
        E = np.eye(dim)
        grad = np.array([(f(x0 + E[k]) - f(x0 - E[k])) / 2 for k in range(dim)])
        H = np.array([[(f(x0 + E[a] + E[b]) - f(x0 + E[a] - E[b]) - f(x0 - E[a] + E[b])
                        + f(x0 - E[a] - E[b])) / 4 for b in range(dim)] for a in range(dim)])
        x_star = x0 - np.linalg.solve(H, grad)
        np.testing.assert_allclose(new.control_points[r], x_star, rtol=1e-8, atol=1e-8)


def test_step_affine_combination_of_neighbours():
    c = random_curve(np.random.default_rng(1), n=10, p=3)
    new = eck_hadenfeld(c, 5, 3)
    idx, g = eh_weights(c, 5, 3)
    np.testing.assert_allclose(new.control_points[5], g @ c.control_points[idx], atol=1e-12)


@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("l", [2, 3])
def test_ranking_number_is_exact_energy_drop(closed, l):  # noqa: E741
    rng = np.random.default_rng(20 + l + closed)
    c = random_curve(rng, n=12, p=4, dim=3, closed=closed)
    z = ranking_numbers(c, l)
    e0 = quad_energy(c, l)
    for r in range(c.n_ctrl):
        drop = e0 - quad_energy(steps.eck_hadenfeld(c, r, l), l)
        assert abs(z[r] - drop) <= 1e-9 * e0, (r, z[r], drop)
        # and z_r = G_rr |d_r - d~_r|^2
        G_rr = c.gram_band(l)[r, c.degree]
        dr = c.control_points[r] - steps.eck_hadenfeld(c, r, l).control_points[r]
        assert abs(z[r] - G_rr * dr @ dr) <= 1e-12 * max(z.max(), 1.0)


def test_step_errors():
    c = random_curve(np.random.default_rng(0), n=8, p=3)
    with pytest.raises(InputError, match="r = 8 is out of range"):
        eck_hadenfeld(c, 8)
    with pytest.raises(InputError, match="l must be 2 or 3"):
        eck_hadenfeld(c, 2, l=4)
    with pytest.raises(InputError, match="degree >= 3"):
        eck_hadenfeld(random_curve(np.random.default_rng(0), n=8, p=2), 2, l=3)
    with pytest.raises(InputError, match="BSplineCurve"):
        eck_hadenfeld(np.zeros((4, 2)), 1)


# -- the ranking-list loop -----------------------------------------------------------------
@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("tol", [None, 0.05])
def test_loop_matches_slow_reference(closed, tol):
    rng = np.random.default_rng(5 + closed)
    c = random_curve(rng, n=40, p=3, closed=closed)
    mask = movable_mask(c, ("g1", "g0"), protect=[10])
    # eps: stop before the ranking numbers reach rounding noise (~1e-15 E, where the
    # incremental and the from-scratch residuals may order near-ties differently)
    d_ref, idx_ref = eh_loop_reference(c, 2, tol, 400, mask, 1e-12)
    res = eck_hadenfeld_fair(c, l=2, tol=tol, eps=1e-12, max_steps=400, clamp=("g1", "g0"),
                             protect=[10])
    assert len(idx_ref) > 20
    assert res.history[:, 0].astype(int).tolist() == idx_ref
    np.testing.assert_allclose(res.curve.control_points, d_ref, atol=1e-10)


def test_loop_energy_bookkeeping_and_monotone():
    c = random_curve(np.random.default_rng(9), n=30, p=3)
    res = eck_hadenfeld_fair(c, l=2, tol=0.1, eps=0.0, max_steps=500, clamp="g2")
    assert np.all(res.history[:, 1] >= 0)
    assert abs((res.energy_before - res.energy_after) - res.history[:, 1].sum()) \
        <= 1e-9 * res.energy_before
    assert abs(res.energy_after - quad_energy(res.curve, 2)) <= 1e-9 * res.energy_before
    # z of consecutive steps need not decrease, but the energy after each is below before
    assert res.energy_after < res.energy_before


def test_tolerance_and_clamps():
    rng = np.random.default_rng(3)
    x = np.linspace(0, 10, 60)
    c = interpolate_bspline(np.c_[x, np.sin(x) + 0.05 * rng.normal(size=60)])
    tol = 0.02
    res = eck_hadenfeld_fair(c, tol=tol, clamp=("g2", "g1"), eps=0.0, max_steps=20000)
    moved = np.linalg.norm(res.curve.control_points - c.control_points, axis=1)
    assert moved.max() <= tol * (1 + 1e-12)
    u = np.linspace(*c.domain, 5001)
    assert np.linalg.norm(res.curve(u) - c(u), axis=1).max() <= tol * (1 + 1e-12)
    t0, t1 = c.domain
    for t, nmax in ((t0, 3), (t1, 2)):
        for nu in range(nmax):
            ref = c(t, nu)
            assert np.abs(res.curve(t, nu) - ref).max() <= 1e-12 * max(1, np.abs(ref).max())
    assert moved[:3].max() == 0 and moved[-2:].max() == 0 and moved[-3] > 0


def test_unconstrained_converges_to_global_solution():
    # Gauss-Seidel on G: with the clamped ends held, the limit solves G_ff d_f = -G_fc d_c
    rng = np.random.default_rng(4)
    c = random_curve(rng, n=10, p=3)
    res = eck_hadenfeld_fair(c, l=3, eps=1e-26, max_steps=2_000_000, clamp="g2")
    G = c.gram_matrix(3).toarray()
    free = movable_mask(c, "g2")
    d = np.array(c.control_points)
    d[free] = np.linalg.solve(G[np.ix_(free, free)], -G[np.ix_(free, ~free)] @ d[~free])
    np.testing.assert_allclose(res.curve.control_points, d, atol=1e-6)
    assert res.stop_reason in ("eps", "converged")


def test_deterministic():
    c = random_curve(np.random.default_rng(12), n=50, p=3, closed=True)
    a = eck_hadenfeld_fair(c, tol=0.05, eps=1e-12)
    b = eck_hadenfeld_fair(c, tol=0.05, eps=1e-12)
    np.testing.assert_array_equal(a.curve.control_points, b.curve.control_points)
    np.testing.assert_array_equal(a.history, b.history)


def test_protect_everything_and_stop_reasons():
    c = random_curve(np.random.default_rng(2), n=8, p=3)
    res = eck_hadenfeld_fair(c, protect=range(8))
    assert res.stop_reason == "no_movable_point" and res.steps == 0
    res = eck_hadenfeld_fair(c, tol=1e-6, eps=0.0, max_steps=10_000)
    assert res.stop_reason == "tolerance"
    res = eck_hadenfeld_fair(c, eps=0.5, max_steps=10_000)
    assert res.stop_reason == "eps"
    res = eck_hadenfeld_fair(c, eps=0.0, max_steps=7)
    assert res.stop_reason == "max_steps" and res.steps == 7


@pytest.mark.parametrize("n", [4, 5, 6, 7])
def test_small_closed_curves_wrap_onto_themselves(n):
    # n < 2p + 1: a control point's band wraps onto itself; steps, ranking numbers and the
    # loop must still be exact (dense quadrature reference)
    rng = np.random.default_rng(n)
    c = BSplineCurve(rng.normal(size=(n, 2)), np.r_[0, np.cumsum(rng.uniform(0.5, 1.5, n))], 3,
                     closed=True)
    e0 = quad_energy(c, 2)
    z = ranking_numbers(c, 2)
    for r in range(n):
        assert abs(e0 - quad_energy(steps.eck_hadenfeld(c, r, 2), 2) - z[r]) <= 1e-12 * e0
    res = eck_hadenfeld_fair(c, tol=0.1, eps=0.0, max_steps=500)
    assert abs(res.energy_after - quad_energy(res.curve, 2)) <= 1e-12 * e0
    assert np.linalg.norm(res.curve.control_points - c.control_points, axis=1).max() <= 0.1 + 1e-15


def test_large_curve_ranking_order():
    # 70000 control points: above the size where the loop prefetches the runner-up; the point
    # faired at step k must be the argmax of the ranking numbers recomputed from scratch
    # (vectorised, from the Gram band) on the curve after k - 1 steps
    rng = np.random.default_rng(21)
    n = 70_000
    d = np.c_[np.arange(n, dtype=float), rng.normal(size=n)]
    t = np.r_[[0.0] * 3, np.arange(n - 2.0), [n - 3.0] * 3]
    c = BSplineCurve(d, t, 3)
    mask = movable_mask(c, "g2")
    full = eck_hadenfeld_fair(c, eps=0.0, max_steps=3000, clamp="g2")
    for k in (1, 40, 700, 3000):
        before = eck_hadenfeld_fair(c, eps=0.0, max_steps=k - 1, clamp="g2").curve
        z = np.where(mask, ranking_numbers(before, 2), -1.0)
        assert int(full.history[k - 1, 0]) == int(np.argmax(z))
        assert abs(full.history[k - 1, 1] - z.max()) <= 1e-9 * z.max()
    assert abs(full.energy_before - full.energy_after - full.history[:, 1].sum()) \
        <= 1e-9 * full.energy_before


def mixed_knot_curve(rng, n, closed):
    """Uniform runs (two spacings) with irregular spans between them and at the ends."""
    m = n if closed else n - 3
    h = np.ones(m)
    h[m // 3:m // 3 + 4] = rng.uniform(0.5, 1.5, 4)
    h[2 * m // 3:] = 0.5
    h[-3:] = rng.uniform(0.5, 1.5, 3)
    br = np.r_[0.0, np.cumsum(h)]
    d = rng.normal(size=(n, 2))
    if closed:
        return BSplineCurve(d, br, 3, closed=True)
    return BSplineCurve(d, np.r_[[0.0] * 3, br, [br[-1]] * 3], 3)


@pytest.mark.parametrize("closed", [False, True])
def test_band_patterns_vs_brute_force(closed):
    from curvefair.fairing.eck_hadenfeld import band_patterns

    c = mixed_knot_curve(np.random.default_rng(31), 60, closed)
    W = c.gram_band(2)
    Wu, pat, upat, ulo, uhi = band_patterns(W)
    np.testing.assert_array_equal(Wu[pat, :-1], W)
    np.testing.assert_array_equal(Wu[:, -1], 1.0 / Wu[:, 3])
    # the longest run of equal consecutive rows, found by brute force
    runs, s = [], 0
    for i in range(1, len(W) + 1):
        if i == len(W) or not np.array_equal(W[i], W[i - 1]):
            runs.append((i - s, s, i))
            s = i
    length, lo, hi = max(runs, key=lambda r: (r[0], -r[1]))
    assert (hi - lo, ulo, uhi) == (length, lo, hi) and np.all(pat[lo:hi] == upat)


@pytest.mark.parametrize("knots", ["uniform", "random"])
def test_band_patterns_few_and_many(knots):
    # uniform knots: a handful of distinct rows, returned as their own small array; knots from
    # random spans: nearly one pattern per row, returned in the working buffer (no copy) --
    # the same identities either way
    from curvefair.fairing.eck_hadenfeld import band_patterns

    n = 200
    rng = np.random.default_rng(5)
    h = np.ones(n - 3) if knots == "uniform" else rng.uniform(0.5, 1.5, n - 3)
    br = np.r_[0.0, np.cumsum(h)]
    c = BSplineCurve(rng.normal(size=(n, 2)), np.r_[[0.0] * 3, br, [br[-1]] * 3], 3)
    W = c.gram_band(2)
    Wu, pat, upat, ulo, uhi = band_patterns(W)
    np.testing.assert_array_equal(Wu[pat, :-1], W)
    np.testing.assert_array_equal(Wu[:, -1], 1.0 / Wu[:, 3])
    assert Wu.shape[0] == len(np.unique(pat)) and Wu.flags.c_contiguous
    if knots == "uniform":
        assert Wu.shape[0] <= 16 and Wu.base is None  # the rows near the clamped ends
    else:
        assert Wu.shape[0] > n // 2


@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("tol", [None, 0.05])
def test_loop_matches_slow_reference_mixed_knots(closed, tol):
    # rows inside the longest uniform run are read from one pattern, the others from pat
    c = mixed_knot_curve(np.random.default_rng(7 + closed), 60, closed)
    mask = movable_mask(c, "g1")
    d_ref, idx_ref = eh_loop_reference(c, 2, tol, 600, mask, 1e-12)
    res = eck_hadenfeld_fair(c, l=2, tol=tol, eps=1e-12, max_steps=600, clamp="g1")
    idx = res.history[:, 0].astype(int).tolist()
    assert len(idx_ref) > 60
    k = next((k for k, (a, b) in enumerate(zip(idx, idx_ref, strict=False)) if a != b), None)
    if k is None:
        assert len(idx) == len(idx_ref)
        np.testing.assert_allclose(res.curve.control_points, d_ref, atol=1e-10)
    else:
        # the orders may part only at a tie within rounding of the ranking numbers (the
        # incremental and the from-scratch residuals differ in the last bits)
        assert k >= 60
        z = ranking_numbers(eck_hadenfeld_fair(c, l=2, tol=None, eps=0.0, max_steps=k,
                                               clamp="g1").curve, 2) if tol is None else None
        if z is not None:
            assert abs(z[idx[k]] - z[idx_ref[k]]) <= 1e-13 * z.max()


@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("p,dim", [(3, 2), (3, 3), (4, 2), (5, 3)])
def test_fused_setup_is_bitwise_band_residual_and_energy(closed, p, dim):
    # the loop's one-pass set-up must give exactly the values of the separate band kernels
    # (the stopping threshold is relative to this energy), and the energy must match quadrature
    from curvefair._kernels.bspline import band_energy, band_residual
    from curvefair._kernels.eck_hadenfeld import setup_state
    from curvefair.fairing.eck_hadenfeld import _aligned_empty

    rng = np.random.default_rng(100 * p + dim + closed)
    for n in (p + 2, 2 * p + 1, 40):
        c = random_curve(rng, n=n, p=p, dim=dim, closed=closed)
        W = np.ascontiguousarray(c.gram_band(2))
        d = np.ascontiguousarray(c.control_points) * 1e3 + 5e5  # large coordinates
        mask = rng.random(n) < 0.7
        X = _aligned_empty((n, 3 * dim))
        z = _aligned_empty((n,))
        e = setup_state(W, p, closed, d, mask, X, z)
        g = np.empty_like(d)
        band_residual(W, p, closed, d, g)
        assert e == band_energy(W, p, closed, d)
        np.testing.assert_array_equal(X[:, :dim], d)
        np.testing.assert_array_equal(X[:, dim:2 * dim], g)
        np.testing.assert_array_equal(X[:, 2 * dim:], d)
        np.testing.assert_array_equal(z, np.where(mask, 0.0, -1.0))
        shifted = c.replace(control_points=d - 5e5)
        assert e == pytest.approx(quad_energy(shifted, 2), rel=1e-9)
