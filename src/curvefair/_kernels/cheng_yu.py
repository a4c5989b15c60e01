"""Compiled kernels of Cheng & Yu's method (:mod:`curvefair.fairing.cheng_yu`): cubic B-splines
faired with the second discrete curvature.

:func:`plan` computes the move of one control point (or of two consecutive ones) and its
modifying factor, shared by the single step :func:`curvefair.fairing.cheng_yu.cheng_yu` and the
automatic method; :func:`cy_loop` is the automatic method's ranking loop with local updates
(:func:`curvefair.fairing.cheng_yu.cheng_yu_driver`), its stop codes :data:`NONE_LEFT`,
:data:`EPS`, :data:`MAX_STEPS`, :data:`CONVERGED`.

Indices are 0-based (the paper's ``Q_0 .. Q_n`` are ``control_points[0 .. n]``).
"""

from __future__ import annotations

import numpy as np

from .._jit import njit
from .ranking import tt_build, tt_top, tt_update, tt_update_range

_P = 3  # cubic
_BISECT = 64
_SAMPLES = 32


# --------------------------------------------------------------------------------------------
# compiled kernels shared by the single step and the driver
# --------------------------------------------------------------------------------------------
@njit(cache=True, inline="always")
def _gram(W, n, closed, m, j):
    """``G[m, j]`` from the band ``W`` (aliased offsets of a short closed curve add up)."""
    s = 0.0
    for o in range(-_P, _P + 1):
        k = m + o
        if closed:
            k = k % n
        elif k < 0 or k >= n:
            continue
        if k == j:
            s += W[m, _P + o]
    return s


@njit(cache=True, inline="always")
def _residual(W, Q, n, closed, m, out):
    """``out = sum_{i != m} d_i Q_i - Q_m = -(G Q)_m / G_mm`` (eq. (8) target minus current)."""
    dim = Q.shape[1]
    for c in range(dim):
        out[c] = 0.0
    for o in range(-_P, _P + 1):
        k = m + o
        if closed:
            k = k % n
        elif k < 0 or k >= n:
            continue
        w = W[m, _P + o]
        for c in range(dim):
            out[c] += w * Q[k, c]
    g = W[m, _P]
    for c in range(dim):
        out[c] = -out[c] / g


@njit(cache=True, inline="always")
def _move_of(s, r0c, r1c, a, b, pair):
    """One coordinate of the displacements at ``s = 1 - d``: single ``s r0``; pair
    ``s A(s)^-1 [r0, r1]`` (eq. (9)). The one formula of both the moves made (:func:`_moves`)
    and the bound checked along the way (:func:`_excess`), so the two cannot differ."""
    if not pair:
        return s * r0c, 0.0
    den = 1.0 - s * s * a * b
    return s * (r0c + s * a * r1c) / den, s * (r1c + s * b * r0c) / den


@njit(cache=True, inline="always")
def _moves(s, r0, r1, a, b, pair, out0, out1):
    """Displacements at ``s`` (:func:`_move_of`) into ``out0`` (and ``out1`` if ``pair``)."""
    for c in range(r0.shape[0]):
        m0, m1 = _move_of(s, r0[c], r1[c], a, b, pair)
        out0[c] = m0
        if pair:
            out1[c] = m1


@njit(cache=True, inline="always")
def _excess(x, s, a, b, pair, e, three):
    """``max_j |Q_j + move_j(s) - Q0_j| - e`` over the moved points (the move by
    :func:`_move_of`, as :func:`_moves` makes it). ``x`` holds the rows as scalars
    (:func:`_rows`): the bisection evaluates this about a hundred times per pair, and array
    arguments would cost each evaluation its reference counting."""
    (q0x, q0y, q0z, o0x, o0y, o0z, q1x, q1y, q1z, o1x, o1y, o1z,
     r0x, r0y, r0z, r1x, r1y, r1z) = x
    m0x, m1x = _move_of(s, r0x, r1x, a, b, pair)
    m0y, m1y = _move_of(s, r0y, r1y, a, b, pair)
    m0z, m1z = _move_of(s, r0z, r1z, a, b, pair)
    worst = _moved_distance(q0x, q0y, q0z, m0x, m0y, m0z, o0x, o0y, o0z, three)
    if pair:
        worst = max(worst, _moved_distance(q1x, q1y, q1z, m1x, m1y, m1z, o1x, o1y, o1z,
                                           three))
    return worst - e


@njit(cache=True, inline="always")
def _moved_distance(qx, qy, qz, mx, my, mz, ox, oy, oz, three):
    """``|q + m - o|`` (``dim`` 2 unless ``three``), summed as :func:`_excess` always has."""
    d2 = 0.0
    v = qx + mx - ox
    d2 += v * v
    v = qy + my - oy
    d2 += v * v
    if three:
        v = qz + mz - oz
        d2 += v * v
    return np.sqrt(d2)


@njit(cache=True, inline="always")
def _rows(Q, Q0, m0, m1, r0, r1, pair):
    """The rows :func:`_excess` reads, as a tuple of 18 floats (``dim`` 2: the first
    coordinates again in the third places, never read; one point: ``Q[m0]`` and ``Q0[m0]``
    again in the second point's places and ``r1``, never read)."""
    three = Q.shape[1] == 3
    z = 2 if three else 0  # (an index that exists; its values are not used in 2-D)
    j = m1 if pair else m0
    return (Q[m0, 0], Q[m0, 1], Q[m0, z], Q0[m0, 0], Q0[m0, 1], Q0[m0, z],
            Q[j, 0], Q[j, 1], Q[j, z], Q0[j, 0], Q0[j, 1], Q0[j, z],
            r0[0], r0[1], r0[z], r1[0], r1[1], r1[z])


@njit(cache=True)
def _step_factor(Q, Q0, m0, m1, r0, r1, a, b, pair, e):
    """Largest ``s = 1 - d`` in ``[0, 1]`` with the error bound kept on all of ``[0, s]``
    (one point: closed form; two points: sampled, then bisected). The returned ``s`` satisfies
    the bound as computed."""
    if e == np.inf:  # no bound
        return 1.0
    e = e * (1.0 - 1e-12)  # margin: the bound then survives any re-rounding of the distance
    x = _rows(Q, Q0, m0, m1, r0, r1, pair)
    three = Q.shape[1] == 3
    if not pair:
        # the segment Q + s r meets the ball |x - Q0| <= e in an interval containing s = 0:
        # its upper end in closed form, |p + s r|^2 = e^2 with p = Q - Q0
        rr = 0.0
        pr = 0.0
        pp = 0.0
        for c in range(Q.shape[1]):
            p = Q[m0, c] - Q0[m0, c]
            rr += r0[c] * r0[c]
            pr += p * r0[c]
            pp += p * p
        if rr == 0.0:
            return 1.0
        es = e * (1.0 - 1e-12)  # aim a hair inside, so the check below passes at once
        disc = pr * pr - rr * (pp - es * es)
        if disc < 0.0:
            disc = 0.0
        if pr <= 0.0:
            s = (np.sqrt(disc) - pr) / rr
        else:
            s = (es * es - pp) / (pr + np.sqrt(disc))
        s = min(max(s, 0.0), 1.0)
        for _ in range(60):  # guard against rounding: shrink until the computed point is inside
            if _excess(x, s, a, b, pair, e, three) <= 0.0:
                return s
            s *= 1.0 - 1e-12
        return 0.0
    if _excess(x, 1.0, a, b, pair, e, three) <= 0.0:
        # still check the path for a rational curve leaving and re-entering the ball
        ok = True
        for k in range(1, _SAMPLES):
            if _excess(x, k / _SAMPLES, a, b, pair, e, three) > 0.0:
                ok = False
                break
        if ok:
            return 1.0
    lo = 0.0
    hi = 1.0
    for k in range(1, _SAMPLES + 1):
        sk = k / _SAMPLES
        if _excess(x, sk, a, b, pair, e, three) > 0.0:
            hi = sk
            break
        lo = sk
    for _ in range(_BISECT):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        if _excess(x, mid, a, b, pair, e, three) > 0.0:
            hi = mid
        else:
            lo = mid
    return lo


@njit(cache=True, readonly=('Q0', 'W'))
def plan(Q, Q0, W, n, closed, m0, pair, e, dfix, new0, new1):
    """New positions of ``Q[m0]`` (and ``Q[m0+1]`` if ``pair``); returns the factor ``d`` used.

    ``e = inf`` means no bound; ``dfix >= 0`` forces the factor.
    """
    dim = Q.shape[1]
    return _plan_into(Q, Q0, W, n, closed, m0, pair, e, dfix, new0, new1, np.zeros(dim),
                      np.zeros(dim), np.zeros(dim), np.zeros(dim))


@njit(cache=True)
def _plan_into(Q, Q0, W, n, closed, m0, pair, e, dfix, new0, new1, r0, r1, tmp0, tmp1):
    """:func:`plan` with its work vectors (``dim`` each) given: the ranking loop calls it for
    every attempted move, so it allocates nothing."""
    dim = Q.shape[1]
    m1 = (m0 + 1) % n if closed else m0 + 1
    for c in range(dim):
        r0[c] = 0.0
        r1[c] = 0.0
        tmp0[c] = 0.0
        tmp1[c] = 0.0
    _residual(W, Q, n, closed, m0, r0)
    a = 0.0
    b = 0.0
    if pair:
        _residual(W, Q, n, closed, m1, r1)
        a = -_gram(W, n, closed, m0, m1) / W[m0, _P]
        b = -_gram(W, n, closed, m1, m0) / W[m1, _P]
    if dfix >= 0.0:
        s = 1.0 - dfix
    else:
        s = _step_factor(Q, Q0, m0, m1, r0, r1, a, b, pair, e)
    _moves(s, r0, r1, a, b, pair, tmp0, tmp1)
    for c in range(dim):
        new0[c] = Q[m0, c] + tmp0[c]
        if pair:
            new1[c] = Q[m1, c] + tmp1[c]
    return 1.0 - s


# --------------------------------------------------------------------------------------------
# the automatic method: compiled ranking loop with local updates
# --------------------------------------------------------------------------------------------
NONE_LEFT = 0  # movable bad points remain, none can lower x
EPS = 1  # largest z of a movable bad point below the threshold
MAX_STEPS = 2
CONVERGED = 3  # no movable bad point at all


@njit(cache=True, inline="always")
def _k_at(Q, lw, mw, i, n, closed, planar):
    """``K_i`` (eq. (3)); the same arithmetic as ``second_curvature_values`` (``dim`` 2 or 3;
    the edge vectors in scalars: the loop evaluates it a few times per attempted move)."""
    if not closed and (i == 0 or i == n - 1):
        return 0.0
    ip = (i - 1) % n
    inx = (i + 1) % n
    three = Q.shape[1] == 3
    a0 = Q[i, 0] - Q[ip, 0]
    a1 = Q[i, 1] - Q[ip, 1]
    b0 = Q[inx, 0] - Q[i, 0]
    b1 = Q[inx, 1] - Q[i, 1]
    a2 = 0.0
    b2 = 0.0
    if three:
        a2 = Q[i, 2] - Q[ip, 2]
        b2 = Q[inx, 2] - Q[i, 2]
    if planar:
        area = 0.5 * (a0 * b1 - a1 * b0)
    else:
        cx = a1 * b2 - a2 * b1
        cy = a2 * b0 - a0 * b2
        cz = a0 * b1 - a1 * b0
        area = 0.5 * np.sqrt(cx * cx + cy * cy + cz * cz)
    if area == 0.0:
        return 0.0
    w = lw[i] * a0 + mw[i] * b0
    s = w * w
    w = lw[i] * a1 + mw[i] * b1
    s += w * w
    if three:
        w = lw[i] * a2 + mw[i] * b2
        s += w * w
    wn = np.sqrt(s)
    if wn == 0.0:
        return 0.0
    return area / wn**3


@njit(cache=True, inline="always")
def _t_at(Q, i, n, closed):
    if not closed and (i == 0 or i == n - 1):
        return 0.5
    ip = (i - 1) % n
    inx = (i + 1) % n
    a = 0.0
    b = 0.0
    for c in range(Q.shape[1]):
        u = Q[i, c] - Q[ip, c]
        v = Q[inx, c] - Q[i, c]
        a += u * u
        b += v * v
    a = np.sqrt(a)
    b = np.sqrt(b)
    s = a + b
    if s > 0.0:
        return b / s
    return 0.5


@njit(cache=True, inline="always")
def _valid(i, n, closed):
    return closed or (2 <= i <= n - 3)


@njit(cache=True, inline="always")
def _d_at(K, t, i, n, closed):
    if not closed and (i == 0 or i == n - 1):
        return 0.0
    return t[i] * K[(i - 1) % n] + (1.0 - t[i]) * K[(i + 1) % n] - K[i]


@njit(cache=True, inline="always")
def _flags_at(K, t, i, n, closed):
    """Bit mask of the bad-point kinds at ``i`` (1, 2, 4 for kinds 1, 2, 3), as in
    ``bad_point_kinds``."""
    if not _valid(i, n, closed):
        return 0
    kp = K[(i - 1) % n]
    k = K[i]
    kn = K[(i + 1) % n]
    f = 0
    if k * kn <= 0.0 and kp * k > 0.0:
        f |= 1
    if (k - kp) * (kn - k) < 0.0:
        f |= 2
    same = (kp > 0 and k > 0 and kn > 0) or (kp < 0 and k < 0 and kn < 0)
    if same and not (abs(k) > 0.5 * ((1.0 - t[i]) * abs(kp) + t[i] * abs(kn))):
        f |= 4
    return f


@njit(cache=True)
def _index_range(lo, hi, n, closed, out):
    """Distinct indices ``lo .. hi`` (cyclic or clipped) written to ``out``; returns how many."""
    if closed:
        if hi - lo + 1 >= n:
            for k in range(n):
                out[k] = k
            return n
        for k in range(lo, hi + 1):
            out[k - lo] = k % n
        return hi - lo + 1
    a = max(lo, 0)
    b = min(hi, n - 1)
    if b < a:
        return 0
    for k in range(a, b + 1):
        out[k - a] = k
    return b - a + 1


@njit(cache=True, inline="always")
def _priority(D, flags, movable, frozen, i):
    if flags[i] != 0 and movable[i] and not frozen[i]:
        return D[i] * D[i]
    return -np.inf


@njit(cache=True)
def _try_step(Q, Q0, W, lw, mw, K, t, D, n, closed, planar, m0, pair, e, min_drop, new0,
              new1, r0, r1, tmp0, tmp1, old_k, old_t, old_d, kr, dr):
    """Move ``m0`` (and ``m0 + 1``); keep it iff ``sum D_i**2`` over the touched valid indices
    drops by more than ``min_drop``. Returns ``(accepted, local change of x)``. The rest are
    work space (``new0`` .. ``tmp1``: ``dim`` floats; ``old_*``, ``kr``, ``dr``: 6 at least):
    the loop attempts several moves per step taken, and none allocates or makes a view."""
    dim = Q.shape[1]
    m1 = (m0 + 1) % n if closed else m0 + 1
    for c in range(dim):
        new0[c] = 0.0
        new1[c] = 0.0
    _plan_into(Q, Q0, W, n, closed, m0, pair, e, -1.0, new0, new1, r0, r1, tmp0, tmp1)
    changed = False
    for c in range(dim):
        if new0[c] != Q[m0, c] or (pair and new1[c] != Q[m1, c]):
            changed = True
    if not changed:
        return False, 0.0
    last = m0 + 1 if pair else m0
    nk = _index_range(m0 - 1, last + 1, n, closed, kr)
    nd = _index_range(m0 - 2, last + 2, n, closed, dr)
    old_q0 = r0  # (the plan's work vectors are free again)
    old_q1 = r1
    for c in range(dim):
        old_q0[c] = Q[m0, c]
        old_q1[c] = Q[m1, c] if pair else Q[m0, c]
    for r in range(nk):
        old_k[r] = K[kr[r]]
        old_t[r] = t[kr[r]]
    for r in range(nd):
        old_d[r] = D[dr[r]]
    before = 0.0
    for r in range(nd):
        j = dr[r]
        if _valid(j, n, closed):
            before += D[j] * D[j]
    for c in range(dim):
        Q[m0, c] = new0[c]
    if pair:
        for c in range(dim):
            Q[m1, c] = new1[c]
    for r in range(nk):
        j = kr[r]
        K[j] = _k_at(Q, lw, mw, j, n, closed, planar)
        t[j] = _t_at(Q, j, n, closed)
    after = 0.0
    for r in range(nd):
        j = dr[r]
        D[j] = _d_at(K, t, j, n, closed)
        if _valid(j, n, closed):
            after += D[j] * D[j]
    if before - after > min_drop:
        return True, after - before
    for c in range(dim):
        Q[m0, c] = old_q0[c]
    if pair:
        for c in range(dim):
            Q[m1, c] = old_q1[c]
    for r in range(nk):
        K[kr[r]] = old_k[r]
        t[kr[r]] = old_t[r]
    for r in range(nd):
        D[dr[r]] = old_d[r]
    return False, 0.0


@njit(cache=True)
def cy_loop(Q, Q0, W, lw, mw, closed, planar, movable, e, eps, max_steps,
            allow_pair, hist, moves):
    """The ranking loop. ``hist[k]`` = x after ``k`` accepted steps; ``moves[k]`` = (first moved
    index, 1 or 2 points, ``z`` of the top bad point, largest displacement). ``hist`` (at least
    one row) and ``moves`` are the first buffers: when a step finds them full they are
    replaced by copies of twice the length (at most what ``max_steps`` needs), so memory
    follows the steps taken, not the cap (``100 n`` by default: 30 GB of buffers at 1e7 control
    points if allocated up front). Returns ``(steps, reason, hist, moves)``, the last two the
    buffers in use."""
    n = Q.shape[0]
    K = np.zeros(n)
    t = np.full(n, 0.5)
    D = np.zeros(n)
    for i in range(n):
        K[i] = _k_at(Q, lw, mw, i, n, closed, planar)
        t[i] = _t_at(Q, i, n, closed)
    x = 0.0
    for i in range(n):
        D[i] = _d_at(K, t, i, n, closed)
        if _valid(i, n, closed):
            x += D[i] * D[i]
    flags = np.zeros(n, dtype=np.int64)
    frozen = np.zeros(n, dtype=np.bool_)
    pr = np.empty(n)
    for i in range(n):
        flags[i] = _flags_at(K, t, i, n, closed)
        pr[i] = _priority(D, flags, movable, frozen, i)
    tv, ti = tt_build(pr)
    # work space of the attempted moves (:func:`_try_step`) and of the neighbourhood updates
    dim = Q.shape[1]
    w_new0 = np.zeros(dim)
    w_new1 = np.zeros(dim)
    w_r0 = np.zeros(dim)
    w_r1 = np.zeros(dim)
    w_tmp0 = np.zeros(dim)
    w_tmp1 = np.zeros(dim)
    w_k = np.zeros(8)
    w_t = np.zeros(8)
    w_d = np.zeros(8)
    w_kr = np.zeros(8, dtype=np.int64)
    w_dr = np.zeros(8, dtype=np.int64)
    q_first = np.zeros(dim)
    q_second = np.zeros(dim)
    hist[0] = x
    steps = 0
    reason = CONVERGED
    while True:
        m, zm = tt_top(tv, ti)
        if zm == -np.inf:
            reason = CONVERGED
            for i in range(n):
                if frozen[i] and flags[i] != 0 and movable[i]:
                    reason = NONE_LEFT
                    break
            break
        if zm < eps:
            reason = EPS
            break
        if steps >= max_steps:
            reason = MAX_STEPS
            break
        first = m
        pair = False
        if allow_pair:
            tt_update(tv, ti, m, -np.inf)
            m2, z2 = tt_top(tv, ti)
            tt_update(tv, ti, m, zm)
            if z2 != -np.inf and z2 >= eps:
                if (closed and (m2 - m) % n == 1) or (not closed and m2 == m + 1):
                    pair = True
                elif (closed and (m - m2) % n == 1) or (not closed and m2 == m - 1):
                    pair = True
                    first = m2
        for c in range(Q.shape[1]):
            q_first[c] = Q[first, c]
            q_second[c] = Q[(first + 1) % n, c]
        ok, dx = _try_step(Q, Q0, W, lw, mw, K, t, D, n, closed, planar, first, pair, e,
                           eps, w_new0, w_new1, w_r0, w_r1, w_tmp0, w_tmp1, w_k, w_t, w_d,
                           w_kr, w_dr)
        if not ok and pair:
            pair = False
            first = m
            # (the displacement is measured from the point moved: ``m``, not ``m - 1``)
            for c in range(Q.shape[1]):
                q_first[c] = Q[first, c]
            ok, dx = _try_step(Q, Q0, W, lw, mw, K, t, D, n, closed, planar, m,
                               np.bool_(False), e, eps, w_new0, w_new1, w_r0, w_r1, w_tmp0,
                               w_tmp1, w_k, w_t, w_d, w_kr, w_dr)
        if not ok:
            frozen[m] = True
            tt_update(tv, ti, m, -np.inf)
            continue
        steps += 1
        x += dx
        if steps >= hist.shape[0] or steps > moves.shape[0]:
            cap = 2 * hist.shape[0]
            if cap > max_steps + 1:
                cap = max_steps + 1
            h2 = np.zeros(cap)
            h2[:steps] = hist[:steps]
            m2 = np.zeros((cap - 1, 4))
            m2[:steps - 1] = moves[:steps - 1]
            hist = h2
            moves = m2
        hist[steps] = x
        moves[steps - 1, 0] = first
        moves[steps - 1, 1] = 2 if pair else 1
        moves[steps - 1, 2] = zm
        disp = 0.0
        for c in range(Q.shape[1]):
            disp += (Q[first, c] - q_first[c]) ** 2
        disp = np.sqrt(disp)
        if pair:
            d2 = 0.0
            for c in range(Q.shape[1]):
                d2 += (Q[(first + 1) % n, c] - q_second[c]) ** 2
            disp = max(disp, np.sqrt(d2))
        moves[steps - 1, 3] = disp
        last = first + 1 if pair else first
        # first - 4 .. last + 4 (10 indices at most; cyclic: at most two pieces), re-ranked
        # together (each block rescanned and each ancestor repaired once; the tree is a
        # function of the entries' values, so it is the tree the updates one by one made)
        lo = first - 4
        hi = last + 4
        if closed and hi - lo + 1 >= n:
            lo = 0
            hi = n - 1
        elif not closed:
            lo = max(lo, 0)
            hi = min(hi, n - 1)
        for k in range(lo, hi + 1):
            frozen[k % n] = False
        for k in range(lo, hi + 1):
            j = k % n
            flags[j] = _flags_at(K, t, j, n, closed)
            pr[j] = _priority(D, flags, movable, frozen, j)
        if lo < 0:
            tt_update_range(tv, ti, lo + n, n - 1, pr)
            tt_update_range(tv, ti, 0, hi, pr)
        elif hi >= n:
            tt_update_range(tv, ti, lo, n - 1, pr)
            tt_update_range(tv, ti, 0, hi - n, pr)
        else:
            tt_update_range(tv, ti, lo, hi, pr)
    return steps, reason, hist, moves
