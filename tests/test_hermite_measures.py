"""The bad-point measures of the Hermite loops (``fair(..., measure=...)``) against independent
computations (scipy's Hermite splines, quadrature, finite differences), and the per-kind
defaults of the method registry."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.interpolate import BPoly, CubicHermiteSpline

from curvefair import (
    InputError,
    fair,
    interpolate_bspline,
    interpolate_cubic,
    interpolate_quintic,
    steps,
)
from curvefair.curves.hermite import CubicHermite, QuinticHermite
from curvefair.fairing.fair import FairingReport


def _cubic(rng, n=9, dim=2, uniform=False):
    t = np.arange(n, dtype=float) * 0.7 if uniform else np.cumsum(rng.uniform(0.2, 1.5, n))
    P = rng.normal(size=(n, dim))
    T = rng.normal(size=(n, dim))
    return CubicHermite(P, T, t)


def _e2_scipy(params, P, T, lo, hi):
    """int |r''|^2 over [params[lo], params[hi]] with scipy's CubicHermiteSpline and quad."""
    spl = CubicHermiteSpline(params, P, T, axis=0)
    d2 = spl.derivative(2)
    return sum(quad(lambda s: float(np.sum(d2(s) ** 2)), params[j], params[j + 1],
                    epsabs=0, epsrel=1e-13)[0] for j in range(lo, hi))


@pytest.mark.parametrize("method", ["poliakoff", "wang-cao", "kjellander"])
def test_energy_is_the_exact_drop_of_the_step(method):
    rng = np.random.default_rng(3)
    for trial in range(4):
        c = _cubic(rng, dim=2 + trial % 2, uniform=method == "kjellander")
        k = 2 + trial
        step = {"poliakoff": steps.poliakoff, "wang-cao": steps.wang_cao,
                "kjellander": steps.kjellander}[method]
        new = step(c, k)
        t = np.asarray(c.params)
        before = _e2_scipy(t, np.asarray(c.points), np.asarray(c.tangents), k - 1, k + 1)
        after = _e2_scipy(t, np.asarray(new.points), np.asarray(new.tangents), k - 1, k + 1)
        got = steps.bad_point_measure(c, k, method, "energy")
        assert got == pytest.approx(before - after, rel=1e-8, abs=1e-12 * before)


@pytest.mark.parametrize("method", ["poliakoff", "wang-cao", "kjellander"])
def test_move_is_the_step_length(method):
    rng = np.random.default_rng(5)
    c = _cubic(rng, uniform=method == "kjellander")
    step = {"poliakoff": steps.poliakoff, "wang-cao": steps.wang_cao,
            "kjellander": steps.kjellander}[method]
    for k in range(1, 8):
        want = np.linalg.norm(np.asarray(step(c, k).points)[k] - np.asarray(c.points)[k])
        assert steps.bad_point_measure(c, k, method, "move") == pytest.approx(want, rel=1e-12)


def _kappa(d1, d2):
    if d1.shape[-1] == 2:
        cross = d1[..., 0] * d2[..., 1] - d1[..., 1] * d2[..., 0]
        return cross / np.linalg.norm(d1, axis=-1) ** 3
    return np.linalg.norm(np.cross(d1, d2), axis=-1) / np.linalg.norm(d1, axis=-1) ** 3


@pytest.mark.parametrize("dim", [2, 3])
def test_sapidis_is_the_jump_of_dkappa_ds_by_finite_differences(dim):
    rng = np.random.default_rng(11 + dim)
    u = np.cumsum(rng.uniform(0.2, 1.0, 10))
    pts = np.c_[u, np.sin(u), np.cos(0.7 * u)][:, :dim] + rng.normal(0, 0.05, (10, dim))
    c = interpolate_cubic(pts, u)  # non-uniform, noisy, curvature of order 1
    t, P, T = np.asarray(c.params), np.asarray(c.points), np.asarray(c.tangents)
    for k in range(1, 8):
        sides = []
        for a, b, sgn in ((k - 1, k, -1.0), (k, k + 1, 1.0)):
            seg = CubicHermiteSpline(t[[a, b]], P[[a, b]], T[[a, b]], axis=0)
            e = 1e-3 * (t[b] - t[a])
            s = t[k] + sgn * e * np.arange(5)
            kap = _kappa(seg(s, 1), seg(s, 2))
            # one-sided fourth-order difference
            dk_dt = sgn * (-25 * kap[0] + 48 * kap[1] - 36 * kap[2] + 16 * kap[3]
                           - 3 * kap[4]) / (12 * e)
            sides.append(dk_dt / np.linalg.norm(T[k]))
        want = abs(sides[1] - sides[0])
        got = steps.bad_point_measure(c, k, "poliakoff", "sapidis")
        assert got == pytest.approx(want, rel=1e-5, abs=1e-8 * max(map(abs, sides)))


def test_quintic_measures_against_scipy():
    rng = np.random.default_rng(2)
    n = 8
    t = np.cumsum(rng.uniform(0.3, 1.4, n))
    P, D1, D2 = rng.normal(size=(3, n, 2))
    q = QuinticHermite(P, D1, D2, t)

    def e2(Pv, A, B, lo, hi):
        y = np.stack([Pv, A, B], axis=1)  # (n, 3, dim)
        bp = BPoly.from_derivatives(t, y)
        d2 = bp.derivative(2)
        return sum(quad(lambda s: float(np.sum(d2(s) ** 2)), t[j], t[j + 1],
                        epsabs=0, epsrel=1e-13)[0] for j in range(lo, hi))

    for k in range(1, n - 1):
        new = steps.wang_quintic(q, k)
        nP, nA, nB = (np.asarray(new.points), np.asarray(new._derivs[0]),
                      np.asarray(new._derivs[1]))
        drop = e2(P, D1, D2, k - 1, k + 1) - e2(nP, nA, nB, k - 1, k + 1)
        assert steps.bad_point_measure(q, k, "wang-quintic", "energy") == pytest.approx(
            drop, rel=1e-7)
        assert steps.bad_point_measure(q, k, "wang-quintic", "move") == pytest.approx(
            np.linalg.norm(nP[k] - P[k]), rel=1e-10)


def _noisy(n=60, seed=0):
    rng = np.random.default_rng(seed)
    s = np.linspace(0, 3, n)
    return np.c_[s, np.sin(s)] + rng.normal(0, 2e-3, (n, 2))


def test_fair_measure_option():
    pts = _noisy()
    c = interpolate_cubic(pts)
    base = fair(c, "poliakoff", tol=6e-3)
    same = fair(c, "poliakoff", tol=6e-3, measure="move")  # the default
    assert base.report["measure"] == "step_length"
    assert fair(c, "poliakoff", tol=6e-3, measure="jump").report["measure"] == (
        "third_derivative_jump")
    assert np.array_equal(np.asarray(base.curve.points), np.asarray(same.curve.points))
    assert np.array_equal(base.history.measure, same.history.measure)
    for m, name in [("energy", "energy_drop"), ("sapidis", "dkappa_ds_jump"),
                    ("move", "step_length")]:
        r = fair(c, "wang-cao", tol=6e-3, measure=m)
        assert r.report["measure"] == name
        moved = np.linalg.norm(np.asarray(r.curve.points) - pts, axis=1)
        assert r.report["steps"] > 0 and moved.max() <= 6e-3
        # the first step moves the point with the largest measure, as computed independently
        first = int(r.history.index[0])
        ms = [steps.bad_point_measure(interpolate_cubic(pts), i, "wang-cao", m, mode="spline")
              for i in range(1, len(pts) - 1)]
        assert first == 1 + int(np.argmax(ms))
    q = interpolate_quintic(pts)
    assert fair(q, "wang-quintic", tol=6e-3, measure="move").report["measure"] == "step_length"
    with pytest.raises(InputError, match="'sapidis'.*valid values are: 'energy', 'move'"):
        fair(q, "wang-quintic", tol=6e-3, measure="sapidis")
    with pytest.raises(InputError, match="valid values are: 'jump', 'energy', 'sapidis', 'move'"):
        fair(c, "poliakoff", tol=6e-3, measure="bogus")


def test_bspline_default_is_global_l3_keeping_the_structure():
    pts = _noisy(50, 4)
    b = interpolate_bspline(pts, 3)
    d = fair(b, tol=5e-3)
    g = fair(b, "global", tol=5e-3, l=3)
    assert d.report["method"] == "global" and d.report["l"] == 3
    assert np.array_equal(np.asarray(d.curve.control_points), np.asarray(g.curve.control_points))
    assert np.array_equal(np.asarray(d.curve.knots), np.asarray(b.knots))
    assert d.curve.degree == b.degree and d.curve.n_ctrl == b.n_ctrl
    # the caller's option wins; degree 2 has no E3: l=2
    assert fair(b, tol=5e-3, l=2).report["l"] == 2
    assert fair(interpolate_bspline(pts, 2), tol=5e-3).report["l"] == 2


def test_methods_command_says_the_default_and_why():
    from click.testing import CliRunner

    from curvefair.cli import main

    out = CliRunner().invoke(main, ["methods"]).output
    line = next(s for s in out.splitlines() if s.startswith("default for BSplineCurve: global"))
    assert "global" in line and "16/84" in line
    js = CliRunner().invoke(main, ["methods", "--json"]).output
    import json

    rows = {r["name"]: r for r in json.loads(js)}
    assert rows["global"]["default"] and "l=3" in rows["global"]["default_options"]
    # eck-hadenfeld is the default only above global_fair.DEFAULT_MAX_CTRL control points
    assert rows["eck-hadenfeld"]["default"] and "200,000" in rows["eck-hadenfeld"]["default_reason"]


def test_structure_free_removes_knots_within_tol():
    pts = _noisy(120, 7)
    b = interpolate_bspline(pts, 3)
    r = fair(b, tol=4e-3, structure="free")
    st = r.report["structure"]
    assert r.curve.n_ctrl < b.n_ctrl and st["knots_removed"] == b.n_ctrl - r.curve.n_ctrl
    assert r.curve.degree == 3 and set(np.asarray(r.curve.knots)) <= set(np.asarray(b.knots))
    # independent check of the tolerance: dense sampling at equal parameter
    u = np.linspace(*b.domain, 20001)
    assert np.linalg.norm(r.curve(u) - b(u), axis=1).max() <= 4e-3
    assert r.report["extrema_before"] == fair(b, tol=4e-3).report["extrema_before"]
    # the report is a FairingReport like every other fair() report (it was a plain dict,
    # without to_dict()): JSON-ready, its per-point entries as lists
    assert isinstance(r.report, FairingReport)
    d = json.loads(json.dumps(r.report.to_dict()))
    assert d["structure"]["knots_removed"] == st["knots_removed"]
    assert d["moved"]["indices"] == np.asarray(r.report["moved"]["indices"]).tolist()
    with pytest.raises(InputError, match="structure"):
        fair(b, tol=4e-3, structure="new")


@pytest.mark.parametrize("degree", [3, 5])
@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("dim", [2, 3])
def test_range_measures_are_measure_at_bit_for_bit(closed, dim, degree):
    """The loop's measures of a range (each segment's coefficients computed once, for the
    cubic jump, Poliakoff's and Wang-Cao's move and the quintic measures) and of the whole
    curve are the bytes of the per-point :func:`measure_at`, for every method and measure
    code, on ranges that wrap round a closed curve's seam."""
    from curvefair._kernels import hermite as k
    from curvefair.fairing.hermite_data import distinct_data

    rng = np.random.default_rng(40 + dim + 2 * closed)
    n = 23
    t = np.cumsum(rng.uniform(0.05, 3.0, n))
    P = rng.normal(size=(n, dim)) * rng.uniform(0.1, 100.0)
    T = rng.normal(size=(n, dim))
    if closed:
        P[-1], T[-1] = P[0], T[0]
    if degree == 3:
        curve = CubicHermite(P, T, t, closed=closed)
    else:
        S = rng.normal(size=(n, dim)) * 3.0
        if closed:
            S[-1] = S[0]
        curve = QuinticHermite(P, T, S, t, closed=closed)
    Pd, D, h = distinct_data(curve)
    nd = Pd.shape[0]
    assert nd == n - closed
    ranges = [(-4, 5), (nd - 6, nd + 3), (0, nd - 1), (7, 7)] if closed else \
        [(1, nd - 2), (1, 1), (nd - 2, nd - 2), (5, 12), (4, 3)]
    seen = set()
    for method in (k.KJELLANDER, k.POLIAKOFF, k.WANG_CAO):
        for mcode in (k.M_DEFAULT, k.M_ENERGY, k.M_SAPIDIS, k.M_MOVE):
            for spline in (False, True):
                args = (Pd, D, h, closed, degree, spline, method, 0.7, mcode)
                mf = k.fast_measure_code(degree, method, mcode)
                seen.add(mf)
                # an open curve's end points have no measure (one segment each)
                ref = np.array([k.measure_at(Pd, D, h, i, degree, spline, method, 0.7, mcode)
                                if closed or 0 < i < nd - 1 else 0.0 for i in range(nd)])
                for a, b in ranges:
                    out = np.full(max(b - a + 1, 0), np.nan)
                    seg = np.empty((b - a + 3, 4, dim))
                    k.range_measures(*args, mf, a, b, seg, out)
                    want = ref[np.arange(a, b + 1) % nd]
                    assert out.tobytes() == want.tobytes(), (method, mcode, a, b)
                whole = k.all_measures(*args)
                assert whole.tobytes() == ref.tobytes()
    assert seen == ({k.MF_GENERIC, k.MF_JUMP, k.MF_POLIAKOFF_MOVE, k.MF_WANG_CAO_MOVE}
                    if degree == 3 else {k.MF_QUINTIC, k.MF_QUINTIC_MOVE})
