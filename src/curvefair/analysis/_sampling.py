"""The sampling pass of :func:`curvefair.analyze`: curvature and ``dkappa/ds`` on a fixed grid
per segment, adaptive quadratures, and the exact sign structure of both.

Grid: every segment is cut into ``P`` equal pieces, each sampled at the 7 nodes of the
Gauss-Kronrod-Lobatto pair of Gander & Gautschi (the 4-point Gauss-Lobatto rule and its 7-point
Kronrod extension, exact for degree 5 and 9): ``K = 6 P + 1`` fractions ``x_0 = 0 < ... <
x_{K-1} = 1``, so both one-sided limits at each knot are samples. The integrals use the 7-point
rule, the difference to the 4-point rule estimates the error, and segments whose estimate is too
large are integrated again on 2, 4, 8, ... times as many pieces (within a work budget).

Signs: the sign of the curvature is the sign of the polynomial ``N = x'y'' - y'x''`` and the
sign of ``dkappa/ds`` that of a polynomial numerator ``E``; both are recovered exactly (up to
rounding) from their ``K`` sampled values, ``K`` exceeding their degree, and their Bernstein
coefficients certify that no sign change hides between two samples, or locate it (see
:func:`sample_curve`).

The compiled passes are in :mod:`curvefair._kernels.sampling`; this module prepares their
tables and buffers and reads their results.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from math import comb
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from .. import _threads
from .._kernels import pairwise as _kp
from .._kernels import sampling as _k
from .._typing import FloatArray
from ..curves.bspline import BSplineCurve
from ._core import CROSS_RTOL, SPEED_RTOL, derivs_at, falling, frenet

if TYPE_CHECKING:
    from ..curves.hermite import HermiteSpline

__all__ = ["Samples", "sample_curve", "scan_sign_changes", "count_sign_changes",
           "rescan_sign_counts", "QUAD_RTOL"]

#: Rounding level of curvature-type quantities computed from floating-point spline data: on a
#: segment of length scale ``ell`` starting at distance ``pos`` from the origin, the
#: curvature is zero within ``ROUNDING_FLOOR (ell + pos) / ell**2`` and ``dkappa/ds`` within
#: ``ROUNDING_FLOOR (ell + pos) / ell**3``: coordinates rounded to ``eps * pos`` and
#: derivatives to ``eps * ell`` bend a straight segment that much (about 1e3 machine
#: epsilons, a margin of about 100 over the rounding estimates).
ROUNDING_FLOOR = 1e3 * float(np.finfo(float).eps)
#: Default relative accuracy requested from the adaptive quadratures.
QUAD_RTOL = 1e-9
_MAX_SPLITS = 48
#: Bisections of a piece at most in the adaptive re-integration (``refine_kernel``).
_MAX_LEVELS = 40
#: Segments: from this many on, the sampling pass runs in ranges on two threads
#: (:mod:`curvefair._threads`; bitwise the same results as on one).
PAR_MIN = 50_000
#: segments per block of a ``sums_only`` pass (:func:`sample_curve`)
STREAM_BLOCK = 65_536
#: Segments: from this many on, a ``sums_only`` pass keeps no samples; the sign counts sample
#: the curve again (:func:`rescan_sign_counts`).
RESCAN_MIN = 1 << 21
#: Noise band of the sign counts: ``|kappa| <= ZERO_RTOL * max(max|kappa|, 1/L)`` and
#: ``|dkappa/ds| <= ZERO_RTOL * max(max|dkappa/ds|, 1/L^2)`` count as zero (defined here for
#: the first pass's provisional counts; :mod:`curvefair.analysis` exports it).
ZERO_RTOL = 1e-9

# Gander & Gautschi (2000): 4-point Gauss-Lobatto and 7-point Kronrod extension on [-1, 1]
_R23 = float(np.sqrt(2.0 / 3.0))
_R15 = float(1.0 / np.sqrt(5.0))
_GK_X = np.array([-1.0, -_R23, -_R15, 0.0, _R15, _R23, 1.0])
_GK_W7 = np.array([11 / 210, 72 / 245, 125 / 294, 16 / 35, 125 / 294, 72 / 245, 11 / 210])
_GK_W4 = np.array([1 / 6, 0.0, 5 / 6, 0.0, 5 / 6, 0.0, 1 / 6])


def _bernstein_basis(d: int, u: FloatArray) -> FloatArray:
    """``(len(u), d+1)`` matrix of the Bernstein polynomials of degree ``d`` at ``u``."""
    i = np.arange(d + 1)
    binom = np.array([comb(d, k) for k in i], dtype=float)
    return binom[None, :] * u[:, None] ** i[None, :] * (1.0 - u[:, None]) ** (d - i)[None, :]


@dataclass(frozen=True)
class _Plan:
    P: int  # pieces per segment
    K: int  # nodes per segment, 6 P + 1
    x: FloatArray  # (K,) fractions
    xk: FloatArray  # (7,) Kronrod nodes on [0, 1]
    w7: FloatArray  # (7,) Kronrod weights on [0, 1]
    w4: FloatArray  # (7,) Lobatto weights on [0, 1] (zeros at the Kronrod-only nodes)
    tab: FloatArray  # (3, K, p1): derivative nu (1, 2, 3) of u^j at x_q
    fit: tuple[FloatArray | None, FloatArray]  # values (K) -> Bernstein coeffs on [0, 1]
    sub: tuple[FloatArray | None, FloatArray]  # values (K) -> Bernstein coeffs per gap
    degs: tuple[int, int]


def numerator_degrees(degree: int, planar: bool) -> tuple[int, int]:
    """Degrees of the curvature numerator ``N`` (planar) and the ``dkappa/ds`` numerator ``E``.

    The leading coefficients of ``r'`` and ``r''`` are parallel, so ``N = x'y'' - y'x''`` has
    degree ``2p - 4`` (not ``2p - 3``), ``N' = x'y''' - y'x'''`` degree ``2p - 5`` and
    ``E = N' |r'|^2 - 3 N (r'.r'')`` degree ``4p - 7``; in 3-D, with ``C = r' x r''``,
    ``E = (C.C') |r'|^2 - 3 |C|^2 (r'.r'')`` has degree ``6p - 11``.
    """
    p = degree
    return max(2 * p - 4, 0), max(4 * p - 7 if planar else 6 * p - 11, 0)


@lru_cache(maxsize=32)
def _plan(degree: int, planar: bool) -> _Plan:
    p = degree
    d_n, d_e = numerator_degrees(p, planar)
    P = max(1, -(-max(d_e, d_n + 1, p + 2) // 6))  # K = 6P + 1 > every degree
    K = 6 * P + 1
    xk = 0.5 * (_GK_X + 1.0)
    x = np.concatenate([[0.0]] + [(k + xk[1:]) / P for k in range(P)])
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
        fit_v = np.linalg.pinv(_bernstein_basis(d, v))  # the same for every gap
        for q in range(K - 1):
            vv = x[q] + (x[q + 1] - x[q]) * v
            to_vals = _bernstein_basis(d, vv) @ pinv  # sample values -> values at vv
            S[q] = (fit_v @ to_vals).T
        subs.append(S)
    return _Plan(P=P, K=K, x=x, xk=xk, w7=0.5 * _GK_W7, w4=0.5 * _GK_W4, tab=tab,
                 fit=(fits[0], cast(FloatArray, fits[1])), sub=(subs[0], cast(FloatArray, subs[1])),
                 degs=(d_n, d_e))


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
    kappa: np.ndarray  # (m, K) float32: kappa * unit (clamped to +-1e38)
    dkds: np.ndarray  # (m, K) float32: dkappa/ds * unit**2
    arc_length: float
    dkds_energy: float
    arc_length_error: float
    dkds_energy_error: float
    n_singular: int
    max_kappa: float
    max_dkds: float
    knots: FloatArray  # (m, 3): jumps of r''', r^(degree), dkappa/ds at each breakpoint
    diagonal: float  # bounding-box diagonal of the breakpoint positions
    ell: FloatArray  # (m,) length scale of each segment (derivative size times width)
    pos: FloatArray  # (m,) norm of each segment's start point
    energies: FloatArray  # (m, 2): exact int |r''|^2 and int |r'''|^2 per segment
    extra: tuple[tuple[np.ndarray, FloatArray, FloatArray], ...]  # per quantity: seg, u, value
    unit: float = 1.0  # the power of two near the curve's size that scales kappa and dkds
    # sums_only: (sum energies[:, 0], sum energies[:, 1], sum of the Sapidis measure, max jump,
    # max top jump) over the interior breakpoints of an open curve, as np.sum / np.max give
    sums: tuple[float, float, float, float, float] | None = None
    # no samples kept (kappa, dkds, ell, pos empty): count the signs by rescan_sign_counts
    rescan: bool = False
    # with rescan: the first pass's counts per block, in curve order (see sample_curve):
    # ``(s0, s1, pieces)``, per quantity (kappa, dkds) the block's stretches between its gap
    # segments, ``(changes, first sign, last sign, least |value| counted nonzero)``, and its
    # gap segments' samples, ``(segment, samples, ell, pos)``
    block_counts: list[tuple[int, int, list[list[tuple[Any, ...]]]]] | None = None


class SpanForms:
    """The power form of a planar curve's segments, made where it is read instead of kept
    whole: a :class:`~curvefair.BSplineCurve`'s spans or a Hermite spline's segments.

    ``rows(a, b)`` gives the coefficients of segments ``a .. b-1``, ``forms[idx]`` those of
    the segments ``idx`` (any integer array), with ``shape = (m, degree + 1, dim)`` and
    ``breaks`` as the whole form's: both are the curve's ``span_coefficients``, whose rows
    are bitwise those of the whole form (each segment's coefficients depend on its own knots
    and control points, or its own two points, only). :func:`sample_curve` reads a range's
    rows while it samples that range: at ten million cubic segments the whole form is 640 MB
    (and was copied once more into frozen memory), a range's rows a sixteenth of it.
    """

    def __init__(self, curve: BSplineCurve | HermiteSpline) -> None:
        self.curve = curve
        if isinstance(curve, BSplineCurve):
            self.breaks = np.asarray(curve.span_breaks)
            # (the stored samples' unit: a power of two near the control points' size)
            self.unit_points = np.asarray(curve.control_points)
        else:
            # the curve's own frozen parameters (the values of its power form's breaks), read
            # only: no copy (8 bytes a segment at the analysis' peak)
            self.breaks = np.asarray(curve.params)
            # the segments' start points: the whole form's unit
            self.unit_points = np.asarray(curve.points)[:-1]
        self.shape = (self.breaks.shape[0] - 1, int(curve.degree) + 1, int(curve.dim))
        self.finite = True  # cleared by a row that is not (the caller then reads the whole form)

    def rows(self, a: int, b: int) -> FloatArray:
        return self[np.arange(a, b)]

    def __getitem__(self, idx: np.ndarray) -> FloatArray:
        out = self.curve.span_coefficients(np.asarray(idx, dtype=np.int64))
        if not np.isfinite(out).all():
            self.finite = False
            out[~np.isfinite(out)] = 0.0
        return out


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


def _frenet_at(cw: FloatArray | SpanForms, h: FloatArray, segs: np.ndarray, us: FloatArray,
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
    r1, r2, r3 = ([r_[:, d] for d in range(dim)] for r_ in rr)  # rr: [r', r'', r''']
    fr = frenet(r1, r2, r3, s1, s2, numerators=numerators)
    return {k: v.reshape(shape) for k, v in fr.items()}


def _refine_gaps(cw: FloatArray | SpanForms, h: FloatArray, plan: _Plan, gaps: np.ndarray
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


@lru_cache(maxsize=32)
def _kernel_tables(degree: int, planar: bool
                   ) -> tuple[FloatArray, FloatArray, np.ndarray, FloatArray]:
    """The pass's constant tables for a degree (made once: on a short curve their Python
    loops were a twentieth of a small fair() call): the sign polynomials' fit and gap
    matrices padded to one shape, their sizes, and ``fall[j, nu] = j!/(j-nu)!``. The kernels
    only read them."""
    plan = _plan(degree, planar)
    p1 = degree + 1
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
    return fits, subs, nfit, fall


def sample_curve(cw: FloatArray | SpanForms, h: FloatArray, planar: bool, closed: bool,
                 rtol: float = QUAD_RTOL, sums_only: bool = False,
                 lean: bool | None = None) -> Samples:
    """Sample ``kappa`` and ``dkappa/ds`` on every segment; integrate; certify signs.

    ``cw`` are power coefficients ``(m, p+1, dim)`` (``dim`` 2 for planar curves, 3 for
    twisted ones), ``h`` the segment widths. One compiled pass over the segments (fused:
    no temporaries of the sample grid's size besides the two results), then adaptive
    re-integration of the segments whose error estimate exceeds ``rtol`` (relative, with an
    equal share of ``rtol`` times the total per unit parameter length), worst first, within a
    budget of ``max(200000, m / 8)`` pieces of 7 nodes.

    The samples are stored in float32 (their signs and rough sizes are all the counts need)
    as the dimensionless ``kappa * unit`` and ``dkappa/ds * unit**2``, ``unit`` the power of
    two nearest the diagonal of the segments' start points: curvature scales as 1/size and
    its derivative as 1/size**2, so a curve drawn at 1e24 (or 1e-24) would otherwise leave
    float32's range (dkappa/ds ~ 1e-48 flushes to zero and every extremum is lost). A power
    of two scales exactly: for curves of ordinary size the stored values are those of
    ``unit = 1`` times ``unit``, bit for bit.

    ``cw`` may be a :class:`SpanForms` (a planar curve whose form is not built): each range of
    the pass then makes its own rows, the re-integration and the sign certificates those of
    the segments they read; for a B-spline ``unit`` is then the power of two nearest the
    diagonal of the control points (a power of two either way: the counts and figures are the
    same bits).

    ``sums_only`` (what :func:`curvefair.analysis.fairness_figures` needs of an open curve
    whose segment forms are made range by range): the jumps and energies are not kept per
    segment (40 bytes a segment at the analysis' peak) but summed block by block as they are
    made, in numpy's pairwise order (:mod:`curvefair._kernels.pairwise`): ``Samples.sums``
    then holds ``np.sum`` of each energy column, ``np.sum`` of the Sapidis measure at the
    interior breakpoints and the largest jumps there, the same bits as those of the arrays
    (``knots`` and ``energies`` are then empty). From :data:`RESCAN_MIN` segments on, a
    ``sums_only`` pass of any curve keeps no samples (``kappa``, ``dkds``, ``ell`` and
    ``pos``: 2 K float32 and two float64 a segment, 9.5 times the coordinates' bytes for a
    planar quintic, the analysis' peak at ten million segments): it runs in blocks of
    ``STREAM_BLOCK`` segments, each writing them in its own rows and counting their sign
    changes at once (:func:`_first_counts`) with the zero band the block's own largest value
    gives, which is never above the final one (that needs the whole curve's largest values
    and size), keeping the samples of its gap segments (which get extra samples later);
    :func:`rescan_sign_counts` keeps those counts where they hold for the final bands and
    samples only the other blocks again. ``Samples.rescan`` says so. ``lean`` (with
    ``sums_only``): True keeps no samples at any size, False keeps them at any size, None
    from ``RESCAN_MIN`` segments on.
    """
    m, p1, dim = cw.shape
    p = p1 - 1
    plan = _plan(p, planar)
    K = plan.K
    fits, subs, nfit, fall = _kernel_tables(p, planar)
    # one spare row per range (the lead-in segment of a range, see pass_kernel); the views of
    # the first m rows are what the analysis keeps
    spare = _threads.CHUNKS
    forms = cw if isinstance(cw, SpanForms) else None
    unit = _unit(cast(FloatArray, cw)) if forms is None else _unit_of(forms.unit_points)
    stream = sums_only and forms is not None and not closed and m >= 2
    lean = sums_only and (m >= RESCAN_MIN if lean is None else lean)
    if lean:  # (each block's own rows, see blocks())
        kap = dks = np.empty((0, K), dtype=np.float32)
        ell = pos = np.empty(0)
    else:
        kap = np.empty((m + spare, K), dtype=np.float32)
        dks = np.empty((m + spare, K), dtype=np.float32)
        ell = np.empty(m + spare)
        pos = np.empty(m + spare)
    if stream:
        knots = energies = np.empty((0, 3))  # (summed by blocks in run(), never kept)
        lbe, lbs = _kp.leaf_bounds(m), _kp.leaf_bounds(m - 1)
        ls2, ls3 = np.empty(lbe.shape[0] - 1), np.empty(lbe.shape[0] - 1)
        lss = np.empty(lbs.shape[0] - 1)
        folds: dict[tuple[int, int], tuple[np.ndarray, ...]] = {}
    else:
        knots = np.empty((m + spare, 3))
        energies = np.empty((m + spare, 2))
    quad = np.empty((m + spare, 4))
    cwc = np.ascontiguousarray(cw, dtype=np.float64) if forms is None else None
    hc = np.ascontiguousarray(h, dtype=np.float64)
    first = np.zeros((2, dim))  # limits at the start of segment 0 (range 0 writes them)
    ksfl = np.zeros(2)
    starts = {a: q for q, a in enumerate(_threads.bounds(0, m))}
    block_rows: dict[int, list[Any]] = {}  # lean: each range's blocks' counts

    def run(a: int, b: int) -> tuple[int, float, float, np.ndarray, np.ndarray, np.ndarray,
                                     np.ndarray]:
        box = np.empty((2, dim))
        endv = np.empty((2, dim))
        fl = np.zeros(2)
        gaps = np.empty((max(1 << 12, (b - a) // 4), 3), dtype=np.int64)
        scratch = m + starts.get(a, 0)
        if stream or lean:  # (each block makes its own rows)
            return blocks(a, b, box, endv, fl, gaps, scratch)
        at = np.full((3, 2), scratch, dtype=np.int64)
        at[:, 0] = 0  # the whole arrays' rows
        if forms is None:
            rows, off = cwc, 0
        else:  # the range's own rows, its lead-in segment first
            off = a - 1 if a > 0 else 0
            # (an empty range still reads the row of its first segment for the box's start,
            # as it does in the whole form)
            rows = forms.rows(off, max(b, off + 1))
        while True:
            nsing, maxk, maxks, ngap = _k.pass_kernel(
                rows, hc, plan.x, plan.tab, plan.w7, plan.w4, plan.P, fall, fits, nfit, subs,
                SPEED_RTOL, CROSS_RTOL, kap, dks, knots, energies, quad, box, ell, pos, gaps,
                unit, a, b, at, first, endv, fl, off, True)
            if ngap <= gaps.shape[0]:
                break
            gaps = np.empty((ngap, 3), dtype=np.int64)  # rare: the buffer was too small; redo
        if a == 0 and b > 0:  # (an empty range 0 .. 0 when there are fewer segments than ranges)
            ksfl[0] = fl[0]
        return nsing, maxk, maxks, box, gaps[:ngap], endv, fl

    def blocks(a: int, b: int, box: np.ndarray, endv: np.ndarray, fl: np.ndarray,
               gaps: np.ndarray, scratch: int) -> tuple[int, float, float, np.ndarray,
                                                        np.ndarray, np.ndarray, np.ndarray]:
        """run() of a range in blocks of STREAM_BLOCK segments (sums_only): if ``stream``,
        each block's jumps and energies in the block's own rows, folded into the leaf sums
        after its pass (else in the whole arrays); if ``lean``, its samples in its own rows.
        Every output is what one pass over the range gives (each block re-runs its lead-in
        segment, as a range does: the same values; maxima, counts and boxes combine
        exactly)."""
        nb = max(min(STREAM_BLOCK, b - a), 1)
        if stream:
            kb = np.empty((nb + 1, 3))
            eb = np.empty((nb + 1, 2))
        else:
            kb, eb = knots, energies
        at = np.array([[0, scratch], [0, nb if stream else scratch], [0, scratch]],
                      dtype=np.int64)
        if lean:  # the samples in the block's own rows too
            kap_b = np.empty((nb + 1, K), dtype=np.float32)
            dks_b = np.empty((nb + 1, K), dtype=np.float32)
            ell_b = np.empty(nb + 1)
            pos_b = np.empty(nb + 1)
            at[2, 1] = nb
        else:
            kap_b, dks_b, ell_b, pos_b = kap, dks, ell, pos
        if stream:  # the fold state (see _kp.fold_block)
            bufs = np.empty((3, 2, _kp.LEAF))
            ints = np.zeros((3, 3), dtype=np.int64)
            fe = np.array([a, a, max(a, 1) - 1], dtype=np.int64)  # first element of each tree
            ints[:2, 2] = max(int(np.searchsorted(lbe, a, side="right")) - 1, 0)
            ints[2, 2] = max(int(np.searchsorted(lbs, fe[2], side="right")) - 1, 0)
            mx = np.full(2, -np.inf)
        nsing, maxk, maxks = 0, 0.0, 0.0
        bx = np.empty((2, dim))
        found: list[np.ndarray] = []
        counted: list[tuple[int, int, list[list[tuple[Any, ...]]]]] = []
        s0 = a
        while True:
            s1 = min(s0 + STREAM_BLOCK, b)
            if forms is None:
                rows, off = cast(FloatArray, cwc), 0
            else:
                off = s0 - 1 if s0 > 0 else 0
                rows = forms.rows(off, max(s1, off + 1))
            if stream:
                at[1, 0] = s0
            if lean:
                at[2, 0] = s0
            while True:
                ns, mk, mks, ngap = _k.pass_kernel(
                    rows, hc, plan.x, plan.tab, plan.w7, plan.w4, plan.P, fall, fits, nfit,
                    subs, SPEED_RTOL, CROSS_RTOL, kap_b, dks_b, kb, eb, quad, bx, ell_b, pos_b,
                    gaps, unit, s0, s1, at, first, endv, fl, off, True)
                if ngap <= gaps.shape[0]:
                    break
                gaps = np.empty((ngap, 3), dtype=np.int64)  # rare: too small; redo the block
            if stream:
                _kp.fold_block(kb, eb, s1 - s0, s0, lbe, lbs, ls2, ls3, lss, bufs, ints, fe,
                               mx)
            nsing += ns
            maxk = max(maxk, mk)
            maxks = max(maxks, mks)
            if s0 == a:
                box[:] = bx
            else:
                np.minimum(box[0], bx[0], out=box[0])
                np.maximum(box[1], bx[1], out=box[1])
            found.append(gaps[:ngap].copy())
            if lean:
                counted.append((s0, s1, _first_counts(kap_b, dks_b, ell_b, pos_b, s0, s1,
                                                      gaps[:ngap], mk, mks, unit, planar)))
            s0 = s1
            if s0 >= b:
                break
        if a == 0 and b > 0:
            ksfl[0] = fl[0]
        if stream:
            folds[(a, b)] = (bufs, ints, fe, mx)  # (ranges may be empty: a == b)
        if lean and a < b:
            block_rows[a] = counted
        return nsing, maxk, maxks, box, np.concatenate(found), endv, fl

    parts = _threads.ranges(run, 0, m, _threads.THREADS, PAR_MIN)
    nsing = sum(r[0] for r in parts)
    maxk = max(r[1] for r in parts)
    maxks = max(r[2] for r in parts)
    box = np.stack([np.min([r[3][0] for r in parts], axis=0),
                    np.max([r[3][1] for r in parts], axis=0)])
    gaps = parts[0][4] if len(parts) == 1 else np.concatenate([r[4] for r in parts])
    ngap = gaps.shape[0]
    sums = None
    if stream:
        sums = _stream_sums(folds, lbe, lbs, ls2, ls3, lss, m)
    else:
        knots, energies = knots[:m], energies[:m]
    kap, dks, quad = kap[:m], dks[:m], quad[:m]
    ell, pos = ell[:m], pos[:m]
    if closed:
        ksfl[1] = parts[-1][6][1]
        _k.seam_jumps(first, parts[-1][5], ksfl, knots)

    # adaptive quadrature where the 7-point/4-point estimate is too large: the worst segments
    # (a power-of-two threshold on estimate/allowance chosen so that their first refinement
    # level fits the budget), in curve order
    tot = np.empty(2)
    hist = np.zeros(64, dtype=np.int64)
    nbad = _k.allowances(quad, hc, float(rtol), tot, hist)
    if nbad:
        budget = max(200_000, m // 8)
        # at most this many segments get even one bisection (2 pieces for one starting
        # piece, whose value the pass has; P more to start from P pieces)
        top = budget // (2 if plan.P == 1 else 3 * plan.P)
        above = np.cumsum(hist[::-1])[::-1]  # above[k]: segments with worst > 2^k
        k = int(np.argmax(above <= top)) if above[0] > top else 0
        thresh = 1.0 if k == 0 else float(2.0**k)
        seg = np.empty(m, dtype=np.int64)  # (pages never written are never mapped)
        seg = seg[:_k.refine_candidates(quad, hc, float(rtol), tot, thresh, seg)].copy()
        rows = cast(FloatArray, cwc)[seg] if forms is None else forms[seg]
        _k.refine_kernel(rows, seg, hc, quad, float(rtol), tot, thresh, plan.P, plan.xk,
                         plan.w7, fall, SPEED_RTOL, CROSS_RTOL, _MAX_LEVELS, budget)

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
    block_counts = [r for a in sorted(block_rows) for r in block_rows[a]] if lean else None
    return Samples(x=plan.x, kappa=kap, dkds=dks, arc_length=float(np.sum(quad[:, 0])),
                   dkds_energy=float(np.sum(quad[:, 2])),
                   arc_length_error=float(np.sum(quad[:, 1])),
                   dkds_energy_error=float(np.sum(quad[:, 3])),
                   n_singular=int(nsing), max_kappa=float(maxk),
                   max_dkds=float(maxks), knots=knots, energies=energies,
                   diagonal=float(np.sqrt(np.sum((box[1] - box[0]) ** 2))), ell=ell,
                   pos=pos, extra=(extra[0], extra[1]), unit=unit, sums=sums, rescan=lean,
                   block_counts=block_counts)


def _first_counts(kap: np.ndarray, dks: np.ndarray, ell: FloatArray, pos: FloatArray, s0: int,
                  s1: int, gaps: np.ndarray, max_k: float, max_ks: float, unit: float,
                  planar: bool) -> list[list[tuple[Any, ...]]]:
    """A long summary's first-pass counts of the block of segments ``s0 .. s1-1`` (its
    samples in the rows ``0 .. s1-s0-1`` of ``kap``, ``dks``, ``ell``, ``pos``; ``gaps`` its
    flagged gaps), per quantity: the stretches between the gap segments (which get extra
    samples later) counted by :func:`curvefair._kernels.sampling.count_block` with the zero
    band the final one would be if the block's largest value ``max_k`` / ``max_ks`` were the
    curve's (the same operations as in :func:`curvefair.analysis._analyze._analyze`: rounding
    is monotone, so never above the final band), and the gap segments' samples kept for the
    final scan (:func:`rescan_sign_counts`). Nothing for ``kappa`` of a 3-D curve."""
    ns = s1 - s0
    el, ps = ell[:ns] / unit, pos[:ns] / unit
    out: list[list[tuple[Any, ...]]] = []
    for which, vals, big, power in ((0, kap, max_k, 1), (1, dks, max_ks, 2)):
        pieces: list[tuple[Any, ...]] = []
        out.append(pieces)
        if which == 0 and not planar:
            continue
        tb = ZERO_RTOL * big * unit if power == 1 else ZERO_RTOL * big * unit * unit
        lo = 0
        segs = gaps[gaps[:, 0] == which, 1]
        for g in np.unique(segs[(segs >= s0) & (segs < s1)]).tolist():
            i = g - s0
            if i > lo:
                pieces.append(("stretch", *_k.count_block(vals[lo:i], tb, el[lo:i], ps[lo:i],
                                                          ROUNDING_FLOOR, power)))
            pieces.append(("gap", g, vals[i].copy(), float(el[i]), float(ps[i])))
            lo = i + 1
        if lo < ns:
            pieces.append(("stretch", *_k.count_block(vals[lo:ns], tb, el[lo:ns], ps[lo:ns],
                                                      ROUNDING_FLOOR, power)))
    return out


def _stream_sums(folds: dict[tuple[int, int], tuple[np.ndarray, ...]], lbe: np.ndarray,
                 lbs: np.ndarray, ls2: FloatArray, ls3: FloatArray, lss: FloatArray, m: int
                 ) -> tuple[float, float, float, float, float]:
    """The figures of :func:`sample_curve`'s ``sums_only`` pass from the ranges' fold states
    (:func:`curvefair._kernels.pairwise.fold_block`): the leaves split between ranges summed
    from their parts in order (an earlier range's unfinished values, then the heads of the
    ranges after it, up to the one in which the leaf ends), then each tree combined in
    numpy's order."""
    trees = ((lbe, ls2), (lbe, ls3), (lbs, lss))
    for t, (lb, ls) in enumerate(trees):
        part: list[FloatArray] = []
        got = 0
        leaf = -1
        for a in sorted(folds):
            bufs, ints, _, _ = folds[a]
            nh, nc, cur = int(ints[t, 0]), int(ints[t, 1]), int(ints[t, 2])
            if nh:
                part.append(bufs[t, 0, :nh])
                got += nh
            if leaf >= 0 and got == lb[leaf + 1] - lb[leaf]:  # the split leaf is whole
                vals = np.concatenate(part)
                ls[leaf] = _kp.pw_sum_long(vals, vals.shape[0])
                part, got, leaf = [], 0, -1
            if nc:  # this range's last leaf is unfinished: its values so far
                assert leaf < 0
                part, got, leaf = [bufs[t, 1, :nc]], nc, cur
        assert leaf < 0, "a leaf left unfinished after the last range"
    mx = np.array([f[3] for f in folds.values()])
    top = mx.max(axis=0)  # (NaN propagates, as np.max)
    n = m - 1
    return (float(_kp.tree_sum(ls2, m)), float(_kp.tree_sum(ls3, m)),
            float(_kp.tree_sum(lss, n)), float(top[0]), float(top[1]))


def rescan_sign_counts(cw: FloatArray | SpanForms, h: FloatArray, breaks: FloatArray,
                       planar: bool, closed: bool, smp: Samples, ktol: float, kstol: float
                       ) -> tuple[int, int]:
    """The sign changes of ``kappa`` and ``dkappa/ds`` (:func:`scan_sign_changes`' counts) of
    a curve whose :func:`sample_curve` pass kept no samples (``smp.rescan``; ``cw``, ``h``,
    ``breaks`` and ``planar`` as that pass and :func:`scan_sign_changes` had them), with the
    zero bands ``ktol`` and ``kstol`` and the extra samples ``smp.extra`` (all scaled by
    ``smp.unit`` as :func:`curvefair.analyze` scales them for :func:`scan_sign_changes`).

    The first pass counted each block's stretches between its gap segments with a band no
    wider than the final one (``smp.block_counts``): a stretch's count holds for the final
    band exactly when no sample it counted as nonzero lies within that band (a sample
    classified differently would have ``band_b < |v| <= band``, above its segment's
    rounding band, which both share), i.e. when its least nonzero ``|v|`` is above it; the
    block's gap segments are then scanned with their kept samples and extra samples
    (:func:`_final_counts`). A block with a stretch that does not hold is sampled again
    (the pass block by block, ``STREAM_BLOCK`` segments, the blocks in ranges on the
    sampling's threads), its samples scanned as they are made; then dropped.

    The counts are exactly the whole scan's: the samples are the first pass's bits (the same
    compiled pass over the same rows, a block re-running its lead-in segment as a range
    does), a change is counted between two consecutive nonzero samples of opposite sign, and a
    block's scan starts with no sign, so the blocks' counts plus the changes between one
    block's last nonzero sample and the next one's first add up to the whole sequence's (and
    on a closed curve one more where the last nonzero sample's sign is not the first's, as
    :func:`scan_sign_changes` counts the seam). A block sampled again costs one more pass
    over its segments' forms and samples (without the energies, jumps, quadratures and gap
    certificates: ``full`` off); the samples (``8 K + 16`` bytes a segment) of a block are
    kept instead of the whole curve's.
    """
    m, p1, dim = cw.shape
    p = p1 - 1
    plan = _plan(p, planar)
    K = plan.K
    fits, subs, nfit, fall = _kernel_tables(p, planar)
    hc = np.ascontiguousarray(h, dtype=np.float64)
    bk = np.ascontiguousarray(breaks, dtype=np.float64)
    forms = cw if isinstance(cw, SpanForms) else None
    cwc = np.ascontiguousarray(cw, dtype=np.float64) if forms is None else None
    g = smp.unit
    # per quantity: samples' slot, extra samples (segment, u, value scaled as the samples),
    # zero band, power of the rounding band (see scan_sign_changes)
    quantities = []
    for which, (ex, tol, power) in enumerate(((smp.extra[0], ktol * g, 1),
                                              (smp.extra[1], kstol * g * g, 2))):
        if which == 0 and not planar:
            continue
        scale = g if power == 1 else g * g
        quantities.append((which, np.ascontiguousarray(ex[0], dtype=np.int64),
                           np.ascontiguousarray(ex[1]), np.ascontiguousarray(ex[2] * scale),
                           float(tol), power))

    def run(a: int, b: int) -> np.ndarray:
        """(n, first sign, last sign) per quantity of segments ``a .. b-1``."""
        state = np.zeros((2, 3), dtype=np.int64)
        if a >= b:
            return state
        nb = min(STREAM_BLOCK, b - a)
        vals = np.empty((2, nb + 1, K), dtype=np.float32)
        kb = np.empty((nb + 1, 3))
        eb = np.empty((nb + 1, 2))
        quad = np.empty((nb + 1, 4))
        ell = np.empty(nb + 1)
        pos = np.empty(nb + 1)
        box = np.empty((2, dim))
        endv = np.empty((2, dim))
        first = np.zeros((2, dim))
        fl = np.zeros(2)
        gaps = np.empty((0, 3), dtype=np.int64)  # (none found: the first pass has them)
        at = np.full((3, 2), nb, dtype=np.int64)
        s0 = a
        while s0 < b:
            s1 = min(s0 + STREAM_BLOCK, b)
            if forms is None:
                rows, off = cast(FloatArray, cwc), 0
            else:
                off = s0 - 1 if s0 > 0 else 0
                rows = forms.rows(off, s1)
            at[:, 0] = s0
            _k.pass_kernel(rows, hc, plan.x, plan.tab, plan.w7, plan.w4, plan.P, fall, fits,
                           nfit, subs, SPEED_RTOL, CROSS_RTOL, vals[0], vals[1], kb, eb, quad,
                           box, ell, pos, gaps, g, s0, s1, at, first, endv, fl, off, False)
            ns = s1 - s0
            for which, ex_seg, ex_u, ex_val, tol, power in quantities:
                _scan_stretch(state[which], vals[which, :ns], plan.x, bk[s0:s1 + 1], s0,
                              (ex_seg, ex_u, ex_val), tol, ell[:ns] / g, pos[:ns] / g, power)
            s0 = s1
        return state

    bc = smp.block_counts
    assert bc is not None  # (sample_curve counts every block of a pass that keeps nothing)
    # the first pass's counts of a block stand where its band was the final one for every
    # sample it counted (the least nonzero |value| above the final band); its gap segments
    # are scanned now with their extra samples; the other blocks are sampled and scanned
    # again, in ranges on the sampling's threads
    parts = [_final_counts(pieces, quantities, plan.x) for _, _, pieces in bc]
    redo = [(a, b) for (a, b, _), got in zip(bc, parts, strict=True) if got is None]
    chunks = _threads.ranges(lambda i, j: [run(*redo[q]) for q in range(i, j)], 0, len(redo),
                             _threads.THREADS, 2)
    again = iter([st for chunk in chunks for st in chunk])
    total = np.zeros((2, 3), dtype=np.int64)
    for got in parts:
        part = next(again) if got is None else got
        for which in (0, 1):
            _join(total[which], *part[which])
    if closed:
        _join_seam(total)
    return int(total[0, 0]), int(total[1, 0])


def _final_counts(pieces: list[list[tuple[Any, ...]]], quantities: list[tuple[Any, ...]],
                  x: FloatArray) -> np.ndarray | None:
    """A block's ``(changes, first sign, last sign)`` per quantity from its first-pass
    pieces (:func:`_first_counts`) with the final zero bands: a stretch's count stands if its
    least nonzero |value| is above the band (else None: the block is sampled again); a gap
    segment's kept samples are scanned with its extra samples (:func:`_scan_stretch`, the
    whole scan's operations)."""
    state = np.zeros((2, 3), dtype=np.int64)
    unit_breaks = np.array([0.0, 1.0])  # (the change locations are not used)
    for which, ex_seg, ex_u, ex_val, tol, power in quantities:
        for kind, *pc in pieces[which]:
            if kind == "stretch":
                n, fs, ls, least = pc
                if not least > tol:
                    return None
                _join(state[which], n, fs, ls)
            else:  # a gap segment: its samples and extra samples, scanned now
                g, row, el, ps = pc
                lo, hi = np.searchsorted(ex_seg, (g, g + 1))
                _scan_stretch(state[which], row[None, :], x, unit_breaks, 0,
                              (ex_seg[lo:hi] - g, ex_u[lo:hi], ex_val[lo:hi]), tol,
                              np.array([el]), np.array([ps]), power)
    return state


def count_sign_changes(vals: np.ndarray, x: FloatArray, breaks: FloatArray,
                       extra: tuple[np.ndarray, FloatArray, FloatArray], tol: float,
                       closed: bool, ell: FloatArray, pos: FloatArray, power: int) -> int:
    """The count of :func:`scan_sign_changes` alone (the same arguments), its segments
    scanned in ranges on the sampling's threads (from ``PAR_MIN`` segments) and joined as
    :func:`rescan_sign_counts` joins its blocks: the same count (a change is counted between
    two consecutive nonzero samples of opposite sign, whichever range they are in)."""
    ex = (np.ascontiguousarray(extra[0], dtype=np.int64), np.ascontiguousarray(extra[1]),
          np.ascontiguousarray(extra[2]))
    bk = np.ascontiguousarray(breaks, dtype=np.float64)
    v = np.ascontiguousarray(vals)
    el = np.ascontiguousarray(ell)
    ps = np.ascontiguousarray(pos)

    def run(a: int, b: int) -> np.ndarray:
        state = np.zeros(3, dtype=np.int64)
        if a < b:
            _scan_stretch(state, v[a:b], x, bk[a:b + 1], a, ex, float(tol), el[a:b], ps[a:b],
                          int(power))
        return state

    total = np.zeros(3, dtype=np.int64)
    for part in _threads.ranges(run, 0, v.shape[0], _threads.THREADS, PAR_MIN):
        _join(total, *part)
    if closed:
        _join_seam(total)
    return int(total[0])


def _scan_stretch(state: np.ndarray, vals: np.ndarray, x: FloatArray, breaks: FloatArray,
                  a: int, extra: tuple[np.ndarray, FloatArray, FloatArray], tol: float,
                  ell: FloatArray, pos: FloatArray, power: int) -> None:
    """Scan segments ``a .. a + len(vals) - 1`` (``vals``, ``ell``, ``pos`` their rows,
    ``breaks`` their ``len(vals) + 1`` breaks; ``extra`` the whole curve's sorted extra
    samples, of which theirs are taken) with :func:`scan_sign_changes`' compiled scan, and
    append the stretch to ``state`` (:func:`_join`)."""
    ex_seg, ex_u, ex_val = extra
    lo, hi = np.searchsorted(ex_seg, (a, a + vals.shape[0]))
    out = np.empty(vals.size + (hi - lo) + 1)  # (its pages written only at changes)
    n, fs, _, _, ls, _, _ = _k.scan_kernel(vals, x, breaks, ex_seg[lo:hi] - a, ex_u[lo:hi],
                                           ex_val[lo:hi], tol, ell, pos, ROUNDING_FLOOR,
                                           power, out)
    _join(state, n, fs, ls)


def _join_seam(state: np.ndarray) -> None:
    """A closed curve's seam, in place on the joined ``state`` (``(..., 3)``: changes, first
    and last nonzero sign): one more change where the last sign is not the first's, as
    :func:`scan_sign_changes` counts it."""
    state[..., 0] += (state[..., 1] != 0) & (state[..., 2] != state[..., 1])


def _join(state: np.ndarray, n: int, fs: int, ls: int) -> None:
    """Append a scanned stretch (``n`` changes, its first and last nonzero sign; 0: none) to
    ``state`` = (changes, first sign, last sign) of the stretches before it."""
    state[0] += n
    if fs != 0:
        if state[2] != 0 and state[2] != fs:
            state[0] += 1
        if state[1] == 0:
            state[1] = fs
        state[2] = ls


def _unit(cw: FloatArray) -> float:
    """The power of two nearest the diagonal of the segments' start points (1.0 if none)."""
    return _unit_of(cw[:, 0, :])


def _unit_of(pts: FloatArray) -> float:
    """The power of two nearest the diagonal of the bounding box of ``pts`` (1.0 if none)."""
    if pts.shape[0] == 0:
        return 1.0
    # per coordinate, 1-D reductions of the strided column (exact, as the reduction along
    # axis 0 is, and several times faster at a million segments)
    ext = np.array([pts[:, d].max() - pts[:, d].min() for d in range(pts.shape[1])])
    diag = float(np.sqrt(np.sum(ext ** 2)))
    if not (np.isfinite(diag) and diag > 0.0):
        return 1.0
    return float(2.0 ** int(np.clip(np.round(np.log2(diag)), -1000, 1000)))


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
    n, fs, ft, fv, ls, lt, lv = _k.scan_kernel(
        np.ascontiguousarray(vals), x, np.ascontiguousarray(breaks, dtype=np.float64),
        np.ascontiguousarray(ex_seg, dtype=np.int64), np.ascontiguousarray(ex_u),
        np.ascontiguousarray(ex_val), float(tol), np.ascontiguousarray(ell),
        np.ascontiguousarray(pos),
        ROUNDING_FLOOR,
        int(power), out)
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
