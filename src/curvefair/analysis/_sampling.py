"""The sampling pass of :func:`curvefair.analyze`: curvature and ``dkappa/ds`` on a
Gauss-Lobatto grid per segment, quadratures, and the exact sign structure of both.

Layout: every segment is sampled at ``K`` Gauss-Lobatto fractions ``x_0 = 0 < ... <
x_{K-1} = 1`` (both one-sided limits at each knot are samples). The sign of the curvature is the
sign of the polynomial ``N = x'y'' - y'x''`` and the sign of ``dkappa/ds`` that of a polynomial
numerator ``E``; both are recovered exactly (up to rounding) from their ``K`` sampled values,
``K`` being larger than their degree, and their Bernstein coefficients certify that no sign
change hides between two samples, or locate it (see :func:`sample_curve`).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from math import comb

import numpy as np
from numba import njit

from .._typing import FloatArray
from ._core import CROSS_RTOL, SPEED_RTOL, derivs_at, falling, frenet, lobatto

__all__ = ["Samples", "sample_curve", "scan_sign_changes"]

#: Rounding level of curvature-type quantities computed from floating-point spline data: on a
#: segment of length scale ``ell`` starting at distance ``pos`` from the origin, the
#: curvature is zero within ``ROUNDING_FLOOR (ell + pos) / ell**2`` and ``dkappa/ds`` within
#: ``ROUNDING_FLOOR (ell + pos) / ell**3``: coordinates rounded to ``eps * pos`` and
#: derivatives to ``eps * ell`` bend a straight segment that much (about 1e3 machine
#: epsilons, a margin of about 100 over the rounding estimates).
ROUNDING_FLOOR = 1e3 * float(np.finfo(float).eps)
_MAX_SPLITS = 48


def _bernstein_basis(d: int, u: FloatArray) -> FloatArray:
    """``(len(u), d+1)`` matrix of the Bernstein polynomials of degree ``d`` at ``u``."""
    i = np.arange(d + 1)
    binom = np.array([comb(d, k) for k in i], dtype=float)
    return binom[None, :] * u[:, None] ** i[None, :] * (1.0 - u[:, None]) ** (d - i)[None, :]


@dataclass(frozen=True)
class _Plan:
    K: int
    x: FloatArray
    w: FloatArray
    tab: FloatArray  # (3, K, p1): derivative nu (1, 2, 3) of u^j at x_q
    fit: tuple[FloatArray | None, FloatArray]  # values (K) -> Bernstein coeffs on [0, 1]
    sub: tuple[FloatArray | None, FloatArray]  # values (K) -> Bernstein coeffs per gap
    degs: tuple[int, int]


def min_nodes(degree: int, planar: bool) -> int:
    """Smallest number of Lobatto nodes per segment the sign certificate needs."""
    p = degree
    d_n = max(2 * p - 4, 0)
    d_e = max(4 * p - 7 if planar else 6 * p - 11, 0)
    return max(d_e + 1, d_n + 2, p + 3)


@lru_cache(maxsize=32)
def _plan(degree: int, planar: bool, nodes: int = 0) -> _Plan:
    p = degree
    # degrees: the leading coefficients of r' and r'' are parallel, so N = x'y'' - y'x'' has
    # degree 2p - 4 (not 2p - 3), N' = x'y''' - y'x''' degree 2p - 5, and the numerator E of
    # dkappa/ds degree 4p - 7 (planar) or 6p - 11 (3-D: |C|^2 (r'.r''), C = r' x r'')
    d_n = max(2 * p - 4, 0)
    d_e = max(4 * p - 7 if planar else 6 * p - 11, 0)
    K = max(min_nodes(p, planar), nodes)
    x, w = lobatto(K)
    tab = np.zeros((3, K, p + 1))
    for nu in range(1, 4):
        for j in range(nu, p + 1):
            tab[nu - 1, :, j] = falling(j, nu)[0] * x ** (j - nu)
    fits: list[FloatArray | None] = []
    subs: list[FloatArray | None] = []
    v = 0.5 - 0.5 * np.cos(np.pi * (np.arange(K) + 0.5) / K)  # Chebyshev points in (0, 1)
    for d in (d_n if planar else -1, d_e):
        if d < 0:
            fits.append(None)
            subs.append(None)
            continue
        pinv = np.linalg.pinv(_bernstein_basis(d, x))  # (d+1, K)
        fits.append(np.ascontiguousarray(pinv.T))  # b = vals @ fit
        # Bernstein coefficients on each gap [x_q, x_{q+1}] of the same polynomial
        S = np.empty((K - 1, K, d + 1))
        for q in range(K - 1):
            vv = x[q] + (x[q + 1] - x[q]) * v
            # values at vv from the global Bernstein coefficients, then refit on the gap
            to_vals = _bernstein_basis(d, vv) @ pinv  # (K, K): sample values -> values at vv
            S[q] = (np.linalg.pinv(_bernstein_basis(d, v)) @ to_vals).T
        subs.append(S)
    return _Plan(K=K, x=x, w=w, tab=tab, fit=(fits[0], fits[1]),
                 sub=(subs[0], subs[1]), degs=(d_n, d_e))


def _variations(b: FloatArray) -> np.ndarray:
    """Sign changes (zeros skipped) along the last axis."""
    sg = np.sign(b)
    if np.all(sg != 0):
        return np.count_nonzero(sg[..., 1:] != sg[..., :-1], axis=-1)
    n = sg.shape[-1]
    nz = sg != 0
    idx = np.where(nz, np.arange(n), 0)
    np.maximum.accumulate(idx, axis=-1, out=idx)
    filled = np.take_along_axis(sg, idx, axis=-1)
    prev = filled[..., :-1]
    cur = sg[..., 1:]
    return np.count_nonzero((cur != 0) & (prev != 0) & (cur != prev), axis=-1)


def _split(b: FloatArray) -> tuple[FloatArray, FloatArray]:
    """de Casteljau at 1/2 of Bernstein coefficients ``(k, d+1)``."""
    n = b.shape[1]
    left = np.empty_like(b)
    right = np.empty_like(b)
    cur = b
    left[:, 0] = cur[:, 0]
    right[:, n - 1] = cur[:, n - 1]
    for r in range(1, n):
        cur = 0.5 * (cur[:, :-1] + cur[:, 1:])
        left[:, r] = cur[:, 0]
        right[:, n - 1 - r] = cur[:, -1]
    return left, right


@dataclass
class Samples:
    """Output of :func:`sample_curve` (internal)."""

    x: FloatArray  # (K,) fractions
    kappa: FloatArray  # (m, K)
    dkds: FloatArray  # (m, K)
    arc_length: float
    dkds_energy: float
    n_singular: int
    max_kappa: float
    max_dkds: float
    knots: FloatArray  # (m, 3): jumps of r''', r^(degree), dkappa/ds at each breakpoint
    diagonal: float  # bounding-box diagonal of the breakpoint positions
    ell: FloatArray  # (m,) length scale of each segment (derivative size times width)
    pos: FloatArray  # (m,) norm of each segment's start point
    energies: FloatArray  # (m, 2): exact int |r''|^2 and int |r'''|^2 per segment
    extra: tuple[tuple[np.ndarray, FloatArray, FloatArray], ...]  # per quantity: seg, u, value


@njit(cache=True)
def _variations_1d(b, n):  # type: ignore[no-untyped-def]
    """Sign changes (zeros skipped) of ``b[:n]``."""
    v = 0
    zero = False
    for i in range(n - 1):
        v += b[i] * b[i + 1] < 0.0
        zero |= b[i] == 0.0
    if not zero:
        return v
    v = 0
    last = 0.0
    for i in range(n):
        if b[i] != 0.0:
            if last * b[i] < 0.0:
                v += 1
            last = b[i]
    return v


@njit(cache=True, fastmath={"contract", "arcp", "reassoc"})
def _pass_kernel(cw, h, tab, w, fall, fits, nfit, subs, speed_rtol, cross_rtol, closed,
                 kap, dks, knots, energies, box, ell, pos, gaps):  # type: ignore[no-untyped-def]
    """One fused pass over the segments (see :func:`sample_curve`).

    ``tab[nu-1, q, j] = j!/(j-nu)! x_q^(j-nu)`` (derivative ``nu`` of ``u^j`` at node ``q``),
    ``fall[j, nu] = j!/(j-nu)!``; ``fits[k]`` (K, dmax+1) maps sampled numerator values to
    Bernstein coefficients (``nfit[k]`` of them; 0: not wanted), ``subs[k]`` (K-1, K, dmax+1)
    the same per gap. Writes ``kap``/``dks`` (m, K); ``knots[i]`` = jumps at breakpoint ``i``
    of the third derivative, of the ``degree``-th derivative and of ``dkappa/ds`` (row 0:
    the seam of a closed curve, else 0); ``energies[i, 0/1]`` (exact ``int |r''|^2`` and
    ``int |r'''|^2``); ``box`` (2, dim) the bounding box of the breakpoint positions; ``ell``
    (m,) each segment's length scale (size of its derivative polynomial times its width),
    ``pos`` (m,) the norm of its start point; and
    ``gaps`` (rows ``(which, segment, gap)`` whose gap Bernstein coefficients still vary at
    least twice). Returns ``(arc, dke, n_singular, max|kappa|, max|dkds|, n_gaps)``.
    """
    m, p1, dim = cw.shape
    K = tab.shape[1]
    p = p1 - 1
    e = np.empty((p1, dim))
    r1 = np.empty(dim)
    r2 = np.empty(dim)
    r3 = np.empty(dim)
    vals = np.empty((2, K))
    bb = np.empty(fits.shape[2])
    endv = np.zeros((2, dim))  # left limits at the previous segment's end
    first = np.zeros((2, dim))  # right limits at the first segment's start
    for d in range(dim):
        box[0, d] = cw[0, 0, d]
        box[1, d] = cw[0, 0, d]
    arc = 0.0
    dke = 0.0
    nsing = 0
    maxk = 0.0
    maxks = 0.0
    ngap = 0
    for i in range(m):
        hi = h[i]
        ih = 1.0 / hi
        ih2 = ih * ih
        ih3 = ih2 * ih
        sc1 = 0.0
        sc2 = 0.0
        hp = 1.0
        for d in range(dim):
            v = cw[i, 0, d]
            if v < box[0, d]:
                box[0, d] = v
            if v > box[1, d]:
                box[1, d] = v
        for j in range(p1):
            nrm = 0.0
            for d in range(dim):
                v = cw[i, j, d]
                e[j, d] = v * hp
                nrm += v * v
            if j >= 1:
                nrm = np.sqrt(nrm) * hp
                sc1 += fall[j, 1] * nrm
                if j >= 2:
                    sc2 += fall[j, 2] * nrm
            hp *= hi
        ell[i] = sc1
        c0n = 0.0
        for d in range(dim):
            c0n += cw[i, 0, d] * cw[i, 0, d]
        pos[i] = np.sqrt(c0n)
        sc1 *= ih
        sc2 *= ih2
        # exact energies: int_0^1 |sum_j g_j u^j|^2 du * h with g_j = fall[j+o, o] e_{j+o} / h^o
        for o in range(2, 4):
            acc = 0.0
            if o <= p:
                for j in range(p1 - o):
                    for k in range(p1 - o):
                        dd = 0.0
                        for d in range(dim):
                            dd += e[j + o, d] * e[k + o, d]
                        acc += dd * fall[j + o, o] * fall[k + o, o] / (j + k + 1.0)
                acc *= ih2 * ih2 if o == 2 else ih3 * ih3
            energies[i, o - 2] = acc * hi
        # jumps at breakpoint i of the third and the degree-th derivative; then the left
        # limits at this segment's end for breakpoint i + 1
        for slot in range(2):
            nu = 3 if slot == 0 else p
            jj = 0.0
            for d in range(dim):
                right = fall[nu, nu] * cw[i, nu, d] if nu <= p else 0.0
                if i == 0:
                    first[slot, d] = right
                diff = right - endv[slot, d]
                jj += diff * diff
                acc = 0.0
                if nu <= p:
                    for j in range(nu, p1):
                        acc += fall[j, nu] * e[j, d]
                endv[slot, d] = acc * ih ** nu
            knots[i, slot] = np.sqrt(jj) if i > 0 else 0.0
        seg_arc = 0.0
        seg_dke = 0.0
        for qn in range(K):
            for d in range(dim):
                a1 = 0.0
                a2 = 0.0
                a3 = 0.0
                for j in range(1, p1):
                    a1 += tab[0, qn, j] * e[j, d]
                    a2 += tab[1, qn, j] * e[j, d]
                    a3 += tab[2, qn, j] * e[j, d]
                r1[d] = a1 * ih
                r2[d] = a2 * ih2
                r3[d] = a3 * ih3
            s2 = 0.0
            dot12 = 0.0
            for d in range(dim):
                s2 += r1[d] * r1[d]
                dot12 += r1[d] * r2[d]
            sp = np.sqrt(s2)
            k_ = 0.0
            ks = 0.0
            ok = sp > speed_rtol * sc1
            if dim == 2:
                num = r1[0] * r2[1] - r1[1] * r2[0]
                num1 = r1[0] * r3[1] - r1[1] * r3[0]
                enum = num1 * s2 - 3.0 * num * dot12
                vals[0, qn] = num
                vals[1, qn] = enum
                if ok:
                    inv = 1.0 / s2
                    k_ = num * inv / sp
                    ks = enum * (inv * inv) * inv
            else:
                c0 = r1[1] * r2[2] - r1[2] * r2[1]
                c1 = r1[2] * r2[0] - r1[0] * r2[2]
                c2_ = r1[0] * r2[1] - r1[1] * r2[0]
                d0 = r1[1] * r3[2] - r1[2] * r3[1]
                d1 = r1[2] * r3[0] - r1[0] * r3[2]
                d2 = r1[0] * r3[1] - r1[1] * r3[0]
                cc = c0 * c0 + c1 * c1 + c2_ * c2_
                cn = np.sqrt(cc)
                enum = (c0 * d0 + c1 * d1 + c2_ * d2) * s2 - 3.0 * cc * dot12
                vals[0, qn] = 0.0
                vals[1, qn] = enum
                if ok and cn > cross_rtol * sp * sc2:
                    inv = 1.0 / s2
                    k_ = cn * inv / sp
                    ks = enum / cn * (inv * inv) * inv
            if not ok or not (np.isfinite(k_) and np.isfinite(ks)):
                k_ = 0.0
                ks = 0.0
                nsing += 1
            kap[i, qn] = k_
            dks[i, qn] = ks
            ak = abs(k_)
            aks = abs(ks)
            if ak > maxk:
                maxk = ak
            if aks > maxks:
                maxks = aks
            seg_arc += w[qn] * sp
            seg_dke += w[qn] * (ks * ks * sp)
        arc += seg_arc * hi
        dke += seg_dke * hi
        knots[i, 2] = abs(dks[i, 0] - dks[i - 1, K - 1]) if i > 0 else 0.0
        # certificate: can a sign change of N (E) hide between two samples?
        for which in range(2):
            nb = nfit[which]
            if nb == 0:
                continue
            for c in range(nb):
                acc = 0.0
                for qn in range(K):
                    acc += vals[which, qn] * fits[which, qn, c]
                bb[c] = acc
            if _variations_1d(bb, nb) <= _variations_1d(vals[which], K):
                continue
            for gq in range(K - 1):
                for c in range(nb):
                    acc = 0.0
                    for qn in range(K):
                        acc += vals[which, qn] * subs[which, gq, qn, c]
                    bb[c] = acc
                if _variations_1d(bb, nb) >= 2:
                    if ngap < gaps.shape[0]:
                        gaps[ngap, 0] = which
                        gaps[ngap, 1] = i
                        gaps[ngap, 2] = gq
                    ngap += 1
    if closed:
        for slot in range(2):
            jj = 0.0
            for d in range(dim):
                diff = first[slot, d] - endv[slot, d]
                jj += diff * diff
            knots[0, slot] = np.sqrt(jj)
        knots[0, 2] = abs(dks[0, 0] - dks[m - 1, K - 1])
    # the end point of the last segment
    for d in range(dim):
        acc = 0.0
        for j in range(p1 - 1, -1, -1):
            acc = acc * h[m - 1] + cw[m - 1, j, d]
        if acc < box[0, d]:
            box[0, d] = acc
        if acc > box[1, d]:
            box[1, d] = acc
    return arc, dke, nsing, maxk, maxks, ngap


def _speed_scales(cc: FloatArray, hh: FloatArray) -> tuple[FloatArray, FloatArray]:
    p1 = cc.shape[1]
    nrm = np.sqrt(np.sum(cc * cc, axis=2))  # (k, p1)
    s1 = np.zeros(cc.shape[0])
    s2 = np.zeros(cc.shape[0])
    for j in range(1, p1):
        s1 += j * nrm[:, j] * hh ** (j - 1)
        if j >= 2:
            s2 += j * (j - 1) * nrm[:, j] * hh ** (j - 2)
    return s1, s2


def _frenet_at(cw: FloatArray, h: FloatArray, segs: np.ndarray, us: FloatArray,
               numerators: bool = False) -> dict[str, FloatArray]:
    """Numpy evaluation of :func:`frenet` at segments ``segs``, fractions ``us``."""
    shape = np.broadcast_shapes(np.shape(segs), np.shape(us))
    sf = np.broadcast_to(segs, shape).reshape(-1)
    uf = np.broadcast_to(us, shape).reshape(-1)
    cg = cw[sf]
    hg = h[sf]
    rr = derivs_at(cg, uf * hg, 3)
    s1, s2 = _speed_scales(cg, hg)
    dim = cw.shape[2]
    fr = frenet(*[[r_[:, d] for d in range(dim)] for r_ in rr], s1, s2,
                numerators=numerators)
    return {k: v.reshape(shape) for k, v in fr.items()}


def _refine_gaps(cw: FloatArray, h: FloatArray, plan: _Plan, gaps: np.ndarray
                 ) -> list[tuple[np.ndarray, FloatArray]]:
    """Halve the flagged gaps (de Casteljau) until every piece's Bernstein coefficients vary
    at most once; the split points are the extra samples, per quantity ``(segment, u)``."""
    out: list[tuple[np.ndarray, FloatArray]] = []
    for which, key in ((0, "N"), (1, "E")):
        g = gaps[gaps[:, 0] == which]
        if g.shape[0] == 0:
            out.append((np.zeros(0, dtype=np.int64), np.zeros(0)))
            continue
        useg, inv = np.unique(g[:, 1], return_inverse=True)
        vals = _frenet_at(cw, h, useg[:, None], plan.x[None, :], numerators=True)[key]
        sub = plan.sub[which]
        assert sub is not None
        q = g[:, 2]
        b = np.einsum("gK,gKd->gd", vals[inv], sub[q])
        seg = g[:, 1].copy()
        lo = plan.x[q]
        hi = plan.x[q + 1]
        segs_out: list[np.ndarray] = []
        u_out: list[FloatArray] = []
        for _ in range(_MAX_SPLITS):
            mid = 0.5 * (lo + hi)
            segs_out.append(seg)
            u_out.append(mid)
            left, right = _split(b)
            b = np.concatenate([left, right])
            seg = np.concatenate([seg, seg])
            lo, hi = np.concatenate([lo, mid]), np.concatenate([mid, hi])
            keep = _variations(b) >= 2
            if not keep.any():
                break
            b, seg, lo, hi = b[keep], seg[keep], lo[keep], hi[keep]
        out.append((np.concatenate(segs_out), np.concatenate(u_out)))
    return out


def sample_curve(cw: FloatArray, h: FloatArray, planar: bool, closed: bool,
                 nodes: int = 0) -> Samples:
    """Sample ``kappa`` and ``dkappa/ds`` on every segment; integrate; certify signs.

    ``cw`` are power coefficients ``(m, p+1, dim)`` (``dim`` 2 for planar curves, 3 for
    twisted ones), ``h`` the segment widths. One compiled pass over the segments (fused:
    no temporaries of the sample grid's size besides the two results).
    """
    m, p1, dim = cw.shape
    p = p1 - 1
    plan = _plan(p, planar, nodes)
    K = plan.K
    dmax = max(plan.degs) + 1
    fits = np.zeros((2, K, dmax))
    subs = np.zeros((2, K - 1, K, dmax))
    nfit = np.zeros(2, dtype=np.int64)
    for which in (0, 1):
        f, sb = plan.fit[which], plan.sub[which]
        if f is not None and sb is not None:
            nfit[which] = f.shape[1]
            fits[which, :, : f.shape[1]] = f
            subs[which, :, :, : f.shape[1]] = sb
    fall = np.zeros((p1, max(p1, 4)))
    for j in range(p1):
        for nu in range(j + 1):
            fall[j, nu] = falling(j, nu)[0]
    kap = np.empty((m, K))
    dks = np.empty((m, K))
    knots = np.empty((m, 3))
    energies = np.empty((m, 2))
    box = np.empty((2, dim))
    ell = np.empty(m)
    pos = np.empty(m)
    cwc = np.ascontiguousarray(cw, dtype=np.float64)
    hc = np.ascontiguousarray(h, dtype=np.float64)
    gaps = np.empty((max(1 << 12, m // 4), 3), dtype=np.int64)
    while True:
        arc, dke, nsing, maxk, maxks, ngap = _pass_kernel(
            cwc, hc, plan.tab, plan.w, fall, fits, nfit, subs, SPEED_RTOL, CROSS_RTOL,
            bool(closed), kap, dks, knots, energies, box, ell, pos, gaps)
        if ngap <= gaps.shape[0]:
            break
        gaps = np.empty((ngap, 3), dtype=np.int64)  # rare: the buffer was too small; redo
    refined = _refine_gaps(cw, h, plan, gaps[:ngap])
    extra = []
    for which, (segs, us) in enumerate(refined):
        if segs.size == 0:
            extra.append((segs, us, np.zeros(0)))
            continue
        order = np.lexsort((us, segs))
        segs, us = segs[order], us[order]
        fr = _frenet_at(cw, h, segs, us)
        extra.append((segs, us, fr["kappa"] if which == 0 else fr["dkds"]))
    return Samples(x=plan.x, kappa=kap, dkds=dks, arc_length=float(arc),
                   dkds_energy=float(dke), n_singular=int(nsing), max_kappa=float(maxk),
                   max_dkds=float(maxks), knots=knots, energies=energies,
                   diagonal=float(np.sqrt(np.sum((box[1] - box[0]) ** 2))), ell=ell,
                   pos=pos,
                   extra=(extra[0], extra[1]))


@njit(cache=True)
def _scan_kernel(vals, x, breaks, ex_seg, ex_u, ex_val, tol, ell, pos, floor, power,
                 out):  # type: ignore[no-untyped-def]
    m, K = vals.shape
    ne = ex_seg.shape[0]
    n = 0
    e = 0
    last_s = 0
    last_t = 0.0
    last_v = 0.0
    first_s = 0
    first_t = 0.0
    first_v = 0.0
    for i in range(m):
        t0 = breaks[i]
        hw = breaks[i + 1] - t0
        q = 0
        tl = tol
        if ell[i] > 0.0:
            fl = floor * (ell[i] + pos[i]) / ell[i] ** (power + 1.0)
            if fl > tl:
                tl = fl
        while e < ne and ex_seg[e] < i:
            e += 1
        while q < K or (e < ne and ex_seg[e] == i):
            if e < ne and ex_seg[e] == i and (q >= K or ex_u[e] < x[q]):
                u = ex_u[e]
                v = ex_val[e]
                e += 1
            else:
                u = x[q]
                v = vals[i, q]
                q += 1
            if v > tl:
                s = 1
            elif v < -tl:
                s = -1
            else:
                continue
            t = t0 + hw * u
            if last_s == 0:
                first_s = s
                first_t = t
                first_v = v
            elif s != last_s:
                out[n] = last_t + (t - last_t) * (last_v / (last_v - v))
                n += 1
            last_s = s
            last_t = t
            last_v = v
    return n, first_s, first_t, first_v, last_s, last_t, last_v


def scan_sign_changes(vals: FloatArray, x: FloatArray, breaks: FloatArray,
                      extra: tuple[np.ndarray, FloatArray, FloatArray], tol: float,
                      closed: bool, ell: FloatArray, pos: FloatArray, power: int
                      ) -> tuple[int, FloatArray]:
    """Sign changes of the sampled sequence, cyclic when closed.

    On segment ``i`` a value counts as zero where ``|v| <= max(tol, ROUNDING_FLOOR (ell_i +
    pos_i) / ell_i**(power + 1))``.

    Returns the count and the linearly interpolated parameters of the changes (sorted).
    """
    ex_seg, ex_u, ex_val = extra
    out = np.empty(vals.size + ex_seg.size + 1)
    n, fs, ft, fv, ls, lt, lv = _scan_kernel(
        np.ascontiguousarray(vals), x, np.ascontiguousarray(breaks, dtype=np.float64),
        np.ascontiguousarray(ex_seg, dtype=np.int64), np.ascontiguousarray(ex_u),
        np.ascontiguousarray(ex_val), float(tol), np.ascontiguousarray(ell),
        np.ascontiguousarray(pos),
        ROUNDING_FLOOR,
        float(power), out)
    loc = out[:n].copy()
    if closed and fs != 0 and ls != fs:
        period = float(breaks[-1] - breaks[0])
        tb = ft + period
        t = lt + (tb - lt) * (lv / (lv - fv))
        if t >= breaks[-1]:
            t -= period
            loc = np.concatenate([[t], loc])
        else:
            loc = np.concatenate([loc, [t]])
    return int(loc.shape[0]), loc
