"""Indexed max tournament tree for ranking-list drivers (compiled with numba).

A ranking-list driver repeatedly takes the entry with the largest ranking number, changes a few
neighbouring entries, and asks again (Eck & Hadenfeld's ranking list; seed 001's "worst point"
loop). A lazy heap grows without bound under such updates; the tournament tree keeps exactly one
slot per entry: ``O(log N)`` per update, ``O(1)`` to read the maximum, no allocation after build.

Layout: ``P`` = smallest power of two >= N; leaves at ``P + i``; node ``j`` holds the larger of
its children ``2j`` and ``2j + 1`` (ties go to the smaller index, so results are deterministic).
Ineligible entries hold ``-inf``.

Examples
--------
>>> import numpy as np
>>> tv, ti = tt_build(np.array([3.0, 7.0, 1.0]))
>>> tt_top(tv, ti)
(1, 7.0)
>>> tt_update(tv, ti, 1, -np.inf)
>>> tt_top(tv, ti)
(0, 3.0)
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["tt_build", "tt_update", "tt_top", "tt_value"]


@njit(cache=True, inline="always")
def _better(v1: float, i1: int, v2: float, i2: int) -> bool:
    # v1 wins over v2; ties (and both -inf) go to the smaller valid index
    if v1 > v2:
        return True
    if v1 < v2:
        return False
    if i2 < 0:
        return True
    if i1 < 0:
        return False
    return i1 <= i2


@njit(cache=True)
def tt_build(values):  # type: ignore[no-untyped-def]
    """Build the tree over ``values`` (float64, shape (N,)); returns ``(tv, ti)``."""
    n = values.shape[0]
    p = 1
    while p < n:
        p *= 2
    tv = np.full(2 * p, -np.inf)
    ti = np.full(2 * p, -1, dtype=np.int64)
    for i in range(n):
        tv[p + i] = values[i]
        ti[p + i] = i
    for j in range(p - 1, 0, -1):
        a = 2 * j
        b = a + 1
        if _better(tv[a], ti[a], tv[b], ti[b]):
            tv[j] = tv[a]
            ti[j] = ti[a]
        else:
            tv[j] = tv[b]
            ti[j] = ti[b]
    return tv, ti


@njit(cache=True)
def tt_update(tv, ti, i, value):  # type: ignore[no-untyped-def]
    """Set entry ``i`` to ``value`` and repair the path to the root (``O(log N)``)."""
    p = tv.shape[0] // 2
    j = p + i
    tv[j] = value
    j //= 2
    while j >= 1:
        a = 2 * j
        b = a + 1
        if _better(tv[a], ti[a], tv[b], ti[b]):
            tv[j] = tv[a]
            ti[j] = ti[a]
        else:
            tv[j] = tv[b]
            ti[j] = ti[b]
        j //= 2


@njit(cache=True)
def tt_top(tv, ti):  # type: ignore[no-untyped-def]
    """``(index, value)`` of the largest entry (index -1 if the tree is empty)."""
    return ti[1], tv[1]


@njit(cache=True)
def tt_value(tv, i):  # type: ignore[no-untyped-def]
    """Current value of entry ``i``."""
    return tv[tv.shape[0] // 2 + i]
