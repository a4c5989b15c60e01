"""Tests for curvefair.fair_points (fairing/pipeline.py).

Independent references: the energy by dense Gauss-Legendre quadrature of ``|C^(l)|^2`` from the
curve's own evaluation (not the Gram matrices); the constrained optimum by
``scipy.optimize.minimize(method="SLSQP")``; the gradient of the energy by central finite
differences; the "minimiser over all curves" claim by re-solving in a strictly larger spline
space (every span halved); the control-ball problem of ``global_fair`` as a feasible competitor.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.interpolate import make_interp_spline
from scipy.optimize import minimize

import curvefair as cf
from curvefair import BSplineCurve
from curvefair.errors import InputError
from curvefair.fairing.global_fair import global_fair
from curvefair.fairing.pipeline import _collocation, _start_curve, fair_points, tube_energy_qp


def quad_energy(curve: BSplineCurve, l: int, per_span: int = 12) -> float:  # noqa: E741
    """int |C^(l)|^2 du by Gauss-Legendre on every knot span (exact for the polynomial)."""
    x, w = np.polynomial.legendre.leggauss(per_span)
    br = np.unique(np.asarray(curve.piecewise.breaks))
    a, b = br[:-1], br[1:]
    uu = (0.5 * (b - a)[:, None] * (x[None, :] + 1) + a[:, None]).reshape(-1)
    ww = (0.5 * (b - a)[:, None] * w[None, :]).reshape(-1)
    d = curve(uu, l)
    return float(np.sum(ww * np.sum(d * d, axis=1)))


def noisy_arc(m: int = 14, sigma: float = 2e-3, seed: int = 1, closed: bool = False,
              dim: int = 2) -> np.ndarray:
    rng = np.random.default_rng(seed)
    if closed:
        t = np.linspace(0, 2 * np.pi, m, endpoint=False)
        pts = np.c_[1.3 * np.cos(t), 0.8 * np.sin(t)]
    else:
        t = np.linspace(0, 2.2, m)
        pts = np.c_[np.cos(t), np.sin(t)]
    if dim == 3:
        pts = np.c_[pts, 0.2 * np.sin(2 * t)]
    return pts + rng.normal(0, sigma, pts.shape)


def refine(curve: BSplineCurve) -> BSplineCurve:
    """The same curve on a knot vector with every span halved (Greville interpolation)."""
    p = curve.degree
    t = np.asarray(curve.knots)
    lo, hi = curve.domain
    br = np.unique(t[(t >= lo) & (t <= hi)])
    inner = np.sort(np.r_[br[1:-1], 0.5 * (br[:-1] + br[1:])])
    tt = np.r_[[lo] * (p + 1), inner, [hi] * (p + 1)]
    n = tt.shape[0] - p - 1
    xg = np.array([tt[i + 1:i + p + 1].mean() for i in range(n)])
    spl = make_interp_spline(xg, curve(xg), k=p, t=tt, axis=0)
    return BSplineCurve(spl.c, tt, p)


# ------------------------------------------------------------------------------------------
def test_tolerance_and_report():
    pts = noisy_arc(30, 3e-3)
    tol = 6e-3
    res = fair_points(pts, tol)
    u = cf.parameterize(pts, "chord")
    dev = np.linalg.norm(res.curve(u) - pts, axis=1)
    assert dev.max() <= tol
    assert res.report["max_deviation"] == pytest.approx(dev.max(), rel=1e-12)
    assert np.array_equal(res.params, u)
    assert res.report["stop_reason"] == "converged"
    assert res.report["n_active"] > 0  # noisy points: the tolerance binds somewhere
    assert res.report["energy_after"] < res.report["energy_before"]
    # the reported energies are E3 (checked by quadrature)
    assert res.report["energy_after"] == pytest.approx(quad_energy(res.curve, 3), rel=1e-6)
    assert res.curve.degree == 5 and not res.curve.closed


@pytest.mark.parametrize("closed", [False, True])
def test_matches_slsqp_optimum(closed):
    """Same problem by scipy's SLSQP on the control points: equal optimum energy."""
    pts = noisy_arc(10, 4e-3, seed=3, closed=closed)
    tol = 5e-3
    res = fair_points(pts, tol, closed=closed)
    c = res.curve
    A = _collocation(c, res.params).toarray()
    n, dim = c.control_points.shape
    shell = c

    def E(z):
        return quad_energy(shell.replace(control_points=z.reshape(n, dim)), 3)

    x0 = np.array(_start_curve(pts, np.r_[res.params, res.params[-1] + np.linalg.norm(
        pts[0] - pts[-1])] if closed else res.params, 5, closed, {3: 1.0}).control_points)
    cons = {"type": "ineq",
            "fun": lambda z: tol**2 - np.sum((A @ z.reshape(n, dim) - pts) ** 2, axis=1)}
    scale = E(x0.ravel())
    ref = minimize(lambda z: E(z) / scale, x0.ravel(), method="SLSQP", constraints=[cons],
                   options={"maxiter": 500, "ftol": 1e-14})
    zref = ref.x.reshape(n, dim)
    assert np.all(np.linalg.norm(A @ zref - pts, axis=1) <= tol * (1 + 1e-6))
    e_ours, e_ref = quad_energy(c, 3), E(ref.x)
    assert e_ours <= e_ref * (1 + 1e-6)
    assert e_ours == pytest.approx(e_ref, rel=1e-4)


def test_kkt_conditions_finite_differences():
    pts = noisy_arc(16, 3e-3, seed=5)
    tol = 4e-3
    res = fair_points(pts, tol)
    c = res.curve
    d = np.array(c.control_points)
    n, dim = d.shape
    # gradient of E3 by central differences of the quadrature energy (E is quadratic: exact
    # up to rounding for any step)
    h = 1e-3
    g = np.zeros_like(d)
    for i in range(n):
        for a in range(dim):
            dp, dm = d.copy(), d.copy()
            dp[i, a] += h
            dm[i, a] -= h
            g[i, a] = (quad_energy(c.replace(control_points=dp), 3)
                       - quad_energy(c.replace(control_points=dm), 3)) / (2 * h)
    A = _collocation(c, res.params).toarray()
    r = A @ d - pts
    mu = np.asarray(res.multipliers)
    stationarity = g + A.T @ (mu[:, None] * r)
    assert np.abs(stationarity).max() <= 1e-6 * np.abs(g).max()
    assert np.all(mu >= 0)
    dist = np.linalg.norm(r, axis=1)
    slack = tol - dist
    assert np.all(mu * slack <= 1e-6 * mu.max() * tol)  # complementary slackness
    assert np.sum(mu > 1e-6 * mu.max()) == res.report["n_active"]


@pytest.mark.parametrize("closed", [False, True])
def test_minimiser_over_a_larger_spline_space(closed):
    """degree 5, l = 3: halving every knot span (a strictly larger space) gains nothing."""
    pts = noisy_arc(18, 3e-3, seed=7, closed=closed)
    tol = 4e-3
    res = fair_points(pts, tol, closed=closed)
    if closed:
        # insert midpoints in the periodic knot vector: the refined closed curve, by
        # interpolation at many points with a periodic knot vector of twice the spans
        c = res.curve
        lo, hi = c.domain
        p = 5
        br = np.unique(np.asarray(c.knots)[p:p + c.n_ctrl + 1])
        period = np.sort(np.r_[br, 0.5 * (br[:-1] + br[1:])])
        fine0 = BSplineCurve(np.zeros((period.size - 1, 2)), period, p, closed=True)
        start0 = _start_curve(pts, np.r_[res.params, hi], p, True, {3: 1.0})
        s = np.linspace(lo, hi, 4 * period.size, endpoint=False)
        from curvefair.fairing.pipeline import _collocation as colloc
        B = colloc(fine0, s).toarray()
        ctrl = np.linalg.lstsq(B, start0(s), rcond=None)[0]
        fine_start = fine0.replace(control_points=ctrl)
        assert np.abs(fine_start(s) - start0(s)).max() < 1e-12
    else:
        start0 = _start_curve(pts, res.params, 5, False, {3: 1.0})
        fine_start = refine(start0)
    fine, _, _, reason = tube_energy_qp(fine_start, res.params, pts, tol, l=3)
    assert reason == "converged"
    e, ef = quad_energy(res.curve, 3), quad_energy(fine, 3)
    assert ef >= e * (1 - 1e-6)
    assert ef == pytest.approx(e, rel=1e-5)


def test_never_above_the_control_ball_problem():
    """The control-point balls of global_fair are a sufficient condition for the data balls
    (convex hull property), so fair_points' energy can only be lower."""
    pts = noisy_arc(25, 3e-3, seed=11)
    tol = 5e-3
    res = fair_points(pts, tol)
    start = _start_curve(pts, res.params, 5, False, {3: 1.0})
    g = global_fair(start, tol=tol, l=3)
    A = _collocation(start, res.params)
    assert np.linalg.norm(A @ np.asarray(g.curve.control_points) - pts, axis=1).max() <= tol
    assert quad_energy(res.curve, 3) <= quad_energy(g.curve, 3) * (1 + 1e-9)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10_000), closed=st.booleans(), dim=st.sampled_from([2, 3]),
       sigma=st.sampled_from([1e-4, 1e-3, 1e-2]), degree=st.sampled_from([3, 4, 5]))
def test_property_tolerance_dense(seed, closed, dim, sigma, degree):
    rng = np.random.default_rng(seed)
    m = int(rng.integers(8, 40))
    pts = noisy_arc(m, sigma, seed=seed, closed=closed, dim=dim)
    tol = 3 * sigma
    l = 2 if degree == 3 else 3  # noqa: E741
    res = fair_points(pts, tol, degree=degree, l=l, closed=closed)
    dev = np.linalg.norm(res.curve(res.params) - pts, axis=1)
    assert dev.max() <= tol
    assert res.report["energy_after"] <= res.report["energy_before"] * (1 + 1e-12)
    assert res.report["stop_reason"] == "converged"
    assert res.curve.closed == closed and res.curve.dim == dim


def test_tolerance_exact_in_float64_at_the_tube_boundary():
    # the case the property above found (seed 302): the interior-point iterate ended 4e-13
    # relative outside tol as float64 evaluates |C(u_i) - p_i|; the tube is now solved a
    # rounding margin inside
    rng = np.random.default_rng(302)
    m = int(rng.integers(8, 40))
    pts = noisy_arc(m, 1e-4, seed=302, closed=False, dim=2)
    res = fair_points(pts, 3e-4, degree=3, l=2)
    assert np.linalg.norm(res.curve(res.params) - pts, axis=1).max() <= 3e-4
    assert res.report["max_deviation"] <= 3e-4
    assert res.report["n_active"] > 0  # the tube is reached: the check is not vacuous


def test_invariance_rigid_and_scale():
    pts = noisy_arc(20, 2e-3, seed=4)
    tol = 4e-3
    res = fair_points(pts, tol)
    th = 0.7
    R = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
    s, shift = 3.0, np.array([5.0, -2.0])
    res2 = fair_points(s * pts @ R.T + shift, s * tol)
    uu = np.linspace(*res.curve.domain, 200)
    a = s * res.curve(uu) @ R.T + shift
    b = res2.curve(s * uu)
    assert np.abs(a - b).max() <= 1e-6 * s * tol


def test_large_tolerance_gives_a_polynomial():
    """Within a huge tolerance the minimiser of E3 has E3 = 0: a quadratic in u."""
    pts = noisy_arc(15, 1e-3, seed=2)
    res = fair_points(pts, 10.0)
    assert res.report["energy_after"] <= 1e-8 * res.report["energy_before"]
    uu = np.linspace(*res.curve.domain, 50)
    assert np.abs(res.curve(uu, 3)).max() <= 1e-3 * np.abs(
        _start_curve(pts, res.params, 5, False, {3: 1.0})(uu, 3)).max()


def test_c4_and_fewer_extrema_than_interpolant():
    pts = noisy_arc(40, 2e-3, seed=9)
    res = fair_points(pts, 8e-3)
    c = res.curve
    br = np.asarray(c.piecewise.breaks)[1:-1]
    for k in range(5):  # continuous up to the fourth derivative at every knot
        jump = np.abs(c(br + 1e-12, k) - c(br - 1e-12, k)).max()
        assert jump <= 1e-6 * max(np.abs(c(br, k)).max(), 1.0)
    before = cf.analyze(cf.interpolate_bspline(pts, 3)).extrema
    after = cf.analyze(c).extrema
    assert after < before


@pytest.mark.parametrize("kw, msg", [
    ({"tol": 0.0}, "tol"), ({"tol": -1.0}, "tol"), ({"tol": np.nan}, "tol"),
    ({"tol": 1e-3, "degree": 1}, "degree"), ({"tol": 1e-3, "l": 6}, "energy order"),
    ({"tol": 1e-3, "l": "x"}, "l must"), ({"tol": 1e-3, "max_steps": 0}, "max_steps"),
    ({"tol": 1e-3, "param": np.arange(3.0)}, "param"),
])
def test_input_errors(kw, msg):
    pts = noisy_arc(12)
    with pytest.raises(InputError, match=msg):
        fair_points(pts, **kw)


def test_too_few_points():
    with pytest.raises(InputError):
        fair_points(np.random.default_rng(0).normal(size=(4, 2)), 1e-3)
