"""Compiled kernel of the corner search of the point-list readers
(:func:`curvefair.io._common.corner_turning`): :func:`chord_turns_kernel`, the turning angle at
every point between the chords to the nearest points at least a given length away, which
measures a noisy list's turns at the scale of its noise; :func:`chord_turns_reference` is the
same search by a plain Python walk, the slow reference the kernel is tested against.
"""

from __future__ import annotations

import numpy as np

from .._jit import njit
from .._typing import FloatArray


@njit(cache=True)
def chord_turns_kernel(p, closed, Lmin, out):
    """Fill ``out`` (NaN on entry) for :func:`curvefair.io._common._chord_turns`: from every
    point ``i`` walk back and forth to the first point ``k`` with ``|p_k - p_i| >= Lmin`` (at
    most ``m // 2`` steps; an open list's ends stop the walk), then
    ``angle = arccos(a . b / (|a| |b|))`` of the chords ``a = p_i - p_back``,
    ``b = p_fwd - p_i``, clipped to [-1, 1]; sums in coordinate order (no fastmath)."""
    m, dim = p.shape
    lo, hi = (0, m) if closed else (1, m - 1)
    lim = m // 2 + 1
    for i in range(lo, hi):
        back = fwd = -1
        for e in range(2):
            step = -1 if e == 0 else 1
            k = i + step
            n_steps = 1
            found = -1
            while n_steps < lim:
                if not closed and (k < 0 or k >= m):
                    break
                kk = k % m
                d2 = 0.0
                for c in range(dim):
                    t = p[kk, c] - p[i, c]
                    d2 += t * t
                if np.sqrt(d2) >= Lmin:
                    found = kk
                    break
                k += step
                n_steps += 1
            if e == 0:
                back = found
            else:
                fwd = found
        if back < 0 or fwd < 0:
            continue
        ab = 0.0
        aa = 0.0
        bb = 0.0
        for c in range(dim):
            a = p[i, c] - p[back, c]
            b = p[fwd, c] - p[i, c]
            ab += a * b
            aa += a * a
            bb += b * b
        cosv = ab / (np.sqrt(aa) * np.sqrt(bb))
        cosv = min(1.0, max(-1.0, cosv))
        out[i] = np.degrees(np.arccos(cosv))


def chord_turns_reference(p: FloatArray, closed: bool, Lmin: float) -> FloatArray:
    """:func:`curvefair.io._common._chord_turns` by a plain Python walk (numpy norms and dot
    products per point): the slow reference :func:`chord_turns_kernel` is tested against."""
    m = p.shape[0]
    out = np.full(m, np.nan)
    idx = range(m) if closed else range(1, m - 1)
    for i in idx:
        ends = []
        for step in (-1, 1):
            k, n_steps, found = i + step, 1, False
            while n_steps < m // 2 + 1:
                if not closed and not 0 <= k < m:
                    break
                if np.linalg.norm(p[k % m] - p[i]) >= Lmin:
                    found = True
                    break
                k += step
                n_steps += 1
            ends.append(k % m if found else -1)
        if ends[0] < 0 or ends[1] < 0:
            continue
        a, b = p[i] - p[ends[0]], p[ends[1]] - p[i]
        na, nb = float(np.linalg.norm(a)), float(np.linalg.norm(b))
        out[i] = np.degrees(np.arccos(np.clip(float(a @ b) / (na * nb), -1.0, 1.0)))
    return out
