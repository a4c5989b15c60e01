"""Compiled kernels of :func:`curvefair.deviation` and
:func:`curvefair.analysis.matched_hermite_bound` (:mod:`curvefair.analysis._deviation`).

:func:`first_pass` bounds every merged piece of the difference curve by its Bernstein control
points and samples it; :func:`hermite_delta_pass` and :func:`bspline_delta_pass` do the same
for the difference of two Hermite splines on the same parameters / two B-splines on the same
knots, forming each piece's power coefficients as they go (the ``*_rows`` kernels form chosen
pieces again), and :func:`split_bounds` picks the pieces left to the search;
:func:`branch_and_bound` runs the halving levels of the parametric search;
:func:`matched_bound_kernel` is the per-span bound of two cubic Hermite curves through
the same number of points, and :func:`matched_hermite_bound_reference` the same bound in numpy,
the plain form the kernel is tested against. :func:`point_distances_kernel` and
:func:`moved_points_kernel` are the per-point moves of :mod:`curvefair._distance` and of
fair()'s point report.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .._jit import njit
from .._typing import FloatArray
from .bspline import _basis_work, _span_basis
from .hermite_power import _cubic_row, _quintic_row

#: values at 0, 1/3, 2/3, 1 -> Bernstein control points of a cubic
TO_BERNSTEIN = np.linalg.inv(np.array([[(1 - x) ** 3, 3 * x * (1 - x) ** 2, 3 * x * x * (1 - x),
                                        x ** 3] for x in (0.0, 1 / 3, 2 / 3, 1.0)]))


_FRACTIONS = np.array([0.0, 0.25, 0.5, 0.75, 1.0])


@njit(cache=True, inline="always")
def _scaled(d, i, wi, ds):  # pragma: no cover - compiled
    """``ds[j] = d[i, j] wi^j``: piece ``i``'s power coefficients on the unit interval."""
    hp = 1.0
    for j in range(ds.shape[0]):
        for c in range(ds.shape[1]):
            ds[j, c] = d[i, j, c] * hp
        hp *= wi


@njit(cache=True, inline="always")
def _piece_first(ds, M, fr):  # pragma: no cover - compiled
    """One piece of :func:`first_pass` from its unit-interval coefficients ``ds``: the
    Bernstein bound ``max_r |sum_k M[r, k] ds[k]|``, the largest squared sample ``|d(f)|^2``
    over ``fr`` (the first one if tied) and its fraction."""
    q, dim = ds.shape
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
    best = -1.0
    bf = 0.0
    for t in range(fr.shape[0]):
        f = fr[t]
        nn = 0.0
        for c in range(dim):
            acc = 0.0
            for j in range(q - 1, -1, -1):
                acc = acc * f + ds[j, c]
            nn += acc * acc
        if nn > best:
            best = nn
            bf = f
    return np.sqrt(u), best, bf


@njit(cache=True, inline="always")
def _row_first(row, wi, M, ds, U, i, best, bi, bf, scale, finite):  # pragma: no cover
    """:func:`_piece_first` of piece ``i``, whose power coefficients are ``row[0]`` (width
    ``wi``), into ``U[i]``; the running state of a pass updated: the largest squared sample
    (the first if tied), its piece and fraction, the rounding scale ``max |c_i0|`` and whether
    every coefficient is finite. Returns the new ``(best, bi, bf, scale, finite)``."""
    for j in range(row.shape[1]):
        for c in range(row.shape[2]):
            if not math.isfinite(row[0, j, c]):
                finite = False
    for c in range(row.shape[2]):
        v = abs(row[0, 0, c])
        if v > scale:
            scale = v
    _scaled(row, 0, wi, ds)
    U[i], nn, f = _piece_first(ds, M, _FRACTIONS)
    if nn > best:
        return nn, i, f, scale, finite
    return best, bi, bf, scale, finite


@njit(cache=True, error_model="numpy")
def first_pass(d, w, M, U):
    """Per piece: ``U[i]`` = max norm of the Bernstein control points of ``d`` on piece ``i``
    (``M`` maps scaled power coefficients to Bernstein ones); returns the largest sampled
    ``|d|`` (ends and quarter points), its piece and fraction."""
    m, q, dim = d.shape
    ds = np.empty((q, dim))
    best = -1.0
    bi = 0
    bf = 0.0
    for i in range(m):
        _scaled(d, i, w[i], ds)
        U[i], nn, f = _piece_first(ds, M, _FRACTIONS)
        if nn > best:
            best = nn
            bi = i
            bf = f
    return np.sqrt(max(best, 0.0)), bi, bf


@njit(cache=True, inline="always")
def _delta_data(pa, ma, sa, pb, mb, sb, t, quintic, i, p2, m2, s2, t2):
    """Piece ``i``'s data of the difference curve ``b - a`` of two Hermite splines on the
    parameters ``t``: rows ``i``, ``i + 1`` of ``pb - pa`` (and of the derivatives) into
    ``p2``, ``m2``, ``s2``, and ``t[i]``, ``t[i + 1]`` into ``t2``. A row of ``b`` past its end
    is read from its start, and so is ``a``'s same row: ``b`` may hold a closed curve's
    distinct data only (the difference at the seam is that of row 0, as
    :func:`curvefair.fairing.hermite_data.full_data` repeats it)."""
    nb = pb.shape[0]
    for k in range(2):
        j = i + k
        if j >= nb:
            j -= nb
        for c in range(pa.shape[1]):
            p2[k, c] = pb[j, c] - pa[j, c]
            m2[k, c] = mb[j, c] - ma[j, c]
            if quintic:
                s2[k, c] = sb[j, c] - sa[j, c]
        t2[k] = t[i + k]


@njit(cache=True, nogil=True, error_model="numpy")
def hermite_delta_pass(pa, ma, sa, pb, mb, sb, t, quintic, M, U, lo, hi):
    """:func:`first_pass` on the pieces ``lo .. hi - 1`` of the difference curve ``b - a`` of
    two cubic (``quintic`` False; ``sa``, ``sb`` unread) or quintic Hermite splines on the
    parameters ``t``, bit for bit as on its whole power form (each piece's coefficients are
    those of :func:`curvefair._kernels.hermite_power.cubic_power_kernel` /
    ``quintic_power_kernel`` on the data's differences, the same inlined row), without that
    form: one piece at a time. Returns the largest squared sample (not its root: ranges are
    compared on it, as one pass compares its pieces), its piece and fraction, ``max |c_i0|``
    over the pieces (the form's largest constant coefficient, the deviation's rounding scale)
    and whether every coefficient was finite. Each range writes only its own ``U[lo:hi]``."""
    dim = pa.shape[1]
    q = 6 if quintic else 4
    p2 = np.empty((2, dim))
    m2 = np.empty((2, dim))
    s2 = np.empty((2, dim))
    t2 = np.empty(2)
    row = np.empty((1, q, dim))
    ds = np.empty((q, dim))
    best = -1.0
    bi = lo
    bf = 0.0
    scale = 0.0
    finite = True
    for i in range(lo, hi):
        _delta_data(pa, ma, sa, pb, mb, sb, t, quintic, i, p2, m2, s2, t2)
        if quintic:
            _quintic_row(p2, m2, s2, t2, 0, row, 0)
        else:
            _cubic_row(p2, m2, t2, 0, row, 0)
        best, bi, bf, scale, finite = _row_first(row, t[i + 1] - t[i], M, ds, U, i, best, bi,
                                                 bf, scale, finite)
    return best, bi, bf, scale, finite


@njit(cache=True, nogil=True, error_model="numpy")
def hermite_delta_rows(pa, ma, sa, pb, mb, sb, t, quintic, idx, out):
    """``out[r]`` = the power coefficients of piece ``idx[r]`` of the difference curve of
    :func:`hermite_delta_pass` (the same bits)."""
    dim = pa.shape[1]
    p2 = np.empty((2, dim))
    m2 = np.empty((2, dim))
    s2 = np.empty((2, dim))
    t2 = np.empty(2)
    for r in range(idx.shape[0]):
        _delta_data(pa, ma, sa, pb, mb, sb, t, quintic, idx[r], p2, m2, s2, t2)
        if quintic:
            _quintic_row(p2, m2, s2, t2, 0, out, r)
        else:
            _cubic_row(p2, m2, t2, 0, out, r)


@njit(cache=True, inline="always")
def _bspline_delta_row(knots, p, s, ctrl, base, closed, prev, have, ndu, left, right, a, d,
                       fact, out, r):
    """Span ``s``'s power coefficients of the B-spline with control points ``ctrl - base``
    into ``out[r]``: :func:`curvefair._kernels.bspline.power_form_kernel`'s operations in its
    order (the basis derivatives of ``_span_basis``, reused while the local knot pattern
    repeats), the differences taken where they are read. Returns ``have``."""
    have = _span_basis(knots, p, s, prev, have, ndu, left, right, a, d)
    n = ctrl.shape[0]
    for k in range(p + 1):
        for e in range(ctrl.shape[1]):
            acc = 0.0
            for b in range(p + 1):
                i = s - p + b
                if closed:
                    i = i % n
                acc += d[0, k, b] * (ctrl[i, e] - base[i, e])
            out[r, k, e] = acc / fact[k]
    return have


@njit(cache=True, inline="always")
def _bspline_delta_body(knots, p, spans, ctrl, base, closed, breaks, M, U, lo, hi):
    """:func:`first_pass` on the pieces ``lo .. hi - 1`` (as :func:`hermite_delta_pass`).
    Kept apart from :func:`_bspline_delta_rows_body`: each kernel inlines only the loop it
    runs (numba copies an inlined body's IR block by block, so what is inlined and never run
    still costs compile time)."""
    dim = ctrl.shape[1]
    ndu, left, right, a, d, fact, prev, have = _basis_work(p)
    best = -1.0
    bi = lo
    bf = 0.0
    scale = 0.0
    finite = True
    row = np.empty((1, p + 1, dim))
    ds = np.empty((p + 1, dim))
    for i in range(lo, hi):
        have = _bspline_delta_row(knots, p, spans[i], ctrl, base, closed, prev, have, ndu,
                                  left, right, a, d, fact, row, 0)
        best, bi, bf, scale, finite = _row_first(row, breaks[i + 1] - breaks[i], M, ds, U, i,
                                                 best, bi, bf, scale, finite)
    return best, bi, bf, scale, finite


@njit(cache=True, inline="always")
def _bspline_delta_rows_body(knots, p, spans, ctrl, base, closed, idx, out):
    """The rows ``idx`` of :func:`_bspline_delta_body`'s pieces into ``out``."""
    ndu, left, right, a, d, fact, prev, have = _basis_work(p)
    for r in range(idx.shape[0]):
        have = _bspline_delta_row(knots, p, spans[idx[r]], ctrl, base, closed, prev, have,
                                  ndu, left, right, a, d, fact, out, r)


@njit(cache=True, nogil=True, error_model="numpy")
def bspline_delta_pass(knots, p, spans, ctrl, base, closed, breaks, M, U, lo, hi):
    """:func:`first_pass` on the pieces ``lo .. hi - 1`` of the difference curve of two
    B-splines on the same knots (control points ``ctrl - base``), bit for bit as on its whole
    power form, without that form; the returns of :func:`hermite_delta_pass`. A cubic runs a
    copy compiled for degree 3 (the same operations, as in ``power_form_kernel``)."""
    if p == 3:
        return _bspline_delta_body(knots, 3, spans, ctrl, base, closed, breaks, M, U, lo, hi)
    return _bspline_delta_body(knots, p, spans, ctrl, base, closed, breaks, M, U, lo, hi)


@njit(cache=True, nogil=True, error_model="numpy")
def bspline_delta_rows(knots, p, spans, ctrl, base, closed, idx, out):
    """``out[r]`` = the power coefficients of piece ``idx[r]`` of :func:`bspline_delta_pass`'s
    difference curve (the same bits)."""
    if p == 3:
        _bspline_delta_rows_body(knots, 3, spans, ctrl, base, closed, idx, out)
    else:
        _bspline_delta_rows_body(knots, p, spans, ctrl, base, closed, idx, out)


@njit(cache=True, nogil=True, error_model="numpy")
def split_bounds(U, thr, sel):
    """``sel[:k]`` = the indices ``i`` (ascending) with ``U[i] > thr``, and the largest of
    the others' ``U``, with 0.0 among them when ``k > 0``: ``numpy.max(numpy.where(U > thr,
    0.0, U))`` (NaN if a bound is NaN), as :func:`curvefair.deviation` has always computed it.
    Returns ``(k, that maximum)``; ``U`` not empty."""
    k = 0
    ub = -np.inf
    nan = False
    for i in range(U.shape[0]):
        u = U[i]
        if u > thr:
            sel[k] = i
            k += 1
            u = 0.0
        if u != u:
            nan = True
        elif u > ub:
            ub = u
    return k, (np.nan if nan else ub)


@njit(cache=True, error_model="numpy")
def _norm_row(v):
    """``sqrt(sum(v * v))`` summed in index order (as the numpy ``_norms`` of
    :mod:`curvefair.analysis._deviation` rounds it)."""
    acc = v[0] * v[0]
    for c in range(1, v.shape[0]):
        acc += v[c] * v[c]
    return np.sqrt(acc)


@njit(cache=True, error_model="numpy")
def branch_and_bound(cb, lo, hi, best, best_t, ub, rtol, atol, levels, cap):
    """The levels of :func:`curvefair.deviation`'s branch-and-bound in one compiled pass.

    Per level, for the pieces left (Bernstein control points ``cb`` (k, q, dim) on
    ``[lo, hi]``): halve each piece (de Casteljau at 1/2: left halves first, then right
    halves), sample every child at its midpoint and the split points, keep the children whose
    bound ``max_i |b_i|`` exceeds ``best + rtol best + atol``; the bounds of the others raise
    ``ub``. The same operations in the same order as the array code it replaces (bitwise the
    same figures). Stops early, before a level, when more than ``cap`` pieces are left (the
    caller trims them) and returns ``(cb, lo, hi, best, best_t, ub, levels done)``.
    """
    q = cb.shape[1]
    dim = cb.shape[2]
    cur = np.empty((q, dim))
    done = 0
    for _ in range(levels):
        k = cb.shape[0]
        if k == 0 or k > cap:
            break
        k2 = 2 * k
        nb = np.empty((k2, q, dim))
        nlo = np.empty(k2)
        nhi = np.empty(k2)
        for i in range(k):
            for j in range(q):
                for c in range(dim):
                    cur[j, c] = cb[i, j, c]
            for c in range(dim):
                nb[i, 0, c] = cur[0, c]
                nb[k + i, q - 1, c] = cur[q - 1, c]
            for r in range(1, q):
                for j in range(q - r):
                    for c in range(dim):
                        cur[j, c] = 0.5 * (cur[j, c] + cur[j + 1, c])
                for c in range(dim):
                    nb[i, r, c] = cur[0, c]
                    nb[k + i, q - 1 - r, c] = cur[q - 1 - r, c]
            mid = 0.5 * (lo[i] + hi[i])
            nlo[i] = lo[i]
            nhi[i] = mid
            nlo[k + i] = mid
            nhi[k + i] = hi[i]
        # each child's midpoint: de Casteljau at 1/2 of its control points
        sbest = -1.0
        skk = 0
        for i in range(k2):
            for j in range(q):
                for c in range(dim):
                    cur[j, c] = nb[i, j, c]
            for r in range(1, q):
                for j in range(q - r):
                    for c in range(dim):
                        cur[j, c] = 0.5 * (cur[j, c] + cur[j + 1, c])
            v = _norm_row(cur[0])
            if v > sbest:
                sbest = v
                skk = i
        if sbest > best:
            best = sbest
            best_t = 0.5 * (nlo[skk] + nhi[skk])
        # the split points: the last control point of each left child
        ebest = -1.0
        ekk = 0
        for i in range(k):
            v = _norm_row(nb[i, q - 1])
            if v > ebest:
                ebest = v
                ekk = i
        if ebest > best:
            best = ebest
            best_t = nhi[ekk]
        thr = best + (rtol * best + atol)
        U = np.empty(k2)
        n_keep = 0
        for i in range(k2):
            u = -1.0
            for j in range(q):
                v = _norm_row(nb[i, j])
                if v > u:
                    u = v
            U[i] = u
            if u > thr:
                n_keep += 1
            elif u > ub:
                ub = u
        cb = np.empty((n_keep, q, dim))
        lo = np.empty(n_keep)
        hi = np.empty(n_keep)
        w = 0
        for i in range(k2):
            if U[i] > thr:
                cb[w] = nb[i]
                lo[w] = nlo[i]
                hi[w] = nhi[i]
                w += 1
        done += 1
    return cb, lo, hi, best, best_t, ub, done


@njit(cache=True, nogil=True, error_model="numpy")
def matched_bound_kernel(ua, ub, pa, pb, ta, tb, pieces, tob, out):
    """:func:`curvefair.analysis.matched_hermite_bound` in one pass over the spans (no
    ``(n, 4, dim)`` temporaries): per span and sub-piece, the difference cubic's values at
    ``s = (j + k / 3) / pieces``, their Bernstein control points by ``tob``, the largest
    control-point norm. :func:`matched_hermite_bound_reference` is the same in numpy."""
    dim = pa.shape[1]
    vals = np.empty((4, dim))
    herm = np.empty((dim, 4))  # the span's Hermite data d0, m0, d1, m1 per coordinate
    for i in range(out.shape[0]):
        ha = ua[i + 1] - ua[i]
        hb = ub[i + 1] - ub[i]
        r = ha / hb
        for c in range(dim):
            herm[c, 0] = pa[i, c] - pb[i, c]
            herm[c, 1] = ta[i, c] * r * hb - tb[i, c] * hb
            herm[c, 2] = pa[i + 1, c] - pb[i + 1, c]
            herm[c, 3] = ta[i + 1, c] * r * hb - tb[i + 1, c] * hb
        best = 0.0
        for j in range(pieces):
            for kk in range(4):
                s = (j + kk / 3.0) / pieces
                s2 = s * s  # products, not pow: the same roundings on every CPU
                s3 = s2 * s
                h00 = 2 * s3 - 3 * s2 + 1
                h10 = s3 - 2 * s2 + s
                h01 = -2 * s3 + 3 * s2
                h11 = s3 - s2
                for c in range(dim):
                    vals[kk, c] = (herm[c, 0] * h00 + herm[c, 1] * h10 + herm[c, 2] * h01
                                   + herm[c, 3] * h11)
            for q in range(4):
                acc = 0.0
                for c in range(dim):
                    v = (tob[q, 0] * vals[0, c] + tob[q, 1] * vals[1, c]
                         + tob[q, 2] * vals[2, c] + tob[q, 3] * vals[3, c])
                    acc += v * v
                if acc > best:
                    best = acc
        out[i] = math.sqrt(best) * (1.0 + 1e-12)


def matched_hermite_bound_reference(a: Any, b: Any, pieces: int = 4) -> FloatArray:
    """:func:`curvefair.analysis.matched_hermite_bound` with numpy arrays of all spans at once
    (the plain form the compiled kernel :func:`matched_bound_kernel` is tested against)."""
    ua, ub = np.asarray(a.params), np.asarray(b.params)
    ha, hb = np.diff(ua), np.diff(ub)
    pa, pb = np.asarray(a.points), np.asarray(b.points)
    ta, tb = np.asarray(a.tangents), np.asarray(b.tangents)
    r = (ha / hb)[:, None]
    d0, d1 = pa[:-1] - pb[:-1], pa[1:] - pb[1:]
    # derivatives with respect to the span's unit parameter s = (t - t_i) / hb
    m0 = ta[:-1] * r * hb[:, None] - tb[:-1] * hb[:, None]
    m1 = ta[1:] * r * hb[:, None] - tb[1:] * hb[:, None]
    best = np.zeros(len(ha))
    k = np.arange(4) / 3.0
    for j in range(pieces):
        s = (j + k) / pieces
        h00 = 2 * s ** 3 - 3 * s ** 2 + 1
        h10 = s ** 3 - 2 * s ** 2 + s
        h01 = -2 * s ** 3 + 3 * s ** 2
        h11 = s ** 3 - s ** 2
        vals = (d0[:, None, :] * h00[None, :, None] + m0[:, None, :] * h10[None, :, None]
                + d1[:, None, :] * h01[None, :, None] + m1[:, None, :] * h11[None, :, None])
        ctrl = np.einsum("kv,svd->skd", TO_BERNSTEIN, vals)
        best = np.maximum(best, np.sqrt(np.max(np.sum(ctrl * ctrl, axis=2), axis=1)))
    return best * (1.0 + 1e-12)


@njit(cache=True, inline="always")
def _row_distance(m, o, i):  # pragma: no cover - compiled
    """``sqrt(sum_d (m[i, d] - o[i, d])**2)``, the squares summed left to right: the
    operations of ``np.linalg.norm(m - o, axis=-1)`` in its order (the one place it is
    written)."""
    acc = 0.0
    for d in range(m.shape[1]):
        x = m[i, d] - o[i, d]
        acc += x * x
    return math.sqrt(acc)


@njit(cache=True, nogil=True, readonly=('m', 'o'))
def point_distances_kernel(m, o, out):  # pragma: no cover - compiled
    """``out[i]`` = :func:`_row_distance` of every row (one pass, no temporaries of the data's
    size: at ten million points numpy's three took 0.4 s)."""
    for i in range(m.shape[0]):
        out[i] = _row_distance(m, o, i)


@njit(cache=True, nogil=True, readonly=('p0', 'p1'))
def moved_points_kernel(p0, p1, idx, disp):  # pragma: no cover - compiled
    """The rows where ``p1`` differs from ``p0`` in any coordinate (``!=``, as numpy compares)
    into ``idx`` (ascending) and their distances (:func:`point_distances_kernel`'s) into
    ``disp``; returns how many."""
    k = 0
    for i in range(p0.shape[0]):
        for d in range(p0.shape[1]):
            if p1[i, d] != p0[i, d]:
                idx[k] = i
                disp[k] = _row_distance(p1, p0, i)
                k += 1
                break
    return k


# ------------------------------------------------------------------------------------------
# nearest points of a piecewise polynomial (the geometric distance of curvefair.deviation)
# ------------------------------------------------------------------------------------------
@njit(cache=True, inline="always")
def _segment_of(breaks, u):  # pragma: no cover - compiled
    """``PiecewisePolynomial.segment_of``: ``searchsorted(breaks, u, "right") - 1`` clipped to
    the segments (NaN sorts last, as in numpy)."""
    m = breaks.shape[0]
    if u != u:
        i = m
    else:
        lo = 0
        hi = m
        while lo < hi:  # the first index whose break is greater than u
            mid = (lo + hi) >> 1
            if breaks[mid] <= u:
                lo = mid + 1
            else:
                hi = mid
        i = lo
    i -= 1
    if i > m - 2:
        i = m - 2
    if i < 0:
        i = 0
    return i


@njit(cache=True, inline="always")
def _horner(coeffs, seg, s, nu, e, fac):  # pragma: no cover - compiled
    """Coordinate ``e`` of the ``nu``-th derivative on segment ``seg`` at local offset ``s``:
    the derivative's coefficients ``coeffs[seg, j, e] * j! / (j - nu)!`` by Horner's rule, the
    operations of ``PiecewisePolynomial.evaluate`` (a multiplication and an addition a
    coefficient, each rounded)."""
    p1 = coeffs.shape[1]
    if nu >= p1:
        return 0.0
    out = coeffs[seg, p1 - 1, e] * fac[nu, p1 - 1]
    for j in range(p1 - 2, nu - 1, -1):
        out = out * s
        out = out + coeffs[seg, j, e] * fac[nu, j]
    return out


@njit(cache=True, error_model="numpy")
def nearest_newton(breaks, coeffs, fac, u, x, j, d0, iters, best_d, best_s):
    """Safeguarded Newton for the nearest point of the curve (power form ``breaks``,
    ``coeffs``) to each row of ``x``, from the dense sample ``u[j]`` (distance ``d0``),
    bracketed by the samples on either side: ``iters`` steps minimising ``|r(s) - x|^2``
    (``g = (r - x).r'``, ``h = |r'|^2 + (r - x).r''``), a step out of the bracket or at
    ``h <= 0`` replaced by bisection; the best distance seen and its parameter into ``best_d``,
    ``best_s``. ``fac[nu, k] = k! / (k - nu)!`` (``nu`` 0-2). The loop of
    ``curvefair.analysis._deviation._Nearest._newton`` per point (its numpy form is the
    reference it is tested against); sums over the coordinates in their order."""
    dim = x.shape[1]
    nu_last = u.shape[0] - 1
    r = np.empty(dim)
    for q in range(x.shape[0]):
        jq = j[q]
        lo = u[jq - 1 if jq >= 1 else 0]
        hi = u[jq + 1 if jq + 1 <= nu_last else nu_last]
        s = u[jq]
        bd = d0[q]
        bs = s
        for _ in range(iters):
            seg = _segment_of(breaks, s)
            t = s - breaks[seg]
            g = 0.0
            h1 = 0.0
            h2 = 0.0
            for e in range(dim):
                r[e] = _horner(coeffs, seg, t, 0, e, fac) - x[q, e]
            for e in range(dim):
                d1 = _horner(coeffs, seg, t, 1, e, fac)
                d2 = _horner(coeffs, seg, t, 2, e, fac)
                g += r[e] * d1
                h1 += d1 * d1
                h2 += r[e] * d2
            h = h1 + h2
            step = g / h if h > 0 else 0.0
            new = s - step
            if g > 0:
                hi = s
            else:
                lo = s
            if h <= 0 or new < lo or new > hi or not np.isfinite(new):
                new = 0.5 * (lo + hi)
            s = new
            seg = _segment_of(breaks, s)
            t = s - breaks[seg]
            d2s = 0.0
            for e in range(dim):
                v = _horner(coeffs, seg, t, 0, e, fac) - x[q, e]
                d2s += v * v
            dist = np.sqrt(d2s)
            if dist < bd:
                bd = dist
                bs = s
        best_d[q] = bd
        best_s[q] = bs


@njit(cache=True, error_model="numpy")
def power_values(breaks, coeffs, fac, u, out):
    """``PiecewisePolynomial.evaluate(u)`` bit for bit (Horner's rule on the segment
    ``segment_of`` picks) into ``out`` (shape ``(len(u), dim)``): the points of a curve at a
    few parameters without the array calls of the numpy form (the geometric distance's
    golden-section search asks for eight points at a time, about 60 times per curve pair)."""
    for q in range(u.shape[0]):
        seg = _segment_of(breaks, u[q])
        t = u[q] - breaks[seg]
        for e in range(out.shape[1]):
            out[q, e] = _horner(coeffs, seg, t, 0, e, fac)
