"""Exact derivative energies, checked against independent quadrature.

References: per-segment Gauss-Legendre quadrature with many nodes on scipy's own evaluation of the
same spline (CubicHermiteSpline / BPoly / BSpline), and scipy.integrate.quad on the curve's
evaluation; neither uses curvefair's coefficient algebra.
"""

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.interpolate import BPoly, CubicHermiteSpline

import curvefair as cf
from curvefair.analysis import segment_energies
from curvefair.errors import InputError


def _gl_energy(spline, breaks, order, nodes=20):
    """Sum over segments of Gauss-Legendre quadrature of |d^order spline|^2 (exact for these
    polynomial integrands: degree <= 2 * 5 < 2 * nodes)."""
    x, w = np.polynomial.legendre.leggauss(nodes)
    total = 0.0
    for a, b in zip(breaks[:-1], breaks[1:], strict=True):
        t = 0.5 * (a + b) + 0.5 * (b - a) * x
        d = spline(t, order)
        total += 0.5 * (b - a) * np.sum(w * np.sum(d * d, axis=1))
    return total


def _data(rng, n, dim):
    t = np.cumsum(rng.uniform(0.1, 3.0, n))
    return rng.normal(size=(n, dim)) * 5, rng.normal(size=(n, dim)), rng.normal(size=(n, dim)), t


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("order", [1, 2, 3])
def test_cubic_hermite_energy_vs_scipy_gauss(dim, order):
    rng = np.random.default_rng(10 + dim)
    p, m, _, t = _data(rng, 11, dim)
    c = cf.CubicHermite(p, m, t)
    ref = _gl_energy(CubicHermiteSpline(t, p, m, axis=0), t, order)
    assert cf.energy(c, order) == pytest.approx(ref, rel=1e-12)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("order", [1, 2, 3, 4, 5])
def test_quintic_hermite_energy_vs_scipy_bpoly(dim, order):
    rng = np.random.default_rng(20 + dim)
    p, m, s, t = _data(rng, 8, dim)
    q = cf.QuinticHermite(p, m, s, t)
    ref = _gl_energy(BPoly.from_derivatives(t, np.stack([p, m, s], axis=1)), t, order)
    assert cf.energy(q, order) == pytest.approx(ref, rel=1e-10)


def test_energy_vs_adaptive_quad_closed_curve():
    # closed periodic spline; reference: scipy.integrate.quad over each segment of |r''|^2
    a = np.linspace(0, 2 * np.pi, 13)[:-1]
    pts = np.c_[np.cos(a) * (1 + 0.2 * np.sin(3 * a)), np.sin(a)]
    c = cf.interpolate_cubic(pts, bc="periodic")
    b = c.piecewise.breaks
    ref = sum(quad(lambda t: float(np.sum(c(t, 2) ** 2)), b[i], b[i + 1], epsabs=0,
                   epsrel=1e-13)[0] for i in range(len(b) - 1))
    assert cf.energy(c) == pytest.approx(ref, rel=1e-11)
    assert np.sum(segment_energies(c)) == pytest.approx(cf.energy(c), rel=1e-14)


def test_energy_bspline_curve_vs_scipy_bspline():
    rng = np.random.default_rng(5)
    pts = np.cumsum(rng.normal(size=(15, 2)), axis=0)
    bs = cf.interpolate_bspline(pts, degree=4)
    spl = bs.to_scipy()
    breaks = np.unique(bs.knots[bs.degree: len(bs.knots) - bs.degree])
    for order in (1, 2, 3, 4):
        ref = _gl_energy(lambda t, nu: spl(t, nu), breaks, order)
        assert cf.energy(bs, order) == pytest.approx(ref, rel=1e-10)


def test_energy_known_value_and_invariance():
    # r(t) = (t, t^2) on [0, 2] as a single cubic Hermite segment: r'' = (0, 2), energy = 8
    c = cf.CubicHermite([[0, 0], [2, 4]], [[1, 0], [1, 4]], [0.0, 2.0])
    assert cf.energy(c) == pytest.approx(8.0, rel=1e-14)
    assert cf.energy(c, 3) == pytest.approx(0.0, abs=1e-12)
    # rigid motion leaves every energy unchanged; uniform scaling by s multiplies it by s^2
    th = 0.7
    R = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
    rng = np.random.default_rng(6)
    pts = np.cumsum(rng.normal(size=(9, 2)), axis=0)
    t = np.arange(9.0)
    c1 = cf.interpolate_cubic(pts, param=t)
    c2 = cf.interpolate_cubic(pts @ R.T + [3, -1], param=t)
    c3 = cf.interpolate_cubic(2.5 * pts, param=t)
    for o in (1, 2, 3):
        assert cf.energy(c2, o) == pytest.approx(cf.energy(c1, o), rel=1e-12)
        assert cf.energy(c3, o) == pytest.approx(6.25 * cf.energy(c1, o), rel=1e-12)


@pytest.mark.parametrize("order", [0, 4, -1, 2.0, "2", True, None])
def test_energy_bad_order(order):
    c = cf.interpolate_cubic([[0, 0], [1, 1], [2, 0]])
    with pytest.raises(InputError, match="order"):
        cf.energy(c, order)


@pytest.mark.parametrize("bad", [None, np.zeros((3, 2)), "curve", 3.0])
def test_energy_bad_curve(bad):
    with pytest.raises(InputError, match="curve"):
        cf.energy(bad)
