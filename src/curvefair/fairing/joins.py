"""What :func:`curvefair.fair` keeps of a curve's structure: smooth joins, corners, straight pieces.

A fairing method moves control points (or data points) one at a time and knows nothing of the
geometry the curve's author drew on purpose. :func:`plan` looks at the curve first and tells
:func:`~curvefair.fairing.fair.fair` what to hold:

* **G1 joins at C0 knots** (a B-spline knot of multiplicity ``degree``: a poly-Bezier join, a
  Rhino kink-free join, an SVG chain whose handles are collinear but of unequal length). The
  curve passes through the control point ``P_j`` of the knot; its tangents there are
  ``P_j - P_{j-1}`` and ``P_{j+1} - P_j``. A join whose tangent directions agree within
  ``g1_angle`` is faired as a C1 join: the parameter of each C0-separated block of spans is
  scaled (an affine map per block: the curve is unchanged, its control points too) so that
  the two derivatives become equal, ``|P_j - P_{j-1}| / (s_l dl) = |P_{j+1} - P_j| / (s_r dr)``
  (``dl``, ``dr`` the adjacent span widths); then one copy of the knot is removed, which drops
  ``P_j`` -- exact when the join is exactly G1, otherwise within the distance ``err`` of ``P_j``
  from ``(dr' P_{j-1} + dl' P_{j+1}) / (dl' + dr')`` (Boehm's knot insertion, which puts it
  back). The method fairs that curve with the tolerance reduced by ``err``; the result is
  written back on the original knot vector (insertion and the inverse scaling are exact), so
  the join is C1 in the scaled parameter: G1 to rounding (about 1e-15 rad), and every control
  point within ``tol`` of its original position (a knot-insertion row is a convex
  combination).
* **G2 joins** (the curvature also continuous, to ``1e-6`` of its size, at a C0 or C1 knot of a
  curve that is not C2 there) of open curves of degree >= 3 are faired through when that is
  cheap: after the G1 step above (C0 knots) the join is C1 with ``r''_+ - r''_- = beta2 r'``
  (Farin's beta-constraints, ``beta1 = 1``); one more knot copy is removed by least squares
  (only the two control points beside the join move, by the residual, which is zero when
  ``beta2 = 0``), so the method fairs a curve that is C2 there and the result, written back
  on the original knots by knot insertion, is G2 to rounding whatever the method does
  (:func:`_g2_through`). When the residual plus the G1 step's ``err`` exceeds ``tol / 4``,
  or one of those points is held, the join is held instead: the control points on which the
  value, tangent and second derivative on either side depend, which keeps position, tangent
  and curvature of both sides exactly.
* **corners** (a C0 knot whose tangents differ by more than ``g1_angle``): the join point
  ``P_j`` is held; the corner stays where it is and stays a corner. Its angle, and each of
  its tangents, may turn by at most :data:`DEFAULT_CORNER_TURN` (1 degree):
  :func:`curvefair.fair` measures every
  corner after the method (:func:`corner_turns`) and, where one turned more, fairs again
  with the control points that fix its angle held (``P_{j-1}``, ``P_j``, ``P_{j+1}``, or
  the supports of the tangents below), then with those of every corner held if another
  turned. Holding the point alone let a method swing the tangents where ``tol`` is longer
  than the handles: a 0.9-degree join of a Rhino PolyCurve came out a 93-degree kink.
* **a handle on its node** (a C0 join whose first derivative vanishes on a side, to
  ``_VANISH`` of the curve's size: ``C 240,60 240,90 240,90`` in SVG, Inkscape's rounded
  corners): the tangent of that side is that of its first derivative that does not vanish
  (``P_3 - P_1`` for a Bezier whose last handle is on its node). Such a join cannot be made
  C1; a G1 one is held -- its point and every control point the two tangents depend on --
  so its tangents and the handle on the node stay exactly; a corner holds its point and
  the handle on it. The seam of an open chain that ends on its start is treated the same
  way.
* **straight pieces**: the control points of a knot span whose control points are collinear
  (to 1e-9 of the curve's size: a line segment drawn as a B-spline or Bezier, a glyph stem)
  are held, so the line stays that line. (Point lists are cut at their corners when read, so
  a straight segment between two corners is a piece of its own with nothing to fair.)
* **seams**: an open curve whose ends coincide (a closed outline written as an open chain) with
  a G1 (G2) seam gets at least a ``g1`` (``g2``) clamp at both ends.

Closed (periodic) B-splines with C0 knots hold the three control points of each G1 join instead
of reparametrising.

``joins="free"`` in :func:`~curvefair.fairing.fair.fair` turns all this off (the method's
plain behaviour).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, NamedTuple, cast

import numpy as np

from .._kernels import joins as _k
from .._typing import FloatArray
from ..curves.bspline import POWER_FORM_MAX_DEGREE, BSplineCurve, basis_derivatives
from ..curves.piecewise import PiecewiseCurve, horner_rows

__all__ = ["plan", "JoinPlan", "Corner", "join_angles", "corner_turns", "DEFAULT_G1_ANGLE",
           "DEFAULT_CORNER_TURN"]

#: Default largest angle (degrees) between the two tangents of a join that is treated as G1.
DEFAULT_G1_ANGLE = 0.5
#: The most (degrees) a corner's angle may change in :func:`curvefair.fair` before the control
#: points that fix it are held (:func:`corner_turns`); Rhino's default angle tolerance.
DEFAULT_CORNER_TURN = 1.0
_G2_REL = 1e-6
_STRAIGHT_REL = 1e-9  # straight: off the line by at most this times the piece's length
#: a derivative of order k vanishes at a join when |r^(k)| w^k is at most this times the
#: curve's size (w the piece's width): a handle of zero length, up to rounding
_VANISH = 1e-10
_ROUND = 8 * np.finfo(float).eps  # plus this times the curve's size (rounding)
_CLAMP_RANK = {"none": -1, "g0": 0, "g1": 1, "g2": 2}


def _angle(a: FloatArray, b: FloatArray) -> float:
    """Angle in radians between two vectors (atan2 of |a x b| and a.b: accurate near 0)."""
    if a.shape[0] == 2:
        cr = abs(float(a[0] * b[1] - a[1] * b[0]))
    else:
        cr = float(np.linalg.norm(np.cross(a, b)))
    return float(np.arctan2(cr, float(a @ b)))


def _curvature(d1: FloatArray, d2: FloatArray) -> float:
    n1 = float(np.linalg.norm(d1))
    if d1.shape[0] == 2:
        cr = float(d1[0] * d2[1] - d1[1] * d2[0])
    else:
        cr = float(np.linalg.norm(np.cross(d1, d2)))
    return cr / max(n1 ** 3, 1e-300)


def join_angles(curve: PiecewiseCurve) -> FloatArray:
    """Angle (radians) between the left and right tangent at every interior break of the
    curve's piecewise-polynomial form (and at the seam of a closed curve), shape ``(k,)``.

    The tangents are the first derivatives of the two polynomial pieces meeting there.
    """
    pp = curve.piecewise
    c = np.asarray(pp.coeffs)
    w = np.asarray(pp.widths)
    p = c.shape[1] - 1
    right = c[:, 1, :]
    left = cast(FloatArray, sum(j * c[:, j, :] * w[:, None] ** (j - 1) for j in range(1, p + 1)))
    pairs = [(left[k - 1], right[k]) for k in range(1, c.shape[0])]
    if curve.closed:
        pairs.append((left[-1], right[0]))
    return np.array([_angle(a, b) for a, b in pairs])


class Corner(NamedTuple):
    """A corner of the input that :func:`corner_turns` checks: where the curve arrives (knot
    ``vl`` of piece ``sl``) and leaves (``vr`` of ``sr``; the same knot but at a seam), the
    input's tangents there (directions; any length), and the control points that fix them."""

    vl: float
    sl: int
    vr: float
    sr: int
    tl: FloatArray
    tr: FloatArray
    support: frozenset[int]


@dataclass
class JoinPlan:
    """What :func:`plan` decided; see the module docstring.

    Attributes
    ----------
    curve : PiecewiseCurve
        The curve to hand to the method (the input, or its reparametrised reduced form).
    protect : frozenset of int
        Indices (of ``curve``'s data/control points) that must not move.
    clamp : (str, str)
        The clamp to use (raised at a smooth seam).
    margin : float
        ``err``: how far the reduced curve's re-inserted control points are from the input's;
        the method's tolerance is ``tol - margin``.
    report : dict
        Counts for the fairing report.
    """

    curve: PiecewiseCurve
    protect: frozenset[int]
    clamp: tuple[str, str]
    margin: float = 0.0
    report: dict[str, Any] = field(default_factory=dict)
    #: the corners of the input whose angle :func:`corner_turns` checks
    corners: list[Corner] = field(default_factory=list)
    # reduction data (B-splines with reduced G1 joins)
    _orig: BSplineCurve | None = None
    _keep: np.ndarray | None = None  # original index of each reduced control point
    _ins: list[tuple[int, int, int, float]] = field(default_factory=list)  # (j, jl, jr, a)
    # G2 joins faired through (second knot copy removed): the knot-insertion matrix from
    # ``curve``'s control points to those of the once-reduced curve, and each column's row
    _g2: Any = None
    _g2_row: np.ndarray | None = None

    @property
    def reduced(self) -> bool:
        return self._orig is not None

    def restorable(self, faired: PiecewiseCurve) -> bool:
        """Whether :meth:`restore` can map ``faired`` back (same knots as :attr:`curve`)."""
        if self._orig is None:
            return True
        c = self.curve
        return (isinstance(faired, BSplineCurve) and isinstance(c, BSplineCurve)
                and faired.degree == c.degree and faired.n_ctrl == c.n_ctrl
                and np.array_equal(faired.knots, c.knots))

    def restore(self, faired: PiecewiseCurve) -> PiecewiseCurve:
        """The faired curve on the input's own knot vector (identity when nothing was reduced)."""
        if self._orig is None:
            return faired
        assert isinstance(faired, BSplineCurve) and self._keep is not None
        Q = np.asarray(faired.control_points)
        if self._g2 is not None:
            Q = np.asarray(self._g2 @ Q)
        P = np.empty((self._orig.n_ctrl, Q.shape[1]))
        P[self._keep] = Q
        for j, jl, jr, a in self._ins:
            P[j] = (1.0 - a) * P[jl] + a * P[jr]
        return BSplineCurve(P, self._orig.knots, self._orig.degree, closed=False)

    def original_index(self, idx: np.ndarray) -> np.ndarray:
        """Map indices of ``curve``'s control points to the input's."""
        if self._keep is None:
            return np.asarray(idx)
        idx = np.asarray(idx, dtype=np.int64)
        if self._g2_row is not None:
            idx = self._g2_row[idx]
        return self._keep[idx]


def _size(pts: FloatArray) -> float:
    # the extent per coordinate as 1-D reductions (max - min, as np.ptp computes it): a
    # reduction along axis 0 of an (n, 2) array is several times slower at a million points
    ext = max((float(pts[:, d].max() - pts[:, d].min()) for d in range(pts.shape[1])),
              default=0.0) if pts.shape[0] else 0.0
    return max(ext, float(np.abs(pts).max()) if pts.size else 0.0, 1e-300)


def _straight_spans(curve: BSplineCurve, P: FloatArray, eps: float) -> tuple[set[int], int]:
    """Control points of every knot span whose ``degree + 1`` control points are within
    ``_STRAIGHT_REL`` times the span's chord plus ``eps`` of the line through the first and
    last of them, and the number of such spans
    (:func:`curvefair._kernels.joins.straight_kernel`)."""
    mark = np.zeros(P.shape[0], dtype=np.bool_)
    k = _k.straight_kernel(np.ascontiguousarray(P, dtype=np.float64),
                           np.ascontiguousarray(curve.spans, dtype=np.int64), int(curve.degree),
                           bool(curve.closed), _STRAIGHT_REL, float(eps), mark)
    return set(np.flatnonzero(mark).tolist()), int(k)


def _side_support(curve: BSplineCurve, span: int, u: float, nder: int) -> list[int]:
    """Control-point indices whose basis functions (or their first ``nder`` derivatives) are
    non-zero at ``u`` evaluated on knot span ``span`` (a one-sided limit at a knot)."""
    p = curve.degree
    ders = basis_derivatives(np.asarray(curve.knots), p, np.array([span]), np.array([u]), nder)
    nz = np.flatnonzero(np.abs(ders[0]).max(axis=0) > 1e-14)
    return [int(i) for i in curve.control_index(span - p + nz)]


def _vanishes(d: FloatArray, w: float, k: int, size: float) -> bool:
    """Whether the derivative ``d`` of order ``k`` of a piece of width ``w`` is zero up to
    rounding: ``|d| w^k <= _VANISH size`` (a handle of zero length for ``k = 1``)."""
    return float(np.linalg.norm(d)) * float(w) ** k <= _VANISH * size


class _SpanForm:
    """What a join plan reads of a B-spline's power form (breaks, widths, degree, values at a
    few breaks on given pieces) without the whole form, which the analysis no longer builds
    either (it reads its spans range by range): the rows of the pieces asked for
    (:meth:`~curvefair.BSplineCurve.span_coefficients`), evaluated by Horner's rule as
    :meth:`~curvefair.PiecewisePolynomial.evaluate` evaluates a few pieces: the same bits."""

    def __init__(self, curve: BSplineCurve) -> None:
        self.curve = curve
        self.breaks = np.asarray(curve.span_breaks)
        self.widths = np.diff(self.breaks)
        self.degree = int(curve.degree)

    def evaluate(self, u: Any, nu: int, segment: np.ndarray) -> FloatArray:
        uf = np.asarray(u, dtype=float).reshape(-1)
        seg = np.asarray(segment).reshape(-1)
        rows = self.curve.span_coefficients(seg)
        return horner_rows(rows, (uf - self.breaks[seg])[:, None], nu)


def _form_of(curve: BSplineCurve) -> Any:
    """The curve's power form if it is built (or has its own evaluator), else a
    :class:`_SpanForm`."""
    if "piecewise" in curve.__dict__ or curve.degree > POWER_FORM_MAX_DEGREE:
        return curve.piecewise
    return _SpanForm(curve)


def _side_tangent(pp: Any, v: float, seg: int, left: bool, size: float
                  ) -> tuple[FloatArray | None, int]:
    """The direction in which the curve arrives at (``left``) or leaves the break ``v`` of
    polynomial piece ``seg``, and the derivative order it comes from: the first derivative
    ``r^(k)`` that does not vanish (``|r^(k)| w^k > _VANISH size``, ``w`` the piece's width),
    ``(-1)^(k+1) r^(k)`` on the arriving side (``r(v - h) - r(v) ~ (-h)^k r^(k) / k!``);
    ``(None, 0)`` when every derivative vanishes (a piece of zero length). A Bezier whose last
    handle lies on its node (``P_2 = P_3``) arrives along ``P_3 - P_1``."""
    w = float(np.asarray(pp.widths)[seg])
    x, s = np.array([v]), np.array([seg])
    for k in range(1, int(pp.degree) + 1):
        d = np.asarray(pp.evaluate(x, k, segment=s), dtype=float).reshape(-1)
        if not _vanishes(d, w, k, size):
            return (-d if left and k % 2 == 0 else d), k
    return None, 0


def _degenerate_join(curve: BSplineCurve, pp: Any, v: float, k: int, j: int, g1: float,
                     size: float, hold: set[int], rep: dict[str, Any],
                     seam: tuple[float, int] | None = None,
                     corners: list[Corner] | None = None) -> None:
    """A C0 join (knot ``v``, break ``k`` of ``pp``, join point ``P_j``) with a handle of zero
    length on a side: it cannot be made C1 (one first derivative is zero), so it is held.
    A corner (tangents apart by more than ``g1``, or a side of zero length) holds its point
    and a handle that lies on it (the first derivative of that side stays zero); a G1 join
    holds every control point its two tangents depend on -- the point, and on each side
    those of the derivatives up to the order that gives the tangent there -- so both
    directions, the handles of zero length and the join stay exactly as they are.
    ``seam``: the seam of a closed curve, where the curve arrives at ``seam = (v_end, last
    piece)`` and leaves at ``(v, k)`` = (the domain's start, piece 0)."""
    vl, kl_seg = seam if seam is not None else (v, k - 1)
    tl, kl = _side_tangent(pp, vl, kl_seg, True, size)
    tr, kr = _side_tangent(pp, v, k, False, size)
    t = np.asarray(curve.knots)
    sl = int(np.searchsorted(t, vl, side="left")) - 1  # the span ending at vl
    sr = int(np.searchsorted(t, v, side="right")) - 1  # the span starting at v
    if tl is None or tr is None or _angle(tl, tr) > g1:
        hold.add(int(curve.control_index(j)))
        # a handle on the node stays there (a cusp or a corner drawn with the handle
        # retracted keeps that: its first derivative stays zero)
        if kl >= 2:
            hold.update(_side_support(curve, sl, vl, 1))
        if kr >= 2:
            hold.update(_side_support(curve, sr, v, 1))
        rep["corners_held"] += 1
        if corners is not None and tl is not None and tr is not None:
            corners.append(Corner(vl, kl_seg, v, k, tl, tr,
                                  frozenset(_side_support(curve, sl, vl, kl))
                                  | frozenset(_side_support(curve, sr, v, kr))))
        return
    hold.update(_side_support(curve, sl, vl, kl))
    hold.update(_side_support(curve, sr, v, kr))
    rep["g1_joins"] += 1


def _bspline_plan(curve: BSplineCurve, clamp: tuple[str, str], protect: frozenset[int],
                  g1: float, tol: float | None, allow_reduce: bool = True,
                  no_g2: frozenset[int] = frozenset()) -> JoinPlan:
    p = curve.degree
    t = np.asarray(curve.knots, dtype=float)
    P = np.asarray(curve.control_points, dtype=float)
    n = P.shape[0]
    size = _size(P)
    eps = _ROUND * size
    hold: set[int] = set()
    corners: list[Corner] = []
    rep: dict[str, Any] = {"g1_joins": 0, "g1_joins_reparametrised": 0, "g2_joins_held": 0,
                           "g2_joins_faired": 0, "corners_held": 0, "straight_spans_held": 0}

    # straight spans: every control point of a span lying on one line
    straight, rep["straight_spans_held"] = _straight_spans(curve, P, eps)
    hold.update(straight)

    # distinct interior knots of the domain and their multiplicities
    lo, hi = curve.domain
    vals, first, counts = np.unique(t, return_index=True, return_counts=True)
    pp = _form_of(curve)
    br = np.asarray(pp.breaks)
    reduce: list[tuple[int, int, float, float]] = []  # (j, knot position a, dl, dr)
    g2_cand: dict[int, set[int]] = {}  # G2 C0 join point -> the control points it depends on
    g2_c1: dict[int, set[int]] = {}  # G2 C1 knot (first index in t) -> the same
    # candidates: interior knots of multiplicity p - 1 or p (C1 / C0); C2 or smoother knots
    # are left to the method, which cannot break them
    cand = (vals > lo) & (vals < hi) & (counts <= p) & (counts >= p - 1)
    cv, ca, cm = vals[cand], first[cand], counts[cand]
    ck = np.searchsorted(br, cv)
    okk = (ck > 0) & (ck < br.shape[0] - 1)
    okk[okk] &= br[ck[okk]] == cv[okk]
    cv, ca, cm, ck = cv[okk], ca[okk], cm[okk], ck[okk]
    wid = np.asarray(pp.widths, dtype=float)
    D1L = pp.evaluate(cv, 1, segment=ck - 1).reshape(-1, P.shape[1])
    D1R = pp.evaluate(cv, 1, segment=ck).reshape(-1, P.shape[1])
    D2L = pp.evaluate(cv, 2, segment=ck - 1).reshape(-1, P.shape[1])
    D2R = pp.evaluate(cv, 2, segment=ck).reshape(-1, P.shape[1])
    for q in range(cv.shape[0]):
        v, a, m = float(cv[q]), int(ca[q]), int(cm[q])
        d1l, d1r, d2l, d2r = D1L[q], D1R[q], D2L[q], D2R[q]
        c0 = m == p
        if _vanishes(d1l, wid[ck[q] - 1], 1, size) or _vanishes(d1r, wid[ck[q]], 1, size):
            # a handle of zero length on one side (a Bezier control point on its node): the
            # tangent there is that of the first derivative that does not vanish
            if c0:
                _degenerate_join(curve, pp, v, int(ck[q]), int(a - 1), g1, size, hold, rep,
                                 corners=corners)
            continue
        ang = _angle(d1l, d1r)
        if c0 and ang > g1:
            hold.add(int(curve.control_index(a - 1)))
            corners.append(Corner(v, int(ck[q]) - 1, v, int(ck[q]), d1l, d1r, frozenset(
                int(i) for i in curve.control_index(np.arange(a - 2, a + 1)))))
            rep["corners_held"] += 1
            continue
        if ang > g1:
            continue
        if c0:
            rep["g1_joins"] += 1
        # G2 (curvature continuous) at a join that is not C2
        if m >= p - 1 and p >= 2:
            kl, kr = _curvature(d1l, d2l), _curvature(d1r, d2r)
            if abs(kl - kr) <= _G2_REL * max(abs(kl), abs(kr)) and max(abs(kl), abs(kr)) > 0:
                sl = int(np.searchsorted(t, v, side="left")) - 1  # span ending at v
                sr = int(np.searchsorted(t, v, side="right")) - 1  # span starting at v
                sup = set(_side_support(curve, sl, v, 2)) | set(_side_support(curve, sr, v, 2))
                through = p >= 3 and not curve.closed and allow_reduce
                if c0 and through and (a - 1) not in protect and (a - 1) not in no_g2:
                    g2_cand[a - 1] = sup  # faired through if both knot copies can go (below)
                elif (m == p - 1 and through and not protect & {a - 2, a - 1}
                      and -a - 1 not in no_g2):
                    g2_c1[a] = sup  # a C1 knot: faired through if one copy can go (below)
                    continue
                else:
                    hold.update(sup)
                    rep["g2_joins_held"] += 1
                    continue
        if not c0:
            continue  # C1 or smoother: the method keeps the tangent continuous itself
        j = int(a - 1)
        if curve.closed or j in protect:
            hold.update(int(i) for i in curve.control_index(np.arange(j - 1, j + 2)))
            continue
        dl = float(v - t[a - 1])
        dr = float(t[a + p] - v)
        reduce.append((j, int(a), dl, dr))

    if curve.closed:
        # the seam of a closed curve sits at the domain's ends, which the knots above leave out:
        # a seam knot of multiplicity degree (a closed outline stored clamped, e.g. a DXF
        # closed SPLINE) is a join like any other -- its point held if it is a corner, its three
        # points held if it is G1 (a periodic curve is not reduced)
        m0 = int(np.count_nonzero(t == lo))
        if m0 >= p:
            a0 = int(np.flatnonzero(t == lo)[0])
            d0 = pp.evaluate(np.array([lo]), 1, segment=np.array([0])).reshape(-1)
            d1 = pp.evaluate(np.array([hi]), 1,
                             segment=np.array([br.shape[0] - 2])).reshape(-1)
            j = a0 - 1
            last = br.shape[0] - 2
            if _vanishes(d0, wid[0], 1, size) or _vanishes(d1, wid[last], 1, size):
                _degenerate_join(curve, pp, lo, 0, j, g1, size, hold, rep, seam=(hi, last),
                                 corners=corners)
            else:
                if _angle(d1, d0) > g1:
                    hold.add(int(curve.control_index(j)))
                    corners.append(Corner(hi, last, lo, 0, d1, d0, frozenset(
                        int(i) for i in curve.control_index(np.arange(j - 1, j + 2)))))
                    rep["corners_held"] += 1
                else:
                    hold.update(int(i) for i in curve.control_index(np.arange(j - 1, j + 2)))
                    rep["g1_joins"] += 1

    out_clamp = list(clamp)
    if not curve.closed:
        e0, e1 = P[0], P[-1]
        if np.abs(e0 - e1).max() <= _STRAIGHT_REL * size:
            d0 = curve(np.array([lo]), 1)[0]
            d1 = curve(np.array([hi]), 1)[0]
            last = br.shape[0] - 2
            if _vanishes(d0, wid[0], 1, size) or _vanishes(d1, wid[last], 1, size):
                # an end handle of zero length: no clamp keeps the end's tangent (it is not the
                # first derivative's), so a G1 seam holds what both end tangents depend on
                tl, kl = _side_tangent(pp, hi, last, True, size)
                tr, kr = _side_tangent(pp, lo, 0, False, size)
                if tl is not None and tr is not None:
                    sup = set(_side_support(curve, n - 1, hi, kl)) | set(
                        _side_support(curve, p, lo, kr))
                    if _angle(tl, tr) <= g1:
                        hold.update(sup)
                        rep["seam_clamp"] = "held"
                    else:
                        corners.append(Corner(hi, last, lo, 0, tl, tr, frozenset(sup)))
            elif min(np.linalg.norm(d0), np.linalg.norm(d1)) > 0 and _angle(d1, d0) > g1:
                # a corner where the chain meets its start (its ends are clamped)
                corners.append(Corner(hi, last, lo, 0, d1, d0, frozenset((0, 1, n - 2, n - 1))))
            elif min(np.linalg.norm(d0), np.linalg.norm(d1)) > 0:
                k0 = _curvature(d0, curve(np.array([lo]), 2)[0])
                k1 = _curvature(d1, curve(np.array([hi]), 2)[0])
                want = "g2" if abs(k0 - k1) <= _G2_REL * max(abs(k0), abs(k1), 1e-300) else "g1"
                for s in (0, 1):
                    if _CLAMP_RANK[out_clamp[s]] < _CLAMP_RANK[want]:
                        out_clamp[s] = want
                rep["seam_clamp"] = want

    jplan = JoinPlan(curve, frozenset(), (out_clamp[0], out_clamp[1]), 0.0, rep,
                     corners=corners)
    # a join is reduced only if its point is free and the reduction moves it little: the
    # re-inserted point is (R P_{j-1} + L P_{j+1}) / (L + R), L and R the handle lengths
    errs: dict[int, float] = {}
    for j, *_ in reduce:
        L = float(np.linalg.norm(P[j] - P[j - 1]))
        R = float(np.linalg.norm(P[j + 1] - P[j]))
        e = (float(np.linalg.norm((R * P[j - 1] + L * P[j + 1]) / (L + R) - P[j]))
             if L > 0 and R > 0 else np.inf)
        if (not allow_reduce or j in hold or (tol is not None and e > 0.25 * tol)
                or not np.isfinite(e)):
            hold.update((j - 1, j, j + 1))  # hold the join's three points instead
        else:
            errs[j] = e
    reduce = [r for r in reduce if r[0] in errs]
    if reduce or g2_c1:
        # block scales: blocks are separated by the C0 knots; s_{b+1}/s_b from each reduced join
        c0_knots = [float(v) for v, m in zip(vals, counts, strict=True)
                    if lo < v < hi and m == p]
        ratio = {}
        for j, a, dl, dr in reduce:
            L = float(np.linalg.norm(P[j] - P[j - 1]))
            R = float(np.linalg.norm(P[j + 1] - P[j]))
            if not (L > 0 and R > 0):
                continue
            ratio[float(t[a])] = (R * dl) / (L * dr)
        scales = [1.0]
        for v in c0_knots:
            scales.append(scales[-1] * ratio.get(v, 1.0))
        edges = np.array([lo] + c0_knots + [hi])
        # phi: piecewise linear, slope scales[b] on block b, phi(lo) = lo
        phi_e = lo + np.r_[0.0, np.cumsum(np.diff(edges) * np.array(scales))]
        if ratio:
            tau = np.interp(t, edges, phi_e)
            tau[t <= lo] = lo
            tau[t >= hi] = phi_e[-1]
        else:  # only G2 C1 knots to remove: the curve's own parameter
            tau = t.copy()
        drop_j = {j for j, *_ in reduce if float(t[j + 1]) in ratio}
        drop_knot = sorted(j + 1 for j in drop_j)
        keep = np.array([i for i in range(n) if i not in drop_j], dtype=np.int64)
        tau_r = np.delete(tau, drop_knot)
        R0 = BSplineCurve(P[keep], tau_r, p, closed=False)
        ins = []
        err = 0.0
        for j in sorted(drop_j):
            a = j + 1
            dl2 = float(tau[a] - tau[a - 1])
            dr2 = float(tau[a + p] - tau[a])
            w = dl2 / (dl2 + dr2)
            ins.append((j, j - 1, j + 1, w))
            err = max(err, float(np.linalg.norm((1.0 - w) * P[j - 1] + w * P[j + 1] - P[j])))
        for jj, sup in g2_cand.items():
            if jj not in drop_j:  # its G1 reduction was refused: hold what keeps it G2
                hold.update(sup)
                rep["g2_joins_held"] += 1
        inv = {int(o): r for r, o in enumerate(keep)}
        jplan.curve = R0
        jplan._orig = curve
        jplan._keep = keep
        jplan._ins = ins
        jplan.margin = err
        rep["g1_joins_reparametrised"] = len(drop_j)
        rep["g1_reduction_error"] = err
        hold_r = {inv[i] for i in hold if i in inv}
        for i in hold:
            if i not in inv:  # a dropped join point asked to hold: hold its neighbours
                hold_r.update((inv[i - 1], inv[i + 1]))
        prot_r = {inv[i] for i in protect if i in inv}
        g2_js = sorted(jj for jj in g2_cand if jj in drop_j)
        # C1 knots (key -a - 1 apart from the join points): rows a-2, a-1 of the input change
        for a, sup in g2_c1.items():
            if a - 2 in inv and a - 1 in inv:
                g2_cand[-a - 1] = sup
                g2_js.append(-a - 1)
            else:
                hold.update(sup)
                rep["g2_joins_held"] += 1
        fixed = hold_r | prot_r
        if g2_js:
            knot_of = {jj: float(tau[jj + 1] if jj >= 0 else tau[-jj - 1]) for jj in g2_js}
            left = {jj: inv[jj - 1] if jj >= 0 else inv[-jj - 3] for jj in g2_js}
            sup_r = {jj: {inv[i] for i in g2_cand[jj] if i in inv}
                     | ({inv[jj - 1], inv[jj + 1]} if jj >= 0 else set()) for jj in g2_js}
            fixed = _g2_through(jplan, R0, knot_of, left, sup_r, fixed, tol, err, rep)
            refused = rep.pop("_g2_refused")
            if refused:  # plan again holding those joins exactly as before (no reduction)
                return _bspline_plan(curve, clamp, protect, g1, tol, allow_reduce,
                                     no_g2 | frozenset(refused))
        jplan.protect = frozenset(fixed)
        rep["held"] = sorted(hold)
        return jplan
    jplan.protect = frozenset(hold | set(protect))
    rep["held"] = sorted(hold)
    return jplan


def _insert_rows(U: FloatArray, rows: list[dict[int, float]], p: int, u: float
                 ) -> tuple[FloatArray, list[dict[int, float]]]:
    """Boehm's knot insertion of ``u`` into ``U`` (Piegl & Tiller A5.1) applied to control
    points given as rows of weights over some basis: ``Q_i = a_i P_i + (1 - a_i) P_{i-1}``
    for ``k - p < i <= k - s``, ``a_i = (u - U_i) / (U_{i+p} - U_i)``, the others copied."""
    k = int(np.searchsorted(U, u, side="right")) - 1
    m = int(np.count_nonzero(U == u))
    new = rows[:k - p + 1]
    for i in range(k - p + 1, k - m + 1):
        a = float((u - U[i]) / (U[i + p] - U[i]))
        row: dict[int, float] = {}
        for q, w in rows[i].items():
            if a * w != 0.0:
                row[q] = row.get(q, 0.0) + a * w
        for q, w in rows[i - 1].items():
            if (1.0 - a) * w != 0.0:
                row[q] = row.get(q, 0.0) + (1.0 - a) * w
        new.append(row)
    new.extend(rows[k - m:])
    return np.insert(U, k + 1, u), new


def _g2_through(jplan: JoinPlan, R0: BSplineCurve, knot: dict[int, float], left: dict[int, int],
                sup_r: dict[int, set[int]], fixed: set[int], tol: float | None, err1: float,
                rep: dict[str, Any]) -> set[int]:
    """Fair through the G2 joins ``knot`` (join point index -> its knot in ``R0``, the
    once-reduced curve, where the join is C1 with a knot of multiplicity ``degree - 1``).

    A G2 join made C1 by the block scaling satisfies ``r''_+ - r''_- = beta2 r'`` (Farin's
    beta-constraints with ``beta1 = 1``). Removing one more knot copy makes it C2 in the scaled
    parameter -- curvature continuous, and G2 whatever the method then does -- at the cost of
    the least-squares residual of the removal: with ``A`` the knot-insertion matrix back to
    ``R0`` (rows are convex combinations), the free control points (those that are not the
    copy of one ``R0`` point) solve ``min |A Q - R0|`` with the others fixed to their ``R0``
    values, so only the two points of ``R0`` beside each join move, by ``|A Q - R0|``. A
    join is refused (its support held instead, as before) when that residual plus the first
    reduction's ``err1`` exceeds ``tol / 4``, or when one of those two points is held.
    Sets ``jplan``'s curve, insertion matrix and margin (the largest distance of the restored
    control points from the input's, measured); returns what to protect on the new curve.
    """
    from scipy.sparse import csr_matrix
    from scipy.sparse.linalg import spsolve

    p = R0.degree
    tau = np.asarray(R0.knots)
    Q0 = np.asarray(R0.control_points)
    n0 = Q0.shape[0]
    acc = sorted(knot)
    refused: list[int] = []
    fixed = set(fixed)
    lim = None if tol is None else 0.25 * tol - err1
    while acc:
        U2 = tau.copy()
        for jj in acc:
            U2 = np.delete(U2, int(np.flatnonzero(U2 == knot[jj])[-1]))
        n2 = n0 - len(acc)
        rows: list[dict[int, float]] = [{i: 1.0} for i in range(n2)]
        U = U2
        for jj in acc:
            U, rows = _insert_rows(U, rows, p, knot[jj])
        unit = {i: next(iter(r)) for i, r in enumerate(rows)
                if len(r) == 1 and next(iter(r.values())) == 1.0}
        changed = [i for i in range(n0) if i not in unit]

        ids = sorted(acc, key=lambda jq: left[jq])
        pos = np.array([left[jq] + 0.5 for jq in ids])

        def owner(i: int, ids: list[int] = ids, pos: np.ndarray = pos) -> int:
            """The join whose removal changed row ``i`` of ``R0`` (the nearest one)."""
            k = int(np.searchsorted(pos, i))
            if k == len(ids) or (k > 0 and i - pos[k - 1] <= pos[k] - i):
                k -= 1
            return ids[k]

        bad = {owner(i) for i in changed if i in fixed}
        if not bad:
            r_i = np.repeat(np.arange(n0), [len(r) for r in rows])
            c_i = np.fromiter((q for r in rows for q in r), dtype=np.int64)
            w_i = np.fromiter((w for r in rows for w in r.values()), dtype=float)
            A = csr_matrix((w_i, (r_i, c_i)), shape=(n0, n2))
            fixed_cols = np.array(sorted(unit.values()), dtype=np.int64)
            free = np.setdiff1d(np.arange(n2), fixed_cols)
            Q2 = np.empty((n2, Q0.shape[1]))
            back = {c: i for i, c in unit.items()}
            Q2[fixed_cols] = Q0[[back[int(c)] for c in fixed_cols]]
            Ac = A[changed]
            rhs = Q0[changed] - Ac[:, fixed_cols] @ Q2[fixed_cols]
            Af = Ac[:, free]
            sol = spsolve((Af.T @ Af).tocsc(), Af.T @ rhs)
            Q2[free] = np.asarray(sol).reshape(len(free), -1)
            res = np.linalg.norm(A @ Q2 - Q0, axis=1)
            worst: dict[int, float] = {}
            for i in changed:
                o = owner(i)
                worst[o] = max(worst.get(o, 0.0), float(res[i]))
            if lim is not None:
                bad = {jj for jj, e in worst.items() if not e <= lim}
            bad |= {jj for jj, e in worst.items() if not np.isfinite(e)}
        if bad:
            for jj in bad:
                acc.remove(jj)
                refused.append(jj)
                fixed |= sup_r[jj]
            continue
        R2 = BSplineCurve(Q2, U2, p, closed=False)
        row_of = np.array([back.get(c, int(np.argmax(A[:, c].toarray()))) for c in range(n2)],
                          dtype=np.int64)
        jplan.curve = R2
        jplan._g2 = A
        jplan._g2_row = row_of
        restored = np.asarray(cast(BSplineCurve, jplan.restore(R2)).control_points)
        assert jplan._orig is not None
        jplan.margin = float(np.linalg.norm(
            restored - np.asarray(jplan._orig.control_points), axis=1).max())
        rep["g2_joins_faired"] = len(acc)
        rep["g2_joins_held"] += len(refused)
        rep["g2_reduction_error"] = float(max(worst.values()))
        rep["_g2_refused"] = refused
        return {unit[i] for i in fixed}
    rep["g2_joins_held"] += len(refused)
    rep["_g2_refused"] = refused
    return fixed


def corner_turns(after: BSplineCurve, corners: list[Corner],
                 limit: float = DEFAULT_CORNER_TURN) -> frozenset[int]:
    """The control points that fix each corner of the input (:attr:`JoinPlan.corners`) whose
    angle ``after`` the fairing differs by more than ``limit`` degrees, or one of whose two
    tangents turned by more than that (a corner swung round whole keeps its angle but not its
    look: a Bezier leaving a line at 0.9 degrees to one side came back at 0.9 degrees to the
    other); empty: none.

    Tangents are those arriving and leaving (:func:`_side_tangent`: the first derivative that
    does not vanish) of ``after``, which is on the input's knots (same breaks), against the
    input's own, kept in each :class:`Corner` by :func:`plan`. A corner whose tangent
    vanishes after counts as turned."""
    if not corners:
        return frozenset()
    pp = after.piecewise
    size = _size(np.asarray(after.control_points, dtype=np.float64))
    lim = float(np.radians(limit))
    out: set[int] = set()
    for c in corners:
        tl, _ = _side_tangent(pp, c.vl, c.sl, True, size)
        tr, _ = _side_tangent(pp, c.vr, c.sr, False, size)
        if (tl is None or tr is None or abs(_angle(tl, tr) - _angle(c.tl, c.tr)) > lim
                or _angle(c.tl, tl) > lim or _angle(c.tr, tr) > lim):
            out.update(c.support)
    return frozenset(out)


def plan(curve: PiecewiseCurve, clamp: tuple[str, str], protect: frozenset[int],
         g1_angle: float = DEFAULT_G1_ANGLE, tol: float | None = None,
         allow_reduce: bool = True) -> JoinPlan:
    """Decide what the fairing keeps (module docstring); ``g1_angle`` in degrees.

    ``allow_reduce=False``: hold the three control points of every G1 join instead of
    reparametrising (for a method that changes the knot vector itself)."""
    g1 = float(np.radians(g1_angle))
    if isinstance(curve, BSplineCurve):
        return _bspline_plan(curve, clamp, protect, g1, tol, allow_reduce)
    # Hermite curves (point data): the reader already cut point lists at their corners, and a
    # straight piece between two corners has nothing to fair; a straight run inside a piece
    # (a line with a bump) is what fairing is for, so nothing more is held here
    return JoinPlan(curve, frozenset(protect), clamp, 0.0, {"held": []})
