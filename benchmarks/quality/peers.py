"""Peer smoothers tuned to a target maximum deviation, returned as curvefair curves.

Every tool here and every curvefair method is judged on the same footing:

* **Parameter.** Every fit uses the chord-length parameter of the input points,
  ``u_0 = 0, u_i = u_{i-1} + |p_i - p_{i-1}|`` (closed curves: one more value for the closing
  point), and every resulting curve lives on that parameter domain. The parametric energies
  ``E2 = int |r''|^2 du`` and ``E3 = int |r'''|^2 du`` are therefore comparable between tools;
  the geometric measures (extrema, inflections, ``int (dkappa/ds)^2 ds``) do not depend on it.
* **Deviation.** ``max_i |C(u_i) - p_i|``, the distance of each input point from the curve at
  that point's own parameter -- the quantity every tool here fits (smoothing splines minimise
  ``sum |C(u_i) - p_i|^2 + ...``) and the one curvefair's tolerance bounds (a data point, or a
  control point of an interpolating B-spline, never moves farther than ``tol``).
* **Curves.** Every result is a :class:`curvefair.PiecewiseCurve` -- a
  :class:`curvefair.BSplineCurve` (``BSplineCurve.from_scipy``) for scipy and splipy, a thin
  :class:`PPCurve` over the piecewise-polynomial form for csaps -- so its metrics come from the
  one definition in :func:`curvefair.analyze`.

Tuning: each peer's smoothing parameter is bisected (on a log scale) for the smoothest result
whose deviation does not exceed the target: the result returned has ``dev <= target`` and, when
the bisection converged, ``dev >= 0.98 target``.

Closed curves: csaps and ``make_smoothing_spline`` have no periodic mode. They are fitted to the
point sequence wrapped around once more on each side (three periods), and the middle period is
kept; the resulting seam mismatch is reported as ``seam`` (it is many orders below the
tolerance on the corpus). ``make_splprep`` is run with ``bc_type="periodic"``; splipy's smooth
is not applied to closed curves.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

import curvefair as cf
from curvefair.curves.piecewise import PiecewiseCurve, PiecewisePolynomial

__all__ = ["PPCurve", "PeerResult", "chord_params", "data_deviation", "tune", "PEERS",
           "run_peer", "peer_names"]


# ---------------------------------------------------------------------------------------------
class PPCurve(PiecewiseCurve):
    """A curve given by its local power form (breaks ``(m+1,)``, coeffs ``(m, p+1, dim)``)."""

    def __init__(self, breaks: np.ndarray, coeffs: np.ndarray, closed: bool = False) -> None:
        self._pp = PiecewisePolynomial(np.array(breaks, dtype=float),
                                       np.array(coeffs, dtype=float))
        self.degree = self._pp.degree
        self._closed = bool(closed)

    @property
    def dim(self) -> int:
        return self._pp.dim

    @property
    def closed(self) -> bool:
        return self._closed

    def _make_piecewise(self) -> PiecewisePolynomial:
        return self._pp

    @classmethod
    def from_ppoly(cls, x: np.ndarray, c: np.ndarray, lo: float, hi: float,
                   closed: bool = False) -> "PPCurve":
        """From scipy-style ``PPoly(c, x)`` with ``c`` shape ``(k+1, m, dim)`` (highest power
        first), restricted to ``[lo, hi]`` (see :meth:`cut`)."""
        c = np.asarray(c, float)
        return cls.cut(np.asarray(x, float), np.transpose(c[::-1], (1, 0, 2)), lo, hi, closed)

    @classmethod
    def cut(cls, x: np.ndarray, coeffs: np.ndarray, lo: float, hi: float,
            closed: bool = False) -> "PPCurve":
        """Local power form ``(x (m+1,), coeffs (m, k+1, dim))`` restricted to ``[lo, hi]``:
        the pieces between, the first re-expanded about ``lo``, the last ending at ``hi``."""
        inner = x[(x > lo) & (x < hi)]
        breaks = np.concatenate([[lo], inner, [hi]])
        seg = np.clip(np.searchsorted(x, breaks[:-1], side="right") - 1, 0, coeffs.shape[0] - 1)
        # re-expand each kept piece about its new left end (only the first one moves)
        out = coeffs[seg].copy()
        shift = breaks[:-1] - x[seg]
        for i in np.flatnonzero(shift != 0):
            out[i] = _taylor_shift(coeffs[seg[i]], shift[i])
        return cls(breaks, out, closed)


def _taylor_shift(c: np.ndarray, d: float) -> np.ndarray:
    """Coefficients (lowest first, shape (k+1, dim)) of ``p(s + d)``."""
    k1 = c.shape[0]
    out = np.zeros_like(c)
    for j in range(k1):
        for i in range(j, k1):
            out[j] += math.comb(i, j) * d ** (i - j) * c[i]
    return out


# ---------------------------------------------------------------------------------------------
def chord_params(points: np.ndarray, closed: bool) -> np.ndarray:
    """Chord-length parameters; closed: ``n + 1`` values (the last for the closing point)."""
    loop = np.vstack([points, points[:1]]) if closed else points
    return cf.parameterize(loop, "chord")


def data_deviation(curve: PiecewiseCurve, points: np.ndarray, u: np.ndarray
                   ) -> tuple[float, int]:
    """``max_i |curve(u_i) - p_i|`` and its index ``i`` (``u`` one value per point)."""
    d = np.linalg.norm(curve(u[: len(points)]) - points, axis=1)
    i = int(np.argmax(d))
    return float(d[i]), i


@dataclass
class PeerResult:
    """A tool's result on one input: the curve (on the chord-length domain), its deviation from
    the input, the smoothing parameter reached and notes."""

    tool: str
    curve: PiecewiseCurve | None
    dev: float = math.nan
    dev_index: int = -1
    param: float = math.nan
    evaluations: int = 0
    converged: bool = False
    note: str = ""
    extra: dict[str, Any] = field(default_factory=dict)


def tune(build: Callable[[float], PiecewiseCurve], points: np.ndarray, u: np.ndarray,
         target: float, lo: float, hi: float, iters: int = 40, rel: float = 0.02,
         integer: bool = False) -> tuple[PiecewiseCurve | None, float, float, int, int, bool]:
    """Bisect ``x`` in ``[lo, hi]`` (more smoothing as ``x`` grows) for the largest ``x`` with
    ``dev(build(x)) <= target``.

    Returns ``(curve, x, dev, dev_index, evaluations, converged)``; ``converged`` when the
    deviation reached ``[(1 - rel) target, target]``. ``curve`` is None when even ``lo`` breaks
    the target.
    """
    evals = 0

    def ev(x: float) -> tuple[PiecewiseCurve | None, float, int]:
        nonlocal evals
        evals += 1
        try:
            c = build(x)
        except Exception:  # noqa: BLE001 - any failure of a peer at this x: treat as unusable
            return None, math.inf, -1
        d, i = data_deviation(c, points, u)
        if not math.isfinite(d):
            return None, math.inf, -1
        return c, d, i

    c_lo, d_lo, i_lo = ev(lo)
    if c_lo is None or d_lo > target:
        return None, lo, d_lo, i_lo, evals, False
    c_hi, d_hi, _ = ev(hi)
    if c_hi is not None and d_hi <= target:  # even the heaviest smoothing stays inside
        return c_hi, hi, d_hi, _, evals, True
    best = (c_lo, lo, d_lo, i_lo)
    a, b = lo, hi
    for _ in range(iters):
        if best[2] >= (1 - rel) * target:
            break
        if integer:
            if b - a <= 1:
                break
            m = float((int(a) + int(b)) // 2)
        else:
            m = 0.5 * (a + b)
        c, d, i = ev(m)
        if c is not None and d <= target:
            a = m
            best = (c, m, d, i)
        else:
            b = m
    return best[0], best[1], best[2], best[3], evals, best[2] >= (1 - rel) * target


# ---------------------------------------------------------------------------------------------
def _wrap(points: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Three periods of a closed point sequence and their parameters; returns the period."""
    n = len(points)
    period = float(u[n])
    pts3 = np.vstack([points, points, points])
    u3 = np.concatenate([u[:n] - period, u[:n], u[:n] + period])
    return pts3, u3, period


def _seam(curve: PiecewiseCurve) -> float:
    t0, t1 = curve.domain
    pp = curve.piecewise
    a = pp.evaluate(np.array([t0]), 0)[0]
    b = pp.evaluate(np.array([t1]), 0, segment=np.array([pp.n_segments - 1]))[0]
    return float(np.linalg.norm(a - b))


def peer_csaps(points: np.ndarray, closed: bool, tol: float) -> PeerResult:
    """csaps ``CubicSmoothingSpline``; ``smooth = p = 1 / (1 + 10^x)`` bisected over x."""
    from csaps import CubicSmoothingSpline

    u = chord_params(points, closed)
    if closed:
        pts_f, u_f, period = _wrap(points, u)
        lo_u, hi_u = 0.0, period
    else:
        pts_f, u_f = points, u
        lo_u, hi_u = float(u[0]), float(u[-1])

    def build(x: float) -> PiecewiseCurve:
        p = 1.0 / (1.0 + 10.0**x)
        s = CubicSmoothingSpline(u_f, pts_f.T, smooth=p).spline
        c = np.asarray(s.c)  # (order, pieces, dim) for axis=-1 data (checked in the tests)
        return PPCurve.from_ppoly(np.asarray(s.x), c, lo_u, hi_u, closed)

    c, x, d, i, ev, ok = tune(build, points, u, tol, -14.0, 16.0)
    res = PeerResult("csaps", c, d, i, x, ev, ok)
    if closed and c is not None:
        res.extra["seam"] = _seam(c)
    return res


def peer_smoothing_spline(points: np.ndarray, closed: bool, tol: float) -> PeerResult:
    """scipy ``make_smoothing_spline`` (one shared lam for all coordinates), lam = 10^x L^3."""
    from scipy.interpolate import make_smoothing_spline

    u = chord_params(points, closed)
    if closed:
        pts_f, u_f, period = _wrap(points, u)
        lo_u, hi_u = 0.0, period
    else:
        pts_f, u_f = points, u
        lo_u, hi_u = float(u[0]), float(u[-1])
    L3 = float(u[-1]) ** 3

    def build(x: float) -> PiecewiseCurve:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            spl = make_smoothing_spline(u_f, pts_f, lam=10.0**x * L3)
        curve = cf.BSplineCurve.from_scipy(spl, closed=False)
        if not closed:
            return curve
        pp = curve.piecewise
        return PPCurve.cut(np.asarray(pp.breaks), np.asarray(pp.coeffs), lo_u, hi_u, True)

    c, x, d, i, ev, ok = tune(build, points, u, tol, -22.0, 6.0)
    res = PeerResult("scipy-smoothing", c, d, i, x, ev, ok)
    if closed and c is not None:
        res.extra["seam"] = _seam(c)
    return res


def peer_splprep(points: np.ndarray, closed: bool, tol: float) -> PeerResult:
    """scipy ``make_splprep`` (FITPACK knot placement), ``s = n tol^2 10^x`` bisected over x.

    ``s`` bounds the sum of squared residuals; the knots FITPACK adds depend on ``s``, so the
    deviation is not strictly monotone in ``x``: the bisection returns the smoothest result it
    met that stays within the target.
    """
    from scipy.interpolate import make_splprep

    u = chord_params(points, closed)
    n = len(points)
    data = np.vstack([points, points[:1]]) if closed else points

    def build(x: float) -> PiecewiseCurve:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            spl, _ = make_splprep(data.T, u=u, s=n * tol * tol * 10.0**x,
                                  bc_type="periodic" if closed else None)
        return cf.BSplineCurve.from_scipy(spl, closed=closed)

    c, x, d, i, ev, ok = tune(build, points, u, tol, -8.0, 4.0)
    res = PeerResult("scipy-splprep", c, d, i, x, ev, ok)
    if c is not None:
        res.extra["n_ctrl"] = int(c.n_ctrl)
    return res


def peer_splipy(points: np.ndarray, closed: bool, tol: float) -> PeerResult:
    """splipy's ``utils.smooth.smooth`` (each interior control point replaced by the mean of
    itself and its two neighbours), applied k times to the natural cubic interpolating B-spline
    (``curvefair.interpolate_bspline``); the largest k within the target."""
    if closed:
        return PeerResult("splipy-smooth", None, note="not applicable to closed curves")
    try:
        from splipy import BSplineBasis, Curve
        from splipy.utils.smooth import smooth
    except ImportError:
        return PeerResult("splipy-smooth", None, note="splipy not installed")

    u = chord_params(points, closed)
    base = cf.interpolate_bspline(points, 3, u)
    knots = np.array(base.knots)
    ctrl0 = np.array(base.control_points)
    cache: dict[int, np.ndarray] = {0: ctrl0}

    def ctrl_after(k: int) -> np.ndarray:
        start = max(j for j in cache if j <= k)
        crv = Curve(BSplineBasis(4, knots), cache[start].copy())
        for _ in range(k - start):
            smooth(crv)
        out = np.array(crv.controlpoints)
        cache[k] = out
        return out

    def build(x: float) -> PiecewiseCurve:
        return cf.BSplineCurve(ctrl_after(int(x)), knots, 3)

    # exponential search for a bracket, then integer bisection
    hi = 1
    while hi < 4096:
        d, _ = data_deviation(build(hi), points, u)
        if d > tol:
            break
        hi *= 2
    c, x, d, i, ev, ok = tune(build, points, u, tol, 0.0, float(hi), integer=True)
    res = PeerResult("splipy-smooth", c, d, i, x, ev, ok or x == hi)
    res.extra["iterations"] = int(x)
    return res


PEERS: dict[str, Callable[[np.ndarray, bool, float], PeerResult]] = {
    "csaps": peer_csaps,
    "scipy-smoothing": peer_smoothing_spline,
    "scipy-splprep": peer_splprep,
    "splipy-smooth": peer_splipy,
}


def peer_names() -> list[str]:
    return list(PEERS)


def run_peer(name: str, points: np.ndarray, closed: bool, tol: float) -> PeerResult:
    return PEERS[name](np.asarray(points, float), bool(closed), float(tol))
