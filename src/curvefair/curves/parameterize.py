"""Parameterisation of data points: uniform, chord length, centripetal, or explicit."""

from __future__ import annotations

import numpy as np

from .._typing import ArrayLike, FloatArray
from .._validate import as_params, as_points, choice, magnitude
from ..errors import InputError

__all__ = ["parameterize", "closed_point_data", "PARAM_NAMES"]

PARAM_NAMES = ("uniform", "chord", "centripetal")


def parameterize(points: ArrayLike, param: str | ArrayLike = "chord") -> FloatArray:
    """Parameter values for ``points``.

    Parameters
    ----------
    points : array_like, shape (n, dim)
    param : {"uniform", "chord", "centripetal"} or array_like of shape (n,)
        ``"uniform"``: ``t_i = i`` (unit spacing, as Kjellander assumes);
        ``"chord"``: cumulative chord length (``t_0 = 0``);
        ``"centripetal"``: cumulative square root of chord length (Lee 1989);
        an array is validated (finite, strictly increasing) and returned as float64.

    Returns
    -------
    ndarray, shape (n,)

    Examples
    --------
    >>> parameterize([[0, 0], [3, 4], [3, 5]], "chord").tolist()
    [0.0, 5.0, 6.0]
    """
    return _parameterize_valid(as_points(points, "points", min_points=2), param)


def _parameterize_valid(pts: FloatArray, param: str | ArrayLike) -> FloatArray:
    """:func:`parameterize` of points that ``as_points(..., min_points=2)`` accepted."""
    n = pts.shape[0]
    if not isinstance(param, str):
        return as_params(param, n, "param")
    choice(param, PARAM_NAMES, "param")
    if param == "uniform":
        return np.arange(n, dtype=float)
    chords = np.sqrt(np.sum(np.diff(pts, axis=0) ** 2, axis=1))
    if param == "centripetal":
        chords = np.sqrt(chords)
    t = np.empty(n)
    t[0] = 0.0
    np.cumsum(chords, out=t[1:])
    return t


def closed_point_data(points: ArrayLike, param: str | ArrayLike
                      ) -> tuple[FloatArray, FloatArray]:
    """The data of a closed curve through ``points``: the distinct points (a repeated first
    point, within 1e-12 of the coordinate size, dropped) and their parameters plus the closing
    one (``param``: a name of :data:`PARAM_NAMES`, or ``len(distinct) + 1`` values).

    Raises
    ------
    InputError
        Fewer than 3 points, or given parameters of another length.
    """
    pts = as_points(points, "points", min_points=3)
    scale = magnitude(pts)
    if np.allclose(pts[0], pts[-1], rtol=0.0, atol=1e-12 * scale):
        pts = pts[:-1]
    loop = np.vstack([pts, pts[:1]])
    if isinstance(param, str):
        t = parameterize(loop, param)
    else:
        t = np.asarray(param, dtype=float)
        if t.shape != (loop.shape[0],):
            raise InputError(f"param for a closed curve needs {loop.shape[0]} values (one per "
                             f"distinct point plus the closing one), got shape {t.shape}")
        t = parameterize(loop, t)
    return pts, t
