"""Evaluation of B-splines of high degree (up to MAX_DEGREE = 25) against exact rational
de Boor evaluation (fractions.Fraction) and scipy's BSpline: values and derivatives, open and
periodic; the low-degree power-form path is kept; analysis agrees with scipy-based curvature.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from curvefair import BSplineCurve, analyze, curvature
from curvefair.curves.bspline import MAX_DEGREE, POWER_FORM_MAX_DEGREE


def _exact(knots, ctrl, p, u, nu):
    """``r^(nu)(u)`` of ``sum_i c_i N_{i,p}`` on the knot vector ``knots`` (scipy layout: the
    domain is ``[t_p, t_{len(ctrl)}]``), exactly in rationals: derivative control points
    ``p (c_{i+1} - c_i) / (t_{i+p+1} - t_{i+1})`` (de Boor), then de Boor's algorithm; rounded
    to float64 once at the end."""
    t = [Fraction(x) for x in knots]
    c = [[Fraction(x) for x in row] for row in ctrl]
    u = Fraction(u)
    q = p
    for _ in range(nu):
        c = [[q * (c[i + 1][e] - c[i][e]) / (t[i + q + 1] - t[i + 1])
              if t[i + q + 1] != t[i + 1] else Fraction(0) for e in range(len(c[0]))]
             for i in range(len(c) - 1)]
        t = t[1:-1]
        q -= 1
    n = len(c)
    s = max(i for i in range(q, n) if t[i] <= u and t[i] < t[i + 1]) if u < t[n] else n - 1
    while t[s] == t[s + 1]:
        s -= 1
    d = [list(c[j]) for j in range(s - q, s + 1)]
    for r in range(1, q + 1):
        for j in range(q, r - 1, -1):
            i = j + s - q
            a = (u - t[i]) / (t[i + q + 1 - r] - t[i])
            d[j] = [(1 - a) * d[j - 1][e] + a * d[j][e] for e in range(len(d[0]))]
    return [float(x) for x in d[q]]


def _curve(p, nspan, closed, seed):
    rng = np.random.default_rng(seed)
    if closed:
        n = max(p + 1, nspan)
        period = np.r_[0.0, np.cumsum(rng.uniform(0.5, 1.5, n))]
        return BSplineCurve(rng.normal(size=(n, 2)) * 10, period, p, closed=True)
    inner = np.sort(rng.uniform(0.0, 2.0, nspan - 1))
    t = np.r_[[0.0] * (p + 1), inner, [2.0] * (p + 1)]
    return BSplineCurve(rng.normal(size=(p + nspan, 3)) * 10, t, p)


DEGREES = [4, 5, 6, 8, 11, 15, 20, MAX_DEGREE]


@pytest.mark.parametrize("p", DEGREES)
@pytest.mark.parametrize("nspan,closed", [(1, False), (3, False), (0, True)])
def test_values_and_derivatives_exact(p, nspan, closed):
    c = _curve(p, nspan, closed, 100 * p + nspan)
    spl = c.to_scipy()
    t0, t1 = c.domain
    u = np.linspace(t0, t1, 5 if p > 15 else 9)
    ext = c.extended_control_points
    for nu in (0, 1, 2, 3):
        ref = np.array([_exact(c.knots, ext, p, x, nu) for x in u])
        scale = np.abs(ref).max()
        got = c(u, nu)
        # relative to the size of the derivative: a few ulp at every degree
        assert np.abs(got - ref).max() <= 2e-14 * scale, (p, nu)
        assert np.abs(got - spl(u, nu)).max() <= 2e-14 * scale, (p, nu)


@pytest.mark.parametrize("p", [POWER_FORM_MAX_DEGREE + 1, 12, MAX_DEGREE])
def test_piecewise_forms_agree_with_scipy(p):
    """evaluate / evaluate_local / segment_values / at and a forced left segment (the left
    limit at a knot) are all accurate at high degree."""
    c = _curve(p, 4, False, p)
    pp = c.piecewise
    spl = c.to_scipy()
    frac = np.array([0.0, 0.3, 1.0])
    for nu in (0, 2):
        got = pp.segment_values(frac, nu)
        u = pp.breaks[:-1, None] + pp.widths[:, None] * frac[None, :]
        # at u = right end of segment i the polynomial of segment i is wanted: its left limit
        ref = np.stack([spl(np.minimum(u[:, k], np.nextafter(pp.breaks[1:], -np.inf)), nu)
                        if k == 2 else spl(u[:, k], nu) for k in range(3)], axis=1)
        scale = np.abs(ref).max()
        assert np.abs(got - ref).max() <= 1e-12 * scale
        loc = pp.evaluate_local(np.array([0.0, 0.5 * pp.widths.min()]), nu)
        ref0 = spl(pp.breaks[:-1], nu)
        assert np.abs(loc[:, 0] - ref0).max() <= 1e-13 * scale
    # left limit at an interior knot through segment=: the curve is C^(p-1) there, so compare
    # the p-th derivative's left limit with scipy just left of the knot (piecewise constant)
    k = pp.breaks[2]
    left = pp.evaluate(np.array([k]), p, segment=np.array([1]))[0]
    ref = spl(np.nextafter(k, -np.inf), p)
    assert np.allclose(left, ref, rtol=1e-10, atol=1e-10 * np.abs(ref).max())


@pytest.mark.parametrize("p", [2, 3, 4, POWER_FORM_MAX_DEGREE])
def test_low_degree_keeps_the_power_form(p):
    """Up to POWER_FORM_MAX_DEGREE evaluation is Horner's rule on the power form, bitwise."""
    c = _curve(p, 5, False, p)
    pp = c.piecewise
    assert pp.evaluator is None
    u = np.linspace(*c.domain, 57)
    seg = pp.segment_of(u)
    for nu in range(p + 1):
        co = pp.coeffs[seg, nu:, :] * np.array(
            [np.prod(np.arange(j - nu + 1, j + 1)) for j in range(nu, p + 1)],
            dtype=float)[None, :, None]
        s = u - pp.breaks[seg]
        ref = co[:, -1, :].copy()
        for j in range(co.shape[1] - 2, -1, -1):
            ref = ref * s[:, None] + co[:, j, :]
        assert np.array_equal(c(u, nu), ref)


def _kappa_scipy(spl, u):
    d1, d2 = spl(u, 1), spl(u, 2)
    return (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / np.hypot(d1[:, 0], d1[:, 1]) ** 3


@pytest.mark.parametrize("p", [8, 15, MAX_DEGREE])
def test_analysis_consistent_at_high_degree(p):
    """curvature() agrees with curvature from scipy's derivatives; analyze()'s inflection and
    extremum counts agree with sign changes of scipy curvature and of its finite-difference
    derivative on a dense grid."""
    rng = np.random.default_rng(p)
    n = p + 3
    # a gentle wave: control points on a sine with small noise
    x = np.linspace(0.0, 10.0, n)
    ctrl = np.c_[x, np.sin(x * 0.9) + 0.05 * rng.normal(size=n)]
    inner = np.linspace(0.0, 1.0, n - p + 1)[1:-1]
    c = BSplineCurve(ctrl, np.r_[[0.0] * (p + 1), inner, [1.0] * (p + 1)], p)
    spl = c.to_scipy()
    u = np.linspace(0.0, 1.0, 20001)
    ks = _kappa_scipy(spl, u)
    kc = curvature(c, u)
    assert np.abs(kc - ks).max() <= 1e-11 * np.abs(ks).max()
    a = analyze(c)
    sgn = np.sign(ks)
    assert a.inflections == int(np.count_nonzero(sgn[1:] != sgn[:-1]))
    dk = np.diff(ks)
    sd = np.sign(dk)
    assert a.extrema == int(np.count_nonzero(sd[1:] != sd[:-1]))
    # the (approximate) inflection parameters sit at the grid's sign changes
    ch = u[np.flatnonzero(sgn[1:] != sgn[:-1])]
    for t in a.inflection_params:
        assert np.abs(ch - t).min() <= 1e-3
