"""Compiled kernel of the corner search of the point-list readers
(:func:`curvefair.io._common.corner_turning`): :func:`chord_turns_kernel`, the turning angle at
every point between the chords to the nearest points at least a given length away, which
measures a noisy list's turns at the scale of its noise; :func:`chord_turns_reference` is the
same search by a plain Python walk, the slow reference the kernel is tested against.
"""

from __future__ import annotations

import numpy as np

from .._jit import njit
from .._typing import FloatArray


@njit(cache=True)
def chord_turns_kernel(p, closed, Lmin, out):
    """Fill ``out`` (NaN on entry) for :func:`curvefair.io._common._chord_turns`: from every
    point ``i`` walk back and forth to the first point ``k`` with ``|p_k - p_i| >= Lmin`` (at
    most ``m // 2`` steps; an open list's ends stop the walk), then
    ``angle = arccos(a . b / (|a| |b|))`` of the chords ``a = p_i - p_back``,
    ``b = p_fwd - p_i``, clipped to [-1, 1]; sums in coordinate order (no fastmath)."""
    m = p.shape[0]
    lo, hi = (0, m) if closed else (1, m - 1)
    lim = m // 2 + 1
    for i in range(lo, hi):
        kb, _, okb = _walk(p, closed, i, i - 1, 1, -1, lim, Lmin)
        kf, _, okf = _walk(p, closed, i, i + 1, 1, 1, lim, Lmin)
        if okb and okf:
            out[i] = _turn(p, i, kb % m, kf % m)


@njit(cache=True, inline="always")
def _turn(p, i, back, fwd):
    """The turn in degrees at ``p_i`` between the chords ``a = p_i - p_back`` and
    ``b = p_fwd - p_i``: ``arccos(a . b / (|a| |b|))``, the cosine clipped to [-1, 1]; sums in
    coordinate order (no fastmath)."""
    ab = 0.0
    aa = 0.0
    bb = 0.0
    for c in range(p.shape[1]):
        u = p[i, c] - p[back, c]
        w = p[fwd, c] - p[i, c]
        ab += u * w
        aa += u * u
        bb += w * w
    cosv = ab / (np.sqrt(aa) * np.sqrt(bb))
    cosv = min(1.0, max(-1.0, cosv))
    return np.degrees(np.arccos(cosv))


@njit(cache=True, inline="always")
def _walk(p, closed, i, k, n_steps, step, lim, Lmin):
    """The chord walk of :func:`chord_turns_kernel` and :func:`corner_turns_range`: from
    ``i``, continued at ``k`` (``n_steps`` taken, one ``step`` of +-1 at a time), to the first
    point at least ``Lmin`` from ``p_i``; ``(k, n_steps, found)`` where it stopped (at the
    point found, or where an open list's end or the step limit ``lim`` ended the walk)."""
    m, dim = p.shape
    while n_steps < lim:
        if not closed and (k < 0 or k >= m):
            return k, n_steps, False
        kk = k % m
        d2 = 0.0
        for c in range(dim):
            t = p[kk, c] - p[i, c]
            d2 += t * t
        if np.sqrt(d2) >= Lmin:
            return k, n_steps, True
        k += step
        n_steps += 1
    return k, n_steps, False


@njit(cache=True, nogil=True)
def corner_turns_range(p, closed, lengths, out, a, b):
    """The first part of :func:`curvefair.io._common.corner_turning` on a noisy list, for the
    points ``a <= i < b`` (independent ranges: two threads): the turns of
    :func:`chord_turns_kernel` at each of the nondecreasing chord lengths ``lengths``, the
    smallest of those reached into ``out[i]`` (0 for a point reaching fewer than two, and for
    an open list's end points). :func:`keep_local_maxima` then keeps one corner per run.

    One walk per direction serves every length: the first point at least ``L2 >= L1`` away is
    never before the first at least ``L1`` away (every point before that is nearer than
    ``L1``), so the walk for ``L2`` resumes where the one for ``L1`` stopped, and a walk that
    ran into an end (or the step limit) for ``L1`` does for ``L2`` too. The angles are those of
    :func:`chord_turns_kernel` (the same operations), so the result is that of the numpy
    composition of its calls, bit for bit (tested)."""
    m = p.shape[0]
    lim = m // 2 + 1
    ns = lengths.shape[0]
    for i in range(a, b):
        out[i] = 0.0
        if not closed and (i == 0 or i == m - 1):
            continue
        kb = i - 1
        sb = 1
        okb = True
        kf = i + 1
        sf = 1
        okf = True
        best = np.inf
        reached = 0
        for s in range(ns):
            L = lengths[s]
            if okb:
                kb, sb, okb = _walk(p, closed, i, kb, sb, -1, lim, L)
            if okf:
                kf, sf, okf = _walk(p, closed, i, kf, sf, 1, lim, L)
            if not (okb and okf):
                break
            ang = _turn(p, i, kb % m, kf % m)
            if ang == ang:  # (NaN: not counted, as the composition's isnan mask)
                if ang < best:
                    best = ang
                reached += 1
        if reached >= 2:
            out[i] = best


@njit(cache=True)
def keep_local_maxima(out, closed):
    """One corner per run of turning neighbours: ``out[i]`` set to 0 unless it is at least
    both neighbours' (a closed list wraps around, an open list's ends are compared with
    -1), every comparison with the values on entry (as ``np.roll`` of a copy)."""
    m = out.shape[0]
    if m == 0:
        return
    first = out[0]
    prev = out[m - 1] if closed else -1.0
    for i in range(m):
        cur = out[i]
        if i + 1 < m:
            nxt = out[i + 1]
        else:
            nxt = first if closed else -1.0
        if not (cur >= prev and cur >= nxt):
            out[i] = 0.0
        prev = cur


def chord_turns_reference(p: FloatArray, closed: bool, Lmin: float) -> FloatArray:
    """:func:`curvefair.io._common._chord_turns` by a plain Python walk (numpy norms and dot
    products per point): the slow reference :func:`chord_turns_kernel` is tested against."""
    m = p.shape[0]
    out = np.full(m, np.nan)
    idx = range(m) if closed else range(1, m - 1)
    for i in idx:
        ends = []
        for step in (-1, 1):
            k, n_steps, found = i + step, 1, False
            while n_steps < m // 2 + 1:
                if not closed and not 0 <= k < m:
                    break
                if np.linalg.norm(p[k % m] - p[i]) >= Lmin:
                    found = True
                    break
                k += step
                n_steps += 1
            ends.append(k % m if found else -1)
        if ends[0] < 0 or ends[1] < 0:
            continue
        a, b = p[i] - p[ends[0]], p[ends[1]] - p[i]
        na, nb = float(np.linalg.norm(a)), float(np.linalg.norm(b))
        out[i] = np.degrees(np.arccos(np.clip(float(a @ b) / (na * nb), -1.0, 1.0)))
    return out


@njit(cache=True)
def noise_terms_2d(p, closed, ratio):
    """The O(n) part of :func:`curvefair.io._common.noise_scale` for a planar list, in one
    pass: for every point ``b`` between its neighbours ``a`` and ``c`` (an open list's inner
    points, every point of a closed one) with a chord ``d = c - a`` of positive length ``L``,
    ``|(b - a) x d| / L`` into ``ratio`` (in point order, only where ``L > 0``); returns the
    count of those and the count of sign flips of the turn ``(b - a) x (c - b)`` between
    consecutive points. The same IEEE operations, in the same order, as the numpy
    expressions it replaces (``sqrt(d0*d0 + d1*d1)``, ``|v0*d1 - v1*d0|``), so the same
    bits."""
    m = p.shape[0]
    lo, hi = (0, m) if closed else (1, m - 1)
    nr = 0
    flips = 0
    prev = 0.0
    for i in range(lo, hi):
        ia = i - 1 if i > 0 else m - 1
        ic = i + 1 if i < m - 1 else 0
        ax = p[ia, 0]
        ay = p[ia, 1]
        bx = p[i, 0]
        by = p[i, 1]
        cx = p[ic, 0]
        cy = p[ic, 1]
        d0 = cx - ax
        d1 = cy - ay
        L = np.sqrt(d0 * d0 + d1 * d1)
        v0 = bx - ax
        v1 = by - ay
        if L > 0:
            ratio[nr] = abs(v0 * d1 - v1 * d0) / L
            nr += 1
        e0 = cx - bx
        e1 = cy - by
        sg = np.sign(v0 * e1 - v1 * e0)
        if i > lo and sg * prev < 0:
            flips += 1
        prev = sg
    return nr, flips


@njit(cache=True)
def point_checks(p, max_magnitude, eps4):
    """The scans of :func:`curvefair.io._common.check_points` in two passes: the first row
    with a non-finite coordinate, the first with one beyond ``max_magnitude``, the largest
    coordinate range, and the first ``i`` whose step to ``i + 1`` is at most ``eps4`` times
    the largest magnitude (at least the smallest normal float) in every coordinate
    (-1 where none). Compared as numpy compares them."""
    m, dim = p.shape
    big = -1
    amax = 0.0
    for i in range(m):
        for c in range(dim):
            v = abs(p[i, c])
            if not np.isfinite(v):
                return i, -1, 0.0, -1
            if v > amax:
                amax = v
            if big < 0 and v > max_magnitude:
                big = i
    if big >= 0 or m < 2:
        return -1, big, 0.0, -1
    extent = 0.0
    for c in range(dim):
        lo = p[0, c]
        hi = p[0, c]
        for i in range(1, m):
            v = p[i, c]
            if v < lo:
                lo = v
            if v > hi:
                hi = v
        if hi - lo > extent:
            extent = hi - lo
    scale = max(amax, 2.2250738585072014e-308)
    lim = eps4 * scale
    for i in range(m - 1):
        d = 0.0
        for c in range(dim):
            t = abs(p[i + 1, c] - p[i, c])
            if t > d:
                d = t
        if d <= lim:
            return -1, -1, extent, i
    return -1, -1, extent, -1


@njit(cache=True)
def coord_extent(p):
    """``np.ptp(p, axis=0).max()`` (the largest coordinate range) in one pass over the rows
    (numpy reduces a column of a C-ordered array with a stride); NaN if any coordinate is
    NaN, as numpy gives. The same subtractions, so the same bits."""
    m, dim = p.shape
    ext = -np.inf
    for c in range(dim):
        lo = p[0, c]
        hi = p[0, c]
        for i in range(1, m):
            v = p[i, c]
            if v != v:
                return np.nan
            if v < lo:
                lo = v
            if v > hi:
                hi = v
        if lo != lo:
            return np.nan
        if hi - lo > ext:
            ext = hi - lo
    return ext


def noise_terms_reference(p: FloatArray, closed: bool) -> tuple[FloatArray, int]:
    """:func:`noise_terms_2d` by whole-array numpy expressions (the code it replaced): the
    ratios (where the chord is positive) and the sign flips of the turn."""
    if closed:
        a, b, c = np.roll(p, 1, 0), p, np.roll(p, -1, 0)
    else:
        a, b, c = p[:-2], p[1:-1], p[2:]
    d = c - a
    L = np.linalg.norm(d, axis=1)
    v = b - a
    cr = np.abs(v[:, 0] * d[:, 1] - v[:, 1] * d[:, 0])
    ok = L > 0
    e2 = c - b
    sg = np.sign(v[:, 0] * e2[:, 1] - v[:, 1] * e2[:, 0])
    return cr[ok] / L[ok], int(np.count_nonzero(sg[1:] * sg[:-1] < 0))


def point_checks_reference(p: FloatArray, max_magnitude: float, eps4: float
                           ) -> tuple[int, int, float, int]:
    """:func:`point_checks` by whole-array numpy expressions (the code it replaced)."""
    bad = np.flatnonzero(~np.isfinite(p).all(axis=1))
    if bad.size:
        return int(bad[0]), -1, 0.0, -1
    big = np.flatnonzero(np.abs(p).max(axis=1) > max_magnitude)
    if big.size or p.shape[0] < 2:
        return -1, int(big[0]) if big.size else -1, 0.0, -1
    extent = float(np.ptp(p, axis=0).max())
    d = np.abs(np.diff(p, axis=0)).max(axis=1)
    scale = max(float(np.abs(p).max()), np.finfo(float).tiny)
    dup = np.flatnonzero(d <= eps4 * scale)
    return -1, -1, extent, int(dup[0]) if dup.size else -1
