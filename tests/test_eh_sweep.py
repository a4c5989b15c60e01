"""Eck-Hadenfeld with ``schedule="sweep"`` (Gauss-Seidel order on a first-in first-out queue).

Checked against a slow reference written from the documented rule with the dense Gram matrix
and every residual ``(G d)_i`` recomputed from scratch (no incremental updates), and
independently: the stopping test holds at the end (every tolerance-clamped energy drop, computed
from scratch, below the threshold), the energy bookkeeping is exact, the tolerance holds on the
densely sampled curve, and without a tolerance the iteration converges to the global minimiser
with the fixed points held.
"""

from __future__ import annotations

import numpy as np
import pytest

import curvefair as cf
from curvefair import BSplineCurve, InputError, interpolate_bspline
from curvefair._kernels.eck_hadenfeld import eh_drop_reference, eh_sweep_reference
from curvefair.fairing.eck_hadenfeld import eck_hadenfeld_fair, movable_mask


def dense_gram(c: BSplineCurve, l: int) -> np.ndarray:  # noqa: E741
    return c.gram_matrix(l).toarray()


def random_curve(rng, n, p, dim, closed, mixed=False):
    if closed:
        th = np.linspace(0, 2 * np.pi, n, endpoint=False)
        base = np.c_[np.cos(th), np.sin(th), 0.3 * np.sin(2 * th)][:, :dim] * 3
        steps = rng.uniform(0.5, 1.5, n)
        if mixed:
            steps[n // 3] = 0.0 if p >= 3 else steps[n // 3]  # a double knot
        knots = np.r_[0.0, np.cumsum(steps)]
        return BSplineCurve(base + rng.normal(scale=0.2, size=(n, dim)), knots, p, closed=True)
    x = np.linspace(0, 10, n)
    pts = np.c_[x, np.sin(x), np.cos(x)][:, :dim] + 0.05 * rng.normal(size=(n, dim))
    if mixed:
        x = np.sort(rng.uniform(0, 10, n))
        x[0], x[-1] = 0.0, 10.0
        pts = np.c_[x, np.sin(x), np.cos(x)][:, :dim] + 0.05 * rng.normal(size=(n, dim))
    return interpolate_bspline(pts, degree=p)


CASES = [(seed, n, p, dim, closed, tol, mixed)
         for seed, (n, p, dim, closed, tol, mixed) in enumerate([
             (40, 3, 2, False, None, False), (40, 3, 2, False, 0.02, False),
             (33, 3, 3, False, 0.1, True), (25, 2, 2, False, 0.05, False),
             (30, 4, 3, False, None, True), (28, 5, 2, False, 0.02, False),
             (40, 3, 2, True, None, False), (36, 3, 3, True, 0.02, True),
             (30, 2, 2, True, 0.1, False), (23, 4, 3, True, None, False),
             (19, 5, 2, True, 0.05, True), (8, 5, 3, True, None, False),
             (5, 3, 2, True, 0.1, False), (6, 3, 2, False, 0.05, False),
         ])]


@pytest.mark.parametrize("seed,n,p,dim,closed,tol,mixed", CASES)
def test_sweep_matches_slow_reference(seed, n, p, dim, closed, tol, mixed):
    rng = np.random.default_rng(100 + seed)
    c = random_curve(rng, n, p, dim, closed, mixed)
    l = 3 if (seed % 3 == 2 and p >= 3) else 2  # noqa: E741
    clamp = ("g1", "g0") if not closed else None
    protect = [n // 2]
    mask = movable_mask(c, clamp if clamp else (None, None), protect)
    res = eck_hadenfeld_fair(c, l=l, tol=tol, eps=1e-4 / n, max_steps=50 * n, clamp=clamp or
                             (None, None), protect=protect, schedule="sweep")
    d_ref, order = eh_sweep_reference(c, l, tol, res.eps_absolute, mask, res.steps)
    assert len(order) == res.steps > 0
    assert res.history[:, 0].astype(int).tolist() == order
    scale = max(1.0, np.abs(c.control_points).max())
    np.testing.assert_allclose(res.curve.control_points, d_ref, rtol=0, atol=1e-11 * scale)


@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("tol", [None, 0.03])
@pytest.mark.parametrize("l", [2, 3])
def test_sweep_stops_only_below_threshold(closed, tol, l):  # noqa: E741
    """Independent of the reference: at the end no movable point can lower E_l by the
    threshold (drops from scratch), the drops add up to the energy change, the tolerance
    holds for the control points and the densely sampled curve."""
    rng = np.random.default_rng(7 + closed)
    c = random_curve(rng, 60, 3, 2, closed)
    res = eck_hadenfeld_fair(c, l=l, tol=tol, eps=1e-6 / 60, clamp=("g2", "g1"),
                             protect=[20], max_steps=1_000_000, schedule="sweep")
    assert res.stop_reason in ("eps", "tolerance", "converged")
    G = dense_gram(c, l)
    d = np.asarray(res.curve.control_points)
    orig = np.asarray(c.control_points)
    mask = movable_mask(c, ("g2", "g1"), [20])
    drops = [eh_drop_reference(G, d, orig, i, tol)[0] for i in np.flatnonzero(mask)]
    assert max(drops) < res.eps_absolute * (1 + 1e-9)
    # energy: exact bookkeeping against d^T G d of input and output
    e_in = float(np.sum(orig * (G @ orig)))
    e_out = float(np.sum(d * (G @ d)))
    assert abs(res.energy_before - e_in) <= 1e-10 * e_in
    assert abs(res.energy_after - e_out) <= 1e-10 * e_in
    assert abs((e_in - e_out) - res.history[:, 1].sum()) <= 1e-9 * e_in
    assert np.all(res.history[:, 1] > 0) and e_out < e_in
    # fixed points did not move; the tolerance holds on the curve (convex hull), densely sampled
    moved = np.linalg.norm(d - orig, axis=1)
    assert moved[~mask].max() == 0.0
    if tol is not None:
        assert moved.max() <= tol * (1 + 1e-12)
        u = np.linspace(*c.domain, 6001)
        assert np.linalg.norm(res.curve(u) - c(u), axis=1).max() <= tol * (1 + 1e-12)


def test_sweep_unconstrained_converges_to_global_solution():
    rng = np.random.default_rng(4)
    c = random_curve(rng, 14, 3, 2, False)
    res = eck_hadenfeld_fair(c, l=3, eps=1e-26, max_steps=2_000_000, clamp="g2",
                             schedule="sweep")
    G = dense_gram(c, 3)
    free = movable_mask(c, "g2")
    d = np.array(c.control_points)
    d[free] = np.linalg.solve(G[np.ix_(free, free)], -G[np.ix_(free, ~free)] @ d[~free])
    np.testing.assert_allclose(res.curve.control_points, d, atol=1e-6)


def test_sweep_and_ranking_reach_the_same_stopping_test():
    """Different orders, same guarantee; on a noisy interpolant the two end equally fair
    (within a few percent in E_2) and the sweep is no less fair."""
    rng = np.random.default_rng(11)
    t = np.arange(3000.0)
    pts = np.c_[t, 20 * np.sin(t / 7) + 50 * np.sin(t / 31)] + 0.05 * rng.normal(size=(3000, 2))
    c = interpolate_bspline(pts, param=t)
    a = eck_hadenfeld_fair(c, tol=0.3, schedule="ranking")
    b = eck_hadenfeld_fair(c, tol=0.3, schedule="sweep")
    assert a.eps_absolute == b.eps_absolute
    assert b.energy_after <= a.energy_after * 1.001
    assert b.energy_after >= a.energy_after * 0.95
    assert np.linalg.norm(b.curve.control_points - c.control_points, axis=1).max() <= 0.3


def test_sweep_through_fair_and_errors():
    c = random_curve(np.random.default_rng(3), 30, 3, 2, False)
    r = cf.fair(c, "eck-hadenfeld", tol=0.02, schedule="sweep")
    assert r.report["schedule"] == "sweep" and r.report["steps"] > 0
    # fair()'s default schedule is the sweep; the paper's function keeps the ranking list
    d = cf.fair(c, "eck-hadenfeld", tol=0.02)
    assert d.report["schedule"] == "sweep"
    np.testing.assert_array_equal(d.curve.control_points, r.curve.control_points)
    assert cf.fair(c, "eck-hadenfeld", tol=0.02, schedule="ranking").report["schedule"] == "ranking"
    assert eck_hadenfeld_fair(c, tol=0.02).steps == eck_hadenfeld_fair(
        c, tol=0.02, schedule="ranking").steps
    assert r.report["max_deviation"] <= 0.02 * (1 + 1e-12)
    again = cf.fair(c, "eck-hadenfeld", tol=0.02, schedule="SWEEP")
    np.testing.assert_array_equal(again.curve.control_points, r.curve.control_points)
    for bad in ("fifo", 3, None):
        with pytest.raises(InputError, match="schedule"):
            eck_hadenfeld_fair(c, schedule=bad)
    # max_steps = 0: the input back; a cap is a cap
    z = eck_hadenfeld_fair(c, tol=0.02, max_steps=0, schedule="sweep")
    assert z.steps == 0 and z.stop_reason == "max_steps"
    np.testing.assert_array_equal(z.curve.control_points, c.control_points)
    capped = eck_hadenfeld_fair(c, tol=0.02, eps=0.0, max_steps=7, schedule="sweep")
    assert capped.steps == 7 and capped.stop_reason == "max_steps"
    # nothing movable
    none = eck_hadenfeld_fair(c, protect=range(c.n_ctrl), schedule="sweep")
    assert none.steps == 0 and none.stop_reason == "no_movable_point"


def test_sweep_eps_zero_terminates():
    """eps = 0: runs until every move is below rounding (no endless zero-length moves)."""
    c = random_curve(np.random.default_rng(5), 20, 3, 2, False)
    res = eck_hadenfeld_fair(c, tol=0.05, eps=0.0, max_steps=10_000_000, schedule="sweep")
    assert res.stop_reason in ("converged", "tolerance")
    assert res.steps < 10_000_000


@pytest.mark.parametrize("schedule", ["ranking", "sweep"])
@pytest.mark.parametrize("offset", [0.0, 3000.0, 1e6])
@pytest.mark.parametrize("dim", [2, 3])
def test_tolerance_holds_as_computed_at_large_coordinates(schedule, offset, dim):
    """The clamped points are stored within tol of the originals as computed, with no
    rounding slack, also when the coordinates are 1e6 times tol (before the rounding margin
    of the ball's radius, 158 of 3002 control points ended 2e-13 beyond tol at 3000)."""
    rng = np.random.default_rng(21)
    n = 400
    t = np.arange(n, dtype=float)
    pts = np.c_[t, 20 * np.sin(t / 7) + 50 * np.sin(t / 31), 10 * np.cos(t / 13)][:, :dim]
    pts = pts + offset + 0.05 * rng.normal(size=(n, dim))
    c = interpolate_bspline(pts, param=t)
    tol = 0.3
    res = eck_hadenfeld_fair(c, tol=tol, schedule=schedule)
    moved = np.linalg.norm(res.curve.control_points - c.control_points, axis=1)
    assert np.count_nonzero(moved > 0.99 * tol) > 10  # the ball is really reached
    assert moved.max() <= tol
    r = cf.fair(c, "eck-hadenfeld", tol=tol, schedule=schedule)
    assert r.report["max_point_displacement"] <= tol
    # the densely sampled curve: the evaluation itself rounds at the size of the coordinates
    u = np.linspace(*c.domain, 20001)
    slack = 8 * np.finfo(float).eps * np.abs(pts).max()
    assert np.linalg.norm(res.curve(u) - c(u), axis=1).max() <= tol + slack


def test_option_checks():
    c = random_curve(np.random.default_rng(8), 20, 3, 2, False)
    for kw in ({"history_max": "x"}, {"history_max": -1}, {"eps_relative": "yes"},
               {"schedule": "Ranking "}):
        with pytest.raises(InputError, match=next(iter(kw))):
            eck_hadenfeld_fair(c, **kw)
    from curvefair.fairing import method_options
    assert method_options("eck-hadenfeld")["schedule"] == "sweep"
