"""The one formula for the distance a data point moved, shared by the fairing guard and reports.

The tolerance promise of :func:`curvefair.fair` is ``|moved_i - original_i| <= tol`` evaluated
in float64. Near the tolerance sphere the last bit of that distance depends on how it is
evaluated (``np.linalg.norm`` of a row uses a dot product, of an ``(n, dim)`` array a sum of
squares; ``math.dist`` is more accurate), so :func:`point_distances` is the formula every report
prints (the row-wise sum of squares of ``np.linalg.norm(d, axis=-1)``, compiled) and
:func:`exceeds` checks all the usual ones: a point passes only if none of them exceeds ``tol``.
"""

from __future__ import annotations

import math

import numpy as np

from ._typing import FloatArray

__all__ = ["point_distances", "exceeds"]

# rows whose reported distance is within this relative margin of tol are also checked with the
# per-row formulas (they differ from the vectorised one by a few ulp of the distance at most)
_NEAR = 64.0 * np.finfo(float).eps


def point_distances(moved: FloatArray, original: FloatArray) -> FloatArray:
    """``np.linalg.norm(moved - original, axis=-1)``: per-point Euclidean distance in float64.

    ``moved``, ``original``: arrays of shape ``(n, dim)`` (or ``(dim,)``). This is the value
    reported as a point's displacement (``max_point_displacement``, ``moved.displacement``).
    """
    m = np.asarray(moved, dtype=np.float64)
    o = np.asarray(original, dtype=np.float64)
    if m.ndim != 2 or m.shape != o.shape or not 1 <= m.shape[1] <= 7:
        return np.linalg.norm(m - o, axis=-1)
    # compiled: the same operations in the same order (squares summed left to right, as
    # numpy's reduction of a row of at most 7 does), without numpy's three temporaries
    from ._kernels.deviation import point_distances_kernel

    out = np.empty(m.shape[0])
    point_distances_kernel(np.ascontiguousarray(m), np.ascontiguousarray(o), out)
    return out


def _row_exceeds(m: FloatArray, o: FloatArray, tol: float) -> bool:
    d = m - o
    return bool(np.linalg.norm(d) > tol or math.dist(m.tolist(), o.tolist()) > tol
                or float(np.linalg.norm(d[None, :], axis=-1)[0]) > tol
                or math.sqrt(float(np.dot(d, d))) > tol
                or math.sqrt(math.fsum(float(v) * float(v) for v in d)) > tol)


def exceeds(moved: FloatArray, original: FloatArray, tol: float) -> np.ndarray:
    """Boolean mask of the rows farther than ``tol`` from the original by ANY usual formula.

    The vectorised :func:`point_distances` decides for every row; rows within a few ulp of
    ``tol`` are also checked one by one with ``np.linalg.norm(row)`` (a dot product),
    ``math.dist`` and the correctly summed ``fsum`` of squares, so whichever of them a user
    evaluates, a row reported inside ``tol`` is inside.
    """
    m = np.asarray(moved, dtype=np.float64)
    o = np.asarray(original, dtype=np.float64)
    d = point_distances(m, o)
    out = d > tol
    near = np.flatnonzero(~out & (d > tol * (1.0 - _NEAR)))
    for i in near.tolist():
        out[i] = _row_exceeds(m[i], o[i], tol)
    return out
