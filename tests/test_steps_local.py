"""The local fairing steps against independent numeric minimisation of the strain energy.

Reference: the strain energy int |r''|^2 dt of the two segments next to the point, evaluated with
scipy's own Hermite interpolants (CubicHermiteSpline / BPoly.from_derivatives -- not curvefair's
coefficient formulas) and dense Gauss-Legendre quadrature, minimised with scipy.optimize.minimize
(BFGS; gradient by central differences, exact for a quadratic up to rounding).
"""

import numpy as np
import pytest
from scipy.interpolate import BPoly, CubicHermiteSpline
from scipy.optimize import minimize

from curvefair import (
    CubicHermite,
    InputError,
    QuinticHermite,
    interpolate_cubic,
    interpolate_quintic,
    steps,
)

GX, GW = np.polynomial.legendre.leggauss(40)


def _quad_energy(evaluate_dd, t0, t1):
    """Dense Gauss-Legendre quadrature of |r''|^2 over [t0, t1] for each segment."""
    e = 0.0
    x = 0.5 * (GX + 1.0)
    w = 0.5 * GW
    tt = t0[:, None] + (t1 - t0)[:, None] * x[None, :]
    vals = evaluate_dd(tt.ravel()).reshape(tt.shape + (-1,))
    e = np.sum((vals**2).sum(-1) * w[None, :] * (t1 - t0)[:, None])
    return float(e)


def _energy_cubic(t3, r3, m3):
    spl = CubicHermiteSpline(t3, r3, m3, axis=0)
    dd = spl.derivative(2)
    return _quad_energy(dd, t3[:-1], t3[1:])


def _energy_quintic(t3, r3, d1, d2):
    spl = BPoly.from_derivatives(t3, np.stack([r3, d1, d2], axis=1), orders=5)
    dd = spl.derivative(2)
    return _quad_energy(dd, t3[:-1], t3[1:])


def _minimise(energy, x0, scales):
    """Minimise energy(x) from x0 (scaled variables); returns the minimiser.

    BFGS (scipy.optimize.minimize), then two Newton polishing steps with a central-difference
    Hessian; both derivatives are exact for a quadratic up to rounding.
    """
    def f(y):
        return energy(y * scales)

    def g(y, hstep=1e-2):
        out = np.empty_like(y)
        for i in range(y.size):
            e = np.zeros_like(y)
            e[i] = hstep
            out[i] = (f(y + e) - f(y - e)) / (2 * hstep)
        return out

    res = minimize(f, x0 / scales, jac=g, method="BFGS", options={"gtol": 1e-12, "maxiter": 500})
    y = res.x
    for _ in range(2):
        H = np.empty((y.size, y.size))
        for i in range(y.size):
            e = np.zeros_like(y)
            e[i] = 1e-1
            H[:, i] = (g(y + e) - g(y - e)) / 2e-1
        y = y - np.linalg.solve(0.5 * (H + H.T), g(y))
    return y * scales


def _random_cubic(rng, n, dim, closed=False):
    t = np.cumsum(rng.uniform(0.3, 2.0, n))
    t -= t[0]
    p = rng.normal(size=(n, dim)) * 2.0
    m = rng.normal(size=(n, dim))
    if closed:
        p[-1] = p[0]
        m[-1] = m[0]
    return CubicHermite(p, m, t, closed=closed)


def _random_quintic(rng, n, dim):
    t = np.cumsum(rng.uniform(0.3, 2.0, n))
    return QuinticHermite(rng.normal(size=(n, dim)) * 2, rng.normal(size=(n, dim)),
                          rng.normal(size=(n, dim)), t - t[0])


def _rel(a, b):
    return np.abs(np.asarray(a) - np.asarray(b)).max() / max(np.abs(b).max(), 1e-300)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("seed", [0, 1])
def test_poliakoff_is_energy_minimiser_over_position(dim, seed):
    rng = np.random.default_rng(seed)
    c = _random_cubic(rng, 6, dim)
    k = 2
    t3 = c.params[k - 1:k + 2]
    m3 = c.tangents[k - 1:k + 2]

    def energy(x):
        r3 = c.points[k - 1:k + 2].copy()
        r3[1] = x
        return _energy_cubic(t3, r3, m3)

    ref = _minimise(energy, c.points[k].copy(), np.ones(dim))
    new = steps.poliakoff(c, k)
    assert _rel(new.points[k], ref) < 1e-9
    np.testing.assert_array_equal(new.tangents, c.tangents)
    np.testing.assert_array_equal(np.delete(new.points, k, 0), np.delete(c.points, k, 0))
    # it makes r''' continuous at t_k (Poliakoff's defining property)
    tk = c.params[k]
    j3 = new.piecewise.evaluate([tk], 3, segment=np.array([k]))[0] - \
        new.piecewise.evaluate([tk], 3, segment=np.array([k - 1]))[0]
    assert np.abs(j3).max() < 1e-9 * np.abs(c.piecewise.coeffs[:, 3]).max()


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_wang_cao_is_energy_minimiser_over_position_and_tangent(dim, seed):
    rng = np.random.default_rng(10 + seed)
    c = _random_cubic(rng, 5, dim)
    k = 2
    t3 = c.params[k - 1:k + 2]
    hmean = np.diff(t3).mean()

    def energy(x):
        r3 = c.points[k - 1:k + 2].copy()
        m3 = c.tangents[k - 1:k + 2].copy()
        r3[1] = x[:dim]
        m3[1] = x[dim:]
        return _energy_cubic(t3, r3, m3)

    x0 = np.concatenate([c.points[k], c.tangents[k]])
    scales = np.concatenate([np.ones(dim), np.ones(dim) / hmean])
    ref = _minimise(energy, x0, scales)
    new = steps.wang_cao(c, k)
    assert _rel(new.points[k], ref[:dim]) < 1e-9
    assert _rel(new.tangents[k], ref[dim:]) < 1e-9
    assert energy(np.concatenate([new.points[k], new.tangents[k]])) <= energy(x0)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_wang_quintic_is_energy_minimiser(dim, seed):
    rng = np.random.default_rng(20 + seed)
    q = _random_quintic(rng, 5, dim)
    k = 2
    t3 = q.params[k - 1:k + 2]
    hmean = np.diff(t3).mean()

    def energy(x):
        r3 = q.points[k - 1:k + 2].copy()
        a = q.d1[k - 1:k + 2].copy()
        b = q.d2[k - 1:k + 2].copy()
        r3[1], a[1], b[1] = x[:dim], x[dim:2 * dim], x[2 * dim:]
        return _energy_quintic(t3, r3, a, b)

    x0 = np.concatenate([q.points[k], q.d1[k], q.d2[k]])
    scales = np.concatenate([np.ones(dim), np.ones(dim) / hmean, np.ones(dim) / hmean**2])
    ref = _minimise(energy, x0, scales)
    new = steps.wang_quintic(q, k)
    assert _rel(new.points[k], ref[:dim]) < 1e-9
    assert _rel(new.d1[k], ref[dim:2 * dim]) < 1e-9
    assert _rel(new.d2[k], ref[2 * dim:]) < 1e-9


def test_kjellander_equals_poliakoff_on_uniform_params_any_spacing():
    rng = np.random.default_rng(3)
    for hs in (1.0, 0.37):
        t = np.arange(7) * hs
        c = CubicHermite(rng.normal(size=(7, 3)), rng.normal(size=(7, 3)), t)
        for k in range(1, 6):
            a = steps.kjellander(c, k).points
            b = steps.poliakoff(c, k).points
            assert _rel(a, b) < 1e-12


def test_kjellander_rejects_nonuniform_params():
    c = _random_cubic(np.random.default_rng(4), 6, 2)
    with pytest.raises(InputError, match="uniform"):
        steps.kjellander(c, 2)


def test_wang_cao_with_tangent_held_is_poliakoff_corollary_1():
    # Corollary 1: minimising over r_k alone gives Poliakoff's point; equivalently the Wang-Cao
    # energy (eq. (14)) with eta = 0 is minimised at Poliakoff's delta. Check through the
    # reference minimiser with the tangent held, on a curve where Wang-Cao changes the tangent.
    rng = np.random.default_rng(5)
    c = _random_cubic(rng, 6, 2)
    k = 3
    wc = steps.wang_cao(c, k)
    assert np.abs(wc.tangents[k] - c.tangents[k]).max() > 1e-3
    held = CubicHermite(wc.points, c.tangents, c.params)
    # Poliakoff's step from the Wang-Cao point must return Poliakoff's point from the original
    # (its target does not depend on r_k): the position-only optimum is unique.
    np.testing.assert_allclose(steps.poliakoff(held, k).points[k], steps.poliakoff(c, k).points[k],
                               rtol=1e-12, atol=1e-12)


def test_wang_cao_single_cubic_reading():
    # ERRATA: r_k + delta*, r'_k + eta* are the value and derivative at t_k of the single cubic
    # Hermite segment over [t_{k-1}, t_{k+1}] with the neighbours' end data.
    rng = np.random.default_rng(6)
    c = _random_cubic(rng, 7, 3)
    for k in range(1, 6):
        seg = CubicHermiteSpline(c.params[[k - 1, k + 1]], c.points[[k - 1, k + 1]],
                                 c.tangents[[k - 1, k + 1]], axis=0)
        new = steps.wang_cao(c, k)
        tk = c.params[k]
        assert _rel(new.points[k], seg(tk)) < 1e-12
        assert _rel(new.tangents[k], seg(tk, 1)) < 1e-12


def test_rho_relation_on_c2_spline():
    # ERRATA: with C2-spline tangents, delta_WC = rho * delta_Poliakoff,
    # rho = 4 (D_{k-1}^3 + D_k^3) / (D_{k-1} + D_k)^3.
    rng = np.random.default_rng(7)
    pts = np.cumsum(rng.normal(size=(9, 2)), axis=0)
    c = interpolate_cubic(pts, "chord")
    for k in range(1, 8):
        d0, d1 = np.diff(c.params)[k - 1], np.diff(c.params)[k]
        rho = 4 * (d0**3 + d1**3) / (d0 + d1) ** 3
        dwc = steps.wang_cao(c, k).points[k] - c.points[k]
        dpo = steps.poliakoff(c, k).points[k] - c.points[k]
        assert _rel(dwc, rho * dpo) < 1e-9


def _corrected_uniform_corollary(q, k):
    # ERRATA: uniform corollary of Wang 2005 (all Delta = 1), delta corrected; eta, xi as printed.
    a = q.coefficients()
    L, R = a[k - 1], a[k]
    delta = (-(R[3] - L[3]) / 5 - 11 / 30 * R[4] + 13 / 30 * L[4] - 0.5 * R[5] + 2 / 3 * L[5])
    eta = (35 / 192 * (R[2] - L[2]) - 35 / 64 * L[3] - 7 / 32 * R[4] - 7 / 8 * L[4]
           - 5 / 12 * R[5] - 55 / 48 * L[5])
    xi = (R[3] - L[3]) + 2 / 3 * R[4] - 10 / 3 * L[4] - 20 / 3 * L[5]
    return delta, eta, xi


def test_wang_quintic_uniform_corollary():
    rng = np.random.default_rng(8)
    q = QuinticHermite(rng.normal(size=(6, 3)), rng.normal(size=(6, 3)), rng.normal(size=(6, 3)),
                       np.arange(6.0))
    for k in range(1, 5):
        d, e, x = _corrected_uniform_corollary(q, k)
        new = steps.wang_quintic(q, k)
        assert _rel(new.points[k] - q.points[k], d) < 1e-10
        assert _rel(new.d1[k] - q.d1[k], e) < 1e-10
        assert _rel(new.d2[k] - q.d2[k], x) < 1e-10


def test_wang_quintic_matches_corrected_closed_form():
    # ERRATA: delta of eq. (4) right; eta = eta_printed - 35 D1^2 D0^2 C2 / (96 (D1+D0)^3);
    # xi with 5/4 instead of 5/16 on the C3 term. C1..C3 as printed (computed here from scipy's
    # own polynomial coefficients of the two segments, not curvefair's).
    rng = np.random.default_rng(9)
    q = _random_quintic(rng, 5, 2)
    k = 2
    D0, D1 = np.diff(q.params)[k - 1], np.diff(q.params)[k]
    bp = BPoly.from_derivatives(q.params, np.stack([q.points, q.d1, q.d2], axis=1), orders=5)
    from scipy.interpolate import PPoly
    pp = PPoly.from_bernstein_basis(bp)
    # PPoly coefficients: c[5 - j, i] multiplies (t - t_i)^j
    L = pp.c[::-1, k - 1]
    R = pp.c[::-1, k]
    C1 = 12 * (R[3] - L[3]) + 24 * (R[4] * D1 - L[4] * D0) + 240 / 7 * (R[5] * D1**2 - L[5] * D0**2)
    C2 = (-4 * (R[2] - L[2]) + 12 * L[3] * D0 + 24 / 5 * R[4] * D1**2 + 96 / 5 * L[4] * D0**2
          + 64 / 7 * R[5] * D1**3 + 176 / 7 * L[5] * D0**3)
    C3 = 2 / 5 * (R[4] * D1**3 + L[4] * D0**3) + 6 / 7 * R[5] * D1**4 + 8 / 7 * L[5] * D0**4
    s = D1 + D0
    delta = 2 / 15 * D1**3 * D0**3 / s**3 * (-C1 + 25 / 16 * (D0 - D1) / (D1 * D0) * C2
                                              + 5 / (D1 * D0) * C3)
    eta_p = 5 / 24 * (D1 - D0) * D1**2 * D0**2 / s**3 * (-C1 + 2 * (D0 - D1) / (D1 * D0) * C2
                                                          + 5 / (D1 * D0) * C3)
    eta = eta_p - 35 * D1**2 * D0**2 * C2 / (96 * s**3)
    xi = 2 / 3 * D1**2 * D0**2 / s**3 * (C1 + 25 / 16 * (D1 - D0) / (D1 * D0) * C2
                                         - 5 / 4 * (7 * D1**2 + 7 * D0**2 + 18 * D1 * D0)
                                         / (D1**2 * D0**2) * C3)
    new = steps.wang_quintic(q, k)
    assert _rel(new.points[k] - q.points[k], delta) < 1e-9
    assert _rel(new.d1[k] - q.d1[k], eta) < 1e-9
    assert _rel(new.d2[k] - q.d2[k], xi) < 1e-9


def test_closed_seam_updates_both_copies():
    rng = np.random.default_rng(11)
    c = _random_cubic(rng, 7, 2, closed=True)
    for fn in (steps.poliakoff, steps.wang_cao):
        new = fn(c, 0)
        np.testing.assert_array_equal(new.points[0], new.points[-1])
        np.testing.assert_array_equal(new.tangents[0], new.tangents[-1])
        assert np.abs(new.points[0] - c.points[0]).max() > 0
        # k = n-1 is the same point
        np.testing.assert_array_equal(fn(c, 6).points, new.points)
    # the seam step minimises the energy of the closing and first segment
    t3 = np.array([c.params[-2] - c.params[-1], 0.0, c.params[1]])  # shift the closing segment
    m3 = c.tangents[[-2, 0, 1]]

    def energy(x):
        r3 = c.points[[-2, 0, 1]].copy()
        r3[1] = x
        return _energy_cubic(t3, r3, m3)

    ref = _minimise(energy, c.points[0].copy(), np.ones(2))
    assert _rel(steps.poliakoff(c, 0).points[0], ref) < 1e-9


def test_quintic_seam():
    rng = np.random.default_rng(12)
    th = np.linspace(0, 2 * np.pi, 9)[:-1]
    pts = np.c_[np.cos(th), np.sin(th)] + 0.05 * rng.normal(size=(8, 2))
    q = interpolate_quintic(pts, bc="periodic")
    new = steps.wang_quintic(q, 0)
    np.testing.assert_array_equal(new.points[0], new.points[-1])
    np.testing.assert_array_equal(new.d2[0], new.d2[-1])


def test_step_bad_input():
    rng = np.random.default_rng(13)
    c = _random_cubic(rng, 5, 2)
    q = _random_quintic(rng, 5, 2)
    for k in (0, 4, -1, 5, 99):
        with pytest.raises(InputError, match="k = "):
            steps.poliakoff(c, k)
    with pytest.raises(InputError, match="integer"):
        steps.poliakoff(c, 1.5)
    with pytest.raises(InputError, match="CubicHermite"):
        steps.wang_cao(q, 2)
    with pytest.raises(InputError, match="QuinticHermite"):
        steps.wang_quintic(c, 2)
    with pytest.raises(InputError, match="at least 3"):
        steps.poliakoff(CubicHermite([[0, 0], [1, 0]], [[1, 0], [1, 0]], [0, 1]), 1)


def test_steps_do_not_modify_input_and_no_nan():
    rng = np.random.default_rng(14)
    c = _random_cubic(rng, 6, 3)
    before = np.array(c.points)
    for fn in (steps.poliakoff, steps.wang_cao):
        out = fn(c, 2)
        assert np.isfinite(out.points).all() and np.isfinite(out.tangents).all()
    np.testing.assert_array_equal(c.points, before)


@pytest.mark.parametrize("method", ["poliakoff", "wang-cao", "wang-quintic"])
def test_clamped_step_is_the_constrained_minimiser(method):
    # fair(mode="hermite", tol) clamps the position radially onto the tolerance circle and
    # re-optimises the derivatives for it; the claim is that this is the exact minimiser of the
    # two segments' strain energy over {|r_k - r_k,orig| <= tol} x derivatives. Reference:
    # position = orig + tol (cos th, sin th), minimise over th and the free derivatives.
    from curvefair import fair

    rng = np.random.default_rng(40)
    if method == "wang-quintic":
        c = _random_quintic(rng, 5, 2)
    else:
        c = _random_cubic(rng, 5, 2)
    kw = {} if method == "wang-quintic" else {"measure": "jump"}  # the papers' ranking
    res = fair(c, method, mode="hermite", tol=0.05, eps=0.0, max_steps=1, tol_on="points", **kw)
    k = int(res.history.index[0])
    assert np.isclose(np.linalg.norm(res.curve.points[k] - c.points[k]), 0.05, rtol=1e-9)
    t3 = c.params[k - 1:k + 2]
    hmean = np.diff(t3).mean()
    nder = {"poliakoff": 0, "wang-cao": 1, "wang-quintic": 2}[method]

    def energy(x):
        r3 = c.points[k - 1:k + 2].copy()
        r3[1] = c.points[k] + 0.05 * np.array([np.cos(x[0]), np.sin(x[0])])
        ders = [np.array(d[k - 1:k + 2]) for d in c._derivs]
        for j in range(nder):
            ders[j][1] = x[1 + 2 * j:3 + 2 * j]
        if method == "wang-quintic":
            return _energy_quintic(t3, r3, ders[0], ders[1])
        return _energy_cubic(t3, r3, ders[0])

    # start from the best of a coarse angle scan
    th = np.linspace(0, 2 * np.pi, 73)[:-1]
    x0 = np.concatenate([[0.0]] + [np.array(d[k]) for d in c._derivs][:nder])
    e = [energy(np.r_[t, x0[1:]]) for t in th]
    x0[0] = th[int(np.argmin(e))]
    scales = np.concatenate([[1.0]] + [np.ones(2) / hmean**j for j in range(1, nder + 1)])
    ref = _minimise(energy, x0, scales)
    ref_pos = c.points[k] + 0.05 * np.array([np.cos(ref[0]), np.sin(ref[0])])
    assert np.abs(res.curve.points[k] - ref_pos).max() < 1e-8
    for j in range(nder):
        assert _rel(res.curve._derivs[j][k], ref[1 + 2 * j:3 + 2 * j]) < 1e-7
