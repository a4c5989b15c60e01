"""curvefair.as_curve: scipy spline objects as curvefair curves, checked against scipy's own
evaluation (positions and derivatives at random parameters), and accepted by fair(), analyze()
and the plots."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from scipy import interpolate as si  # noqa: E402

from curvefair import (  # noqa: E402
    BSplineCurve,
    CubicHermite,
    InputError,
    QuinticHermite,
    analyze,
    as_curve,
    fair,
    interpolate_cubic,
)

RNG = np.random.default_rng(3)


def _data(n=12, dim=2):
    x = np.linspace(0.0, 1.0, n)
    cols = [x, np.sin(4 * x) + 0.05 * RNG.normal(size=n)]
    if dim == 3:
        cols.append(np.cos(3 * x))
    return x, np.column_stack(cols)


def _ppoly(spl):
    """scipy's PPoly of a vector BSpline, one coordinate at a time (scipy's own conversion)."""
    cs = [si.PPoly.from_spline((spl.t, spl.c[:, j], spl.k)) for j in range(spl.c.shape[1])]
    return si.PPoly(np.stack([p.c for p in cs], axis=2), cs[0].x)


def _close(curve, reference, lo, hi, derivs=(0, 1, 2), graph=False):
    u = np.sort(RNG.uniform(lo, hi, 300))
    size = np.abs(curve(u)).max()
    for nu in derivs:
        ref = np.asarray(reference(u, nu), dtype=float)
        if graph:  # (x, f(x)): x' = 1, x'' = 0
            xcol = u if nu == 0 else (np.ones_like(u) if nu == 1 else np.zeros_like(u))
            ref = np.column_stack([xcol, ref])
        scale = max(size, np.abs(ref).max())
        assert np.max(np.abs(curve(u, nu) - ref)) <= 1e-10 * scale, nu


@pytest.mark.parametrize("dim", [2, 3])
def test_bspline_make_interp_spline(dim):
    x, y = _data(dim=dim)
    spl = si.make_interp_spline(x, y, k=3)
    c = as_curve(spl)
    assert isinstance(c, BSplineCurve) and c.dim == dim
    _close(c, lambda u, nu: spl(u, nu), x[0], x[-1])


def test_splprep_tck_and_make_splprep():
    _, y = _data(20)
    tck, u = si.splprep(y.T, s=0.01)
    for obj in (tck, (tck, u), tuple(tck)):
        c = as_curve(obj)
        assert isinstance(c, BSplineCurve)
        _close(c, lambda q, nu: np.column_stack(si.splev(q, tck, der=nu)), 0.0, 1.0)
    if hasattr(si, "make_splprep"):
        spl, u2 = si.make_splprep(y.T, s=0.01)
        c = as_curve((spl, u2))
        vals = lambda q, nu: np.asarray(spl(q, nu)).reshape(2, -1).T  # noqa: E731
        _close(c, vals, 0.0, 1.0)
        assert isinstance(as_curve(spl), BSplineCurve)


def test_cubic_spline_is_an_exact_cubic_hermite():
    x, y = _data()
    cs = si.CubicSpline(x, y)
    c = as_curve(cs)
    assert isinstance(c, CubicHermite)
    np.testing.assert_array_equal(c.points[:-1], y[:-1])  # the spline's own coefficients
    np.testing.assert_allclose(c.points[-1], y[-1], rtol=1e-14, atol=1e-15)
    _close(c, lambda u, nu: cs(u, nu), x[0], x[-1], derivs=(0, 1, 2, 3))


def test_periodic_cubic_spline_is_closed():
    t = np.linspace(0, 2 * np.pi, 13)
    y = np.c_[np.cos(t), np.sin(2 * t) * 0.3 + np.sin(t)]
    y[-1] = y[0]
    cs = si.CubicSpline(t, y, bc_type="periodic")
    c = as_curve(cs)
    assert c.closed
    _close(c, lambda u, nu: cs(u, nu), t[0], t[-1])


def test_pchip_akima_ppoly_bpoly():
    x, y = _data()
    for obj in (si.PchipInterpolator(x, y), si.Akima1DInterpolator(x, y)):
        c = as_curve(obj)
        assert isinstance(c, CubicHermite)  # C1 cubics
        _close(c, lambda u, nu, o=obj: o(u, nu), x[0], x[-1], derivs=(0, 1))
    # a C2 quintic: QuinticHermite; a C4 quintic and a C2 quartic: B-splines
    spl5 = si.make_interp_spline(x, y, k=5)
    pp = _ppoly(spl5)
    c = as_curve(pp)
    assert isinstance(c, QuinticHermite)
    _close(c, lambda u, nu: pp(u, nu), x[0], x[-1], derivs=(0, 1, 2, 3))
    spl4 = si.make_interp_spline(x, y, k=4)
    pp4 = _ppoly(spl4)
    c4 = as_curve(pp4)
    assert isinstance(c4, BSplineCurve) and c4.degree == 4
    _close(c4, lambda u, nu: pp4(u, nu), x[0], x[-1], derivs=(0, 1, 2, 3))
    d = np.gradient(y, x, axis=0)
    bp = si.BPoly.from_derivatives(x, np.stack([y, d], axis=1))  # C1 cubic, Bernstein basis
    cb = as_curve(bp)
    assert isinstance(cb, CubicHermite)
    _close(cb, lambda u, nu: bp(u, nu), x[0], x[-1], derivs=(0, 1))



@pytest.mark.parametrize("dim", [2, 3])
def test_piecewise_polynomials_with_the_values_first(dim):
    # scipy objects built with axis=1 evaluate to (dim, len(u)) (csaps' spline form is such a
    # PPoly): converted like their axis-0 twins, checked against scipy's evaluation moved back
    x, y = _data(dim=dim)
    cases = [si.CubicSpline(x, y.T, axis=1),  # C2 cubic: CubicHermite
             si.PPoly.from_spline(si.make_interp_spline(x, y[:, 0], k=3))]  # scalar graph
    spl5 = si.make_interp_spline(x, y, k=5)
    pp5 = _ppoly(spl5)
    # the values' axis first in the coefficients, as scipy takes them with axis=1
    cases.append(si.PPoly(np.moveaxis(pp5.c, 2, 0), pp5.x, axis=1))  # C4 quintic
    d = np.gradient(y, x, axis=0)
    bp = si.BPoly.from_derivatives(x, np.stack([y, d], axis=1))  # C1 cubic, Bernstein basis
    cases.append(si.BPoly(np.moveaxis(bp.c, 2, 0), bp.x, axis=1))
    kinds = (CubicHermite, CubicHermite, QuinticHermite, CubicHermite)
    for obj, kind in zip(cases, kinds, strict=True):
        c = as_curve(obj)
        assert isinstance(c, kind), type(obj).__name__
        if obj.c.ndim == 2:
            continue  # the graph case is tested in test_scalar_splines_are_graphs
        _close(c, lambda u, nu, o=obj: np.moveaxis(np.asarray(o(u, nu)), 1, 0), x[0], x[-1],
               derivs=(0, 1))


def test_csaps_spline_form_is_accepted():
    csaps = pytest.importorskip("csaps")
    x, y = _data()
    spl = csaps.CubicSmoothingSpline(x, y.T, smooth=0.99).spline  # a PPoly with axis=1
    c = as_curve(spl)
    assert isinstance(c, CubicHermite)
    _close(c, lambda u, nu: np.moveaxis(np.asarray(spl(u, nu)), 1, 0), x[0], x[-1])


def test_scalar_splines_are_graphs():
    x = np.linspace(0, 3, 9)
    f = np.sin(x)
    for obj in (si.make_interp_spline(x, f, k=3), si.CubicSpline(x, f), si.splrep(x, f)):
        c = as_curve(obj)
        ref = (lambda u, nu, o=obj: si.splev(u, o, der=nu)) if isinstance(obj, tuple) else \
            (lambda u, nu, o=obj: o(u, nu))
        _close(c, ref, x[0], x[-1], graph=True)


def test_refused_objects_name_the_argument():
    with pytest.raises(InputError, match="curve must be a curvefair curve or a scipy spline"):
        as_curve(object())
    x, y = _data()
    jump = si.PPoly(np.stack([np.zeros((2, 2)), np.array([[0.0, 0.0], [1.0, 5.0]])], axis=0)
                    .transpose(0, 1, 2), [0.0, 1.0, 2.0])
    with pytest.raises(InputError):
        as_curve(jump)  # scalar with a jump at x = 1
    with pytest.raises(InputError, match="shape"):
        as_curve(si.make_interp_spline(x, np.c_[y, y], k=3))  # 4-D values
    with pytest.raises(InputError, match="fair"):
        fair(object())
    c = interpolate_cubic(y)
    assert as_curve(c) is c


def test_fair_analyze_and_plots_take_scipy_objects():
    from curvefair.plot import figure

    x, y = _data(15)
    cs = si.CubicSpline(x, y)
    ref = as_curve(cs)
    a, b = analyze(cs), analyze(ref)
    assert a.inflections == b.inflections and a.energy2 == b.energy2
    r = fair(cs, tol=0.01)
    r_ref = fair(ref, tol=0.01)
    np.testing.assert_array_equal(r.curve.points, r_ref.curve.points)
    spl = si.make_interp_spline(x, y, k=3)
    fig = figure([spl, cs])
    assert len(fig.axes) >= 2
