"""Interpolating splines through data points: C2 cubic and C4 quintic.

Both return Hermite splines (:class:`~curvefair.CubicHermite`, :class:`~curvefair.QuinticHermite`)
whose per-point derivatives are those of the interpolating spline, so the local fairing steps of
seeds 000 and 001 apply directly.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy.interpolate import CubicSpline, make_interp_spline

from .._typing import ArrayLike, FloatArray
from .._validate import as_points, as_vectors, choice
from ..errors import InputError
from .hermite import CubicHermite, QuinticHermite
from .parameterize import parameterize

__all__ = ["interpolate_cubic", "interpolate_quintic", "BC_NAMES"]

BC_NAMES = ("natural", "clamped", "not-a-knot", "periodic")

# An end condition, as accepted in a (left, right) pair:
#   "natural", "not-a-knot", or (order, vector) with order 1 (given tangent) or 2 (given second
#   derivative) -- the same convention as scipy's ``bc_type``.
EndCondition = Any


def _close_points(pts: FloatArray) -> FloatArray:
    """Repeat the first point last unless it is already there."""
    scale = max(float(np.abs(pts).max()), 1.0)
    if np.allclose(pts[0], pts[-1], rtol=0.0, atol=1e-12 * scale):
        pts = pts.copy()
        pts[-1] = pts[0]
        return pts
    return np.vstack([pts, pts[:1]])


def _prepare(points: ArrayLike, param: Any, bc: Any, min_points: int
             ) -> tuple[FloatArray, FloatArray, bool]:
    periodic = isinstance(bc, str) and bc == "periodic"
    pts = as_points(points, "points", min_points=min_points)
    if periodic:
        pts = _close_points(pts)
        if pts.shape[0] < 4:
            raise InputError("a periodic (closed) curve needs at least 3 distinct points")
        if isinstance(param, str):
            t = parameterize(pts, param)
        else:
            t = np.asarray(param, dtype=float)
            if t.shape == (pts.shape[0] - 1,):
                raise InputError(
                    "param for a closed curve needs one value per point plus one for the closing "
                    f"point ({pts.shape[0]} values)")
            t = parameterize(pts, t)
    else:
        t = parameterize(pts, param)
    return pts, t, periodic


def _end_condition(spec: Any, which: str, dim: int, natural_orders: tuple[int, ...],
                   end_tangent: FloatArray | None) -> Any:
    """Translate one end's condition into scipy's (order, value) list form."""
    if isinstance(spec, str):
        choice(spec, ("natural", "clamped", "not-a-knot"), f"bc ({which} end)")
        if spec == "natural":
            return [(o, np.zeros(dim)) for o in natural_orders]
        if spec == "clamped":
            if end_tangent is None:
                raise InputError(f'bc="clamped" needs end_tangents=(left, right) ({which} end)')
            if len(natural_orders) == 1:
                return [(1, end_tangent)]
            return [(1, end_tangent), (3, np.zeros(dim))]
        return "not-a-knot"
    try:
        order, value = spec
        order = int(order)
    except (TypeError, ValueError):
        raise InputError(
            f"bc ({which} end) must be 'natural', 'clamped', 'not-a-knot' or (order, vector), "
            f"got {spec!r}") from None
    if order not in (1, 2):
        raise InputError(f"bc ({which} end): derivative order must be 1 or 2, got {order}")
    vec = as_vectors(value, (dim,), f"bc ({which} end) vector")
    if len(natural_orders) == 1:
        return [(order, vec)]
    # quintic: a given derivative plus the natural condition that completes it
    extra = {1: 3, 2: 4}[order]  # the natural complement of the given derivative
    return [(order, vec), (extra, np.zeros(dim))]


def _bc_pair(bc: Any, dim: int, natural_orders: tuple[int, ...],
             end_tangents: ArrayLike | None) -> tuple[Any, Any]:
    tangents: list[FloatArray | None] = [None, None]
    if end_tangents is not None:
        et = as_vectors(end_tangents, (2, dim), "end_tangents")
        tangents = [et[0], et[1]]
    if isinstance(bc, str):
        choice(bc, BC_NAMES, "bc")
        left = right = bc
    else:
        try:
            left, right = bc
        except (TypeError, ValueError):
            raise InputError(f"bc must be one of {BC_NAMES} or a (left, right) pair, got {bc!r}"
                             ) from None
    return (_end_condition(left, "left", dim, natural_orders, tangents[0]),
            _end_condition(right, "right", dim, natural_orders, tangents[1]))


def interpolate_cubic(points: ArrayLike, param: str | ArrayLike = "chord", bc: Any = "natural",
                      *, end_tangents: ArrayLike | None = None) -> CubicHermite:
    """C2 interpolating parametric cubic spline, returned as a :class:`CubicHermite`.

    Parameters
    ----------
    points : array_like, shape (n, dim)
        Data points, dim 2 or 3, no two consecutive points equal.
    param : {"uniform", "chord", "centripetal"} or array_like, shape (n,)
        Parameterisation (see :func:`curvefair.parameterize`).
    bc : str or (left, right)
        ``"natural"`` (zero second derivative at both ends, the papers' choice),
        ``"clamped"`` (given end tangents, ``end_tangents=(left, right)``), ``"not-a-knot"``,
        ``"periodic"`` (closed curve; the first point is repeated last unless it already is).
        A pair sets each end on its own: each is ``"natural"``, ``"not-a-knot"``, ``"clamped"``,
        ``(1, tangent)`` or ``(2, second_derivative)``.
    end_tangents : array_like, shape (2, dim), optional
        Tangents for ``"clamped"`` ends.

    Returns
    -------
    CubicHermite
        ``.tangents`` are the spline's first derivatives at the data points.

    Notes
    -----
    The tangents solve the usual tridiagonal C2 system (scipy's ``CubicSpline``); the Hermite
    form is then exactly the interpolating spline.

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import interpolate_cubic
    >>> pts = np.column_stack([np.arange(1.0, 8.0), np.ones(7)])
    >>> pts[3] = (4.3, 1.6)            # Wang & Cao 2006, Example 1
    >>> c = interpolate_cubic(pts)
    >>> c.degree, c.points.shape
    (3, (7, 2))
    """
    pts, t, periodic = _prepare(points, param, bc, min_points=2)
    if periodic:
        spl = CubicSpline(t, pts, bc_type="periodic", axis=0)
    else:
        left, right = _bc_pair(bc, pts.shape[1], (2,), end_tangents)
        scipy_bc = tuple("not-a-knot" if c == "not-a-knot" else c[0] for c in (left, right))
        if pts.shape[0] < 4 and "not-a-knot" in scipy_bc and scipy_bc != ("not-a-knot",) * 2:
            raise InputError("a not-a-knot end needs at least 4 points unless both ends are not-a-knot")
        spl = CubicSpline(t, pts, bc_type=scipy_bc, axis=0)
    tangents = spl(t, 1)
    if periodic:
        tangents[-1] = tangents[0]
    return CubicHermite(pts, tangents, t, closed=periodic)


def interpolate_quintic(points: ArrayLike, param: str | ArrayLike = "chord", bc: Any = "natural",
                        *, end_tangents: ArrayLike | None = None) -> QuinticHermite:
    """C4 interpolating parametric quintic spline, returned as a :class:`QuinticHermite`.

    Parameters
    ----------
    points : array_like, shape (n, dim)
    param : as for :func:`interpolate_cubic`.
    bc : str or (left, right)
        ``"natural"``: ``r''' = r'''' = 0`` at both ends -- the natural end conditions of the
        quintic spline that minimises the jerk energy ``int |r'''|^2 dt`` among C2 interpolants.
        ``"clamped"``: given end tangent and ``r''' = 0`` (the natural complement).
        ``"not-a-knot"`` (needs n >= 6), ``"periodic"`` (closed).
        A pair per end: ``"natural"``, ``"clamped"``, ``"not-a-knot"``, ``(1, tangent)`` or
        ``(2, second_derivative)``. A given tangent is completed by ``r''' = 0`` and a given second
        derivative by ``r'''' = 0`` (the variational natural complements).
    end_tangents : array_like, shape (2, dim), optional

    Returns
    -------
    QuinticHermite
        With ``d1``, ``d2`` the spline's first and second derivatives at the data points.

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import interpolate_quintic
    >>> q = interpolate_quintic(np.c_[np.cos(np.linspace(0, 3, 9)), np.sin(np.linspace(0, 3, 9))])
    >>> q.degree
    5
    """
    pts, t, periodic = _prepare(points, param, bc, min_points=2)
    n, dim = pts.shape
    if periodic:
        spl = make_interp_spline(t, pts, k=5, bc_type="periodic", axis=0)
    else:
        left, right = _bc_pair(bc, dim, (3, 4), end_tangents)
        if left == "not-a-knot" or right == "not-a-knot":
            if left != right:
                raise InputError("for quintic splines, not-a-knot must be used at both ends")
            if n < 6:
                raise InputError(f"a not-a-knot quintic spline needs at least 6 points, got {n}")
            spl = make_interp_spline(t, pts, k=5, bc_type=None, axis=0)
        else:
            spl = make_interp_spline(t, pts, k=5, bc_type=(left, right), axis=0)
    d1 = spl(t, 1)
    d2 = spl(t, 2)
    if periodic:
        d1[-1] = d1[0]
        d2[-1] = d2[0]
    return QuinticHermite(pts, d1, d2, t, closed=periodic)
