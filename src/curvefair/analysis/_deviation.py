"""Maximum distance between two curves: at equal parameters (certified), or geometric."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from .. import _threads
from .._distance import point_distances
from .._kernels import deviation as _k
from .._typing import ArrayLike, FloatArray
from ..curves.piecewise import PiecewiseCurve
from ..errors import InputError
from ._core import bernstein_matrix, check_curve, fields_to_dict, taylor_shift, to_bernstein

__all__ = ["Deviation", "deviation", "hermite_delta_deviation", "bspline_delta_deviation",
           "DEVIATION_RTOL",
           "matched_hermite_bound"]

#: Relative accuracy of :attr:`Deviation.max_distance` (see :func:`deviation`).
DEVIATION_RTOL = 1e-12
_MAX_LEVELS = 64
#: Pieces the branch-and-bound keeps per level: at least this many, and an eighth of the
#: curve's pieces (a tolerance-bound result has its maximum at many knots: about 4.5 % of the
#: pieces of a 1e7-point cubic are candidates at the first level); beyond it the pieces with
#: the smallest bounds are dropped into ``upper_bound``.
_MAX_CANDIDATES = 1 << 18
#: pieces from which hermite_delta_deviation's pass runs on two threads
_PAR_MIN = 50_000
_CANDIDATE_SHARE = 8  # the cap's other term: pieces // _CANDIDATE_SHARE


@dataclass(frozen=True, eq=False)
class Deviation:
    """Result of :func:`deviation`.

    Attributes
    ----------
    max_distance : float
        ``kind="parametric"``: ``max_t |a(t) - b(t)|`` over the common domain (a lower bound
        attained at :attr:`param`, within the accuracy stated in :func:`deviation`).
        ``kind="geometric"``: the Hausdorff distance ``max(h(a, b), h(b, a))`` with
        ``h(a, b) = max_t min_s |a(t) - b(s)|``.
    upper_bound : float or None
        Parametric: certified upper bound of the true maximum (Bernstein convex-hull bound);
        ``max_distance <= true max <= upper_bound`` up to rounding. Geometric: None (the
        search is not certified, see :func:`deviation`).
    param : float
        Parameter of ``curve_a`` where the maximum is attained (geometric: of ``point_a``).
    point_a, point_b : ndarray, shape (dim,)
        ``a(param)`` and ``b(param)``; geometric: the two points, one on each curve, at the
        distance :attr:`max_distance` (``point_b`` is the nearest point of ``b`` to
        ``point_a``, or ``point_a`` the nearest of ``a`` to ``point_b``).
    max_point_displacement : float or None
        ``max_i |P_i^a - P_i^b|`` over the data points (``points`` of Hermite curves,
        ``control_points`` of B-splines) when both curves have the same kind and number of
        them; else None.
    point_index : int or None
        Index of that data point (0-based).
    kind : {"parametric", "geometric"}
        Which distance was measured.
    """

    max_distance: float
    upper_bound: float | None
    param: float
    point_a: FloatArray
    point_b: FloatArray
    max_point_displacement: float | None
    point_index: int | None
    kind: str = "parametric"

    def to_dict(self) -> dict[str, Any]:
        """A JSON-serialisable dict of plain floats, ints, lists and None."""
        return fields_to_dict(self)


def _data_points(curve: PiecewiseCurve) -> tuple[str, FloatArray] | None:
    for name in ("control_points", "points"):
        v = getattr(curve, name, None)
        if isinstance(v, np.ndarray):
            return name, v
    return None


def point_displacement(a: PiecewiseCurve, b: PiecewiseCurve
                       ) -> tuple[float | None, int | None]:
    """The largest displacement between the data points of two curves of one kind.

    Parameters
    ----------
    a, b : curve
        Curves whose data points correspond one to one: control points of two B-splines,
        points of two Hermite curves, with the same shape.

    Returns
    -------
    (float, int) or (None, None)
        ``max_i |b_i - a_i|`` (:func:`curvefair._distance.point_distances`, the figure
        :func:`curvefair.fair` reports as ``max_point_displacement``) and its 0-based index;
        ``(None, None)`` when the data points are of different kinds or counts (nothing to
        compare point by point).
    """
    da, db = _data_points(a), _data_points(b)
    if da is None or db is None or da[0] != db[0] or da[1].shape != db[1].shape:
        return None, None
    d = point_distances(np.asarray(da[1]), np.asarray(db[1]))  # as fair()'s report
    if d.size == 0:
        return None, None
    k = int(np.argmax(d))
    return float(d[k]), k


def _on_breaks(curve: PiecewiseCurve, starts: FloatArray, mids: FloatArray, q: int
               ) -> FloatArray:
    """Power coefficients of ``curve`` re-expanded about ``starts`` (one per merged piece)."""
    pp = curve.piecewise
    seg = pp.segment_of(mids)
    c = np.asarray(pp.coeffs)[seg]
    delta = starts - pp.breaks[seg]
    if np.any(delta != 0.0):
        c = taylor_shift(c, delta)
    if c.shape[1] < q:
        c = np.concatenate([c, np.zeros((c.shape[0], q - c.shape[1], c.shape[2]))], axis=1)
    return c


def _de_casteljau_split(b: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Split Bernstein control points ``(k, q, dim)`` at 1/2: left and right halves."""
    q = b.shape[1]
    left = np.empty_like(b)
    right = np.empty_like(b)
    cur = b.copy()
    left[:, 0] = cur[:, 0]
    right[:, q - 1] = cur[:, q - 1]
    for r in range(1, q):
        cur = 0.5 * (cur[:, :-1] + cur[:, 1:])
        left[:, r] = cur[:, 0]
        right[:, q - 1 - r] = cur[:, -1]
    return left, right


def _norms(b: FloatArray) -> FloatArray:
    return np.sqrt(np.sum(b * b, axis=-1))


def _search(U: FloatArray, best: float, best_t: float, rows: Any,
            starts: FloatArray, ends: FloatArray, atol: float) -> tuple[float, float, float]:
    """The branch-and-bound of :func:`deviation` after its first pass: ``U`` the pieces'
    Bernstein bounds, ``best`` the largest sample (at ``best_t``), ``rows(sel)`` the power
    coefficients of the pieces ``sel`` (the few whose bound exceeds the best sample),
    ``starts``, ``ends`` the pieces' ends, ``atol`` the absolute part of the search's
    tolerance. Returns ``(max_distance, upper_bound, param)``, the parameter not yet clamped
    to the domain."""

    def tol() -> float:
        return DEVIATION_RTOL * best + atol

    # the pieces to search and the largest bound of the others (0.0 counts when some are
    # searched, as in max(where(U > thr, 0, U))), in one compiled pass over U
    sel = np.empty(U.shape[0], dtype=np.int64)  # (pages never written are never mapped)
    k, ub = _k.split_bounds(U, best + tol(), sel)
    sel = sel[:k]
    ub = float(ub)
    cb, lo, hi = to_bernstein(rows(sel), ends[sel] - starts[sel]), starts[sel], ends[sel]
    levels = _MAX_LEVELS
    cap = max(_MAX_CANDIDATES, U.shape[0] // _CANDIDATE_SHARE)
    if cb.shape[0]:
        cb, lo, hi, best, best_t, ub, done = _k.branch_and_bound(
            np.ascontiguousarray(cb, dtype=np.float64), np.ascontiguousarray(lo, dtype=np.float64),
            np.ascontiguousarray(hi, dtype=np.float64), float(best), float(best_t), float(ub),
            DEVIATION_RTOL, float(atol), _MAX_LEVELS, cap)
        best, best_t, ub = float(best), float(best_t), float(ub)
        levels -= int(done)
    for _ in range(levels):  # only when more than cap pieces are left
        if cb.shape[0] == 0:
            break
        if cb.shape[0] > cap:
            order = np.argsort(-np.max(_norms(cb), axis=1))
            drop = order[cap:]
            ub = max(ub, float(np.max(_norms(cb[drop]))))
            keep = order[:cap]
            cb, lo, hi = cb[keep], lo[keep], hi[keep]
        left, right = _de_casteljau_split(cb)
        mid = 0.5 * (lo + hi)
        cb = np.concatenate([left, right])
        lo, hi = np.concatenate([lo, mid]), np.concatenate([mid, hi])
        # sample each child's midpoint (de Casteljau at 1/2 = first point of the right half)
        _, rr = _de_casteljau_split(cb)
        sv = _norms(rr[:, 0])
        kk = int(np.argmax(sv))
        if sv[kk] > best:
            best = float(sv[kk])
            best_t = float(0.5 * (lo[kk] + hi[kk]))
        ends_v = _norms(left[:, -1])
        kk = int(np.argmax(ends_v))
        if ends_v[kk] > best:
            best = float(ends_v[kk])
            best_t = float(hi[kk])  # the split point: the end of left child kk
        Uc = np.max(_norms(cb), axis=1)
        sel = Uc > best + tol()
        if np.any(~sel):
            ub = max(ub, float(np.max(Uc[~sel])))
        cb, lo, hi = cb[sel], lo[sel], hi[sel]
    if cb.shape[0]:
        ub = max(ub, float(np.max(_norms(cb))))
    ub = max(ub, best)
    return best, best_t, ub


def hermite_delta_deviation(curve: Any, points: FloatArray, derivs: tuple[FloatArray, ...]
                            ) -> tuple[float, float, float] | None:
    """``(max_distance, upper_bound, param)`` of ``max_t |b(t) - a(t)|``, ``a = curve`` a
    :class:`~curvefair.CubicHermite` or :class:`~curvefair.QuinticHermite` and ``b`` the curve
    with ``a``'s parameters and the data ``points``, ``derivs`` (the tangents; or the first
    and second derivatives), all ``(n, dim)``; for a closed ``a`` they may hold the distinct
    rows only (the seam's row is then row 0's).

    The figures are those of :func:`deviation` on the difference curve (the power form of the
    data's differences against the zero curve: exactly linear in them, no rounding of the
    coordinates' offset), bit for bit, but the difference curve's power form is never built:
    one compiled pass forms each piece's coefficients, bounds it (Bernstein hull) and samples
    it (:func:`curvefair._kernels.deviation.hermite_delta_pass`), and only the pieces left to
    the branch-and-bound are formed again. A certificate of a long curve then costs one read
    of the two curves' data, not a form of ``q (n - 1) dim`` numbers and its copies (at 1e7
    planar cubic points: 640 MB of fresh memory per certificate, several per fair() call).

    Returns None when a coefficient is not finite (the caller then measures the usual way,
    which reports it)."""
    from ..curves.hermite import QuinticHermite

    quintic = isinstance(curve, QuinticHermite)
    pa = np.ascontiguousarray(curve.points, dtype=np.float64)
    da = [np.ascontiguousarray(x, dtype=np.float64) for x in curve._derivs]
    pb = np.asarray(points, dtype=np.float64)
    db = [np.asarray(x, dtype=np.float64) for x in derivs]
    if len(db) != len(da) or pb.ndim != 2 or pb.shape[1] != pa.shape[1] \
            or pb.shape[0] not in ((pa.shape[0] - 1, pa.shape[0]) if curve.closed
                                   else (pa.shape[0],)) \
            or any(x.shape != pb.shape for x in db):
        raise InputError("hermite_delta_deviation: points and derivs must be (n, dim) rows of "
                         f"the curve's {pa.shape[0]} x {pa.shape[1]} data")
    t = np.ascontiguousarray(curve.params, dtype=np.float64)
    sa, sb = (da[1], db[1]) if quintic else (da[0], db[0])
    q = 6 if quintic else 4
    M = bernstein_matrix(q - 1)

    def run(U: FloatArray, lo: int, hi: int) -> tuple[float, int, float, float, bool]:
        return _k.hermite_delta_pass(pa, da[0], sa, pb, db[0], sb, t, quintic, M, U, lo, hi)

    def rows(sel: np.ndarray) -> FloatArray:
        out = np.empty((sel.shape[0], q, pa.shape[1]))
        _k.hermite_delta_rows(pa, da[0], sa, pb, db[0], sb, t, quintic,
                              np.ascontiguousarray(sel, dtype=np.int64), out)
        return out

    return _delta_figures(run, rows, t)


def bspline_delta_deviation(curve: Any, control_points: FloatArray
                            ) -> tuple[float, float, float] | None:
    """``(max_distance, upper_bound, param)`` of ``max_t |b(t) - a(t)|``, ``a = curve`` a
    :class:`~curvefair.BSplineCurve` and ``b`` the B-spline with ``a``'s knots, degree and
    closedness and the control points ``control_points`` (``a``'s shape): the figures of
    :func:`deviation` on the difference curve (the power form of the control points'
    differences against the zero curve), bit for bit, without that form, as
    :func:`hermite_delta_deviation` does for Hermite splines
    (:func:`curvefair._kernels.deviation.bspline_delta_pass`). None when a coefficient is not
    finite."""
    ca = np.ascontiguousarray(curve.control_points, dtype=np.float64)
    cb = np.asarray(control_points, dtype=np.float64)
    if cb.shape != ca.shape:
        raise InputError("bspline_delta_deviation: control_points must have the curve's shape "
                         f"{ca.shape}, got {cb.shape}")
    p = int(curve.degree)
    knots = np.ascontiguousarray(curve.knots, dtype=np.float64)
    spans = np.ascontiguousarray(curve.spans, dtype=np.int64)
    breaks = np.ascontiguousarray(curve.span_breaks, dtype=np.float64)
    closed = bool(curve.closed)
    M = bernstein_matrix(p)

    def run(U: FloatArray, lo: int, hi: int) -> tuple[float, int, float, float, bool]:
        return _k.bspline_delta_pass(knots, p, spans, cb, ca, closed, breaks, M, U, lo, hi)

    def rows(sel: np.ndarray) -> FloatArray:
        out = np.empty((sel.shape[0], p + 1, ca.shape[1]))
        _k.bspline_delta_rows(knots, p, spans, cb, ca, closed,
                              np.ascontiguousarray(sel, dtype=np.int64), out)
        return out

    return _delta_figures(run, rows, breaks)


def _delta_figures(run: Any, rows: Any, breaks: FloatArray) -> tuple[float, float, float] | None:
    """The piece passes ``run(U, lo, hi)`` over ranges on two threads, combined in curve order
    as one pass compares its pieces (on the squared samples), then :func:`_search`; None if a
    coefficient was not finite."""
    m = breaks.shape[0] - 1
    U = np.empty(m)
    best_sq, i, f, scale, finite = -1.0, 0, 0.0, 0.0, True
    for r_best, r_i, r_f, r_scale, r_finite in _threads.ranges(
            lambda lo, hi: run(U, lo, hi), 0, m, _threads.THREADS, _PAR_MIN):
        if r_best > best_sq:
            best_sq, i, f = r_best, r_i, r_f
        scale = max(scale, r_scale)
        finite = finite and r_finite
    if not finite:
        return None
    best = math.sqrt(max(best_sq, 0.0))
    starts, ends = breaks[:-1], breaks[1:]
    best, best_t, ub = _search(U, best, float(starts[i] + f * (ends[i] - starts[i])), rows,
                               starts, ends, 1e-13 * max(float(scale), np.finfo(float).tiny))
    return best, ub, min(max(best_t, float(breaks[0])), float(breaks[-1]))


def deviation(curve_a: object, curve_b: object,
              kind: Literal["auto", "parametric", "geometric"] = "auto", *,
              spans: ArrayLike | None = None) -> Deviation:
    """Maximum distance between two curves: ``max_t |a(t) - b(t)|``, or geometric.

    Parameters
    ----------
    curve_a, curve_b : PiecewiseCurve
        Same dimension. For the parametric distance, the same parameter domain (to ``1e-12``
        of its length), e.g. a curve and its faired version; their breakpoints may differ.
    kind : {"auto", "parametric", "geometric"}
        ``"parametric"``: ``max_t |a(t) - b(t)|`` at equal parameters (certified; the quantity
        a fairing tolerance bounds). ``"geometric"``: the Hausdorff distance
        ``max(h(a, b), h(b, a))``, ``h(a, b) = max_t min_s |a(t) - b(s)|``, which needs no
        common parametrisation (two files read back, a curve re-interpolated through moved
        points). ``"auto"`` (default): parametric when the domains agree, else geometric.
    spans : array_like of int, optional
        Geometric distance only: measure only the points of these polynomial pieces
        (0-based, each curve's own pieces; for two curves through the same number of points,
        the spans between the same data points), each against the whole other curve: the
        Hausdorff distance restricted to them. What a per-span bound such as
        :func:`matched_hermite_bound` leaves to refine, at the cost of those pieces only.

    Returns
    -------
    Deviation

    Raises
    ------
    InputError
        Not curves, different dimensions, different domains with ``kind="parametric"``.

    Notes
    -----
    Parametric. The breakpoints of both curves are merged; on every merged piece
    ``d(t) = a(t) - b(t)`` is one polynomial, which is written in Bernstein form (control
    points ``b_i``). By the
    convex-hull property ``|d(t)| <= max_i |b_i|`` on the piece, and ``b_0``, ``b_q`` are
    the exact end values. The search is a branch-and-bound: pieces are sampled (ends and
    quarter points); pieces whose bound does not exceed the best sample by more than the
    tolerance are discarded, the others are halved (de Casteljau) until none is left.

    Accuracy guarantee: ``max_distance <= true max <= upper_bound`` and
    ``upper_bound - max_distance <= 1e-12 max_distance + 1e-13 S``, ``S`` the largest absolute
    coordinate of either curve (the rounding level of the difference), unless the search
    stopped at its size cap (then the gap is still certified by ``upper_bound``). This is the
    lecture notes' deviation bound (004, eqs. (8.34)-(8.36)) made sharp: the control-point
    bound ``max_i |R_i - Q_i|`` is :attr:`Deviation.max_point_displacement` for B-splines on
    equal knots.

    Geometric (not certified): dense sampling and local optimisation. Each curve is sampled
    at 16 parameters per polynomial piece at least, and at most 1/2048 of its length apart.
    For every sample of one curve the 2 nearest samples of the other (k-d tree; 4 in the
    refinement) each start a safeguarded Newton iteration on ``g(s) = (c(s) - x) . c'(s) = 0``
    within the two neighbouring sample intervals; the smallest distance found is the distance
    to the nearest point. The largest sampled distances are then refined by golden-section
    maximisation over the neighbouring intervals. Both steps converge to rounding level where
    the distance function is smooth; the figure can be too small only if the largest distance
    lies between samples away from the refined ones, and too large only if a nearest point
    lies on a stretch of the other curve that none of the nearest samples leads to. Tests
    compare it with scipy (dense k-d tree, bounded Brent minimisation and maximisation).

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import interpolate_cubic, deviation
    >>> p = np.c_[np.arange(7.0), np.ones(7)]
    >>> a = interpolate_cubic(p)
    >>> q = p.copy(); q[3, 1] += 0.5
    >>> d = deviation(a, interpolate_cubic(q, param=a.params))
    >>> round(d.max_distance, 6), d.point_index
    (0.5, 3)
    """
    a = check_curve(curve_a, "curve_a")
    b = check_curve(curve_b, "curve_b")
    if kind not in ("auto", "parametric", "geometric"):
        raise InputError(f"kind must be 'auto', 'parametric' or 'geometric', got {kind!r}")
    if spans is not None:
        if kind != "geometric":
            raise InputError("spans is for kind='geometric' (the parametric search already "
                             "visits only the pieces that can hold the maximum)")
        sel = np.unique(np.asarray(spans, dtype=np.int64).reshape(-1))
        n_min = min(a.piecewise.n_segments, b.piecewise.n_segments)
        if sel.size and (sel[0] < 0 or sel[-1] >= n_min):
            raise InputError(f"spans must be piece indices 0 .. {n_min - 1} of both curves, "
                             f"got {int(sel[0] if sel[0] < 0 else sel[-1])}")
        if a.dim != b.dim:
            raise InputError(f"curve_a is {a.dim}-D but curve_b is {b.dim}-D")
        return _geometric(a, b, sel)
    if a.dim != b.dim:
        raise InputError(f"curve_a is {a.dim}-D but curve_b is {b.dim}-D")
    (a0, a1), (b0, b1) = a.domain, b.domain
    span = max(a1 - a0, b1 - b0)
    tol_t = 1e-12 * max(span, abs(a0), abs(a1))
    same = abs(a0 - b0) <= tol_t and abs(a1 - b1) <= tol_t
    if kind == "geometric" or (kind == "auto" and not same):
        return _geometric(a, b)
    if not same:
        raise InputError(f"curve_a's domain [{a0!r}, {a1!r}] differs from curve_b's domain "
                         f"[{b0!r}, {b1!r}]; the parametric deviation compares a(t) and b(t) "
                         "at equal t (kind='geometric' measures the distance between the "
                         "curves as point sets)")
    ba, bb = np.asarray(a.piecewise.breaks), np.asarray(b.piecewise.breaks)
    if ba.shape == bb.shape and np.all(np.abs(ba - bb) <= tol_t):
        br = ba
    else:
        u = np.union1d(ba, bb)
        keep = np.concatenate([[True], np.diff(u) > tol_t])
        br = u[keep]
        br[0], br[-1] = a0, a1
        if br.shape[0] < 2:
            br = np.array([a0, a1])
    starts, ends = br[:-1], br[1:]
    q = max(a.piecewise.degree, b.piecewise.degree) + 1
    ca, cb = np.asarray(a.piecewise.coeffs), np.asarray(b.piecewise.coeffs)
    # b the zero curve (one 0.0 broadcast: a difference curve's certificate)
    zero = cb.ndim > 0 and not any(cb.strides) and cb.size > 0 and cb.flat[0] == 0.0
    if br is ba and ca.shape == cb.shape:
        # same breakpoints and degree: no re-expansion; x - 0.0 is x bit for bit (no copy)
        d = ca if zero else ca - cb
    else:
        mids = 0.5 * (starts + ends)
        d = _on_breaks(a, starts, mids, q) - _on_breaks(b, starts, mids, q)
    w = ends - starts
    scale = max(float(np.max(np.abs(ca[:, 0, :]))),
                0.0 if zero else float(np.max(np.abs(cb[:, 0, :]))), np.finfo(float).tiny)

    # every piece: Bernstein bound U and samples at the ends (exact) and quarter points
    U = np.empty(d.shape[0])
    # the kernel only reads d: always as a read-only array (d is the caller's read-only form
    # against the zero curve), so that numba compiles it for one argument type
    d = np.ascontiguousarray(d)
    if d.flags.writeable:
        d = d.view()
        d.flags.writeable = False
    best, i, f = _k.first_pass(d, np.ascontiguousarray(w),
                             bernstein_matrix(q - 1), U)
    best, best_t, ub = _search(U, float(best), float(starts[i] + f * w[i]),
                               lambda sel: d[sel], starts, ends, 1e-13 * scale)
    t = min(max(best_t, a0), a1)
    pa = np.asarray(a(t), dtype=float).reshape(-1)
    pb = np.asarray(b(min(max(t, b0), b1)), dtype=float).reshape(-1)
    mpd, idx = point_displacement(a, b)
    from ..curves.piecewise import readonly

    pa, pb = readonly(pa), readonly(pb)
    return Deviation(max_distance=best, upper_bound=ub, param=t, point_a=pa, point_b=pb,
                     max_point_displacement=mpd, point_index=idx)


# ------------------------------------------------------------------------------------------
# geometric (Hausdorff) distance
# ------------------------------------------------------------------------------------------
_GEO_SAMPLES = 16       # samples per polynomial piece, at least
_GEO_RESOLUTION = 2048  # and at most this fraction of the length apart
_GEO_MAX_PER_PIECE = 8192
_GEO_NEIGHBOURS = 4     # nearest samples each refined by Newton (refinement)
_GEO_DENSE_NEIGHBOURS = 2  # the same for every sample (first pass)
_GEO_NEWTON = 8         # Newton (or bisection) iterations for the nearest point
_GEO_REFINE = 8         # largest sampled distances refined by golden-section search
_GEO_GOLDEN = 30        # golden-section iterations (bracket shrinks by 0.618 each)


def _dense_params(c: PiecewiseCurve) -> FloatArray:
    """Sample parameters: every piece at least ``_GEO_SAMPLES`` times and no two samples
    farther apart than ``1/_GEO_RESOLUTION`` of the curve's length (long straight pieces next
    to short curved ones are sampled as finely as the rest)."""
    br = np.asarray(c.piecewise.breaks, dtype=float)
    f8 = np.linspace(0.0, 1.0, 9)
    u8 = br[:-1, None] + np.diff(br)[:, None] * f8[None, :]
    r8 = np.asarray(c(u8.reshape(-1)), dtype=float).reshape(u8.shape[0], 9, -1)
    seg_len = np.sum(np.linalg.norm(np.diff(r8, axis=1), axis=2), axis=1)
    total = float(seg_len.sum())
    h = total / _GEO_RESOLUTION if total > 0 else 1.0
    with np.errstate(invalid="ignore", divide="ignore"):
        k = np.ceil(np.nan_to_num(seg_len / h, nan=0.0, posinf=0.0))
    k = np.clip(k, _GEO_SAMPLES, _GEO_MAX_PER_PIECE).astype(int)
    parts = [br[i] + (br[i + 1] - br[i]) * np.arange(k[i]) / k[i] for i in range(k.shape[0])]
    return np.r_[np.concatenate(parts), br[-1]]


_FACTORIALS: dict[int, FloatArray] = {}


def _falling_factorials(p1: int) -> FloatArray:
    """``f[nu, k] = k! / (k - nu)!`` for ``nu`` 0-2 and ``k < p1`` (0 where ``k < nu``): the
    factors of ``derivative_coefficients``, made once per degree."""
    f = _FACTORIALS.get(p1)
    if f is None:
        from math import factorial

        f = np.zeros((3, p1))
        for nu in range(3):
            for k in range(nu, p1):
                f[nu, k] = float(factorial(k) // factorial(k - nu))
        f.setflags(write=False)
        _FACTORIALS[p1] = f
    return f


def _at(c: PiecewiseCurve, t: FloatArray) -> FloatArray:
    """``c(t)`` bit for bit, shape ``(len(t), dim)``, for parameters ``t`` in the curve's
    domain (taken as ``__call__`` takes them, :meth:`PiecewiseCurve._in_domain`): the power
    form evaluated by :func:`curvefair._kernels.deviation.power_values`, or by the curve
    itself when it has its own evaluator."""
    pp = c.piecewise
    t = np.asarray(t, dtype=np.float64).reshape(-1)
    if pp.evaluator is not None:
        return np.asarray(c(t), dtype=float).reshape(t.shape[0], -1)
    u = c._in_domain(t)
    out = np.empty((u.shape[0], pp.coeffs.shape[2]))
    _k.power_values(pp.breaks, pp.coeffs, _falling_factorials(pp.coeffs.shape[1]),
                    np.ascontiguousarray(u), out)
    return out


class _Nearest:
    """Nearest point of a curve to query points: dense samples + safeguarded Newton."""

    def __init__(self, c: PiecewiseCurve) -> None:
        from scipy.spatial import cKDTree

        self.c = c
        self.u = _dense_params(c)
        self.tree = cKDTree(np.asarray(c(self.u), dtype=float))

    def __call__(self, x: FloatArray, k: int = _GEO_NEIGHBOURS
                 ) -> tuple[FloatArray, FloatArray]:
        """Distances and parameters of the nearest points to ``x`` (shape ``(m, dim)``),
        trying the ``k`` nearest samples."""
        k = min(k, self.u.shape[0])
        m = x.shape[0]
        d0, jj = self.tree.query(x, k=k)
        d0 = np.asarray(d0, dtype=float).reshape(m, k)
        jj = np.asarray(jj).reshape(m, k)
        d, sv = self._newton(np.repeat(x, k, axis=0), jj.reshape(-1), d0.reshape(-1))
        d, sv = d.reshape(m, k), sv.reshape(m, k)
        c = np.argmin(d, axis=1)
        rows = np.arange(m)
        return d[rows, c], sv[rows, c]

    def _newton(self, x: FloatArray, j: np.ndarray, d0: FloatArray
                ) -> tuple[FloatArray, FloatArray]:
        """Safeguarded Newton from the samples ``u[j]`` (:func:`curvefair._kernels.deviation.
        nearest_newton`, compiled: the geometric distance calls this some 70 times per curve
        pair, on a few rows each for a short curve); a curve evaluated by its own
        representation (:attr:`PiecewisePolynomial.evaluator`) takes :meth:`_newton_numpy`."""
        pp = self.c.piecewise
        if pp.evaluator is not None:
            return self._newton_numpy(x, j, d0)
        best_d = np.empty(x.shape[0])
        best_s = np.empty(x.shape[0])
        p1 = pp.coeffs.shape[1]
        _k.nearest_newton(pp.breaks, pp.coeffs, _falling_factorials(p1), self.u,
                          np.ascontiguousarray(x, dtype=np.float64),
                          np.ascontiguousarray(j, dtype=np.int64),
                          np.ascontiguousarray(d0, dtype=np.float64), _GEO_NEWTON, best_d,
                          best_s)
        return best_d, best_s

    def _newton_numpy(self, x: FloatArray, j: np.ndarray, d0: FloatArray
                      ) -> tuple[FloatArray, FloatArray]:
        """:meth:`_newton` in numpy (whole arrays a step; the reference of the kernel)."""
        pp = self.c.piecewise
        u = self.u
        lo = u[np.maximum(j - 1, 0)]
        hi = u[np.minimum(j + 1, u.shape[0] - 1)]
        s = u[j].copy()
        best_d = d0.copy()
        best_s = s.copy()
        for _ in range(_GEO_NEWTON):
            r = pp.evaluate(s) - x
            d1 = pp.evaluate(s, 1)
            d2 = pp.evaluate(s, 2)
            g = np.einsum("ij,ij->i", r, d1)
            h = np.einsum("ij,ij->i", d1, d1) + np.einsum("ij,ij->i", r, d2)
            step = np.where(h > 0, g / np.where(h > 0, h, 1.0), 0.0)
            new = s - step
            # g > 0: the distance decreases towards smaller s (the minimum is in [lo, s])
            lo = np.where(g > 0, lo, s)
            hi = np.where(g > 0, s, hi)
            # outside the bracket or a non-convex point: bisect the bracket
            bad = (h <= 0) | (new < lo) | (new > hi) | ~np.isfinite(new)
            new = np.where(bad, 0.5 * (lo + hi), new)
            s = new
            dist = np.linalg.norm(pp.evaluate(s) - x, axis=1)
            better = dist < best_d
            best_d = np.where(better, dist, best_d)
            best_s = np.where(better, s, best_s)
        return best_d, best_s


def _directed(a: PiecewiseCurve, near_b: _Nearest, spans: np.ndarray | None = None
              ) -> tuple[float, float, float]:
    """``h(a, b) = max_t min_s |a(t) - b(s)|``: value, ``t`` on ``a``, ``s`` on ``b``; with
    ``spans`` (sorted piece indices of ``a``), ``t`` only on those pieces (the same samples as
    for the whole curve, with the pieces' ends). ``-1`` when no sample is left."""
    ua = _dense_params(a)
    lo_run = hi_run = None
    if spans is not None:
        # the samples on the chosen pieces, each piece with both ends; runs of consecutive
        # chosen pieces bound the refinement (it never looks at a piece not chosen)
        br = np.asarray(a.piecewise.breaks, dtype=float)
        chosen = np.zeros(br.shape[0] - 1, dtype=bool)
        chosen[spans] = True
        edges = np.diff(np.r_[0, chosen.astype(np.int8), 0])
        lo_run, hi_run = br[np.flatnonzero(edges == 1)], br[np.flatnonzero(edges == -1)]
        run = np.searchsorted(hi_run, ua, side="left")
        inside = run < hi_run.shape[0]
        inside[inside] = ua[inside] >= lo_run[run[inside]]
        full, idx = ua, np.flatnonzero(inside)
        ua = full[idx]
        if ua.shape[0] == 0:
            return -1.0, float(br[0]), float(near_b.u[0])
    da, sb = near_b(np.asarray(a(ua), dtype=float), _GEO_DENSE_NEIGHBOURS)
    best, bt, bs = -1.0, float(ua[0]), float(sb[0])
    # refine the largest local maxima of the sampled distance
    if lo_run is None:
        interior = np.r_[True, da[1:] >= da[:-1]] & np.r_[da[:-1] >= da[1:], True]
    else:  # a run's first and last samples have no neighbour in the other runs
        step = np.diff(idx) == 1
        interior = (np.r_[True, (da[1:] >= da[:-1]) | ~step]
                    & np.r_[(da[:-1] >= da[1:]) | ~step, True])
    cand = np.flatnonzero(interior)
    cand = cand[np.argsort(-da[cand], kind="stable")][:_GEO_REFINE]
    if lo_run is None or hi_run is None:
        lo = ua[np.maximum(cand - 1, 0)]
        hi = ua[np.minimum(cand + 1, ua.shape[0] - 1)]
    else:  # the neighbouring samples of the whole curve, within the candidate's run
        r = np.searchsorted(hi_run, ua[cand], side="left")
        lo = np.maximum(full[np.maximum(idx[cand] - 1, 0)], lo_run[r])
        hi = np.minimum(full[np.minimum(idx[cand] + 1, full.shape[0] - 1)], hi_run[r])
    g = (math.sqrt(5.0) - 1.0) / 2.0

    def dist(t: FloatArray) -> tuple[FloatArray, FloatArray]:
        return near_b(_at(a, t))

    x1 = hi - g * (hi - lo)
    x2 = lo + g * (hi - lo)
    f1, s1 = dist(x1)
    f2, s2 = dist(x2)
    f0, s0 = dist(ua[cand])  # the samples themselves, with every neighbour tried
    seen = [(f0, ua[cand], s0), (f1, x1, s1), (f2, x2, s2)]
    for _ in range(_GEO_GOLDEN):
        right = f2 > f1  # the maximum lies in [x1, hi]: drop [lo, x1)
        lo = np.where(right, x1, lo)
        hi = np.where(right, hi, x2)
        kx, kf, ks = (np.where(right, x2, x1), np.where(right, f2, f1),
                      np.where(right, s2, s1))
        nx = np.where(right, lo + g * (hi - lo), hi - g * (hi - lo))
        fn, sn = dist(nx)
        seen.append((fn, nx, sn))
        x1, f1, s1 = (np.where(right, kx, nx), np.where(right, kf, fn),
                      np.where(right, ks, sn))
        x2, f2, s2 = (np.where(right, nx, kx), np.where(right, fn, kf),
                      np.where(right, sn, ks))
        if not float(np.max(hi - lo)) > 0.0:
            break
    for f, t, sv in seen:
        k = int(np.argmax(f))
        if float(f[k]) > best:
            best, bt, bs = float(f[k]), float(t[k]), float(sv[k])
    return best, bt, bs


def geometric_upper_bound(curve_a: PiecewiseCurve, curve_b: PiecewiseCurve) -> float:
    """An upper bound of the Hausdorff distance between two curves, from one dense pass.

    Every distance computed from a sample ``x_i`` of one curve is the distance to an actual
    point of the other, so it bounds ``dist(x_i, other)`` from above; the distance to a
    curve changes by at most the arc length moved, so on the arc between samples ``x_i`` and
    ``x_{i+1}`` (arc length ``l_i``, taken as 1.01 times the chord: samples are at most 1/2048
    of the length apart, at least 16 per polynomial piece)
    ``dist <= (d_i + d_{i+1} + l_i) / 2``. The bound is the largest of these, both ways. It
    is cheap (no refinement) and within about half a sample gap of the true distance.
    """
    out = 0.0
    for x_curve, y_curve in ((curve_a, curve_b), (curve_b, curve_a)):
        u = _dense_params(x_curve)
        X = np.asarray(x_curve(u), dtype=float)
        d, _ = _Nearest(y_curve)(X, _GEO_DENSE_NEIGHBOURS)
        arc = 1.01 * np.linalg.norm(np.diff(X, axis=0), axis=1)
        out = max(out, float(np.max(0.5 * (d[:-1] + d[1:] + arc))) if arc.size else
                  float(np.max(d)))
    return out


def matched_hermite_bound(a: Any, b: Any, pieces: int = 4) -> FloatArray:
    """Per span, an upper bound of the Hausdorff distance of two cubic Hermite curves through
    the same number of points.

    Parameters
    ----------
    a, b : CubicHermite
        Two curves with as many points (and parameters) each; their parameters may differ
        (e.g. the chord lengths of moved points).
    pieces : int
        Sub-pieces per span bounded separately (more: a tighter bound).

    Returns
    -------
    ndarray, shape (n_spans,)
        ``max_t |b(t) - a(psi(t))|`` on each span, ``psi`` the piecewise-linear map of ``b``'s
        parameters onto ``a``'s (point ``i`` to point ``i``): every point of either curve has
        a point of the other within that distance, so the largest entry bounds the Hausdorff
        distance. On each span ``a o psi - b`` is one cubic (Hermite data: the point
        differences and the tangents, ``a``'s scaled by the span ratio); each sub-piece is
        bounded by the norms of its Bernstein control points (convex hull property), up to
        rounding of the coordinates (the result is enlarged by ``1e-12`` relative). O(n):
        what the read-back check of a written point file uses before any sampling.
    """
    ua, ub = (np.ascontiguousarray(c.params, dtype=float) for c in (a, b))
    pa, pb = (np.ascontiguousarray(c.points, dtype=float) for c in (a, b))
    ta, tb = (np.ascontiguousarray(c.tangents, dtype=float) for c in (a, b))
    out = np.empty(max(len(ua) - 1, 0))
    q = int(pieces)
    # span ranges on two threads (each span's bound on its own: the same bits)
    _threads.ranges(lambda lo, hi: _k.matched_bound_kernel(
        ua[lo:hi + 1], ub[lo:hi + 1], pa[lo:hi + 1], pb[lo:hi + 1], ta[lo:hi + 1],
        tb[lo:hi + 1], q, _k.TO_BERNSTEIN, out[lo:hi]), 0, out.shape[0], _threads.THREADS,
        _PAR_MIN)
    return out


def _geometric(a: PiecewiseCurve, b: PiecewiseCurve, spans: np.ndarray | None = None
               ) -> Deviation:
    hab, ta, sb = _directed(a, _Nearest(b), spans)
    hba, tb, sa = _directed(b, _Nearest(a), spans)
    if hab >= hba:
        best, t, pa, pb = hab, ta, a(ta), b(sb)
    else:
        best, t, pa, pb = hba, sa, a(sa), b(tb)
    pa = np.asarray(pa, dtype=float).reshape(-1)
    pb = np.asarray(pb, dtype=float).reshape(-1)
    pa.setflags(write=False)
    pb.setflags(write=False)
    mpd, idx = point_displacement(a, b)
    # (max with 0: no sample at all, ``spans`` empty)
    return Deviation(max_distance=max(float(best), 0.0), upper_bound=None, param=float(t),
                     point_a=pa,
                     point_b=pb, max_point_displacement=mpd, point_index=idx, kind="geometric")
