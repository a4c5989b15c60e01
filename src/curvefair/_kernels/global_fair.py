"""Compiled kernels of :mod:`curvefair.fairing.global_fair`: block-banded Newton systems.

The Newton systems of the global fairing QP have the form (``n`` points, ``dim`` coordinates,
unknowns interleaved: point ``i``, coordinate ``a`` is unknown ``i dim + a``)::

    M = Q^T (kron(K, I_dim) + blockdiag(B_i)) Q,   K = 2 G / E0 (banded, bandwidth p),

with one orthogonal ``dim x dim`` frame ``Q_i`` per point (the identity unless ``rot[i]``) and
some unknowns fixed (``fix[i, a]``: row and column replaced by the identity). ``M`` is banded
with bandwidth ``kd = (p + 1) dim - 1`` (open curves) or cyclic-banded (closed curves).

Storage: ``L[r, k] = M[r + k, r]`` (``k = 0 .. kd``; closed curves: row ``(r + k) mod N``), one
row per unknown, factorised in place: open curves ``U D U^T`` (:func:`assemble_ldl`, the
planar cubic window in registers), closed curves band Cholesky, solved by bordering: the last
``kd`` unknowns are eliminated through a ``kd x kd`` Schur complement, ``O(N kd^2)`` in all.
Everything is ``O(N)`` time and memory.

The ADMM warm start of open curves (:func:`admm_factor`, :func:`admm_sweep_t`) factorises the
``n x n`` band ``K + rho I`` once for all coordinates.

Every kernel takes ``K`` as the pair ``(K, ks)``: the band rows of the UNSCALED energy matrix
(the curve's cached Gram band, read only) and the scale ``ks = 2 / E0``; each entry is read as
``K[i, j] * ks``, the same rounded value as an entry of the scaled copy ``K * ks`` (so the
results are bitwise those of a scaled copy, without its ``n (2p + 1)`` doubles).

One compiled copy per kernel and array layout: numba compiles a function again for every new
argument type, and a literal (``0``, ``False`` written in a call) has its own type
(``Literal[int](0)`` is not ``int64``), as have read-only and writeable arrays. So calls between
kernels pass ``np.intp(0)`` / ``np.bool_(False)``, and ``K`` always arrives read only
(:func:`curvefair.fairing.global_fair._readonly_view`): each kernel is compiled once per
layout of its blocks and frames (planar blocks are a strided view, see ``_ssn_work``), not once
per caller.
"""

from __future__ import annotations

import numpy as np

from .._jit import njit
from .bspline import residual_row

# ------------------------------------------------------------------------------------------
# assembly
# ------------------------------------------------------------------------------------------


@njit(cache=True)
def _assemble_range2(K, ks, p, closed, B, Q, rot, fix, L, i0, i1):
    """:func:`assemble_range` for planar curves, branch-light: the frame of point ``i`` is the
    rotation with first column ``q_i`` (``(1, 0)`` without frame), so the block
    ``M[(j, .), (i, .)] = K_ij Q_j^T Q_i = K_ij [[C, -S], [S, C]]`` with ``C = q_j . q_i``,
    ``S = q_j x q_i``; fixed unknowns enter as 0/1 weights."""
    n = K.shape[0]
    for i in range(i0, i1):
        ri = rot[i]
        qi0 = Q[i, 0, 0] if ri else 1.0
        qi1 = Q[i, 1, 0] if ri else 0.0
        wi0 = 0.0 if fix[i, 0] else 1.0
        wi1 = 0.0 if fix[i, 1] else 1.0
        C0 = 2 * i
        C1 = C0 + 1
        # diagonal block: K_ii I + Q_i^T B_i Q_i
        b00 = B[i, 0, 0]
        b01 = B[i, 0, 1]
        b10 = B[i, 1, 0]
        b11 = B[i, 1, 1]
        if ri and not (b01 == 0.0 and b10 == 0.0 and b00 == b11):
            # Q = [[q0, -q1], [q1, q0]]
            c00 = b00 * qi0 + b01 * qi1
            c01 = -b00 * qi1 + b01 * qi0
            c10 = b10 * qi0 + b11 * qi1
            c11 = -b10 * qi1 + b11 * qi0
            b00 = qi0 * c00 + qi1 * c10
            b10 = -qi1 * c00 + qi0 * c10
            b11 = -qi1 * c01 + qi0 * c11
        kk = (K[i, p] * ks)
        L[C0, 0] = (kk + b00) * wi0 + (1.0 - wi0)
        L[C0, 1] = b10 * wi0 * wi1
        L[C1, 0] = (kk + b11) * wi1 + (1.0 - wi1)
        for o in range(1, p + 1):
            j = i + o
            k = 2 * o
            if j >= n:
                if not closed:
                    L[C0, k] = 0.0
                    L[C0, k + 1] = 0.0
                    L[C1, k - 1] = 0.0
                    L[C1, k] = 0.0
                    continue
                j -= n
            rj = rot[j]
            qj0 = Q[j, 0, 0] if rj else 1.0
            qj1 = Q[j, 1, 0] if rj else 0.0
            wj0 = 0.0 if fix[j, 0] else 1.0
            wj1 = 0.0 if fix[j, 1] else 1.0
            kk = (K[i, p + o] * ks)
            cc = kk * (qj0 * qi0 + qj1 * qi1)
            sn = kk * (qj0 * qi1 - qj1 * qi0)
            L[C0, k] = cc * (wi0 * wj0)
            L[C0, k + 1] = sn * (wi0 * wj1)
            L[C1, k - 1] = -sn * (wi1 * wj0)
            L[C1, k] = cc * (wi1 * wj1)
        L[C1, 2 * p + 1] = 0.0


@njit(cache=True, nogil=True, readonly=('K',), any_layout=('B', 'Q'))
def assemble_range(K, ks, p, closed, B, Q, rot, fix, L, i0, i1):
    """Write the lower-band entries of the columns of points ``i0 .. i1 - 1`` into ``L``."""
    if B.shape[1] == 2:
        _assemble_range2(K, ks, p, closed, B, Q, rot, fix, L, i0, i1)
        return
    n = K.shape[0]
    dim = B.shape[1]
    kd = L.shape[1] - 1
    blk = np.empty((dim, dim))
    qq = np.empty((dim, dim))
    for i in range(i0, i1):
        for a in range(dim):
            for k in range(kd + 1):
                L[i * dim + a, k] = 0.0
        # fast path: no frame and no fixed unknown at i .. i + p
        plain = True
        for o in range(p + 1):
            j = i + o
            if j >= n:
                if not closed:
                    break
                j -= n
            if rot[j]:
                plain = False
                break
            for a in range(dim):
                if fix[j, a]:
                    plain = False
            if not plain:
                break
        if plain:
            for a in range(dim):
                C = i * dim + a
                for o in range(p + 1):
                    if i + o >= n and not closed:
                        break
                    L[C, o * dim] = (K[i, p + o] * ks)
                for b in range(a, dim):
                    L[C, b - a] += B[i, b, a]
            continue
        ri = rot[i]
        if dim == 2:
            # planar: the 2 x 2 blocks written out (frames are rotations)
            fi0 = fix[i, 0]
            fi1 = fix[i, 1]
            for o in range(p + 1):
                j = i + o
                if j >= n:
                    if not closed:
                        break
                    j -= n
                rj = rot[j]
                kk = (K[i, p + o] * ks)
                if ri and rj:
                    t00 = Q[j, 0, 0] * Q[i, 0, 0] + Q[j, 1, 0] * Q[i, 1, 0]
                    t01 = Q[j, 0, 0] * Q[i, 0, 1] + Q[j, 1, 0] * Q[i, 1, 1]
                    t10 = Q[j, 0, 1] * Q[i, 0, 0] + Q[j, 1, 1] * Q[i, 1, 0]
                    t11 = Q[j, 0, 1] * Q[i, 0, 1] + Q[j, 1, 1] * Q[i, 1, 1]
                elif ri:
                    t00 = Q[i, 0, 0]
                    t01 = Q[i, 0, 1]
                    t10 = Q[i, 1, 0]
                    t11 = Q[i, 1, 1]
                elif rj:
                    t00 = Q[j, 0, 0]
                    t01 = Q[j, 1, 0]
                    t10 = Q[j, 0, 1]
                    t11 = Q[j, 1, 1]
                else:
                    t00 = 1.0
                    t01 = 0.0
                    t10 = 0.0
                    t11 = 1.0
                # m_ba = M[(j, b), (i, a)]
                m00 = kk * t00
                m01 = kk * t01
                m10 = kk * t10
                m11 = kk * t11
                if o == 0:
                    b00 = B[i, 0, 0]
                    b01 = B[i, 0, 1]
                    b10 = B[i, 1, 0]
                    b11 = B[i, 1, 1]
                    if ri and not (b01 == 0.0 and b10 == 0.0 and b00 == b11):
                        q00 = Q[i, 0, 0]
                        q01 = Q[i, 0, 1]
                        q10 = Q[i, 1, 0]
                        q11 = Q[i, 1, 1]
                        # (Q^T B Q)[b, a]
                        c00 = b00 * q00 + b01 * q10
                        c01 = b00 * q01 + b01 * q11
                        c10 = b10 * q00 + b11 * q10
                        c11 = b10 * q01 + b11 * q11
                        b00 = q00 * c00 + q10 * c10
                        b01 = q00 * c01 + q10 * c11
                        b10 = q01 * c00 + q11 * c10
                        b11 = q01 * c01 + q11 * c11
                    m00 += b00
                    m01 += b01
                    m10 += b10
                    m11 += b11
                fj0 = fix[j, 0]
                fj1 = fix[j, 1]
                C = 2 * i
                k = 2 * o
                # column (i, 0): rows (j, 0), (j, 1)
                L[C, k] = (1.0 if k == 0 else 0.0) if (fi0 or fj0) else m00
                L[C, k + 1] = 0.0 if (fi0 or fj1) else m10
                # column (i, 1): rows (j, 0) (only o > 0), (j, 1)
                if o > 0:
                    L[C + 1, k - 1] = 0.0 if (fi1 or fj0) else m01
                L[C + 1, k] = (1.0 if k == 0 else 0.0) if (fi1 or fj1) else m11
            continue
        for o in range(p + 1):
            j = i + o
            if j >= n:
                if not closed:
                    break
                j -= n
            rj = rot[j]
            kk = (K[i, p + o] * ks)
            # blk[b, a] = M[(j, b), (i, a)]
            if not ri and not rj:
                for b in range(dim):
                    for a in range(dim):
                        blk[b, a] = kk if a == b else 0.0
            else:
                for b in range(dim):
                    for a in range(dim):
                        if ri and rj:
                            v = 0.0
                            for c in range(dim):
                                v += Q[j, c, b] * Q[i, c, a]
                        elif ri:
                            v = Q[i, b, a]
                        else:
                            v = Q[j, a, b]
                        blk[b, a] = kk * v
            if o == 0:
                if ri:
                    for b in range(dim):
                        for c in range(dim):
                            t = 0.0
                            for e in range(dim):
                                t += B[i, c, e] * Q[i, e, b]
                            qq[c, b] = t
                    for b in range(dim):
                        for a in range(dim):
                            t = 0.0
                            for c in range(dim):
                                t += Q[i, c, b] * qq[c, a]
                            blk[b, a] += t
                else:
                    for b in range(dim):
                        for a in range(dim):
                            blk[b, a] += B[i, b, a]
            for a in range(dim):
                C = i * dim + a
                fa = fix[i, a]
                for b in range(dim):
                    k = o * dim + b - a
                    if k < 0:
                        continue
                    if fa or fix[j, b]:
                        L[C, k] = 1.0 if k == 0 else 0.0
                    else:
                        L[C, k] = blk[b, a]


@njit(cache=True, nogil=True, readonly=('K',), any_layout=('B', 'Q'))
def assemble(K, ks, p, closed, B, Q, rot, fix, L):
    """Fill ``L`` (shape (n dim, kd + 1)) with the lower band of ``M`` (see module docstring)."""
    assemble_range(K, ks, p, closed, B, Q, rot, fix, L, np.intp(0), K.shape[0])


@njit(cache=True)
def _ldl7(K, ks, p, B, Q, rot, fix, L, j, jstop, nxt, nmax):
    """Elimination steps ``j .. jstop - 1`` (``jstop <= N - 7``) of :func:`assemble_ldl` for
    ``kd = 7``, with the 7 x 7 window loaded from (and written back to) the right-looking
    storage at ``L[j:j + 7]``, the columns of points ``nxt .. nmax - 1`` assembled in batches
    just before they are needed (points from ``nmax`` on must be assembled already: rows up to
    ``jstop + 6`` are read). Returns ``(info, j, nxt)``."""
    dim = B.shape[1]
    p00 = L[j + 0, 0]
    p10 = L[j + 0, 1]
    p11 = L[j + 1, 0]
    p20 = L[j + 0, 2]
    p21 = L[j + 1, 1]
    p22 = L[j + 2, 0]
    p30 = L[j + 0, 3]
    p31 = L[j + 1, 2]
    p32 = L[j + 2, 1]
    p33 = L[j + 3, 0]
    p40 = L[j + 0, 4]
    p41 = L[j + 1, 3]
    p42 = L[j + 2, 2]
    p43 = L[j + 3, 1]
    p44 = L[j + 4, 0]
    p50 = L[j + 0, 5]
    p51 = L[j + 1, 4]
    p52 = L[j + 2, 3]
    p53 = L[j + 3, 2]
    p54 = L[j + 4, 1]
    p55 = L[j + 5, 0]
    p60 = L[j + 0, 6]
    p61 = L[j + 1, 5]
    p62 = L[j + 2, 4]
    p63 = L[j + 3, 3]
    p64 = L[j + 4, 2]
    p65 = L[j + 5, 1]
    p66 = L[j + 6, 0]
    while j < jstop:
        if j + 7 >= nxt * dim and nxt < nmax:
            stop = min(nmax, nxt + 256)
            assemble_range(K, ks, p, np.bool_(False), B, Q, rot, fix, L, nxt, stop)
            nxt = stop
        d = p00
        if not d > 0.0:
            return j + 1, j, nxt
        r = 1.0 / d
        a1 = p10
        a2 = p20
        a3 = p30
        a4 = p40
        a5 = p50
        a6 = p60
        a7 = L[j, 7]
        l1 = a1 * r
        l2 = a2 * r
        l3 = a3 * r
        l4 = a4 * r
        l5 = a5 * r
        l6 = a6 * r
        l7 = a7 * r
        L[j, 0] = r
        L[j, 1] = l1
        L[j, 2] = l2
        L[j, 3] = l3
        L[j, 4] = l4
        L[j, 5] = l5
        L[j, 6] = l6
        L[j, 7] = l7
        p00 = p11 - l1 * a1
        p10 = p21 - l2 * a1
        p11 = p22 - l2 * a2
        p20 = p31 - l3 * a1
        p21 = p32 - l3 * a2
        p22 = p33 - l3 * a3
        p30 = p41 - l4 * a1
        p31 = p42 - l4 * a2
        p32 = p43 - l4 * a3
        p33 = p44 - l4 * a4
        p40 = p51 - l5 * a1
        p41 = p52 - l5 * a2
        p42 = p53 - l5 * a3
        p43 = p54 - l5 * a4
        p44 = p55 - l5 * a5
        p50 = p61 - l6 * a1
        p51 = p62 - l6 * a2
        p52 = p63 - l6 * a3
        p53 = p64 - l6 * a4
        p54 = p65 - l6 * a5
        p55 = p66 - l6 * a6
        p60 = L[j + 1, 6] - l7 * a1
        p61 = L[j + 2, 5] - l7 * a2
        p62 = L[j + 3, 4] - l7 * a3
        p63 = L[j + 4, 3] - l7 * a4
        p64 = L[j + 5, 2] - l7 * a5
        p65 = L[j + 6, 1] - l7 * a6
        p66 = L[j + 7, 0] - l7 * a7
        j += 1
    # write the window back (right-looking storage) and finish in place
    L[j + 0, 0] = p00
    L[j + 0, 1] = p10
    L[j + 1, 0] = p11
    L[j + 0, 2] = p20
    L[j + 1, 1] = p21
    L[j + 2, 0] = p22
    L[j + 0, 3] = p30
    L[j + 1, 2] = p31
    L[j + 2, 1] = p32
    L[j + 3, 0] = p33
    L[j + 0, 4] = p40
    L[j + 1, 3] = p41
    L[j + 2, 2] = p42
    L[j + 3, 1] = p43
    L[j + 4, 0] = p44
    L[j + 0, 5] = p50
    L[j + 1, 4] = p51
    L[j + 2, 3] = p52
    L[j + 3, 2] = p53
    L[j + 4, 1] = p54
    L[j + 5, 0] = p55
    L[j + 0, 6] = p60
    L[j + 1, 5] = p61
    L[j + 2, 4] = p62
    L[j + 3, 3] = p63
    L[j + 4, 2] = p64
    L[j + 5, 1] = p65
    L[j + 6, 0] = p66
    return 0, j, nxt


@njit(cache=True, nogil=True, readonly=('K',), any_layout=('B', 'Q'))
def assemble_ldl(K, ks, p, B, Q, rot, fix, L):
    """Assemble (open curves) and factorise ``M = U D U^T`` (``U`` unit lower band) in one pass:
    the columns of a batch of points are written just before the first elimination step that
    needs them. On exit ``L[j, 0] = 1 / D_j`` and ``L[j, k] = U[j + k, j]`` (see
    :func:`ldl_solve`). For ``kd = 7`` (planar cubics) the partially eliminated 7 x 7 window
    is kept in registers (the band is read once and written once, no read-modify-write of
    the trailing rows); otherwise right-looking in place. Returns 0 or ``j + 1`` for a
    non-positive pivot ``j``."""
    n = K.shape[0]
    dim = B.shape[1]
    N = n * dim
    kd = L.shape[1] - 1
    nxt = 0
    j = 0
    if kd == 7 and N > 16:
        nxt = min(n, 256)
        assemble_range(K, ks, p, np.bool_(False), B, Q, rot, fix, L, np.intp(0), nxt)
        info, j, nxt = _ldl7(K, ks, p, B, Q, rot, fix, L, np.intp(0), N - 7, nxt, n)
        if info:
            return info
    while j < N:
        if nxt < n:
            stop = min(n, nxt + 256)
            assemble_range(K, ks, p, np.bool_(False), B, Q, rot, fix, L, nxt, stop)
            nxt = stop
        # columns whose updates reach only assembled rows
        j1 = N if nxt == n else max(j, nxt * dim - kd)
        info = _ldl_cols(L, j, j1, N)
        if info:
            return info
        j = j1
    return 0


@njit(cache=True, nogil=True, readonly=('K',), any_layout=('B', 'Q'))
def assemble_ldl_head(K, ks, p, B, Q, rot, fix, L, nmax):
    """First part of :func:`assemble_ldl` (``kd = 7``, ``N > 16``) while the columns of the
    points ``nmax .. n - 1`` are assembled elsewhere (:func:`assemble_range`, e.g. on another
    thread): assembles points ``0 .. nmax - 1`` and eliminates the columns that read only
    those. Returns ``(info, j)``: continue with :func:`assemble_ldl_tail` from ``j`` once
    every column is assembled. The same operations as :func:`assemble_ldl` (bitwise)."""
    dim = B.shape[1]
    nxt = min(nmax, 256)
    assemble_range(K, ks, p, np.bool_(False), B, Q, rot, fix, L, np.intp(0), nxt)
    info, j, nxt = _ldl7(K, ks, p, B, Q, rot, fix, L, np.intp(0), max(nmax * dim - 8, 0), nxt,
                         nmax)
    return info, j


@njit(cache=True, nogil=True, readonly=('K',), any_layout=('B', 'Q'))
def assemble_ldl_tail(K, ks, p, B, Q, rot, fix, L, j):
    """The rest of :func:`assemble_ldl` after :func:`assemble_ldl_head` (every column
    assembled)."""
    n = K.shape[0]
    N = n * B.shape[1]
    info, j, nxt = _ldl7(K, ks, p, B, Q, rot, fix, L, j, N - 7, n, n)
    if info:
        return info
    return _ldl_cols(L, j, N, N)


@njit(cache=True)
def _ldl_cols(L, j0, j1, N):
    """Elimination steps ``j0 .. j1 - 1`` of the band ``U D U^T`` factorisation of the first
    ``N`` rows, right looking in place (see :func:`assemble_ldl`)."""
    kd = L.shape[1] - 1
    for j in range(j0, j1):
        d = L[j, 0]
        if not d > 0.0:
            return j + 1
        r = 1.0 / d
        L[j, 0] = r
        kmax = min(kd, N - 1 - j)
        for a in range(1, kmax + 1):
            aa = L[j, a]
            if aa != 0.0:
                la = aa * r
                for b in range(a, kmax + 1):
                    L[j + a, b - a] -= L[j, b] * la
        for k in range(1, kmax + 1):
            L[j, k] *= r
    return 0


@njit(cache=True)
def ldl_solve(L, N, x):
    """Solve ``U D U^T y = x`` in place (factor of :func:`assemble_ldl`), left looking: each
    substitution step is one multiply-add on the recurrence (``kd = 7`` written out with the
    last seven unknowns in registers)."""
    kd = L.shape[1] - 1
    if kd == 7 and N > 7:
        x1 = 0.0
        x2 = 0.0
        x3 = 0.0
        x4 = 0.0
        x5 = 0.0
        x6 = 0.0
        x7 = 0.0
        for j in range(N):
            if j >= 7:
                s = (x[j] - L[j - 7, 7] * x7 - L[j - 6, 6] * x6 - L[j - 5, 5] * x5
                     - L[j - 4, 4] * x4 - L[j - 3, 3] * x3 - L[j - 2, 2] * x2)
                v = s - L[j - 1, 1] * x1
            else:
                v = x[j]
                for k in range(1, j + 1):
                    v -= L[j - k, k] * x[j - k]
            x[j] = v
            x7 = x6
            x6 = x5
            x5 = x4
            x4 = x3
            x3 = x2
            x2 = x1
            x1 = v
        x1 = 0.0
        x2 = 0.0
        x3 = 0.0
        x4 = 0.0
        x5 = 0.0
        x6 = 0.0
        x7 = 0.0
        for i in range(N - 1, -1, -1):  # the D^-1 scaling folded in (same cache line)
            if i + 7 < N:
                s = (x[i] * L[i, 0] - L[i, 7] * x7 - L[i, 6] * x6 - L[i, 5] * x5
                     - L[i, 4] * x4 - L[i, 3] * x3 - L[i, 2] * x2)
                v = s - L[i, 1] * x1
            else:
                v = x[i] * L[i, 0]
                for k in range(1, N - i):
                    v -= L[i, k] * x[i + k]
            x[i] = v
            x7 = x6
            x6 = x5
            x5 = x4
            x4 = x3
            x3 = x2
            x2 = x1
            x1 = v
        return
    for j in range(N):
        v = x[j]
        for k in range(1, min(kd, j) + 1):
            v -= L[j - k, k] * x[j - k]
        x[j] = v
    for j in range(N):
        x[j] *= L[j, 0]
    for i in range(N - 1, -1, -1):
        v = x[i]
        for k in range(1, min(kd, N - 1 - i) + 1):
            v -= L[i, k] * x[i + k]
        x[i] = v


@njit(cache=True, inline="always")
def _krow(K, ks, p, closed, x, i, a, interior):
    """``(K x)_{i, a}`` for points ``x`` (n, dim), ``K`` by its band rows ``K[i, p + o] * ks``
    (closed: indices mod n); ``interior`` (``p <= i < n - p``) skips the wrap tests. Inlined at
    numba IR level: the same additions in the same order as a written-out loop."""
    n = x.shape[0]
    acc = 0.0
    if interior:
        for o in range(-p, p + 1):
            acc += (K[i, p + o] * ks) * x[i + o, a]
    else:
        for o in range(-p, p + 1):
            j = i + o
            if j < 0 or j >= n:
                if not closed:
                    continue
                j = j + n if j < 0 else j - n
            acc += (K[i, p + o] * ks) * x[j, a]
    return acc


@njit(cache=True)
def band_residual_scaled(W, ks, p, closed, x, out):
    """``out = (W ks) x`` per coordinate in the difference form of
    :func:`curvefair._kernels.bspline.band_residual` (``sum_{o != 0} (W[i, p + o] ks) (x_{i+o} -
    x_i)``, the same operations on the entries of the scaled band: :func:`residual_row`)."""
    n, dim = x.shape
    for i in range(n):
        interior = i >= p and i + p < n
        for a in range(dim):
            out[i, a] = residual_row(W, ks, p, closed, x, i, a, interior)


@njit(cache=True, readonly=('K',))
def band_matvec(K, ks, p, closed, x, out):
    """``out = kron(K ks, I) x`` for points ``x`` (n, dim); ``K ks`` given by its band rows
    ``K[i, p + o] * ks = (K ks)_{i, i+o}`` (symmetric; closed: indices mod n)."""
    n, dim = x.shape
    for i in range(n):
        interior = i >= p and i + p < n
        for a in range(dim):
            out[i, a] = _krow(K, ks, p, closed, x, i, a, interior)


# ------------------------------------------------------------------------------------------
# band Cholesky (open curves)
# ------------------------------------------------------------------------------------------


@njit(cache=True)
def _chol_cols(L, j0, j1, N):
    """Elimination steps ``j0 .. j1 - 1`` of the band Cholesky of the first ``N`` rows (right
    looking; the planar cubic band ``kd = 7`` written out). Returns 0 or ``j + 1`` for a
    non-positive pivot ``j``."""
    kd = L.shape[1] - 1
    for j in range(j0, j1):
        d = L[j, 0]
        if not d > 0.0:
            return j + 1
        d = np.sqrt(d)
        L[j, 0] = d
        inv = 1.0 / d
        if kd == 7 and j + 7 < N:
            l1 = L[j, 1] * inv
            l2 = L[j, 2] * inv
            l3 = L[j, 3] * inv
            l4 = L[j, 4] * inv
            l5 = L[j, 5] * inv
            l6 = L[j, 6] * inv
            l7 = L[j, 7] * inv
            L[j, 1] = l1
            L[j, 2] = l2
            L[j, 3] = l3
            L[j, 4] = l4
            L[j, 5] = l5
            L[j, 6] = l6
            L[j, 7] = l7
            L[j + 1, 0] -= l1 * l1
            L[j + 1, 1] -= l2 * l1
            L[j + 1, 2] -= l3 * l1
            L[j + 1, 3] -= l4 * l1
            L[j + 1, 4] -= l5 * l1
            L[j + 1, 5] -= l6 * l1
            L[j + 1, 6] -= l7 * l1
            L[j + 2, 0] -= l2 * l2
            L[j + 2, 1] -= l3 * l2
            L[j + 2, 2] -= l4 * l2
            L[j + 2, 3] -= l5 * l2
            L[j + 2, 4] -= l6 * l2
            L[j + 2, 5] -= l7 * l2
            L[j + 3, 0] -= l3 * l3
            L[j + 3, 1] -= l4 * l3
            L[j + 3, 2] -= l5 * l3
            L[j + 3, 3] -= l6 * l3
            L[j + 3, 4] -= l7 * l3
            L[j + 4, 0] -= l4 * l4
            L[j + 4, 1] -= l5 * l4
            L[j + 4, 2] -= l6 * l4
            L[j + 4, 3] -= l7 * l4
            L[j + 5, 0] -= l5 * l5
            L[j + 5, 1] -= l6 * l5
            L[j + 5, 2] -= l7 * l5
            L[j + 6, 0] -= l6 * l6
            L[j + 6, 1] -= l7 * l6
            L[j + 7, 0] -= l7 * l7
            continue
        kmax = min(kd, N - 1 - j)
        for k in range(1, kmax + 1):
            L[j, k] *= inv
        for a in range(1, kmax + 1):
            la = L[j, a]
            if la != 0.0:
                for b in range(a, kmax + 1):
                    L[j + a, b - a] -= L[j, b] * la
    return 0


@njit(cache=True)
def band_cholesky(L, N):
    """In-place Cholesky of the first ``N`` rows of the lower band ``L`` (entries reaching
    beyond row ``N - 1`` are left alone). Returns 0, or ``j + 1`` if pivot ``j`` is not
    positive (not positive definite in floating point)."""
    return _chol_cols(L, np.intp(0), N, N)


@njit(cache=True)
def band_solve(L, N, x):
    """Solve ``L L^T y = x`` in place for the first ``N`` entries of ``x`` (1-D)."""
    kd = L.shape[1] - 1
    if kd == 7 and N > 7:
        _band_solve7(L, N, x)
        return
    for j in range(N):
        v = x[j] / L[j, 0]
        x[j] = v
        kmax = min(kd, N - 1 - j)
        if v != 0.0:
            for k in range(1, kmax + 1):
                x[j + k] -= L[j, k] * v
    for i in range(N - 1, -1, -1):
        s = x[i]
        kmax = min(kd, N - 1 - i)
        for k in range(1, kmax + 1):
            s -= L[i, k] * x[i + k]
        x[i] = s / L[i, 0]


@njit(cache=True)
def _band_solve7(L, N, x):
    """:func:`band_solve` for ``kd = 7`` (planar cubics), ``N > 7``: left-looking substitutions
    with the last seven unknowns in registers, the newest subtracted last (one multiply-add and
    one multiply by the reciprocal pivot on the recurrence)."""
    for j in range(7):
        s = x[j]
        for k in range(1, j + 1):
            s -= L[j - k, k] * x[j - k]
        x[j] = s / L[j, 0]
    x1 = x[6]
    x2 = x[5]
    x3 = x[4]
    x4 = x[3]
    x5 = x[2]
    x6 = x[1]
    x7 = x[0]
    for j in range(7, N):
        r = 1.0 / L[j, 0]
        s = (x[j] - L[j - 7, 7] * x7 - L[j - 6, 6] * x6 - L[j - 5, 5] * x5 - L[j - 4, 4] * x4
             - L[j - 3, 3] * x3 - L[j - 2, 2] * x2)
        v = (s - L[j - 1, 1] * x1) * r
        x[j] = v
        x7 = x6
        x6 = x5
        x5 = x4
        x4 = x3
        x3 = x2
        x2 = x1
        x1 = v
    for i in range(N - 1, N - 8, -1):
        s = x[i]
        for k in range(1, N - i):
            s -= L[i, k] * x[i + k]
        x[i] = s / L[i, 0]
    x1 = x[N - 7]
    x2 = x[N - 6]
    x3 = x[N - 5]
    x4 = x[N - 4]
    x5 = x[N - 3]
    x6 = x[N - 2]
    x7 = x[N - 1]
    for i in range(N - 8, -1, -1):
        r = 1.0 / L[i, 0]
        s = (x[i] - L[i, 7] * x7 - L[i, 6] * x6 - L[i, 5] * x5 - L[i, 4] * x4 - L[i, 3] * x3
             - L[i, 2] * x2)
        v = (s - L[i, 1] * x1) * r
        x[i] = v
        x7 = x6
        x6 = x5
        x5 = x4
        x4 = x3
        x3 = x2
        x2 = x1
        x1 = v


@njit(cache=True)
def band_solve_columns(L, N, X):
    """:func:`band_solve` of every column of ``X`` (``(N', m)``, first ``N`` rows) at once: per
    column the same operations in the same order (so the same bits as ``m`` calls), but the
    ``m`` recurrences run side by side, which a substitution bound by the latency of its
    chain of multiply-subtracts and divisions gains from (used for the ``kd`` coupling columns
    of :func:`cyclic_cholesky`)."""
    kd = L.shape[1] - 1
    m = X.shape[1]
    if kd == 7 and N > 7:
        for j in range(7):
            for c in range(m):
                s = X[j, c]
                for k in range(1, j + 1):
                    s -= L[j - k, k] * X[j - k, c]
                X[j, c] = s / L[j, 0]
        for j in range(7, N):
            r = 1.0 / L[j, 0]
            for c in range(m):
                s = (X[j, c] - L[j - 7, 7] * X[j - 7, c] - L[j - 6, 6] * X[j - 6, c]
                     - L[j - 5, 5] * X[j - 5, c] - L[j - 4, 4] * X[j - 4, c]
                     - L[j - 3, 3] * X[j - 3, c] - L[j - 2, 2] * X[j - 2, c])
                X[j, c] = (s - L[j - 1, 1] * X[j - 1, c]) * r
        for i in range(N - 1, N - 8, -1):
            for c in range(m):
                s = X[i, c]
                for k in range(1, N - i):
                    s -= L[i, k] * X[i + k, c]
                X[i, c] = s / L[i, 0]
        for i in range(N - 8, -1, -1):
            r = 1.0 / L[i, 0]
            for c in range(m):
                s = (X[i, c] - L[i, 7] * X[i + 7, c] - L[i, 6] * X[i + 6, c]
                     - L[i, 5] * X[i + 5, c] - L[i, 4] * X[i + 4, c] - L[i, 3] * X[i + 3, c]
                     - L[i, 2] * X[i + 2, c])
                X[i, c] = (s - L[i, 1] * X[i + 1, c]) * r
        return
    for j in range(N):
        kmax = min(kd, N - 1 - j)
        for c in range(m):
            v = X[j, c] / L[j, 0]
            X[j, c] = v
            if v != 0.0:
                for k in range(1, kmax + 1):
                    X[j + k, c] -= L[j, k] * v
    for i in range(N - 1, -1, -1):
        kmax = min(kd, N - 1 - i)
        for c in range(m):
            s = X[i, c]
            for k in range(1, kmax + 1):
                s -= L[i, k] * X[i + k, c]
            X[i, c] = s / L[i, 0]


# ------------------------------------------------------------------------------------------
# cyclic band (closed curves): bordering
# ------------------------------------------------------------------------------------------


@njit(cache=True, nogil=True)
def cyclic_cholesky(L, Y, S):
    """Factorise the cyclic band ``L`` (N > 3 kd): band Cholesky of the leading
    ``N - kd`` unknowns, ``Y = M_II^{-1} M_IB`` (shape (N - kd, kd)) and the Cholesky factor of
    the Schur complement ``S = M_BB - M_IB^T Y`` (lower, (kd, kd)). Returns 0 or a failure
    code."""
    N = L.shape[0]
    kd = L.shape[1] - 1
    nI = N - kd
    # coupling columns M_IB before the factorisation overwrites L[:nI]
    for r in range(nI):
        for c in range(kd):
            Y[r, c] = 0.0
    for r in range(nI - kd, nI):
        for k in range(1, kd + 1):
            R = r + k
            if R >= nI:
                Y[r, R - nI] = L[r, k]
    for r in range(nI, N):
        for k in range(1, kd + 1):
            R = r + k
            if R >= N:
                Y[R - N, r - nI] = L[r, k]
    for c in range(kd):
        for c2 in range(kd):
            S[c, c2] = 0.0
    for r in range(nI, N):
        for k in range(0, kd + 1):
            R = r + k
            if R < N:
                S[R - nI, r - nI] = L[r, k]
                S[r - nI, R - nI] = L[r, k]
    # save the coupling block (nonzero in its first and last kd rows only), then factorise
    # the interior
    info = band_cholesky(L, nI)
    if info:
        return info
    Cb = np.empty((2 * kd, kd))
    for r in range(kd):
        for c in range(kd):
            Cb[r, c] = Y[r, c]
            Cb[kd + r, c] = Y[nI - kd + r, c]
    band_solve_columns(L, nI, Y)
    # S -= M_IB^T Y over the nonzero rows of M_IB, in row order (the zero rows add exact zeros)
    for c in range(kd):
        for c2 in range(kd):
            acc = 0.0
            for r in range(kd):
                acc += Cb[r, c] * Y[r, c2]
            for r in range(kd):
                acc += Cb[kd + r, c] * Y[nI - kd + r, c2]
            S[c, c2] -= acc
    # dense Cholesky of S (lower), in place
    for j in range(kd):
        d = S[j, j]
        for m in range(j):
            d -= S[j, m] * S[j, m]
        if not d > 0.0:
            return nI + j + 1
        d = np.sqrt(d)
        S[j, j] = d
        for i in range(j + 1, kd):
            v = S[i, j]
            for m in range(j):
                v -= S[i, m] * S[j, m]
            S[i, j] = v / d
    for j in range(kd):
        for i in range(j):
            S[i, j] = 0.0
    return 0


@njit(cache=True)
def cyclic_solve_full(L, Y, S, x):
    """Solve ``M y = x`` in place with the factorisation of :func:`cyclic_cholesky`."""
    N = L.shape[0]
    kd = L.shape[1] - 1
    nI = N - kd
    xb = np.empty(kd)
    # x_B - M_IB^T M_II^{-1} x_I = x_B - Y^T x_I  (Y = M_II^{-1} M_IB, M_II symmetric): one
    # pass over the rows of Y, each entry's sum in row order
    for c in range(kd):
        xb[c] = x[nI + c]
    for r in range(nI):
        xr = x[r]
        for c in range(kd):
            xb[c] -= Y[r, c] * xr
    # S z = xb
    for i in range(kd):
        v = xb[i]
        for m in range(i):
            v -= S[i, m] * xb[m]
        xb[i] = v / S[i, i]
    for i in range(kd - 1, -1, -1):
        v = xb[i]
        for m in range(i + 1, kd):
            v -= S[m, i] * xb[m]
        xb[i] = v / S[i, i]
    band_solve(L, nI, x)
    for r in range(nI):
        acc = 0.0
        for c in range(kd):
            acc += Y[r, c] * xb[c]
        x[r] -= acc
    for c in range(kd):
        x[nI + c] = xb[c]


@njit(cache=True)
def cyclic_solve_columns(L, Y, S, X):
    """:func:`cyclic_solve_full` of every column of ``X`` (``(N, m)``) at once, per column the
    same operations in the same order (the same bits as ``m`` calls; the substitutions of the
    columns run side by side, :func:`band_solve_columns`). The ADMM start of closed curves
    solves its coordinates so."""
    N = L.shape[0]
    kd = L.shape[1] - 1
    nI = N - kd
    m = X.shape[1]
    xb = np.empty((kd, m))
    for c in range(kd):
        for a in range(m):
            xb[c, a] = X[nI + c, a]
    for r in range(nI):  # one pass over the rows of Y, each entry's sum in row order
        for c in range(kd):
            for a in range(m):
                xb[c, a] -= Y[r, c] * X[r, a]
    for a in range(m):
        for i in range(kd):
            v = xb[i, a]
            for j in range(i):
                v -= S[i, j] * xb[j, a]
            xb[i, a] = v / S[i, i]
        for i in range(kd - 1, -1, -1):
            v = xb[i, a]
            for j in range(i + 1, kd):
                v -= S[j, i] * xb[j, a]
            xb[i, a] = v / S[i, i]
    band_solve_columns(L, nI, X)
    for r in range(nI):
        for a in range(m):
            acc = 0.0
            for c in range(kd):
                acc += Y[r, c] * xb[c, a]
            X[r, a] -= acc
    for c in range(kd):
        for a in range(m):
            X[nI + c, a] = xb[c, a]


# ------------------------------------------------------------------------------------------
# right-hand sides in the rotated frames
# ------------------------------------------------------------------------------------------


@njit(cache=True)
def prep_rhs(K, ks, p, closed, B, Q, rot, fix, fix0, rhs, c, out, sgn=1.0):
    """``out = Q^T (sgn rhs - (kron(K ks, I) + B) z)`` with ``z_i = c_i Q_i[:, 0]`` at the ``rot``
    points (their prescribed normal displacement), fixed unknowns set to their values (``c_i``
    for the normal of a ``rot`` point, 0 at fixed points)."""
    n, dim = rhs.shape
    if dim == 2:
        prep_rhs2_range(K, ks, p, closed, B, Q, rot, fix, fix0, rhs, c, out, sgn, np.intp(0),
                        rhs.shape[0])
        return
    anyrot = False
    for i in range(n):
        if rot[i]:
            anyrot = True
            break
    for i in range(n):
        for a in range(dim):
            out[i, a] = sgn * rhs[i, a]
    if anyrot:
        for i in range(n):
            for o in range(-p, p + 1):
                j = i + o
                if j < 0 or j >= n:
                    if not closed:
                        continue
                    j %= n
                if rot[j]:
                    kc = (K[i, p + o] * ks) * c[j]
                    for a in range(dim):
                        out[i, a] -= kc * Q[j, a, 0]
            if rot[i]:
                for a in range(dim):
                    t = 0.0
                    for b in range(dim):
                        t += B[i, a, b] * Q[i, b, 0]
                    out[i, a] -= t * c[i]
        for i in range(n):
            if rot[i]:
                w0 = out[i, 0]
                w1 = out[i, 1]
                w2 = out[i, 2] if dim == 3 else 0.0
                for a in range(dim):
                    t = Q[i, 0, a] * w0 + Q[i, 1, a] * w1
                    if dim == 3:
                        t += Q[i, 2, a] * w2
                    out[i, a] = t
    for i in range(n):
        for a in range(dim):
            if fix[i, a]:
                out[i, a] = c[i] if (rot[i] and a == 0 and not fix0[i, a]) else 0.0


@njit(cache=True, nogil=True, any_layout=('B', 'Q'))
def prep_rhs2_range(K, ks, p, closed, B, Q, rot, fix, fix0, rhs, c, out, sgn, i0, i1):
    """:func:`prep_rhs` for planar curves in one pass (selects instead of branches on the
    frame flags of the neighbours), on the points ``i0 .. i1 - 1`` (each point is independent:
    ranges may run concurrently)."""
    n = rhs.shape[0]
    for i in range(i0, i1):
        w0 = sgn * rhs[i, 0]
        w1 = sgn * rhs[i, 1]
        interior = i >= p and i + p < n
        for o in range(-p, p + 1):
            j = i + o
            if not interior:
                if j < 0 or j >= n:
                    if not closed:
                        continue
                    j = j + n if j < 0 else j - n
            rj = rot[j]
            kc = (K[i, p + o] * ks) * (c[j] if rj else 0.0)
            w0 -= kc * (Q[j, 0, 0] if rj else 0.0)
            w1 -= kc * (Q[j, 1, 0] if rj else 0.0)
        if rot[i]:
            q0 = Q[i, 0, 0]
            q1 = Q[i, 1, 0]
            ci = c[i]
            w0 -= (B[i, 0, 0] * q0 + B[i, 0, 1] * q1) * ci
            w1 -= (B[i, 1, 0] * q0 + B[i, 1, 1] * q1) * ci
            # Q^T w, Q = [[q0, -q1], [q1, q0]]
            t0 = q0 * w0 + q1 * w1
            w1 = -q1 * w0 + q0 * w1
            w0 = t0
            if fix[i, 0]:
                w0 = 0.0 if fix0[i, 0] else ci
            if fix[i, 1]:
                w1 = 0.0
        else:
            if fix[i, 0]:
                w0 = 0.0
            if fix[i, 1]:
                w1 = 0.0
        out[i, 0] = w0
        out[i, 1] = w1


@njit(cache=True)
def post_solve(y, Q, rot, fix0):
    """Back to the original frame: ``y_i <- Q_i y_i`` at the ``rot`` points, 0 at fixed
    points."""
    post_solve_range(y, Q, rot, fix0, 0, y.shape[0])


@njit(cache=True, nogil=True, any_layout=('Q',))
def post_solve_range(y, Q, rot, fix0, i0, i1):
    """:func:`post_solve` on the points ``i0 .. i1 - 1``; returns ``max |y_i|^2`` over the
    ``rot`` points and over the others (the norm before the rotation, which keeps it)."""
    dim = y.shape[1]
    m2 = 0.0
    r2 = 0.0
    for i in range(i0, i1):
        if fix0[i, 0]:
            for a in range(dim):
                y[i, a] = 0.0
        elif rot[i] and dim == 2:  # Q = [[q0, -q1], [q1, q0]]: only its first column is read
            q0 = Q[i, 0, 0]
            q1 = Q[i, 1, 0]
            w0 = y[i, 0]
            w1 = y[i, 1]
            y[i, 0] = q0 * w0 - q1 * w1
            y[i, 1] = q1 * w0 + q0 * w1
            r2 = max(r2, w0 * w0 + w1 * w1)
        elif rot[i]:
            w0 = y[i, 0]
            w1 = y[i, 1]
            w2 = y[i, 2] if dim == 3 else 0.0
            for a in range(dim):
                t = Q[i, a, 0] * w0 + Q[i, a, 1] * w1
                if dim == 3:
                    t += Q[i, a, 2] * w2
                y[i, a] = t
            r2 = max(r2, w0 * w0 + w1 * w1 + w2 * w2)
        else:
            yy = 0.0
            for a in range(dim):
                yy += y[i, a] * y[i, a]
            m2 = max(m2, yy)
    return r2, m2


@njit(cache=True)
def max_point_norm2(y):
    """``max_i |y_i|^2`` (NaN propagates)."""
    m2 = 0.0
    for i in range(y.shape[0]):
        yy = 0.0
        for a in range(y.shape[1]):
            yy += y[i, a] * y[i, a]
        if not yy <= m2:
            m2 = yy
    return m2


# ------------------------------------------------------------------------------------------
# interior point (Mehrotra) per-point work; F = E/E0, f_i = (|v_i|^2 / t2 - 1) / 2 <= 0
# ------------------------------------------------------------------------------------------


@njit(cache=True)
def ip_eval(g0, K, ks, p, closed, v, lam, free, t2, rd, s):
    """Dual residual ``rd = g0 + K v + lam v / t2`` and slacks ``s = -f`` (at least ``1e-16``:
    a point that rounding puts on its sphere) at the free points (0 and 1 elsewhere); returns
    ``(max |rd|, min s, sum lam s)``. (Helpers inlined by hand: numba's inlined helpers made
    this loop five times slower.)"""
    n, dim = v.shape
    rdm = 0.0
    smin = np.inf
    ls = 0.0
    for i in range(n):
        if not free[i]:
            for a in range(dim):
                rd[i, a] = 0.0
            s[i] = 1.0
            continue
        vv = 0.0
        li = lam[i]
        interior = i >= p and i + p < n
        for a in range(dim):
            acc = _krow(K, ks, p, closed, v, i, a, interior)
            va = v[i, a]
            r = g0[i, a] + acc + li * (va / t2)
            rd[i, a] = r
            ar = abs(r)
            if ar > rdm:
                rdm = ar
            vv += va * va
        si = -0.5 * (vv / t2 - 1.0)
        if si < 1e-16:  # (on the sphere by rounding: s = 0 would divide by zero; NaN stays)
            si = 1e-16
        s[i] = si
        if si < smin:
            smin = si
        ls += li * si
    return rdm, smin, ls


@njit(cache=True)
def ip_blocks(v, lam, s, free, t2, B):
    """``B_i = lam_i I / t2 + (lam_i / s_i) a_i a_i^T``, ``a_i = v_i / t2`` (identity at fixed
    points, whose rows are replaced anyway)."""
    n, dim = v.shape
    for i in range(n):
        if free[i]:
            iso = lam[i] / t2
            w = lam[i] / s[i]
            for a in range(dim):
                wa = w * (v[i, a] / t2)
                for b in range(dim):
                    B[i, a, b] = wa * (v[i, b] / t2) + (iso if a == b else 0.0)
        else:
            for a in range(dim):
                for b in range(dim):
                    B[i, a, b] = 1.0 if a == b else 0.0


@njit(cache=True)
def ip_rhs(rd, v, rc, rp, lam, s, free, t2, out):
    """``out = -rd - a q``, ``q = (-rc + lam rp) / s`` (reduced Newton right-hand side,
    ``a = v / t2``; ``rp`` a primal residual to remove, e.g. the second-order term)."""
    n, dim = v.shape
    for i in range(n):
        if free[i]:
            q = (rc[i] - lam[i] * rp[i]) / s[i]
            for a in range(dim):
                out[i, a] = -rd[i, a] + (v[i, a] / t2) * q
        else:
            for a in range(dim):
                out[i, a] = 0.0


@njit(cache=True)
def ip_recover(dv, v, rc, rp, lam, s, free, t2, ds, dl):
    """``ds = -rp - a.dv`` (linearised slack step), ``dl = (-rc + lam rp + lam a.dv) / s``;
    returns the
    largest steps keeping every point inside its ball (exact, the constraint is quadratic) and
    ``lam`` non-negative (inf if unbounded)."""
    n, dim = v.shape
    bm = np.inf
    lm = np.inf
    for i in range(n):
        if not free[i]:
            ds[i] = 0.0
            dl[i] = 0.0
            continue
        adv = 0.0
        a2 = 0.0
        a1 = 0.0
        c0 = -t2
        for a in range(dim):
            adv += (v[i, a] / t2) * dv[i, a]
            a2 += dv[i, a] * dv[i, a]
            a1 += v[i, a] * dv[i, a]
            c0 += v[i, a] * v[i, a]
        e = (-rc[i] + lam[i] * rp[i] + lam[i] * adv) / s[i]
        ds[i] = -rp[i] - adv
        dl[i] = e
        if e < 0.0:
            t = -lam[i] / e
            if t < lm:
                lm = t
        if a2 > 0.0:
            # positive root of a2 t^2 + 2 a1 t + c0 = 0 (c0 < 0: inside)
            disc = np.sqrt(max(a1 * a1 - a2 * c0, 0.0))
            if a1 >= 0.0:
                t = -c0 / (a1 + disc) if a1 + disc > 0.0 else np.inf
            else:
                t = (disc - a1) / a2
            if t < bm:
                bm = t
    return bm, lm


@njit(cache=True)
def ip_corrector(lam, s, dl, ds, ap, ad, free, rc):
    """Affine-scaling complementarity ``sum (lam + ad dl)(s + ap ds)`` and
    ``rc = lam s + dl ds`` (the sigma mu term is subtracted by the caller)."""
    n = lam.shape[0]
    acc = 0.0
    for i in range(n):
        if free[i]:
            acc += (lam[i] + ad * dl[i]) * (s[i] + ap * ds[i])
            rc[i] = lam[i] * s[i] + dl[i] * ds[i]
        else:
            rc[i] = 0.0
    return acc


@njit(cache=True)
def ip_update(v, dv, lam, dl, st):
    n, dim = v.shape
    for i in range(n):
        for a in range(dim):
            v[i, a] += st * dv[i, a]
        lam[i] += st * dl[i]


@njit(cache=True)
def second_order(dv, free, t2, out):
    """``out_i = |dv_i|^2 / (2 t2)``: the slack a full step loses to the curvature of the
    sphere (the constraint is quadratic: ``f(v + dv) = f + a.dv + |dv|^2 / (2 t2)``)."""
    n, dim = dv.shape
    for i in range(n):
        acc = 0.0
        if free[i]:
            for a in range(dim):
                acc += dv[i, a] * dv[i, a]
        out[i] = acc / (2.0 * t2)


# ------------------------------------------------------------------------------------------
# ADMM warm start (open curves): one factorisation of K + rho I (n x n, bandwidth p), shared
# by the coordinates
# ------------------------------------------------------------------------------------------


@njit(cache=True, readonly=('K',))
def shift_cholesky(K, ks, p, rho, L):
    """Band Cholesky of ``K + rho I`` (open curve, ``L`` shape (n, p + 1), ``L[r, k] =
    M[r + k, r]``), with the RECIPROCAL pivots stored in ``L[:, 0]`` (for
    :func:`admm_sweep`). Returns 0 or ``j + 1`` for a non-positive pivot ``j``."""
    n = K.shape[0]
    for i in range(n):
        for o in range(p + 1):
            L[i, o] = (K[i, p + o] * ks) if i + o < n else 0.0
        L[i, 0] += rho
    info = _chol_cols(L, np.intp(0), n, n)
    for j in range(n):
        L[j, 0] = 1.0 / L[j, 0]
    return info


@njit(cache=True, nogil=True, readonly=('K',))
def admm_factor(K, ks, p, rho, L):
    """Factor of ``K + rho I`` (open curve) for the ADMM sweeps. ``p = 3`` (for
    :func:`admm_sweep_t`): ``K + rho I = U D U^T`` (``U`` unit lower) computed with the active
    window in registers (one division, one multiply and one multiply-add on the pivot
    recurrence, no square root), ``L[i, 0] = 1 / D_i``, ``L[i, k] = U[i + k, i]``. Otherwise
    the band Cholesky of :func:`shift_cholesky` (for :func:`admm_sweep`). Returns 0 or
    ``j + 1`` for a non-positive pivot ``j``."""
    n = K.shape[0]
    if p != 3 or n < 4:
        return shift_cholesky(K, ks, p, rho, L)
    # pending (partially eliminated) entries: P00 = A'[j, j], P10 = A'[j+1, j], P20 = A'[j+2, j],
    # P11 = A'[j+1, j+1], P21 = A'[j+2, j+1], P22 = A'[j+2, j+2]
    P00 = (K[0, 3] * ks) + rho
    P10 = (K[0, 4] * ks)
    P20 = (K[0, 5] * ks)
    P11 = (K[1, 3] * ks) + rho
    P21 = (K[1, 4] * ks)
    P22 = (K[2, 3] * ks) + rho
    for j in range(n):
        d = P00
        if not d > 0.0:
            return j + 1
        r = 1.0 / d
        a1 = P10
        a2 = P20
        a3 = (K[j, 6] * ks)
        l1 = a1 * r
        l2 = a2 * r
        l3 = a3 * r
        L[j, 0] = r
        L[j, 1] = l1
        L[j, 2] = l2
        L[j, 3] = l3
        if j + 3 < n:
            e31 = (K[j + 1, 5] * ks)
            e32 = (K[j + 2, 4] * ks)
            e33 = (K[j + 3, 3] * ks) + rho
        else:
            e31 = 0.0
            e32 = 0.0
            e33 = 0.0
        P00 = P11 - l1 * a1
        P10 = P21 - l2 * a1
        P20 = e31 - l3 * a1
        P11 = P22 - l2 * a2
        P21 = e32 - l3 * a2
        P22 = e33 - l3 * a3
    return 0


@njit(cache=True, nogil=True)
def admm_sweep(L, y, z, u, g0, rho, r2, alpha):
    """One over-relaxed ADMM iteration for ``min g0.x + x.K x / 2`` s.t. ``|z_i|^2 <= r2_i``,
    ``x = z`` (Boyd et al. 2011, sec. 3.4.3 / 5.1, scaled dual ``u``): on entry ``y`` holds
    ``-g0 + rho (z - u)``; ``x = (K + rho I)^{-1} y`` (factor ``L`` of :func:`shift_cholesky`),
    ``xh = alpha x + (1 - alpha) z``, ``z = P(xh + u)``, ``u += xh - z``; on exit ``y`` holds
    the next right-hand side. Arrays ``(n, dim)``; the point updates are done inside the
    backward substitution (the last solved ``x_i`` kept in a ring buffer). Cubics use
    :func:`admm_sweep_t`. Returns the squared norms of the primal residual ``x - z`` and of the
    change of ``z``."""
    n, dim = y.shape
    kd = L.shape[1] - 1
    R = 8
    while R < kd + 1:
        R *= 2
    msk = R - 1
    xb = np.zeros((R, dim))
    for j in range(n):
        inv = L[j, 0]
        kmax = min(kd, n - 1 - j)
        for a in range(dim):
            v = y[j, a] * inv
            y[j, a] = v
            for k in range(1, kmax + 1):
                y[j + k, a] -= L[j, k] * v
    rr = 0.0
    dz = 0.0
    xi = np.empty(dim)
    w = np.empty(dim)
    for i in range(n - 1, -1, -1):
        kmax = min(kd, n - 1 - i)
        inv = L[i, 0]
        q2 = 0.0
        for a in range(dim):
            s = y[i, a]
            for k in range(1, kmax + 1):
                s -= L[i, k] * xb[(i + k) & msk, a]
            x = s * inv
            xb[i & msk, a] = x
            xi[a] = x
            wa = alpha * x + (1.0 - alpha) * z[i, a] + u[i, a]
            w[a] = wa
            q2 += wa * wa
        f = 1.0
        if q2 > r2[i]:
            f = np.sqrt(r2[i] / q2) if r2[i] > 0.0 else 0.0
        for a in range(dim):
            zn = w[a] * f
            un = w[a] - zn
            e = xi[a] - zn
            rr += e * e
            e = zn - z[i, a]
            dz += e * e
            z[i, a] = zn
            u[i, a] = un
            y[i, a] = -g0[i, a] + rho * (zn - un)
    return rr, dz


@njit(cache=True, nogil=True)
def admm_sweep_t(L, y, z, u, g0, rho, t2, free, alpha):
    """:func:`admm_sweep` for cubics (``p = 3``, the ``U D U^T`` factor of :func:`admm_factor`)
    on COORDINATE-MAJOR arrays ``y, z, u, g0`` of shape ``(dim, n)``, balls of radius^2 ``t2``
    at the ``free`` points (0 elsewhere): unit substitutions with the last three unknowns in
    registers (one multiply-add on each recurrence, the newest unknown subtracted last; the
    forward coefficients ``U[j, j - k] = L[j - k, k]`` read from the neighbouring rows), then
    the relaxation / projection / dual update as a separate loop over contiguous coordinates,
    which the compiler vectorises (about 40 % faster than the same work interleaved with the
    backward substitution)."""
    dim, n = y.shape
    if dim == 2:
        a1 = 0.0
        a2 = 0.0
        a3 = 0.0
        b1 = 0.0
        b2 = 0.0
        b3 = 0.0
        for j in range(n):
            f3 = L[j - 3, 3] if j >= 3 else 0.0
            f2 = L[j - 2, 2] if j >= 2 else 0.0
            f1 = L[j - 1, 1] if j >= 1 else 0.0
            ta = y[0, j] - f3 * a3 - f2 * a2
            tb = y[1, j] - f3 * b3 - f2 * b2
            va = ta - f1 * a1
            vb = tb - f1 * b1
            r = L[j, 0]
            y[0, j] = va * r
            y[1, j] = vb * r
            a3 = a2
            a2 = a1
            a1 = va
            b3 = b2
            b2 = b1
            b1 = vb
        a1 = 0.0
        a2 = 0.0
        a3 = 0.0
        b1 = 0.0
        b2 = 0.0
        b3 = 0.0
        for i in range(n - 1, -1, -1):
            ta = y[0, i] - L[i, 3] * a3 - L[i, 2] * a2
            tb = y[1, i] - L[i, 3] * b3 - L[i, 2] * b2
            l1 = L[i, 1]
            xa = ta - l1 * a1
            xb = tb - l1 * b1
            y[0, i] = xa
            y[1, i] = xb
            a3 = a2
            a2 = a1
            a1 = xa
            b3 = b2
            b2 = b1
            b1 = xb
        beta = 1.0 - alpha
        for i in range(n):
            za = z[0, i]
            zb = z[1, i]
            wa = alpha * y[0, i] + beta * za + u[0, i]
            wb = alpha * y[1, i] + beta * zb + u[1, i]
            ri = t2 if free[i] else 0.0
            den = max(wa * wa + wb * wb, ri)
            f = np.sqrt(ri / den) if den > 0.0 else 1.0
            zna = wa * f
            znb = wb * f
            una = wa - zna
            unb = wb - znb
            z[0, i] = zna
            z[1, i] = znb
            u[0, i] = una
            u[1, i] = unb
            y[0, i] = rho * (zna - una) - g0[0, i]
            y[1, i] = rho * (znb - unb) - g0[1, i]
        return
    for a in range(dim):
        v1 = 0.0
        v2 = 0.0
        v3 = 0.0
        for j in range(n):
            v = y[a, j]
            if j >= 3:
                v -= L[j - 3, 3] * v3
            if j >= 2:
                v -= L[j - 2, 2] * v2
            if j >= 1:
                v -= L[j - 1, 1] * v1
            y[a, j] = v * L[j, 0]
            v3 = v2
            v2 = v1
            v1 = v
        v1 = 0.0
        v2 = 0.0
        v3 = 0.0
        for i in range(n - 1, -1, -1):
            x = y[a, i] - L[i, 3] * v3 - L[i, 2] * v2 - L[i, 1] * v1
            y[a, i] = x
            v3 = v2
            v2 = v1
            v1 = x
    beta = 1.0 - alpha
    for i in range(n):
        q2 = 0.0
        for a in range(dim):
            wa = alpha * y[a, i] + beta * z[a, i] + u[a, i]
            y[a, i] = wa
            q2 += wa * wa
        ri = t2 if free[i] else 0.0
        den = max(q2, ri)
        f = np.sqrt(ri / den) if den > 0.0 else 1.0
        for a in range(dim):
            zn = y[a, i] * f
            un = y[a, i] - zn
            z[a, i] = zn
            u[a, i] = un
            y[a, i] = rho * (zn - un) - g0[a, i]


# ------------------------------------------------------------------------------------------
# per-point bookkeeping
# ------------------------------------------------------------------------------------------


@njit(cache=True)
def finish_points(d0, v, free, rmax, ract, x, act):
    """``x = d0 + v`` with every free point pulled inside radius ``rmax`` so that the ROUNDED
    ``fl(x_i - d0_i)`` is within ``rmax`` too (fixed points: ``x = d0``); ``act[i]``: the final
    displacement is longer than ``ract``."""
    finish_points_range(d0, v, free, rmax, ract, x, act, 0, d0.shape[0])


@njit(cache=True, nogil=True)
def finish_points_range(d0, v, free, rmax, ract, x, act, i0, i1):
    """:func:`finish_points` on the points ``i0 .. i1 - 1`` (independent: ranges may run
    concurrently)."""
    dim = d0.shape[1]
    for i in range(i0, i1):
        if not free[i]:
            for a in range(dim):
                x[i, a] = d0[i, a]
            act[i] = False
            continue
        vv = 0.0
        for a in range(dim):
            vv += v[i, a] * v[i, a]
        dist = np.sqrt(vv)
        f = rmax / dist if dist > rmax else 1.0
        for a in range(dim):
            x[i, a] = d0[i, a] + v[i, a] * f
        dist = 0.0
        for _ in range(8):  # o + v rounds: shrink until fl(x - o) is inside
            ww = 0.0
            for a in range(dim):
                w = x[i, a] - d0[i, a]
                ww += w * w
            dist = np.sqrt(ww)
            if not dist > rmax:
                break
            f = rmax / dist * (1.0 - 2.0**-40)
            for a in range(dim):
                x[i, a] = d0[i, a] + (x[i, a] - d0[i, a]) * f
        act[i] = dist > ract


@njit(cache=True, inline="always")
def _frame3(Q, i, x, y, z):
    """``Q_i``: the orthonormal 3-D frame whose first column is the unit vector ``(x, y, z)``
    (Duff et al. 2017, "Building an orthonormal basis, revisited"); inlined at numba IR level
    (no call with an array argument in the loops)."""
    sgn = 1.0 if z >= 0.0 else -1.0
    a_ = -1.0 / (sgn + z)
    b = x * y * a_
    Q[i, 0, 0] = x
    Q[i, 1, 0] = y
    Q[i, 2, 0] = z
    Q[i, 0, 1] = 1.0 + sgn * x * x * a_
    Q[i, 1, 1] = sgn * b
    Q[i, 2, 1] = -sgn * x
    Q[i, 0, 2] = b
    Q[i, 1, 2] = sgn + y * y * a_
    Q[i, 2, 2] = -y


@njit(cache=True)
def set_frames(nrm, rot, Q, fix, fix0):
    """``fix = fix0`` plus the first axis of the ``rot`` points; ``Q_i`` the orthonormal frame
    whose first column is the unit ``nrm_i`` at the ``rot`` points (2-D: the tangent is ``nrm``
    turned by 90 degrees; 3-D: Duff et al. 2017, "Building an orthonormal basis, revisited"),
    the same as ``global_fair._frames``."""
    n, dim = nrm.shape
    for i in range(n):
        for a in range(dim):
            fix[i, a] = fix0[i, a]
        if not rot[i]:
            continue
        fix[i, 0] = True
        if dim == 2:
            Q[i, 0, 0] = nrm[i, 0]
            Q[i, 1, 0] = nrm[i, 1]
            Q[i, 0, 1] = -nrm[i, 1]
            Q[i, 1, 1] = nrm[i, 0]
        else:
            _frame3(Q, i, nrm[i, 0], nrm[i, 1], nrm[i, 2])


@njit(cache=True, any_layout=('u',))
def admm_active_norms(u, free, out):
    """``|u_i|`` of the free points with ``u_i != 0`` (the projected ones) packed into ``out``;
    returns their number."""
    n, dim = u.shape
    m = 0
    for i in range(n):
        if free[i]:
            uu = 0.0
            for a in range(dim):
                uu += u[i, a] * u[i, a]
            if uu > 0.0:
                out[m] = np.sqrt(uu)
                m += 1
    return m


@njit(cache=True)
def admm_rescale(z, u, g0, f, rho, y):
    """``u *= f`` (new ``rho`` = old / ``f``) and ``y = rho (z - u) - g0``."""
    n, dim = z.shape
    for i in range(n):
        for a in range(dim):
            u[i, a] *= f
            y[i, a] = rho * (z[i, a] - u[i, a]) - g0[i, a]


@njit(cache=True, any_layout=('z', 'u'))
def admm_multipliers(z, u, free, rho, t2, lam):
    """``lam_i = max(rho t2 (u_i . z_i) / |z_i|^2, 0)`` at the free points with ``z_i != 0``
    (from ``g0 + K z + rho u = 0`` and ``g0 + K z + lam z / t2 = 0``), 0 elsewhere; returns the
    sums over the free points of ``lam`` and of the slack ``(1 - |z|^2 / t2) / 2``, and their
    number."""
    n, dim = z.shape
    sl = 0.0
    ss = 0.0
    m = 0
    for i in range(n):
        lam[i] = 0.0
        if not free[i]:
            continue
        zz = 0.0
        uz = 0.0
        for a in range(dim):
            zz += z[i, a] * z[i, a]
            uz += u[i, a] * z[i, a]
        if zz > 0.0:
            lam[i] = max(rho * t2 * uz / zz, 0.0)
        sl += lam[i]
        ss += 0.5 * (1.0 - zz / t2)
        m += 1
    return sl, ss, m


# ------------------------------------------------------------------------------------------
# active-set (semismooth) Newton per-point work
# ------------------------------------------------------------------------------------------


@njit(cache=True)
def ssn_eval_prep(g0, K, ks, p, closed, v, lam, free, t2, kappa, delta, S, rd,
                  B, nrm, c, Q, fix, fix0):
    """Semismooth Newton per-point work, one pass: active set ``S = free & (lam + kappa f > 0) &
    (v != 0)`` (``f = (|v|^2 / t2 - 1) / 2``); ``lam`` clipped to ``max(lam, 0)`` on ``S`` and 0
    elsewhere; ``rd = g0 + K v + lam v / t2``; blocks ``B = (lam / t2 + delta) I``; at the
    active points the unit normals ``nrm``, the prescribed normal displacements ``c = -f t2 /
    |v|`` (the linearised sphere), their frames ``Q`` (as :func:`set_frames`; planar: the first
    column only, and only the diagonal of ``B``, whose other entries must be 0) and ``fix =
    fix0`` plus the normal axis. Returns ``(max |rd|, max f over free, max |f|
    over S, |S|)``."""
    return ssn_eval_range(g0, K, ks, p, closed, v, lam, free, t2, kappa, delta, S, rd, B,
                          nrm, c, Q, fix, fix0, 0, v.shape[0])


@njit(cache=True, nogil=True, any_layout=('B', 'Q'))
def ssn_eval_range(g0, K, ks, p, closed, v, lam, free, t2, kappa, delta, S, rd,
                   B, nrm, c, Q, fix, fix0, i0, i1):
    """:func:`ssn_eval_prep` on the points ``i0 .. i1 - 1`` (reads ``v`` of their neighbours,
    writes their own data only: ranges may run concurrently; the maxima and the count of
    several ranges combine to those of their union)."""
    n, dim = v.shape
    c23 = dim == 2 and p == 3
    rdm = 0.0
    fm = -np.inf
    fsm = 0.0
    ns = 0
    for i in range(i0, i1):
        vv = 0.0
        for a in range(dim):
            vv += v[i, a] * v[i, a]
        r = np.sqrt(vv)
        fi = 0.5 * (vv / t2 - 1.0)
        for a in range(dim):
            fix[i, a] = fix0[i, a]
        if not free[i]:
            S[i] = False
            lam[i] = 0.0
            for a in range(dim):
                rd[i, a] = 0.0
        else:
            act = lam[i] + kappa * fi > 0.0 and r > 0.0
            S[i] = act
            if act:
                ns += 1
                if lam[i] < 0.0:
                    lam[i] = 0.0
                if not abs(fi) <= fsm:
                    fsm = abs(fi)
            else:
                lam[i] = 0.0
            if not fi <= fm:
                fm = fi
            li = lam[i]
            interior = i >= p and i + p < n
            if c23 and interior:
                k0 = (K[i, 0] * ks)
                k1 = (K[i, 1] * ks)
                k2 = (K[i, 2] * ks)
                k3 = (K[i, 3] * ks)
                k4 = (K[i, 4] * ks)
                k5 = (K[i, 5] * ks)
                k6 = (K[i, 6] * ks)
                for a in range(2):
                    acc = (k0 * v[i - 3, a] + k1 * v[i - 2, a] + k2 * v[i - 1, a] + k3 * v[i, a]
                           + k4 * v[i + 1, a] + k5 * v[i + 2, a] + k6 * v[i + 3, a])
                    x = g0[i, a] + acc + li * (v[i, a] / t2)
                    rd[i, a] = x
                    if not abs(x) <= rdm:  # NaN propagates
                        rdm = abs(x)
            for a in range(dim):
                if c23 and interior:
                    break
                acc = _krow(K, ks, p, closed, v, i, a, interior)
                x = g0[i, a] + acc + li * (v[i, a] / t2)
                rd[i, a] = x
                if not abs(x) <= rdm:  # NaN propagates
                    rdm = abs(x)
        iso = lam[i] / t2 + delta
        if dim == 2:  # off-diagonal entries stay 0 (B allocated zero)
            B[i, 0, 0] = iso
            B[i, 1, 1] = iso
        else:
            for a in range(dim):
                for b in range(dim):
                    B[i, a, b] = iso if a == b else 0.0
        if S[i]:
            for a in range(dim):
                nrm[i, a] = v[i, a] / r
            c[i] = -fi * t2 / r
            fix[i, 0] = True
            if dim == 2:  # first column only: the planar kernels build the rotation from it
                Q[i, 0, 0] = nrm[i, 0]
                Q[i, 1, 0] = nrm[i, 1]
            else:
                _frame3(Q, i, nrm[i, 0], nrm[i, 1], nrm[i, 2])
        # (nrm, c and Q of inactive points are left as they are: never read)
    return rdm, fm, fsm, ns


@njit(cache=True)
def ssn_update_k(K, ks, p, closed, v, dv, rd, lam, S, nrm, t2, retract,
                 edges_only=False):
    """Semismooth Newton update: the multipliers of the active points from the normal component
    of the stationarity equation (``K dv`` computed on the fly), then ``v += dv``; with
    ``retract`` the active points are put back on their sphere (the tangent-plane step
    overshoots radially by ``|dv_t|^2 / (2 tol)``). ``edges_only`` (planar cubics, ``n > 6``):
    the points ``3 .. n - 4`` are left to the caller (:func:`ssn_update23_range`)."""
    n, dim = v.shape
    if dim == 2 and p == 3 and n > 6:
        if not edges_only:
            ssn_update23_range(K, ks, closed, v, dv, rd, lam, S, nrm, t2, retract, np.intp(3),
                               n - 3)
        lo = 3
        hi = n - 3
    else:
        lo = 0
        hi = 0
    tol = np.sqrt(t2)
    kdv = np.empty(dim)
    for i in range(n):
        if lo <= i < hi:
            continue
        for a in range(dim):
            kdv[a] = _krow(K, ks, p, closed, dv, i, a, False)
        if S[i]:
            acc = 0.0
            li = lam[i] / t2
            vv = 0.0
            for a in range(dim):
                acc += nrm[i, a] * (rd[i, a] + kdv[a] + li * dv[i, a])
                vv += v[i, a] * v[i, a]
            lam[i] = lam[i] - acc * t2 / np.sqrt(vv)  # |v_i| as in the evaluation
        else:
            lam[i] = 0.0
    for i in range(n):
        if lo <= i < hi:
            continue
        vv = 0.0
        for a in range(dim):
            v[i, a] += dv[i, a]
            vv += v[i, a] * v[i, a]
        if retract and S[i] and vv > 0.0:
            f = tol / np.sqrt(vv)
            for a in range(dim):
                v[i, a] *= f


@njit(cache=True, error_model="numpy", nogil=True)
def ssn_update23_range(K, ks, closed, v, dv, rd, lam, S, nrm, t2, retract, i0, i1):
    """:func:`ssn_update_k` for planar cubics on the interior points ``i0 .. i1 - 1``: one
    pass, selects instead of branches (numpy error model: the unselected quotients of inactive
    points may be inf). Reads ``dv`` of the neighbours, writes the points' own ``v`` and
    ``lam``: ranges may run concurrently."""
    tol = np.sqrt(t2)
    for i in range(i0, i1):
        si = S[i]
        li = lam[i] / t2
        acc = 0.0
        k0 = K[i, 0] * ks
        k1 = K[i, 1] * ks
        k2 = K[i, 2] * ks
        k3 = K[i, 3] * ks
        k4 = K[i, 4] * ks
        k5 = K[i, 5] * ks
        k6 = K[i, 6] * ks
        for a in range(2):
            kd = (k0 * dv[i - 3, a] + k1 * dv[i - 2, a] + k2 * dv[i - 1, a] + k3 * dv[i, a]
                  + k4 * dv[i + 1, a] + k5 * dv[i + 2, a] + k6 * dv[i + 3, a])
            acc += nrm[i, a] * (rd[i, a] + kd + li * dv[i, a])
        r = np.sqrt(v[i, 0] * v[i, 0] + v[i, 1] * v[i, 1])  # |v_i| as in the evaluation
        lnew = lam[i] - acc * t2 / r
        lam[i] = lnew if si else 0.0
        x0 = v[i, 0] + dv[i, 0]
        x1 = v[i, 1] + dv[i, 1]
        vv = x0 * x0 + x1 * x1
        f = tol / np.sqrt(vv)
        f = f if (retract and si and vv > 0.0) else 1.0
        v[i, 0] = x0 * f
        v[i, 1] = x1 * f
