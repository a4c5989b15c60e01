"""The deviation certificate of two Hermite splines on the same parameters, formed one piece
at a time (:func:`curvefair.analysis.hermite_delta_deviation`).

Checked against (a) :func:`curvefair.deviation` on the whole power form of the difference
curve (``fairing._tolerance.delta_deviation``, the path it replaces: the same figures bit for
bit) and (b) an independent measure: the difference curve evaluated densely through
``scipy.interpolate.CubicHermiteSpline`` / ``BPoly.from_derivatives`` (cubic, quintic), whose
maximum must lie between the certified ``max_distance`` and ``upper_bound``.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import BPoly, CubicHermiteSpline

import curvefair as cf
from curvefair.analysis import hermite_delta_deviation
from curvefair.errors import CurvefairError
from curvefair.fairing._tolerance import delta_deviation, difference_deviation


def _curve(kind: str, n: int, dim: int, closed: bool, seed: int):
    rng = np.random.default_rng(seed)
    t = np.cumsum(rng.uniform(0.3, 2.0, n))
    P = np.c_[t, np.sin(t)] if dim == 2 else np.c_[t, np.sin(t), np.cos(t / 2)]
    P = P + 0.05 * rng.normal(size=P.shape)
    if closed:
        a = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
        P = np.c_[np.cos(a), np.sin(a), 0.1 * np.sin(3 * a)][:, :dim] * 10.0 \
            + 0.05 * rng.normal(size=(n, dim))
    if kind == "cubic":
        return cf.interpolate_cubic(P, bc="periodic" if closed else "natural")
    return cf.interpolate_quintic(P, bc="periodic" if closed else "natural")


def _moved(c, rng, scale: float):
    """A second data set on ``c``'s parameters: every row moved by up to ``scale``."""
    pts = np.asarray(c.points) + scale * rng.normal(size=c.points.shape)
    ders = [np.asarray(d) + scale * rng.normal(size=d.shape) for d in c._derivs]
    if c.closed:  # the seam repeated exactly, as a closed curve holds it
        pts[-1] = pts[0]
        for d in ders:
            d[-1] = d[0]
    return pts, ders


def _fields(c, pts, ders):
    if isinstance(c, cf.QuinticHermite):
        return {"points": pts, "d1": ders[0], "d2": ders[1]}
    return {"points": pts, "tangents": ders[0]}


CASES = [(kind, n, dim, closed, seed)
         for kind in ("cubic", "quintic") for n in (4, 9, 60, 700)
         for dim in (2, 3) for closed in (False, True) for seed in (0, 1)]


@pytest.mark.parametrize(("kind", "n", "dim", "closed", "seed"), CASES)
def test_same_bits_as_the_whole_form(kind, n, dim, closed, seed):
    c = _curve(kind, n, dim, closed, seed)
    rng = np.random.default_rng(100 + seed)
    for scale in (1e-3, 0.3):
        pts, ders = _moved(c, rng, scale)
        delta = _fields(c, pts - c.points, [d - e for d, e in zip(ders, c._derivs, strict=True)])
        ref = delta_deviation(c, delta)
        got = hermite_delta_deviation(c, pts, tuple(ders))
        assert got is not None
        want = (ref.max_distance, ref.upper_bound, ref.param)
        assert [x.hex() for x in got] == [float(x).hex() for x in want]
        if closed:  # the distinct rows only: the seam's row is row 0's
            nd = pts.shape[0] - 1
            got2 = hermite_delta_deviation(c, pts[:nd], tuple(d[:nd] for d in ders))
            assert got2 == got


def _dense_max(c, pts, ders):
    """max over 200 samples per piece of ``|b(t) - a(t)|`` and the difference curve itself,
    by scipy's Hermite forms of the data's differences (an evaluation independent of
    curvefair's power forms)."""
    t = np.asarray(c.params)
    dp = pts - np.asarray(c.points)
    dd = [d - np.asarray(e) for d, e in zip(ders, c._derivs, strict=True)]
    if len(dd) == 1:
        f = CubicHermiteSpline(t, dp, dd[0])
    else:
        f = BPoly.from_derivatives(t, np.stack([dp, dd[0], dd[1]], axis=1))
    s = np.concatenate([np.linspace(t[i], t[i + 1], 200) for i in range(t.size - 1)])
    return float(np.max(np.linalg.norm(f(s), axis=1))), f


@pytest.mark.parametrize(("kind", "closed"), [("cubic", False), ("cubic", True),
                                              ("quintic", False), ("quintic", True)])
def test_brackets_a_dense_evaluation(kind, closed):
    c = _curve(kind, 40, 3, closed, 5)
    pts, ders = _moved(c, np.random.default_rng(9), 0.02)
    best, ub, param = hermite_delta_deviation(c, pts, tuple(ders))
    dense, f = _dense_max(c, pts, ders)
    # max_distance is the distance at the reported parameter (scipy's evaluation there)
    assert float(np.linalg.norm(f(param))) == pytest.approx(best, rel=1e-9)
    assert dense <= ub * (1 + 1e-12)
    # the dense maximum is within the search's stated gap of the certified figures
    assert best >= dense * (1 - 1e-6)
    assert ub - best <= 1e-12 * best + 1e-13 * 20.0
    assert c.params[0] <= param <= c.params[-1]


def test_fair_reports_the_same_certificate_as_the_whole_form():
    """fair()'s certificate of a Hermite result (difference_deviation) and the loop's curve
    bound take the new path; the figures are the whole form's."""
    c = _curve("cubic", 300, 2, False, 3)
    r = cf.fair(c, "poliakoff", tol=0.01)
    got = difference_deviation(c, r.curve)
    delta = _fields(c, np.asarray(r.curve.points) - c.points,
                    [np.asarray(d) - e for d, e in zip(r.curve._derivs, c._derivs, strict=True)])
    ref = delta_deviation(c, delta)
    assert got == (ref.max_distance, ref.upper_bound, ref.param)
    assert r.report["max_deviation"] <= 0.01


def test_non_finite_data_fall_back():
    c = _curve("cubic", 10, 2, False, 0)
    pts = np.array(c.points)
    pts[4, 0] = np.inf
    assert hermite_delta_deviation(c, pts, (np.asarray(c.tangents),)) is None


@pytest.mark.parametrize("bad", ["rows", "dim", "derivs"])
def test_wrong_shapes_are_clear_errors(bad):
    c = _curve("cubic", 10, 2, False, 0)
    pts, ders = np.asarray(c.points), (np.asarray(c.tangents),)
    if bad == "rows":  # an open curve's data must have all its rows
        pts, ders = pts[:-1], (ders[0][:-1],)
    elif bad == "dim":
        pts = np.c_[pts, pts[:, :1]]
    else:
        ders = ders + ders
    with pytest.raises(CurvefairError, match="hermite_delta_deviation"):
        hermite_delta_deviation(c, pts, ders)


@pytest.mark.parametrize("case", ["mixed", "none", "all", "nan", "one"])
def test_split_bounds_is_numpys_selection(case):
    """The compiled selection of the pieces to search and the others' largest bound are
    numpy's flatnonzero(U > thr) and max(where(U > thr, 0.0, U)) (max(U) when none)."""
    from curvefair._kernels.deviation import split_bounds

    rng = np.random.default_rng(7)
    U = rng.uniform(0.0, 1.0, 1000)
    thr = {"mixed": 0.7, "none": 2.0, "all": -1.0, "nan": 0.7, "one": 0.7}[case]
    if case == "nan":
        U[10] = np.nan
    if case == "one":
        U = np.array([0.9])
    sel = np.empty(U.size, dtype=np.int64)
    k, ub = split_bounds(U, thr, sel)
    want = np.flatnonzero(U > thr)
    np.testing.assert_array_equal(sel[:k], want)
    ref = np.max(U) if want.size == 0 else np.max(np.where(U > thr, 0.0, U))
    assert (np.isnan(ub) and np.isnan(ref)) or float(ub).hex() == float(ref).hex()


@pytest.mark.parametrize(("kind", "closed", "dim"), [("cubic", False, 2), ("quintic", True, 3)])
def test_long_curve_on_two_threads_same_bits(kind, closed, dim):
    """Past ``_PAR_MIN`` pieces the pass runs in ranges on two threads, combined in curve
    order: the figures are still the whole form's, bit for bit (ties of the largest sample
    across ranges keep the first, as one pass does)."""
    from curvefair.analysis import _deviation

    n = _deviation._PAR_MIN + 20_000
    c = _curve(kind, n, dim, closed, 11)
    rng = np.random.default_rng(12)
    pts, ders = _moved(c, rng, 1e-3)
    # a tie: the same largest move at two places far apart (the earlier one must win)
    for k in (n // 5, 4 * n // 5):
        pts[k] = np.asarray(c.points)[k] + 0.5
    delta = _fields(c, pts - c.points, [d - e for d, e in zip(ders, c._derivs, strict=True)])
    ref = delta_deviation(c, delta)
    got = hermite_delta_deviation(c, pts, tuple(ders))
    assert got is not None
    assert [x.hex() for x in got] == [float(x).hex() for x in
                                      (ref.max_distance, ref.upper_bound, ref.param)]


# -- B-splines: bspline_delta_deviation ------------------------------------------------------

def _bspline(p: int, n: int, dim: int, closed: bool, seed: int, repeated: bool = False):
    rng = np.random.default_rng(seed)
    if closed:
        a = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
        P = np.c_[np.cos(a), np.sin(a), 0.2 * np.sin(2 * a)][:, :dim] * 5.0
        return cf.interpolate_bspline(P + 0.02 * rng.normal(size=P.shape), p, closed=True)
    P = np.cumsum(rng.normal(size=(n, dim)), axis=0)
    inner = np.sort(rng.uniform(0.0, 10.0, n - p - 1))
    if repeated and inner.size > 4:
        inner[3] = inner[2]  # a double knot (one span of zero width, skipped)
        inner = np.sort(inner)
    knots = np.r_[[0.0] * (p + 1), inner, [10.0] * (p + 1)]
    return cf.BSplineCurve(P, knots, p)


BCASES = [(p, n, dim, closed, seed, rep)
          for p in (2, 3, 5) for n in (8, 40, 400) for dim in (2, 3)
          for closed in (False, True) for seed in (0,) for rep in ((False, True) if not closed
                                                                   else (False,))]


@pytest.mark.parametrize(("p", "n", "dim", "closed", "seed", "rep"), BCASES)
def test_bspline_same_bits_as_the_whole_form(p, n, dim, closed, seed, rep):
    from curvefair.analysis import bspline_delta_deviation

    c = _bspline(p, n, dim, closed, seed, rep)
    rng = np.random.default_rng(50 + n)
    for scale in (1e-4, 0.2):
        cb = np.asarray(c.control_points) + scale * rng.normal(size=c.control_points.shape)
        ref = delta_deviation(c, {"control_points": cb - c.control_points})
        got = bspline_delta_deviation(c, cb)
        assert got is not None
        assert [x.hex() for x in got] == [float(x).hex() for x in
                                          (ref.max_distance, ref.upper_bound, ref.param)]


def test_bspline_brackets_scipy_and_runs_on_two_threads():
    """A long cubic (past _PAR_MIN spans: the threaded path) against scipy's BSpline of the
    control points' differences, sampled densely near the certified maximum; and bit for bit
    the whole form's figures."""
    from scipy.interpolate import BSpline

    from curvefair.analysis import _deviation, bspline_delta_deviation

    n = _deviation._PAR_MIN + 10_000
    c = _bspline(3, n, 2, False, 4)
    rng = np.random.default_rng(3)
    cb = np.asarray(c.control_points) + 1e-3 * rng.normal(size=c.control_points.shape)
    got = bspline_delta_deviation(c, cb)
    ref = delta_deviation(c, {"control_points": cb - c.control_points})
    assert got == (ref.max_distance, ref.upper_bound, ref.param)
    best, ub, param = got
    f = BSpline(np.asarray(c.knots), cb - c.control_points, 3)
    s = np.linspace(0.0, 10.0, 2_000_001)
    dense = float(np.max(np.linalg.norm(f(s), axis=1)))
    assert dense <= ub * (1 + 1e-12)
    assert best >= dense * (1 - 1e-6)
    assert np.linalg.norm(f(param)) == pytest.approx(best, rel=1e-9)


def test_bspline_shape_error_and_non_finite():
    from curvefair.analysis import bspline_delta_deviation

    c = _bspline(3, 12, 2, False, 0)
    with pytest.raises(CurvefairError, match="bspline_delta_deviation"):
        bspline_delta_deviation(c, np.asarray(c.control_points)[:-1])
    cb = np.array(c.control_points)
    cb[5, 1] = np.inf
    assert bspline_delta_deviation(c, cb) is None
