"""Shared machinery of the analysis functions: input checks, locating parameters, local
derivatives, the Frenet quantities and Bernstein/Taylor helpers.

Everything works on the local power form ``r(t) = sum_j c[i, j] (t - t_i)**j`` of
:attr:`curvefair.PiecewiseCurve.piecewise`, vectorised over segments and samples.
"""

from __future__ import annotations

from collections.abc import Sequence
from math import comb, factorial
from typing import Literal

import numpy as np

from .._typing import ArrayLike, FloatArray
from .._validate import choice
from ..curves.piecewise import PiecewiseCurve, PiecewisePolynomial
from ..errors import InputError

Side = Literal["right", "left"]

#: A point is *singular* (zero speed) where ``|r'| <= SPEED_RTOL * scale`` with ``scale`` the
#: size of the derivative polynomial of its segment (see :func:`speed_scale`).
SPEED_RTOL = 1e-12
#: In 3-D the curvature counts as exactly zero where ``|r' x r''| <= CROSS_RTOL |r'| * scale2``,
#: ``scale2`` the size of the segment's second-derivative polynomial.
CROSS_RTOL = 1e-13


def check_curve(curve: object, name: str = "curve") -> PiecewiseCurve:
    """Raise :class:`InputError` unless ``curve`` is a :class:`PiecewiseCurve`."""
    if not isinstance(curve, PiecewiseCurve):
        raise InputError(
            f"{name} must be a curvefair curve (a PiecewiseCurve such as CubicHermite, "
            f"QuinticHermite or BSplineCurve), got {type(curve).__name__}")
    return curve


def falling(j: np.ndarray | int, nu: int) -> np.ndarray:
    """``j! / (j - nu)!`` (0 where ``j < nu``), as floats."""
    j = np.atleast_1d(np.asarray(j))
    out = np.array([factorial(int(k)) // factorial(int(k) - nu) if k >= nu else 0 for k in j],
                   dtype=float)
    return out


def locate(curve: PiecewiseCurve, u: ArrayLike, side: str
           ) -> tuple[np.ndarray, FloatArray, tuple[int, ...], bool]:
    """Segment index and local offset for parameters ``u``.

    ``side="right"`` takes the segment starting at a breakpoint (right limit), ``"left"`` the
    one ending there (left limit). Closed curves wrap periodically; an open curve rejects
    parameters outside its domain. Returns ``(seg, s, shape, scalar)`` with ``seg``, ``s``
    flattened.
    """
    choice(side, ("right", "left"), "side")
    try:
        ua = np.asarray(u, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"u must be a number or an array of numbers, got {u!r}") from None
    scalar = ua.ndim == 0
    shape = ua.shape
    uf = ua.reshape(-1)
    if not np.all(np.isfinite(uf)):
        ib = int(np.flatnonzero(~np.isfinite(uf))[0])
        raise InputError(f"u contains a non-finite parameter {uf[ib]!r} at index {ib}")
    pp = curve.piecewise
    b = pp.breaks
    t0, t1 = float(b[0]), float(b[-1])
    if curve.closed:
        uf = t0 + np.mod(uf - t0, t1 - t0)
        if side == "left":
            uf = np.where(uf <= t0, t1, uf)
    else:
        slack = 1e-12 * (t1 - t0)
        bad = (uf < t0 - slack) | (uf > t1 + slack)
        if np.any(bad):
            v = uf[np.flatnonzero(bad)[0]]
            raise InputError(f"u = {v!r} is outside the curve's domain [{t0!r}, {t1!r}]")
        uf = np.clip(uf, t0, t1)
    m = pp.n_segments
    if side == "right":
        seg = np.searchsorted(b, uf, side="right") - 1
    else:
        seg = np.searchsorted(b, uf, side="left") - 1
    seg = np.clip(seg, 0, m - 1)
    s = uf - b[seg]
    return seg, s, shape, scalar


def horner(c: FloatArray, s: FloatArray) -> FloatArray:
    """Evaluate ``sum_j c[..., j, :] s**j``; ``c`` (k, q, dim) and ``s`` (k,) -> (k, dim)."""
    out = c[:, -1, :].copy()
    for j in range(c.shape[1] - 2, -1, -1):
        out *= s[:, None]
        out += c[:, j, :]
    return out


def derivs_at(coeffs: FloatArray, s: FloatArray, nmax: int) -> list[FloatArray]:
    """``[r', r'', ..., r^(nmax)]`` at local offsets ``s``; ``coeffs`` (k, p+1, dim) gathered
    per point. Derivatives above the degree are zero."""
    p1 = coeffs.shape[1]
    out = []
    for nu in range(1, nmax + 1):
        if nu >= p1:
            out.append(np.zeros((coeffs.shape[0], coeffs.shape[2])))
            continue
        fac = falling(np.arange(nu, p1), nu)
        out.append(horner(coeffs[:, nu:, :] * fac[None, :, None], s))
    return out


def speed_scale(coeffs: FloatArray, h: FloatArray, nu: int = 1) -> FloatArray:
    """Size of the ``nu``-th derivative polynomial of each segment:
    ``sum_j j!/(j-nu)! |c_j| h**(j-nu)`` (an upper bound of ``|r^(nu)|`` on the segment)."""
    p1 = coeffs.shape[1]
    out = np.zeros(coeffs.shape[0])
    for j in range(nu, p1):
        out += falling(j, nu)[0] * np.sqrt(np.sum(coeffs[:, j, :] ** 2, axis=1)) * h ** (j - nu)
    return out


def frenet(r1: Sequence[FloatArray], r2: Sequence[FloatArray], r3: Sequence[FloatArray],
           scale1: FloatArray, scale2: FloatArray, *, want_torsion: bool = False,
           numerators: bool = False) -> dict[str, FloatArray]:
    """Curvature, its arc-length derivative (and torsion) from the first three derivatives.

    ``r1``, ``r2``, ``r3`` are sequences of ``dim`` component arrays of one common shape;
    ``scale1``/``scale2`` (sizes of the segment's first/second derivative polynomials, see
    :func:`speed_scale`) broadcast against it. Planar curves give the signed curvature.
    Returns ``kappa``, ``dkds``, ``speed``, ``singular`` (zero speed or a non-finite
    intermediate: ``kappa = dkds = 0`` there) and optionally ``torsion``. With
    ``numerators=True`` also the polynomial numerators: ``N = x'y'' - y'x''`` (planar only)
    and ``E`` (``dkds = E / S^6`` planar, ``E / (|r' x r''| S^6)`` in 3-D), raw.
    """
    dim = len(r1)
    s2 = r1[0] * r1[0]
    for d in range(1, dim):
        s2 = s2 + r1[d] * r1[d]
    sp = np.sqrt(s2)
    singular = sp <= SPEED_RTOL * scale1
    tors = None
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        dot12 = r1[0] * r2[0]
        for d in range(1, dim):
            dot12 = dot12 + r1[d] * r2[d]
        if dim == 2:
            num = r1[0] * r2[1] - r1[1] * r2[0]
            num1 = r1[0] * r3[1] - r1[1] * r3[0]
            kappa = num / s2 / sp
            # d kappa/ds = (N' S^2 - 3 N (r'.r'')) / S^6
            enum = num1 * s2 - 3.0 * num * dot12
            dkds = enum / (s2 * s2) / s2
        else:
            cr = _cross(r1, r2)
            cr1 = _cross(r1, r3)
            c2 = cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]
            cn = np.sqrt(c2)
            flat = cn <= CROSS_RTOL * sp * scale2
            kappa = cn / s2 / sp
            # |C|' = C.C'/|C|;  d kappa/ds = (C.C' S^2 - 3 |C|^2 (r'.r'')) / (|C| S^6)
            ccp = cr[0] * cr1[0] + cr[1] * cr1[1] + cr[2] * cr1[2]
            enum = ccp * s2 - 3.0 * c2 * dot12
            dkds = enum / cn / (s2 * s2) / s2
            dkds = np.where(flat, 0.0, dkds)
            kappa = np.where(flat, 0.0, kappa)
            if want_torsion:
                trip = cr[0] * r3[0] + cr[1] * r3[1] + cr[2] * r3[2]
                tors = np.where(flat, 0.0, trip / c2)
        bad = singular | ~np.isfinite(kappa) | ~np.isfinite(dkds)
        if tors is not None:
            bad |= ~np.isfinite(tors)
    out = {"kappa": np.where(bad, 0.0, kappa), "dkds": np.where(bad, 0.0, dkds),
           "speed": sp, "singular": bad}
    if tors is not None:
        out["torsion"] = np.where(bad, 0.0, tors)
    if numerators:
        out["E"] = enum
        if dim == 2:
            out["N"] = num
    return out


def _cross(a: Sequence[FloatArray], b: Sequence[FloatArray]) -> list[FloatArray]:
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


# -- per-segment polynomial algebra --------------------------------------------------------------
def bernstein_matrix(d: int) -> FloatArray:
    """``M`` with ``b = M q``: power coefficients ``q`` on [0, 1] -> Bernstein coefficients."""
    M = np.zeros((d + 1, d + 1))
    for i in range(d + 1):
        for k in range(i + 1):
            M[i, k] = comb(i, k) / comb(d, k)
    return M


def to_bernstein(poly: FloatArray, h: FloatArray) -> FloatArray:
    """Bernstein coefficients on [0, 1] of ``poly`` (m, d+1) in ``s in [0, h]``, ``u = s/h``.

    Works for vector-valued coefficients ``(m, d+1, dim)`` too.
    """
    d = poly.shape[1] - 1
    hp = h[:, None] ** np.arange(d + 1)[None, :]
    if poly.ndim == 3:
        q = poly * hp[:, :, None]
        return np.einsum("ik,mkd->mid", bernstein_matrix(d), q)
    return (poly * hp) @ bernstein_matrix(d).T


def taylor_shift(coeffs: FloatArray, delta: FloatArray) -> FloatArray:
    """Re-expand per-segment power coefficients ``(m, q, dim)`` about ``t_i + delta_i``."""
    q = coeffs.shape[1]
    out = np.zeros_like(coeffs)
    dl = delta[:, None]
    for j in range(q):
        acc = np.zeros((coeffs.shape[0], coeffs.shape[2]))
        for i in range(q - 1, j - 1, -1):
            acc = acc * dl + comb(i, j) * coeffs[:, i, :]
        out[:, j, :] = acc
    return out


def bounding_diagonal(pp: PiecewisePolynomial) -> float:
    """Diagonal of the bounding box of the breakpoint positions (the scale ``L``)."""
    c0 = pp.coeffs[:, 0, :]
    lo = c0.min(axis=0)
    hi = c0.max(axis=0)
    last = pp.evaluate(np.array([pp.breaks[-1]]))[0]
    lo = np.minimum(lo, last)
    hi = np.maximum(hi, last)
    return float(np.sqrt(np.sum((hi - lo) ** 2)))


def fields_to_dict(obj: object) -> dict[str, object]:
    """A dataclass's fields as a JSON-serialisable dict of plain floats/ints/bools/lists/None."""
    from dataclasses import fields

    out: dict[str, object] = {}
    for f in fields(obj):  # type: ignore[arg-type]
        v = getattr(obj, f.name)
        if isinstance(v, np.ndarray):
            out[f.name] = v.tolist()
        elif isinstance(v, (bool, np.bool_)):
            out[f.name] = bool(v)
        elif isinstance(v, (int, np.integer)):
            out[f.name] = int(v)
        elif isinstance(v, (float, np.floating)):
            out[f.name] = float(v)
        else:
            out[f.name] = v
    return out
