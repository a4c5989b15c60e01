"""Compiled kernels of the sampling pass of :func:`curvefair.analyze`
(:mod:`curvefair.analysis._sampling`, whose docstring describes the grid, the quadratures and
the sign certificates).

:func:`pass_kernel` is the fused pass over the segments (curvature and ``dkappa/ds`` at every
node, exact energies, jumps at the breakpoints, 7-/4-point quadratures, the gaps whose
Bernstein coefficients may hide a sign change); :func:`allowances` the error allowance of each
segment's quadratures, :func:`refine_kernel` their adaptive re-integration;
:func:`scan_kernel` the sign changes of the sampled sequence
(:func:`curvefair.analysis._sampling.scan_sign_changes`). The curvature kernels use the
fast-math flags ``_FM`` (contraction, reciprocals, reassociation) but not ``nnan``/``ninf``:
they test their values for NaN and infinity.
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import njit

_FM = {"contract", "arcp", "reassoc"}
_F32_MAX = 1e38


@njit(cache=True, error_model="numpy")
def _variations_1d(b, n):
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


@njit(cache=True, fastmath=_FM, inline="always", error_model="numpy")
def _setup(cw, i, hi, fall, e):
    """Scaled coefficients ``e_j = c_j h^j`` of segment ``i`` and the sizes of its first and
    second derivative polynomials (for the zero-speed and zero-curvature tests)."""
    p1, dim = e.shape
    sc1 = 0.0
    sc2 = 0.0
    hp = 1.0
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
    ih = 1.0 / hi
    return sc1 * ih, sc2 * ih * ih


@njit(cache=True, fastmath=_FM, inline="always", error_model="numpy")
def _frenet_node(r1, r2, r3, sc1, sc2, speed_rtol, cross_rtol):
    """``(kappa, dkds, speed, N, E, singular)`` at one node (see ``_core.frenet``)."""
    dim = r1.shape[0]
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
        if ok:
            inv = 1.0 / s2
            k_ = num * inv / sp
            ks = enum * (inv * inv) * inv
    else:
        num = 0.0
        c0 = r1[1] * r2[2] - r1[2] * r2[1]
        c1 = r1[2] * r2[0] - r1[0] * r2[2]
        c2 = r1[0] * r2[1] - r1[1] * r2[0]
        d0 = r1[1] * r3[2] - r1[2] * r3[1]
        d1 = r1[2] * r3[0] - r1[0] * r3[2]
        d2 = r1[0] * r3[1] - r1[1] * r3[0]
        cc = c0 * c0 + c1 * c1 + c2 * c2
        cn = np.sqrt(cc)
        enum = (c0 * d0 + c1 * d1 + c2 * d2) * s2 - 3.0 * cc * dot12
        if ok and cn > cross_rtol * sp * sc2:
            inv = 1.0 / s2
            k_ = cn * inv / sp
            ks = enum / cn * (inv * inv) * inv
    singular = not ok or not (np.isfinite(k_) and np.isfinite(ks))
    if singular:
        k_ = 0.0
        ks = 0.0
    return k_, ks, sp, num, enum, singular


@njit(cache=True, nogil=True, fastmath=_FM, error_model="numpy", readonly=('cw', 'h'))
def pass_kernel(cw, h, x, tab, w7, w4, P, fall, fits, nfit, subs, speed_rtol, cross_rtol,
                kap, dks, knots, energies, quad, box, ell, pos, gaps, unit,
                i_lo, i_hi, at, first, endv, ksfl, off, full):
    """One fused pass over the segments (see
    :func:`curvefair.analysis._sampling.sample_curve`).

    ``x`` the node fractions, ``tab[nu-1, q, j] = j!/(j-nu)! x_q^(j-nu)`` (derivative ``nu``
    of ``u^j`` at node ``q``),
    ``w7``/``w4`` the Kronrod/Lobatto weights of one piece on [0, 1], ``fall[j, nu] =
    j!/(j-nu)!``; ``fits[k]`` (K, dmax+1) maps sampled numerator values to Bernstein
    coefficients (``nfit[k]`` of them; 0: not wanted), ``subs[k]`` (K-1, K, dmax+1) the same
    per gap. Writes ``kap``/``dks`` (m, K), scaled by ``unit`` and ``unit**2`` (see
    :func:`curvefair.analysis._sampling.sample_curve`); ``knots[i]`` = jumps at breakpoint
    ``i`` of the third derivative, of the ``degree``-th derivative and of ``dkappa/ds`` (row 0:
    the seam of a closed curve, else 0); ``energies[i]`` (exact ``int |r''|^2``, ``int |r'''|^2``);
    ``quad[i]`` (7-point arc length, its error estimate, the same for ``int kappa_s^2 ds``);
    ``box`` (2, dim) the bounding box of the breakpoint positions; ``ell`` each segment's length
    scale; ``pos`` the norm of its start point; and ``gaps`` (rows ``(which, segment, gap)``
    whose gap Bernstein coefficients still vary at least twice). Returns ``(n_singular,
    max|kappa|, max|dkds|, n_gaps)``.

    **Ranges.** Only segments ``i_lo .. i_hi - 1`` are done (their rows of the per-segment
    outputs, their gaps, their bounding box and counts), so that ranges can run on several
    threads. A range starting after segment 0 first runs the whole pass over segment
    ``i_lo - 1`` (the limits at its end are what the jumps at breakpoint ``i_lo`` need),
    writing that segment's rows to the spare rows named in ``at``: every value is computed by
    the same code from the same inputs however the segments are split, so the results are
    bitwise the same on one thread or several. ``first`` gets the right limits of the third
    and ``degree``-th derivative at the start of segment 0 (range with ``i_lo == 0``),
    ``endv`` the left limits at the end of segment ``i_hi - 1``, ``ksfl`` ``dkappa/ds`` at
    those two places: :func:`seam_jumps` makes the closed curve's seam row from them.

    ``cw`` holds the rows of segments ``off .. off + len(cw) - 1`` (those the range reads, the
    lead-in segment included): the whole form (``off = 0``) or a range's own rows made for
    it (:class:`curvefair.analysis._sampling.SpanForms`); ``h`` covers every segment.

    **Rows.** ``at`` (3, 2) int64 places the per-segment outputs, as three groups: ``quad``
    (``at[0]``), ``knots`` and ``energies`` (``at[1]``), ``kap``, ``dks``, ``ell`` and ``pos``
    (``at[2]``). Segment ``i``'s row of a group is ``i - at[g, 0]``, the lead-in segment's
    row ``at[g, 1]``: ``(0, scratch)`` writes the whole arrays (a spare row ``scratch`` past
    ``m`` per range), ``(s0, nb)`` a block's own ``nb + 1`` rows for a block starting at
    segment ``s0``.

    ``full`` False: the samples alone (``kap``, ``dks``, ``ell``, ``pos``, the box and the
    maxima; for :func:`curvefair.analysis._sampling.rescan_sign_counts`): no energies, jumps,
    quadratures or gaps. The samples are computed by the same code either way (the parts
    skipped only read them).
    """
    m = h.shape[0]
    p1 = cw.shape[1]
    dim = cw.shape[2]
    K = tab.shape[1]
    p = p1 - 1
    unit2 = unit * unit
    e = np.empty((p1, dim))
    r1 = np.empty(dim)
    r2 = np.empty(dim)
    r3 = np.empty(dim)
    c1 = np.empty(dim)
    c2 = np.empty(dim)
    c3 = np.empty(dim)
    b0 = np.empty(dim)
    b1 = np.empty(dim)
    vals = np.empty((2, K))
    fa = np.empty(K)
    fd = np.empty(K)
    ksa = np.empty(K)
    bb = np.empty(fits.shape[2])
    endv[:, :] = 0.0  # left limits at the previous segment's end
    i0 = i_lo - 1 if i_lo > 0 else 0  # the first segment run (see Ranges)
    for d in range(dim):
        box[0, d] = cw[i0 - off, 0, d]
        box[1, d] = cw[i0 - off, 0, d]
    ks_start = 0.0
    ks_end = 0.0
    ks_prev_end = 0.0
    hilb = np.empty(2 * p1)
    for j in range(2 * p1):
        hilb[j] = 1.0 / (j + 1.0)
    nsing = 0
    maxk = 0.0
    maxks = 0.0
    ngap = 0
    for i in range(i0, i_hi):
        own = i >= i_lo
        row = i - at[0, 0] if own else at[0, 1]  # quad
        krow = i - at[1, 0] if own else at[1, 1]  # knots, energies
        srow = i - at[2, 0] if own else at[2, 1]  # kap, dks, ell, pos
        hi = h[i]
        ih = 1.0 / hi
        ih2 = ih * ih
        ih3 = ih2 * ih
        sc1, sc2 = _setup(cw, i - off, hi, fall, e)
        ell[srow] = sc1 * hi
        c0n = 0.0
        for d in range(dim):
            v = cw[i - off, 0, d]
            c0n += v * v
            if v < box[0, d]:
                box[0, d] = v
            if v > box[1, d]:
                box[1, d] = v
        pos[srow] = np.sqrt(c0n)
        if full:  # (not read by the samples)
            # exact energies: h int_0^1 |sum_j g_j u^j|^2 du with g_j = fall[j+o, o] e_{j+o} / h^o
            for o in range(2, 4):
                acc = 0.0
                if o <= p:
                    for j in range(p1 - o):
                        for k in range(p1 - o):
                            dd = 0.0
                            for d in range(dim):
                                dd += e[j + o, d] * e[k + o, d]
                            acc += dd * fall[j + o, o] * fall[k + o, o] * hilb[j + k]
                    acc *= ih2 * ih2 if o == 2 else ih3 * ih3
                energies[krow, o - 2] = acc * hi
            # jumps at breakpoint i of the third and the degree-th derivative; then the left
            # limits at this segment's end for breakpoint i + 1
            for slot in range(2):
                nu = 3 if slot == 0 else p
                ihn = 1.0
                for _ in range(nu):
                    ihn *= ih
                jj = 0.0
                for d in range(dim):
                    right = fall[nu, nu] * cw[i - off, nu, d] if nu <= p else 0.0
                    if i == 0:
                        first[slot, d] = right
                    diff = right - endv[slot, d]
                    jj += diff * diff
                    acc = 0.0
                    if nu <= p:
                        for j in range(nu, p1):
                            acc += fall[j, nu] * e[j, d]
                    endv[slot, d] = acc * ihn
                knots[krow, slot] = np.sqrt(jj) if i > 0 else 0.0
        if p1 == 4:  # cubic: derivative polynomials in u written out (the common case)
            for d in range(dim):
                c1[d] = e[1, d] * ih
                c2[d] = 2.0 * e[2, d] * ih
                c3[d] = 3.0 * e[3, d] * ih
                b0[d] = 2.0 * e[2, d] * ih2
                b1[d] = 6.0 * e[3, d] * ih2
                r3[d] = 6.0 * e[3, d] * ih3
        if p1 == 4 and dim == 2:
            # planar cubic, written branch-free so that the node loops vectorise; the same
            # formulas as _frenet_node
            thr = speed_rtol * sc1
            for qn in range(K):
                u = x[qn]
                X1 = c1[0] + u * (c2[0] + u * c3[0])
                Y1 = c1[1] + u * (c2[1] + u * c3[1])
                X2 = b0[0] + u * b1[0]
                Y2 = b0[1] + u * b1[1]
                s2 = X1 * X1 + Y1 * Y1
                num = X1 * Y2 - Y1 * X2
                num1 = X1 * r3[1] - Y1 * r3[0]
                vals[0, qn] = num
                vals[1, qn] = num1 * s2 - 3.0 * num * (X1 * X2 + Y1 * Y2)
                fa[qn] = np.sqrt(s2)
                fd[qn] = s2
            for qn in range(K):
                s2 = fd[qn]
                sp = fa[qn]
                inv = 1.0 / s2
                k_ = vals[0, qn] * inv / sp
                ks = vals[1, qn] * (inv * inv) * inv
                good = (sp > thr) and (abs(k_) < np.inf) and (abs(ks) < np.inf)
                k_ = k_ if good else 0.0
                ks = ks if good else 0.0
                nsing += (not good) & own
                kap[srow, qn] = min(max(k_ * unit, -_F32_MAX), _F32_MAX)
                dks[srow, qn] = min(max(ks * unit2, -_F32_MAX), _F32_MAX)
                maxk = max(maxk, abs(k_))
                maxks = max(maxks, abs(ks))
                ksa[qn] = ks
                fd[qn] = ks * ks * sp
            ks_start = ksa[0]
            ks_end = ksa[K - 1]
        else:
            for qn in range(K):
                if p1 == 4:
                    u = x[qn]
                    for d in range(dim):
                        r1[d] = c1[d] + u * (c2[d] + u * c3[d])
                        r2[d] = b0[d] + u * b1[d]
                else:
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
                k_, ks, sp, num, enum, sing = _frenet_node(r1, r2, r3, sc1, sc2, speed_rtol,
                                                           cross_rtol)
                vals[0, qn] = num
                vals[1, qn] = enum
                nsing += sing & own
                # stored in float32 (sign and rough size are all the counts need), clamped
                kap[srow, qn] = min(max(k_ * unit, -_F32_MAX), _F32_MAX)
                dks[srow, qn] = min(max(ks * unit2, -_F32_MAX), _F32_MAX)
                if qn == 0:
                    ks_start = ks
                ks_end = ks
                ak = abs(k_)
                aks = abs(ks)
                if ak > maxk:
                    maxk = ak
                if aks > maxks:
                    maxks = aks
                fa[qn] = sp
                fd[qn] = ks * ks * sp
        if full:
            # 7-point Kronrod and 4-point Lobatto on each of the P pieces
            qa = 0.0
            ea = 0.0
            qd = 0.0
            ed = 0.0
            for k in range(P):
                a7 = 0.0
                a4 = 0.0
                d7 = 0.0
                d4 = 0.0
                for j in range(7):
                    a7 += w7[j] * fa[6 * k + j]
                    a4 += w4[j] * fa[6 * k + j]
                    d7 += w7[j] * fd[6 * k + j]
                    d4 += w4[j] * fd[6 * k + j]
                qa += a7
                ea += abs(a7 - a4)
                qd += d7
                ed += abs(d7 - d4)
            sw = hi / P
            quad[row, 0] = qa * sw
            quad[row, 1] = ea * sw
            quad[row, 2] = qd * sw
            quad[row, 3] = ed * sw
            knots[krow, 2] = abs(ks_start - ks_prev_end) if i > 0 else 0.0
            if i == 0:
                ksfl[0] = ks_start
        ks_prev_end = ks_end
        if not own or not full:
            continue  # a range's lead-in segment (its gaps belong to the range before), or
            # the samples alone
        # certificate: can a sign change of N (E) hide between two samples?
        for which in range(2):
            nb = nfit[which]
            if nb == 0:
                continue
            if which == 0 and p1 == 4 and dim == 2:
                # planar cubic: N is a quadratic n0 + n1 u + n2 u^2 (its cubic term cancels);
                # a hidden pair of roots straddles its vertex, inside one gap
                n1 = c1[0] * b1[1] + c2[0] * b0[1] - c1[1] * b1[0] - c2[1] * b0[0]
                n2 = c2[0] * b1[1] + c3[0] * b0[1] - c2[1] * b1[0] - c3[1] * b0[0]
                if n2 != 0.0:
                    us = -0.5 * n1 / n2
                    if 0.0 < us < 1.0:
                        gq = 0
                        while gq < K - 2 and x[gq + 1] <= us:
                            gq += 1
                        n0 = c1[0] * b0[1] - c1[1] * b0[0]
                        nv = n0 + us * (n1 + us * n2)
                        if nv * vals[0, gq] < 0.0 and nv * vals[0, gq + 1] < 0.0:
                            if ngap < gaps.shape[0]:
                                gaps[ngap, 0] = 0
                                gaps[ngap, 1] = i
                                gaps[ngap, 2] = gq
                            ngap += 1
                continue
            # Bernstein sign variations of the polynomial vs those of its samples
            vb = 0
            lastb = 0.0
            for c in range(nb):
                acc = 0.0
                for qn in range(K):
                    acc += vals[which, qn] * fits[which, qn, c]
                if acc != 0.0:
                    if lastb * acc < 0.0:
                        vb += 1
                    lastb = acc
            if vb == 0:
                continue
            vs = 0
            lasts = 0.0
            for qn in range(K):
                v = vals[which, qn]
                if v != 0.0:
                    if lasts * v < 0.0:
                        vs += 1
                    lasts = v
            if vb <= vs:
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
    ksfl[1] = ks_prev_end
    if i_hi < m:
        return nsing, maxk, maxks, ngap
    # the end point of the last segment
    for d in range(dim):
        acc = 0.0
        for j in range(p1 - 1, -1, -1):
            acc = acc * h[m - 1] + cw[m - 1 - off, j, d]
        if acc < box[0, d]:
            box[0, d] = acc
        if acc > box[1, d]:
            box[1, d] = acc
    return nsing, maxk, maxks, ngap


@njit(cache=True, nogil=True, fastmath=_FM, error_model="numpy")
def seam_jumps(first, endv, ksfl, knots):
    """Row 0 of ``knots`` for a closed curve: the jumps at the seam, from the right limits at
    the start of segment 0 (``first``, ``ksfl[0]``) and the left limits at the end of the last
    segment (``endv``, ``ksfl[1]``) that :func:`pass_kernel` reports."""
    dim = first.shape[1]
    for slot in range(2):
        jj = 0.0
        for d in range(dim):
            diff = first[slot, d] - endv[slot, d]
            jj += diff * diff
        knots[0, slot] = np.sqrt(jj)
    knots[0, 2] = abs(ksfl[0] - ksfl[1])


@njit(cache=True, error_model="numpy")
def allowance(quad, h, i, rtol, ta, td):
    """Error allowances ``(a_arc, a_dkds)`` of segment ``i`` and its worst estimate /
    allowance ratio: ``rtol (|Q_i| + |total| h_i / sum h)``, ``ta``/``td`` the totals over
    ``sum h``. Compiled without fast-math and called (not inlined) by both kernels below, so
    the pass that picks the segments and the refinement that stops on them see the same
    bits."""
    aa = rtol * (abs(quad[i, 0]) + ta * h[i])
    ad = rtol * (abs(quad[i, 2]) + td * h[i])
    wa = quad[i, 1] / aa if aa > 0.0 else (np.inf if quad[i, 1] > 0.0 else 0.0)
    wd = quad[i, 3] / ad if ad > 0.0 else (np.inf if quad[i, 3] > 0.0 else 0.0)
    return aa, ad, (wa if wa > wd else wd)


@njit(cache=True, error_model="numpy")
def allowances(quad, h, rtol, tot, hist):
    """Totals and counts of the segments' error allowances (:func:`allowance`): ``tot`` gets
    ``(|sum Q_arc| / sum h, |sum Q_dkds| / sum h)``; ``hist[k]`` counts the segments whose
    worst ratio ``w`` has ``2^k < w <= 2^(k+1)`` (k capped at 63). Returns the number of
    segments over their allowance. (No per-segment arrays: :func:`refine_kernel` recomputes
    each allowance, 24 bytes per segment less of fresh memory.)"""
    m = quad.shape[0]
    ta = 0.0
    td = 0.0
    th = 0.0
    for i in range(m):
        ta += quad[i, 0]
        td += quad[i, 2]
        th += h[i]
    ta = abs(ta) / th
    td = abs(td) / th
    tot[0] = ta
    tot[1] = td
    n = 0
    for i in range(m):
        w = allowance(quad, h, i, rtol, ta, td)[2]
        if w > 1.0:
            n += 1
            k = 63 if not w < 2.0**63 else math.frexp(w)[1] - 1
            hist[k] += 1
    return n


@njit(cache=True, fastmath=_FM, inline="always", error_model="numpy")
def _piece7(e, a, b, hi, ih, xk, w7, fall, sc1, sc2, speed_rtol, cross_rtol, r1, r2, r3):
    """The 7-point rule on the piece ``[a, b]`` (fractions of the segment, width ``hi``) of
    the arc length and the dkds energy: ``(hi (b - a) sum w7 |r'|, hi (b - a) sum w7
    (dkappa/ds)^2 |r'|)``."""
    p1, dim = e.shape
    w = b - a
    qa = 0.0
    qd = 0.0
    for j in range(7):
        u = a + w * xk[j]
        for d in range(dim):
            a1 = 0.0
            a2 = 0.0
            a3 = 0.0
            for jj in range(p1 - 1, 0, -1):
                a1 = a1 * u + fall[jj, 1] * e[jj, d]
                if jj >= 2:
                    a2 = a2 * u + fall[jj, 2] * e[jj, d]
                if jj >= 3:
                    a3 = a3 * u + fall[jj, 3] * e[jj, d]
            r1[d] = a1 * ih
            r2[d] = a2 * ih * ih
            r3[d] = a3 * ih * ih * ih
        k_, ks, sp, num, enum, sing = _frenet_node(r1, r2, r3, sc1, sc2, speed_rtol,
                                                   cross_rtol)
        qa += w7[j] * sp
        qd += w7[j] * ks * ks * sp
    return qa * hi * w, qd * hi * w


@njit(cache=True, error_model="numpy")
def refine_candidates(quad, h, rtol, tot, thresh, out):
    """The segments whose worst ratio (:func:`allowance`) exceeds ``thresh``, in order, into
    ``out``; returns how many (those :func:`refine_kernel` may refine)."""
    n = 0
    for i in range(h.shape[0]):
        w = allowance(quad, h, i, rtol, tot[0], tot[1])[2]
        if w > thresh:
            out[n] = i
            n += 1
    return n


@njit(cache=True, fastmath=_FM, error_model="numpy", readonly=('cw', 'h'))
def refine_kernel(cw, seg, h, quad, rtol, tot, thresh, P, xk, w7, fall, speed_rtol,
                  cross_rtol, max_levels, budget):
    """Adaptive re-integration, in place, of the segments whose worst ratio (:func:`allowance`
    with the totals ``tot`` of :func:`allowances`) exceeds ``thresh``.

    Locally adaptive bisection: segment ``i`` starts as ``P`` equal pieces (for ``P = 1``
    the whole segment with the value the pass computed, ``quad[i]``); a piece is
    accepted when the 7-point rule on its two halves differs from the rule on the whole
    piece by at most the piece's share of the segment's allowances (its width times them),
    else its halves are refined in turn, down to ``max_levels`` bisections or until the
    work budget (pieces) is spent; a piece left unrefined then keeps its own value and half
    its parent's differences as its error estimates (its whole value for a starting piece).
    Only the pieces around a narrow feature are refined (a space curve whose curvature dips
    nearly to zero, where dkappa/ds turns within a tiny parameter range), where refining
    every piece of the segment uniformly spends thousands of pieces.
    ``quad`` rows: (arc length, its error estimate, dkds energy, its error estimate).
    ``seg``: the segments that may be refined, in curve order (every segment whose ratio
    exceeds ``thresh``: :func:`refine_candidates`), ``cw[k]`` the power form of ``seg[k]``.
    Returns the pieces used.
    """
    p1 = cw.shape[1]
    dim = cw.shape[2]
    e = np.empty((p1, dim))
    r1 = np.empty(dim)
    r2 = np.empty(dim)
    r3 = np.empty(dim)
    cap = P + 2 * max_levels + 4
    st = np.empty((cap, 6))      # pieces to refine: a, b, Q_arc, Q_dkds, inherited errors
    used = 0
    ta = tot[0]
    td = tot[1]
    for k_seg in range(seg.shape[0]):
        i = seg[k_seg]
        aa, ad, w = allowance(quad, h, i, rtol, ta, td)
        if not w > thresh:
            continue
        if used + (2 if P == 1 else 3 * P) > budget:
            break
        hi = h[i]
        ih = 1.0 / hi
        sc1, sc2 = _setup(cw, k_seg, hi, fall, e)
        top = 0
        if P == 1:
            # one starting piece: the whole segment, whose 7-point value the pass computed
            st[0, 0] = 0.0
            st[0, 1] = 1.0
            st[0, 2] = quad[i, 0]
            st[0, 3] = quad[i, 2]
            st[0, 4] = np.inf
            st[0, 5] = np.inf
            top = 1
        for k in range(P - 1 if P > 1 else -1, -1, -1):  # pushed last first: popped in order
            a = k / P
            b = (k + 1) / P
            qa, qd = _piece7(e, a, b, hi, ih, xk, w7, fall, sc1, sc2, speed_rtol,
                             cross_rtol, r1, r2, r3)
            st[top, 0] = a
            st[top, 1] = b
            st[top, 2] = qa
            st[top, 3] = qd
            st[top, 4] = np.inf
            st[top, 5] = np.inf
            top += 1
        used += P if P > 1 else 0
        sum_a = 0.0
        sum_d = 0.0
        err_a = 0.0
        err_d = 0.0
        while top > 0:
            top -= 1
            a = st[top, 0]
            b = st[top, 1]
            qa = st[top, 2]
            qd = st[top, 3]
            ea = st[top, 4]
            ed = st[top, 5]
            mid = 0.5 * (a + b)
            if used + 2 > budget or not (a < mid < b) or b - a < 0.5 ** max_levels \
                    or top + 2 > cap:
                # cannot refine further: the piece's own value, its parent's difference
                sum_a += qa
                sum_d += qd
                err_a += abs(qa) if ea == np.inf else ea
                err_d += abs(qd) if ed == np.inf else ed
                continue
            la, ld = _piece7(e, a, mid, hi, ih, xk, w7, fall, sc1, sc2, speed_rtol,
                             cross_rtol, r1, r2, r3)
            ra, rd = _piece7(e, mid, b, hi, ih, xk, w7, fall, sc1, sc2, speed_rtol,
                             cross_rtol, r1, r2, r3)
            used += 2
            da = abs(la + ra - qa)
            dd = abs(ld + rd - qd)
            frac = b - a
            if da <= aa * frac and dd <= ad * frac:
                sum_a += la + ra
                sum_d += ld + rd
                err_a += da
                err_d += dd
                continue
            st[top, 0] = mid
            st[top, 1] = b
            st[top, 2] = ra
            st[top, 3] = rd
            st[top, 4] = 0.5 * da
            st[top, 5] = 0.5 * dd
            st[top + 1, 0] = a
            st[top + 1, 1] = mid
            st[top + 1, 2] = la
            st[top + 1, 3] = ld
            st[top + 1, 4] = 0.5 * da
            st[top + 1, 5] = 0.5 * dd
            top += 2
        quad[i, 0] = sum_a
        quad[i, 1] = err_a
        quad[i, 2] = sum_d
        quad[i, 3] = err_d
    return used


@njit(cache=True, inline="always")
def _zero_band(tol, li, pi, floor, power):
    """The half-width of the zero band of a segment (length ``li``, position ``pi``) in
    :func:`scan_kernel`: ``max(tol, floor (li + pi) / li**(power + 1))`` (``tol`` alone for a
    segment of length 0)."""
    tl = tol
    if li > 0.0:
        fl = floor * (li + pi) / (li * li)
        if power == 2:
            fl /= li
        if fl > tl:
            tl = fl
    return tl


@njit(cache=True, inline="always")
def _sign(v, tl):
    """The sign the scans give a sample ``v`` with the zero band ``tl``: 1 above it, -1
    below ``-tl``, 0 within."""
    if v > tl:
        return 1
    if v < -tl:
        return -1
    return 0


@njit(cache=True, nogil=True, error_model="numpy")
def count_block(vals, tol, ell, pos, floor, power):
    """:func:`scan_kernel`'s count of the samples ``vals`` (m, K) alone, with a zero band
    ``tol`` that may be lower than the final one (a long summary's first pass, which knows
    only its block's largest value, see :func:`curvefair.analysis._sampling.sample_curve`):
    returns ``(changes, first sign, last sign, least)``, ``least`` the smallest ``|v|`` of
    the samples counted as nonzero (``inf``: none). A count stands for the final band
    ``tol_f >= tol`` exactly when ``least > tol_f``: a sample classified differently has
    ``tol < |v| <= tol_f`` (it is above its segment's rounding band, common to both). No
    extra samples are merged: the caller counts the stretches between the gap segments,
    which get them (:func:`curvefair.analysis._sampling._first_counts`)."""
    m, K = vals.shape
    n = 0
    first_s = 0
    last_s = 0
    least = np.inf
    for i in range(m):
        tl = _zero_band(tol, ell[i], pos[i], floor, power)
        for q in range(K):
            v = float(vals[i, q])
            s = _sign(v, tl)
            if s == 0:
                continue
            a = abs(v)
            if a < least:
                least = a
            if s != last_s:
                if last_s == 0:
                    first_s = s
                else:
                    n += 1
                last_s = s
    return n, first_s, last_s, least


@njit(cache=True, nogil=True, error_model="numpy")
def scan_kernel(vals, x, breaks, ex_seg, ex_u, ex_val, tol, ell, pos, floor, power,
                out):
    """The sign changes of :func:`curvefair.analysis._sampling.scan_sign_changes` in one pass:
    the sampled values ``vals`` (m, K) at fractions ``x`` merged per segment with the extra
    samples (``ex_seg``, ``ex_u``, ``ex_val``, sorted), a value counting as zero within
    ``max(tol, floor (ell_i + pos_i) / ell_i**(power + 1))``; the linearly interpolated
    parameters of the changes go to ``out``. Returns their number and the first and last
    nonzero sample's sign, parameter and value (for the seam of a closed curve)."""
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
        tl = _zero_band(tol, ell[i], pos[i], floor, power)
        while e < ne and ex_seg[e] < i:
            e += 1
        has_extra = e < ne and ex_seg[e] == i
        if not has_extra:
            # fast path: no sign change within the segment's interior unless the samples show
            # one; positions are only needed where a change happens
            for q in range(K):
                v = float(vals[i, q])
                s = _sign(v, tl)
                if s == 0:
                    continue
                if s != last_s:
                    t = breaks[i] + (breaks[i + 1] - breaks[i]) * x[q]
                    if last_s == 0:
                        first_s = s
                        first_t = t
                        first_v = v
                    else:
                        out[n] = last_t + (t - last_t) * (last_v / (last_v - v))
                        n += 1
                    last_s = s
                last_t = breaks[i] + (breaks[i + 1] - breaks[i]) * x[q]
                last_v = v
            continue
        t0 = breaks[i]
        hw = breaks[i + 1] - t0
        q = 0
        while q < K or (e < ne and ex_seg[e] == i):
            if e < ne and ex_seg[e] == i and (q >= K or ex_u[e] < x[q]):
                u = ex_u[e]
                v = ex_val[e]
                e += 1
            else:
                u = x[q]
                v = float(vals[i, q])
                q += 1
            s = _sign(v, tl)
            if s == 0:
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
