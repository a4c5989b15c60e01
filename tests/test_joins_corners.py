"""Corners of B-splines keep their angle to within ``corner_turn`` (1 degree by default).

A corner is a C0 knot whose tangents differ by more than ``g1_angle``. Its point was held, its
tangents were not: where ``tol`` is longer than the handles, a method swung them (a Rhino 2
PolyCurve's 0.9-degree join came out a 93-degree kink, tests/test_io_3dm_polycurve.py).
Angles here are measured independently of curvefair: positions from scipy's ``BSpline`` on
either side of the knot, the difference quotient extrapolated to h = 0.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import curvefair as cf
from curvefair.fairing.joins import DEFAULT_CORNER_TURN


def _chain(P: np.ndarray) -> cf.BSplineCurve:
    """Cubic B-spline on 19 control points: simple knots, a knot of multiplicity 3 at u = 7
    (a C0 join at ``P[9]``)."""
    t = np.r_[[0.0] * 4, np.arange(1.0, 7.0), [7.0] * 3, np.arange(8.0, 14.0), [14.0] * 4]
    return cf.BSplineCurve(P, t, 3)


def _direction(c: cf.BSplineCurve, u: float, side: int) -> np.ndarray:
    S = c.to_scipy()
    d = []
    for h in (1e-5, 5e-6):
        v = (np.asarray(S(u + side * h)) - np.asarray(S(u))) * side
        d.append(v / np.linalg.norm(v))
    v = 2 * d[1] - d[0]
    return v / np.linalg.norm(v)


def _turn(c: cf.BSplineCurve, u: float, u_end: float | None = None) -> float:
    """Degrees between the tangent arriving at ``u`` (at ``u_end`` for a seam) and leaving."""
    a = _direction(c, u if u_end is None else u_end, -1)
    b = _direction(c, u, 1)
    return math.degrees(math.acos(float(np.clip(a @ b, -1.0, 1.0))))


def _wiggly_chain(corner_deg: float) -> np.ndarray:
    """Two wiggly pieces of 10 control points each, meeting at (3, 0) at a corner of
    ``corner_deg`` with handles 0.06 long there (tol below: 0.15)."""
    rng = np.random.default_rng(7)
    left = np.c_[np.linspace(0.0, 3.0, 10), 0.08 * rng.standard_normal(10)]
    left[-1] = (3.0, 0.0)
    left[-2] = (2.94, 0.0)                            # arrives along +x
    a = math.radians(corner_deg)
    d = np.array((math.cos(a), math.sin(a)))
    right = np.array([left[-1] + s * d for s in np.linspace(0.0, 3.0, 10)])
    right += 0.08 * rng.standard_normal((10, 2)) * np.array((-d[1], d[0]))
    right[0], right[1] = left[-1], left[-1] + 0.06 * d  # leaves along d
    return np.vstack([left, right[1:]])


@pytest.mark.parametrize("method", ["global", "eck-hadenfeld"])
@pytest.mark.parametrize("corner", [2.0, 35.0])
def test_a_corner_keeps_its_angle(method, corner):
    """(Knot removal finds no knot to remove next to a corner of this chain, and Cheng-Yu
    refuses corners.)"""
    c = _chain(_wiggly_chain(corner))
    tol = 0.2
    assert _turn(c, 7.0) == pytest.approx(corner, abs=1e-6)
    free = cf.fair(c, method, tol=tol, corner_turn=math.inf).curve
    kept = cf.fair(c, method, tol=tol)
    for out in (free, kept.curve):
        assert np.abs(out.control_points - c.control_points).max() > 0
        assert np.linalg.norm(out.control_points - c.control_points, axis=1).max() <= tol
        assert np.array_equal(out.control_points[9], c.control_points[9])  # the corner
    # the premise: with no limit the method swings the short handles
    assert abs(_turn(free, 7.0) - corner) > DEFAULT_CORNER_TURN
    assert abs(_turn(kept.curve, 7.0) - corner) <= DEFAULT_CORNER_TURN
    # and neither tangent swings round (same angle, turned whole)
    for side in (-1, 1):
        d0, d1 = _direction(c, 7.0, side), _direction(kept.curve, 7.0, side)
        assert math.degrees(math.acos(min(1.0, float(d0 @ d1)))) <= DEFAULT_CORNER_TURN
    assert kept.report["joins"]["corner_points_held"] >= 3


def test_corner_turn_option_is_checked():
    c = _chain(_wiggly_chain(35.0))
    with pytest.raises(cf.InputError, match="corner_turn"):
        cf.fair(c, tol=0.1, corner_turn=-1.0)
    with pytest.raises(cf.InputError, match="corner_turn"):
        cf.fair(c, tol=0.1, corner_turn=float("nan"))
    # zero: no corner may turn at all
    out = cf.fair(c, tol=0.2, corner_turn=0.0).curve
    assert np.abs(out.control_points - c.control_points).max() > 0
    assert np.array_equal(out.control_points[8:11], c.control_points[8:11])


@pytest.mark.parametrize("method", ["global", "eck-hadenfeld"])
def test_a_corner_where_an_open_chain_meets_its_start(method):
    """A teardrop drawn as an open chain ending on its start (simple knots inside): its tip is
    a corner of the seam, held by the clamps at its point; its angle is now kept too."""
    t = np.linspace(0.0, 2 * np.pi, 19)
    rng = np.random.default_rng(3)
    r = 1.0 + 0.04 * rng.standard_normal(19)
    P = np.c_[r * np.sin(t / 2) ** 2 * np.cos(t), r * np.sin(t / 2) ** 2 * np.sin(t)] * 3.0
    P[0] = P[-1] = (0.0, 0.0)
    P[1], P[-2] = (0.05, 0.02), (0.05, -0.02)           # short handles at the tip
    c = cf.BSplineCurve(P, np.r_[[0.0] * 4, np.arange(1.0, 16.0), [16.0] * 4], 3)
    hi = c.domain[1]
    before = _turn(c, 0.0, hi)
    assert 30.0 < before < 180.0
    free = cf.fair(c, method, tol=0.12, corner_turn=math.inf).curve
    kept = cf.fair(c, method, tol=0.12).curve
    assert abs(_turn(free, 0.0, hi) - before) > DEFAULT_CORNER_TURN
    assert abs(_turn(kept, 0.0, hi) - before) <= DEFAULT_CORNER_TURN
    assert np.abs(kept.control_points - c.control_points).max() > 0
    assert np.array_equal(kept.control_points[[0, -1]], c.control_points[[0, -1]])
