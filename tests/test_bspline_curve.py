"""BSplineCurve: evaluation, power form, scipy round trip, builders, Gram matrices, validation.

References: scipy.interpolate.BSpline (independent de Boor evaluation), a naive recursive
Cox-de Boor basis (slow, obviously correct), dense Gauss quadrature of scipy-evaluated basis
derivatives for the Gram matrices, interpolate_cubic for the natural cubic interpolant.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.interpolate import BSpline

import curvefair
from curvefair import BSplineCurve, InputError, fit_bspline, interpolate_bspline
from curvefair._kernels.bspline import basis_reference
from curvefair.curves.bspline import basis_derivatives


def _random_open(rng, n, p, dim=2, repeat=True):
    inner = np.sort(rng.uniform(0.0, 3.0, n - p - 1))
    if repeat and inner.size >= 3 and p >= 2:
        inner[2] = inner[1]  # a double interior knot
    t = np.r_[[0.0] * (p + 1), inner, [3.0] * (p + 1)]
    return BSplineCurve(rng.normal(size=(n, dim)), t, p)


def _random_closed(rng, n, p, dim=2):
    gaps = rng.uniform(0.3, 1.7, n)
    period = np.r_[0.0, np.cumsum(gaps)]
    return BSplineCurve(rng.normal(size=(n, dim)), period, p, closed=True)


@pytest.mark.parametrize("p", [2, 3, 4, 5])
@pytest.mark.parametrize("closed", [False, True])
def test_evaluation_matches_scipy(p, closed):
    rng = np.random.default_rng(10 * p + closed)
    c = _random_closed(rng, 11, p, 3) if closed else _random_open(rng, 11, p, 3)
    spl = c.to_scipy()
    t0, t1 = c.domain
    u = np.linspace(t0, t1, 301)
    for nu in range(p + 1):
        ref = spl(u, nu)
        scale = np.abs(ref).max()
        np.testing.assert_allclose(c(u, nu), ref, rtol=0, atol=1e-10 * scale)


@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("dim", [2, 3])
def test_cubic_power_form_copy_is_the_general_loop(closed, dim):
    # power_form_kernel and power_form_pair_kernel run a copy compiled for degree 3; it must
    # give bitwise what the general loop gives: that loop run by the interpreter (py_func:
    # no degree known at compile time, the same float64 operations in the same order)
    from curvefair._kernels import bspline as kb

    rng = np.random.default_rng(40 + 2 * dim + closed)
    c = _random_closed(rng, 23, 3, dim) if closed else _random_open(rng, 23, 3, dim)
    t = np.ascontiguousarray(c.knots)
    s = np.ascontiguousarray(c.spans, dtype=np.int64)
    ctrl = np.ascontiguousarray(c.control_points)
    base = ctrl + 1e-3 * rng.normal(size=ctrl.shape)
    shape = (s.size, 4, dim)
    got, got2, gotd = np.empty(shape), np.empty(shape), np.empty(shape)
    kb.power_form_kernel(t, 3, s, ctrl, closed, got)
    kb.power_form_pair_kernel(t, 3, s, ctrl, base, closed, got2, gotd)
    ref, refd = np.empty(shape), np.empty(shape)
    kb._power_form_body.py_func(t, 3, s, ctrl, base, closed, ref, refd, True)
    assert np.array_equal(got, ref) and np.array_equal(got2, ref)
    assert np.array_equal(gotd, refd)
    # and it is the curve's derivatives at the span starts (scipy's de Boor evaluation)
    spl = c.to_scipy()
    for k in range(4):
        want = spl(t[s], k) / math.factorial(k)
        np.testing.assert_allclose(got[:, k], want, rtol=0,
                                   atol=1e-11 * max(np.abs(want).max(), 1.0))


def test_basis_matches_naive_recursion():
    rng = np.random.default_rng(3)
    p = 3
    c = _random_open(rng, 9, p)
    t = np.array(c.knots)
    x = rng.uniform(*c.domain, 40)
    span = np.searchsorted(t, x, side="right") - 1
    got = basis_derivatives(t, p, span, x, 0)[:, 0, :]
    for q in range(x.size):
        ref = [basis_reference(t, p, span[q] - p + a, x[q]) for a in range(p + 1)]
        np.testing.assert_allclose(got[q], ref, atol=1e-14)


def test_basis_derivatives_finite_differences():
    rng = np.random.default_rng(4)
    p = 4
    c = _random_open(rng, 10, p, repeat=False)
    t = np.array(c.knots)
    x = rng.uniform(*c.domain, 30)
    span = np.searchsorted(t, x, side="right") - 1
    h = 1e-6
    d = basis_derivatives(t, p, span, x, 2)
    dp = basis_derivatives(t, p, span, x + h, 1)
    dm = basis_derivatives(t, p, span, x - h, 1)
    ok = (x - h > t[span]) & (x + h < t[span + 1])
    np.testing.assert_allclose(d[ok, 1], (dp[ok, 0] - dm[ok, 0]) / (2 * h), atol=1e-6)
    np.testing.assert_allclose(d[ok, 2], (dp[ok, 1] - dm[ok, 1]) / (2 * h), rtol=1e-5, atol=1e-4)


@pytest.mark.parametrize("p", [2, 3, 5])
def test_closed_is_periodic_and_smooth_at_seam(p):
    c = _random_closed(np.random.default_rng(p), 9, p)
    t0, t1 = c.domain
    for nu in range(p):
        a = c.piecewise.evaluate(np.array([t1]), nu, segment=np.array([c.piecewise.n_segments - 1]))
        b = c(np.array([t0]), nu)
        np.testing.assert_allclose(a, b, atol=1e-9 * max(1.0, np.abs(b).max()))
    np.testing.assert_allclose(c(t0 + 0.3 + 2 * (t1 - t0)), c(t0 + 0.3), atol=1e-12)


@pytest.mark.parametrize("closed", [False, True])
def test_scipy_round_trip(closed):
    rng = np.random.default_rng(7)
    c = _random_closed(rng, 8, 3) if closed else _random_open(rng, 8, 3)
    spl = c.to_scipy()
    assert isinstance(spl, BSpline)
    back = BSplineCurve.from_scipy(spl)
    assert back.closed == closed
    np.testing.assert_array_equal(back.knots, c.knots)
    np.testing.assert_array_equal(back.control_points, c.control_points)
    assert back.degree == c.degree


def test_period_only_knots_equal_full_knots():
    rng = np.random.default_rng(8)
    c = _random_closed(rng, 7, 3)
    full = BSplineCurve(c.control_points, c.knots, 3, closed=True)
    np.testing.assert_array_equal(full.knots, c.knots)
    assert c.knots.shape == (7 + 2 * 3 + 1,)
    assert c.extended_control_points.shape == (10, 2)


def test_immutable():
    c = _random_open(np.random.default_rng(1), 6, 3)
    with pytest.raises(ValueError):
        c.control_points[0, 0] = 5.0
    with pytest.raises(ValueError):
        c.knots[0] = -1.0
    with pytest.raises(ValueError):
        c.piecewise.coeffs[0, 0, 0] = 1.0
    d = c.replace(control_points=np.zeros((6, 2)))
    assert np.all(d.control_points == 0) and not np.all(c.control_points == 0)


def test_exported():
    assert curvefair.BSplineCurve is BSplineCurve
    assert issubclass(BSplineCurve, curvefair.PiecewiseCurve)


# -- builders ------------------------------------------------------------------------------
@pytest.mark.parametrize("p", [2, 3, 4, 5])
@pytest.mark.parametrize("closed", [False, True])
def test_interpolate_passes_through_points(p, closed):
    rng = np.random.default_rng(p)
    pts = np.cumsum(rng.uniform(0.5, 1.0, (12, 2)), axis=0) * [1, 0.3] + rng.normal(size=(12, 2))
    if closed:
        ang = np.sort(rng.uniform(0, 2 * np.pi, 12))
        pts = np.c_[np.cos(ang), np.sin(ang)] * rng.uniform(0.8, 1.2, (12, 1))
    c = interpolate_bspline(pts, degree=p, closed=closed)
    assert c.degree == p and c.closed == closed
    from curvefair import parameterize
    loop = np.vstack([pts, pts[:1]]) if closed else pts
    t = parameterize(loop, "chord")
    np.testing.assert_allclose(c(t), loop, atol=1e-9)


def test_open_cubic_interpolant_is_natural_spline():
    rng = np.random.default_rng(5)
    pts = rng.normal(size=(9, 3))
    c = interpolate_bspline(pts, degree=3)
    h = curvefair.interpolate_cubic(pts)
    u = np.linspace(*c.domain, 200)
    np.testing.assert_allclose(c(u), h(u), atol=1e-10)


@pytest.mark.parametrize("closed", [False, True])
def test_fit_reproduces_a_spline_in_its_space(closed):
    # the knots depend only on the parameters and n_ctrl: take them from a first fit, put random
    # control points on them, sample at the same parameters -> least squares must return them
    rng = np.random.default_rng(11)
    m = 60
    u = np.sort(rng.uniform(0, 5, m))
    u[0] = 0.0
    param = np.r_[u, 5.5] if closed else u
    first = fit_bspline(rng.normal(size=(m, 2)), 9, param=param, closed=closed)
    ref = first.replace(control_points=rng.normal(size=(9, 2)))
    fit = fit_bspline(ref(u), 9, param=param, closed=closed)
    np.testing.assert_array_equal(fit.knots, ref.knots)
    np.testing.assert_allclose(fit.control_points, ref.control_points, atol=1e-9)


def test_fit_polynomial_exact():
    u = np.linspace(0.0, 2.0, 60)
    pts = np.c_[u**3 - u, 2 * u**2 + 1]
    c = fit_bspline(pts, 7, degree=3, param=u)
    np.testing.assert_allclose(c(u), pts, atol=1e-11)


def test_fit_least_squares_optimal():
    rng = np.random.default_rng(2)
    pts = rng.normal(size=(30, 2)).cumsum(axis=0)
    c = fit_bspline(pts, 8)
    t = curvefair.parameterize(pts, "chord")
    r0 = np.sum((c(t) - pts) ** 2)
    for _ in range(5):  # any perturbation of the control points increases the residual
        d = c.replace(control_points=c.control_points + 1e-3 * rng.normal(size=(8, 2)))
        assert np.sum((d(t) - pts) ** 2) > r0


# -- Gram matrices -------------------------------------------------------------------------
@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("p,l", [(3, 2), (3, 3), (4, 2), (5, 3), (2, 2)])
def test_gram_matches_dense_quadrature(closed, p, l):  # noqa: E741
    rng = np.random.default_rng(100 + p + l)
    c = _random_closed(rng, 9, p) if closed else _random_open(rng, 9, p, repeat=False)
    G = c.gram_matrix(l).toarray()
    n = c.n_ctrl
    # basis functions via scipy, integrated with 12-point Gauss per span (far more than needed)
    t = np.array(c.knots)
    xg, wg = np.polynomial.legendre.leggauss(12)
    br = c.piecewise.breaks
    x = ((br[:-1, None] + br[1:, None]) / 2 + (np.diff(br)[:, None] / 2) * xg).ravel()
    w = (np.diff(br)[:, None] / 2 * wg).ravel()
    K = t.shape[0] - p - 1
    B = np.empty((K, x.size))
    for i in range(K):
        coef = np.zeros(K)
        coef[i] = 1.0
        B[i] = BSpline(t, coef, p)(x, l)
    if closed:
        B2 = np.zeros((n, x.size))
        for i in range(K):
            B2[i % n] += B[i]
        B = B2
    ref = (B * w) @ B.T
    np.testing.assert_allclose(G, ref, atol=1e-9 * np.abs(ref).max())
    # energy from the Gram matrix equals dense quadrature of |r^(l)|^2
    e = np.sum(w * np.sum(c(x, l) ** 2, axis=1))
    assert abs(c.energy_l(l) - e) <= 1e-9 * e


# -- validation ----------------------------------------------------------------------------
@pytest.mark.parametrize("kwargs,match", [
    (dict(control_points=np.zeros((5, 2)), knots=np.r_[0, 0, 0, 0, 1, 2, 2, 2], degree=3),
     "n \\+ degree \\+ 1 = 9"),
    (dict(control_points=np.zeros((5, 2)), knots=np.r_[0, 0, 0, 0, 2, 1, 2, 2, 2], degree=3),
     "non-decreasing: knots\\[4\\]"),
    (dict(control_points=np.zeros((5, 2)), knots=np.r_[0, 0, 0, 0.5, 1, 2, 2, 2, 2], degree=3),
     "clamped"),
    (dict(control_points=np.zeros((8, 2)),
          knots=np.r_[0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2], degree=3),
     "knots\\[4\\] has multiplicity"),
    (dict(control_points=np.zeros((5, 2)), knots=np.r_[0, 0, 0, 0, np.nan, 2, 2, 2, 2], degree=3),
     "knots contains a non-finite value .*nan.* at index 4"),
    (dict(control_points=[[0, 0], [1, np.inf], [2, 0], [3, 0], [4, 0]],
          knots=np.r_[0, 0, 0, 0, 1, 2, 2, 2, 2], degree=3), "row 1"),
    (dict(control_points=np.zeros((5, 4)), knots=np.r_[0, 0, 0, 0, 1, 2, 2, 2, 2], degree=3),
     "columns"),
    (dict(control_points=np.zeros((5, 2)), knots=np.r_[0, 0, 0, 0, 1, 2, 2, 2, 2], degree=1),
     "degree"),
    (dict(control_points=np.zeros((3, 2)), knots=np.r_[0, 0, 0, 0, 1, 1, 1], degree=3),
     "at least 4"),
    (dict(control_points=np.zeros((5, 2)), knots=np.arange(7.0), degree=3, closed=True),
     "n \\+ 2 degree \\+ 1 = 12"),
    (dict(control_points=np.zeros((5, 2)), knots=np.r_[0, 1, 1, 1, 1, 2], degree=3, closed=True),
     "multiplicity"),
    (dict(control_points=np.zeros((5, 2)), knots=np.r_[np.arange(11.0), 12.0], degree=3,
          closed=True), "periodic"),
])
def test_invalid_input(kwargs, match):
    with pytest.raises(InputError, match=match):
        BSplineCurve(**kwargs)


def test_builder_errors():
    with pytest.raises(InputError, match="n_ctrl"):
        fit_bspline(np.random.default_rng(0).normal(size=(10, 2)), 20)
    with pytest.raises(InputError, match="degree"):
        interpolate_bspline(np.random.default_rng(0).normal(size=(10, 2)), degree=1)
    with pytest.raises(InputError, match="coincident"):
        interpolate_bspline([[0, 0], [1, 1], [1, 1], [2, 0], [3, 1]])


def test_from_scipy_unclamped_open_spline():
    rng = np.random.default_rng(21)
    t = np.sort(rng.uniform(0, 10, 14))  # 14 knots, no multiplicity: not clamped
    spl = BSpline(t, rng.normal(size=(10, 2)), 3)
    c = BSplineCurve.from_scipy(spl)
    assert c.domain == (t[3], t[10])
    u = np.linspace(t[3], t[10], 500)
    for nu in range(3):
        np.testing.assert_allclose(c(u, nu), spl(u, nu), atol=1e-9 * np.abs(spl(u, nu)).max())


@pytest.mark.parametrize("spacing", ["chord", "uneven", "wild"])
def test_open_cubic_interpolant_matches_scipy_natural(spacing):
    # the O(m) tridiagonal path of interpolate_bspline against scipy's make_interp_spline
    from scipy.interpolate import make_interp_spline

    rng = np.random.default_rng(len(spacing))
    for m in (4, 5, 9, 57):
        pts = np.cumsum(rng.normal(size=(m, 3)), axis=0)
        if spacing == "chord":
            param = "chord"
        elif spacing == "uneven":
            param = np.cumsum(rng.uniform(0.05, 3.0, m))
        else:
            param = np.cumsum(np.r_[1.0, rng.choice([1e-3, 1.0, 100.0], m - 1)])
        c = interpolate_bspline(pts, param=param)
        t = curvefair.parameterize(pts, param)
        ref = make_interp_spline(t, pts, k=3, bc_type="natural", axis=0)
        np.testing.assert_array_equal(c.knots, ref.t)
        scale = np.abs(ref.c).max()
        np.testing.assert_allclose(c.control_points, ref.c, rtol=0, atol=1e-10 * scale)
        np.testing.assert_allclose(c(t), pts, rtol=0, atol=1e-10 * scale)


@pytest.mark.parametrize("spacing", ["uniform", "uneven", "wild"])
def test_natural_cubic_elimination_matches_pivoting_solve(spacing):
    # the compiled elimination without pivoting against LAPACK gbsv (partial pivoting) on the
    # same tridiagonal system, both coordinates, plus the interpolation conditions
    from curvefair._kernels.bspline import natural_cubic_kernel
    from curvefair.curves.bspline import _natural_cubic_gbsv

    rng = np.random.default_rng(7 + len(spacing))
    m = 400
    if spacing == "uniform":
        u = np.arange(m, dtype=float)
    elif spacing == "uneven":
        u = np.cumsum(rng.uniform(0.05, 3.0, m))
    else:
        u = np.cumsum(np.r_[0.0, rng.choice([1e-4, 1.0, 1e3], m - 1)])
    pts = np.cumsum(rng.normal(size=(m, 2)), axis=0)
    T = np.empty(m + 6)
    d = np.empty((m + 2, 2))
    assert natural_cubic_kernel(u, pts, T, d, np.empty(m))
    ref = _natural_cubic_gbsv(u, pts, T)
    scale = np.abs(ref).max()
    # the wild spacing makes the system ill-conditioned (control points ~1e7): both solves
    # interpolate to ~1e-16 relative but differ by ~2e-10 relative
    np.testing.assert_allclose(d[1:-1], ref, rtol=0, atol=1e-9 * scale)
    np.testing.assert_array_equal(d[[0, -1]], pts[[0, -1]])
    c = BSplineCurve(d, T, 3)
    np.testing.assert_allclose(c(u), pts, rtol=0, atol=1e-13 * scale)
    np.testing.assert_allclose(c(u[[0, -1]], 2), 0.0, atol=1e-8 * scale / (u[1] - u[0]) ** 2)


def test_interpolate_bspline_coincident_points_with_given_params():
    # the compiled coincident check raises as_points' message, also when params are given
    pts = np.c_[np.arange(8.0), np.zeros(8)]
    pts[5] = pts[4]
    with pytest.raises(InputError, match="indices 4 and 5"):
        interpolate_bspline(pts, param=np.arange(8.0))
    pts[5, 1] = 1e-9  # a tiny but real step is accepted
    interpolate_bspline(pts, param=np.arange(8.0))


@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("degree", [2, 3, 5])
def test_power_form_in_ranges_is_bitwise_one_pass(monkeypatch, closed, degree):
    """The power form (and the pair form of fair()'s tolerance check) computed in ranges of
    spans on two threads equals the one-pass result bit for bit: each span depends on its own
    knots and control points, and the basis reuse between equal knot patterns starts afresh
    in every range with the same values."""
    from curvefair import _threads
    from curvefair.curves import bspline as B
    from curvefair.fairing._tolerance import prime_power_forms

    rng = np.random.default_rng(degree + 10 * closed)
    x = np.sort(rng.uniform(0, 30, 400))  # non-uniform knots: the basis is recomputed
    c = interpolate_bspline(np.c_[x, np.sin(x)] + 0.01 * rng.normal(size=(400, 2)),
                            degree=degree, closed=closed)
    moved = np.asarray(c.control_points) + 1e-3 * rng.normal(size=(c.n_ctrl, 2))
    out = {}
    for th, pm in ((1, 10**9), (2, 7)):
        monkeypatch.setattr(_threads, "THREADS", th)
        monkeypatch.setattr(B, "POWER_FORM_PAR_MIN", pm)
        own = c.replace(control_points=np.asarray(c.control_points)).piecewise.coeffs
        new, figs = prime_power_forms(c, c.replace(control_points=moved))
        s = np.ascontiguousarray(c.spans, dtype=np.int64)
        pair = np.empty((s.size, degree + 1, 2))
        diff = np.empty_like(pair)
        B.power_form(np.ascontiguousarray(c.knots), degree, s, np.ascontiguousarray(moved),
                     closed, pair, np.ascontiguousarray(c.control_points), diff)
        out[th] = [np.asarray(own), np.asarray(new.piecewise.coeffs), pair, diff,
                   np.array(figs)]
    for a, b in zip(out[1], out[2], strict=True):
        assert np.array_equal(a, b, equal_nan=True)
    assert np.array_equal(out[1][1], out[1][2])  # the pair pass's own form is the curve's
    # and the form is the curve's: against scipy's BSpline at the span midpoints
    br = np.asarray(c.piecewise.breaks)
    mid, h = 0.5 * (br[:-1] + br[1:]), 0.5 * np.diff(br)
    val = sum(out[2][0][:, k, :] * h[:, None] ** k for k in range(degree + 1))
    t = np.asarray(c.knots)
    ctrl = np.asarray(c.control_points)[c.control_index(np.arange(t.size - degree - 1))]
    ref = BSpline(t, ctrl, degree)(mid)
    assert np.allclose(val, ref, rtol=1e-9, atol=1e-9 * np.abs(ref).max())


@pytest.mark.parametrize("p", [2, 3, 4, 5])
@pytest.mark.parametrize("closed", [False, True])
def test_few_parameters_without_the_power_form_are_bitwise_the_same(p, closed):
    """A few parameters of a long curve whose power form is not built are evaluated from their
    spans' forms only (fair() evaluates its input at the certificate's parameter after dropping
    the form): bitwise what the whole form gives, the form still not built; and scipy's
    BSpline agrees (independent de Boor evaluation)."""
    rng = np.random.default_rng(7 * p + closed)
    c = _random_closed(rng, 800, p) if closed else _random_open(rng, 800, p)
    ctrl, t = np.array(c.control_points), np.array(c.knots)
    br = np.unique(t[p:t.size - p])
    lo, hi = c.domain
    u = np.r_[rng.uniform(lo, hi, 3), br[5], br[-6], lo, hi]  # breaks: the segment chosen
    full = BSplineCurve(ctrl, t, p, closed=closed)
    _ = full.piecewise
    spl = full.to_scipy()
    w = lo + np.mod(u - lo, hi - lo) if closed else u  # a closed curve wraps its end to its start
    for nu in range(p + 1):
        bare = BSplineCurve(ctrl, t, p, closed=closed)
        got = bare(u, nu)
        assert "piecewise" not in bare.__dict__
        assert np.array_equal(got, full(u, nu))
        ref = spl(w, nu)
        assert np.allclose(got, ref, rtol=1e-9, atol=1e-9 * np.abs(ref).max())
    # many parameters (or a cached form): the whole form, built once
    many = BSplineCurve(ctrl, t, p, closed=closed)
    v = np.linspace(lo, hi, 50)
    assert np.array_equal(many(v), full(v)) and "piecewise" in many.__dict__


@pytest.mark.parametrize("knots", ["chord", "uniform", "repeated"])
@pytest.mark.parametrize("degree,l", [(3, 2), (3, 3), (2, 2), (5, 3)])
def test_gram_band_in_two_halves_is_bitwise_one_pass(monkeypatch, knots, degree, l):  # noqa: E741
    """A long open curve's Gram band is accumulated in two halves on two threads (the second
    from p spans before its own, into rows of its own): every row bitwise the one-pass sum,
    whether the spans reuse their neighbour's element matrix (uniform knots) or not, and
    across repeated interior knots (empty spans skipped)."""
    from curvefair import _threads
    from curvefair.curves import bspline as B

    rng = np.random.default_rng(degree + 7 * l)
    n = 300
    if knots == "repeated":
        inner = np.repeat(np.arange(1.0, 100.0), 2)[: n - degree - 1]
        t = np.r_[[0.0] * (degree + 1), inner, [inner[-1] + 1.0] * (degree + 1)]
        c = BSplineCurve(rng.normal(size=(t.size - degree - 1, 2)), t, degree)
    else:
        x = np.arange(n, dtype=float) if knots == "uniform" else np.sort(rng.uniform(0, 90, n))
        c = interpolate_bspline(np.c_[x, np.sin(x)] + 0.01 * rng.normal(size=(n, 2)),
                                degree=degree, param="uniform" if knots == "uniform" else "chord")
    def fresh():  # a new curve: no Gram band cached with its knots
        return BSplineCurve(np.array(c.control_points), np.array(c.knots), degree)

    monkeypatch.setattr(_threads, "THREADS", 1)
    one = np.asarray(fresh().gram_band(l))
    monkeypatch.setattr(_threads, "THREADS", 2)
    monkeypatch.setattr(B, "GRAM_PAR_MIN", 8)
    calls = []
    kernel = B.gram_kernel
    monkeypatch.setattr(B, "gram_kernel", lambda *a: calls.append(a[-1]) or kernel(*a))
    two = np.asarray(fresh().gram_band(l))
    assert len(calls) == 2 and calls[1] > 0  # the second half starts at a later row
    assert one.tobytes() == two.tobytes()
    assert np.abs(one).max() > 0


def test_gauss_nodes_made_once_and_handed_out_as_copies():
    # the Gram band's quadrature (made once per node count): numpy's leggauss mapped to [0, 1],
    # bit for bit; a caller writing into its arrays leaves the next caller's intact
    from curvefair.curves.bspline import _gauss

    for nq in (1, 2, 3, 4, 6):
        x, w = np.polynomial.legendre.leggauss(nq)
        a, b = _gauss(nq)
        assert np.array_equal(a, 0.5 * (x + 1.0)) and np.array_equal(b, 0.5 * w)
        a[:] = 7.0
        b[:] = 7.0
        c, d = _gauss(nq)
        assert np.array_equal(c, 0.5 * (x + 1.0)) and np.array_equal(d, 0.5 * w)
        assert abs(d.sum() - 1.0) < 4e-15  # the weights integrate 1 over [0, 1]
        # independently of leggauss: exact for every monomial up to degree 2 nq - 1
        for k in range(2 * nq):
            assert abs(np.sum(d * c**k) - 1.0 / (k + 1)) < 1e-14, (nq, k)
