"""Distinct-data layout of Hermite splines used by the steps and the fairing drivers."""

from __future__ import annotations

import numpy as np

from .._typing import FloatArray
from ..curves.hermite import CubicHermite, HermiteSpline, QuinticHermite

__all__ = ["distinct_data", "distinct_derivatives", "distinct_points", "full_data", "rebuild",
           "uniform_spacing"]


def distinct_points(curve: HermiteSpline) -> tuple[FloatArray, FloatArray]:
    """``(P, h)`` of :func:`distinct_data`: the distinct points (a fresh writable copy) and
    the segment widths."""
    pts = np.array(curve.points, dtype=np.float64)
    h = np.diff(np.asarray(curve.params, dtype=np.float64))
    if curve.closed:
        pts = pts[:-1]
    return np.ascontiguousarray(pts), np.ascontiguousarray(h)


def distinct_derivatives(curve: HermiteSpline) -> list[FloatArray]:
    """The derivative data of the distinct points, one ``(nd, dim)`` array per order: views of
    the curve's own (read-only) arrays, no copy."""
    ders = [np.asarray(d) for d in curve._derivs]
    return [d[:-1] for d in ders] if curve.closed else ders


def distinct_data(curve: HermiteSpline) -> tuple[FloatArray, FloatArray, FloatArray]:
    """``(P, D, h)``: distinct points ``(nd, dim)``, derivatives ``(nd, nb, dim)``, widths.

    A closed curve drops its repeated last point; its segment widths include the closing one.
    Arrays are fresh writable copies.
    """
    P, h = distinct_points(curve)
    D = np.ascontiguousarray(np.stack(distinct_derivatives(curve), axis=1), dtype=np.float64)
    return P, D, h


def full_data(curve: HermiteSpline, P: FloatArray, D: FloatArray
              ) -> tuple[FloatArray, FloatArray]:
    """Distinct data ``P``, ``D`` laid out as ``curve``'s arrays: the seam repeated if closed."""
    if curve.closed:
        return np.vstack([P, P[:1]]), np.concatenate([D, D[:1]], axis=0)
    return P, D


def rebuild(curve: HermiteSpline, P: FloatArray, D: FloatArray) -> HermiteSpline:
    """A curve like ``curve`` with distinct data ``P``, ``D`` (the seam is repeated if closed)."""
    P, D = full_data(curve, P, D)
    if isinstance(curve, QuinticHermite):
        return QuinticHermite(P, D[:, 0], D[:, 1], curve.params, closed=curve.closed)
    return CubicHermite(P, D[:, 0], curve.params, closed=curve.closed)


def uniform_spacing(params: FloatArray, rtol: float = 1e-9) -> float | None:
    """The common spacing of ``params`` if they are uniform (to ``rtol``), else None."""
    h = np.diff(np.asarray(params, dtype=np.float64))
    if h.size == 0:
        return None
    hm = float(h.mean())
    if np.all(np.abs(h - hm) <= rtol * abs(hm)):
        return hm
    return None
