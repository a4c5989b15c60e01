"""Glyph contours as B-splines, and back with the outline's structure kept exactly.

A contour is the list of its points in file order, each on- or off-curve, with the UFO
``smooth`` flag (binary fonts: a node whose neighbours are exactly collinear with it).

**To a B-spline** (:func:`contour_curve`). The contour is walked from one on-curve point (the
first corner, else the first on-curve point: the seam of the closed chain) round to itself:

- cubic contours (UFO ``curve``, CFF): each segment is a cubic Bezier (a line ``A B`` is the
  exactly degree-elevated ``A, A + (B - A)/3, A + 2(B - A)/3, B``), joined by knots of
  multiplicity 3 -- the B-spline form of a poly-Bezier, with spans of width 1;
- a TrueType contour of off-curve points only (every on-curve point implied, as in many
  circles) is the periodic quadratic B-spline with uniform knots on those points;
- a repeated on-curve point (a zero-length line) is one control point, held;
- quadratic contours (UFO ``qcurve``, TrueType ``glyf``): a run of ``k`` off-curve points
  between two on-curve points is a quadratic B-spline of ``k`` spans of width 1 with simple
  knots between them. Its joins are the midpoints of consecutive off-curve points, which is
  TrueType's implied on-curve point (the point at a simple knot ``u_i`` of a quadratic B-spline
  is ``(h_{i+1} P_{i-1} + h_i P_i)/(h_i + h_{i+1})`` for span widths ``h``: the midpoint when
  they are equal), so the B-spline is the TrueType outline exactly, and every B-spline with
  these knots is one; explicit on-curve points are knots of multiplicity 2; a line is the
  elevated ``A, (A + B)/2, B``.

The control points of the B-spline are the contour's points plus the elevated interior points
of lines; ``index[k]`` gives the control point of the contour's point ``k``.

**Back** (:func:`constrained_points`): the faired control points at ``index`` are the new
contour points, then the outline's rules are enforced exactly:

- points of straight segments and corner nodes (on-curve points that are not smooth) keep
  their input position, and so does a corner's handle where rounding would turn the tangent
  along it, or the corner's angle, by more than :data:`CORNER_TURN` (1 degree, as the
  fairing allows) from the input's when the fair had kept it within that; a node flagged
  smooth that is kinked in the input (on the integer grid, three points rarely line up
  exactly: a corner to the fairing) is not made more kinked than its input plus
  :data:`SMOOTH_KINK_GROWTH` (0.1 degree) by the rounding -- the side that turned more keeps
  its handle;
- a smooth node stays smooth: its on-curve point is put on the segment between its two
  neighbours (the collinear handles of a cubic node, the two off-curve points of a TrueType
  node), or the handle next to a line on that line's extension;
- a smooth node at a horizontal (vertical) extremum -- its neighbours have exactly its ``y``
  (``x``) -- keeps that: the neighbours get the node's ``y`` (``x``);
- integer formats (binary fonts) round to integers; a smooth node then needs three lattice
  points on a line: the nearest lattice point of the segment, else the input's three points
  moved by the node's rounded move (a translation keeps them collinear), else the input's
  three points;
- the moves are then scaled down, ``p = p0 + s (p1 - p0)`` with ``s`` halved from 1, until no
  point is farther than ``tol`` from its input position (``s = 0`` is the input itself). A
  B-spline's distance to another with the same knots is at most the largest distance of
  their control points (convex hull property of the difference curve), so the written outline
  is within ``tol`` of the input everywhere.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from math import gcd

import numpy as np

from .._typing import FloatArray
from ..curves.bspline import BSplineCurve
from ._common import Unsupported

__all__ = ["Contour", "contour_curve", "constrained_points", "smooth_angle"]

#: a node flagged smooth is kept exactly smooth when its input turns by at most this (degrees,
#: the G1 threshold of :mod:`curvefair.fairing.joins`)
SMOOTH_ANGLE = 0.5
#: a node flagged smooth that the grid keeps from being exactly smooth (a corner to the
#: fairing) is not written more kinked than this beyond its input's kink (degrees) by the
#: rounding: where it would be, the side that turned more keeps its input handle
SMOOTH_KINK_GROWTH = 0.1
#: a corner node's tangent turns by at most this on write (degrees; the fairing's own limit,
#: :data:`curvefair.fairing.joins.DEFAULT_CORNER_TURN`): where rounding to the grid turns it
#: more, that side's handle keeps its input position
CORNER_TURN = 1.0


@dataclass(frozen=True)
class Contour:
    """One contour: ``points (n, 2)`` in file order, ``on (n,)`` on-curve flags, ``smooth``
    flags, ``closed``, ``quadratic`` (TrueType-style off-curve runs) and ``grid`` (integer
    coordinates on write)."""

    points: FloatArray
    on: tuple[bool, ...]
    smooth: tuple[bool, ...]
    closed: bool
    quadratic: bool
    grid: bool = False


def _angle(a: FloatArray, b: FloatArray) -> float:
    cr = float(a[0] * b[1] - a[1] * b[0])
    return float(np.arctan2(abs(cr), float(a @ b)))


def smooth_angle(c: Contour, k: int) -> float | None:
    """Turning angle (radians) at the on-curve point ``k`` between its neighbours, or None
    when it has not two neighbours."""
    n = len(c.on)
    if not c.closed and (k == 0 or k == n - 1):
        return None
    a, b = c.points[(k - 1) % n], c.points[(k + 1) % n]
    p = c.points[k]
    if np.array_equal(a, p) or np.array_equal(b, p):
        return None
    return _angle(p - a, b - p)


def _node_kinds(c: Contour) -> tuple[list[int], list[int], list[int]]:
    """(smooth nodes kept exactly smooth, corner nodes, points of straight segments)."""
    n = len(c.on)
    smooth: list[int] = []
    corners: list[int] = []
    line: set[int] = set()
    for k in range(n):
        if not c.on[k]:
            continue
        nxt = (k + 1) % n
        if (c.closed or k < n - 1) and c.on[nxt]:
            line.update((k, nxt))
        ang = smooth_angle(c, k)
        both_on = ang is not None and c.on[(k - 1) % n] and c.on[(k + 1) % n]
        if ang is not None and c.smooth[k] and not both_on and \
                ang <= np.radians(SMOOTH_ANGLE) and (not c.grid or ang == 0.0):
            smooth.append(k)
        else:
            corners.append(k)
    return smooth, corners, sorted(line)


def _rotation(c: Contour, corners: list[int]) -> int:
    if not c.closed:
        return 0
    if corners:
        return corners[0]
    return next(k for k in range(len(c.on)) if c.on[k])


def contour_curve(c: Contour) -> tuple[BSplineCurve, np.ndarray, list[int]]:
    """The B-spline of a contour (see the module docstring).

    Returns
    -------
    curve : BSplineCurve
        Degree 3 (cubic contours) or 2 (quadratic), clamped, from the seam node round to it.
    index : ndarray of int, shape (n,)
        Control point of each contour point.
    corners : list of int
        Control points of the corner nodes and the ends of straight segments (to hold).

    Raises
    ------
    Unsupported
        No on-curve point, fewer than two points, a cubic segment with other than 0 or 2
        off-curve points, zero-length segments.
    """
    n = len(c.on)
    if not any(c.on) and c.quadratic and c.closed and n >= 3:
        # TrueType: every on-curve point implied -- the periodic quadratic B-spline with
        # uniform knots whose control points are the off-curve points
        if any(np.array_equal(c.points[k], c.points[(k + 1) % n]) for k in range(n)):
            raise Unsupported("an all-off-curve contour with repeated points")
        return (BSplineCurve(c.points, np.arange(n + 1, dtype=np.float64), 2, closed=True),
                np.arange(n, dtype=np.intp), [])
    if n < 2 or not any(c.on):
        raise Unsupported("a contour without on-curve points" if n >= 2 else
                          "a contour of fewer than two points")
    smooth, corners, line = _node_kinds(c)
    r = _rotation(c, corners)
    order = [(r + i) % n for i in range(n)] + ([r] if c.closed else [])
    if not c.closed and not c.on[0]:
        raise Unsupported("an open contour starting with an off-curve point")
    p = 2 if c.quadratic else 3
    P = c.points
    ctl: list[FloatArray] = [P[order[0]]]
    index = np.full(n, -1, dtype=np.intp)
    index[order[0]] = 0
    knots: list[float] = [0.0] * (p + 1)
    u = 0.0
    i = 0
    while i < len(order) - 1:
        j = i + 1
        while not c.on[order[j]]:
            j += 1
            if j == len(order):
                raise Unsupported("an open contour ending with an off-curve point")
        a, b = P[order[i]], P[order[j]]
        offs = order[i + 1:j]
        if not offs and np.array_equal(a, b):
            # a zero-length line (a repeated on-curve point): no span; the twin is the same
            # control point and, like every line end, is held
            if j < len(order) - 1 or not c.closed:
                index[order[j]] = len(ctl) - 1
            if j == len(order) - 1 and len(knots) > p + 1:
                del knots[-p:]  # the chain ends at the join before
            i = j
            continue
        if not offs:  # a line
            inner = [a + (b - a) / 2] if p == 2 else [a + (b - a) / 3, a + 2 * (b - a) / 3]
            ctl.extend(inner)
            u += 1.0
        elif p == 3:
            if len(offs) != 2:
                raise Unsupported(f"a cubic segment with {len(offs)} off-curve points")
            for k in offs:
                index[k] = len(ctl)
                ctl.append(P[k])
            u += 1.0
        else:
            for m, k in enumerate(offs):
                index[k] = len(ctl)
                ctl.append(P[k])
                if m > 0:
                    knots.append(u)
                u += 1.0
        if j < len(order) - 1 or not c.closed:
            index[order[j]] = len(ctl)
        ctl.append(b)
        if j < len(order) - 1:
            knots.extend([u] * p)
        i = j
    knots.extend([u] * (p + 1))
    cp = np.array(ctl, dtype=np.float64)
    curve = BSplineCurve(cp, np.array(knots), p)
    hold = sorted({int(index[k]) for k in corners} | {int(index[k]) for k in line}
                  | ({len(ctl) - 1} if c.closed and (r in corners or r in line) else set()))
    return curve, index, hold


def _primitive(v: FloatArray) -> tuple[int, int]:
    x, y = int(v[0]), int(v[1])
    g = gcd(x, y) or 1
    return x // g, y // g


def _exact_smooth(c: Contour, q: FloatArray, k: int, horizontal: bool, vertical: bool) -> bool:
    n = len(c.on)
    a, b = q[(k - 1) % n], q[(k + 1) % n]
    d1, d2 = q[k] - a, b - q[k]
    if not (np.any(d1) and np.any(d2)):
        return False
    cr = d1[0] * d2[1] - d1[1] * d2[0]
    ok = float(d1 @ d2) > 0 and (cr == 0.0 if c.grid else _angle(d1, d2) <= 1e-12)
    if horizontal:
        ok = ok and a[1] == q[k][1] == b[1]
    if vertical:
        ok = ok and a[0] == q[k][0] == b[0]
    return bool(ok)


def _place(c: Contour, q: FloatArray, target: FloatArray, k: int, horizontal: bool,
           vertical: bool, fixed: np.ndarray) -> None:
    """Make node ``k`` exactly smooth in ``q`` (in place), near ``target``."""
    n = len(c.on)
    ia, ib = (k - 1) % n, (k + 1) % n
    P0 = c.points
    if horizontal or vertical:
        ax = 1 if horizontal else 0
        val = q[k][ax]
        for j in (ia, ib):
            if not fixed[j]:
                q[j][ax] = val
        if fixed[ia] or fixed[ib]:
            val = q[ia][ax] if fixed[ia] else q[ib][ax]
            q[k][ax] = q[ia][ax] = q[ib][ax] = val
        return
    if fixed[ia] or fixed[ib]:  # a line on one side: the other neighbour on its extension
        f, m = (ia, ib) if fixed[ia] else (ib, ia)
        if fixed[m]:
            return
        d = P0[k] - P0[f]
        t = float((target[m] - q[k]) @ d) / float(d @ d)
        if c.grid:
            dx, dy = _primitive(d)
            g = max(abs(int(d[0])) // max(abs(dx), 1), abs(int(d[1])) // max(abs(dy), 1))
            s = max(1, round(t * g))
            q[m] = q[k] + s * np.array([dx, dy], dtype=float)
        else:
            q[m] = q[k] + max(t, 1e-3) * d
        return
    a, b = q[ia], q[ib]
    if not c.grid:
        d = b - a
        t = float((q[k] - a) @ d) / float(d @ d)
        q[k] = a + min(max(t, 1e-3), 1 - 1e-3) * d
        return
    best: tuple[float, FloatArray, FloatArray, FloatArray] | None = None
    d = b - a
    g = gcd(int(abs(d[0])), int(abs(d[1])))
    if g >= 2:
        step = d / g
        t = float((q[k] - a) @ d) / float(d @ d)
        m = min(max(round(t * g), 1), g - 1)
        cand = a + m * step
        best = (float(np.linalg.norm(cand - target[k])), a.copy(), cand, b.copy())
    move = np.round(q[k] - P0[k])
    tr = (P0[ia] + move, P0[k] + move, P0[ib] + move)
    err = max(float(np.linalg.norm(tr[i] - target[j])) for i, j in enumerate((ia, k, ib)))
    if best is None or err < best[0]:
        best = (err, *tr)
    q[ia], q[k], q[ib] = best[1], best[2], best[3]


def _side_tangent(pts: FloatArray, k: int, idx: list[int]) -> FloatArray | None:
    for i in idx:
        if not np.array_equal(pts[i], pts[k]):
            return pts[i] - pts[k]
    return None


def _corner_side(c: Contour, P0: FloatArray, k: int, step: int) -> list[int]:
    """The off-curve points on side ``step`` (-1: before, +1: after) of the corner node ``k``
    up to the first one off the node in the input -- the points its tangent on that side
    leaves along; empty for a straight side (an on-curve neighbour, held anyway) and at the
    end of an open contour."""
    n = len(c.on)
    idx: list[int] = []
    j = k
    for _ in range(n - 1):
        j += step
        if not c.closed and not 0 <= j < n:
            return []
        j %= n
        if c.on[j]:
            return []
        idx.append(j)
        if not np.array_equal(P0[j], P0[k]):
            return idx
    return []


def _corner_side_turned(c: Contour, q: FloatArray, target: FloatArray, P0: FloatArray,
                        k: int, step: int) -> list[int]:
    """The points of side ``step`` of the corner node ``k`` (:func:`_corner_side`) when that
    side's tangent in ``q`` (rounded) turned by more than :data:`CORNER_TURN` from the
    input's (or is lost: every one of them on the node) while in ``target`` (the fair's,
    unrounded) it did not; else an empty list. A corner the fair itself turned more
    (``fair(..., corner_turn=math.inf)``) is the fair's choice."""
    idx = _corner_side(c, P0, k, step)
    if not idx:
        return []
    t0 = P0[idx[-1]] - P0[k]
    limit = np.radians(CORNER_TURN)
    tt = _side_tangent(target, k, idx)
    if tt is None or _angle(t0, tt) > limit:
        return []
    tq = _side_tangent(q, k, idx)
    return idx if tq is None or _angle(t0, tq) > limit else []


def _corner_opening(pts: FloatArray, k: int, sides: tuple[list[int], list[int]]
                    ) -> float | None:
    """The signed angle (radians) from the corner node ``k``'s tangent on one side to the
    other's in ``pts``, or None when a side's points all sit on the node."""
    ta = _side_tangent(pts, k, sides[0])
    tb = _side_tangent(pts, k, sides[1])
    if ta is None or tb is None:
        return None
    return float(np.arctan2(ta[0] * tb[1] - ta[1] * tb[0], ta @ tb))


def _by_turn(sides: tuple[list[int], list[int]], P0: FloatArray, q: FloatArray, k: int
             ) -> list[list[int]]:
    """The two sides of node ``k``, the one whose tangent turned more from ``P0`` to ``q``
    first (a side whose points all sit on the node counts as turned most)."""
    def side_turn(idx: list[int]) -> float:
        t0, tq = _side_tangent(P0, k, idx), _side_tangent(q, k, idx)
        return np.inf if t0 is None or tq is None else _angle(t0, tq)

    return sorted(sides, key=side_turn, reverse=True)


def _corner_angle_turned(c: Contour, q: FloatArray, target: FloatArray, P0: FloatArray,
                         k: int) -> list[list[int]]:
    """The two sides' points (:func:`_corner_side`) of the corner node ``k``, the side whose
    tangent turned more first, when the corner's angle in ``q`` (rounded) differs from the
    input's by more than :data:`CORNER_TURN` while in ``target`` (the fair's, unrounded) it
    did not: each side within the limit (:func:`_corner_side_turned`) can still open or close
    the angle by twice it (Bilbo's ``O``: two handles moved one unit each, 0.46 and 0.60
    degrees, the corner 1.07). Empty otherwise, and for a corner with a straight side (its
    angle then turns with the other side's tangent alone)."""
    sides = (_corner_side(c, P0, k, -1), _corner_side(c, P0, k, 1))
    if not sides[0] or not sides[1]:
        return []
    a0 = _corner_opening(P0, k, sides)
    at = _corner_opening(target, k, sides)
    aq = _corner_opening(q, k, sides)
    limit = np.radians(CORNER_TURN)

    def turn(a: float | None) -> float:
        return np.inf if a is None or a0 is None else \
            abs(float(np.angle(np.exp(1j * (a - a0)))))

    if a0 is None or turn(at) > limit or turn(aq) <= limit:
        return []
    return _by_turn(sides, P0, q, k)


def _kink_grown(c: Contour, q: FloatArray, target: FloatArray, P0: FloatArray, k: int
                ) -> list[list[int]]:
    """The sides of the node ``k`` -- flagged smooth, kinked in the input (integer
    coordinates rarely line up exactly), so a corner to the fairing -- the side whose tangent
    turned more first, when its kink (180 degrees minus the angle between its two tangents)
    grew by more than :data:`SMOOTH_KINK_GROWTH` in ``q`` (rounded) while in ``target`` (the
    fair's, unrounded) it did not; empty otherwise. A side along a straight segment is its
    on-curve neighbour (held anyway)."""
    n = len(c.on)
    sides = []
    for step in (-1, 1):
        idx = _corner_side(c, P0, k, step)
        j = (k + step) % n
        if not idx and (c.closed or 0 <= k + step < n) and c.on[j]:
            idx = [j]
        if not idx:
            return []
        sides.append(idx)
    two = (sides[0], sides[1])
    a0 = _corner_opening(P0, k, two)
    if a0 is None:
        return []
    most = np.pi - abs(a0) + np.radians(SMOOTH_KINK_GROWTH)

    def grown(pts: FloatArray) -> bool:
        a = _corner_opening(pts, k, two)
        return a is None or np.pi - abs(a) > most

    if grown(target) or not grown(q):
        return []
    return _by_turn(two, P0, q, k)


def _hold_until_kept(rule: Callable[..., list[list[int]]], c: Contour, q: FloatArray,
                     target: FloatArray, P0: FloatArray, held: np.ndarray, k: int) -> None:
    """Give the sides of node ``k`` that ``rule`` names their input points back in ``q``
    (marked in ``held``), one side at a time, until it names none."""
    for back in rule(c, q, target, P0, k):
        q[back] = P0[back]
        held[back] = True
        if not rule(c, q, target, P0, k):
            break


def constrained_points(c: Contour, new: FloatArray, tol: float | None,
                       ) -> tuple[FloatArray, float]:
    """The contour's points from faired ones with the outline's rules enforced (module
    docstring); returns ``(points, s)``, ``s`` the scale of the moves that was kept."""
    P0 = np.asarray(c.points, dtype=np.float64)
    new = np.asarray(new, dtype=np.float64)
    smooth, corners, line = _node_kinds(c)
    n = len(c.on)
    fixed = np.zeros(n, dtype=bool)
    fixed[corners] = True
    fixed[line] = True
    ext = {}
    for k in smooth:
        a, b = P0[(k - 1) % n], P0[(k + 1) % n]
        ext[k] = (bool(a[1] == P0[k][1] == b[1]), bool(a[0] == P0[k][0] == b[0]))
    s = 1.0
    for _ in range(14):
        target = P0 + s * (new - P0)
        target[fixed] = P0[fixed]
        q = np.round(target) if c.grid else target.copy()
        q[fixed] = P0[fixed]
        for k in smooth:
            _place(c, q, target, k, *ext[k], fixed)
        # a corner whose tangent turned (a short handle rounded to the grid: Linux Libertine's
        # 3-unit handles turned 4.4 degrees) gets that side's handle back
        held = fixed.copy()
        for k in corners:
            for step in (-1, 1):
                back = _corner_side_turned(c, q, target, P0, k, step)
                if back:
                    q[back] = P0[back]
                    held[back] = True
            # and so does the side that turned more where the two sides together turned the
            # corner's angle by more (then the other side too, if that is not enough)
            _hold_until_kept(_corner_angle_turned, c, q, target, P0, held, k)
            # a node the designer flagged smooth is not made more kinked by the rounding
            if c.smooth[k]:
                _hold_until_kept(_kink_grown, c, q, target, P0, held, k)
        # a node spoilt by a neighbour's placement (TrueType: two nodes share an off-curve
        # point) gets its input points back, until every smooth node is exactly smooth
        for _ in range(n + 1):
            bad = [k for k in smooth if not _exact_smooth(c, q, k, *ext[k])
                   and not all(np.array_equal(q[j], P0[j]) for j in ((k - 1) % n, k, (k + 1) % n))]
            if not bad:
                break
            for k in bad:
                for j in ((k - 1) % n, k, (k + 1) % n):
                    q[j] = P0[j]
                    held[j] = True
        else:  # pragma: no cover - the input itself satisfies every rule
            q = P0.copy()
        dmax = float(np.max(np.linalg.norm(q - P0, axis=1))) if n else 0.0
        if tol is None or dmax <= tol:
            return q, s
        s *= 0.5
    return P0.copy(), 0.0


def harmonize(c: Contour, q: FloatArray, tol: float | None, sweeps: int = 8) -> FloatArray:
    """G2 at the smooth nodes of a cubic contour, moving only their two handles along the
    tangent, each point within ``tol`` of the input.

    At a node ``P`` with handles ``P - a u`` and ``P + b u`` (``u`` the unit tangent), the
    curvature of the incoming cubic at its end is ``(2/3) h / a**2`` and of the outgoing one at
    its start ``(2/3) k / b**2`` (``h``, ``k``: signed distances of the segments' other
    handles from the tangent line; e.g. Farin, *Curves and Surfaces for CAGD*, eq. for the
    end curvature of a Bezier curve). Where ``h k > 0`` (no inflection at the node) the
    handles are set to ``a/b = sqrt(h/k)`` with ``a + b`` kept, which makes the two
    curvatures equal; a move that would leave ``tol`` is shortened. The neighbouring nodes'
    curvatures depend on these handles too, so the nodes are swept ``sweeps`` times. Integer
    contours: only horizontal/vertical nodes, rounded (the tangent stays exact). Quadratic
    contours are returned unchanged.
    """
    if c.quadratic:
        return q
    q = np.array(q, dtype=np.float64)
    P0 = np.asarray(c.points, dtype=np.float64)
    smooth, _, _ = _node_kinds(c)
    n = len(c.on)
    nodes = [k for k in smooth if not c.on[(k - 1) % n] and not c.on[(k + 1) % n]
             and (c.closed or 2 <= k <= n - 3)]

    def ok(j: int, p: FloatArray) -> bool:
        return tol is None or float(np.linalg.norm(p - P0[j])) <= tol

    for _ in range(sweeps):
        for k in nodes:
            ia, ib = (k - 1) % n, (k + 1) % n
            P, A, B = q[k], q[ia], q[ib]
            d = B - A
            if c.grid and d[0] != 0 and d[1] != 0:
                continue
            u = d / np.linalg.norm(d)
            a, b = float((P - A) @ u), float((B - P) @ u)
            h = float(u[0] * (q[(k - 2) % n] - P)[1] - u[1] * (q[(k - 2) % n] - P)[0])
            kk = float(u[0] * (q[(k + 2) % n] - P)[1] - u[1] * (q[(k + 2) % n] - P)[0])
            if a <= 0 or b <= 0 or h * kk <= 0:
                continue
            r = float(np.sqrt(h / kk))
            L = a + b
            a1 = L * r / (1 + r)
            for t in (1.0, 0.5, 0.25, 0.125, 0.0625, 0.0):
                at = a + t * (a1 - a)
                na, nb = P - at * u, P + (L - at) * u
                if c.grid:
                    na, nb = np.round(na), np.round(nb)
                if ok(ia, na) and ok(ib, nb) and float((P - na) @ u) > 0 and \
                        float((nb - P) @ u) > 0:
                    q[ia], q[ib] = na, nb
                    break
    return q


#: samples per Bezier segment of :func:`fairness` (``t = 0, 1/(M-1), ..., 1``)
FAIRNESS_SAMPLES = 40


def _segments(c: Contour, pts: FloatArray) -> list[list[FloatArray]]:
    """The smooth runs of the contour drawn with points ``pts``: lists of Bezier control
    polygons (degree 2 or 3), split at the corner nodes (on-curve points not kept smooth,
    :func:`_node_kinds`) and at straight segments. A TrueType run of ``k`` off-curve points
    between two on-curve points is ``k`` quadratic pieces joined at the implied on-curve
    midpoints; a contour of off-curve points only is one run of such pieces."""
    P = np.asarray(pts, dtype=np.float64)
    n = len(c.on)
    if not any(c.on):
        return [[np.array([(P[i - 1] + P[i]) / 2, P[i], (P[i] + P[(i + 1) % n]) / 2])
                 for i in range(n)]]
    _, corners, _ = _node_kinds(c)
    start = _rotation(c, corners)
    order = [(start + i) % n for i in range(n)] + ([start] if c.closed else [])
    out: list[list[FloatArray]] = []
    cur: list[FloatArray] = []
    cset = set(corners)
    i = 0
    while i < len(order) - 1:
        j = i + 1
        while j < len(order) - 1 and not c.on[order[j]]:
            j += 1
        a, b = P[order[i]], P[order[j]]
        offs = [P[k] for k in order[i + 1:j]]
        if not offs:  # a line ends a run
            if cur:
                out.append(cur)
            cur = []
        elif c.quadratic and len(offs) > 1:
            ends = [a] + [(offs[m] + offs[m + 1]) / 2 for m in range(len(offs) - 1)] + [b]
            cur.extend(np.array([ends[m], o, ends[m + 1]]) for m, o in enumerate(offs))
        else:
            cur.append(np.array([a, *offs, b]))
        if order[j] in cset and cur:
            out.append(cur)
            cur = []
        i = j
    if cur:
        out.append(cur)
    return out


def fairness(c: Contour, pts: FloatArray) -> tuple[int, float]:
    """``(curvature extrema, bending energy)`` of the contour drawn with points ``pts``,
    measured on its Bezier segments as written (not on a B-spline fitted to them).

    Each smooth run (:func:`_segments`) is sampled at :data:`FAIRNESS_SAMPLES` parameters per
    segment; the signed curvature of a segment ``x(t)`` is
    ``kappa = (x' x y'' - x'' y') / |x'|^3`` (Bernstein derivatives, e.g. Farin, *Curves and
    Surfaces for CAGD*), the energy is ``sum over runs of int kappa^2 |x'| dt`` (trapezoid-free
    Riemann sum, step ``1/(M-1)``), and an extremum is a sign change of the successive
    differences of ``kappa`` along the run, differences below ``1e-3 / M`` of the run's largest
    ``|kappa|`` ignored (sampling noise, flat stretches). The same definition is used by
    ``benchmarks/bench_fonts.py``.
    """
    m = FAIRNESS_SAMPLES
    t = np.linspace(0.0, 1.0, m)[:, None]
    ext, energy = 0, 0.0
    for run in _segments(c, pts):
        ks = []
        for S in run:
            deg = len(S) - 1
            D = deg * np.diff(S, axis=0)
            if deg == 2:
                d1 = (1 - t) * D[0] + t * D[1]
                d2 = np.broadcast_to(D[1] - D[0], d1.shape)
            else:  # cubic
                d1 = (1 - t) ** 2 * D[0] + 2 * t * (1 - t) * D[1] + t ** 2 * D[2]
                d2 = 2 * ((1 - t) * (D[1] - D[0]) + t * (D[2] - D[1]))
            sp = np.hypot(d1[:, 0], d1[:, 1])
            k = (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / np.maximum(sp, 1e-300) ** 3
            energy += float(np.sum(k * k * sp)) / (m - 1)
            ks.append(k)
        kap = np.concatenate(ks)
        scale = max(float(np.max(np.abs(kap))), 1e-300)
        d = np.diff(kap)
        d = d[np.abs(d) > 1e-3 * scale / m]
        ext += int(np.sum(np.sign(d[1:]) != np.sign(d[:-1])))
    return ext, energy
