"""C4 quintic interpolation (``interpolate_quintic``), checked against independent references.

References:

* scipy's ``make_interp_spline(k=5)`` -- a B-spline collocation solve, a different formulation
  and code base (its knots for not-a-knot ends are the data parameters without the second,
  third and the two matching ones at the right end; mixed ends are built from explicit knots);
* exact rational arithmetic (``fractions.Fraction``): a slow reference that builds every
  segment's quintic by inverting the 6 x 6 confluent Vandermonde matrix of its end data and
  solves the C3/C4 + natural end conditions by Gauss-Jordan elimination -- no closed-form
  Hermite coefficients and no stiffness matrix of the implementation are used;
* polynomials: the interpolant of data sampled from a global polynomial of degree <= 5 that
  satisfies the homogeneous end conditions is that polynomial (the family is computed as the
  null space of the conditions on the monomial coefficients);
* lines: chord-parameterised collinear data are interpolated by the line itself.
"""

from __future__ import annotations

from fractions import Fraction as Fr

import numpy as np
import pytest
from numpy.polynomial import Polynomial
from scipy.interpolate import make_interp_spline
from scipy.linalg import null_space

import curvefair as cf
from curvefair.curves.interpolate import quintic_hermite_data
from curvefair.errors import InputError


# ----------------------------------------------------------------------------------------------
# helpers
# ----------------------------------------------------------------------------------------------
def _walk(rng, n, dim, step=(0.2, 2.0)):
    """Random non-uniform polyline: random directions, step lengths in ``step``."""
    d = rng.normal(size=(n - 1, dim))
    d *= (rng.uniform(*step, n - 1) / np.linalg.norm(d, axis=1))[:, None]
    return np.vstack([rng.normal(size=(1, dim)), rng.normal(size=(1, dim)) + np.cumsum(d, axis=0)])


def _rel(a, b):
    return float(np.abs(np.asarray(a) - np.asarray(b)).max() / np.abs(np.asarray(b)).max())


def _scipy_derivs(t, pts, bc_type, knots=None):
    spl = make_interp_spline(t, pts, k=5, t=knots, bc_type=bc_type, axis=0)
    return spl(t, 1), spl(t, 2)


def _side_values(curve, x, nu):
    """r^(nu) at breakpoints ``x`` from the left and from the right segment."""
    pp = curve.piecewise
    seg = np.searchsorted(pp.breaks, x) - 1
    return (pp.evaluate(x, nu, segment=seg), pp.evaluate(x, nu, segment=seg + 1))


def _knot_jumps(curve, nu):
    pp = curve.piecewise
    x = pp.breaks[1:-1]
    lft, rgt = _side_values(curve, x, nu)
    return np.abs(lft - rgt).max(axis=-1), np.maximum(np.abs(lft), np.abs(rgt)).max()


# ----------------------------------------------------------------------------------------------
# exact rational reference (slow, independent)
# ----------------------------------------------------------------------------------------------
def _gauss_jordan(A, B):
    n = len(A)
    M = [A[i][:] + B[i][:] for i in range(n)]
    for k in range(n):
        piv = next(i for i in range(k, n) if M[i][k] != 0)
        M[k], M[piv] = M[piv], M[k]
        inv = 1 / M[k][k]
        M[k] = [v * inv for v in M[k]]
        for i in range(n):
            if i != k and M[i][k] != 0:
                f = M[i][k]
                M[i] = [a - f * c for a, c in zip(M[i], M[k], strict=True)]
    return [row[n:] for row in M]


def _monomial_derivs(y, k):
    """d^k/dy^k of y**j, j = 0..5, at y (exact)."""
    out = []
    for j in range(6):
        c = 1
        for q in range(k):
            c *= j - q
        out.append(Fr(0) if j < k else Fr(c) * y ** (j - k))
    return out


def _hermite_weights(h, x, nu):
    """Weights over the end data (p0, m0, s0, p1, m1, s1) of r^(nu)(x) for the degree-5
    polynomial on [0, h] with that data: V c = data, r^(nu)(x) = D c, w = V^-T D^T."""
    V = [_monomial_derivs(Fr(0), k) for k in range(3)] + [_monomial_derivs(h, k) for k in range(3)]
    VT = [[V[i][j] for i in range(6)] for j in range(6)]
    return [r[0] for r in _gauss_jordan(VT, [[v] for v in _monomial_derivs(x, nu)])]


def _exact_natural(p, t):
    """(r', r'') at the data of the natural C4 quintic spline, in exact arithmetic on the
    given float data, rounded once at the end."""
    n, dim = p.shape
    T = [Fr(float(v)) for v in t]
    P = [[Fr(float(v)) for v in row] for row in p]
    A = [[Fr(0)] * (2 * n) for _ in range(2 * n)]
    B = [[Fr(0)] * dim for _ in range(2 * n)]

    def add(row, seg, x, nu, sign):
        w = _hermite_weights(T[seg + 1] - T[seg], x, nu)
        for q in range(6):
            pt, kind = seg + q // 3, q % 3
            if kind == 0:
                for c in range(dim):
                    B[row][c] -= sign * w[q] * P[pt][c]
            else:
                A[row][2 * pt + kind - 1] += sign * w[q]

    row = 0
    for nu in (3, 4):  # natural ends
        add(row, 0, Fr(0), nu, 1)
        add(row + 1, n - 2, T[-1] - T[-2], nu, 1)
        row += 2
    for i in range(1, n - 1):  # C3 and C4 at the interior points
        for nu in (3, 4):
            add(row, i, Fr(0), nu, 1)
            add(row, i - 1, T[i] - T[i - 1], nu, -1)
            row += 1
    X = np.array([[float(v) for v in r] for r in _gauss_jordan(A, B)])
    return X[0::2], X[1::2]


# ----------------------------------------------------------------------------------------------
# 1. agreement with scipy's make_interp_spline(k=5)
# ----------------------------------------------------------------------------------------------
def _bc_cases(dim, rng):
    z = np.zeros(dim)
    v1, v2 = rng.normal(size=dim), rng.normal(size=dim)
    nat = [(3, z), (4, z)]
    return [
        ("natural", None, (nat, nat)),
        ("clamped", np.array([v1, v2]), ([(1, v1), (3, z)], [(1, v2), (3, z)])),
        (((2, v1), (1, v2)), None, ([(2, v1), (4, z)], [(1, v2), (3, z)])),
        (((2, v1), "natural"), None, ([(2, v1), (4, z)], nat)),
        (("clamped", (2, v2)), np.array([v1, v2]), ([(1, v1), (3, z)], [(2, v2), (4, z)])),
    ]


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("n", [2, 3, 4, 7, 25])
def test_matches_make_interp_spline(n, dim):
    rng = np.random.default_rng(100 * n + dim)
    for _ in range(3):
        pts = _walk(rng, n, dim)
        explicit = rng.uniform(0.1, 3.0, n).cumsum() * 10.0 ** rng.uniform(-2, 2)
        for param in ("chord", "centripetal", explicit):
            t = cf.parameterize(pts, param)
            for bc, et, sbc in _bc_cases(dim, rng):
                if n == 2 and bc == "natural":
                    continue  # not determined by the conditions (see test_two_points)
                q = cf.interpolate_quintic(pts, param, bc, end_tangents=et)
                d1, d2 = _scipy_derivs(t, pts, sbc)
                assert _rel(q.d1, d1) < 1e-9, bc
                assert _rel(q.d2, d2) < 1e-9, bc


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("n", [4, 5, 6, 7, 12, 40])
def test_not_a_knot_and_periodic_match_make_interp_spline(n, dim):
    rng = np.random.default_rng(7 * n + dim)
    z = np.zeros(dim)
    for _ in range(3):
        pts = _walk(rng, n, dim)
        t = cf.parameterize(pts)
        if n >= 6:
            q = cf.interpolate_quintic(pts, bc="not-a-knot")
            d1, d2 = _scipy_derivs(t, pts, None)  # scipy's default: not-a-knot
            assert _rel(q.d1, d1) < 1e-9 and _rel(q.d2, d2) < 1e-9
        # one not-a-knot end: scipy with explicit knots (data sites 1, 2 removed on that side)
        q = cf.interpolate_quintic(pts, bc=("not-a-knot", "natural"))
        knots = np.r_[[t[0]] * 6, t[3:-1], [t[-1]] * 6]
        d1, d2 = _scipy_derivs(t, pts, (None, [(3, z), (4, z)]), knots)
        assert _rel(q.d1, d1) < 1e-9 and _rel(q.d2, d2) < 1e-9
        v = rng.normal(size=dim)
        q = cf.interpolate_quintic(pts, bc=((1, v), "not-a-knot"))
        knots = np.r_[[t[0]] * 6, t[1:-3], [t[-1]] * 6]
        d1, d2 = _scipy_derivs(t, pts, ([(1, v), (3, z)], None), knots)
        assert _rel(q.d1, d1) < 1e-9 and _rel(q.d2, d2) < 1e-9
        # closed
        q = cf.interpolate_quintic(pts, bc="periodic")
        d1, d2 = _scipy_derivs(q.params, q.points, "periodic")
        assert _rel(q.d1, d1) < 1e-9 and _rel(q.d2, d2) < 1e-9


def test_general_end_conditions_of_the_internal_solver():
    # the fair loop's re-interpolation (fairing/local_hermite.py) passes given r''' / r''''
    # values and (r', r'') pairs: every pair of orders 1..4 against scipy
    rng = np.random.default_rng(11)
    pairs = [(3, 4), (1, 3), (2, 4), (1, 2), (1, 4), (2, 3), (4, 3), (3, 1)]
    for n in (2, 3, 8):
        pts = _walk(rng, n, 3)
        t = cf.parameterize(pts) * 7.0
        for lo in pairs:
            for ro in pairs:
                if n == 2 and set(lo) <= {3, 4} and set(ro) <= {3, 4}:
                    continue
                left = [(o, rng.normal(size=3)) for o in lo]
                right = [(o, rng.normal(size=3)) for o in ro]
                d1, d2 = quintic_hermite_data(pts, t, left, right, False)
                e1, e2 = _scipy_derivs(t, pts, (left, right))
                assert _rel(d1, e1) < 1e-9 and _rel(d2, e2) < 1e-9, (n, lo, ro)


# ----------------------------------------------------------------------------------------------
# 2. exact rational arithmetic
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("seed", range(3))
def test_matches_exact_rational_solution(seed):
    rng = np.random.default_rng(seed)
    n = 9 + seed
    pts = _walk(rng, n, 2 + seed % 2, step=(0.05, 3.0))  # spacing ratios up to 60
    q = cf.interpolate_quintic(pts)
    m, s = _exact_natural(pts, q.params)
    assert _rel(q.d1, m) < 1e-13
    assert _rel(q.d2, s) < 1e-13


# ----------------------------------------------------------------------------------------------
# 3. polynomial reproduction
# ----------------------------------------------------------------------------------------------
def _conditions(a, b, orders_a, orders_b):
    """Rows (over monomial coefficients c_0..c_5) of r^(k)(x) = 0 for the given orders."""
    rows = []
    for x, orders in ((a, orders_a), (b, orders_b)):
        for k in orders:
            rows.append([Polynomial(np.eye(6)[j]).deriv(k)(x) for j in range(6)])
    return np.array(rows).reshape(-1, 6)


_POLY_CASES = {
    # bc: (homogeneous orders at the left end, at the right end, given orders left, right,
    #      dimension of the reproduced family of polynomials of degree <= 5)
    "natural": ((3, 4), (3, 4), (), (), 3),  # r'''' = 0 at two points: quadratics only
    "clamped": ((3,), (3,), (1,), (1,), 4),  # r''' = c (t - a)(t - b)
    "second": ((4,), (4,), (2,), (2,), 4),  # cubics
    "mixed": ((3,), (4,), (1,), (2,), 4),
    "not-a-knot": ((), (), (), (), 6),  # every quintic
    "nak-natural": ((), (3, 4), (), (), 4),
}


@pytest.mark.parametrize("case", list(_POLY_CASES))
@pytest.mark.parametrize("dim", [2, 3])
def test_reproduces_polynomials(case, dim):
    hom_l, hom_r, giv_l, giv_r, fam = _POLY_CASES[case]
    rng = np.random.default_rng(len(case) + dim)
    for n in (6, 9, 20):
        t = np.r_[0.0, np.cumsum(rng.uniform(0.1, 1.0, n - 1))]
        t = -1.0 + 2.5 * t / t[-1]  # [-1, 1.5], non-uniform
        N = null_space(_conditions(t[0], t[-1], hom_l, hom_r))
        polys = [Polynomial(N @ rng.normal(size=N.shape[1])) for _ in range(dim)]
        assert N.shape[1] == fam
        pts = np.column_stack([p(t) for p in polys])

        def given(order, x, polys=polys):
            return np.array([p.deriv(order)(x) for p in polys])

        if case == "not-a-knot":
            bc = "not-a-knot"
        elif case == "nak-natural":
            bc = ("not-a-knot", "natural")
        elif case == "natural":
            bc = "natural"
        else:
            bc = ((giv_l[0], given(giv_l[0], t[0])), (giv_r[0], given(giv_r[0], t[-1])))
        q = cf.interpolate_quintic(pts, t, bc)
        d1 = np.column_stack([p.deriv(1)(t) for p in polys])
        d2 = np.column_stack([p.deriv(2)(t) for p in polys])
        # d2 to 5e-13: the samples are the polynomial rounded to float64, and the exact
        # (rational) spline of the rounded samples is up to ~2e-13 off the polynomial's r''
        assert _rel(q.d1, d1) < 1e-13, case
        assert _rel(q.d2, d2) < 5e-13, case
        u = np.linspace(t[0], t[-1], 301)
        assert _rel(q(u), np.column_stack([p(u) for p in polys])) < 1e-13


# ----------------------------------------------------------------------------------------------
# 4. straight lines
# ----------------------------------------------------------------------------------------------
def _line(rng):
    n = int(rng.integers(3, 40))
    dim = int(rng.integers(2, 4))
    u = np.cumsum(rng.uniform(0.05, 1.0, n)) * 10.0 ** rng.uniform(-1, 1)
    d = rng.normal(size=dim)
    d /= np.linalg.norm(d)
    return rng.normal(size=dim) + u[:, None] * d, d


def test_collinear_points_give_the_line():
    # 200 random collinear inputs, non-uniform spacing (ratios up to 20), 2-D and 3-D, chord
    # parameters: the exact spline is the line, r' = direction, r'' = 0. The data are the line
    # rounded to float64 (about eps |p| off it), and that is all the error allowed here.
    rng = np.random.default_rng(2024)
    eps = np.finfo(float).eps
    worst = 0.0
    for _ in range(200):
        pts, d = _line(rng)
        q = cf.interpolate_quintic(pts)
        h = np.diff(q.params)
        hloc = np.minimum(np.r_[h[0], h], np.r_[h, h[-1]])
        speed = np.linalg.norm(q.d1, axis=1)
        perp = np.linalg.norm(q.d1 - np.outer(q.d1 @ d, d), axis=1) / speed
        bend = np.linalg.norm(q.d2, axis=1) * hloc / speed
        noise = eps * np.abs(pts).max() / h.min()  # rounding of the data, relative
        assert perp.max() < max(1e-13, 10 * noise)
        assert bend.max() < max(1e-13, 10 * noise)
        worst = max(worst, perp.max(), bend.max())
        np.testing.assert_allclose(q.d1 @ d, 1.0, rtol=1e-13)
        a = cf.analyze(q)
        assert a.inflections == 0 and a.extrema == 0
    assert worst < 1e-12


def test_collinear_points_stay_on_the_line_for_any_parameterisation():
    # with uniform / centripetal parameters the spline runs along the line at a varying speed:
    # r' and r'' stay parallel to it
    rng = np.random.default_rng(5)
    for _ in range(50):
        pts, d = _line(rng)
        for param in ("uniform", "centripetal"):
            q = cf.interpolate_quintic(pts, param)
            for der in (q.d1, q.d2):
                perp = der - np.outer(der @ d, d)
                assert np.abs(perp).max() < 1e-12 * np.abs(der).max()


def test_collinear_exact_reference():
    # worst-case looking data (offset far from the origin, spacing ratios up to 60): the solve
    # reproduces the exact solution of the rounded data to rounding level
    rng = np.random.default_rng(9)
    for _ in range(3):
        u = np.cumsum(rng.uniform(0.05, 3.0, 14)) * 0.01
        d = np.array([0.6, -0.8])
        pts = np.array([30.0, 40.0]) + u[:, None] * d
        q = cf.interpolate_quintic(pts)
        m, s = _exact_natural(pts, q.params)
        assert np.abs(q.d1 - m).max() < 1e-14
        h = np.diff(q.params)
        assert np.abs(q.d2 - s).max() * h.min() < 1e-14


# ----------------------------------------------------------------------------------------------
# 5. continuity and end conditions
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("bc", ["natural", "clamped", "not-a-knot", "periodic",
                                ("not-a-knot", (2, [0.5, -1.0, 2.0]))])
def test_c4_at_knots(bc):
    rng = np.random.default_rng(3)
    pts = _walk(rng, 30, 3, step=(0.05, 2.0))
    q = cf.interpolate_quintic(pts, bc=bc, end_tangents=[[1.0, 0, 0], [0, 1.0, 0]])
    for nu in range(5):
        jumps, size = _knot_jumps(q, nu)
        assert jumps.max() < 1e-11 * size, nu
    jumps, size = _knot_jumps(q, 5)
    assert jumps.max() > 1e-3 * size  # r^(5) does jump: the check above can fail
    if bc == "periodic":
        pp = q.piecewise
        t0, t1 = q.domain
        for nu in range(5):
            a = pp.evaluate(np.array([t0]), nu, segment=np.array([0]))
            b = pp.evaluate(np.array([t1]), nu, segment=np.array([pp.n_segments - 1]))
            scale = max(np.abs(a).max(), np.abs(b).max())
            assert np.abs(a - b).max() < 1e-11 * scale, nu
        np.testing.assert_array_equal(q.d1[0], q.d1[-1])
        np.testing.assert_array_equal(q.d2[0], q.d2[-1])


@pytest.mark.parametrize("dim", [2, 3])
def test_end_conditions_hold(dim):
    rng = np.random.default_rng(8)
    pts = _walk(rng, 15, dim)
    v1, v2 = rng.normal(size=dim), rng.normal(size=dim)
    z = np.zeros(dim)

    def at(q, nu):
        ends = np.array(q.domain)
        pp = q.piecewise
        return pp.evaluate(ends, nu, segment=np.array([0, pp.n_segments - 1]))

    def size(q, nu):
        return np.abs(q(np.linspace(*q.domain, 200), nu)).max()

    q = cf.interpolate_quintic(pts)
    for nu in (3, 4):
        np.testing.assert_allclose(at(q, nu), 0.0, atol=1e-12 * size(q, nu))
    q = cf.interpolate_quintic(pts, bc="clamped", end_tangents=[v1, v2])
    np.testing.assert_allclose(at(q, 1), [v1, v2], rtol=0, atol=1e-13 * size(q, 1))
    np.testing.assert_allclose(at(q, 3), 0.0, atol=1e-12 * size(q, 3))
    q = cf.interpolate_quintic(pts, bc=((2, v1), (1, v2)))
    np.testing.assert_allclose(at(q, 2)[0], v1, rtol=0, atol=1e-13 * size(q, 2))
    np.testing.assert_allclose(at(q, 4)[0], z, atol=1e-12 * size(q, 4))
    np.testing.assert_allclose(at(q, 1)[1], v2, rtol=0, atol=1e-13 * size(q, 1))
    np.testing.assert_allclose(at(q, 3)[1], z, atol=1e-12 * size(q, 3))
    # not-a-knot: no jump of r^(5) at the second, third and the matching interior points
    q = cf.interpolate_quintic(pts, bc="not-a-knot")
    lft, rgt = _side_values(q, q.params[[1, 2, -3, -2]], 5)
    np.testing.assert_allclose(lft, rgt, rtol=0, atol=1e-10 * size(q, 5))
    lft, rgt = _side_values(q, q.params[3:-3], 5)
    assert np.abs(lft - rgt).max() > 1e-3 * size(q, 5)


def test_interpolates_and_scales_with_the_parameter():
    rng = np.random.default_rng(4)
    pts = _walk(rng, 20, 3)
    t = cf.parameterize(pts)
    q = cf.interpolate_quintic(pts, t)
    np.testing.assert_allclose(q(q.params), pts, rtol=0, atol=1e-13 * np.abs(pts).max())
    for c in (1e-6, 1e6):  # d1 / c, d2 / c**2 (parameter scale invariance, no over/underflow)
        qc = cf.interpolate_quintic(pts, t * c)
        np.testing.assert_allclose(qc.d1 * c, q.d1, rtol=1e-12, atol=1e-14 * np.abs(q.d1).max())
        np.testing.assert_allclose(qc.d2 * c**2, q.d2, rtol=1e-12,
                                   atol=1e-14 * np.abs(q.d2).max())
    # rigid motion: derivatives rotate with the points
    R = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    qr = cf.interpolate_quintic(pts @ R.T + [5.0, -2.0, 1.0], t)
    np.testing.assert_allclose(qr.d1, q.d1 @ R.T, atol=1e-12 * np.abs(q.d1).max())
    np.testing.assert_allclose(qr.d2, q.d2 @ R.T, atol=1e-12 * np.abs(q.d2).max())


def test_large_input():
    # O(n) banded solve: 200 000 points, C4 at every knot and agreement with scipy
    rng = np.random.default_rng(6)
    n = 200_000
    s = np.linspace(0.0, 50.0, n)
    pts = np.c_[s, np.sin(s), np.cos(0.3 * s)] + 1e-3 * (50.0 / n) * rng.normal(size=(n, 3))
    q = cf.interpolate_quintic(pts)
    d1, d2 = _scipy_derivs(q.params, pts, ([(3, np.zeros(3)), (4, np.zeros(3))],) * 2)
    # scipy's own accuracy limits this comparison (its spline, rebuilt in Hermite form, has
    # C3/C4 jumps of ~1e-6 relative at this size); ours are at the 1e-12 level
    assert _rel(q.d1, d1) < 1e-8 and _rel(q.d2, d2) < 1e-6
    for nu in (3, 4):
        jumps, size = _knot_jumps(q, nu)
        assert jumps.max() < 1e-10 * size


# ----------------------------------------------------------------------------------------------
# 6. small inputs and errors
# ----------------------------------------------------------------------------------------------
def test_two_points():
    # natural ends leave r = line + c (t - t0)(t - t1) free; the line is returned
    q = cf.interpolate_quintic([[0.0, 0.0], [3.0, 4.0]])
    np.testing.assert_allclose(q.d1, [[0.6, 0.8]] * 2, rtol=1e-15)
    np.testing.assert_array_equal(q.d2, 0.0)
    q = cf.interpolate_quintic([[0.0, 0.0], [3.0, 4.0]], bc="clamped",
                               end_tangents=[[1.0, 0.0], [0.0, 1.0]])
    np.testing.assert_allclose(q.d1, [[1.0, 0.0], [0.0, 1.0]], atol=1e-15)


def test_three_point_periodic():
    q = cf.interpolate_quintic([[0.0, 0.0], [2.0, 0.0], [1.0, 1.5]], bc="periodic")
    assert q.closed and q.n_points == 4
    d1, d2 = _scipy_derivs(q.params, q.points, "periodic")
    assert _rel(q.d1, d1) < 1e-10 and _rel(q.d2, d2) < 1e-10


@pytest.mark.parametrize("call, fragment", [
    (lambda: cf.interpolate_quintic(np.eye(5)[:, :2] + np.arange(5)[:, None], bc="not-a-knot"),
     "at least 6"),
    (lambda: cf.interpolate_quintic([[0, 0], [1, 1], [2, 0]], bc=("not-a-knot", "natural")),
     "at least 4"),
    (lambda: cf.interpolate_quintic([[0, 0], [1, 1], [2, 0]], bc="clamped"), "end_tangents"),
    (lambda: cf.interpolate_quintic([[0, 0], [1, 1], [2, 0]], bc=((3, [0, 0]), "natural")),
     "order must be 1 or 2"),
    (lambda: cf.interpolate_quintic([[0, 0], [1, 1], [2, 0]], bc="foo"), "'natural'"),
])
def test_errors(call, fragment):
    with pytest.raises(InputError) as exc:
        call()
    assert fragment in str(exc.value)


@pytest.mark.parametrize("own", [True, False])
def test_band_solve_in_place_and_on_a_copy(own):
    """``_solve`` factors the band made by ``_banded`` in place (no copy of it) and copies any
    other band first; both give scipy's ``solve_banded`` on the same matrix (an independent
    LAPACK call through scipy's checks and conversions)."""
    from scipy.linalg import solve_banded

    from curvefair.curves import interpolate as ip

    rng = np.random.default_rng(11)
    h = rng.uniform(0.3, 2.0, 9)
    dsc, ab = ip._banded(h, 10, 9, 3, 3)
    rhs = rng.normal(size=(20, 2))
    want = solve_banded((3, 3), np.array(ab), rhs)
    band = ab if own else np.array(ab)  # a C-ordered copy: not _banded's layout
    before = np.array(band)
    got = ip._solve(band, 3, 3, rhs)
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12 * np.abs(want).max())
    # in place: _banded's band was factored (overwritten); a copy leaves the argument alone
    assert np.array_equal(band, before) != own


def test_natural_and_periodic_ends_solve_by_banded_cholesky_else_lu(monkeypatch):
    """r''' and r'''' given at both ends (natural ends; wang-quintic re-interpolates with the
    input's own values) and the periodic chain are symmetric positive definite: solved by
    LAPACK's banded Cholesky on the 4-row lower band. Every other end condition, or a failed
    Cholesky, goes to the general band LU, which gives the same spline to rounding (the
    exact-arithmetic comparison above checks the Cholesky path to 1e-13)."""
    from curvefair.curves import interpolate as ip

    spd: list[tuple[int, int]] = []
    lu: list[tuple[int, int]] = []
    real_spd, real_lu = ip._solve_spd, ip._solve

    def spy_spd(ab, rhs):
        spd.append(ab.shape)
        return real_spd(ab, rhs)

    def spy_lu(ab, lo, up, rhs):
        lu.append(ab.shape)
        return real_lu(ab, lo, up, rhs)

    monkeypatch.setattr(ip, "_solve_spd", spy_spd)
    monkeypatch.setattr(ip, "_solve", spy_lu)
    rng = np.random.default_rng(21)
    pts = _walk(rng, 40, 3)
    t = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))]
    ring = np.c_[np.cos(np.linspace(0, 6, 30)), np.sin(np.linspace(0, 6, 30))]
    ring += 0.01 * rng.normal(size=ring.shape)
    given = ([(3, rng.normal(size=3)), (4, rng.normal(size=3))],
             [(4, rng.normal(size=3)), (3, rng.normal(size=3))])
    def dd(q):
        return q.d1, q.d2

    runs = [lambda: dd(cf.interpolate_quintic(pts)),
            lambda: dd(cf.interpolate_quintic(ring, bc="periodic")),
            lambda: quintic_hermite_data(pts, t, *given, False)]
    first = [r() for r in runs]
    assert spd == [(4, 80), (4, 60), (4, 80)] and lu == []
    cf.interpolate_quintic(pts, bc="not-a-knot")
    cf.interpolate_quintic(pts, bc=((1, np.ones(3)), "natural"))
    assert len(spd) == 3 and len(lu) == 2
    monkeypatch.setattr(ip, "_solve_spd", lambda ab, rhs: None)  # as if Cholesky failed
    for run, (d1, d2) in zip(runs, first, strict=True):
        e1, e2 = run()
        assert _rel(d1, e1) < 1e-13 and _rel(d2, e2) < 1e-13
    assert len(lu) == 5


def _whole_first_guess(h, delta, periodic):
    # the first guess as one whole-array computation (how it was made before it was made by
    # blocks): np.roll for the periodic neighbours, slices for the open interior
    sig = delta / h[:, None]
    if periodic:
        a, b = np.roll(h, 1)[:, None], h[:, None]
        sa, sb = np.roll(sig, 1, axis=0), sig
        return (b * sa + a * sb) / (a + b), 2.0 * (sb - sa) / (a + b)
    n = h.size + 1
    m = np.empty((n, sig.shape[1]))
    s = np.zeros_like(m)
    if n == 2:
        m[:] = sig[0]
        return m, s
    a, b = h[:-1, None], h[1:, None]
    m[1:-1] = (b * sig[:-1] + a * sig[1:]) / (a + b)
    s[1:-1] = 2.0 * (sig[1:] - sig[:-1]) / (a + b)
    s[0], s[-1] = s[1], s[-2]
    m[0] = sig[0] - 0.5 * h[0] * s[0]
    m[-1] = sig[-1] + 0.5 * h[-1] * s[-1]
    return m, s


def test_first_guess_by_blocks_is_the_whole_one_and_fits_quadratics():
    """The solver's first guess is made a block of points at a time (``_guess_rows``): every
    block of 1, 2, 3, 7 or 1000 points, open and periodic, 2-50 points over six decades, is
    bit for bit the whole-array computation's rows (a periodic curve's row ``npt`` is row 0).
    Independently, the three-point estimates are exact for data from a quadratic."""
    from curvefair.curves import interpolate as ip

    rng = np.random.default_rng(31)
    blocks = 0
    for n in (2, 3, 4, 5, 8, 50):
        for periodic in (False, True):
            if periodic and n < 4:
                continue
            pts = rng.normal(size=(n, 3)) * 10.0 ** rng.uniform(-3, 3, (n, 1))
            if periodic:
                pts[-1] = pts[0]
            h = rng.uniform(0.01, 5.0, n - 1)
            m, s = _whole_first_guess(h, np.diff(pts, axis=0), periodic)
            npt = n - 1 if periodic else n
            for size in (1, 2, 3, 7, 1000):
                for a in range(0, npt, size):
                    b = min(a + size, npt)
                    mb, sb = ip._guess_rows(h, pts, a, b, periodic)
                    assert mb.tobytes() == m[a:b].tobytes() and sb.tobytes() == s[a:b].tobytes()
                    blocks += 1
            if periodic:
                mb, sb = ip._guess_rows(h, pts, npt, npt + 1, True)
                assert mb.tobytes() == m[:1].tobytes() and sb.tobytes() == s[:1].tobytes()
    assert blocks > 250
    # a quadratic r(t) = c0 + c1 t + c2 t^2 at uneven t: m = r'(t_i), s = r''(t_i) = 2 c2
    t = np.cumsum(rng.uniform(0.2, 2.0, 12))
    c = rng.normal(size=(3, 2))
    pts = c[0] + t[:, None] * c[1] + t[:, None] ** 2 * c[2]
    m, s = ip._guess_rows(np.diff(t), pts, 0, 12, False)
    np.testing.assert_allclose(m, c[1] + 2.0 * t[:, None] * c[2], rtol=1e-11, atol=1e-11)
    np.testing.assert_allclose(s, np.broadcast_to(2.0 * c[2], s.shape), rtol=1e-11, atol=1e-11)
