"""deviation(): maximum distance between two curves, checked against brute-force sampling.

Reference: |a(t) - b(t)| at 10^6 equally spaced parameters (plus the breakpoints), evaluated by
scipy's own spline objects where possible; it is a lower bound of the true maximum, within
O(spacing^2) of it.
"""

import json

import numpy as np
import pytest
from scipy.interpolate import CubicHermiteSpline

import curvefair as cf
from curvefair.errors import InputError


def _brute(fa, fb, t0, t1, extra=()):
    t = np.concatenate([np.linspace(t0, t1, 1_000_001), np.asarray(extra, dtype=float)])
    d = np.linalg.norm(fa(t) - fb(t), axis=1)
    k = int(np.argmax(d))
    return float(d[k]), float(t[k])


def _check(dev, brute, scale):
    # brute force never exceeds the certified maximum, and is close to it
    assert dev.max_distance >= brute - 1e-12 * scale
    assert dev.max_distance <= brute + 1e-7 * scale
    assert dev.upper_bound >= dev.max_distance
    assert dev.upper_bound - dev.max_distance <= 1e-12 * dev.max_distance + 1e-12 * scale


@pytest.mark.parametrize("dim", [2, 3])
def test_same_breakpoints_vs_brute_force(dim):
    rng = np.random.default_rng(dim)
    pts = np.cumsum(rng.normal(size=(30, dim)), axis=0)
    a = cf.interpolate_cubic(pts)
    moved = pts + 0.05 * rng.normal(size=pts.shape)
    b = cf.interpolate_cubic(moved, param=a.params)
    dev = cf.deviation(a, b)
    ref_a = CubicHermiteSpline(a.params, a.points, a.tangents, axis=0)
    ref_b = CubicHermiteSpline(b.params, b.points, b.tangents, axis=0)
    brute, tb = _brute(ref_a, ref_b, *a.domain, a.params)
    _check(dev, brute, np.abs(pts).max())
    assert dev.param == pytest.approx(tb, abs=1e-3 * np.ptp(a.params))
    np.testing.assert_allclose(dev.point_a, ref_a(dev.param), atol=1e-12)
    np.testing.assert_allclose(dev.point_b, ref_b(dev.param), atol=1e-12)
    assert np.linalg.norm(dev.point_a - dev.point_b) == pytest.approx(dev.max_distance,
                                                                      rel=1e-12)
    d = np.linalg.norm(pts - moved, axis=1)
    assert dev.point_index == int(np.argmax(d))
    assert dev.max_point_displacement == pytest.approx(d.max(), rel=1e-15)


def test_different_breakpoints_and_degrees():
    # a: cubic through 17 points, b: quintic through 11 others, both on parameters [0, 1]
    f = lambda t: np.c_[np.cos(3 * t), np.sin(2 * t)]  # noqa: E731
    ta, tb = np.linspace(0, 1, 17), np.sort(np.r_[0, np.random.default_rng(1).uniform(0, 1, 9), 1])
    a = cf.interpolate_cubic(f(ta), param=ta)
    b = cf.interpolate_quintic(f(tb), param=tb)
    dev = cf.deviation(a, b)
    brute, _ = _brute(a, b, 0.0, 1.0, np.r_[ta, tb])
    _check(dev, brute, 1.0)
    assert dev.max_point_displacement is None and dev.point_index is None  # counts differ
    # symmetric
    assert cf.deviation(b, a).max_distance == pytest.approx(dev.max_distance, rel=1e-12)


def test_closed_curves_and_bspline():
    th = np.linspace(0, 2 * np.pi, 25)[:-1]
    pts = np.c_[np.cos(th), 0.6 * np.sin(th), 0.1 * np.sin(3 * th)]
    a = cf.interpolate_cubic(pts, bc="periodic")
    b = cf.interpolate_cubic(pts * 1.01, param=a.params, bc="periodic")
    dev = cf.deviation(a, b)
    brute, _ = _brute(a, b, *a.domain)
    _check(dev, brute, 1.0)
    assert dev.point_index is not None and dev.point_index < 24
    bs = cf.interpolate_bspline(pts[:12, :2], degree=3, param=np.linspace(0, 1, 12))
    cub = cf.interpolate_cubic(pts[:12, :2] + 0.01, param=np.linspace(0, 1, 12))
    dev2 = cf.deviation(bs, cub)
    brute2, _ = _brute(bs, cub, 0.0, 1.0)
    _check(dev2, brute2, 1.0)
    assert dev2.max_point_displacement is None  # control points vs data points: not compared


def test_bspline_control_point_displacement_bounds_deviation():
    # lecture notes 004 eqs. (8.34)-(8.36): on equal knots the curve moves at most as far as
    # the farthest control point
    rng = np.random.default_rng(4)
    a = cf.interpolate_bspline(np.cumsum(rng.normal(size=(12, 2)), axis=0), degree=3)
    ctrl = np.array(a.control_points)
    ctrl[5] += [0.3, -0.2]
    b = a.replace(control_points=ctrl)
    dev = cf.deviation(a, b)
    assert dev.point_index == 5
    assert dev.max_point_displacement == pytest.approx(np.hypot(0.3, 0.2), rel=1e-15)
    assert dev.max_distance <= dev.max_point_displacement + 1e-15
    brute, _ = _brute(a, b, *a.domain)
    _check(dev, brute, np.abs(ctrl).max())


def test_identical_and_translated_curves():
    rng = np.random.default_rng(5)
    pts = np.cumsum(rng.normal(size=(2000, 2)), axis=0)
    a = cf.interpolate_cubic(pts)
    dev0 = cf.deviation(a, a)
    assert dev0.max_distance == 0.0 and dev0.upper_bound == 0.0
    # a translated copy is at constant distance: the bound search must not explode
    b = cf.CubicHermite(a.points + [3.0, 4.0], a.tangents, a.params)
    dev = cf.deviation(a, b)
    assert dev.max_distance == pytest.approx(5.0, rel=1e-12)
    assert dev.upper_bound == pytest.approx(5.0, rel=1e-12)


def test_to_dict_and_bad_input():
    a = cf.interpolate_cubic([[0, 0], [1, 1], [2, 0], [3, 1]])
    d = cf.deviation(a, cf.interpolate_cubic(a.points + 0.1, param=a.params)).to_dict()
    json.dumps(d, allow_nan=False)
    assert isinstance(d["point_a"], list) and isinstance(d["point_index"], int)
    with pytest.raises(InputError, match="domain"):
        cf.deviation(a, cf.interpolate_cubic(a.points, param=a.params * 2), kind="parametric")
    with pytest.raises(InputError, match="kind"):
        cf.deviation(a, a, kind="hausdorff")
    with pytest.raises(InputError, match="3-D"):
        cf.deviation(a, cf.interpolate_cubic(np.c_[a.points, np.zeros(4)], param=a.params))
    with pytest.raises(InputError, match="curve_b"):
        cf.deviation(a, a.points)
    with pytest.raises(InputError, match="curve_a"):
        cf.deviation(None, a)


# ---------------------------------------------------------------------------------------------
# geometric (Hausdorff) distance: curves with different parameter domains
# ---------------------------------------------------------------------------------------------
def _hausdorff_reference(a, b, n=400_001, top=10):
    """max(h(a, b), h(b, a)) with scipy: the distance of a point to the other curve by dense
    sampling (k-d tree) and bounded minimisation around the nearest sample, maximised over
    the curve by bounded (Brent) maximisation around the largest of 20,001 samples."""
    from scipy.optimize import minimize_scalar
    from scipy.spatial import cKDTree

    def directed(x_curve, y_curve):
        uy = np.linspace(*y_curve.domain, n)
        tree = cKDTree(y_curve(uy))
        h = uy[1] - uy[0]

        def dist(t):
            x = x_curve(t).reshape(-1)
            d0, j = tree.query(x)
            lo, hi = max(uy[j] - 2 * h, uy[0]), min(uy[j] + 2 * h, uy[-1])
            r = minimize_scalar(lambda s: float(np.linalg.norm(y_curve(s) - x)),
                                bounds=(lo, hi), method="bounded", options={"xatol": 1e-14})
            return min(float(r.fun), float(d0))

        ux = np.linspace(*x_curve.domain, 20_001)
        d = tree.query(x_curve(ux))[0]
        hx = ux[1] - ux[0]
        out = 0.0
        for i in np.argsort(-d)[:top]:
            lo, hi = max(ux[i] - hx, ux[0]), min(ux[i] + hx, ux[-1])
            r = minimize_scalar(lambda t: -dist(t), bounds=(lo, hi), method="bounded",
                                options={"xatol": 1e-13})
            out = max(out, -float(r.fun), dist(ux[i]))
        return out

    return max(directed(a, b), directed(b, a))


def test_geometric_distance_of_reparametrised_and_offset_curves():
    th = np.pi * np.linspace(0.0, 1.0, 25) ** 1.5  # uneven spacing: chord != uniform
    p = np.c_[np.cos(th), np.sin(th)]
    a = cf.interpolate_cubic(p)                       # chord-length parameters
    # the same points, uniform parameters on another domain: another curve, close to a
    b = cf.interpolate_cubic(p, param=np.linspace(0.0, 7.0, 25))
    # scaled points: chord parameters scaled too, so the domains differ
    c = cf.interpolate_cubic(1.01 * p)
    for x, y in ((a, b), (a, c), (b, c)):
        d = cf.deviation(x, y)
        assert d.kind == "geometric" and d.upper_bound is None
        ref = _hausdorff_reference(x, y)
        # (scipy's bounded search stops at a relative parameter tolerance ~1.5e-8)
        assert d.max_distance == pytest.approx(ref, rel=1e-6, abs=1e-7)
        # the two points it names are on the curves and that far apart
        assert np.linalg.norm(d.point_a - d.point_b) == pytest.approx(d.max_distance, rel=1e-9)
        assert np.linalg.norm(d.point_a - x(d.param)) <= 1e-12
        # the cheap bound of one dense pass: above the distance, within a sample gap of it
        from curvefair.analysis import geometric_upper_bound

        ub = geometric_upper_bound(x, y)
        length = max(float(np.sum(np.linalg.norm(np.diff(cv(np.linspace(*cv.domain, 20001)),
                                                          axis=0), axis=1))) for cv in (x, y))
        assert ref * (1 - 1e-9) <= ub <= ref + length / 2048


def test_geometric_distance_exact_cases():
    # a straight line and the same line parametrised 5 times faster, then shifted by 0.3
    a = cf.interpolate_cubic(np.c_[np.linspace(0, 1, 6), np.zeros(6)], param=np.linspace(0, 1, 6))
    b = cf.interpolate_cubic(np.c_[np.linspace(0, 1, 6), np.full(6, 0.3)],
                             param=np.linspace(0, 5, 6))
    assert cf.deviation(a, b).max_distance == pytest.approx(0.3, rel=1e-12)
    b0 = cf.interpolate_cubic(a.points, param=np.linspace(2, 7, 6))
    assert cf.deviation(a, b0).max_distance <= 1e-12
    # a shorter curve: the uncovered end of the longer one counts (h(a, b) side)
    short = cf.interpolate_cubic(np.c_[np.linspace(0, 0.8, 5), np.zeros(5)])
    assert cf.deviation(a, short).max_distance == pytest.approx(0.2, rel=1e-12)
    assert cf.deviation(short, a).max_distance == pytest.approx(0.2, rel=1e-12)
    # kind="geometric" on equal domains never exceeds the parametric figure
    rng = np.random.default_rng(3)
    pts = np.cumsum(rng.normal(size=(40, 2)), axis=0)
    u = cf.interpolate_cubic(pts)
    v = cf.interpolate_cubic(pts + rng.normal(scale=0.05, size=pts.shape), param=u.params)
    geo, par = cf.deviation(u, v, kind="geometric"), cf.deviation(u, v, kind="parametric")
    assert geo.max_distance <= par.upper_bound
    assert geo.max_distance == pytest.approx(_hausdorff_reference(u, v), rel=1e-6)


def test_geometric_distance_finds_nearest_point_on_long_straight_piece():
    """A long straight piece next to short curved ones (an SVG glyph stem): the nearest point
    lies on the long piece between its samples."""
    from curvefair import BSplineCurve

    P = np.array([[0, 0], [0, 1], [0, 2], [0, 100], [1, 100.5], [2, 100], [2, 99]], float)
    knots = np.r_[0, 0, 0, 0, 3, 3, 3, 9, 9, 9, 9].astype(float)  # a C0 corner at 3
    a = BSplineCurve(P, knots, 3)
    b = BSplineCurve(P + [0.25, 0.0], knots * 2.0, 3)
    d = cf.deviation(a, b)
    assert d.kind == "geometric"
    assert d.max_distance == pytest.approx(_hausdorff_reference(a, b), rel=1e-6)


@pytest.mark.parametrize("dim,closed", [(2, False), (3, False), (2, True)])
def test_matched_hermite_bound_kernel_vs_numpy_and_dense_sampling(dim, closed):
    """The compiled per-span bound of two Hermite curves through as many points equals the
    numpy form to rounding, and bounds |b(t) - a(psi(t))| sampled densely with scipy's
    CubicHermiteSpline on every span (psi maps b's parameters onto a's, point i to point i), up
    to the rounding of evaluating the two curves separately."""
    from curvefair import _threads
    from curvefair._kernels.deviation import matched_hermite_bound_reference
    from curvefair.analysis import _deviation as _dev
    from curvefair.analysis import matched_hermite_bound

    rng = np.random.default_rng(11 + dim + 7 * closed)
    for n in (2, 3, 9, 120):
        if closed and n < 4:
            continue
        th = np.linspace(0, 2 * np.pi, n, endpoint=not closed)
        P = np.c_[np.cos(th), np.sin(th), 0.2 * th][:, :dim] * 10 + rng.normal(size=(n, dim))
        Q = P + 10.0 ** rng.integers(-6, -1) * rng.normal(size=P.shape)
        bc = "periodic" if closed else "natural"
        a = cf.interpolate_cubic(np.r_[P, P[:1]] if closed else P, bc=bc)
        b = cf.interpolate_cubic(np.r_[Q, Q[:1]] if closed else Q, bc=bc)
        for pieces in (1, 4, 6):
            got = matched_hermite_bound(a, b, pieces)
            ref = matched_hermite_bound_reference(a, b, pieces)
            assert got.shape == ref.shape == (len(a.params) - 1,)
            np.testing.assert_allclose(got, ref, rtol=1e-13, atol=1e-15 * float(ref.max()))
            with pytest.MonkeyPatch.context() as mp:  # span ranges on two threads: same bits
                mp.setattr(_threads, "THREADS", 2)
                mp.setattr(_dev, "_PAR_MIN", 2)
                assert matched_hermite_bound(a, b, pieces).tobytes() == got.tobytes()
        fa = CubicHermiteSpline(a.params, a.points, a.tangents)
        fb = CubicHermiteSpline(b.params, b.points, b.tangents)
        bound = matched_hermite_bound(a, b)
        for i in range(len(bound)):
            t = np.linspace(b.params[i], b.params[i + 1], 201)
            s = (t - b.params[i]) / (b.params[i + 1] - b.params[i])
            psi = a.params[i] + s * (a.params[i + 1] - a.params[i])
            d = np.linalg.norm(fb(t) - fa(psi), axis=1).max()
            # slack: the rounding of evaluating coordinates of size max|x| separately
            slack = 16 * np.finfo(float).eps * float(np.abs(P).max() + 1)
            assert d <= bound[i] + slack, (n, i, d, bound[i])


def test_geometric_distance_on_chosen_spans_against_scipy():
    """``deviation(a, b, kind="geometric", spans=S)``: the Hausdorff distance restricted to
    the pieces S of each curve, each point measured against the whole other curve (scipy:
    dense k-d tree and bounded minimisation); all spans give the whole-curve figure, none 0."""
    from scipy.optimize import minimize_scalar
    from scipy.spatial import cKDTree

    rng = np.random.default_rng(3)
    t = np.linspace(0.0, 3.0, 40)
    p = np.c_[t, np.sin(2 * t)] + rng.normal(scale=0.01, size=(40, 2))
    q = p + rng.normal(scale=0.02, size=(40, 2))
    a, b = cf.interpolate_cubic(p), cf.interpolate_cubic(q)  # each on its own chord lengths
    spans = [5, 6, 20, 38]

    def directed(x_curve, y_curve, pieces):
        uy = np.linspace(*y_curve.domain, 400_001)
        tree = cKDTree(y_curve(uy))
        hy = uy[1] - uy[0]

        def dist(s):
            x = x_curve(s).reshape(-1)
            d0, j = tree.query(x)
            lo, hi = max(uy[j] - 2 * hy, uy[0]), min(uy[j] + 2 * hy, uy[-1])
            r = minimize_scalar(lambda v: float(np.linalg.norm(y_curve(v) - x)),
                                bounds=(lo, hi), method="bounded", options={"xatol": 1e-14})
            return min(float(r.fun), float(d0))

        br = x_curve.params
        out = 0.0
        for i in pieces:
            ux = np.linspace(br[i], br[i + 1], 2001)
            d = tree.query(x_curve(ux))[0]
            k = int(np.argmax(d))
            lo, hi = ux[max(k - 1, 0)], ux[min(k + 1, len(ux) - 1)]
            r = minimize_scalar(lambda s: -dist(s), bounds=(lo, hi), method="bounded",
                                options={"xatol": 1e-13})
            out = max(out, -float(r.fun), dist(ux[k]))
        return out

    d = cf.deviation(a, b, kind="geometric", spans=spans)
    ref = max(directed(a, b, spans), directed(b, a, spans))
    assert d.kind == "geometric"
    assert d.max_distance == pytest.approx(ref, rel=1e-6, abs=1e-9)
    whole = cf.deviation(a, b, kind="geometric")
    assert d.max_distance <= whole.max_distance
    every = cf.deviation(a, b, kind="geometric", spans=np.arange(39))
    assert every.max_distance == whole.max_distance
    assert cf.deviation(a, b, kind="geometric", spans=[]).max_distance == 0.0
    with pytest.raises(cf.InputError, match="spans"):
        cf.deviation(a, b, kind="parametric", spans=[1])
    with pytest.raises(cf.InputError, match="0 .. 38"):
        cf.deviation(a, b, kind="geometric", spans=[39])


def test_many_equal_maxima_searched_compiled_and_trimmed(monkeypatch):
    """A result held on its tolerance has its largest deviation at many knots: every piece
    is a candidate of the branch-and-bound. The compiled levels take them all (the cap grows
    with the curve: an eighth of its pieces); with the cap forced below the candidates, the
    array levels trim the smallest bounds into ``upper_bound``, which stays certified.
    Checked against dense sampling of ``|a(t) - b(t)|``."""
    from curvefair.analysis import _deviation as D

    rng = np.random.default_rng(5)
    n = 4001
    t = np.linspace(0.0, 40.0, n)
    a = cf.interpolate_cubic(np.c_[t, np.sin(t)], param=t)
    # every point moved by exactly 0.01 (the tolerance ball's surface), direction random
    ang = rng.uniform(0, 2 * np.pi, n)
    moved = np.asarray(a.points) + 0.01 * np.c_[np.cos(ang), np.sin(ang)]
    b = cf.interpolate_cubic(moved, param=t)
    dense, _ = _brute(a, b, 0.0, 40.0)  # a lower bound of the true maximum, close to it
    full = cf.deviation(a, b)
    _check(full, dense, 40.0)  # the rounding level: 1e-13 of the largest coordinate (40)
    monkeypatch.setattr(D, "_MAX_CANDIDATES", 8)
    monkeypatch.setattr(D, "_CANDIDATE_SHARE", 10**9)  # cap = 8 pieces
    seen = []
    bnb = D._k.branch_and_bound
    monkeypatch.setattr(D._k, "branch_and_bound",
                        lambda cb, *x: seen.append(cb.shape[0]) or bnb(cb, *x))
    trimmed = cf.deviation(a, b)
    assert seen and seen[0] > 8  # more candidates than the cap: the array levels trim
    assert dense - 1e-12 <= trimmed.upper_bound  # still certified
    assert trimmed.max_distance <= full.upper_bound
    assert trimmed.max_distance >= 0.999 * full.max_distance


@pytest.mark.parametrize("dim", [2, 3])
def test_nearest_point_newton_kernel_vs_numpy_and_dense_sampling(dim):
    """The compiled nearest-point Newton of the geometric distance (``_Nearest._newton``)
    against its numpy form, step for step: bit for bit in 2-D; in 3-D numpy's einsum may sum
    the three coordinates in another order (it does on AVX-512 CPUs), so to 1e-13 relative.
    Both against an independent figure: the distance to 200,001 samples of the curve (above
    the true nearest distance by at most the square of half the sample gap over twice the
    radius of curvature, far below the 1e-6 allowed)."""
    from curvefair.analysis._deviation import _GEO_NEIGHBOURS, _Nearest

    rng = np.random.default_rng(20 + dim)
    for trial in range(12):
        n = int(rng.integers(5, 60))
        t = np.linspace(0.0, 6.0, n)
        P = (np.c_[3 * np.cos(t), 2 * np.sin(1.7 * t), t][:, :dim]
             + 0.05 * rng.normal(size=(n, dim)))
        c = (cf.interpolate_cubic(P) if trial % 3 == 0 else
             cf.interpolate_bspline(P, degree=3 if trial % 3 == 1 else 5,
                                    closed=trial % 2 == 1))
        near = _Nearest(c)
        X = (np.asarray(c(np.sort(rng.uniform(*c.domain, 40))))
             + 0.3 * rng.normal(size=(40, dim)))
        k = _GEO_NEIGHBOURS
        d0, jj = near.tree.query(X, k=k)
        args = (np.repeat(X, k, axis=0), jj.reshape(-1), d0.reshape(-1))
        got, ref = near._newton(*args), near._newton_numpy(*args)
        if dim == 2:
            np.testing.assert_array_equal(got[0], ref[0])
            np.testing.assert_array_equal(got[1], ref[1])
        else:
            np.testing.assert_allclose(got[0], ref[0], rtol=1e-13, atol=0)
        # every distance is that of the curve point at the parameter returned
        pts = np.asarray(c(got[1]))
        np.testing.assert_allclose(np.linalg.norm(pts - args[0], axis=1), got[0],
                                   rtol=1e-12, atol=1e-14)
        # and the nearest one: dense samples
        from scipy.spatial import cKDTree

        dense = np.asarray(c(np.linspace(*c.domain, 200_001)))
        dd, _ = cKDTree(dense).query(X)
        best = got[0].reshape(-1, k).min(axis=1)
        assert np.all(best <= dd + 1e-12)
        np.testing.assert_allclose(best, dd, atol=1e-6, rtol=0)


def test_points_for_the_golden_search_are_the_curves_own():
    """``_at`` (the compiled Horner evaluation of the geometric distance's search) gives the
    curve's own ``c(t)`` bit for bit: open and closed, 2-D and 3-D, cubic Hermite and cubic /
    quintic B-splines, at random parameters, the domain's ends and every breakpoint (where
    the segment chosen matters)."""
    from curvefair.analysis._deviation import _at

    rng = np.random.default_rng(3)
    for trial in range(24):
        dim, closed = 2 + trial % 2, trial % 3 == 0
        P = rng.normal(size=(int(rng.integers(8, 40)), dim)).cumsum(axis=0)
        if trial % 4 < 2:
            c = cf.interpolate_cubic(np.vstack([P, P[:1]]) if closed else P,
                                     bc="periodic" if closed else "natural")
        else:
            c = cf.interpolate_bspline(P, degree=3 + 2 * (trial % 2), closed=closed)
        t0, t1 = c.domain
        t = np.r_[rng.uniform(t0, t1, 50), t0, t1, np.asarray(c.piecewise.breaks)]
        np.testing.assert_array_equal(_at(c, t), np.asarray(c(t)))
