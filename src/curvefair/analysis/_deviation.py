"""Maximum distance between two curves over a common parameter range."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numba import njit

from .._distance import point_distances
from .._typing import FloatArray
from ..curves.piecewise import PiecewiseCurve
from ..errors import InputError
from ._core import bernstein_matrix, check_curve, fields_to_dict, taylor_shift, to_bernstein

__all__ = ["Deviation", "deviation", "DEVIATION_RTOL"]

#: Relative accuracy of :attr:`Deviation.max_distance` (see :func:`deviation`).
DEVIATION_RTOL = 1e-12
_MAX_LEVELS = 64
_MAX_CANDIDATES = 1 << 18


@dataclass(frozen=True, eq=False)
class Deviation:
    """Result of :func:`deviation`.

    Attributes
    ----------
    max_distance : float
        ``max_t |a(t) - b(t)|`` over the common domain (a lower bound attained at
        :attr:`param`, within the accuracy stated in :func:`deviation`).
    upper_bound : float
        Certified upper bound of the true maximum (Bernstein convex-hull bound);
        ``max_distance <= true max <= upper_bound`` up to rounding.
    param : float
        Parameter where the maximum is attained.
    point_a, point_b : ndarray, shape (dim,)
        ``a(param)`` and ``b(param)``.
    max_point_displacement : float or None
        ``max_i |P_i^a - P_i^b|`` over the data points (``points`` of Hermite curves,
        ``control_points`` of B-splines) when both curves have the same kind and number of
        them; else None.
    point_index : int or None
        Index of that data point (0-based).
    """

    max_distance: float
    upper_bound: float
    param: float
    point_a: FloatArray
    point_b: FloatArray
    max_point_displacement: float | None
    point_index: int | None

    def to_dict(self) -> dict[str, Any]:
        """A JSON-serialisable dict of plain floats, ints, lists and None."""
        return fields_to_dict(self)


def _data_points(curve: PiecewiseCurve) -> tuple[str, FloatArray] | None:
    for name in ("control_points", "points"):
        v = getattr(curve, name, None)
        if isinstance(v, np.ndarray):
            return name, v
    return None


def _point_displacement(a: PiecewiseCurve, b: PiecewiseCurve
                        ) -> tuple[float | None, int | None]:
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


@njit(cache=True, error_model="numpy")
def _first_pass(d, w, M, U):  # type: ignore[no-untyped-def]
    """Per piece: ``U[i]`` = max norm of the Bernstein control points of ``d`` on piece ``i``
    (``M`` maps scaled power coefficients to Bernstein ones); returns the largest sampled
    ``|d|`` (ends and quarter points), its piece and fraction."""
    m, q, dim = d.shape
    ds = np.empty((q, dim))
    best = -1.0
    bi = 0
    bf = 0.0
    fr = np.array([0.0, 0.25, 0.5, 0.75, 1.0])
    for i in range(m):
        hp = 1.0
        for j in range(q):
            for c in range(dim):
                ds[j, c] = d[i, j, c] * hp
            hp *= w[i]
        u = 0.0
        for r in range(q):
            nn = 0.0
            for c in range(dim):
                acc = 0.0
                for k in range(r + 1):
                    acc += M[r, k] * ds[k, c]
                nn += acc * acc
            if nn > u:
                u = nn
        U[i] = np.sqrt(u)
        for t in range(5):
            f = fr[t]
            nn = 0.0
            for c in range(dim):
                acc = 0.0
                for j in range(q - 1, -1, -1):
                    acc = acc * f + ds[j, c]
                nn += acc * acc
            if nn > best:
                best = nn
                bi = i
                bf = f
    return np.sqrt(max(best, 0.0)), bi, bf


def _norms(b: FloatArray) -> FloatArray:
    return np.sqrt(np.sum(b * b, axis=-1))


def deviation(curve_a: object, curve_b: object) -> Deviation:
    """Maximum distance ``max_t |a(t) - b(t)|`` between two curves with the same domain.

    Parameters
    ----------
    curve_a, curve_b : PiecewiseCurve
        Same dimension and the same parameter domain (to ``1e-12`` of its length), e.g. a
        curve and its faired version. Their breakpoints may differ.

    Returns
    -------
    Deviation

    Raises
    ------
    InputError
        Not curves, different dimensions or different domains.

    Notes
    -----
    The breakpoints of both curves are merged; on every merged piece ``d(t) = a(t) - b(t)`` is
    one polynomial, which is written in Bernstein form (control points ``b_i``). By the
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
    if a.dim != b.dim:
        raise InputError(f"curve_a is {a.dim}-D but curve_b is {b.dim}-D")
    (a0, a1), (b0, b1) = a.domain, b.domain
    span = max(a1 - a0, b1 - b0)
    tol_t = 1e-12 * max(span, abs(a0), abs(a1))
    if abs(a0 - b0) > tol_t or abs(a1 - b1) > tol_t:
        raise InputError(f"curve_a's domain [{a0!r}, {a1!r}] differs from curve_b's domain "
                         f"[{b0!r}, {b1!r}]; deviation compares a(t) and b(t) at equal t")
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
    if br is ba and ca.shape == cb.shape:
        d = ca - cb  # same breakpoints and degree: no re-expansion
    else:
        mids = 0.5 * (starts + ends)
        d = _on_breaks(a, starts, mids, q) - _on_breaks(b, starts, mids, q)
    w = ends - starts
    scale = max(float(np.max(np.abs(ca[:, 0, :]))), float(np.max(np.abs(cb[:, 0, :]))),
                np.finfo(float).tiny)
    atol = 1e-13 * scale

    # every piece: Bernstein bound U and samples at the ends (exact) and quarter points
    U = np.empty(d.shape[0])
    best, i, f = _first_pass(np.ascontiguousarray(d), np.ascontiguousarray(w),
                             bernstein_matrix(q - 1), U)
    best_t = float(starts[i] + f * w[i])

    def tol() -> float:
        return DEVIATION_RTOL * best + atol

    sel = np.flatnonzero(U > best + tol())
    ub = float(np.max(U)) if sel.size == 0 else float(np.max(np.where(U > best + tol(), 0.0, U)))
    cb, lo, hi = to_bernstein(d[sel], w[sel]), starts[sel], ends[sel]
    for _ in range(_MAX_LEVELS):
        if cb.shape[0] == 0:
            break
        if cb.shape[0] > _MAX_CANDIDATES:
            order = np.argsort(-np.max(_norms(cb), axis=1))
            drop = order[_MAX_CANDIDATES:]
            ub = max(ub, float(np.max(_norms(cb[drop]))))
            keep = order[:_MAX_CANDIDATES]
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
    t = min(max(best_t, a0), a1)
    pa = np.asarray(a(t), dtype=float).reshape(-1)
    pb = np.asarray(b(min(max(t, b0), b1)), dtype=float).reshape(-1)
    mpd, idx = _point_displacement(a, b)
    pa.setflags(write=False)
    pb.setflags(write=False)
    return Deviation(max_distance=best, upper_bound=ub, param=t, point_a=pa, point_b=pb,
                     max_point_displacement=mpd, point_index=idx)
