"""Power form of cubic and quintic Hermite data: one compiled pass, no temporaries.

The coefficients are those of seed 001 eq. (6) (cubic) and seed 000 eq. (2) (quintic); the
docstrings of :class:`curvefair.CubicHermite` and :class:`curvefair.QuinticHermite` state them.
Each segment's coefficients are computed with the operations of the vectorised numpy
formulas below (``*_reference``) in the same order; ``D**3`` and the higher powers go through
the C library's ``pow`` (correctly rounded in glibc), ``D**2`` is ``D * D``. numpy's own
array ``power`` is dispatched to SIMD code on some CPUs (on AVX-512 it was measured up to 0.64
ulp from the exact cube, against 0.5 for ``pow``), so the numpy formulas differ from these in
the last bit of some cubic and higher terms, by CPU: the compiled pass gives the same numbers
on every machine.

Why compiled: the numpy form makes about ten temporaries of the data's size; at 1e7 points
those are gigabytes of fresh memory per call, paid in page faults (27x the time of 1e6
points for 10x the data, docs/benchmarks.md). The pass writes each coefficient once.
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import njit


@njit(cache=True, inline="always")
def _widths(t, i):  # pragma: no cover - compiled
    """``D = t[i + 1] - t[i]``, ``D * D`` and ``pow(D, 3)``."""
    D = t[i + 1] - t[i]
    return D, D * D, math.pow(D, 3.0)


@njit(cache=True, inline="always")
def _cubic_row(p, m, t, i, out, r):  # pragma: no cover - compiled
    """Segment ``i``'s coefficients into ``out[r]`` (the one place the formula is written)."""
    D, D2, D3 = _widths(t, i)
    for d in range(out.shape[2]):
        dp = p[i + 1, d] - p[i, d]
        out[r, 0, d] = p[i, d]
        out[r, 1, d] = m[i, d]
        out[r, 2, d] = 3.0 * dp / D2 - (2.0 * m[i, d] + m[i + 1, d]) / D
        out[r, 3, d] = -2.0 * dp / D3 + (m[i, d] + m[i + 1, d]) / D2


@njit(cache=True, nogil=True, readonly=('p', 'm', 't'))
def cubic_power_kernel(p, m, t, out):  # pragma: no cover - compiled
    """``out[i, j, d]`` (shape ``(n - 1, 4, dim)``) from points ``p``, tangents ``m`` and
    parameters ``t`` (``n`` of each)."""
    for i in range(out.shape[0]):
        _cubic_row(p, m, t, i, out, i)


@njit(cache=True, nogil=True, readonly=('p', 'm', 't', 'idx'))
def cubic_power_rows(p, m, t, idx, out):  # pragma: no cover - compiled
    """``out[r]`` = the coefficients of segment ``idx[r]`` (:func:`cubic_power_kernel`'s row,
    bit for bit: the same inlined code), for a few segments of a long curve."""
    for r in range(idx.shape[0]):
        _cubic_row(p, m, t, idx[r], out, r)


@njit(cache=True, inline="always")
def _quintic_row(p, m, s, t, i, out, r):  # pragma: no cover - compiled
    """Segment ``i``'s coefficients into ``out[r]`` (the one place the formula is written)."""
    D, D2, D3 = _widths(t, i)
    D4 = math.pow(D, 4.0)
    D5 = math.pow(D, 5.0)
    for d in range(out.shape[2]):
        b1 = p[i + 1, d] - p[i, d] - m[i, d] * D - 0.5 * s[i, d] * D2
        b2 = m[i + 1, d] - m[i, d] - s[i, d] * D
        b3 = s[i + 1, d] - s[i, d]
        out[r, 0, d] = p[i, d]
        out[r, 1, d] = m[i, d]
        out[r, 2, d] = 0.5 * s[i, d]
        out[r, 3, d] = (10.0 * b1 - 4.0 * b2 * D + 0.5 * b3 * D2) / D3
        out[r, 4, d] = (-15.0 * b1 + 7.0 * b2 * D - b3 * D2) / D4
        out[r, 5, d] = (6.0 * b1 - 3.0 * b2 * D + 0.5 * b3 * D2) / D5


@njit(cache=True, nogil=True, readonly=('p', 'm', 's', 't'))
def quintic_power_kernel(p, m, s, t, out):  # pragma: no cover - compiled
    """``out[i, j, d]`` (shape ``(n - 1, 6, dim)``) from points ``p``, first and second
    derivatives ``m``, ``s`` and parameters ``t``."""
    for i in range(out.shape[0]):
        _quintic_row(p, m, s, t, i, out, i)


@njit(cache=True, nogil=True, readonly=('p', 'm', 's', 't', 'idx'))
def quintic_power_rows(p, m, s, t, idx, out):  # pragma: no cover - compiled
    """``out[r]`` = the coefficients of segment ``idx[r]`` (:func:`quintic_power_kernel`'s row,
    bit for bit)."""
    for r in range(idx.shape[0]):
        _quintic_row(p, m, s, t, idx[r], out, r)


def cubic_power_reference(p: np.ndarray, m: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Seed 001 eq. (6), vectorised numpy: ``(n-1, 4, dim)``."""
    D = np.diff(t)[:, None]
    dp = p[1:] - p[:-1]
    c = np.empty((p.shape[0] - 1, 4, p.shape[1]))
    c[:, 0] = p[:-1]
    c[:, 1] = m[:-1]
    c[:, 2] = 3.0 * dp / D**2 - (2.0 * m[:-1] + m[1:]) / D
    c[:, 3] = -2.0 * dp / D**3 + (m[:-1] + m[1:]) / D**2
    return c


def quintic_power_reference(p: np.ndarray, m: np.ndarray, s: np.ndarray,
                            t: np.ndarray) -> np.ndarray:
    """Seed 000 eq. (2), vectorised numpy: ``(n-1, 6, dim)``."""
    D = np.diff(t)[:, None]
    b1 = p[1:] - p[:-1] - m[:-1] * D - 0.5 * s[:-1] * D**2
    b2 = m[1:] - m[:-1] - s[:-1] * D
    b3 = s[1:] - s[:-1]
    c = np.empty((p.shape[0] - 1, 6, p.shape[1]))
    c[:, 0] = p[:-1]
    c[:, 1] = m[:-1]
    c[:, 2] = 0.5 * s[:-1]
    c[:, 3] = (10.0 * b1 - 4.0 * b2 * D + 0.5 * b3 * D**2) / D**3
    c[:, 4] = (-15.0 * b1 + 7.0 * b2 * D - b3 * D**2) / D**4
    c[:, 5] = (6.0 * b1 - 3.0 * b2 * D + 0.5 * b3 * D**2) / D**5
    return c
