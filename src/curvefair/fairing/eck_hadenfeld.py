"""Eck & Hadenfeld local energy fairing of B-spline curves (seed 003) and its ranking list.

One step moves one control point ``d_r`` to the minimiser of the energy
``E_l = int |x^(l)(t)|^2 dt`` (``l = 2`` or ``3``) with every other control point held
(seed 003, eqs. (12)-(16)). The automatic method (:func:`eck_hadenfeld_fair`, registered as
``"eck-hadenfeld"`` in :func:`curvefair.fair`) is the ranking list described in ERRATA: always fair
the control point whose move lowers the energy most, recompute only the ``2p + 1`` neighbours,
keep every control point within ``tol`` of its ORIGINAL position. ``schedule="sweep"`` takes the
same steps in Gauss-Seidel order instead (every point above the threshold in turn, then the
neighbours of the moved ones), with the same stopping test: faster on large curves and, on
noisy data, as fair or fairer at the same threshold.

Indices are 0-based (the paper writes ``d_0 .. d_n`` with order ``k = p + 1``; its ``2k - 1``
neighbours are our ``2p + 1``).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from .._jit import njit, prefetch
from .._kernels.bspline import band_energy, band_residual, energy_row, residual_row
from .._typing import FloatArray
from .._validate import as_step_count, check_finite, choice, parse_clamp
from ..curves.bspline import BSplineCurve
from ..errors import InputError
from .stop import StopReason

if TYPE_CHECKING:
    from .problem import FairingProblem, Outcome

__all__ = [
    "eck_hadenfeld",
    "eh_weights",
    "ranking_numbers",
    "eck_hadenfeld_fair",
    "EHResult",
    "movable_mask",
]

STOP_REASONS: dict[int, StopReason] = {0: "converged", 1: "max_steps", 2: "no_movable_point"}


# ------------------------------------------------------------------------------------------
# argument checks shared by the B-spline methods
# ------------------------------------------------------------------------------------------
def check_bspline(curve: object, name: str = "curve") -> BSplineCurve:
    if not isinstance(curve, BSplineCurve):
        raise InputError(f"{name} must be a BSplineCurve, got {type(curve).__name__}")
    return curve


def check_l(l: object, degree: int) -> int:  # noqa: E741
    if isinstance(l, bool) or not isinstance(l, (int, np.integer)) or int(l) not in (2, 3):
        raise InputError(f"l must be 2 or 3, got {l!r}")
    if int(l) > degree:
        raise InputError(f"l = {l} needs degree >= {l}, the curve has degree {degree}")
    return int(l)


def check_index(i: object, n: int, name: str) -> int:
    if isinstance(i, bool) or not isinstance(i, (int, np.integer)):
        raise InputError(f"{name} must be an integer index, got {i!r}")
    if not 0 <= int(i) < n:
        raise InputError(f"{name} = {i} is out of range [0, {n - 1}]")
    return int(i)


SCHEDULES = ("ranking", "sweep")


def check_schedule(schedule: object) -> str:
    """``"ranking"`` or ``"sweep"`` (any case)."""
    if isinstance(schedule, str) and schedule.lower() in SCHEDULES:
        return schedule.lower()
    return choice(schedule, SCHEDULES, "schedule")


def movable_mask(curve: BSplineCurve, clamp: Any = (None, None),
                 protect: Iterable[int] = ()) -> np.ndarray:
    """Boolean mask of the control points a method may move.

    ``clamp = (left, right)`` in the grammar of :func:`curvefair._validate.parse_clamp`, each
    ``None``/``"none"`` or ``"g0"``, ``"g1"``, ``"g2"`` (any case): fix 0, 1, 2, 3 end control
    points, which keeps position, tangent, curvature at that end of a clamped B-spline (ERRATA,
    Eck & Hadenfeld: fixing ``m + 1`` points keeps ``C^m`` contact). A single string applies to
    both ends. Closed curves have no ends: the clamp is ignored.
    ``protect``: control-point indices that never move.
    """
    from .problem import fixed_mask

    n = curve.n_ctrl
    prot = [check_index(i, n, "protect index") for i in protect]
    return ~fixed_mask(curve, parse_clamp(clamp), prot)


# ------------------------------------------------------------------------------------------
# one step
# ------------------------------------------------------------------------------------------
def _neighbours(curve: BSplineCurve, r: int) -> tuple[np.ndarray, np.ndarray]:
    """Control indices ``i`` of the band row ``r`` and their column in the band."""
    p = curve.degree
    n = curve.n_ctrl
    off = np.arange(-p, p + 1)
    i = r + off
    if curve.closed:
        return i % n, off + p
    keep = (i >= 0) & (i < n)
    return i[keep], (off + p)[keep]


def eh_weights(curve: BSplineCurve, r: int,
               l: int = 2) -> tuple[np.ndarray, FloatArray]:  # noqa: E741
    """Weights ``gamma_i`` of the Eck-Hadenfeld control point ``d~_r = sum_{i != r} gamma_i d_i``.

    Parameters
    ----------
    curve : BSplineCurve
    r : int
        0-based control point index.
    l : {2, 3}
        Derivative in the energy ``E_l``.

    Returns
    -------
    indices : int ndarray
        The neighbours ``i != r`` (at most ``2 degree``; cyclic for closed curves).
    gamma : ndarray
        Their weights; they sum to 1 (seed 003 eq. (16)).

    Notes
    -----
    Eck & Hadenfeld, eqs. (14)-(15): ``gamma_i = - G_ri / G_rr`` with the exact Gram integrals
    ``G_ij = int N_i^(l) N_j^(l) dt`` over the curve's domain (ERRATA: over the whole domain).

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import BSplineCurve
    >>> from curvefair.fairing.eck_hadenfeld import eh_weights
    >>> c = BSplineCurve(np.zeros((12, 2)), np.arange(13.0), 3, closed=True)
    >>> idx, g = eh_weights(c, 5, l=2)
    >>> idx.tolist(), (g * 16).round(12).tolist()
    ([2, 3, 4, 6, 7, 8], [-1.0, 0.0, 9.0, 9.0, 0.0, -1.0])
    """
    curve = check_bspline(curve)
    lv = check_l(l, curve.degree)
    r = check_index(r, curve.n_ctrl, "r")
    W = curve.gram_band(lv)
    idx, col = _neighbours(curve, r)
    gamma: dict[int, float] = {}
    for i, c in zip(idx.tolist(), col.tolist(), strict=True):
        if c == curve.degree:
            continue
        gamma[i] = gamma.get(i, 0.0) - W[r, c] / W[r, curve.degree]
    n = curve.n_ctrl
    # ascending index; closed curves: ascending signed cyclic offset from r
    keys = sorted(gamma, key=(lambda i: (i - r + n // 2) % n) if curve.closed else None)
    return np.array(keys, dtype=np.int64), np.array([gamma[i] for i in keys])


def _residual(curve: BSplineCurve, W: FloatArray) -> FloatArray:
    """``g = G d`` (per coordinate) from the band, compiled, in difference form (accurate for
    large coordinates, see :func:`curvefair._kernels.bspline.band_residual`): shape (n, dim)."""
    d = np.ascontiguousarray(curve.control_points)
    g = np.empty_like(d)
    band_residual(np.ascontiguousarray(W), curve.degree, curve.closed, d, g)
    return g


def _energy(curve: BSplineCurve, W: FloatArray) -> float:
    """``E_l = d^T G d`` in difference form (:func:`curvefair._kernels.bspline.band_energy`)."""
    return float(band_energy(np.ascontiguousarray(W), curve.degree, curve.closed,
                             np.ascontiguousarray(curve.control_points)))


def eck_hadenfeld(curve: BSplineCurve, r: int, l: int = 2) -> BSplineCurve:  # noqa: E741
    """Move control point ``r`` to the minimiser of ``E_l`` with all others held.

    Parameters
    ----------
    curve : BSplineCurve
        Open or closed (closed: the neighbourhood is cyclic).
    r : int
        0-based control point index.
    l : {2, 3}
        ``E_l = int |x^(l)(t)|^2 dt`` over the curve's domain.

    Returns
    -------
    BSplineCurve
        Same knots; only ``control_points[r]`` differs.

    Notes
    -----
    Eck & Hadenfeld, eqs. (14)-(16): ``d~_r = sum_{i != r} gamma_i d_i`` with
    ``gamma_i = - G_ri / G_rr``; equivalently ``d~_r = d_r - (G d)_r / G_rr`` (ERRATA). The Gram
    integrals are exact (Gauss-Legendre per knot span). The energy drops by
    ``z_r = G_rr |d_r - d~_r|^2`` (see :func:`ranking_numbers`).

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import BSplineCurve, steps
    >>> d = np.c_[np.arange(9.0), np.zeros(9)]
    >>> d[4, 1] = 1.0
    >>> c = BSplineCurve(d, np.r_[0, 0, 0, np.arange(7.0), 6, 6, 6], 3)
    >>> float(steps.eck_hadenfeld(c, 4).control_points[4, 1])
    0.0
    """
    curve = check_bspline(curve)
    lv = check_l(l, curve.degree)
    r = check_index(r, curve.n_ctrl, "r")
    W = curve.gram_band(lv)
    idx, col = _neighbours(curve, r)
    d = np.array(curve.control_points)
    g_r = (W[r, col][:, None] * d[idx]).sum(axis=0)
    d[r] = d[r] - g_r / W[r, curve.degree]
    return curve.replace(control_points=d)


def ranking_numbers(curve: BSplineCurve, l: int = 2) -> FloatArray:  # noqa: E741
    """Ranking numbers ``z_r = G_rr |d_r - d~_r|^2`` of every control point, shape ``(n,)``.

    ``z_r`` is the exact drop of ``E_l`` when :func:`eck_hadenfeld` moves ``d_r`` (ERRATA, the
    ranking list): ``E(d_r + delta) = E + 2 delta.(G d)_r + G_rr |delta|^2`` and
    ``delta = -(G d)_r / G_rr`` give ``z_r = |(G d)_r|^2 / G_rr``.
    """
    curve = check_bspline(curve)
    lv = check_l(l, curve.degree)
    W = curve.gram_band(lv)
    g = _residual(curve, W)
    return np.sum(g * g, axis=1) / W[:, curve.degree]


# ------------------------------------------------------------------------------------------
# the compiled ranking-list loop
# ------------------------------------------------------------------------------------------
@njit(cache=True, error_model="numpy")
def _candidate(g0, g1, g2, d0, d1, d2, o0, o1, o2, gii, igii, tol):  # type: ignore[no-untyped-def]
    """Constrained minimiser of the energy over one control point: ``(z, e0, e1, e2)``.

    The energy as a function of ``d_i`` alone is ``G_ii |x - x*|^2 + const`` (isotropic), with
    ``x* = d_i - g_i / G_ii``; its minimiser over the ball ``|x - orig_i| <= tol`` is the
    projection of ``x*`` onto the ball, with exact drop
    ``G_ii (|d_i - x*|^2 - |x - x*|^2) = G_ii (2 e.s - |e|^2)`` (``s = x* - d_i``,
    ``e = x - d_i``). A move shorter than 4 ulp-ish of the coordinates (``4e-16 (|d_i|_inf +
    tol)``) counts as no move (z = 0). The ball's radius is ``tol`` less a rounding margin
    ``2e-15 (|d_i|_inf + 2 tol)``, which bounds the rounding of the clamped point, of its
    storage and of any later distance computation: ``|x - orig_i| <= tol`` holds as computed,
    also for coordinates much larger than ``tol``. Scalars only: numba array arguments cost
    reference counting per call.
    """
    s0 = -g0 * igii
    s1 = -g1 * igii
    s2 = -g2 * igii
    # a move below the rounding of the coordinates is no move (else rounding noise in z keeps
    # the loop busy with zero-length moves)
    m = max(abs(d0), abs(d1), abs(d2))
    floor = 4e-16 * (m + (tol if tol < np.inf else 0.0))
    floor *= floor
    if s0 * s0 + s1 * s1 + s2 * s2 <= floor:
        return 0.0, 0.0, 0.0, 0.0
    if tol < np.inf:
        # the ball's radius less a rounding margin: the STORED point (every coordinate rounded
        # at the size of the coordinates, several times) is then within tol as computed by
        # anyone, |x - orig| <= tol even for coordinates 1e6 times tol
        rad = tol - 2e-15 * (m + 2.0 * tol)
        rad = rad if rad > 0.0 else 0.0
        v0 = d0 + s0 - o0
        v1 = d1 + s1 - o1
        v2 = d2 + s2 - o2
        vv = v0 * v0 + v1 * v1 + v2 * v2
        if vv > rad * rad:
            f = rad / np.sqrt(vv)
            e0 = o0 + v0 * f - d0
            e1 = o1 + v1 * f - d1
            e2 = o2 + v2 * f - d2
            ee = e0 * e0 + e1 * e1 + e2 * e2
            if ee <= floor:
                return 0.0, 0.0, 0.0, 0.0
            z = gii * (2.0 * (e0 * s0 + e1 * s1 + e2 * s2) - ee)
            if z < 0.0:
                z = 0.0
            return z, e0, e1, e2
    return gii * (s0 * s0 + s1 * s1 + s2 * s2), s0, s1, s2


@njit(cache=True, inline="always")
def _candidate2(g0, g1, d0, d1, o0, o1, gii, igii, tol):  # type: ignore[no-untyped-def]
    """:func:`_candidate` for a planar point, branch-free: the free and the clamped move are
    both computed and one is selected (a mispredicted branch on whether the ball is reached
    costs more than the extra arithmetic); the same operations in the same order, so the same
    values bitwise (also the zero move below rounding). Returns ``(z, e0, e1)``."""
    s0 = -g0 * igii
    s1 = -g1 * igii
    a0 = abs(d0)
    a1 = abs(d1)
    m = a0 if a0 > a1 else a1
    floor = 4e-16 * (m + (tol if tol < np.inf else 0.0))
    floor *= floor
    ss = s0 * s0 + s1 * s1
    rad = tol - 2e-15 * (m + 2.0 * tol)
    rad = rad if rad > 0.0 else 0.0
    v0 = d0 + s0 - o0
    v1 = d1 + s1 - o1
    vv = v0 * v0 + v1 * v1
    f = rad / np.sqrt(vv)  # inf/nan when not clamped: not selected below
    c0 = o0 + v0 * f - d0
    c1 = o1 + v1 * f - d1
    ee = c0 * c0 + c1 * c1
    zc = gii * (2.0 * (c0 * s0 + c1 * s1) - ee)
    zc = zc if zc > 0.0 else 0.0
    zc = 0.0 if ee <= floor else zc
    clamped = tol < np.inf and vv > rad * rad
    z = zc if clamped else gii * ss
    z = 0.0 if ss <= floor else z
    nomove = ss <= floor or (clamped and ee <= floor)  # _candidate returns zeros then
    e0 = c0 if clamped else s0
    e1 = c1 if clamped else s1
    e0 = 0.0 if nomove else e0
    e1 = 0.0 if nomove else e1
    return z, e0, e1


@njit(cache=True, inline="always")
def _point_candidate(X, i, Wu, pi, p, D, tol):  # type: ignore[no-untyped-def]
    """``(z, e0, e1, e2)`` of control point ``i`` from the loop state ``X = [d | G d | orig]``
    (``D`` columns each) and its band row ``Wu[pi]``: :func:`_candidate` in 3-D, the
    branch-free :func:`_candidate2` in the plane (same values). Inlined; the one place the
    state's columns are unpacked for a candidate."""
    if D == 3:
        return _candidate(X[i, 3], X[i, 4], X[i, 5], X[i, 0], X[i, 1], X[i, 2],
                          X[i, 6], X[i, 7], X[i, 8], Wu[pi, p], Wu[pi, 2 * p + 1], tol)
    z, e0, e1 = _candidate2(X[i, 2], X[i, 3], X[i, 0], X[i, 1], X[i, 4], X[i, 5],
                            Wu[pi, p], Wu[pi, 2 * p + 1], tol)
    return z, e0, e1, 0.0


@njit(cache=True, inline="always")
def _record(hist, nh, r, z, e0, e1, e2):  # type: ignore[no-untyped-def]
    """Write step ``(index, z, displacement)`` into row ``nh`` of ``hist`` while it has room;
    returns the new row count. Inlined into both loops."""
    if nh < hist.shape[0]:
        hist[nh, 0] = r
        hist[nh, 1] = z
        hist[nh, 2] = np.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
        nh += 1
    return nh


@njit(cache=True, inline="always")
def _move_residuals(X, Wu, pr, r, e0, e1, e2, D, p, closed):  # type: ignore[no-untyped-def]
    """After ``d_r`` moved by ``e``: ``(G d)_i += G_ir e`` over the band of ``r`` (cyclic for
    closed curves), ``G``'s row ``r`` being ``Wu[pr]``. Inlined at numba IR level into both
    loops (no call with array arguments in them); the one place this update is written."""
    n = X.shape[0]
    for c in range(2 * p + 1):
        i = r + c - p
        if closed:
            if i < 0:
                i += n
            elif i >= n:
                i -= n
        elif i < 0 or i >= n:
            continue
        w = Wu[pr, c]
        X[i, D] += w * e0
        X[i, D + 1] += w * e1
        if D == 3:
            X[i, 5] += w * e2


_BLOCK_SHIFT = 3  # 8 control points (one 64-byte line of z) per leaf of the tournament tree
_SPECULATE_BYTES = 1 << 22  # prefetch the runner-up's data when the state exceeds ~4 MB
_RUNNER_UP_TOP = 256  # the runner-up is sought among the siblings of the nodes below 256
_PREFETCH_LEVELS = 4  # tree nodes prefetched on the runner-up's path (from its leaf up)


@njit(cache=True, error_model="numpy")
def _eh_loop(X, z, Wu, pat, upat, ulo, uhi, D, p, closed, tol, eps_abs, max_steps,
             hist, T):  # type: ignore[no-untyped-def]
    """Ranking-list loop, compiled; updates ``X`` and ``z`` in place.

    ``X[i] = (d_i, g_i, orig_i)``, ``D`` columns each (``X`` has ``3 D`` columns),
    ``g = G d``; ``z[i]`` the ranking number (-1: never moves); ``G``'s band row ``i`` is
    ``Wu[pat[i]]`` (rows shared by equal knot patterns), and every row ``ulo <= i < uhi`` is
    ``Wu[upat]`` (the longest run of one pattern: the uniform interior, whose ``pat`` entries are
    then never read). Everything is written out in this one function: calling numba functions
    with array arguments costs reference counting per call.

    4-ary tournament tree over blocks of 8 control points, one array ``T`` of (value, index)
    pairs (the index stored as a float, exact below 2**53; a node's 4 children are one 64-byte
    cache line): a leaf ``P + b`` holds block ``b``'s largest ``z`` and the index, node ``j``
    the largest of ``4j .. 4j + 3`` (ties to the smaller index, hence to the smaller control
    point). After a move, the ``2p + 1`` changed ``z`` are recomputed (planar curves:
    branch-free, both the free and the tolerance-clamped candidate are evaluated and selected,
    which avoids unpredictable branches; the values are bitwise those of :func:`_candidate`),
    their one or two blocks rescanned and the ancestors repaired (level by level as a contiguous
    range until the range is one node, then along its path with the node carried in registers,
    which keeps a store-to-load round trip off every level): ``O(p + log N)`` per step. At 1e6
    points the 4-ary tree touches 9 cache lines per path instead of the binary tree's 17.

    On large curves the step is bound by memory latency (the next point is usually far away).
    The data of the runner-up (which is the next point whenever this move does not change its
    rank: on noisy data every far jump) are then prefetched one step ahead, as long as far jumps
    are frequent (a running share above 1/4; the slow tail of a fairing run moves locally): its
    band rows, ranking numbers and the lower levels of its tree path. The runner-up is sought
    among the siblings of the top levels of the winner's path only (nodes below 256, hot in the
    cache; walking the whole path cost more than the prefetch saved), which finds it unless it
    shares the winner's subtree 3 levels down. Prefetches never change results.

    ``hist`` (shape (cap, 3)) receives (index, z, displacement) of the first ``cap`` steps.
    ``T`` is the tree's storage, shape ``(>= 2 P, 2)`` (:func:`_tree_buffer`): allocated by
    numpy, which asks for transparent huge pages on large arrays (numba's allocator does not:
    fewer first-touch page faults), and 64-byte aligned.
    Returns (steps, total energy drop, stop code, number of history rows).
    """
    n = X.shape[0]
    C = X.shape[1]
    B = 1 << _BLOCK_SHIFT
    nb = (n + B - 1) >> _BLOCK_SHIFT
    P = 1
    while P < nb:
        P *= 4
    for j in range(2 * P):
        T[j, 0] = -1.0
        T[j, 1] = 0.0
    tol2 = tol * tol
    any_movable = False
    for i in range(n):
        if z[i] >= 0.0:
            any_movable = True
            pi = upat if ulo <= i < uhi else pat[i]
            z[i] = _point_candidate(X, i, Wu, pi, p, D, tol)[0]
    if not any_movable:
        return 0, 0.0, 2, 0
    for b in range(nb):
        k0 = b << _BLOCK_SHIFT
        best = k0
        for k in range(k0 + 1, min(k0 + B, n)):
            if z[k] > z[best]:
                best = k
        T[P + b, 0] = z[best]
        T[P + b, 1] = best
    L = P >> 2
    while L >= 1:  # level L holds nodes L .. 2L - 1, children of j: 4j .. 4j + 3
        for j in range(L, 2 * L):
            c = 4 * j
            c01 = c + (T[c + 1, 0] > T[c, 0])  # branch-free selects, ties to the left
            c23 = c + 2 + (T[c + 3, 0] > T[c + 2, 0])
            m = c23 if T[c23, 0] > T[c01, 0] else c01
            T[j, 0] = T[m, 0]
            T[j, 1] = T[m, 1]
        L >>= 2
    steps = 0
    drop = 0.0
    code = 1
    nh = 0
    wrap_all = closed and 2 * p + 1 >= n
    big = n * (C + 2) * 8 >= _SPECULATE_BYTES
    farrate = 0.0  # running share of far jumps (> 16 points from the previous step)
    prev = -(1 << 40)
    while steps < max_steps:
        r = int(T[1, 1])
        zr = T[1, 0]
        if zr <= 0.0 or zr < eps_abs:
            code = 0
            break
        farrate = 0.9375 * farrate + (0.0625 if abs(r - prev) > 16 else 0.0)
        prev = r
        if big and farrate > 0.25:
            j = P + (r >> _BLOCK_SHIFT)
            while j >= _RUNNER_UP_TOP:
                j >>= 2
            bz = -2.0
            bf = float(r)
            while j > 1:  # branch-free: a mispredicted branch here delays the prefetches
                g = j & ~3
                for q in range(g, g + 4):
                    sv = T[q, 0] if q != j else -2.0
                    sf = T[q, 1]
                    gt = sv > bz
                    bz = sv if gt else bz
                    bf = sf if gt else bf
                j >>= 2
            bi = int(bf)
            q0 = bi - p if bi >= p else 0
            for q in range(q0 * C, (q0 + 2 * p + 1) * C, 8):
                prefetch(X, q)
            prefetch(X, (q0 + 2 * p + 1) * C - 1)
            prefetch(z, q0)
            prefetch(z, q0 + 2 * p)
            j = P + (bi >> _BLOCK_SHIFT)
            for _ in range(_PREFETCH_LEVELS):
                prefetch(T, 2 * j)
                j >>= 2
        pr = upat if ulo <= r < uhi else pat[r]
        zz, e0, e1, e2 = _point_candidate(X, r, Wu, pr, p, D, tol)
        X[r, 0] += e0
        X[r, 1] += e1
        if D == 3:
            X[r, 2] += e2
        _move_residuals(X, Wu, pr, r, e0, e1, e2, D, p, closed)
        # the changed ranking numbers: one or two contiguous ranges
        lo1 = r - p
        hi1 = r + p
        lo2 = 0
        hi2 = -1
        if wrap_all:
            lo1 = 0
            hi1 = n - 1
        elif lo1 < 0:
            if closed:
                lo2 = lo1 + n
                hi2 = n - 1
            lo1 = 0
        elif hi1 >= n:
            if closed:
                lo2 = 0
                hi2 = hi1 - n
            hi1 = n - 1
        if hi1 >= n:  # open curve shorter than the band: both ends clipped
            hi1 = n - 1
        for rng in range(2):
            lo = lo1 if rng == 0 else lo2
            hi = hi1 if rng == 0 else hi2
            if hi < lo:
                continue
            inside = ulo <= lo and hi < uhi  # one pattern: no pat reads
            if D == 3:
                for i in range(lo, hi + 1):
                    if z[i] < 0.0:
                        continue
                    pi = upat if inside else pat[i]
                    z[i] = _point_candidate(X, i, Wu, pi, p, D, tol)[0]
            elif tol2 == np.inf:
                for i in range(lo, hi + 1):
                    pi = upat if inside else pat[i]
                    gii = Wu[pi, p]
                    igii = Wu[pi, 2 * p + 1]
                    a0 = abs(X[i, 0])
                    a1 = abs(X[i, 1])
                    m = a0 if a0 > a1 else a1
                    floor = 4e-16 * m
                    floor *= floor
                    s0 = -X[i, 2] * igii
                    s1 = -X[i, 3] * igii
                    ss = s0 * s0 + s1 * s1
                    zn = 0.0 if ss <= floor else gii * ss
                    zo = z[i]
                    z[i] = zo if zo < 0.0 else zn
            else:
                for i in range(lo, hi + 1):
                    pi = upat if inside else pat[i]
                    zn = _point_candidate(X, i, Wu, pi, p, D, tol)[0]
                    zo = z[i]
                    z[i] = zo if zo < 0.0 else zn
            blo = lo >> _BLOCK_SHIFT
            bhi = hi >> _BLOCK_SHIFT
            for b in range(blo, bhi + 1):
                k0 = b << _BLOCK_SHIFT
                best = k0
                zb = z[k0]
                for k in range(k0 + 1, min(k0 + B, n)):
                    zk = z[k]
                    gt = zk > zb
                    best = k if gt else best
                    zb = zk if gt else zb
                T[P + b, 0] = zb
                T[P + b, 1] = best
            # repair the ancestors: level by level while the range spans several nodes,
            # then along the single path with the node's (value, index) carried in registers
            # (reading it back from T would put a store-to-load round trip on every level)
            if blo == bhi:
                j = P + blo
                cv = zb
                cf = float(best)
            else:
                a = (P + blo) >> 2
                bb = (P + bhi) >> 2
                while a < bb:
                    for j in range(a, bb + 1):
                        c = 4 * j
                        c01 = c + (T[c + 1, 0] > T[c, 0])
                        c23 = c + 2 + (T[c + 3, 0] > T[c + 2, 0])
                        m = c23 if T[c23, 0] > T[c01, 0] else c01
                        T[j, 0] = T[m, 0]
                        T[j, 1] = T[m, 1]
                    a >>= 2
                    bb >>= 2
                j = a
                c = 4 * j
                c01 = c + (T[c + 1, 0] > T[c, 0])
                c23 = c + 2 + (T[c + 3, 0] > T[c + 2, 0])
                m = c23 if T[c23, 0] > T[c01, 0] else c01
                cv = T[m, 0]
                cf = T[m, 1]
                T[j, 0] = cv
                T[j, 1] = cf
            while j > 1:  # the same selects, node j's own entry taken from the registers
                g = j & ~3
                k = j & 3
                v0 = cv if k == 0 else T[g, 0]
                v1 = cv if k == 1 else T[g + 1, 0]
                v2 = cv if k == 2 else T[g + 2, 0]
                v3 = cv if k == 3 else T[g + 3, 0]
                f0 = cf if k == 0 else T[g, 1]
                f1 = cf if k == 1 else T[g + 1, 1]
                f2 = cf if k == 2 else T[g + 2, 1]
                f3 = cf if k == 3 else T[g + 3, 1]
                t1 = v1 > v0
                va = v1 if t1 else v0
                fa = f1 if t1 else f0
                t3 = v3 > v2
                vb = v3 if t3 else v2
                fb = f3 if t3 else f2
                tb = vb > va
                cv = vb if tb else va
                cf = fb if tb else fa
                j >>= 2
                T[j, 0] = cv
                T[j, 1] = cf
        drop += zr
        nh = _record(hist, nh, r, zr, e0, e1, e2)
        steps += 1
    return steps, drop, code, nh


@njit(cache=True, error_model="numpy")
def _eh_sweep(X, z, Wu, pat, upat, ulo, uhi, D, p, closed, tol, eps_abs, max_steps,
              hist, Q, flags):  # type: ignore[no-untyped-def]
    """Sweep schedule (``schedule="sweep"``), compiled; updates ``X`` in place.

    The same step, state and stopping test as :func:`_eh_loop` (``X = [d | G d | orig]``,
    ``Wu``/``pat``/``upat``/``ulo``/``uhi`` the band rows, ``z`` 0 for movable and -1 for fixed
    points on entry), but Gauss-Seidel order instead of the ranking list: a first-in first-out
    queue of the points whose ranking number is at least the threshold ``eps_abs``, filled in
    index order; a popped point is faired if its ranking number (recomputed then) is still at
    least the threshold, and every neighbour whose ``(G d)_j`` the move changed joins the queue
    unless it is queued already or its unconstrained drop ``|(G d)_j|^2 / G_jj`` (an upper bound
    of the tolerance-clamped one) is below the threshold. When the queue is empty every
    ranking number is below the threshold: the stopping test of the ranking list, met without
    a priority structure. Memory is read in index order (one queue pass is a sweep), so a step
    costs about the same at 1e6 points as in cache; the ranking list's far jumps cost a DRAM
    latency each.

    ``Q`` (int64, ``n``) is the ring buffer; ``flags`` (uint8, ``n``) is 1 for queued and 2
    for fixed points (``z`` is read only once, for the fixed ones).
    ``hist`` as in :func:`_eh_loop`. Returns (steps, total energy drop, stop code, history
    rows): code 0 queue empty, 1 ``max_steps``, 2 no movable point.
    """
    n = X.shape[0]
    thr = eps_abs
    head = 0
    tail = 0
    cnt = 0
    any_movable = False
    for i in range(n):
        if z[i] < 0.0:
            flags[i] = 2  # never moves
            continue
        flags[i] = 0
        any_movable = True
        pi = upat if ulo <= i < uhi else pat[i]
        zi = _point_candidate(X, i, Wu, pi, p, D, tol)[0]
        if zi > 0.0 and zi >= thr:
            Q[tail] = i
            tail += 1
            flags[i] = 1
            cnt += 1
    if not any_movable:
        return 0, 0.0, 2, 0
    if tail == n:
        tail = 0
    wrap_all = closed and 2 * p + 1 >= n
    steps = 0
    drop = 0.0
    nh = 0
    code = 0
    while cnt > 0:
        if steps >= max_steps:
            code = 1
            break
        r = Q[head]
        head += 1
        if head == n:
            head = 0
        cnt -= 1
        flags[r] = 0
        pr = upat if ulo <= r < uhi else pat[r]
        zz, e0, e1, e2 = _point_candidate(X, r, Wu, pr, p, D, tol)
        if zz <= 0.0 or zz < thr:
            continue
        X[r, 0] += e0
        X[r, 1] += e1
        if D == 3:
            X[r, 2] += e2
        _move_residuals(X, Wu, pr, r, e0, e1, e2, D, p, closed)
        # every point whose (G d)_i changed: queue it when its drop may reach the threshold
        if wrap_all:
            lo = 0
            hi = n - 1
        else:
            lo = r - p
            hi = r + p
            if not closed:
                lo = lo if lo > 0 else 0
                hi = hi if hi < n else n - 1
        for k in range(lo, hi + 1):
            i = k
            if i < 0:
                i += n
            elif i >= n:
                i -= n
            if flags[i] != 0:  # queued already, or fixed
                continue
            pi = upat if ulo <= i < uhi else pat[i]
            if D == 3:
                gg = X[i, 3] * X[i, 3] + X[i, 4] * X[i, 4] + X[i, 5] * X[i, 5]
            else:
                gg = X[i, 2] * X[i, 2] + X[i, 3] * X[i, 3]
            zu = gg * Wu[pi, 2 * p + 1]
            if zu > 0.0 and zu >= thr:
                Q[tail] = i
                tail += 1
                if tail == n:
                    tail = 0
                flags[i] = 1
                cnt += 1
        drop += zz
        nh = _record(hist, nh, r, zz, e0, e1, e2)
        steps += 1
    return steps, drop, code, nh


@njit(cache=True)
def _patterns(W, Wu, pat):  # type: ignore[no-untyped-def]
    """Fill ``pat`` and the distinct rows ``Wu`` (see :func:`band_patterns`); returns
    ``(number of patterns, pattern of the longest run, its start, its end)``."""
    n, w = W.shape
    m = 0
    run0 = 0
    best = -1
    blo = 0
    bhi = 0
    for i in range(n):
        new = i == 0
        if not new:
            for c in range(w):
                if W[i, c] != W[i - 1, c]:
                    new = True
                    break
        if new:
            if i > 0 and i - run0 > bhi - blo:
                best, blo, bhi = m - 1, run0, i
            for c in range(w):
                Wu[m, c] = W[i, c]
            Wu[m, w] = 1.0 / W[i, w // 2]
            m += 1
            run0 = i
        pat[i] = m - 1
    if n - run0 > bhi - blo:
        best, blo, bhi = m - 1, run0, n
    return m, best, blo, bhi


def band_patterns(W: FloatArray) -> tuple[FloatArray, np.ndarray, int, int, int]:
    """Compress a band ``W`` into distinct rows ``Wu`` and ``pat`` with ``W[i] == Wu[pat[i]]``.

    Consecutive equal rows share one entry (uniform knots: a handful of rows in all). ``Wu``
    has one more column: ``1 / G_ii``. Also returns the longest run of one pattern
    ``(upat, ulo, uhi)``: ``pat[ulo:uhi] == upat``."""
    n, w = W.shape
    Wu = np.empty((n, w + 1))
    pat = np.empty(n, dtype=np.int32)
    m, upat, ulo, uhi = _patterns(np.ascontiguousarray(W), Wu, pat)
    return Wu[:m].copy(), pat, int(upat), int(ulo), int(uhi)


@njit(cache=True)
def _largest_free_z(W, p, closed, d, mask):  # type: ignore[no-untyped-def]
    """Largest unconstrained ranking number ``|(G d)_i|^2 / G_ii`` over the movable points (0
    if none): the residual of :func:`curvefair._kernels.bspline.band_residual` row by row, same
    operations, without the ``(n, dim)`` temporaries."""
    n, dim = d.shape
    best = 0.0
    first = True
    for i in range(n):
        if not mask[i]:
            continue
        interior = i >= p and i + p < n
        gg = 0.0
        for a in range(dim):
            acc = residual_row(W, 1.0, p, closed, d, i, a, interior)
            gg += acc * acc
        v = gg / W[i, p]
        if first or v > best:
            best = v
            first = False
    return best


@njit(cache=True)
def _setup_state(W, p, closed, d, mask, X, z):  # type: ignore[no-untyped-def]
    """One pass over the control points ``d``: the loop state ``X = [d | G d | d]`` (the
    residual of :func:`curvefair._kernels.bspline.band_residual`), the ranking-number slots
    ``z`` (0 movable, -1 fixed, from ``mask``) and the energy ``d^T G d``, returned. Each value
    is computed with the same operations in the same order as ``band_residual`` /
    ``band_energy`` (so bitwise equal to them); fused, the 1e6-point set-up reads ``d`` once."""
    n, dim = d.shape
    e = 0.0
    for i in range(n):
        interior = i >= p and i + p < n
        for a in range(dim):
            xi = d[i, a]
            acc = residual_row(W, 1.0, p, closed, d, i, a, interior)
            X[i, a] = xi
            X[i, dim + a] = acc
            X[i, 2 * dim + a] = xi
        e = energy_row(W, p, closed, d, i, e)
        z[i] = 0.0 if mask[i] else -1.0
    return e


def _tree_buffer(n: int) -> FloatArray:
    """Storage of :func:`_eh_loop`'s tournament tree for ``n`` control points: ``(2 P, 2)``,
    ``P`` the smallest power of 4 ``>=`` the number of blocks, 64-byte aligned."""
    nb = (int(n) + (1 << _BLOCK_SHIFT) - 1) >> _BLOCK_SHIFT
    P = 1
    while P < nb:
        P *= 4
    return _aligned_empty((2 * P, 2))


def _aligned_empty(shape: tuple[int, ...]) -> FloatArray:
    """``np.empty(shape)`` starting on a 64-byte cache line (the ranking-list loop's blocks of
    8 ranking numbers are then exactly one line each)."""
    size = int(np.prod(shape))
    buf = np.empty(size + 8)
    off = (-buf.ctypes.data % 64) // 8
    return buf[off:off + size].reshape(shape)


def default_eps(n: int) -> float:
    """Default relative threshold of the ranking list: ``1e-4 / n`` (see
    :func:`eck_hadenfeld_fair`)."""
    return 1e-4 / max(int(n), 1)


@dataclass(frozen=True)
class EHResult:
    """Outcome of :func:`eck_hadenfeld_fair`.

    Attributes
    ----------
    curve : BSplineCurve
    steps : int
    stop_reason : str
        ``"eps"`` (largest ranking number below the threshold), ``"converged"`` (every move is
        0), ``"tolerance"`` (the remaining moves above the threshold are blocked by the
        tolerance), ``"max_steps"``, ``"no_movable_point"``.
    energy_before, energy_after : float
        ``E_l`` of the input and of the result (exact, from the Gram matrix).
    eps_absolute : float
        The threshold on the ranking numbers actually used.
    history : ndarray, shape (s, 3)
        ``(index, z, displacement)`` of the first ``history_max`` steps.
    """

    curve: BSplineCurve
    steps: int
    stop_reason: StopReason
    energy_before: float
    energy_after: float
    eps_absolute: float
    history: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))


def eck_hadenfeld_fair(curve: BSplineCurve, *, l: int = 2, tol: float | None = None,  # noqa: E741
                       eps: float | None = None, eps_relative: bool = True,
                       max_steps: int | None = None, clamp: Any = (None, None),
                       protect: Iterable[int] = (), history_max: int = 1_000_000,
                       schedule: str = "ranking") -> EHResult:
    """Eck & Hadenfeld ranking-list fairing of a B-spline curve.

    Parameters
    ----------
    curve : BSplineCurve
    l : {2, 3}
        Energy ``E_l = int |x^(l)|^2 dt``.
    tol : float or None
        Largest distance of every control point from its ORIGINAL position (hence, by the
        convex hull property, of the curve from the input curve at equal parameter).
    eps : float, optional
        Stop when the largest ranking number is below ``eps * E_l(input)``
        (``eps_relative=True``; default ``1e-4 / n``, i.e. ``1e-4`` of the mean energy per
        control point, which gives the same local accuracy for every ``n``) or below ``eps``
        (``eps_relative=False``; default 0). Larger thresholds take fewer steps and end less
        fair; the trade-off is measured in docs/benchmarks.md ("Eck-Hadenfeld: threshold and
        schedule").
    max_steps : int or None
        Step cap (default ``100 n``).
    clamp : (left, right)
        End conditions, see :func:`movable_mask` (ignored for closed curves).
    protect : iterable of int
        Control points that never move.
    history_max : int
        Record ``(index, z, displacement)`` for at most this many steps.
    schedule : {"ranking", "sweep"}
        Which control point to fair next. ``"ranking"`` (default): the ranking list of the
        paper, always the one with the largest ranking number. ``"sweep"``: Gauss-Seidel order
        - every control point whose ranking number is at least the threshold, in index order,
        then again every neighbour of a moved point whose number may have reached it, until
        none does (see ``_eh_sweep``). Same step, same tolerance, same stopping test (when
        it stops, no ranking number is above the threshold); only the order differs: the
        sweep reads memory in order instead of jumping across the curve, and leaves most
        ranking numbers far below the threshold where the ranking list leaves them just
        below it (measurements: docs/benchmarks.md, "Eck-Hadenfeld: threshold and schedule").

    Returns
    -------
    EHResult

    Notes
    -----
    The ranking list of ERRATA (the section after seed 003): fair the control point with the
    largest ranking number, recompute only the ``2 degree + 1`` neighbours whose ``(G d)_i``
    changed, repeat. The ranking number is the exact energy drop of the (tolerance-clamped)
    move: ``z_r = G_rr |d_r - d~_r|^2`` when no clamping is needed (ERRATA); when ``d~_r`` is
    projected onto the ball ``|x - d_r^orig| <= tol``, the projection is the exact constrained
    minimiser over ``d_r`` (the energy is isotropic in ``d_r``) and
    ``z_r = G_rr (|d_r - d~_r|^2 - |x - d~_r|^2)`` is its exact drop (ERRATA prints
    ``G_rr |d_r - x|^2``, which ranks such moves too high). Without a tolerance the iteration is a
    Gauss-Seidel sweep and converges to the global minimiser with the fixed points held.
    Compiled loops: ``O(log N)`` per step for the ranking list (see ``_eh_loop``), ``O(degree)``
    per step for the sweep (``_eh_sweep``).

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import interpolate_bspline
    >>> from curvefair.fairing.eck_hadenfeld import eck_hadenfeld_fair
    >>> rng = np.random.default_rng(0)
    >>> x = np.linspace(0, 6, 40)
    >>> c = interpolate_bspline(np.c_[x, np.sin(x) + 0.01 * rng.normal(size=40)])
    >>> res = eck_hadenfeld_fair(c, tol=0.01, clamp=("g2", "g2"))
    >>> bool(res.energy_after < res.energy_before)
    True
    """
    from .problem import make_problem

    prob = make_problem(check_bspline(curve), tol=tol, eps=eps, max_steps=max_steps,
                        clamp=clamp, protect=protect)
    out = solve(prob, l=l, eps_relative=eps_relative, history_max=history_max,
                schedule=schedule)
    h = out.history
    assert h is not None
    hist = np.column_stack([h.index.astype(np.float64), h.measure, h.displacement])
    return EHResult(cast(BSplineCurve, out.curve), out.steps, out.stop_reason,
                    out.extra["energy_l_before"], out.extra["energy_l_after"],
                    cast(float, out.eps_absolute), hist.reshape(-1, 3))


def solve(problem: FairingProblem, *, l: int = 2, eps_relative: bool = True,  # noqa: E741
          history_max: int = 1_000_000, schedule: str = "sweep") -> Outcome:
    """Eck & Hadenfeld as a solver of ``problem`` (``fair(curve, "eck-hadenfeld")``).

    ``problem.eps`` is relative to ``E_l(input)`` (default :func:`default_eps`);
    ``eps_relative=False`` makes it an absolute threshold on the ranking numbers (default 0).
    The order defaults to ``"sweep"`` here, :func:`eck_hadenfeld_fair` keeps the paper's
    ranking list (docs/benchmarks.md, "Eck-Hadenfeld schedule").
    """
    from .problem import FairingHistory, Outcome, eps_threshold

    curve = check_bspline(problem.curve)
    lv = check_l(l, curve.degree)
    n = curve.n_ctrl
    tolv = problem.tol
    max_steps = as_step_count(problem.max_steps, default=100 * n)
    history_max = as_step_count(history_max, "history_max", default=1_000_000)
    if not isinstance(eps_relative, (bool, np.bool_)):
        raise InputError(f"eps_relative must be True or False, got {eps_relative!r}")
    sched = check_schedule(schedule)
    mask = problem.movable
    W = np.ascontiguousarray(curve.gram_band(lv))
    dim = curve.dim
    d = np.ascontiguousarray(curve.control_points)
    X = _aligned_empty((n, 3 * dim))  # [d | g = G d | d original]
    z = _aligned_empty((n,))
    e0 = float(_setup_state(W, curve.degree, curve.closed, d, mask, X, z))
    if eps_relative:
        epsv, eps_abs = eps_threshold(problem.eps, e0, default_eps(n))
    else:
        epsv = eps_abs = 0.0 if problem.eps is None else problem.eps
    hist = np.zeros((int(min(history_max, max_steps)), 3))
    Wu, pat, upat, ulo, uhi = band_patterns(W)
    if sched == "ranking":
        steps, drop, code, nh = _eh_loop(X, z, Wu, pat, upat, ulo, uhi, dim, curve.degree,
                                         curve.closed, tolv, eps_abs, int(max_steps), hist,
                                         _tree_buffer(n))
    else:
        steps, drop, code, nh = _eh_sweep(X, z, Wu, pat, upat, ulo, uhi, dim, curve.degree,
                                          curve.closed, tolv, eps_abs, int(max_steps), hist,
                                          np.empty(n, dtype=np.int64),
                                          np.empty(n, dtype=np.uint8))
    # the loop keeps every coordinate finite and the knots are the input's: no re-validation
    out = BSplineCurve._trusted(np.ascontiguousarray(X[:, :dim]), curve.knots, curve.degree,
                                curve.closed, same_knots_as=curve)
    e1 = _energy(out, W)
    if not np.isfinite(e1):
        check_finite(out.control_points, "control_points")
    reason = STOP_REASONS[int(code)]
    if reason == "converged":
        zfree = float(_largest_free_z(W, curve.degree, curve.closed, X[:, :dim], mask))
        if zfree > eps_abs and zfree > 0.0:
            reason = "tolerance"  # the unconstrained moves are still worth making
        elif eps_abs > 0.0 and zfree > 0.0:
            reason = "eps"
    # a view: the rows never written were never touched (np.zeros maps them lazily)
    h = hist[:nh]
    history = FairingHistory.from_arrays(h[:, 0].astype(np.int64), h[:, 1], h[:, 2],
                                         "control point")
    return Outcome(
        curve=out, steps=int(steps), stop_reason=reason, history=history, eps=epsv,
        max_steps=int(max_steps), eps_absolute=eps_abs,
        extra={"l": int(l), "schedule": sched, "energy_l_before": e0, "energy_l_after": e1,
               "eps_relative": bool(eps_relative), "eps_absolute": eps_abs,
               "history_truncated": bool(steps > h.shape[0])})


# ------------------------------------------------------------------------------------------
# registration with fair()
# ------------------------------------------------------------------------------------------
def _register() -> None:
    from .fair import MethodSpec, register_method

    register_method(MethodSpec(
        name="eck-hadenfeld",
        curve_types=(BSplineCurve,),
        solver=solve,
        summary="Eck & Hadenfeld: move control points to their energy-minimising positions "
                "(E_l, l=2|3), within tol of the original; default schedule=sweep (the same "
                "steps in Gauss-Seidel order, as fair or fairer on 54 benchmark data sets), "
                "schedule=ranking: the paper's ranking list",
        source="Eck & Hadenfeld, Local energy fairing of B-spline curves, eqs. (12)-(16); "
               "ranking list as in ERRATA",
        default=True,
        default_reason="default above 200,000 control points (global_fair.DEFAULT_MAX_CTRL), "
                       "where 'global' l=3 costs ~30x one csaps fit: the sweep's whole call is "
                       "a few csaps fits at 1e6 [benchmarks/bench_call_cost.py]",
    ))


_register()
