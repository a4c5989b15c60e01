"""Degenerate but valid inputs, every builder x every registered method.

Collinear points (zero curvature), exactly fair input (nothing moves), 2 or 3 points, nearly
coincident points, very uneven spacing, closed curves given with their first point repeated
last. "Handled sensibly" is checked as: either a documented :class:`curvefair.CurvefairError`
with a message, or a finite result within tol (dense sampling at equal parameters) in which
nothing moves when there is nothing to fair.
"""

from __future__ import annotations

import numpy as np
import pytest
from test_robust_properties import build, curve_distance, data_of, dense_params, size_of

import curvefair as cf
from curvefair.fairing import available_methods


def _param_methods(curve):
    """The methods whose result lives on the input's parameter domain (all but points-l1, whose
    result is the natural cubic on the moved points' chord parameters - what a point file gives
    back; its geometric contract is tested in tests/test_points_l1.py)."""
    return [m for m in available_methods(curve) if m != "points-l1"]


KINDS = ("cubic", "quintic", "bspline3", "bspline4", "fit3")
CLAMPS = ("g0", "g1", "g2")


def _curves(pts, closed=False, kinds=KINDS):
    """(kind, method, curve) for every builder accepting ``pts`` and every method for it."""
    out = []
    for kind in kinds:
        try:
            probe = build(kind, pts, closed)
        except cf.CurvefairError:
            continue
        for method in _param_methods(probe):
            param = "uniform" if method == "kjellander" else "chord"
            try:
                c = build(kind, pts, closed, param)
            except cf.CurvefairError:
                continue
            out.append((kind, method, c))
    return out


def _fair_or_refuse(c, method, **kw):
    try:
        return cf.fair(c, method, **kw)
    except cf.CurvefairError as exc:
        assert str(exc)
        return None


def _check_valid(c, res, tol):
    out = res.curve
    assert np.isfinite(data_of(out)).all()
    u = dense_params(c)
    assert np.isfinite(out(u)).all()
    assert curve_distance(c, out) <= tol * (1 + 1e-12)
    for k, v in res.report.items():
        if isinstance(v, float):
            assert np.isfinite(v), k


# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("spacing", ["even", "uneven"])
def test_collinear_points_nothing_moves_zero_curvature(dim, spacing):
    rng = np.random.default_rng(3)
    s = np.linspace(0, 6, 9) if spacing == "even" else np.cumsum(np.r_[0, rng.uniform(0.05, 3, 8)])
    direction = np.array([0.6, -0.8, 0.3])[:dim]
    pts = np.array([1.0, 2.0, -1.0])[:dim] + s[:, None] * direction
    runs = _curves(pts)
    assert {m for _, m, _ in runs} >= set(available_methods()) - {"kjellander", "points-l1"} or \
        spacing == "uneven"
    for kind, method, c in runs:
        u = dense_params(c, 801)
        for clamp in CLAMPS:
            res = _fair_or_refuse(c, method, tol=0.05, clamp=clamp)
            if res is None:
                continue
            _check_valid(c, res, 0.05)
            d = data_of(res.curve)
            # still on the line (distance from it, independent of the curve code)
            rel = d - pts[0]
            off = rel - (rel @ direction)[:, None] * direction / (direction @ direction)
            assert np.abs(off).max() <= 1e-12 * size_of(c), (kind, method, clamp)
            move = np.linalg.norm(d - data_of(c), axis=1).max()
            if not (method == "kjellander" and spacing == "uneven"):
                # (uniform parameters on uneven points: a line at varying speed, whose third
                # derivative jumps; Kjellander evens the speed out by sliding along the line)
                assert move <= 1e-12 * size_of(c), (kind, method, clamp, move)
            k = np.abs(np.asarray(cf.curvature(res.curve, u)))
            assert k.max() <= 1e-9 / size_of(c), (kind, method, clamp, k.max())


def test_exactly_fair_cubic_nothing_moves():
    """Points ON one cubic polynomial: the not-a-knot cubic spline is that polynomial, every
    third-derivative jump is zero, so the jump-ranked cubic methods have nothing to do."""
    t = np.linspace(0, 2, 9)
    pts = np.c_[t, 0.5 * t**3 - t**2 + 0.2 * t, 0.1 * t**2]
    c = cf.interpolate_cubic(pts, "uniform", "not-a-knot")
    # the interpolant IS the polynomial (independent check against the formula)
    uu = np.linspace(0, 1, 101) * c.domain[1]
    tt = uu / c.domain[1] * 2
    np.testing.assert_allclose(c(uu), np.c_[tt, 0.5 * tt**3 - tt**2 + 0.2 * tt, 0.1 * tt**2],
                               atol=1e-12)
    for method in ("kjellander", "poliakoff", "wang-cao"):
        for mode in ("spline", "hermite"):
            res = cf.fair(c, method, tol=0.05, mode=mode, clamp="g1")
            move = np.abs(data_of(res.curve) - data_of(c)).max()
            assert move <= 1e-12, (method, mode, move)


def test_exactly_fair_single_polynomial_bspline_knot_removal_nothing_moves():
    """A cubic Bezier with extra knots inserted: no knot has a jump, nothing to remove."""
    from scipy.interpolate import BSpline, insert

    bez = BSpline(np.r_[[0.0] * 4, [1.0] * 4], np.array([[0, 0], [1, 2], [3, 2], [4, 0.5]]), 3)
    spl = bez
    for x in (0.2, 0.45, 0.7):
        spl = insert(x, spl)
    c = cf.BSplineCurve.from_scipy(spl)
    res = cf.fair(c, "knot-removal", tol=0.05)
    assert np.abs(data_of(res.curve) - data_of(c)).max() <= 1e-12
    assert res.report["max_deviation"] <= 1e-12


@pytest.mark.parametrize("n", [2, 3])
@pytest.mark.parametrize("closed", [False, True])
def test_two_or_three_points(n, closed):
    pts = np.array([[0.0, 0.0], [1.0, 0.4], [2.2, -0.1]])[:n]
    runs = 0
    for kind in KINDS:
        try:
            c = build(kind, pts, closed)
        except cf.CurvefairError as exc:
            assert "point" in str(exc)  # builders say how many points they need
            continue
        for method in _param_methods(c):
            param = "uniform" if method == "kjellander" else "chord"
            try:
                c = build(kind, pts, closed, param)
            except cf.CurvefairError:
                continue
            res = _fair_or_refuse(c, method, tol=0.1)
            if res is not None:
                runs += 1
                _check_valid(c, res, 0.1)
                if not closed:  # end points are always kept
                    np.testing.assert_array_equal(data_of(res.curve)[[0, -1]],
                                                  data_of(c)[[0, -1]])
    if n == 3:
        assert runs > 0  # three points are enough for the Hermite methods


@pytest.mark.parametrize("gap", [1e-6, 1e-9])
def test_nearly_coincident_points(gap):
    x = np.linspace(0, 5, 10)
    pts = np.c_[x, np.sin(x)]
    pts = np.insert(pts, 4, pts[4] + gap * np.array([0.6, 0.8]), axis=0)
    for _kind, method, c in _curves(pts):
        res = _fair_or_refuse(c, method, tol=0.05)
        if res is not None:
            _check_valid(c, res, 0.05)


@pytest.mark.parametrize("closed", [False, True])
def test_very_uneven_spacing(closed):
    rng = np.random.default_rng(5)
    if closed:
        th = np.r_[0, 1e-4, 2e-4, 0.5, 2.5, 2.5005, 4.0, 5.5]
        pts = np.c_[np.cos(th), np.sin(th)] * 3
    else:
        x = np.r_[0, 1e-4, 2e-4, 1, 50, 50.001, 120, 121]
        pts = np.c_[x, 5 * np.sin(x / 20)]
    pts = pts + 1e-5 * rng.normal(size=pts.shape)
    for _kind, method, c in _curves(pts, closed):
        for tol in (1e-3, 0.3):
            res = _fair_or_refuse(c, method, tol=tol)
            if res is not None:
                _check_valid(c, res, tol)


@pytest.mark.parametrize("kind", KINDS)
def test_closed_with_first_point_repeated(kind):
    th = np.linspace(0, 2 * np.pi, 13)  # th[-1] == 2 pi: the first point repeated last
    rng = np.random.default_rng(8)
    pts = np.c_[2 * np.cos(th), np.sin(th)]
    pts[1:-1] += 0.05 * rng.normal(size=(11, 2))
    pts[-1] = pts[0]
    a = build(kind, pts, True)
    b = build(kind, pts[:-1], True)  # the same loop without the repetition
    u = dense_params(a, 501)
    np.testing.assert_allclose(a(u), b(u), rtol=0, atol=1e-12)
    for method in _param_methods(a):
        c = build(kind, pts, True, "uniform" if method == "kjellander" else "chord")
        res = _fair_or_refuse(c, method, tol=0.02)
        if res is None:
            continue
        _check_valid(c, res, 0.02)
        out = res.curve
        assert out.closed
        if hasattr(out, "points"):
            np.testing.assert_array_equal(out.points[0], out.points[-1])
        # the seam stays closed and C1 (C2 for the splines)
        pp = out.piecewise
        t0, t1 = out.domain
        last = np.array([pp.n_segments - 1])
        for nu in range(2 if res.report.get("mode") == "hermite" else 3):
            end = pp.evaluate(np.array([t1]), nu, segment=last)[0]  # left limit at the seam
            start = pp.evaluate(np.array([t0]), nu, segment=np.array([0]))[0]
            np.testing.assert_allclose(end, start, rtol=0,
                                       atol=1e-9 * max(1.0, np.abs(start).max()),
                                       err_msg=f"{kind} {method} nu={nu}")
