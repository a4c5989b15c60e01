"""Hermite splines and interpolation, checked against scipy's independent implementations."""

import numpy as np
import pytest
from scipy.interpolate import BPoly, CubicHermiteSpline

import curvefair as cf
from curvefair.errors import CurvefairError, InputError


def _random_data(rng, n, dim):
    t = np.cumsum(rng.uniform(0.2, 2.0, n))
    return rng.normal(size=(n, dim)), rng.normal(size=(n, dim)), rng.normal(size=(n, dim)), t


@pytest.mark.parametrize("dim", [2, 3])
def test_cubic_hermite_matches_scipy(dim):
    rng = np.random.default_rng(1)
    p, m, _, t = _random_data(rng, 9, dim)
    c = cf.CubicHermite(p, m, t)
    ref = CubicHermiteSpline(t, p, m, axis=0)
    u = np.linspace(t[0], t[-1], 777)
    for nu in range(4):
        np.testing.assert_allclose(c(u, nu), ref(u, nu), rtol=1e-11, atol=1e-11)
    assert c.degree == 3 and c.coefficients().shape == (8, 4, dim)


@pytest.mark.parametrize("dim", [2, 3])
def test_quintic_hermite_matches_scipy_bpoly(dim):
    rng = np.random.default_rng(2)
    p, m, s, t = _random_data(rng, 7, dim)
    q = cf.QuinticHermite(p, m, s, t)
    ref = BPoly.from_derivatives(t, np.stack([p, m, s], axis=1))
    u = np.linspace(t[0], t[-1], 555)
    for nu in range(6):
        np.testing.assert_allclose(q(u, nu), ref(u, nu), rtol=1e-9, atol=1e-9)
    assert q.degree == 5 and q.coefficients().shape == (6, 6, dim)


def _jumps(curve, nu):
    pp = curve.piecewise
    b = pp.breaks[1:-1]
    seg = np.arange(b.size)
    return np.abs(pp.evaluate(b, nu, segment=seg) - pp.evaluate(b, nu, segment=seg + 1)).max()


@pytest.mark.parametrize("param", ["uniform", "chord", "centripetal"])
@pytest.mark.parametrize("dim", [2, 3])
def test_interpolate_cubic_natural_is_c2_and_natural(param, dim):
    rng = np.random.default_rng(3)
    pts = np.cumsum(rng.normal(size=(12, dim)), axis=0)
    c = cf.interpolate_cubic(pts, param=param)
    np.testing.assert_allclose(c(c.params), pts, atol=1e-12)
    scale = np.abs(c.piecewise.coeffs[:, 2]).max()
    assert _jumps(c, 1) < 1e-10 * scale and _jumps(c, 2) < 1e-10 * scale
    np.testing.assert_allclose(c(np.array(c.domain), 2), 0, atol=1e-10 * scale)


def test_interpolate_cubic_bcs():
    rng = np.random.default_rng(4)
    pts = np.cumsum(rng.normal(size=(10, 2)), axis=0)
    left, right = np.array([1.0, 2.0]), np.array([-3.0, 0.5])
    c = cf.interpolate_cubic(pts, bc="clamped", end_tangents=[left, right])
    np.testing.assert_allclose(c(np.array(c.domain), 1), [left, right], atol=1e-12)
    c = cf.interpolate_cubic(pts, bc=((2, [0.3, 0.1]), (1, right)))
    np.testing.assert_allclose(c(c.domain[0], 2), [0.3, 0.1], atol=1e-10)
    np.testing.assert_allclose(c(c.domain[1], 1), right, atol=1e-12)
    c = cf.interpolate_cubic(pts, bc="not-a-knot")
    pp = c.piecewise
    np.testing.assert_allclose(pp.coeffs[0, 3], pp.coeffs[1, 3], rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("dim", [2, 3])
def test_interpolate_periodic_closes_and_is_smooth_across_seam(dim):
    s = np.linspace(0, 2 * np.pi, 13)[:-1]
    pts = np.column_stack([np.cos(s), 0.6 * np.sin(s)]
                          + ([0.1 * np.sin(2 * s)] if dim == 3 else []))
    for build, order in ((cf.interpolate_cubic, 2), (cf.interpolate_quintic, 4)):
        c = build(pts, bc="periodic")
        assert c.closed and c.n_points == 13
        np.testing.assert_array_equal(c.points[0], c.points[-1])
        t0, t1 = c.domain
        pp = c.piecewise
        for nu in range(order + 1):
            a = pp.evaluate(np.array([t0]), nu, segment=np.array([0]))
            b = pp.evaluate(np.array([t1]), nu, segment=np.array([pp.n_segments - 1]))
            np.testing.assert_allclose(a, b, atol=1e-8)
        # periodic evaluation wraps
        np.testing.assert_allclose(c(t0 + 0.3), c(t1 + 0.3), atol=1e-12)


def test_interpolate_quintic_natural_c4():
    rng = np.random.default_rng(5)
    pts = np.cumsum(rng.normal(size=(11, 3)), axis=0)
    q = cf.interpolate_quintic(pts)
    np.testing.assert_allclose(q(q.params), pts, atol=1e-11)
    scale = np.abs(q.piecewise.coeffs).max()
    for nu in range(5):
        assert _jumps(q, nu) < 1e-8 * scale
    ends = np.array(q.domain)
    np.testing.assert_allclose(q(ends, 3), 0, atol=1e-8 * scale)
    np.testing.assert_allclose(q(ends, 4), 0, atol=1e-8 * scale)
    tan = np.array([[1.0, 0, 0], [0, 1.0, 0]])
    q = cf.interpolate_quintic(pts, bc="clamped", end_tangents=tan)
    np.testing.assert_allclose(q(ends, 1), tan, atol=1e-10)
    q = cf.interpolate_quintic(pts, bc=((2, [1.0, 0, 0]), "natural"))
    np.testing.assert_allclose(q(ends[0], 2), [1.0, 0, 0], atol=1e-9)


def test_parameterize():
    pts = [[0, 0], [3, 4], [3, 5]]
    np.testing.assert_allclose(cf.parameterize(pts, "chord"), [0, 5, 6])
    np.testing.assert_allclose(cf.parameterize(pts, "centripetal"), [0, np.sqrt(5), np.sqrt(5) + 1])
    np.testing.assert_allclose(cf.parameterize(pts, "uniform"), [0, 1, 2])


def test_immutable():
    c = cf.interpolate_cubic([[0, 0], [1, 1], [2, 0]])
    for arr in (c.points, c.tangents, c.params, c.piecewise.coeffs):
        with pytest.raises(ValueError):
            arr[0] = 1.0
    c2 = c.replace(points=c.points + 1.0)
    assert c2 is not c and np.allclose(c2.points, c.points + 1.0)


@pytest.mark.parametrize(
    "call, fragment",
    [
        (lambda: cf.interpolate_cubic([[0, 0], [np.nan, 1], [2, 2]]), "row 1"),
        (lambda: cf.interpolate_cubic([[0, 0], [1, 1], [1, 1], [2, 0]]), "indices 1 and 2"),
        (lambda: cf.interpolate_cubic([[0, 0, 0, 0], [1, 1, 1, 1]]), "columns"),
        (lambda: cf.interpolate_cubic([[0, 0]]), "at least 2"),
        (lambda: cf.interpolate_cubic([0, 1, 2]), "shape (n, dim)"),
        (lambda: cf.interpolate_cubic([[0, 0], [1, 1], [2, 0]], param="foo"), "'chord'"),
        (lambda: cf.interpolate_cubic([[0, 0], [1, 1], [2, 0]], bc="bar"), "'natural'"),
        (lambda: cf.interpolate_cubic([[0, 0], [1, 1], [2, 0]], param=[0, 2, 1]), "param[1]"),
        (lambda: cf.interpolate_cubic([[0, 0], [1, 1], [2, 0]], bc="clamped"), "end_tangents"),
        (lambda: cf.CubicHermite([[0, 0], [1, 1]], [[1, 0]], [0, 1]), "tangents"),
        (lambda: cf.CubicHermite([[0, 0], [1, 1]], [[1, 0], [1, 0]], [0, np.inf]), "params"),
        (lambda: cf.CubicHermite([[0, 0], [1, 1], [2, 0]], [[1, 0]] * 3, [0, 1, 2], closed=True),
         "points[0]"),
        (lambda: cf.interpolate_cubic([[0, 0], [1, 1], [2, 0]])(99.0), "outside"),
        (lambda: cf.interpolate_cubic([[0, 0], [1, 1], [2, 0]])(0.5, nu=4), "nu"),
        (lambda: cf.interpolate_quintic(np.eye(3)[:, :2], bc="not-a-knot"), "at least 6"),
    ],
)
def test_bad_input_errors(call, fragment):
    with pytest.raises(CurvefairError) as exc:
        call()
    assert isinstance(exc.value, (InputError, ValueError))
    assert fragment in str(exc.value)


@pytest.mark.parametrize("dim", [2, 3])
def test_power_form_kernels_exact_and_machine_independent(dim):
    """The compiled power forms (one pass, no temporaries) against exact rational arithmetic:
    every coefficient within 2 ulp of the magnitude of its terms, on spacings over six
    decades; the powers of the width correctly rounded (``pow``), so the numbers do not
    depend on the CPU; and within rounding of the vectorised numpy formulas."""
    from fractions import Fraction as Fr

    from curvefair._kernels.hermite_power import (
        cubic_power_reference,
        quintic_power_reference,
    )
    from curvefair.curves.hermite import (
        cubic_hermite_coefficients,
        quintic_hermite_coefficients,
    )

    rng = np.random.default_rng(7)
    eps = np.finfo(float).eps
    for n in (2, 3, 40):
        t = np.cumsum(10.0 ** rng.uniform(-3, 3, n))
        p, m, s = (rng.normal(size=(n, dim)) * 10.0 ** rng.uniform(-2, 4) for _ in range(3))
        c = cubic_hermite_coefficients(p, m, t)
        q = quintic_hermite_coefficients(p, m, s, t)
        assert c.shape == (n - 1, 4, dim) and q.shape == (n - 1, 6, dim)
        for i in range(n - 1):
            D = Fr(t[i + 1]) - Fr(t[i])
            for d in range(dim):
                p0, p1, m0, m1, s0, s1 = (Fr(v) for v in (p[i, d], p[i + 1, d], m[i, d],
                                                          m[i + 1, d], s[i, d], s[i + 1, d]))
                dp = p1 - p0
                exact = [(p0, abs(p0)), (m0, abs(m0)),
                         (3 * dp / D**2 - (2 * m0 + m1) / D,
                          abs(3 * dp / D**2) + abs((2 * m0 + m1) / D)),
                         (-2 * dp / D**3 + (m0 + m1) / D**2,
                          abs(2 * dp / D**3) + abs((m0 + m1) / D**2))]
                for j, (v, size) in enumerate(exact):
                    assert abs(Fr(c[i, j, d]) - v) <= 16 * eps * size, (i, j, d)
                b1 = dp - m0 * D - s0 * D**2 / 2
                b2 = m1 - m0 - s0 * D
                b3 = s1 - s0
                qx = [(p0, abs(p0)), (m0, abs(m0)), (s0 / 2, abs(s0 / 2)),
                      ((10 * b1 - 4 * b2 * D + b3 * D**2 / 2) / D**3,
                       (abs(10 * b1) + abs(4 * b2 * D) + abs(b3 * D**2 / 2)) / D**3),
                      ((-15 * b1 + 7 * b2 * D - b3 * D**2) / D**4,
                       (abs(15 * b1) + abs(7 * b2 * D) + abs(b3 * D**2)) / D**4),
                      ((6 * b1 - 3 * b2 * D + b3 * D**2 / 2) / D**5,
                       (abs(6 * b1) + abs(3 * b2 * D) + abs(b3 * D**2 / 2)) / D**5)]
                # b1, b2 themselves cancel: their rounding is relative to their terms
                slack = (abs(dp) + abs(m0 * D) + abs(s0 * D**2)) * 64 * eps
                for j, (v, size) in enumerate(qx):
                    bound = 64 * eps * size + (0 if j < 3 else 15 * slack / D ** j)
                    assert abs(Fr(q[i, j, d]) - v) <= bound, (i, j, d)
        # the widths' cubes are the correctly rounded ones (pow), whatever the CPU: with
        # p = (0, 1) and zero tangents, a_3 = -2 / D^3 is one rounding of the rounded cube
        for x in np.diff(t):
            one = cubic_hermite_coefficients(np.array([[0.0] * dim, [1.0] * dim]),
                                             np.zeros((2, dim)), np.array([0.0, x]))
            assert one[0, 3, 0] == -2.0 / float(Fr(float(x)) ** 3)
        # and within rounding of numpy's vectorised formulas
        np.testing.assert_allclose(c, cubic_power_reference(p, m, t), rtol=1e-9,
                                   atol=1e-12 * float(np.abs(c).max()))
        np.testing.assert_allclose(q, quintic_power_reference(p, m, s, t), rtol=1e-6,
                                   atol=1e-9 * float(np.abs(q).max()))
        # strided (non-contiguous) input gives the same numbers
        assert np.array_equal(cubic_hermite_coefficients(np.asfortranarray(p), m, t), c)


def test_is_chord_interpolant_marker_and_full_check():
    """fair()'s guard recognises the curve a point file is read as: at once when
    interpolate_cubic made it, otherwise by rebuilding it; affine changes of parameter
    allowed, anything else refused."""
    from curvefair.fairing._guard import is_chord_interpolant

    rng = np.random.default_rng(3)
    s = np.linspace(0, 3, 30)
    P = np.c_[s, np.sin(s)] + 1e-3 * rng.normal(size=(30, 2))
    c = cf.interpolate_cubic(P, "chord", "natural")
    assert c._chord_natural and is_chord_interpolant(c)
    ring = np.c_[np.cos(2 * np.pi * s[:-1] / 3), np.sin(2 * np.pi * s[:-1] / 3)]
    cp = cf.interpolate_cubic(ring, "chord", "periodic")
    assert cp._chord_natural and cp.closed and is_chord_interpolant(cp)
    # the same data built by hand (no marker): the full check agrees, for both
    for k in (c, cp):
        bare = cf.CubicHermite(k.points, k.tangents, k.params, closed=k.closed)
        assert not bare._chord_natural and is_chord_interpolant(bare)
        # an affine change of parameter: t -> 2.5 t + 7, tangents / 2.5
        aff = cf.CubicHermite(k.points, np.asarray(k.tangents) / 2.5,
                              2.5 * np.asarray(k.params) + 7.0, closed=k.closed)
        assert is_chord_interpolant(aff)
    # not the chord natural interpolant: other parameters, other ends, moved tangents
    assert not cf.interpolate_cubic(P, "uniform", "natural")._chord_natural
    assert not is_chord_interpolant(cf.interpolate_cubic(P, "uniform", "natural"))
    assert not is_chord_interpolant(cf.interpolate_cubic(P, "chord", "not-a-knot"))
    bent = np.array(c.tangents)
    bent[10] *= 1.01
    assert not is_chord_interpolant(cf.CubicHermite(c.points, bent, c.params))
    # a replaced curve does not inherit the marker: moved points are checked again
    moved = np.array(c.points)
    moved[5, 1] += 0.01
    r = c.replace(points=moved)
    assert not r._chord_natural and not is_chord_interpolant(r)


def test_domain_without_power_form():
    """A Hermite curve's domain is its first and last parameter, read without building the
    power form (a read-back check of a 1e6-point file asked for it and paid 0.35 s)."""
    c = cf.interpolate_cubic(np.c_[np.arange(6.0), np.arange(6.0) ** 2], "chord")
    q = cf.interpolate_quintic(np.c_[np.arange(6.0), np.arange(6.0) ** 2])
    for k in (c, q):
        dom = k.domain
        assert "piecewise" not in k.__dict__  # not built
        assert dom == (float(k.piecewise.breaks[0]), float(k.piecewise.breaks[-1]))


def test_construction_never_writes_the_callers_arrays_and_shares_frozen_ones():
    """The curve validates the caller's float64 arrays where they are and freezes its own
    copy: a closed curve's seam snapped to row 0 is snapped in that copy, the caller's array
    keeps its values; another curve's (frozen, whole) arrays are shared, not copied; a frozen
    part of a larger array is copied (the curve does not keep the larger one alive)."""
    a = np.linspace(0.0, 2 * np.pi, 9)
    P = np.c_[np.cos(a), np.sin(a)]
    P[-1] = P[0] + 1e-13  # within the seam tolerance, not equal
    T = np.c_[-np.sin(a), np.cos(a)]
    T[-1] = T[0]
    keep_P, keep_T = P.copy(), T.copy()
    c = cf.CubicHermite(P, T, a, closed=True)
    np.testing.assert_array_equal(P, keep_P)
    np.testing.assert_array_equal(T, keep_T)
    assert c.points[-1].tobytes() == c.points[0].tobytes()
    assert not np.shares_memory(c.points, P)
    P[2] = 7.0  # the caller changes its array: the curve does not see it
    assert c.points[2, 0] != 7.0
    d = cf.CubicHermite(c.points, c.tangents, c.params, closed=True)
    assert np.shares_memory(d.points, c.points) and np.shares_memory(d.params, c.params)
    part = cf.CubicHermite(c.points[:4], c.tangents[:4], c.params[:4])
    assert not np.shares_memory(part.points, c.points)
    r = cf.interpolate_cubic(c.points[:-1])  # a reader's rebuild of the distinct points
    assert not r.points.flags.writeable
    Q = np.c_[np.arange(6.0), np.arange(6.0) ** 2]
    keep_Q = Q.copy()
    cf.interpolate_cubic(Q, bc="periodic")  # closing the points never writes Q
    np.testing.assert_array_equal(Q, keep_Q)
