"""The automatic Hermite fairing loop fair(): consistency, clamps, tolerance, protection, report.

Independent references: scipy's CubicSpline / make_interp_spline and curvefair's
interpolate_cubic / interpolate_quintic (full O(n) solves) for the windowed re-interpolation;
replaying the loop's history with the public single steps; dense evaluation of end derivatives.
"""

import json

import numpy as np
import pytest
from scipy.interpolate import CubicSpline

from curvefair import InputError, interpolate_cubic, interpolate_quintic, steps
from curvefair.fairing import FairingResult, available_methods, fair
from curvefair.fairing.local_hermite import hold_zone_cubic

CUBIC = ["poliakoff", "wang-cao"]


def _noisy(n, dim=2, seed=0, noise=0.02, closed=False):
    rng = np.random.default_rng(seed)
    if closed:
        th = np.linspace(0, 2 * np.pi, n + 1)[:-1]
        pts = np.c_[np.cos(th), np.sin(th)] * 3
        if dim == 3:
            pts = np.c_[pts, 0.5 * np.sin(2 * th)]
    else:
        th = np.linspace(0, 3, n)
        pts = np.c_[th * 2, np.sin(2 * th)]
        if dim == 3:
            pts = np.c_[pts, np.cos(th)]
    return pts + noise * rng.normal(size=pts.shape)


def _rel(a, b):
    return np.abs(np.asarray(a) - np.asarray(b)).max() / max(np.abs(np.asarray(b)).max(), 1e-300)


def _example1():
    pts = np.column_stack([np.arange(1.0, 8.0), np.ones(7)])
    pts[3] = (4.3, 1.6)
    return pts


# ----------------------------------------------------------------------------------------------
# spline mode: the output is exactly the interpolating spline of its points
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("method", CUBIC)
@pytest.mark.parametrize("n,dim", [(12, 2), (300, 3)])
def test_cubic_spline_mode_equals_reinterpolation_natural(method, n, dim):
    c = interpolate_cubic(_noisy(n, dim, seed=n), "chord", "natural")
    res = fair(c, method, tol=0.03, eps=0.0, max_steps=4 * n)
    assert res.report["steps"] > 0
    ref = interpolate_cubic(res.curve.points, c.params, "natural")
    assert _rel(res.curve.tangents, ref.tangents) < 1e-12


def test_cubic_spline_mode_g1_equals_clamped_reinterpolation():
    c = interpolate_cubic(_noisy(250, 2, seed=3), "centripetal", "not-a-knot")
    res = fair(c, "poliakoff", tol=0.02, eps=0.0, max_steps=1500, clamp="g1")
    ref = CubicSpline(c.params, res.curve.points, axis=0,
                      bc_type=((1, c.tangents[0]), (1, c.tangents[-1])))
    assert _rel(res.curve.tangents, ref(c.params, 1)) < 1e-12
    np.testing.assert_array_equal(res.curve.tangents[[0, -1]], c.tangents[[0, -1]])


@pytest.mark.parametrize("n", [15, 400])  # dense inverse path / windowed path
def test_cubic_closed_spline_mode_equals_periodic_reinterpolation(n):
    c = interpolate_cubic(_noisy(n, 2, seed=n, closed=True), "chord", "periodic")
    res = fair(c, "wang-cao", tol=0.05, eps=0.0, max_steps=3 * n)
    assert res.report["steps"] > 0
    ref = interpolate_cubic(res.curve.points, c.params, "periodic")
    assert _rel(res.curve.tangents, ref.tangents) < 1e-12
    np.testing.assert_array_equal(res.curve.points[0], res.curve.points[-1])


def test_closed_seam_is_eligible():
    pts = _noisy(12, 2, seed=5, noise=0.0, closed=True)
    pts[0] *= 1.3  # the seam is the bad point
    c = interpolate_cubic(pts, bc="periodic")
    res = fair(c, "poliakoff", eps=0.0, max_steps=1)
    assert res.history.index[0] == 0
    np.testing.assert_array_equal(res.curve.points[0], res.curve.points[-1])
    assert np.abs(res.curve.points[0] - c.points[0]).max() > 0.1


@pytest.mark.parametrize("n", [10, 200])
def test_quintic_spline_mode_equals_reinterpolation(n):
    q = interpolate_quintic(_noisy(n, 2, seed=7 + n, noise=0.05))
    res = fair(q, "wang-quintic", tol=0.05, eps=0.0, max_steps=3 * n)
    assert res.report["steps"] > 0
    ref = interpolate_quintic(res.curve.points, q.params)  # natural, as the input
    assert _rel(res.curve.d1, ref.d1) < 1e-12
    assert _rel(res.curve.d2, ref.d2) < 1e-12


@pytest.mark.parametrize("n", [30, 200])  # dense inverse path / windowed path
def test_quintic_closed_spline_mode(n):
    q = interpolate_quintic(_noisy(n, 3, seed=9, closed=True), bc="periodic")
    res = fair(q, "wang-quintic", tol=0.05, eps=0.0, max_steps=100)
    ref = interpolate_quintic(res.curve.points, q.params, bc="periodic")
    assert _rel(res.curve.d1, ref.d1) < 1e-12
    assert _rel(res.curve.d2, ref.d2) < 1e-12


def test_spline_mode_replays_with_public_steps():
    # Loop = (step with the public function, re-interpolate with the full solver), repeated
    # at the indices the loop chose.
    pts = _noisy(20, 2, seed=11, noise=0.05)
    for method, fn in (("poliakoff", steps.poliakoff), ("wang-cao", steps.wang_cao)):
        c = interpolate_cubic(pts)
        res = fair(c, method, eps=0.0, max_steps=25, guard=False, joins="free")
        cur = c
        for k in res.history.index:
            cur = interpolate_cubic(fn(cur, int(k)).points, c.params, "natural")
        assert _rel(res.curve.points, cur.points) < 1e-10
        assert _rel(res.curve.tangents, cur.tangents) < 1e-10


@pytest.mark.parametrize("method,interp,fn", [
    ("poliakoff", interpolate_cubic, steps.poliakoff),
    ("wang-cao", interpolate_cubic, steps.wang_cao),
    ("wang-quintic", interpolate_quintic, steps.wang_quintic),
])
def test_hermite_mode_replays_with_public_steps(method, interp, fn):
    c = interp(_noisy(15, 3, seed=12, noise=0.05))
    res = fair(c, method, mode="hermite", eps=0.0, max_steps=30, guard=False, joins="free")
    cur = c
    for k in res.history.index:
        cur = fn(cur, int(k))
    assert _rel(res.curve.points, cur.points) < 1e-12
    for a, b in zip(res.curve._derivs, cur._derivs, strict=True):
        assert _rel(a, b) < 1e-12


@pytest.mark.parametrize("method,interp,fn", [
    ("poliakoff", interpolate_cubic, steps.poliakoff),
    ("wang-quintic", interpolate_quintic, steps.wang_quintic),
])
def test_large_curve_loop_replays_with_public_steps(method, interp, fn):
    """On data too large for the caches (60,000 points, above the loop's 4 MB threshold) the
    loop prefetches the runner-up's data while its steps jump far; the result must still be
    the public steps replayed at the indices it chose."""
    n = 60000
    c = interp(_noisy(n, 2, seed=13, noise=2e-4))
    res = fair(c, method, mode="hermite", eps=0.0, max_steps=60, guard=False, joins="free")
    k = np.asarray(res.history.index)
    assert np.mean(np.abs(np.diff(k)) > 16) > 0.5  # far jumps: the prefetching path ran
    cur = c
    for i in k:
        cur = fn(cur, int(i))
    assert _rel(res.curve.points, cur.points) < 1e-12
    for a, b in zip(res.curve._derivs, cur._derivs, strict=True):
        assert _rel(a, b) < 1e-12


def test_loop_picks_the_largest_third_derivative_jump():
    c = interpolate_cubic(_example1())
    res = fair(c, "poliakoff", eps=0.0, max_steps=1, measure="jump")  # the papers' measure
    pp = c.piecewise
    t = c.params[1:-1]
    i = np.arange(1, 6)
    jump = np.linalg.norm(pp.evaluate(t, 3, segment=i) - pp.evaluate(t, 3, segment=i - 1), axis=1)
    assert res.history.index[0] == 1 + int(np.argmax(jump))
    assert res.history.measure[0] == pytest.approx(jump.max(), rel=1e-12)
    assert res.history.displacement[0] == pytest.approx(
        np.linalg.norm(res.curve.points[res.history.index[0]] - c.points[res.history.index[0]]),
        rel=1e-12)


# ----------------------------------------------------------------------------------------------
# clamps
# ----------------------------------------------------------------------------------------------
def _end_derivs(curve, nu):
    t0, t1 = curve.domain
    pp = curve.piecewise
    return (pp.evaluate(np.array([t0]), nu, segment=np.array([0]))[0],
            pp.evaluate(np.array([t1]), nu, segment=np.array([pp.n_segments - 1]))[0])


def _scale(curve, nu):
    return np.abs(curve.piecewise.evaluate(curve.params, nu)).max()


@pytest.mark.parametrize("method,interp", [("poliakoff", interpolate_cubic),
                                           ("wang-cao", interpolate_cubic),
                                           ("wang-quintic", interpolate_quintic)])
@pytest.mark.parametrize("mode", ["spline", "hermite"])
def test_g2_clamp_keeps_end_tangent_and_curvature(method, interp, mode):
    bc = "natural" if method == "wang-quintic" else "not-a-knot"
    c = interp(_noisy(120, 2, seed=21, noise=0.05), "chord", bc)
    res = fair(c, method, mode=mode, clamp="g2", tol=0.05, eps=0.0, max_steps=600)
    assert res.report["steps"] > 0
    for nu in (1, 2):
        a0, a1 = _end_derivs(c, nu)
        b0, b1 = _end_derivs(res.curve, nu)
        s = _scale(c, nu)
        assert np.abs(a0 - b0).max() <= 1e-12 * s
        assert np.abs(a1 - b1).max() <= 1e-12 * s
    # and something near the ends did change
    assert res.report["n_moved"] > 0


@pytest.mark.parametrize("method,interp", [("wang-cao", interpolate_cubic),
                                           ("wang-quintic", interpolate_quintic)])
def test_mixed_clamp_pair(method, interp):
    c = interp(_noisy(80, 3, seed=22, noise=0.05))
    res = fair(c, method, clamp=("g1", "g0"), tol=0.05, eps=0.0, max_steps=300)
    a0, _ = _end_derivs(c, 1)
    b0, _ = _end_derivs(res.curve, 1)
    assert np.abs(a0 - b0).max() <= 1e-12 * _scale(c, 1)
    assert res.report["clamp"] == ["g1", "g0"]


@pytest.mark.parametrize("seed", [0, 1])
def test_g2_cubic_spline_hold_zone(seed):
    # Brute force with a full clamped-spline solve (scipy): moving the first free point changes
    # r''(t_0) by less than 1e-15 of what it changes at its own parameter; moving the last held
    # point would change it by more than that.
    rng = np.random.default_rng(seed)
    h = rng.uniform(0.5, 2.0, 80) if seed else np.ones(80)
    t = np.r_[0.0, np.cumsum(h)]
    nh = hold_zone_cubic(h)

    def effect(k):
        y = np.zeros(t.size)
        y[k] = 1.0
        spl = CubicSpline(t, y, bc_type=((1, 0.0), (1, 0.0)))
        return abs(spl(t[0], 2)) / abs(spl(t[k], 2))

    assert effect(nh + 1) < 1e-15
    assert effect(nh) > 1e-19
    c = interpolate_cubic(_noisy(100, 2, seed=23))
    res = fair(c, "poliakoff", clamp=("g2", "g0"), eps=0.0, max_steps=50)
    held = res.report["held"]
    assert held == list(range(1, 1 + hold_zone_cubic(np.diff(c.params))))
    assert not set(res.history.index.tolist()) & set(held)


# ----------------------------------------------------------------------------------------------
# tolerance and protection
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("method,interp", [("kjellander",
                                            lambda p: interpolate_cubic(p, "uniform")),
                                           ("poliakoff", interpolate_cubic),
                                           ("wang-cao", interpolate_cubic),
                                           ("wang-quintic", interpolate_quintic)])
@pytest.mark.parametrize("mode", ["spline", "hermite"])
@pytest.mark.parametrize("tol_on", ["points", "curve"])
def test_tolerance_never_exceeded_and_stops(method, interp, mode, tol_on):
    pts = _noisy(40, 2, seed=31, noise=0.1)
    c = interp(pts)
    tol = 0.01
    res = fair(c, method, mode=mode, tol=tol, max_steps=20000, tol_on=tol_on, guard=False)
    d = np.linalg.norm(res.curve.points - c.points, axis=1)
    assert d.max() <= tol
    assert res.report["max_point_displacement"] <= tol
    assert res.report["stop_reason"] == "tolerance"
    assert res.report["energy_after"] < res.report["energy_before"]
    if tol_on == "points":
        assert np.isclose(d.max(), tol, rtol=1e-6)  # the worst point is on its sphere
    else:  # the whole curve, by dense sampling
        u = np.linspace(*c.domain, 40001)
        assert np.linalg.norm(res.curve(u) - c(u), axis=1).max() <= tol


def test_protect_and_report_moved():
    c = interpolate_cubic(_noisy(30, 2, seed=32, noise=0.1))
    prot = [3, 4, 10]
    res = fair(c, "wang-cao", protect=prot, tol=0.02, eps=0.0, max_steps=500)
    np.testing.assert_array_equal(res.curve.points[prot], c.points[prot])
    moved = res.report["moved"]
    idx = np.array(moved["indices"])
    assert not set(idx.tolist()) & set(prot)
    d = np.linalg.norm(res.curve.points - c.points, axis=1)
    np.testing.assert_array_equal(np.flatnonzero(d > 0), idx)
    np.testing.assert_allclose(moved["displacement"], d[idx], rtol=1e-14)
    assert res.report["max_point_index"] == int(np.argmax(d))


def test_protect_everything_nothing_to_move():
    c = interpolate_cubic(_noisy(6, 2, seed=33))
    res = fair(c, "poliakoff", protect=range(6))
    assert res.report["steps"] == 0 and res.report["stop_reason"] == "no_movable_point"
    np.testing.assert_array_equal(res.curve.points, c.points)


# ----------------------------------------------------------------------------------------------
# stopping rules, defaults, report
# ----------------------------------------------------------------------------------------------
def test_eps_and_max_steps():
    c = interpolate_cubic(_example1())
    res = fair(c, "poliakoff")
    r = res.report
    assert r["stop_reason"] == "eps"
    # eps is relative to the largest initial measure (default 1e-2); the threshold is absolute
    assert r["eps"] == 1e-2
    assert r["eps_absolute"] == pytest.approx(1e-2 * r["measure_max_before"])
    assert r["measure_max_after"] < r["eps_absolute"]
    assert np.all(res.history.measure >= r["eps_absolute"])
    res2 = fair(c, "poliakoff", max_steps=3, eps=0.0)
    assert res2.report["steps"] == 3 and res2.report["stop_reason"] == "max_steps"
    np.testing.assert_array_equal(res2.history.step, [1, 2, 3])
    res3 = fair(c, "poliakoff", max_steps=0)
    assert res3.report["steps"] == 0
    np.testing.assert_array_equal(res3.curve.points, c.points)


def test_example1_all_methods_flatten_the_bump():
    # ERRATA: every consistent reading of Example 1 drives P4 to y = 1.000, x in [4.00, 4.26]
    pts = _example1()
    for method in ("kjellander", "poliakoff", "wang-cao", "wang-quintic"):
        if method == "wang-quintic":
            c = interpolate_quintic(pts)
        else:
            c = interpolate_cubic(pts, "uniform" if method == "kjellander" else "chord")
        # the paper's loop as it is: no straight runs held, no never-worse guard
        res = fair(c, method, joins="free", guard=False)
        r = res.report
        assert r["energy_after"] < 0.01 * r["energy_before"]
        assert abs(res.curve.points[3, 1] - 1.0) < 0.1
        assert 3.95 < res.curve.points[3, 0] < 4.3


def test_report_is_json_and_complete():
    c = interpolate_cubic(_noisy(25, 3, seed=41))
    res = fair(c, "wang-cao", tol=0.01)
    assert isinstance(res, FairingResult)
    text = json.dumps(res.report.to_dict(), allow_nan=False)
    back = json.loads(text)
    # the per-point entries stay arrays in the report; to_dict() lists the same values
    moved = res.report["moved"]
    assert isinstance(moved["indices"], np.ndarray) and moved["indices"].dtype == np.int64
    assert not moved["indices"].flags.writeable
    assert back["moved"]["indices"] == moved["indices"].tolist()
    assert back["moved"]["displacement"] == moved["displacement"].tolist()
    assert back["steps"] == res.report["steps"] and back["tol"] == res.report["tol"]
    for key in ("method", "steps", "stop_reason", "moved", "energy_before", "energy_after",
                "max_jump_before", "max_jump_after", "inflections_before", "inflections_after",
                "extrema_before", "extrema_after", "max_point_displacement", "max_deviation",
                "max_deviation_param", "max_deviation_point", "tol", "eps", "max_steps", "clamp",
                "time_s"):
        assert key in back
    assert back["steps"] == len(res.history)
    assert res.history.index.dtype == np.int64 and res.history.displacement.dtype == np.float64
    assert np.all(res.history.displacement > 0)
    assert back["energy_after"] <= back["energy_before"]


def test_same_input_same_output():
    c = interpolate_quintic(_noisy(40, 2, seed=42))
    a = fair(c, "wang-quintic", tol=0.02, eps=0.0, max_steps=200)
    b = fair(c, "wang-quintic", tol=0.02, eps=0.0, max_steps=200)
    np.testing.assert_array_equal(a.curve.points, b.curve.points)
    np.testing.assert_array_equal(a.history.index, b.history.index)


def test_default_methods_and_registry():
    c = interpolate_cubic(_noisy(8, 2))
    q = interpolate_quintic(_noisy(8, 2))
    # chord-length natural or periodic cubics (point data, open or closed): points-l1
    assert fair(c, tol=0.1).report["method"] == "points-l1"
    loop = interpolate_cubic(np.vstack([_noisy(8, 2), _noisy(8, 2)[:1]]), "chord", "periodic")
    assert fair(loop, tol=0.1).report["method"] == "points-l1"
    assert fair(q).report["method"] == "wang-quintic"
    assert {"kjellander", "poliakoff", "wang-cao"} <= set(available_methods(c))
    assert "wang-quintic" not in available_methods(c)
    assert "wang-quintic" in available_methods(q)


# ----------------------------------------------------------------------------------------------
# bad input
# ----------------------------------------------------------------------------------------------
def test_bad_input():
    c = interpolate_cubic(_noisy(8, 2))
    q = interpolate_quintic(_noisy(8, 2))
    with pytest.raises(InputError, match="valid methods.*poliakoff"):
        fair(c, "nope")
    with pytest.raises(InputError, match="wang-quintic.*QuinticHermite"):
        fair(c, "wang-quintic")
    with pytest.raises(InputError, match="tol"):
        fair(c, tol=0)
    with pytest.raises(InputError, match="tol"):
        fair(c, tol=-1.0)
    with pytest.raises(InputError, match="eps"):
        fair(c, eps=-1.0)
    with pytest.raises(InputError, match="max_steps"):
        fair(c, max_steps=-2)
    with pytest.raises(InputError, match="clamp"):
        fair(c, clamp="g3")
    with pytest.raises(InputError, match="clamp"):
        fair(c, clamp=("g0", "g1", "g2"))
    with pytest.raises(InputError, match="mode"):
        fair(c, mode="bezier")
    with pytest.raises(InputError, match="protect index 8"):
        fair(c, protect=[8])
    with pytest.raises(InputError, match="protect"):
        fair(c, protect=[-1])
    with pytest.raises(InputError, match="uniform"):
        fair(c, "kjellander")
    with pytest.raises(InputError, match="unknown options"):
        fair(q, "wang-quintic", bogus=1)
    with pytest.raises(InputError, match="at least 3"):
        fair(interpolate_cubic([[0, 0], [1, 1]]), "poliakoff")
    with pytest.raises(InputError, match="curvefair curve"):
        fair(np.zeros((3, 2)))


def test_a_result_that_moved_nothing_is_analysed_once(monkeypatch):
    """A method that moved nothing returns the input's data: fair() reports the input's
    figures for the result too (one analysis, not two), and they are the result's own."""
    import sys

    import curvefair as cf

    fair_module = sys.modules["curvefair.fairing.fair"]
    rng = np.random.default_rng(1)
    t = np.linspace(0, 6, 60)
    c = cf.interpolate_bspline(np.c_[t, np.sin(t)] + 0.01 * rng.normal(size=(60, 2)))
    seen = []
    block_of = fair_module._analysis_block_of
    monkeypatch.setattr(fair_module, "_analysis_block_of",
                        lambda cv, lean=None: seen.append(cv) or block_of(cv, lean))
    for method, kw, moved in (("knot-removal", {"tol": 1e-9}, False),
                              ("eck-hadenfeld", {"tol": 0.02, "max_steps": 0}, False),
                              ("eck-hadenfeld", {"tol": 0.02}, True)):
        seen.clear()
        res = cf.fair(c, method, **kw)
        assert (res.report["n_moved"] > 0) is moved
        assert len(seen) == (2 if moved else 1)
        a = cf.analyze(res.curve)
        assert res.report["extrema_after"] == a.extrema
        assert res.report["inflections_after"] == a.inflections
        assert res.report["energy_after"] == a.energy2
        assert res.report["dkds_energy_after"] == a.dkds_energy
        assert res.report["sapidis_sum_after"] == a.sapidis_sum
