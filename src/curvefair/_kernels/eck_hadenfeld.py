"""Compiled kernels of the Eck-Hadenfeld method (:mod:`curvefair.fairing.eck_hadenfeld`).

One step moves one control point to the constrained minimiser of the energy
``E_l = d^T G d`` over that point alone (:func:`_candidate`); the ranking-list loop
(:func:`eh_loop`, a tournament tree over the ranking numbers) and the sweep schedule
(:func:`eh_sweep`) repeat it until every ranking number is below the threshold.
:func:`setup_state` builds the loop state ``X = [d | G d | d]`` and the energy in one pass,
:func:`largest_free_z` the largest unconstrained ranking number, :func:`patterns` the distinct
rows of the Gram band (:func:`curvefair.fairing.eck_hadenfeld.band_patterns`). The rows of
``G d`` and of the energy are those of :mod:`curvefair._kernels.bspline` (inlined).
"""

from __future__ import annotations

from collections import deque

import numpy as np

from .._jit import njit, prefetch
from .bspline import energy_row, residual_row


# ------------------------------------------------------------------------------------------
# the compiled ranking-list loop
# ------------------------------------------------------------------------------------------
@njit(cache=True, error_model="numpy")
def _candidate(g0, g1, g2, d0, d1, d2, o0, o1, o2, gii, igii, tol):
    """Constrained minimiser of the energy over one control point: ``(z, e0, e1, e2)``.

    The energy as a function of ``d_i`` alone is ``G_ii |x - x*|^2 + const`` (isotropic), with
    ``x* = d_i - g_i / G_ii``; its minimiser over the ball ``|x - orig_i| <= tol`` is the
    projection of ``x*`` onto the ball, with exact drop
    ``G_ii (|d_i - x*|^2 - |x - x*|^2) = G_ii (2 e.s - |e|^2)`` (``s = x* - d_i``,
    ``e = x - d_i``). A move shorter than 4 ulp-ish of the coordinates (``4e-16 (|d_i|_inf +
    tol)``) counts as no move (z = 0). The ball's radius is ``tol`` less a rounding margin
    ``2e-15 (|d_i|_inf + 2 tol)``, which bounds the rounding of the clamped point, of its
    storage and of any later distance computation: ``|x - orig_i| <= tol`` holds as computed,
    also for coordinates much larger than ``tol``. Scalars only: numba array arguments cost
    reference counting per call.
    """
    s0 = -g0 * igii
    s1 = -g1 * igii
    s2 = -g2 * igii
    # a move below the rounding of the coordinates is no move (else rounding noise in z keeps
    # the loop busy with zero-length moves)
    m = max(abs(d0), abs(d1), abs(d2))
    floor = 4e-16 * (m + (tol if tol < np.inf else 0.0))
    floor *= floor
    if s0 * s0 + s1 * s1 + s2 * s2 <= floor:
        return 0.0, 0.0, 0.0, 0.0
    if tol < np.inf:
        # the ball's radius less a rounding margin: the STORED point (every coordinate rounded
        # at the size of the coordinates, several times) is then within tol as computed by
        # anyone, |x - orig| <= tol even for coordinates 1e6 times tol
        rad = tol - 2e-15 * (m + 2.0 * tol)
        rad = rad if rad > 0.0 else 0.0
        v0 = d0 + s0 - o0
        v1 = d1 + s1 - o1
        v2 = d2 + s2 - o2
        vv = v0 * v0 + v1 * v1 + v2 * v2
        if vv > rad * rad:
            f = rad / np.sqrt(vv)
            e0 = o0 + v0 * f - d0
            e1 = o1 + v1 * f - d1
            e2 = o2 + v2 * f - d2
            ee = e0 * e0 + e1 * e1 + e2 * e2
            if ee <= floor:
                return 0.0, 0.0, 0.0, 0.0
            z = gii * (2.0 * (e0 * s0 + e1 * s1 + e2 * s2) - ee)
            if z < 0.0:
                z = 0.0
            return z, e0, e1, e2
    return gii * (s0 * s0 + s1 * s1 + s2 * s2), s0, s1, s2


@njit(cache=True, inline="always")
def _candidate2(g0, g1, d0, d1, o0, o1, gii, igii, tol):
    """:func:`_candidate` for a planar point, branch-free: the free and the clamped move are
    both computed and one is selected (a mispredicted branch on whether the ball is reached
    costs more than the extra arithmetic); the same operations in the same order, so the same
    values bitwise (also the zero move below rounding). Returns ``(z, e0, e1)``."""
    s0 = -g0 * igii
    s1 = -g1 * igii
    a0 = abs(d0)
    a1 = abs(d1)
    m = a0 if a0 > a1 else a1
    floor = 4e-16 * (m + (tol if tol < np.inf else 0.0))
    floor *= floor
    ss = s0 * s0 + s1 * s1
    rad = tol - 2e-15 * (m + 2.0 * tol)
    rad = rad if rad > 0.0 else 0.0
    v0 = d0 + s0 - o0
    v1 = d1 + s1 - o1
    vv = v0 * v0 + v1 * v1
    f = rad / np.sqrt(vv)  # inf/nan when not clamped: not selected below
    c0 = o0 + v0 * f - d0
    c1 = o1 + v1 * f - d1
    ee = c0 * c0 + c1 * c1
    zc = gii * (2.0 * (c0 * s0 + c1 * s1) - ee)
    zc = zc if zc > 0.0 else 0.0
    zc = 0.0 if ee <= floor else zc
    clamped = tol < np.inf and vv > rad * rad
    z = zc if clamped else gii * ss
    z = 0.0 if ss <= floor else z
    nomove = ss <= floor or (clamped and ee <= floor)  # _candidate returns zeros then
    e0 = c0 if clamped else s0
    e1 = c1 if clamped else s1
    e0 = 0.0 if nomove else e0
    e1 = 0.0 if nomove else e1
    return z, e0, e1


@njit(cache=True, inline="always")
def _point_candidate(X, i, Wu, pi, p, D, tol):
    """``(z, e0, e1, e2)`` of control point ``i`` from the loop state ``X = [d | G d | orig]``
    (``D`` columns each) and its band row ``Wu[pi]``: :func:`_candidate` in 3-D, the
    branch-free :func:`_candidate2` in the plane (same values). Inlined; the one place the
    state's columns are unpacked for a candidate."""
    if D == 3:
        return _candidate(X[i, 3], X[i, 4], X[i, 5], X[i, 0], X[i, 1], X[i, 2],
                          X[i, 6], X[i, 7], X[i, 8], Wu[pi, p], Wu[pi, 2 * p + 1], tol)
    z, e0, e1 = _candidate2(X[i, 2], X[i, 3], X[i, 0], X[i, 1], X[i, 4], X[i, 5],
                            Wu[pi, p], Wu[pi, 2 * p + 1], tol)
    return z, e0, e1, 0.0


@njit(cache=True, inline="always")
def _record(hist, nh, r, z, e0, e1, e2):
    """Write step ``(index, z, displacement)`` into row ``nh`` of ``hist`` while it has room;
    returns the new row count. Inlined into both loops."""
    if nh < hist.shape[0]:
        hist[nh, 0] = r
        hist[nh, 1] = z
        hist[nh, 2] = np.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
        nh += 1
    return nh


@njit(cache=True, inline="always")
def _move_residuals(X, Wu, pr, r, e0, e1, e2, D, p, closed):
    """After ``d_r`` moved by ``e``: ``(G d)_i += G_ir e`` over the band of ``r`` (cyclic for
    closed curves), ``G``'s row ``r`` being ``Wu[pr]``. Inlined at numba IR level into both
    loops (no call with array arguments in them); the one place this update is written."""
    n = X.shape[0]
    for c in range(2 * p + 1):
        i = r + c - p
        if closed:
            if i < 0:
                i += n
            elif i >= n:
                i -= n
        elif i < 0 or i >= n:
            continue
        w = Wu[pr, c]
        X[i, D] += w * e0
        X[i, D + 1] += w * e1
        if D == 3:
            X[i, 5] += w * e2


BLOCK_SHIFT = 3  # 8 control points (one 64-byte line of z) per leaf of the tournament tree
_SPECULATE_BYTES = 1 << 22  # prefetch the runner-up's data when the state exceeds ~4 MB
_RUNNER_UP_TOP = 256  # the runner-up is sought among the siblings of the nodes below 256
_PREFETCH_LEVELS = 4  # tree nodes prefetched on the runner-up's path (from its leaf up)


@njit(cache=True, error_model="numpy")
def eh_loop(X, z, Wu, pat, upat, ulo, uhi, D, p, closed, tol, eps_abs, max_steps,
            hist, T):
    """Ranking-list loop, compiled; updates ``X`` and ``z`` in place.

    ``X[i] = (d_i, g_i, orig_i)``, ``D`` columns each (``X`` has ``3 D`` columns),
    ``g = G d``; ``z[i]`` the ranking number (-1: never moves); ``G``'s band row ``i`` is
    ``Wu[pat[i]]`` (rows shared by equal knot patterns), and every row ``ulo <= i < uhi`` is
    ``Wu[upat]`` (the longest run of one pattern: the uniform interior, whose ``pat`` entries are
    then never read). Everything is written out in this one function: calling numba functions
    with array arguments costs reference counting per call.

    4-ary tournament tree over blocks of 8 control points, one array ``T`` of (value, index)
    pairs (the index stored as a float, exact below 2**53; a node's 4 children are one 64-byte
    cache line): a leaf ``P + b`` holds block ``b``'s largest ``z`` and the index, node ``j``
    the largest of ``4j .. 4j + 3`` (ties to the smaller index, hence to the smaller control
    point). After a move, the ``2p + 1`` changed ``z`` are recomputed (planar curves:
    branch-free, both the free and the tolerance-clamped candidate are evaluated and selected,
    which avoids unpredictable branches; the values are bitwise those of :func:`_candidate`),
    their one or two blocks rescanned and the ancestors repaired (level by level as a contiguous
    range until the range is one node, then along its path with the node carried in registers,
    which keeps a store-to-load round trip off every level): ``O(p + log N)`` per step. At 1e6
    points the 4-ary tree touches 9 cache lines per path instead of the binary tree's 17.

    On large curves the step is bound by memory latency (the next point is usually far away).
    The data of the runner-up (which is the next point whenever this move does not change its
    rank: on noisy data every far jump) are then prefetched one step ahead, as long as far jumps
    are frequent (a running share above 1/4; the slow tail of a fairing run moves locally): its
    band rows, ranking numbers and the lower levels of its tree path. The runner-up is sought
    among the siblings of the top levels of the winner's path only (nodes below 256, hot in the
    cache; walking the whole path cost more than the prefetch saved), which finds it unless it
    shares the winner's subtree 3 levels down. Prefetches never change results.

    ``hist`` (shape (cap, 3)) receives (index, z, displacement) of the first ``cap`` steps.
    ``T`` is the tree's storage, shape ``(>= 2 P, 2)``
    (:func:`curvefair.fairing.eck_hadenfeld._tree_buffer`): allocated by numpy, which asks for
    transparent huge pages on large arrays (numba's allocator does not: fewer first-touch page
    faults), and 64-byte aligned.
    Returns (steps, total energy drop, stop code, number of history rows).
    """
    n = X.shape[0]
    C = X.shape[1]
    B = 1 << BLOCK_SHIFT
    nb = (n + B - 1) >> BLOCK_SHIFT
    P = 1
    while P < nb:
        P *= 4
    for j in range(2 * P):
        T[j, 0] = -1.0
        T[j, 1] = 0.0
    tol2 = tol * tol
    any_movable = False
    for i in range(n):
        if z[i] >= 0.0:
            any_movable = True
            pi = upat if ulo <= i < uhi else pat[i]
            z[i] = _point_candidate(X, i, Wu, pi, p, D, tol)[0]
    if not any_movable:
        return 0, 0.0, 2, 0
    for b in range(nb):
        k0 = b << BLOCK_SHIFT
        best = k0
        for k in range(k0 + 1, min(k0 + B, n)):
            if z[k] > z[best]:
                best = k
        T[P + b, 0] = z[best]
        T[P + b, 1] = best
    L = P >> 2
    while L >= 1:  # level L holds nodes L .. 2L - 1, children of j: 4j .. 4j + 3
        for j in range(L, 2 * L):
            c = 4 * j
            c01 = c + (T[c + 1, 0] > T[c, 0])  # branch-free selects, ties to the left
            c23 = c + 2 + (T[c + 3, 0] > T[c + 2, 0])
            m = c23 if T[c23, 0] > T[c01, 0] else c01
            T[j, 0] = T[m, 0]
            T[j, 1] = T[m, 1]
        L >>= 2
    steps = 0
    drop = 0.0
    code = 1
    nh = 0
    wrap_all = closed and 2 * p + 1 >= n
    big = n * (C + 2) * 8 >= _SPECULATE_BYTES
    farrate = 0.0  # running share of far jumps (> 16 points from the previous step)
    prev = -(1 << 40)
    while steps < max_steps:
        r = int(T[1, 1])
        zr = T[1, 0]
        if zr <= 0.0 or zr < eps_abs:
            code = 0
            break
        farrate = 0.9375 * farrate + (0.0625 if abs(r - prev) > 16 else 0.0)
        prev = r
        if big and farrate > 0.25:
            j = P + (r >> BLOCK_SHIFT)
            while j >= _RUNNER_UP_TOP:
                j >>= 2
            bz = -2.0
            bf = float(r)
            while j > 1:  # branch-free: a mispredicted branch here delays the prefetches
                g = j & ~3
                for q in range(g, g + 4):
                    sv = T[q, 0] if q != j else -2.0
                    sf = T[q, 1]
                    gt = sv > bz
                    bz = sv if gt else bz
                    bf = sf if gt else bf
                j >>= 2
            bi = int(bf)
            q0 = bi - p if bi >= p else 0
            for q in range(q0 * C, (q0 + 2 * p + 1) * C, 8):
                prefetch(X, q)
            prefetch(X, (q0 + 2 * p + 1) * C - 1)
            prefetch(z, q0)
            prefetch(z, q0 + 2 * p)
            j = P + (bi >> BLOCK_SHIFT)
            for _ in range(_PREFETCH_LEVELS):
                prefetch(T, 2 * j)
                j >>= 2
        pr = upat if ulo <= r < uhi else pat[r]
        zz, e0, e1, e2 = _point_candidate(X, r, Wu, pr, p, D, tol)
        X[r, 0] += e0
        X[r, 1] += e1
        if D == 3:
            X[r, 2] += e2
        _move_residuals(X, Wu, pr, r, e0, e1, e2, D, p, closed)
        # the changed ranking numbers: one or two contiguous ranges
        lo1 = r - p
        hi1 = r + p
        lo2 = 0
        hi2 = -1
        if wrap_all:
            lo1 = 0
            hi1 = n - 1
        elif lo1 < 0:
            if closed:
                lo2 = lo1 + n
                hi2 = n - 1
            lo1 = 0
        elif hi1 >= n:
            if closed:
                lo2 = 0
                hi2 = hi1 - n
            hi1 = n - 1
        if hi1 >= n:  # open curve shorter than the band: both ends clipped
            hi1 = n - 1
        for rng in range(2):
            lo = lo1 if rng == 0 else lo2
            hi = hi1 if rng == 0 else hi2
            if hi < lo:
                continue
            inside = ulo <= lo and hi < uhi  # one pattern: no pat reads
            if D == 3:
                for i in range(lo, hi + 1):
                    if z[i] < 0.0:
                        continue
                    pi = upat if inside else pat[i]
                    z[i] = _point_candidate(X, i, Wu, pi, p, D, tol)[0]
            elif tol2 == np.inf:
                for i in range(lo, hi + 1):
                    pi = upat if inside else pat[i]
                    gii = Wu[pi, p]
                    igii = Wu[pi, 2 * p + 1]
                    a0 = abs(X[i, 0])
                    a1 = abs(X[i, 1])
                    m = a0 if a0 > a1 else a1
                    floor = 4e-16 * m
                    floor *= floor
                    s0 = -X[i, 2] * igii
                    s1 = -X[i, 3] * igii
                    ss = s0 * s0 + s1 * s1
                    zn = 0.0 if ss <= floor else gii * ss
                    zo = z[i]
                    z[i] = zo if zo < 0.0 else zn
            else:
                for i in range(lo, hi + 1):
                    pi = upat if inside else pat[i]
                    zn = _point_candidate(X, i, Wu, pi, p, D, tol)[0]
                    zo = z[i]
                    z[i] = zo if zo < 0.0 else zn
            blo = lo >> BLOCK_SHIFT
            bhi = hi >> BLOCK_SHIFT
            for b in range(blo, bhi + 1):
                k0 = b << BLOCK_SHIFT
                best = k0
                zb = z[k0]
                for k in range(k0 + 1, min(k0 + B, n)):
                    zk = z[k]
                    gt = zk > zb
                    best = k if gt else best
                    zb = zk if gt else zb
                T[P + b, 0] = zb
                T[P + b, 1] = best
            # repair the ancestors: level by level while the range spans several nodes,
            # then along the single path with the node's (value, index) carried in registers
            # (reading it back from T would put a store-to-load round trip on every level)
            if blo == bhi:
                j = P + blo
                cv = zb
                cf = float(best)
            else:
                a = (P + blo) >> 2
                bb = (P + bhi) >> 2
                while a < bb:
                    for j in range(a, bb + 1):
                        c = 4 * j
                        c01 = c + (T[c + 1, 0] > T[c, 0])
                        c23 = c + 2 + (T[c + 3, 0] > T[c + 2, 0])
                        m = c23 if T[c23, 0] > T[c01, 0] else c01
                        T[j, 0] = T[m, 0]
                        T[j, 1] = T[m, 1]
                    a >>= 2
                    bb >>= 2
                j = a
                c = 4 * j
                c01 = c + (T[c + 1, 0] > T[c, 0])
                c23 = c + 2 + (T[c + 3, 0] > T[c + 2, 0])
                m = c23 if T[c23, 0] > T[c01, 0] else c01
                cv = T[m, 0]
                cf = T[m, 1]
                T[j, 0] = cv
                T[j, 1] = cf
            while j > 1:  # the same selects, node j's own entry taken from the registers
                g = j & ~3
                k = j & 3
                v0 = cv if k == 0 else T[g, 0]
                v1 = cv if k == 1 else T[g + 1, 0]
                v2 = cv if k == 2 else T[g + 2, 0]
                v3 = cv if k == 3 else T[g + 3, 0]
                f0 = cf if k == 0 else T[g, 1]
                f1 = cf if k == 1 else T[g + 1, 1]
                f2 = cf if k == 2 else T[g + 2, 1]
                f3 = cf if k == 3 else T[g + 3, 1]
                t1 = v1 > v0
                va = v1 if t1 else v0
                fa = f1 if t1 else f0
                t3 = v3 > v2
                vb = v3 if t3 else v2
                fb = f3 if t3 else f2
                tb = vb > va
                cv = vb if tb else va
                cf = fb if tb else fa
                j >>= 2
                T[j, 0] = cv
                T[j, 1] = cf
        drop += zr
        nh = _record(hist, nh, r, zr, e0, e1, e2)
        steps += 1
    return steps, drop, code, nh


@njit(cache=True, error_model="numpy")
def eh_sweep(X, z, Wu, pat, upat, ulo, uhi, D, p, closed, tol, eps_abs, max_steps,
             hist, Q, flags):
    """Sweep schedule (``schedule="sweep"``), compiled; updates ``X`` in place.

    The same step, state and stopping test as :func:`eh_loop` (``X = [d | G d | orig]``,
    ``Wu``/``pat``/``upat``/``ulo``/``uhi`` the band rows, ``z`` 0 for movable and -1 for fixed
    points on entry), but Gauss-Seidel order instead of the ranking list: a first-in first-out
    queue of the points whose ranking number is at least the threshold ``eps_abs``, filled in
    index order; a popped point is faired if its ranking number (recomputed then) is still at
    least the threshold, and every neighbour whose ``(G d)_j`` the move changed joins the queue
    unless it is queued already or its unconstrained drop ``|(G d)_j|^2 / G_jj`` (an upper bound
    of the tolerance-clamped one) is below the threshold. When the queue is empty every
    ranking number is below the threshold: the stopping test of the ranking list, met without
    a priority structure. Memory is read in index order (one queue pass is a sweep), so a step
    costs about the same at 1e6 points as in cache; the ranking list's far jumps cost a DRAM
    latency each.

    ``Q`` (int64, ``n``) is the ring buffer; ``flags`` (uint8, ``n``) is 1 for queued and 2
    for fixed points (``z`` is read only once, for the fixed ones).
    ``hist`` as in :func:`eh_loop`. Returns (steps, total energy drop, stop code, history
    rows): code 0 queue empty, 1 ``max_steps``, 2 no movable point.
    """
    n = X.shape[0]
    thr = eps_abs
    head = 0
    tail = 0
    cnt = 0
    any_movable = False
    for i in range(n):
        if z[i] < 0.0:
            flags[i] = 2  # never moves
            continue
        flags[i] = 0
        any_movable = True
        pi = upat if ulo <= i < uhi else pat[i]
        zi = _point_candidate(X, i, Wu, pi, p, D, tol)[0]
        if zi > 0.0 and zi >= thr:
            Q[tail] = i
            tail += 1
            flags[i] = 1
            cnt += 1
    if not any_movable:
        return 0, 0.0, 2, 0
    if tail == n:
        tail = 0
    wrap_all = closed and 2 * p + 1 >= n
    steps = 0
    drop = 0.0
    nh = 0
    code = 0
    while cnt > 0:
        if steps >= max_steps:
            code = 1
            break
        r = Q[head]
        head += 1
        if head == n:
            head = 0
        cnt -= 1
        flags[r] = 0
        pr = upat if ulo <= r < uhi else pat[r]
        zz, e0, e1, e2 = _point_candidate(X, r, Wu, pr, p, D, tol)
        if zz <= 0.0 or zz < thr:
            continue
        X[r, 0] += e0
        X[r, 1] += e1
        if D == 3:
            X[r, 2] += e2
        _move_residuals(X, Wu, pr, r, e0, e1, e2, D, p, closed)
        # every point whose (G d)_i changed: queue it when its drop may reach the threshold
        if wrap_all:
            lo = 0
            hi = n - 1
        else:
            lo = r - p
            hi = r + p
            if not closed:
                lo = lo if lo > 0 else 0
                hi = hi if hi < n else n - 1
        for k in range(lo, hi + 1):
            i = k
            if i < 0:
                i += n
            elif i >= n:
                i -= n
            if flags[i] != 0:  # queued already, or fixed
                continue
            pi = upat if ulo <= i < uhi else pat[i]
            if D == 3:
                gg = X[i, 3] * X[i, 3] + X[i, 4] * X[i, 4] + X[i, 5] * X[i, 5]
            else:
                gg = X[i, 2] * X[i, 2] + X[i, 3] * X[i, 3]
            zu = gg * Wu[pi, 2 * p + 1]
            if zu > 0.0 and zu >= thr:
                Q[tail] = i
                tail += 1
                if tail == n:
                    tail = 0
                flags[i] = 1
                cnt += 1
        drop += zz
        nh = _record(hist, nh, r, zz, e0, e1, e2)
        steps += 1
    return steps, drop, code, nh


@njit(cache=True)
def patterns(W, Wu, pat):
    """Fill ``pat`` and the distinct rows ``Wu`` (see
    :func:`curvefair.fairing.eck_hadenfeld.band_patterns`); returns ``(number of patterns,
    pattern of the longest run, its start, its end)``."""
    n, w = W.shape
    m = 0
    run0 = 0
    best = -1
    blo = 0
    bhi = 0
    for i in range(n):
        new = i == 0
        if not new:
            for c in range(w):
                if W[i, c] != W[i - 1, c]:
                    new = True
                    break
        if new:
            if i > 0 and i - run0 > bhi - blo:
                best, blo, bhi = m - 1, run0, i
            for c in range(w):
                Wu[m, c] = W[i, c]
            Wu[m, w] = 1.0 / W[i, w // 2]
            m += 1
            run0 = i
        pat[i] = m - 1
    if n - run0 > bhi - blo:
        best, blo, bhi = m - 1, run0, n
    return m, best, blo, bhi


@njit(cache=True)
def largest_free_z(W, p, closed, d, mask):
    """Largest unconstrained ranking number ``|(G d)_i|^2 / G_ii`` over the movable points (0
    if none): the residual of :func:`curvefair._kernels.bspline.band_residual` row by row, same
    operations, without the ``(n, dim)`` temporaries."""
    n, dim = d.shape
    best = 0.0
    first = True
    for i in range(n):
        if not mask[i]:
            continue
        interior = i >= p and i + p < n
        gg = 0.0
        for a in range(dim):
            acc = residual_row(W, 1.0, p, closed, d, i, a, interior)
            gg += acc * acc
        v = gg / W[i, p]
        if first or v > best:
            best = v
            first = False
    return best


@njit(cache=True, readonly=('W', 'd', 'mask'))
def setup_state(W, p, closed, d, mask, X, z):
    """One pass over the control points ``d``: the loop state ``X = [d | G d | d]`` (the
    residual of :func:`curvefair._kernels.bspline.band_residual`), the ranking-number slots
    ``z`` (0 movable, -1 fixed, from ``mask``) and the energy ``d^T G d``, returned. Each value
    is computed with the same operations in the same order as ``band_residual`` /
    ``band_energy`` (so bitwise equal to them); fused, the 1e6-point set-up reads ``d`` once."""
    n, dim = d.shape
    e = 0.0
    for i in range(n):
        interior = i >= p and i + p < n
        for a in range(dim):
            xi = d[i, a]
            acc = residual_row(W, 1.0, p, closed, d, i, a, interior)
            X[i, a] = xi
            X[i, dim + a] = acc
            X[i, 2 * dim + a] = xi
        e = energy_row(W, p, closed, d, i, e)
        z[i] = 0.0 if mask[i] else -1.0
    return e


# -- slow references (plain numpy, not compiled) ----------------------------------------------
def eh_loop_reference(c, l, tol, n_steps, mask, eps_rel):  # noqa: E741
    """Slow reference of :func:`eh_loop`: every ranking number recomputed from scratch.

    Each step builds the residual ``G d`` anew from the dense Gram matrix and scans every
    movable point for the largest tolerance-clamped energy drop, instead of the kernel's
    incremental residuals, band patterns and tournament tree: the obvious form of the ranking
    list the compiled loop is tested against (``tests/test_eck_hadenfeld.py``).

    Parameters
    ----------
    c : curvefair.BSplineCurve
        The curve (its ``control_points`` and ``gram_matrix(l)`` are read).
    l : int
        Order of the energy's derivative.
    tol : float or None
        Radius of the ball around each original control point, ``None`` for no tolerance.
    n_steps : int
        Largest number of steps.
    mask : numpy.ndarray
        ``True`` for the movable control points.
    eps_rel : float
        Stopping threshold relative to the initial energy.

    Returns
    -------
    tuple of (numpy.ndarray, list of int)
        The faired control points and the indices moved, in order.
    """
    d = np.array(c.control_points)
    orig = d.copy()
    G = c.gram_matrix(l).toarray()
    eps_abs = eps_rel * np.sum(d * (G @ d))
    idx = []
    for _ in range(n_steps):
        g = G @ d
        best, best_z, best_x = -1, -1.0, None
        for i in range(len(d)):
            if not mask[i]:
                continue
            xs = d[i] - g[i] / G[i, i]
            x = xs
            floor = 4e-16 * (np.abs(d[i]).max() + (tol or 0.0))
            if tol is not None:
                v = xs - orig[i]
                nv = np.linalg.norm(v)
                if nv > tol:
                    x = orig[i] + v * tol / nv
            if np.linalg.norm(x - d[i]) <= floor or np.linalg.norm(xs - d[i]) <= floor:
                continue  # a move below rounding is no move
            zi = G[i, i] * (np.sum((d[i] - xs) ** 2) - np.sum((x - xs) ** 2))
            if zi > best_z:
                best, best_z, best_x = i, zi, x
        if best_z <= 0 or best_z < eps_abs:
            break
        d[best] = best_x
        idx.append(best)
    return d, idx


def eh_drop_reference(G, d, orig, i, tol):
    """Slow reference of one step of :func:`eh_sweep`: ``(drop, move)`` of point ``i``.

    The tolerance-clamped energy minimiser over ``d_i``, from the dense Gram matrix ``G`` and
    the whole residual ``G[i] @ d`` computed from scratch (the kernel keeps it up to date);
    used by :func:`eh_sweep_reference` and by ``tests/test_eh_sweep.py``'s stopping test.

    Returns
    -------
    tuple of (float, numpy.ndarray)
        The energy drop (0 for a move below rounding) and the move of ``d_i``.
    """
    g = G[i] @ d
    s = -g / G[i, i]
    x = d[i] + s
    v = x - orig[i]
    nv = np.linalg.norm(v)
    if tol is not None and nv > tol:
        x = orig[i] + v * (tol / nv)
    e = x - d[i]
    floor = 4e-16 * (np.abs(d[i]).max() + (tol or 0.0))
    if np.linalg.norm(s) <= floor or np.linalg.norm(e) <= floor:
        return 0.0, np.zeros_like(e)
    return max(G[i, i] * (2 * e @ s - e @ e), 0.0), e


def _sweep_band(c, i):
    """Indices whose residual a move of d_i changes, in the order the schedule queues them."""
    n, p = c.n_ctrl, c.degree
    if c.closed:
        if 2 * p + 1 >= n:
            return list(range(n))
        return [(i + o) % n for o in range(-p, p + 1)]
    return [i + o for o in range(-p, p + 1) if 0 <= i + o < n]


def eh_sweep_reference(c, l, tol, eps_abs, mask, max_steps):  # noqa: E741
    """Slow reference of :func:`eh_sweep`: the documented first-in first-out schedule.

    Queue (index order) every movable point whose drop reaches the threshold; pop, fair it if
    its drop (recomputed) still does; queue every non-queued movable point of its band whose
    unconstrained drop ``|(G d)_j|^2 / G_jj`` reaches the threshold. Dense Gram matrix and
    every residual recomputed from scratch (no incremental updates): the obvious form the
    compiled sweep is tested against (``tests/test_eh_sweep.py``).

    Returns
    -------
    tuple of (numpy.ndarray, list of int)
        The faired control points and the indices moved, in order.
    """
    G = c.gram_matrix(l).toarray()
    d = np.array(c.control_points)
    orig = d.copy()

    def reaches(z):
        return z > 0.0 and z >= eps_abs

    q = deque(i for i in range(len(d))
              if mask[i] and reaches(eh_drop_reference(G, d, orig, i, tol)[0]))
    queued = set(q)
    order = []
    while q and len(order) < max_steps:
        i = q.popleft()
        queued.discard(i)
        z, e = eh_drop_reference(G, d, orig, i, tol)
        if not reaches(z):
            continue
        d[i] += e
        order.append(i)
        for j in _sweep_band(c, i):
            if mask[j] and j not in queued:
                g = G[j] @ d
                if reaches(g @ g / G[j, j]):
                    q.append(j)
                    queued.add(j)
    return d, order
