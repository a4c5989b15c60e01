"""Fairness analysis of a whole curve: energies, bad-point measures, curvature structure."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, cast

import numpy as np

from .._typing import FloatArray
from .._validate import as_positive
from ..curves.bspline import POWER_FORM_MAX_DEGREE, BSplineCurve
from ..curves.hermite import CubicHermite, QuinticHermite
from ..curves.piecewise import PiecewiseCurve, readonly
from ..interop import as_curve
from ._core import bounding_diagonal, check_curve, falling, fields_to_dict
from ._energy import segment_energies
from ._sampling import (
    QUAD_RTOL,
    ZERO_RTOL,
    SpanForms,
    count_sign_changes,
    rescan_sign_counts,
    sample_curve,
    scan_sign_changes,
)

__all__ = ["Analysis", "analyze", "fairness_figures", "derivative_jumps", "ZERO_RTOL",
           "PLANAR_RTOL"]

#: A 3-D curve is treated as planar when it deviates from its best plane by at most
#: ``PLANAR_RTOL * L`` (measured on its power coefficients, see :func:`analyze`).
PLANAR_RTOL = 1e-9


def _ro(a: np.ndarray) -> np.ndarray:
    return readonly(np.asarray(a))


@dataclass(frozen=True, eq=False)
class Analysis:
    """Result of :func:`analyze` (all arrays read-only; indices 0-based).

    Attributes
    ----------
    dim, degree, n_segments : int
    closed : bool
    planar : bool
        2-D curve, or a 3-D curve lying in a plane (then analysed in that plane).
    energy2, energy3 : float
        Exact ``int |r''|^2 dt`` and ``int |r'''|^2 dt`` (0 when the degree is lower).
    arc_length : float
    dkds_energy : float
        ``int (dkappa/ds)^2 ds``.
    arc_length_error, dkds_energy_error : float
        Error estimates of the two adaptive quadratures (see :func:`analyze`).
    jump_indices : ndarray of int, shape (k,)
        The interior breakpoints, as indices into ``curve.piecewise.breaks``: ``1 .. m-1`` for
        an open curve, ``0 .. m-1`` for a closed one (0 is the seam).
    jump_params : ndarray, shape (k,)
        Their parameters.
    jumps : ndarray, shape (k,)
        ``|r'''(t_j+) - r'''(t_j-)|`` (Wang & Cao 2006, eqs. (3) and (7): the bad-point
        measure).
    max_jump : float
    max_jump_index : int or None
        Breakpoint index of the largest jump (None without interior breakpoints).
    top_order : int
        The degree: order of the derivative in :attr:`top_jumps`.
    top_jumps : ndarray, shape (k,)
        ``|r^(degree)(t_j+) - r^(degree)(t_j-)|`` (a C4 quintic spline has no third-derivative
        jump; this is its bad-point measure).
    max_top_jump : float
    sapidis : ndarray, shape (k,)
        Sapidis-Farin measure ``z_j = |kappa_s(t_j+) - kappa_s(t_j-)|``, ``kappa_s =
        dkappa/ds`` (lecture notes 004 / ERRATA "Which knot").
    sapidis_sum : float
    max_sapidis : float
    max_sapidis_index : int or None
    inflections : int
        Number of sign changes of the signed curvature (see :func:`analyze` for 3-D).
    inflection_params : ndarray
        Approximate parameters of the inflections.
    extrema : int
        Number of sign changes of ``dkappa/ds`` (curvature extrema), across knots included.
    extremum_params : ndarray
        Approximate parameters of the extrema.
    max_curvature : float
        Largest ``|kappa|`` over the samples.
    kappa_tol, dkds_tol : float
        The noise bands used by the counts.
    n_singular : int
        Number of samples at zero speed (curvature undefined, taken as 0).
    """

    dim: int
    degree: int
    n_segments: int
    closed: bool
    planar: bool
    energy2: float
    energy3: float
    arc_length: float
    dkds_energy: float
    arc_length_error: float
    dkds_energy_error: float
    jump_indices: np.ndarray
    jump_params: FloatArray
    jumps: FloatArray
    max_jump: float
    max_jump_index: int | None
    top_order: int
    top_jumps: FloatArray
    max_top_jump: float
    sapidis: FloatArray
    sapidis_sum: float
    max_sapidis: float
    max_sapidis_index: int | None
    inflections: int
    inflection_params: FloatArray
    extrema: int
    extremum_params: FloatArray
    max_curvature: float
    kappa_tol: float
    dkds_tol: float
    n_singular: int

    def to_dict(self) -> dict[str, Any]:
        """A JSON-serialisable dict: plain ``float``/``int``/``bool``/``None`` and lists."""
        return fields_to_dict(self)


# ------------------------------------------------------------------------------------------------
def _knots(m: int, closed: bool) -> tuple[np.ndarray, np.ndarray]:
    """Interior breakpoints and the segment ending at each (left neighbour)."""
    idx = np.arange(0 if closed else 1, m)
    left = (idx - 1) % m
    return idx, left


def derivative_jumps(curve: PiecewiseCurve, nu: int) -> tuple[np.ndarray, FloatArray]:
    """``|r^(nu)(t_j+) - r^(nu)(t_j-)|`` at the interior breakpoints.

    Returns ``(indices, jumps)``; indices into ``curve.piecewise.breaks`` (closed curves
    include the seam, index 0, where the first segment's start meets the last one's end).
    Exact from the power coefficients: right limit ``nu! c[j, nu]``, left limit
    ``sum_k k!/(k-nu)! c[j-1, k] h_{j-1}^(k-nu)``.
    """
    c = check_curve(curve)
    pp = c.piecewise
    coeffs = np.asarray(pp.coeffs)
    m, p1, dim = coeffs.shape
    idx, left = _knots(m, c.closed)
    if nu >= p1:
        return idx, np.zeros(idx.shape[0])
    right_val = falling(nu, nu)[0] * coeffs[idx, nu, :]
    h = pp.widths[left]
    left_val = np.zeros((idx.shape[0], dim))
    for k in range(p1 - 1, nu - 1, -1):
        left_val = left_val * h[:, None] + falling(k, nu)[0] * coeffs[left, k, :]
    return idx, np.sqrt(np.sum((right_val - left_val) ** 2, axis=1))


def _plane_basis(coeffs: FloatArray, h: FloatArray, L: float) -> FloatArray | None:
    """Orthonormal basis (3, 2) of the plane holding a 3-D curve, or None if it is twisted."""
    c0 = coeffs[:, 0, :]
    cen = c0.mean(axis=0)
    vecs = [c0 - cen] + [coeffs[:, j, :] * (h[:, None] ** j) for j in range(1, coeffs.shape[1])]
    M = sum(v.T @ v for v in vecs)
    _, V = np.linalg.eigh(M)
    n = V[:, 0]
    dev = max(float(np.max(np.abs(v @ n))) for v in vecs)
    if dev > PLANAR_RTOL * max(L, np.finfo(float).tiny):
        return None
    return V[:, [2, 1]]


def _argmax_or_none(values: FloatArray, idx: np.ndarray) -> tuple[float, int | None]:
    if values.size == 0:
        return 0.0, None
    k = int(np.argmax(values))
    return float(values[k]), int(idx[k])


def analyze(curve: object, *, quad_rtol: float = QUAD_RTOL) -> Analysis:
    """Analyse the fairness of a curve: energies, jumps, Sapidis measure, inflections, extrema.

    Parameters
    ----------
    curve : PiecewiseCurve
        Any curvefair curve, 2-D or 3-D, open or closed, of any degree.
    quad_rtol : float
        Relative accuracy requested from the adaptive quadratures of ``arc_length`` and
        ``dkds_energy`` (default 1e-9). The counts do not depend on it.

    Returns
    -------
    Analysis
        Frozen dataclass; :meth:`Analysis.to_dict` gives a JSON-ready dict (no NaN).

    Notes
    -----
    **Energies** are exact (:func:`curvefair.energy`). **Jumps** at the interior breakpoints
    ``t_j`` (closed curves: the seam too) are exact from the power coefficients:
    ``|r'''(t_j+) - r'''(t_j-)|`` is Wang & Cao 2006's bad-point measure (eq. (3), non-uniform
    eq. (7); ``6 |a_{j,3} - a_{j-1,3}|`` for a cubic), ``top_jumps`` the same for the
    ``degree``-th derivative.

    **Sapidis-Farin measure** (004, Farin's method; ERRATA "Which knot"):
    ``z_j = |kappa_s(t_j+) - kappa_s(t_j-)|``, ``kappa_s = dkappa/ds`` evaluated on both sides
    by the general formula of :func:`curvefair.analysis.curvature_derivative`. For a planar C2
    cubic it equals ``|r' x jump(r''')| / |r'|^4``.

    **Sampling.** Every segment is cut into ``P`` equal pieces and each piece is sampled at the
    7 nodes of the Gauss-Kronrod-Lobatto pair of Gander & Gautschi (2000), both ends included,
    so both one-sided limits at every knot are samples. ``P`` is the smallest number for which
    the ``6P + 1`` nodes exceed the degrees of the sign polynomials below (``P = 1`` for
    planar cubics, 2 for twisted cubics, 3 for planar and 4 for twisted quintics).

    **Quadratures.** ``arc_length = int |r'| dt`` and ``dkds_energy = int kappa_s^2 |r'| dt``
    use the 7-point Kronrod rule on each piece (exact for degree 9); the difference to the
    embedded 4-point Lobatto rule is a (pessimistic) error estimate. Segments whose estimate
    exceeds ``quad_rtol * (|Q_i| + |total| h_i / (t_end - t_start))`` are integrated again on
    2, 4, ..., 1024 times as many pieces until two levels agree to that allowance, worst
    segments first (those whose estimate/allowance ratio exceeds a power of two chosen to fit
    the budget), within a budget of ``max(200000, m/8)`` pieces. The reported
    ``arc_length_error`` and ``dkds_energy_error`` are the sums of the final per-segment
    estimates. Typical results (tested against ``scipy.integrate.quad``): relative error
    1e-13..1e-10 for arc length, 1e-12..1e-8 for ``dkds_energy`` on planar curves; in 3-D
    ``|kappa|`` has near-corners where the curvature nearly vanishes and ``dkds_energy``
    converges more slowly (about 1e-7 relative, correctly estimated). On very large wiggly
    curves the budget can stop the refinement first; the error estimates then say so.

    **Counting inflections and extrema** (exact sign structure, noise band):

    1. The sampled values of ``kappa`` (for inflections) and ``kappa_s`` (for extrema), in
       curve order, both one-sided values at every knot, form a sequence. A value counts as
       zero when ``|kappa| <= max(1e-9 max(max|kappa|, 1/L), F (ell_i + pos_i) / ell_i^2)``,
       resp. ``|kappa_s| <= max(1e-9 max(max|kappa_s|, 1/L^2), F (ell_i + pos_i) /
       ell_i^3)``: ``L`` is the diagonal of the bounding box of the breakpoint positions, the
       maxima are over the samples, and the second term is the rounding level of the segment
       (``ell_i`` its length scale = size of its derivative polynomial times its width,
       ``pos_i`` the distance of its start from the origin, ``F = 1e3 eps``): rounded
       coordinates and coefficients bend a straight spline that much. The count is the
       number of sign changes between consecutive non-zero values, cyclically for a closed
       curve. A sign change across a knot (the curvature jump of a C1 curve, or a jump of
       ``kappa_s``) counts. The parameters reported are linear interpolations between the
       two samples of each change.
    2. No sign change hides between samples: on each segment the sign of ``kappa`` is that of
       the polynomial ``N = x'y'' - y'x''`` (degree ``2p - 4``) and the sign of ``kappa_s``
       that of the polynomial ``E = N' |r'|^2 - 3 N (r'.r'')`` (degree ``4p - 7``; in 3-D
       ``(C.C') |r'|^2 - 3 |C|^2 (r'.r'')``, ``C = r' x r''``, degree ``6p - 11``). The
       number of nodes exceeds these degrees, so the samples determine the polynomials;
       where their Bernstein coefficients on the segment vary in sign more often than the
       samples do, the gaps between samples are halved (de Casteljau) until each piece's
       coefficients vary at most once, and the split points become extra samples: then every
       sign change of the polynomial shows in the sample sequence (up to rounding). For a
       planar cubic ``N`` is a quadratic and the check is its vertex.

    Limitation of the noise band: an excursion beyond the band that is narrower than the
    sample spacing while all its samples lie inside the band is not counted; this only
    matters for curves whose ``|kappa_s|`` spans many orders of magnitude (near-cusps).

    Straight pieces give no inflections or extrema. A circle arc interpolated by a cubic
    spline has a curvature that really oscillates slightly about ``1/R`` (relative amplitude
    about 1e-5 for 40 points on a half circle): those extrema are real and counted.

    **3-D curves.** A 3-D curve lying in a plane (deviation at most ``1e-9 L`` from its best
    fitting plane, measured on the scaled power coefficients) is analysed in that plane with
    signed curvature. A twisted space curve has unsigned curvature, which has no sign to
    change: ``inflections = 0`` and ``inflection_params`` is empty (inflections of a twisted
    curve, points where ``r' x r''`` vanishes, are not generic); extrema are the sign changes
    of ``d|kappa|/ds`` (where ``|kappa| = 0`` exactly, ``d|kappa|/ds`` is taken as 0).

    **Degenerate points.** Where the speed is zero (``|r'| <= 1e-12`` times the size of the
    segment's derivative polynomial), or where an intermediate overflows, curvature and
    ``kappa_s`` are taken as 0 and the sample is counted in ``n_singular``; in the sign
    sequences such samples are zeros (skipped). No output is NaN or infinite.

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import interpolate_cubic, analyze
    >>> x = np.linspace(-2, 2, 21)
    >>> a = analyze(interpolate_cubic(np.c_[x, np.tanh(2 * x)]))   # S-curve
    >>> a.inflections
    1
    >>> a.max_jump_index is not None and a.energy2 > 0
    True
    """
    c = check_curve(as_curve(curve, "curve"))  # scipy splines too (curvefair.interop)
    rtol = as_positive(quad_rtol, "quad_rtol")
    assert rtol is not None
    out = _analyze(c, rtol, False)
    assert isinstance(out, Analysis)
    return out


def fairness_figures(curve: PiecewiseCurve, *, lean: bool | None = None) -> dict[str, Any]:
    """The scalar figures of :func:`analyze` that a fairing report prints, bit for bit the
    same, without the per-breakpoint arrays: ``energy2``, ``energy3``, ``max_jump``,
    ``max_top_jump``, ``sapidis_sum``, ``dkds_energy``, ``inflections``, ``extrema``.

    :func:`curvefair.fair` analyses its input and its result; at ten million segments the
    frozen per-breakpoint arrays of a full :class:`Analysis` (jumps, top jumps, Sapidis
    measure, their indices and parameters: 40 bytes a segment) would be made at the call's
    peak and never read.

    ``lean``: keep no samples (count each block's signs as it is made, see
    :func:`curvefair.analysis._sampling.sample_curve`), whatever the size; None: from
    ``RESCAN_MIN`` segments on. The same figures either way; lean, the analysis holds less
    than half the memory (52-60 bytes a segment instead of 128-228 for planar cubics and
    quintics): what :func:`curvefair.fair` asks for when the input's analysis runs beside
    the method.
    """
    out = _analyze(check_curve(curve), QUAD_RTOL, True, lean=lean)
    assert isinstance(out, dict)
    return out


def lean_by_default(n_segments: int) -> bool:
    """Whether :func:`fairness_figures` of a curve of ``n_segments`` segments keeps no samples
    unless told (``lean=None``): from ``RESCAN_MIN`` segments on, where memory is what limits
    a call (:func:`curvefair.fair` then analyses its input before the method, not beside it)."""
    from ._sampling import RESCAN_MIN

    return n_segments >= RESCAN_MIN


def _span_forms(c: PiecewiseCurve) -> SpanForms | None:
    """A planar B-spline's or Hermite spline's segment forms made where the sampling reads
    them, when its whole power form is not built (else that is read), else None."""
    if c.dim != 2 or "piecewise" in c.__dict__:
        return None
    if type(c) is BSplineCurve and c.degree <= POWER_FORM_MAX_DEGREE:
        return SpanForms(c)
    if type(c) in (CubicHermite, QuinticHermite):
        return SpanForms(cast(CubicHermite | QuinticHermite, c))
    return None


def _analyze(c: PiecewiseCurve, rtol: float, summary: bool, whole: bool = False,
             lean: bool | None = None) -> Analysis | dict[str, Any]:
    """:func:`analyze` of a checked curve; ``summary``: :func:`fairness_figures` instead;
    ``whole``: read the whole power form even where :class:`SpanForms` could be made."""
    forms = None if whole else _span_forms(c)
    coeffs: FloatArray | None
    if forms is not None:
        breaks = forms.breaks  # and the widths, as the whole form has them
        h = np.diff(breaks)
        m, p1, dim = forms.shape
        coeffs = None
    else:
        pp = c.piecewise
        coeffs = np.asarray(pp.coeffs)
        breaks = np.asarray(pp.breaks)
        m, p1, dim = coeffs.shape
        h = pp.widths
    degree = p1 - 1
    closed = bool(c.closed)
    planar = dim == 2
    cw: FloatArray | SpanForms = forms if forms is not None else cast(FloatArray, coeffs)
    if dim == 3:
        assert coeffs is not None
        L = bounding_diagonal(pp)
        E = _plane_basis(coeffs, h, L)
        if E is not None:
            planar = True
            cw = np.ascontiguousarray(coeffs @ E)  # (m, p1, 2): coordinates in the plane

    smp = sample_curve(cw, h, planar, closed, rtol, sums_only=summary, lean=lean)
    if forms is not None and not forms.finite:
        c.piecewise  # noqa: B018 (a form beyond float64 raises the whole form's own message)
        return _analyze(c, rtol, summary, True, lean)
    if dim == 2:
        L = smp.diagonal
    ks = slice(0 if closed else 1, m)  # the interior knots as a slice (cheaper than indexing)
    # analyze() keeps one frozen copy of each per-knot column; the summary reads the values
    # where the pass wrote them
    keep = (lambda a: a) if summary else _ro
    sums = smp.sums  # (a summary of an open planar curve: summed in the pass, see there)
    if sums is not None:
        e2, e3, sap, max_jump, max_top = sums
    elif cw is coeffs or cw is forms:
        # exact energies and jumps from the same compiled pass
        e2 = float(np.sum(smp.energies[:, 0]))
        e3 = float(np.sum(smp.energies[:, 1]))
        jumps = keep(smp.knots[ks, 0])
        top = keep(smp.knots[ks, 1])
    else:  # a planar 3-D curve: energies and jumps from its own (3-D) coefficients
        e2 = float(np.sum(segment_energies(c, 2))) if degree >= 2 else 0.0
        e3 = float(np.sum(segment_energies(c, 3))) if degree >= 3 else 0.0
        jumps = derivative_jumps(c, 3)[1]
        top = derivative_jumps(c, degree)[1]
    if sums is None:
        max_top = float(top.max()) if top.size else 0.0

    kap, dks = smp.kappa, smp.dkds
    max_k, max_ks = smp.max_kappa, smp.max_dkds
    if smp.extra[0][2].size:
        max_k = max(max_k, float(np.max(np.abs(smp.extra[0][2]))))
    if smp.extra[1][2].size:
        max_ks = max(max_ks, float(np.max(np.abs(smp.extra[1][2]))))
    invL = 1.0 / L if L > 0 else 0.0
    ktol = ZERO_RTOL * max(max_k, invL)
    kstol = ZERO_RTOL * max(max_ks, invL * invL)
    # the samples hold kappa * unit and dkappa/ds * unit**2 (a power of two, exact): scale
    # the thresholds, the refined values and the rounding band's lengths alike
    g = smp.unit
    ell_g, pos_g = smp.ell / g, smp.pos / g
    ex_k, ex_ks = smp.extra
    if smp.rescan:  # (a long curve's summary: no samples kept, see sample_curve)
        assert summary
        n_infl, n_ext = rescan_sign_counts(cw, h, breaks, planar, closed, smp, ktol, kstol)
        infl_at = ext_at = np.zeros(0)
    elif summary:  # the counts alone (in ranges on the sampling's threads)
        n_infl = count_sign_changes(kap, smp.x, breaks, (ex_k[0], ex_k[1], ex_k[2] * g),
                                    ktol * g, closed, ell_g, pos_g, 1) if planar else 0
        n_ext = count_sign_changes(dks, smp.x, breaks, (ex_ks[0], ex_ks[1], ex_ks[2] * g * g),
                                   kstol * g * g, closed, ell_g, pos_g, 2)
        infl_at = ext_at = np.zeros(0)
    else:
        if planar:
            n_infl, infl_at = scan_sign_changes(kap, smp.x, breaks,
                                                (ex_k[0], ex_k[1], ex_k[2] * g), ktol * g,
                                                closed, ell_g, pos_g, 1)
        else:
            n_infl, infl_at = 0, np.zeros(0)
        n_ext, ext_at = scan_sign_changes(dks, smp.x, breaks,
                                          (ex_ks[0], ex_ks[1], ex_ks[2] * g * g),
                                          kstol * g * g, closed, ell_g, pos_g, 2)

    if summary:
        # the sum of the column where the pass wrote it: numpy's pairwise summation runs
        # over a strided column as over analyze()'s frozen contiguous copy (the same bits,
        # tested on 60,000 segments), without a copy at the analysis' peak
        if sums is None:
            max_jump = float(jumps.max()) if jumps.size else 0.0
            sap = float(np.sum(smp.knots[ks, 2]))
        return {"energy2": e2, "energy3": e3, "max_jump": max_jump, "max_top_jump": max_top,
                "sapidis_sum": sap,
                "dkds_energy": float(smp.dkds_energy), "inflections": int(n_infl),
                "extrema": int(n_ext)}
    jidx = np.arange(0 if closed else 1, m, dtype=np.int64)
    max_jump, max_jump_index = _argmax_or_none(jumps, jidx)

    # -- Sapidis-Farin measure from the one-sided samples at the knots ----------------------
    z = _ro(smp.knots[ks, 2])
    max_z, max_z_index = _argmax_or_none(z, jidx)

    return Analysis(
        dim=int(dim), degree=int(degree), n_segments=int(m), closed=closed, planar=planar,
        energy2=e2, energy3=e3, arc_length=float(smp.arc_length),
        dkds_energy=float(smp.dkds_energy), arc_length_error=float(smp.arc_length_error),
        dkds_energy_error=float(smp.dkds_energy_error),
        jump_indices=_ro(jidx), jump_params=_ro(breaks[ks]),
        jumps=_ro(jumps), max_jump=max_jump, max_jump_index=max_jump_index,
        top_order=int(degree), top_jumps=_ro(top), max_top_jump=max_top,
        sapidis=_ro(z), sapidis_sum=float(np.sum(z)), max_sapidis=max_z,
        max_sapidis_index=max_z_index,
        inflections=int(n_infl), inflection_params=_ro(infl_at),
        extrema=int(n_ext), extremum_params=_ro(ext_at),
        max_curvature=max_k, kappa_tol=float(ktol), dkds_tol=float(kstol),
        n_singular=int(smp.n_singular),
    )

