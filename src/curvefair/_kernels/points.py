"""Compiled kernels of :mod:`curvefair.fairing.points_l1`: the interior point of one tube QP.

Unknowns interleaved: B-spline coefficient ``j`` (of the natural cubic, after the two end
conditions are eliminated), coordinate ``a`` is unknown ``j dim + a``. Constraint row ``i``
(a data point, or a curve sample between two data points) evaluates the curve at one parameter:
``C_i x = sum_s W[i, s] x_{start_i + s}`` (``s = 0 .. 3``; a cubic B-spline has at most four
non-zero basis functions there). The Newton matrix is

    M = K + sum_i C_i^T B_i C_i,

``K`` the (scaled) interleaved energy matrix, banded with ``dim x dim`` blocks of block
half-bandwidth 4 (given by its lower band ``Kb``), and one symmetric ``dim x dim`` block
``B_i`` per constraint row. Lower band storage ``L[r, k] = M[r + k, r]`` with
``kd = 5 dim - 1``, as :func:`curvefair._kernels.global_fair.band_cholesky` takes it.
"""

from __future__ import annotations

import numpy as np

from .._jit import njit
from .global_fair import band_cholesky, band_solve


@njit(cache=True)
def assemble_newton(L0, Aw, B, dim, L):
    """``L = L0 + band(sum_i A_i^T B_i A_i)`` for a tridiagonal ``A`` (``A[i, i - 1 + s] =
    Aw[i, s]``): ``L0`` the lower band of the (interleaved) energy matrix, ``L`` of the same
    shape ``(N dim, 5 dim)``."""
    N = Aw.shape[0]
    kd = L.shape[1] - 1
    L[:, :] = L0
    for i in range(N):
        for s2 in range(3):
            j2 = i - 1 + s2
            if j2 < 0 or j2 >= N:
                continue
            w2 = Aw[i, s2]
            if w2 == 0.0:
                continue
            for s1 in range(s2, 3):
                j1 = i - 1 + s1
                if j1 < 0 or j1 >= N:
                    continue
                w = Aw[i, s1] * w2
                if w == 0.0:
                    continue
                for b in range(dim):
                    r = j2 * dim + b
                    for a in range(dim):
                        rr = j1 * dim + a
                        k = rr - r
                        if k >= 0 and k <= kd:
                            L[r, k] += w * B[i, a, b]
    return 0


@njit(cache=True)
def energy_band(jstart, JV, Wk, gstart, GV, gw, L):
    """Lower band ``L[r, k] = K[r + k, r]`` (interleaved, ``kd = 5 dim - 1``) of
    ``K = sum_k J_k^T Wk_k J_k + sum_k gw_k g_k^T g_k`` (``(x) I``): ``J_k`` the jump rows,
    ``JV[k, s]`` at columns ``jstart_k + s`` (``s = 0 .. 4``), ``Wk`` their ``dim x dim``
    weights; ``g_k`` the third-derivative rows (four columns from ``gstart_k``). ``L`` zeroed
    first."""
    nj, _, dim = Wk.shape
    kd = L.shape[1] - 1
    L[:, :] = 0.0
    for k in range(nj):
        j0 = jstart[k]
        for s2 in range(5):
            v2 = JV[k, s2]
            if v2 == 0.0:
                continue
            for s1 in range(s2, 5):
                w = JV[k, s1] * v2
                if w == 0.0:
                    continue
                for b in range(dim):
                    r = (j0 + s2) * dim + b
                    for aa in range(dim):
                        kk = (j0 + s1) * dim + aa - r
                        if kk >= 0 and kk <= kd:
                            L[r, kk] += w * Wk[k, aa, b]
    for k in range(gstart.shape[0]):
        j0 = gstart[k]
        c = gw[k]
        for s2 in range(4):
            v2 = GV[k, s2] * c
            for s1 in range(s2, 4):
                w = GV[k, s1] * v2
                kk = (s1 - s2) * dim
                for b in range(dim):
                    L[(j0 + s2) * dim + b, kk] += w
    return 0


@njit(cache=True)
def band_quad(Kb, x):
    """``x^T K x`` for the symmetric band ``Kb[r, k] = K[r + k, r]`` (``x`` 1-D)."""
    n = x.shape[0]
    kd = Kb.shape[1] - 1
    s = 0.0
    for r in range(n):
        xr = x[r]
        t = 0.5 * Kb[r, 0] * xr
        kmax = min(kd, n - 1 - r)
        for k in range(1, kmax + 1):
            t += Kb[r, k] * x[r + k]
        s += t * xr
    return 2.0 * s


@njit(cache=True)
def apply_rows(start, W, x, out):
    """``out = C x`` (``x`` shape (N, dim), ``out`` shape (m, dim))."""
    m = start.shape[0]
    dim = x.shape[1]
    for i in range(m):
        j0 = start[i]
        for a in range(dim):
            s = 0.0
            for s_ in range(4):
                s += W[i, s_] * x[j0 + s_, a]
            out[i, a] = s


@njit(cache=True)
def _rows_t(start, W, v, out):
    """``out += C^T v`` (``v`` shape (m, dim), ``out`` shape (N, dim))."""
    m = start.shape[0]
    dim = v.shape[1]
    for i in range(m):
        j0 = start[i]
        for s_ in range(4):
            w = W[i, s_]
            if w != 0.0:
                for a in range(dim):
                    out[j0 + s_, a] += w * v[i, a]


@njit(cache=True)
def _band_mv(Kb, x, out):
    """``out = K x`` for the symmetric band ``Kb[r, k] = K[r + k, r]`` (``x``, ``out`` 1-D)."""
    n = x.shape[0]
    kd = Kb.shape[1] - 1
    for r in range(n):
        out[r] = Kb[r, 0] * x[r]
    for r in range(n):
        kmax = min(kd, n - 1 - r)
        xr = x[r]
        for k in range(1, kmax + 1):
            v = Kb[r, k]
            out[r + k] += v * xr
            out[r] += v * x[r + k]


@njit(cache=True)
def _residuals(Kb, start, W, Y, t2, x, lam, tinv, v, fi, rd, rc):
    """``v = C x - Y``, ``f_i = (|v_i|^2 / t2_i - 1) / 2``, ``rd = K x + C^T (lam v / t2)``,
    ``rc = -lam f - tinv``; returns the residual norm squared without ``rd``'s scaling."""
    m, dim = Y.shape
    N = x.shape[0]
    apply_rows(start, W, x, v)
    for i in range(m):
        s = 0.0
        for a in range(dim):
            v[i, a] -= Y[i, a]
            s += v[i, a] * v[i, a]
        fi[i] = 0.5 * (s / t2[i] - 1.0)
        rc[i] = -lam[i] * fi[i] - tinv
    rdf = rd.reshape(N * dim)
    _band_mv(Kb, x.reshape(N * dim), rdf)
    tmp = np.empty((m, dim))
    for i in range(m):
        c = lam[i] / t2[i]
        for a in range(dim):
            tmp[i, a] = c * v[i, a]
    _rows_t(start, W, tmp, rd)


@njit(cache=True)
def _assemble(start, W, v, fi, lam, t2, a, L):
    """``L += band(sum_i C_i^T B_i C_i)``, ``B_i = lam_i / t2_i I + ww_i a_i a_i^T`` with
    ``a_i = v_i / t2_i`` (stored in ``a``) and ``ww_i = lam_i / (-f_i)``: the constraint part
    of the Newton matrix of :func:`tube_ipm`."""
    m, dim = v.shape
    kd = L.shape[1] - 1
    for i in range(m):
        ww = lam[i] / (-fi[i])
        d0 = lam[i] / t2[i]
        for b in range(dim):
            a[i, b] = v[i, b] / t2[i]
        j0 = start[i]
        for s2 in range(4):
            w2 = W[i, s2]
            if w2 == 0.0:
                continue
            for s1 in range(s2, 4):
                w = W[i, s1] * w2
                if w == 0.0:
                    continue
                for b in range(dim):
                    r = (j0 + s2) * dim + b
                    for aa in range(dim):
                        k = (j0 + s1) * dim + aa - r
                        if k >= 0 and k <= kd:
                            bab = ww * a[i, aa] * a[i, b]
                            if aa == b:
                                bab += d0
                            L[r, k] += w * bab


@njit(cache=True)
def _assemble2(start, W, v, fi, lam, t2, a, L):
    """:func:`_assemble` for ``dim = 2`` without branches: the same products added in the
    same order (a zero weight adds an exact zero), so the same band to the last bit."""
    m = v.shape[0]
    for i in range(m):
        ww = lam[i] / (-fi[i])
        d0 = lam[i] / t2[i]
        a0 = v[i, 0] / t2[i]
        a1 = v[i, 1] / t2[i]
        a[i, 0] = a0
        a[i, 1] = a1
        b00 = ww * a0 * a0 + d0
        b01 = ww * a1 * a0
        b10 = ww * a0 * a1
        b11 = ww * a1 * a1 + d0
        j0 = start[i]
        for s2 in range(4):
            w2 = W[i, s2]
            r = (j0 + s2) * 2
            w = W[i, s2] * w2
            L[r, 0] += w * b00
            L[r, 1] += w * b01
            L[r + 1, 0] += w * b11
            for s1 in range(s2 + 1, 4):
                w = W[i, s1] * w2
                k = (s1 - s2) * 2
                L[r, k] += w * b00
                L[r, k + 1] += w * b01
                L[r + 1, k - 1] += w * b10
                L[r + 1, k] += w * b11


@njit(cache=True)
def tube_ipm(Kb, start, W, Y, rad, x, lam, max_steps, gap, stall):
    """Primal-dual interior point for ``min x^T K x / 2`` (``K`` the scaled energy, lower band
    ``Kb``) s.t. ``|C_i x - Y_i| <= rad_i``, from a strictly feasible ``x`` and positive ``lam``
    (both updated in place). Boyd & Vandenberghe sec. 11.7: surrogate gap ``eta = -f.lam``,
    centring ``t = 10 m / eta``, Newton step on the modified KKT residual, step length kept
    strictly feasible (``lam > 0``, every ``|C_i x - Y_i| < rad_i``) with a backtracking line
    search on the residual norm.

    Returns ``(steps, code)``: code 0 converged (``max|rd| < 1e-8`` of its initial value and
    ``eta < gap``, or ``eta < stall`` and not halved over the last three steps: the rounding
    floor of ``eta``, which grows with the number of constraints), 1 max_steps, 2 numerical
    (factorisation, non-finite step or no progress: converged if ``eta < 1e-6``, reported by
    the caller).
    """
    N, dim = x.shape
    m = Y.shape[0]
    n = N * dim
    kd = Kb.shape[1] - 1
    t2 = rad * rad
    v = np.empty((m, dim))
    fi = np.empty(m)
    rd = np.empty((N, dim))
    rc = np.empty(m)
    v1 = np.empty((m, dim))
    fi1 = np.empty(m)
    rd1 = np.empty((N, dim))
    rc1 = np.empty(m)
    a = np.empty((m, dim))
    L = np.empty((n, kd + 1))
    rhs = np.empty((N, dim))
    tmp = np.empty((m, dim))
    Cdx = np.empty((m, dim))
    dlam = np.empty(m)
    x1 = np.empty((N, dim))
    lam1 = np.empty(m)
    qa1 = np.empty(m)
    qa2 = np.empty(m)
    qc0 = np.empty(m)
    R1 = np.empty((N, dim))
    R2 = np.empty((N, dim))
    _residuals(Kb, start, W, Y, t2, x, lam, 0.0, v, fi, rd, rc)
    gscale = 0.0
    for j in range(N):
        for b in range(dim):
            gscale = max(gscale, abs(rd[j, b]))
    if gscale == 0.0:
        gscale = 1.0
    steps = 0
    code = 1
    hist = np.full(3, np.inf)
    while steps < max_steps:
        eta = 0.0
        for i in range(m):
            eta -= fi[i] * lam[i]
        tinv = eta / (10.0 * m)
        # v, f and rd are those of the current (x, lam); only rc depends on the centring
        for i in range(m):
            rc[i] = -lam[i] * fi[i] - tinv
        rdn = 0.0
        for j in range(N):
            for b in range(dim):
                rdn = max(rdn, abs(rd[j, b]))
        if rdn < 1e-8 * gscale:
            if eta < gap:
                code = 0
                break
            # the rounding floor of the gap (it grows with m): below ``stall`` and not halved
            # in three steps, the iterate is optimal to the accuracy float64 gives
            if eta < stall and eta > 0.5 * hist[steps % 3]:
                code = 0
                break
        hist[steps % 3] = eta
        # Newton matrix K + sum_i C_i^T B_i C_i, B_i = lam_i / t2_i I + ww_i a_i a_i^T
        L[:, :] = Kb
        if dim == 2:
            _assemble2(start, W, v, fi, lam, t2, a, L)
        else:
            _assemble(start, W, v, fi, lam, t2, a, L)
        # rhs = -rd - C^T (a rc / f)
        for j in range(N):
            for b in range(dim):
                rhs[j, b] = -rd[j, b]
        for i in range(m):
            c = -rc[i] / fi[i]
            for b in range(dim):
                tmp[i, b] = c * a[i, b]
        _rows_t(start, W, tmp, rhs)
        if band_cholesky(L, n) != 0:
            code = 2
            break
        dxf = rhs.reshape(n)
        band_solve(L, n, dxf)
        dx = rhs
        finite = True
        for j in range(n):
            if not np.isfinite(dxf[j]):
                finite = False
                break
        if not finite:
            code = 2
            break
        apply_rows(start, W, dx, Cdx)
        smax = 1.0
        tmax = np.inf
        for i in range(m):
            adx = 0.0
            a2 = 0.0
            a1 = 0.0
            c0 = 0.0
            for b in range(dim):
                adx += a[i, b] * Cdx[i, b]
                a2 += Cdx[i, b] * Cdx[i, b]
                a1 += v[i, b] * Cdx[i, b]
                c0 += v[i, b] * v[i, b]
            qa1[i] = a1
            qa2[i] = a2
            qc0[i] = c0
            c0 -= t2[i]
            dl = (rc[i] - lam[i] * adx) / fi[i]
            dlam[i] = dl
            if dl < 0.0:
                smax = min(smax, -lam[i] / dl)
            if a2 > 0.0:
                disc = max(a1 * a1 - a2 * c0, 0.0)
                tmax = min(tmax, (-a1 + np.sqrt(disc)) / a2)
        st = min(0.99 * smax, 0.99 * tmax)
        rn = 0.0
        for j in range(N):
            for b in range(dim):
                rn += (rd[j, b] / gscale) ** 2
        for i in range(m):
            rn += rc[i] * rc[i]
        rnorm = np.sqrt(rn)
        # along the step the residual is a polynomial in its length s (K quadratic, the
        # constraints quadratic in x): rd(s) = rd + s R1 + s^2 R2, |v_i(s)|^2 = c0 + 2 s a1
        # + s^2 a2; the backtracking tests it without re-evaluating C x, and the accepted
        # point is evaluated exactly (and rejected if rounding put it outside a ball)
        _band_mv(Kb, dxf, R1.reshape(n))
        for i in range(m):
            c1 = dlam[i] / t2[i]
            c2 = lam[i] / t2[i]
            for b in range(dim):
                tmp[i, b] = c1 * v[i, b] + c2 * Cdx[i, b]
        _rows_t(start, W, tmp, R1)
        for i in range(m):
            c1 = dlam[i] / t2[i]
            for b in range(dim):
                tmp[i, b] = c1 * Cdx[i, b]
        R2[:, :] = 0.0
        _rows_t(start, W, tmp, R2)
        while st > 1e-14:
            ok = True
            r1 = 0.0
            for i in range(m):
                f1 = 0.5 * ((qc0[i] + st * (2.0 * qa1[i] + st * qa2[i])) / t2[i] - 1.0)
                if not f1 < 0.0:
                    ok = False
                    break
                c = -(lam[i] + st * dlam[i]) * f1 - tinv
                r1 += c * c
            if ok:
                for j in range(N):
                    for b in range(dim):
                        r1 += ((rd[j, b] + st * (R1[j, b] + st * R2[j, b])) / gscale) ** 2
                if np.sqrt(r1) <= (1.0 - 0.01 * st) * rnorm:
                    for j in range(N):
                        for b in range(dim):
                            x1[j, b] = x[j, b] + st * dx[j, b]
                    for i in range(m):
                        lam1[i] = lam[i] + st * dlam[i]
                    _residuals(Kb, start, W, Y, t2, x1, lam1, tinv, v1, fi1, rd1, rc1)
                    for i in range(m):
                        if not fi1[i] < 0.0:
                            ok = False
                            break
                    if ok:
                        break
            st *= 0.5
        if st <= 1e-14:
            code = 2
            break
        x[:, :] = x1
        lam[:] = lam1
        fi[:] = fi1
        v[:, :] = v1
        rd[:, :] = rd1
        steps += 1
    return steps, code


@njit(cache=True)
def polyline_distance(x, poly, idx, seg_ok, use_ok, best):
    """``best[r]``: the distance of ``x[r]`` to the nearest of the polyline segments
    ``poly[i] -> poly[i + 1]`` next to the vertices ``idx[r, :]`` (``i = idx - 1`` and ``idx``,
    clipped to the segments; with ``use_ok``, segments whose ``seg_ok[i]`` is False count as
    infinitely far). The arithmetic, operation for operation, of the numpy loop it replaces in
    :func:`curvefair.fairing.points_l1._polyline_distance` (sums over the coordinates as
    numpy's reductions add them, in order; NaN propagating as in ``np.minimum``)."""
    m, dim = x.shape
    hi = poly.shape[0] - 2
    d = np.empty(dim)
    for r in range(m):
        b = np.inf
        for col in range(idx.shape[1]):
            for off in (-1, 0):
                i0 = idx[r, col] + off
                if i0 < 0:
                    i0 = 0
                elif i0 > hi:
                    i0 = hi
                for k in range(dim):
                    d[k] = poly[i0 + 1, k] - poly[i0, k]
                # numpy's reduction over a short axis adds the coordinates in order
                dd = d[0] * d[0]
                for k in range(1, dim):
                    dd += d[k] * d[k]
                if dd < 1e-300:
                    dd = 1e-300
                num = (x[r, 0] - poly[i0, 0]) * d[0]
                for k in range(1, dim):
                    num += (x[r, k] - poly[i0, k]) * d[k]
                s = num / dd
                if s < 0.0:
                    s = 0.0
                elif s > 1.0:
                    s = 1.0
                ss = 0.0
                for k in range(dim):
                    e = (x[r, k] - poly[i0, k]) - s * d[k]
                    if k == 0:
                        ss = e * e
                    else:
                        ss += e * e
                dist = np.sqrt(ss)
                if use_ok and not seg_ok[i0]:
                    dist = np.inf
                if np.isnan(b) or np.isnan(dist):
                    b = np.nan
                elif dist < b:
                    b = dist
        best[r] = b


# ------------------------------------------------------------------------------------------
# the closed-curve interior point (:func:`curvefair.fairing.points_l1._tube_qp_cyclic`): its
# sparse products, with scipy's summation orders (bit for bit the scipy.sparse results)
# ------------------------------------------------------------------------------------------
@njit(cache=True)
def csr_matvecs(indptr, indices, data, X, out):
    """``out = C @ X`` for ``C`` in CSR arrays: each row's stored entries added in their stored
    order onto 0.0, as scipy's ``csr_matvecs`` (``X`` and ``out`` 2-D)."""
    nv = X.shape[1]
    for i in range(indptr.shape[0] - 1):
        for k in range(nv):
            out[i, k] = 0.0
        for jj in range(indptr[i], indptr[i + 1]):
            j = indices[jj]
            a = data[jj]
            for k in range(nv):
                out[i, k] += a * X[j, k]


@njit(cache=True)
def csr_t_matvecs(indptr, indices, data, Z, out):
    """``out = C.T @ Z`` for ``C`` in CSR arrays, as scipy computes it (``C.T`` is CSC on the
    same arrays, ``csc_matvecs``): rows of ``C`` in order, each entry added onto 0.0."""
    nv = Z.shape[1]
    out[:, :] = 0.0
    for j in range(indptr.shape[0] - 1):
        for ii in range(indptr[j], indptr[j + 1]):
            i = indices[ii]
            a = data[ii]
            for k in range(nv):
                out[i, k] += a * Z[j, k]


@njit(cache=True)
def cyclic_newton_band(cp, ci, cx, B, kp, ki, kx, pos, dim):
    """The lower band, in the order ``pos`` (``pos[j]``: position of unknown block ``j``), of
    ``M = Ks + CI^T blockdiag(B) CI`` with ``CI = C (x) I_dim``: ``(band, kd)``, ``band[o, c] =
    M[r, c]`` (permuted indices, ``o = r - c``), ``kd`` the largest ``o`` of a non-zero entry.

    The values are those of ``(Pm @ (Ks + CI.T @ Bd @ CI) @ Pm.T)`` in scipy.sparse, bit for
    bit: ``CI.T @ Bd`` has one product per entry, ``X[(p, a), (k, b)] = B[k, a, b] C[k, p]``
    (entries that are exactly 0 dropped); ``X @ CI`` adds, onto 0.0 and over the constraint
    rows ``k`` in ascending order, ``C[k, q] X[(p, a), (k, b)]``; then one addition of ``Ks``
    (``C``: ``cp, ci, cx``; ``Ks``: ``kp, ki, kx``, CSR arrays)."""
    N = pos.shape[0]
    n = N * dim
    m = cp.shape[0] - 1
    kdmax = 0
    for k in range(m):
        for jj in range(cp[k], cp[k + 1]):
            for ll in range(cp[k], cp[k + 1]):
                d = abs(pos[ci[jj]] - pos[ci[ll]])
                if d > kdmax:
                    kdmax = d
    kdmax = kdmax * dim + dim - 1
    for r in range(n):
        for jj in range(kp[r], kp[r + 1]):
            c = ki[jj]
            d = abs((pos[r // dim] * dim + r % dim) - (pos[c // dim] * dim + c % dim))
            if d > kdmax:
                kdmax = d
    band = np.zeros((kdmax + 1, n))
    for k in range(m):
        for jj in range(cp[k], cp[k + 1]):
            p = ci[jj]
            cpv = cx[jj]
            for ll in range(cp[k], cp[k + 1]):
                q = ci[ll]
                cqv = cx[ll]
                for a in range(dim):
                    rr = pos[p] * dim + a
                    for b in range(dim):
                        cc = pos[q] * dim + b
                        if rr < cc:
                            continue
                        xv = B[k, a, b] * cpv
                        if xv != 0.0:
                            band[rr - cc, cc] += cqv * xv
    for r in range(n):
        rr = pos[r // dim] * dim + r % dim
        for jj in range(kp[r], kp[r + 1]):
            c = ki[jj]
            cc = pos[c // dim] * dim + c % dim
            if rr >= cc:
                band[rr - cc, cc] = kx[jj] + band[rr - cc, cc]
    kd = 0
    for o in range(kdmax, 0, -1):
        nz = False
        for c in range(n - o):
            if band[o, c] != 0.0:
                nz = True
                break
        if nz:
            kd = o
            break
    return band, kd


@njit(cache=True)
def csr_matmat(n_row, n_col, Ap, Aj, Ax, Bp, Bj, Bx):
    """``C = A @ B`` in CSR arrays exactly as scipy.sparse computes it (``csr_matmat`` of its
    sparsetools): row by row, products added onto 0.0 in the order of ``A``'s and then
    ``B``'s stored entries; each row's columns stored in reverse order of first touch; exact
    zeros dropped. Returns ``(indptr, indices, data)`` (int32 indices: the small operators of
    :func:`curvefair.fairing.points_l1.natural_operators`)."""
    nxt = np.full(n_col, -1, dtype=np.int64)
    sums = np.zeros(n_col)
    # an upper bound of the entries: the structural count (scipy's csr_matmat_maxnnz)
    mask = np.full(n_col, -1, dtype=np.int64)
    cap = 0
    for i in range(n_row):
        for jj in range(Ap[i], Ap[i + 1]):
            j = Aj[jj]
            for kk in range(Bp[j], Bp[j + 1]):
                k = Bj[kk]
                if mask[k] != i:
                    mask[k] = i
                    cap += 1
    Cp = np.empty(n_row + 1, dtype=np.int32)
    Cj = np.empty(cap, dtype=np.int32)
    Cx = np.empty(cap)
    nnz = 0
    Cp[0] = 0
    for i in range(n_row):
        head = -2
        length = 0
        for jj in range(Ap[i], Ap[i + 1]):
            j = Aj[jj]
            v = Ax[jj]
            for kk in range(Bp[j], Bp[j + 1]):
                k = Bj[kk]
                sums[k] += v * Bx[kk]
                if nxt[k] == -1:
                    nxt[k] = head
                    head = k
                    length += 1
        for _ in range(length):
            if sums[head] != 0:
                Cj[nnz] = head
                Cx[nnz] = sums[head]
                nnz += 1
            temp = head
            head = nxt[head]
            nxt[temp] = -1
            sums[temp] = 0.0
        Cp[i + 1] = nnz
    return Cp, Cj[:nnz].copy(), Cx[:nnz].copy()
