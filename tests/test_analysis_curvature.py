"""Curvature, torsion and dkappa/ds, checked against geometry and finite differences.

Independent references: circles and helices (closed-form curvature and torsion), finite
differences of the curve's POSITIONS only (tangent angle for planar curves, Frenet formulas with
finite-difference derivatives in 3-D), never curvefair's derivative formulas.
"""

import numpy as np
import pytest

import curvefair as cf
from curvefair.analysis import curvature_derivative
from curvefair.errors import InputError


def _fd_derivs(curve, t, d):
    """r', r'', r''' by central differences of positions (5-point stencils; exact for a cubic
    piece when the stencil stays inside one segment). ``d``: scalar or one step per point."""
    t = np.asarray(t, dtype=float)
    d1 = np.broadcast_to(np.asarray(d, dtype=float), t.shape)
    d = d1[:, None]
    p2, p1, p0, m1, m2 = (curve(t + 2 * d1), curve(t + d1), curve(t), curve(t - d1),
                          curve(t - 2 * d1))
    r1 = (-p2 + 8 * p1 - 8 * m1 + m2) / (12 * d)
    r2 = (-p2 + 16 * p1 - 30 * p0 + 16 * m1 - m2) / (12 * d**2)
    r3 = (p2 - 2 * p1 + 2 * m1 - m2) / (2 * d**3)
    return r1, r2, r3


def _interior_params(curve, per_segment=3, margin=0.2):
    """Parameters strictly inside segments, and the width of their segment."""
    b = curve.piecewise.breaks
    f = np.linspace(margin, 1 - margin, per_segment)
    t = (b[:-1, None] + np.diff(b)[:, None] * f[None, :]).ravel()
    return t, np.repeat(np.diff(b), per_segment)


@pytest.mark.parametrize("R", [0.01, 1.0, 250.0])
def test_circle_curvature_is_one_over_r_and_signed(R):
    a = np.linspace(0, 2 * np.pi, 201)[:-1]
    ccw = cf.interpolate_cubic(np.c_[R * np.cos(a), R * np.sin(a)], bc="periodic")
    cw = cf.interpolate_cubic(np.c_[R * np.cos(a), -R * np.sin(a)], bc="periodic")
    u = np.linspace(*ccw.domain, 1001)
    k = cf.curvature(ccw, u)
    assert isinstance(k, np.ndarray) and k.shape == u.shape
    np.testing.assert_allclose(k, 1.0 / R, rtol=1e-4)  # spline error O(h^2) ~ 1e-5 here
    np.testing.assert_allclose(cf.curvature(cw, u), -1.0 / R, rtol=1e-4)
    k0 = cf.curvature(ccw, 0.3 * ccw.domain[1])
    assert isinstance(k0, float) and k0 == pytest.approx(1.0 / R, rel=1e-4)


def test_planar_curvature_vs_tangent_angle_finite_differences():
    # kappa = d(theta)/ds, theta the tangent angle from finite differences of positions
    rng = np.random.default_rng(1)
    pts = np.cumsum(rng.normal(size=(12, 2)), axis=0)
    c = cf.interpolate_cubic(pts, param="centripetal")
    t, w = _interior_params(c)
    d = 1e-5 * w
    r1p, _, _ = _fd_derivs(c, t + d, 0.05 * w)
    r1m, _, _ = _fd_derivs(c, t - d, 0.05 * w)
    th_p = np.arctan2(r1p[:, 1], r1p[:, 0])
    th_m = np.arctan2(r1m[:, 1], r1m[:, 0])
    dth = np.angle(np.exp(1j * (th_p - th_m)))
    ds = np.linalg.norm(c(t + d) - c(t - d), axis=1)  # chord of a short arc: ds to O(d^3)
    np.testing.assert_allclose(cf.curvature(c, t), dth / ds, rtol=1e-6, atol=1e-9)


@pytest.mark.parametrize("closed", [False, True])
def test_helix_curvature_torsion_vs_frenet_finite_differences(closed):
    a, h = 2.0, 0.5  # helix (a cos, a sin, h s): kappa = a/(a^2+h^2), tau = h/(a^2+h^2)
    s = np.linspace(0, 6 * np.pi, 301)
    pts = np.c_[a * np.cos(s), a * np.sin(s), h * s]
    if closed:  # a closed space curve: a torus knot
        s = np.linspace(0, 2 * np.pi, 401)[:-1]
        pts = np.c_[(2 + np.cos(3 * s)) * np.cos(2 * s), (2 + np.cos(3 * s)) * np.sin(2 * s),
                    np.sin(3 * s)]
        c = cf.interpolate_cubic(pts, bc="periodic")
    else:
        c = cf.interpolate_cubic(pts)
    t, w = _interior_params(c)
    t, w = t[::7], w[::7]
    r1, r2, r3 = _fd_derivs(c, t, 0.05 * w)
    cr = np.cross(r1, r2)
    k_ref = np.linalg.norm(cr, axis=1) / np.linalg.norm(r1, axis=1) ** 3
    tau_ref = np.einsum("ij,ij->i", cr, r3) / np.einsum("ij,ij->i", cr, cr)
    np.testing.assert_allclose(cf.curvature(c, t), k_ref, rtol=1e-8)
    np.testing.assert_allclose(cf.torsion(c, t), tau_ref, rtol=1e-6, atol=1e-8)
    if not closed:  # and the closed-form helix values, away from the natural ends
        mid = t[(t > 0.2 * c.domain[1]) & (t < 0.8 * c.domain[1])]
        np.testing.assert_allclose(cf.curvature(c, mid), a / (a * a + h * h), rtol=1e-3)
        np.testing.assert_allclose(cf.torsion(c, mid), h / (a * a + h * h), rtol=2e-3)
    assert np.all(cf.curvature(c, t) >= 0)  # unsigned in 3-D


@pytest.mark.parametrize("dim", [2, 3])
def test_dkds_vs_finite_differences_of_curvature(dim):
    rng = np.random.default_rng(2 + dim)
    q = cf.interpolate_quintic(np.cumsum(rng.normal(size=(9, dim)), axis=0))
    t, w = _interior_params(q)
    d = 1e-4 * w
    k = lambda s: cf.curvature(q, s)  # noqa: E731
    fd = (-k(t + 2 * d) + 8 * k(t + d) - 8 * k(t - d) + k(t - 2 * d)) / (12 * d)
    speed = np.linalg.norm(_fd_derivs(q, t, 1e-2 * w)[0], axis=1)
    np.testing.assert_allclose(curvature_derivative(q, t), fd / speed, rtol=1e-5, atol=1e-7)


def test_one_sided_values_at_a_c1_knot():
    # a C1 Hermite curve: curvature and dkappa/ds jump at the knots
    rng = np.random.default_rng(7)
    c = cf.CubicHermite(np.cumsum(rng.normal(size=(5, 2)), axis=0), rng.normal(size=(5, 2)),
                        [0.0, 1.0, 2.5, 3.0, 4.0])
    for f in (cf.curvature, curvature_derivative):
        left, right = f(c, 2.5, side="left"), f(c, 2.5, side="right")
        assert left != pytest.approx(right, rel=1e-3)
        assert left == pytest.approx(f(c, 2.5 - 1e-7), rel=1e-4, abs=1e-6)
        assert right == pytest.approx(f(c, 2.5 + 1e-7), rel=1e-4, abs=1e-6)
        assert f(c, 2.5) == right  # default: right limit
        assert f(c, 0.0, side="left") == f(c, 0.0)  # domain start: only one side exists


def test_closed_curve_wraps_and_left_limit_at_seam():
    a = np.linspace(0, 2 * np.pi, 9)[:-1]
    c = cf.interpolate_cubic(np.c_[2 * np.cos(a), np.sin(a)], bc="periodic")
    t0, t1 = c.domain
    u = np.array([0.1, 0.7]) * (t1 - t0)
    np.testing.assert_allclose(cf.curvature(c, u + (t1 - t0)), cf.curvature(c, u), rtol=1e-12)
    assert cf.curvature(c, t0, side="left") == pytest.approx(cf.curvature(c, t1 - 1e-9),
                                                            rel=1e-6)


def test_zero_speed_gives_zero_not_nan():
    # tangent zero at the middle point: speed vanishes there (a stop)
    c = cf.CubicHermite([[0, 0], [1, 1], [2, 0]], [[1, 0], [0, 0], [1, 0]], [0.0, 1.0, 2.0])
    for f in (cf.curvature, curvature_derivative):
        v = f(c, np.array([0.5, 1.0, 1.5]))
        assert np.all(np.isfinite(v)) and v[1] == 0.0
    a = cf.analyze(c)
    assert a.n_singular >= 1
    d = a.to_dict()
    assert all(np.isfinite(v) for v in d.values() if isinstance(v, float))


def test_shapes_and_scalar():
    c = cf.interpolate_cubic(np.c_[np.arange(6.0), np.arange(6.0) ** 2])
    u = np.linspace(*c.domain, 12).reshape(3, 4)
    assert cf.curvature(c, u).shape == (3, 4)
    assert curvature_derivative(c, u).shape == (3, 4)
    assert isinstance(cf.curvature(c, 1.0), float)
    assert isinstance(cf.curvature(c, np.float64(1.0)), float)
    np.testing.assert_array_equal(cf.curvature(c, u)[1], cf.curvature(c, u[1]))


def test_bad_input():
    c2 = cf.interpolate_cubic([[0, 0], [1, 1], [2, 0]])
    with pytest.raises(InputError, match="3-D"):
        cf.torsion(c2, 0.5)
    with pytest.raises(InputError, match="outside"):
        cf.curvature(c2, 100.0)
    with pytest.raises(InputError, match="non-finite"):
        cf.curvature(c2, [0.1, np.nan])
    with pytest.raises(InputError, match="u must be"):
        cf.curvature(c2, "abc")
    with pytest.raises(InputError, match="side"):
        cf.curvature(c2, 0.5, side="middle")
    with pytest.raises(InputError, match="curve"):
        cf.curvature(np.zeros((3, 2)), 0.5)
