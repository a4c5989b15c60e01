"""Compiled kernels of the knot-removal method (:mod:`curvefair.fairing.knot_removal`).

:func:`knot_measure` is the Sapidis-Farin measure of one knot from the control points (scalar
code, the same on every CPU; :func:`measure_all` runs it over a set of knots), :func:`kr_loop`
the automatic loop: remove-and-reinsert the knot of the largest ranking number (one point or
least squares), update the measures of the neighbouring knots and the tournament tree
(:mod:`curvefair._kernels.ranking`), until a stopping rule holds.
"""

from __future__ import annotations

import numpy as np

from .._jit import njit
from .bspline import _ders_one
from .pairwise import pw_sum
from .ranking import tt_update, tt_update_range

# ------------------------------------------------------------------------------------------
# the compiled loop
# ------------------------------------------------------------------------------------------


@njit(cache=True, inline="always")
def ipow(x, k):
    """``x ** k`` for a whole ``k >= 1`` as ``k - 1`` multiplications in turn (no ``pow``: the
    same bits on every CPU; :func:`curvefair.fairing.knot_removal._speed_power` is its numpy
    twin)."""
    out = x
    for _ in range(k - 1):
        out = out * x
    return out


@njit(cache=True, inline="always")
def knot_measure(d, k, p, ctrl, C, right, left2):
    """:meth:`curvefair.fairing.knot_removal._KnotData.jumps` /
    :func:`curvefair.fairing.knot_removal.sapidis_measure` at one knot, same operation order."""
    num, speed = _measure_parts(d, k, p, ctrl, C, right, left2)
    return num / ipow(speed, 3 if p == 2 else p + 1)


@njit(cache=True, inline="always")
def _measure_parts(d, k, p, ctrl, C, right, left2):
    """Numerator and ``|r'|`` (``inf`` if zero) of the measure at knot ``k``: the measure is
    ``num / speed ** (p + 1)`` (``p = 2``: ``** 3``); numpy's operation order."""
    dim = d.shape[1]
    J0 = J1 = J2 = 0.0
    a0 = a1 = a2 = 0.0  # r'
    b0 = b1 = b2 = 0.0  # r'' right
    l0 = l1 = l2 = 0.0  # r'' left
    for a in range(p + 2):
        q = ctrl[k, a]
        c = C[k, a]
        J0 += c * d[q, 0]
        J1 += c * d[q, 1]
        if dim == 3:
            J2 += c * d[q, 2]
    # r'' (right) enters only a quadratic's or a 3-D curve's measure: a planar curve of
    # degree >= 3 passes no r'' table (right has one row per knot, see _KnotData)
    second = p == 2 or dim == 3
    for a in range(p + 1):
        q = ctrl[k, a + 1]
        c = right[k, 0, a]
        a0 += c * d[q, 0]
        a1 += c * d[q, 1]
        if dim == 3:
            a2 += c * d[q, 2]
        if second:
            c = right[k, 1, a]
            b0 += c * d[q, 0]
            b1 += c * d[q, 1]
            if dim == 3:
                b2 += c * d[q, 2]
    if p == 2:
        for a in range(p + 1):
            q = ctrl[k, a]
            c = left2[k, a]
            l0 += c * d[q, 0]
            l1 += c * d[q, 1]
            if dim == 3:
                l2 += c * d[q, 2]
    if dim == 2:
        ss = a0 * a0 + a1 * a1
    else:
        ss = a0 * a0 + a1 * a1 + a2 * a2
    speed = np.sqrt(ss)
    if not speed > 0:
        speed = np.inf
    if p == 2:
        if dim == 2:
            return abs((a0 * b1 - a1 * b0) - (a0 * l1 - a1 * l0)), speed
        x0 = a1 * b2 - a2 * b1
        x1 = a2 * b0 - a0 * b2
        x2 = a0 * b1 - a1 * b0
        kr = np.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
        x0 = a1 * l2 - a2 * l1
        x1 = a2 * l0 - a0 * l2
        x2 = a0 * l1 - a1 * l0
        kl = np.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
        return abs(kr - kl), speed
    if dim == 2:
        return abs(a0 * J1 - a1 * J0), speed
    c0 = a1 * J2 - a2 * J1
    c1 = a2 * J0 - a0 * J2
    c2 = a0 * J1 - a1 * J0
    x0 = a1 * b2 - a2 * b1
    x1 = a2 * b0 - a0 * b2
    x2 = a0 * b1 - a1 * b0
    nb = np.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
    scale = np.sqrt(a0 * a0 + a1 * a1 + a2 * a2) * np.sqrt(b0 * b0 + b1 * b1 + b2 * b2)
    if nb > 1e-12 * scale:
        v = abs(x0 * c0 + x1 * c1 + x2 * c2) / nb
    else:
        v = np.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
    return v, speed


@njit(cache=True, inline="always")
def _knot_tables_body(knots, p, js, lo, hi, nder, two, c, right, left2):
    """The loop of :func:`knot_tables`, inlined with ``p`` and ``nder`` as passed (constants:
    the loops unrolled, the same operations in the same order)."""
    ndu = np.empty((p + 1, p + 1))
    lw = np.empty(p + 1)
    rw = np.empty(p + 1)
    a = np.empty((2, p + 1))
    R = np.empty((1, nder + 1, p + 1))
    L = np.empty((1, nder + 1, p + 1))
    q0 = np.intp(0)
    for q in range(lo, hi):
        j = js[q]
        # right limit at t_j: span j at local offset 0; left limit: span j - 1 at offset
        # t_j - t_{j-1} (both local: equal knot patterns give equal values)
        _ders_one(knots, p, j, 0.0, knots[j], nder, ndu, lw, rw, a, R, q0)
        _ders_one(knots, p, j - 1, knots[j] - knots[j - 1], knots[j - 1], nder, ndu, lw, rw,
                  a, L, q0)
        for i in range(p + 2):
            c[q, i] = 0.0
        for i in range(p + 1):
            c[q, i + 1] += R[0, p, i]
        for i in range(p + 1):
            c[q, i] -= L[0, p, i]
        for i in range(p + 1):
            right[q, 0, i] = R[0, 1, i]
            if two:
                right[q, 1, i] = R[0, 2, i]
            if p == 2:
                left2[q, i] = L[0, 2, i]


@njit(cache=True, nogil=True, readonly=('knots', 'js'))
def knot_tables(knots, p, js, lo, hi, nder, two, c, right, left2):
    """Per-knot basis tables of the Sapidis-Farin measure for knots ``js[lo:hi]`` (rows
    ``lo .. hi - 1`` of the outputs; the ranges are independent, for two threads):
    ``c[q]`` the jump coefficients of the ``p``-th derivative at ``t_j`` (basis functions
    ``j - p - 1 .. j``: right limit minus left limit), ``right[q]`` the right limits of the
    first (and, ``two``, second) derivatives, ``left2[q]`` (``p = 2``) the left limit of the
    second. Piegl & Tiller A2.3 up to derivative ``nder`` (:func:`curvefair._kernels.bspline.
    _ders_one`, whose values do not depend on the highest derivative asked); a cubic's loop is
    compiled for ``p = 3``."""
    if p == 3 and nder == 3:
        _knot_tables_body(knots, 3, js, lo, hi, 3, two, c, right, left2)
    else:
        _knot_tables_body(knots, p, js, lo, hi, nder, two, c, right, left2)


@njit(cache=True, nogil=True, readonly=('d',))
def measure_all(d, ks, p, ctrl, C, right, left2, out):
    for u in range(ks.shape[0]):
        out[u] = knot_measure(d, ks[u], p, ctrl, C, right, left2)


@njit(cache=True, inline="always")
def _ls_moves(d, k, p, ctrl, alphas, new, Q, A, f):
    """Least-squares removal (seed 004 eqs. (8.24)-(8.30)) at knot ``k``: the ``p`` new control
    points of basis functions ``j-p .. j-1`` into ``new``; ``Q`` (p+2, dim), ``A`` (p, p-1),
    ``f`` (p, dim) are work arrays. Householder QR of the ``p x (p-1)`` removal system."""
    dim = d.shape[1]
    for a in range(p + 2):
        q = ctrl[k, a]
        for e in range(dim):
            Q[a, e] = d[q, e]
    A[:, :] = 0.0
    for r in range(p):
        al = alphas[k, r]
        for e in range(dim):
            f[r, e] = Q[r + 1, e]
        if r <= p - 2:
            A[r, r] = al
        else:
            for e in range(dim):
                f[r, e] -= al * Q[p + 1, e]
        if r >= 1:
            A[r, r - 1] = 1.0 - al
        else:
            for e in range(dim):
                f[r, e] -= (1.0 - al) * Q[0, e]
    m = p
    nc = p - 1
    for c in range(nc):  # Householder: zero A[c+1:, c], apply to f
        s = 0.0
        for r in range(c, m):
            s += A[r, c] * A[r, c]
        nrm = np.sqrt(s)
        if nrm == 0.0:
            continue
        alpha = -nrm if A[c, c] >= 0 else nrm
        v0 = A[c, c] - alpha
        vv = s - A[c, c] * A[c, c] + v0 * v0
        A[c, c] = v0
        if vv > 0:
            for c2 in range(c + 1, nc):
                s2 = 0.0
                for r in range(c, m):
                    s2 += A[r, c] * A[r, c2]
                g = 2.0 * s2 / vv
                for r in range(c, m):
                    A[r, c2] -= g * A[r, c]
            for e in range(dim):
                s2 = 0.0
                for r in range(c, m):
                    s2 += A[r, c] * f[r, e]
                g = 2.0 * s2 / vv
                for r in range(c, m):
                    f[r, e] -= g * A[r, c]
        A[c, c] = alpha
    for e in range(dim):  # back substitution R P = (Q^T f)[:p-1]
        for c in range(nc - 1, -1, -1):
            s = f[c, e]
            for c2 in range(c + 1, nc):
                s -= A[c, c2] * f[c2, e]
            f[c, e] = s / A[c, c]
    # reinsertion (8.29)-(8.30): new_r = al_r P_r + (1 - al_r) P_{r-1}, with P_{-1} = Q_0 and
    # P_{p-1} = Q_{p+1}
    for r in range(p):
        al = alphas[k, r]
        for e in range(dim):
            hi = f[r, e] if r <= p - 2 else Q[p + 1, e]
            lo = f[r - 1, e] if r >= 1 else Q[0, e]
            new[r, e] = al * hi + (1.0 - al) * lo


@njit(cache=True, readonly=('orig',))
def kr_loop(d, orig, mask, tol, p, n, closed, js, pos, C, right, left2, ctrl, a1, denom,
            alphas, lsq, eps_abs, max_steps, stop_on_tol, z, rank, tv, ti, total,
            cap, floor):
    """The Sapidis-Farin loop (see :func:`curvefair.fairing.knot_removal.knot_removal_fair`);
    returns ``(steps, reason code, tracked sum, history, blocked knots, number blocked)``. ``d``,
    ``z``, ``rank`` and the tree are updated in place. Per step: the removal moves (one point, or a
    ``p x (p-1)`` least squares solve), the measure at the ``<= 2p+1`` touched knots, ``O(log N)``
    tree updates."""
    dim = d.shape[1]
    nk = js.shape[0]
    nt = pos.shape[0]
    nm = p if lsq else 1
    idx = np.empty(nm, dtype=np.int64)
    new = np.empty((nm, dim))
    old = np.empty((nm, dim))
    Q = np.empty((p + 2, dim))
    A = np.empty((p, max(p - 1, 1)))
    f = np.empty((p, dim))
    tk = np.empty(nm * (p + 2), dtype=np.int64)
    zold = np.empty(nm * (p + 2))
    znew = np.empty(nm * (p + 2))
    hist = np.empty((max(cap, 1), 3))
    blocked = np.empty(nk, dtype=np.int64)
    nb = 0
    steps = 0
    code = 0  # max_steps
    while steps < max_steps:
        k = ti[1]
        zk = tv[1]
        if zk < 0:  # every knot blocked
            code = 1
            break
        if zk <= eps_abs or zk <= floor:
            code = 2
            break
        j = js[k]
        if lsq:
            _ls_moves(d, k, p, ctrl, alphas, new, Q, A, f)
            for r in range(p):
                idx[r] = ctrl[k, r + 1]
        else:
            a = a1[k]
            q = ctrl[k, a]
            idx[0] = q
            g = denom[k]
            for e in range(dim):
                # the jump c @ d[idx] summed as numpy's matmul does (OpenBLAS dgemv: the first
                # four products pairwise, then the rest in turn), so that the move is bitwise
                # the vectorised one for p <= 5
                s = ((C[k, 0] * d[ctrl[k, 0], e] + C[k, 1] * d[ctrl[k, 1], e])
                     + (C[k, 2] * d[ctrl[k, 2], e] + C[k, 3] * d[ctrl[k, 3], e]))
                for b in range(4, p + 2):
                    s += C[k, b] * d[ctrl[k, b], e]
                new[0, e] = d[q, e] - s / g
        ok = True
        for r in range(nm):
            if not mask[idx[r]]:
                ok = False
        if ok and tol < np.inf:
            for r in range(nm):
                q = idx[r]
                ss = 0.0
                for e in range(dim):
                    x = new[r, e] - orig[q, e]
                    ss += x * x
                if not np.sqrt(ss) <= tol:
                    ok = False
        if not ok:
            if stop_on_tol:
                code = 1
                break
            rank[k] = -1.0
            tt_update(tv, ti, k, -1.0)
            blocked[nb] = j
            nb += 1
            continue
        for r in range(nm):
            q = idx[r]
            for e in range(dim):
                old[r, e] = d[q, e]
        for r in range(nm):
            q = idx[r]
            for e in range(dim):
                d[q, e] = new[r, e]
        # knot j's measure depends on the control points of basis functions j-p-1 .. j, so a
        # moved control point b touches the knots b .. b+p+1 (closed: their period copies);
        # sorted and unique, as np.unique gives them
        m = 0
        for r in range(nm):
            for a in range(p + 2):
                jj = idx[r] + a
                if closed:
                    jj = p + (jj - p) % n
                if jj < 0 or jj >= nt:
                    continue
                kk = pos[jj]
                if kk < 0:
                    continue
                dup = False
                for u in range(m):
                    if tk[u] == kk:
                        dup = True
                        break
                if dup:
                    continue
                u = m  # insertion sort (at most 2p+1 entries)
                while u > 0 and tk[u - 1] > kk:
                    tk[u] = tk[u - 1]
                    u -= 1
                tk[u] = kk
                m += 1
        for u in range(m):
            kk = tk[u]
            zold[u] = z[kk]
            znew[u] = knot_measure(d, kk, p, ctrl, C, right, left2)
        new_total = total - pw_sum(zold, m) + pw_sum(znew, m)
        if new_total >= total - floor:
            for r in range(nm - 1, -1, -1):
                q = idx[r]
                for e in range(dim):
                    d[q, e] = old[r, e]
            code = 3
            break
        total = new_total
        for u in range(m):
            kk = tk[u]
            zz = znew[u]
            z[kk] = zz
            if rank[kk] >= 0:
                rank[kk] = zz
        # the tree holds a function of the leaves (ties to the smaller index), so one range
        # repair over a contiguous run of touched knots leaves it as the single updates would
        if m > 0 and tk[m - 1] - tk[0] < 2 * m:
            tt_update_range(tv, ti, tk[0], tk[m - 1], rank)
        else:
            for u in range(m):
                kk = tk[u]
                if rank[kk] >= 0:
                    tt_update(tv, ti, kk, rank[kk])
        if steps >= hist.shape[0]:
            h2 = np.empty((2 * hist.shape[0], 3))
            h2[:steps] = hist[:steps]
            hist = h2
        mv = -np.inf
        for r in range(nm):
            ss = 0.0
            for e in range(dim):
                x = new[r, e] - old[r, e]
                ss += x * x
            v = np.sqrt(ss)
            if v > mv or v != v:
                mv = v
        hist[steps, 0] = j
        hist[steps, 1] = zk
        hist[steps, 2] = mv
        steps += 1
    return steps, code, total, hist, blocked, nb
