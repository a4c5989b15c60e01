"""Curvature, its arc-length derivative and torsion of curvefair curves at given parameters."""

from __future__ import annotations

from typing import Any

import numpy as np

from .._typing import ArrayLike
from ..errors import InputError
from ._core import check_curve, derivs_at, frenet, locate, speed_scale

__all__ = ["curvature", "curvature_derivative", "torsion"]


def _frenet_at(curve: object, u: ArrayLike, side: str, want_torsion: bool = False
               ) -> tuple[dict[str, np.ndarray], tuple[int, ...], bool]:
    c = check_curve(curve)
    seg, s, shape, scalar = locate(c, u, side)
    pp = c.piecewise
    cg = np.asarray(pp.coeffs)[seg]
    h = pp.widths[seg]
    if pp.evaluator is None:
        rr = derivs_at(cg, s, 3)
    else:  # high degree: derivatives from the curve's basis (see PiecewisePolynomial.evaluator)
        rr = [pp.at(seg, s, nu) for nu in (1, 2, 3)]
    r1, r2, r3 = (tuple(r[:, d] for d in range(c.dim)) for r in rr)
    out = frenet(r1, r2, r3, speed_scale(cg, h, 1), speed_scale(cg, h, 2),
                 want_torsion=want_torsion)
    return out, shape, scalar


def _shape(x: np.ndarray, shape: tuple[int, ...], scalar: bool) -> Any:
    x = x + 0.0  # no negative zeros
    x = x + 0.0  # no negative zeros
    return float(x[0]) if scalar else x.reshape(shape)


def curvature(curve: object, u: ArrayLike, *, side: str = "right") -> Any:
    """Curvature at parameters ``u``: signed for planar curves, unsigned (>= 0) in 3-D.

    Parameters
    ----------
    curve : PiecewiseCurve
    u : float or array_like
        Parameters in the curve's domain (closed curves wrap around periodically).
    side : {"right", "left"}
        At a breakpoint, use the segment starting there (right limit, the default) or ending
        there (left limit). Only matters where the curvature jumps (a C1 curve).

    Returns
    -------
    float or ndarray
        A float for scalar ``u``, else an array of ``u``'s shape.

    Notes
    -----
    ``kappa = (x'y'' - y'x'') / |r'|^3`` in 2-D (positive where the curve turns
    counter-clockwise), ``kappa = |r' x r''| / |r'|^3`` in 3-D.

    Zero-speed points (``|r'| <= 1e-12`` times the size of the segment's derivative
    polynomial, see :data:`curvefair.analysis._core.SPEED_RTOL`), where the curvature is
    undefined (a cusp or a stop), return ``0.0``; no NaN or inf is ever returned.

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import interpolate_cubic, curvature
    >>> a = np.linspace(0, np.pi, 41)
    >>> c = interpolate_cubic(np.c_[2 * np.cos(a), 2 * np.sin(a)])
    >>> round(curvature(c, c.params[20]), 3)      # counter-clockwise circle of radius 2
    0.5
    """
    out, shape, scalar = _frenet_at(curve, u, side)
    return _shape(out["kappa"], shape, scalar)


def curvature_derivative(curve: object, u: ArrayLike, *, side: str = "right") -> Any:
    """Derivative of the curvature with respect to arc length, ``d kappa / ds``.

    Parameters
    ----------
    curve : PiecewiseCurve
    u : float or array_like
    side : {"right", "left"}
        One-sided value at a breakpoint (``dkappa/ds`` of a C2 cubic jumps at every knot;
        the jump is the Sapidis-Farin measure used by :func:`curvefair.analyze`).

    Returns
    -------
    float or ndarray

    Notes
    -----
    Planar: with ``N = x'y'' - y'x''``, ``N' = x'y''' - y'x'''``, ``S = |r'|``:
    ``dkappa/ds = (N' S^2 - 3 N (r'.r'')) / S^6`` (derivative of the signed curvature).
    3-D: with ``C = r' x r''``, ``C' = r' x r'''``:
    ``dkappa/ds = (C.C' S^2 - 3 |C|^2 (r'.r'')) / (|C| S^6)``; where ``|C| = 0`` (zero
    curvature, where the unsigned curvature has a corner) the value is defined as 0, the mean
    of its two one-sided limits. Zero-speed points return 0 (see :func:`curvature`).

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import interpolate_cubic
    >>> from curvefair.analysis import curvature_derivative
    >>> c = interpolate_cubic([[0, 0], [1, 0], [2, 1], [3, 3]], param="uniform")
    >>> left = curvature_derivative(c, 1.0, side="left")    # a knot: kappa_s jumps there
    >>> right = curvature_derivative(c, 1.0)
    >>> bool(abs(right - left) > 0.1)
    True
    """
    out, shape, scalar = _frenet_at(curve, u, side)
    return _shape(out["dkds"], shape, scalar)


def torsion(curve: object, u: ArrayLike, *, side: str = "right") -> Any:
    """Torsion of a 3-D curve at parameters ``u``.

    Parameters
    ----------
    curve : PiecewiseCurve
        A 3-D curve (a planar curve raises :class:`~curvefair.errors.InputError`).
    u : float or array_like
    side : {"right", "left"}

    Returns
    -------
    float or ndarray

    Notes
    -----
    ``tau = (r' x r'') . r''' / |r' x r''|^2``. Undefined where the curvature vanishes
    (``|r' x r''|`` negligible) or the speed is zero; ``0.0`` is returned there.

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import interpolate_cubic, torsion
    >>> a = np.linspace(0, 4 * np.pi, 161)
    >>> c = interpolate_cubic(np.c_[np.cos(a), np.sin(a), 0.5 * a])   # helix: tau = 0.5/1.25
    >>> round(torsion(c, c.params[80]), 3)
    0.4
    """
    c = check_curve(curve)
    if c.dim != 3:
        raise InputError(f"torsion needs a 3-D curve, got a {c.dim}-D curve")
    out, shape, scalar = _frenet_at(c, u, side, want_torsion=True)
    return _shape(out["torsion"], shape, scalar)
