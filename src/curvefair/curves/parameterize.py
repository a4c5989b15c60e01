"""Parameterisation of data points: uniform, chord length, centripetal, or explicit."""

from __future__ import annotations

import numpy as np

from .._typing import ArrayLike, FloatArray
from .._validate import as_params, as_points, choice

__all__ = ["parameterize", "PARAM_NAMES"]

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
    pts = as_points(points, "points", min_points=2)
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
