"""Discrete curvature of point sequences and the second discrete curvature of cubic B-splines.

Cheng & Yu (seed 002): the discrete curvature ``C_i`` of a polygon (eq. (2), corrected by the
ERRATA), the second discrete curvature ``K_i`` of the control polygon of a cubic B-spline
(Definition 1), its first and second differences (Definition 2), and the three kinds of bad
points with their local fairing values ``z_i = D_i**2`` (section "Smoothing criterion").

Indices are 0-based, exactly as in the paper, whose control points are ``Q_0 .. Q_n`` and whose
knots are ``u_0 .. u_{n+4}`` (control point ``Q_i`` owns the B-spline on ``[u_i, u_{i+4}]``; the
curve lives on ``[u_3, u_{n+1}]``).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._typing import ArrayLike, FloatArray
from .._validate import as_points, magnitude
from ..errors import InputError

__all__ = [
    "discrete_curvature",
    "second_discrete_curvature",
    "bad_points",
    "SecondDiscreteCurvature",
    "BadPoint",
]


def _readonly(a: np.ndarray) -> np.ndarray:
    from ..curves.piecewise import readonly

    return readonly(np.asarray(a))


def _cross2(a: FloatArray, b: FloatArray) -> FloatArray:
    """Signed 2-D cross product (twice the signed triangle area) row by row, or for 3-D the norm."""
    if a.shape[-1] == 2:
        return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return np.linalg.norm(np.cross(a, b), axis=-1)


# --------------------------------------------------------------------------------------------
# discrete curvature of a polygon
# --------------------------------------------------------------------------------------------
def discrete_curvature(points: ArrayLike, closed: bool = False) -> FloatArray:
    """Discrete curvature ``C_i`` at every vertex of a point sequence (Cheng & Yu, eq. (2)).

    Parameters
    ----------
    points : array_like, shape (n, dim)
        Vertices, ``dim`` 2 or 3; no two consecutive vertices may coincide.
    closed : bool
        Treat the polygon as closed (cyclic neighbours). Each vertex is listed once; if the
        first vertex is repeated as the last one (the curvefair convention for closed Hermite
        data), the repeat is recognised and gets the same value as the first.

    Returns
    -------
    ndarray, shape (n,)
        Signed curvature for planar input (positive where the polygon turns left, i.e.
        counter-clockwise); for 3-D input the unsigned value (the same formula with the
        triangle area taken as ``|e_i x e_{i+1}| / 2``).

    Raises
    ------
    InputError
        Non-finite values, coincident consecutive vertices, fewer than 2 vertices (3 when
        ``closed``), or a hairpin ``Q_{i-1} == Q_{i+1}`` where the discrete curvature does not
        exist (the chord ``M_i`` vanishes).

    Notes
    -----
    With ``L_i = |Q_i - Q_{i-1}|``, ``M_i = |Q_{i+1} - Q_{i-1}|`` and ``D_i`` the signed area of
    the triangle ``Q_{i-1} Q_i Q_{i+1}``::

        C_i = 4 (L_i + L_{i+1})**2 D_i / (L_i L_{i+1} M_i**3)

    This is eq. (2) of Cheng & Yu with the factor 4 of the ERRATA (the printed factor 2 gives
    half the curvature): it is the planar curvature ``x'y'' - y'x'' / (x'^2 + y'^2)^(3/2)`` of the
    chord-length difference quotients ``Q' = (Q_{i+1} - Q_{i-1}) / (L_i + L_{i+1})`` and
    ``Q'' = 2 ((Q_{i+1} - Q_i)/L_{i+1} - (Q_i - Q_{i-1})/L_i) / (L_i + L_{i+1})`` (eq. (1), which is
    garbled in the seed text).

    On a circle of radius ``R`` the value is ``(L_i + L_{i+1})**2 / (M_i**2 R)``, i.e. ``1/R`` only
    in the limit of fine spacing (relative error about ``L_i L_{i+1} / (4 R**2)`` for small chords,
    second order); it always overestimates a circle slightly.

    Open ends follow Remark 1: the reflected vertices ``Q_{-1} = 2 Q_0 - Q_1`` and
    ``Q_n = 2 Q_{n-1} - Q_{n-2}`` make the end triangles degenerate, so ``C_0 = C_{n-1} = 0``.

    Examples
    --------
    >>> import numpy as np
    >>> a = np.linspace(0.0, 0.5, 6)
    >>> c = discrete_curvature(np.c_[2 * np.cos(a), 2 * np.sin(a)])
    >>> c.round(4).tolist()        # radius 2: 1/R = 0.5 up to (spacing / 2)**2
    [0.0, 0.5013, 0.5013, 0.5013, 0.5013, 0.0]
    """
    pts = as_points(points, "points", min_points=3 if closed else 2)
    n = pts.shape[0]
    closed = bool(closed)
    repeated = False
    if closed:
        scale = magnitude(pts)
        if n > 3 and np.all(np.abs(pts[0] - pts[-1]) <= 4 * np.finfo(float).eps * scale):
            repeated = True
            pts = pts[:-1]
        elif np.all(np.abs(pts[0] - pts[-1]) <= 4 * np.finfo(float).eps * scale):
            raise InputError("points: a closed polygon needs at least 3 distinct vertices")
        prev = np.roll(pts, 1, axis=0)
        nxt = np.roll(pts, -1, axis=0)
        c = _discrete_curvature_core(prev, pts, nxt, 0)
        if repeated:
            c = np.append(c, c[0])
        return c
    if n == 2:
        return np.zeros(2)
    c = np.zeros(n)
    c[1:-1] = _discrete_curvature_core(pts[:-2], pts[1:-1], pts[2:], 1)
    return c


def _discrete_curvature_core(prev: FloatArray, cur: FloatArray, nxt: FloatArray,
                             offset: int) -> FloatArray:
    e0 = cur - prev
    e1 = nxt - cur
    chord = nxt - prev
    l0 = np.linalg.norm(e0, axis=1)
    l1 = np.linalg.norm(e1, axis=1)
    m = np.linalg.norm(chord, axis=1)
    scale = np.maximum(l0, l1)
    bad = np.flatnonzero(m <= 1e-14 * scale)
    if bad.size:
        i = int(bad[0]) + offset
        raise InputError(
            f"points: the polygon turns back on itself at index {i} "
            f"(points[{i}-1] == points[{i}+1]); the discrete curvature does not exist there"
        )
    twice_area = _cross2(e0, e1)
    s = l0 + l1
    return 2.0 * twice_area * s * s / (l0 * l1 * m**3)


# --------------------------------------------------------------------------------------------
# second discrete curvature of the control polygon of a cubic B-spline
# --------------------------------------------------------------------------------------------
def check_cubic_bspline(curve: Any, what: str) -> Any:
    """Check that ``curve`` is a cubic :class:`~curvefair.BSplineCurve` and return it."""
    from ..curves.bspline import BSplineCurve

    if not isinstance(curve, BSplineCurve):
        raise InputError(f"{what} needs a cubic BSplineCurve, got {type(curve).__name__}")
    if curve.degree != 3:
        raise InputError(f"{what} is defined for cubic B-splines only, got degree {curve.degree}")
    if not curve.closed and curve.n_ctrl < 3:
        raise InputError(f"{what} needs at least 3 control points, got {curve.n_ctrl}")
    return curve


def corner_cut_ratios(knots: FloatArray, n: int, closed: bool) -> tuple[FloatArray, FloatArray]:
    """The corner-cutting proportions ``l_i`` and ``m_i`` of Definition 1, shape ``(n,)`` each.

    ``l_i = (u_{i+3} - u_{i+2}) / (u_{i+3} - u_i)``,
    ``m_i = (u_{i+2} - u_{i+1}) / (u_{i+4} - u_{i+1})``
    (Cheng & Yu, Definition 1). Open curves: defined for ``i = 1 .. n-2`` (the end entries are 0);
    closed curves: for every control point, with the periodic knot vector.
    """
    t = np.asarray(knots, dtype=float)
    lw = np.zeros(n)
    mw = np.zeros(n)
    if closed:
        i = np.arange(1, n + 1)
        dst = i % n
    else:
        i = np.arange(1, n - 1)
        dst = i
    den_l = t[i + 3] - t[i]
    den_m = t[i + 4] - t[i + 1]
    # den > 0 always: a cubic B-spline has interior multiplicity <= 3 and a non-empty domain
    lw[dst] = (t[i + 3] - t[i + 2]) / den_l
    mw[dst] = (t[i + 2] - t[i + 1]) / den_m
    return lw, mw


def second_curvature_values(ctrl: FloatArray, lw: FloatArray, mw: FloatArray,
                            closed: bool) -> FloatArray:
    """``K_i`` of eq. (3) for control points ``ctrl`` (n, dim); open ends are 0 (see
    :func:`second_discrete_curvature`)."""
    n = ctrl.shape[0]
    k = np.zeros(n)
    if closed:
        idx = np.arange(n)
        prev, cur, nxt = ctrl[(idx - 1) % n], ctrl, ctrl[(idx + 1) % n]
        lwi, mwi, ki, i0 = lw, mw, k, 0
    else:
        # interior points 1 .. n-2 as views (no index array, no gathered copies of the
        # control points: 3.5x the coordinates' bytes less at a million points)
        prev, cur, nxt = ctrl[:-2], ctrl[1:-1], ctrl[2:]
        lwi, mwi, ki, i0 = lw[1:-1], mw[1:-1], k[1:-1], 1
    e0 = cur - prev
    e1 = nxt - cur
    area = 0.5 * _cross2(e0, e1)
    w = lwi[:, None] * e0 + mwi[:, None] * e1
    wn = np.linalg.norm(w, axis=1)
    nz = area != 0.0
    bad = np.flatnonzero(nz & (wn == 0.0))
    if bad.size:
        i = int(bad[0]) + i0
        raise InputError(
            f"curve: the second discrete curvature at control point {i} does not exist "
            "(a knot of multiplicity 3 makes a corner there)"
        )
    ki[nz] = area[nz] / wn[nz] ** 3
    return k


def _difference_weights(ctrl: FloatArray, closed: bool) -> FloatArray:
    """``t_i = L_{i+1} / (L_i + L_{i+1})`` of Definition 2 (0.5 where undefined)."""
    n = ctrl.shape[0]
    legs = np.linalg.norm(np.diff(ctrl, axis=0), axis=1)  # legs[j] = |Q_{j+1} - Q_j| = L_{j+1}
    t = np.full(n, 0.5)
    if closed:
        closing = np.linalg.norm(ctrl[0] - ctrl[-1])
        L = np.concatenate([[closing], legs])  # L[i] = |Q_i - Q_{i-1}|, cyclic
        Li, Li1 = L, np.roll(L, -1)
        idx = np.arange(n)
    else:
        Li, Li1 = legs[:-1], legs[1:]
        idx = np.arange(1, n - 1)
    s = Li + Li1
    ok = s > 0
    tt = np.full(idx.shape[0], 0.5)
    tt[ok] = Li1[ok] / s[ok]
    t[idx] = tt
    return t


@dataclass(frozen=True, eq=False)
class SecondDiscreteCurvature:
    """Second discrete curvature of a cubic B-spline's control polygon and its differences.

    Attributes
    ----------
    K : ndarray, shape (n,)
        ``K_i`` (Cheng & Yu, Definition 1, eq. (3)); signed for planar curves, unsigned in 3-D.
        Open curves: ``K_0 = K_{n-1} = 0`` by the paper's convention ``Q_{-1} = Q_0``,
        ``Q_n = Q_{n-1}`` (degenerate corner triangle, Proposition 2); they are no curvature of
        the curve.
    first_difference : ndarray, shape (n,)
        ``Delta K_i = K_i - K_{i-1}`` (Definition 2; ``Delta K_0 = 0`` for open curves, cyclic for
        closed ones).
    second_difference : ndarray, shape (n,)
        ``D_i = t_i K_{i-1} + (1 - t_i) K_{i+1} - K_i`` (Definition 2; ``D_0 = D_{n-1} = 0`` for
        open curves).
    weights : ndarray, shape (n,)
        ``t_i = L_{i+1} / (L_i + L_{i+1})`` (0.5 at open ends and where both legs vanish).
    params : ndarray, shape (n,)
        The joint ``u_{i+2}`` whose curve curvature ``K_i`` measures (Theorem 2).
    valid : ndarray of bool, shape (n,)
        Where ``D_i`` and the bad-point criteria involve only curvatures of the curve: every
        index of a closed curve, ``2 .. n-3`` of an open one (they avoid the conventional
        ``K_0``, ``K_{n-1}``).
    indicator : float
        The whole-curve fairing indicator ``x = sum D_i**2`` over the valid indices.
    closed : bool
    """

    K: FloatArray
    first_difference: FloatArray
    second_difference: FloatArray
    weights: FloatArray
    params: FloatArray
    valid: np.ndarray
    indicator: float
    closed: bool


def second_discrete_curvature(curve: Any) -> SecondDiscreteCurvature:
    """Second discrete curvature ``K_i`` at the control points of a cubic B-spline, with the
    first and second differences (Cheng & Yu, Definitions 1 and 2).

    Parameters
    ----------
    curve : BSplineCurve
        Cubic, open (clamped) or closed (periodic), dim 2 or 3.

    Returns
    -------
    SecondDiscreteCurvature
        Arrays of shape ``(n,)`` for the ``n`` (distinct) control points, and the fairing
        indicator ``x = sum D_i**2``.

    Raises
    ------
    InputError
        Not a cubic :class:`~curvefair.BSplineCurve`; a knot of multiplicity 3 at a joint with a
        true corner (the value does not exist there).

    Notes
    -----
    Cutting the corners of the control polygon with ``l_i = (u_{i+3} - u_{i+2}) / (u_{i+3} - u_i)``
    and ``m_i = (u_{i+2} - u_{i+1}) / (u_{i+4} - u_{i+1})``::

        K_i = D(Q_{i-1}, Q_i, Q_{i+1}) / |l_i (Q_i - Q_{i-1}) + m_i (Q_{i+1} - Q_i)|**3      (3)

    with ``D`` the signed triangle area (ERRATA: Theorem 2 holds with the area, not twice it).
    Theorem 2: at the joint ``u_{i+2}`` the curve's curvature ``k_i`` satisfies
    ``K_i = 3 (u_{i+3} - u_i)(u_{i+4} - u_{i+1}) / (4 (u_{i+3} - u_{i+1})**2) k_i``, i.e.
    ``K_i = 27 k_i / 16`` for uniform knots. The theorem holds for any knot vector at a simple
    knot (the curve is C2 there). At a double knot ``u_j = u_{j+1}`` the curve is only C1; there
    ``K_{j-2}`` matches the curvature from the left and ``K_{j-1}`` the one from the right.
    In 3-D ``D`` is the unsigned area ``|e_i x e_{i+1}| / 2`` and ``K_i >= 0`` matches the unsigned
    curvature. Definition 2: ``Delta K_i = K_i - K_{i-1}``,
    ``D_i = t_i K_{i-1} + (1 - t_i) K_{i+1} - K_i`` with ``t_i = L_{i+1} / (L_i + L_{i+1})``,
    ``L_i = |Q_i - Q_{i-1}|``. Indices are 0-based like the paper's ``Q_0 .. Q_n``.

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import BSplineCurve
    >>> a = np.linspace(0, 2 * np.pi, 13)[:-1]
    >>> c = BSplineCurve(np.c_[np.cos(a), np.sin(a)], np.arange(13.0), 3, closed=True)
    >>> s = second_discrete_curvature(c)
    >>> bool(np.allclose(s.K, s.K[0])), bool(np.allclose(s.second_difference, 0))
    (True, True)
    """
    curve = check_cubic_bspline(curve, "second_discrete_curvature")
    ctrl = np.asarray(curve.control_points, dtype=float)
    n = ctrl.shape[0]
    closed = bool(curve.closed)
    knots = np.asarray(curve.knots, dtype=float)
    lw, mw = corner_cut_ratios(knots, n, closed)
    K = second_curvature_values(ctrl, lw, mw, closed)
    t = _difference_weights(ctrl, closed)
    dK = np.zeros(n)
    D = np.zeros(n)
    valid = np.zeros(n, dtype=bool)
    if closed:
        dK = K - np.roll(K, 1)
        D = t * np.roll(K, 1) + (1.0 - t) * np.roll(K, -1) - K
        valid[:] = True
        params = knots[np.arange(n) + 2].copy()
        params[0] = knots[n + 2]
    else:
        dK[1:] = np.diff(K)
        D[1:-1] = t[1:-1] * K[:-2] + (1.0 - t[1:-1]) * K[2:] - K[1:-1]
        valid[2:n - 2] = True
        params = knots[np.arange(n) + 2].copy()
    x = float(np.sum(D[valid] ** 2))
    return SecondDiscreteCurvature(
        K=_readonly(K), first_difference=_readonly(dK), second_difference=_readonly(D),
        weights=_readonly(t), params=_readonly(params), valid=_readonly(valid),
        indicator=x, closed=closed,
    )


# --------------------------------------------------------------------------------------------
# bad points
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class BadPoint:
    """One bad control point (Cheng & Yu, section "Smoothing criterion").

    Attributes
    ----------
    index : int
        0-based control point index ``i``.
    kind : int
        The first kind that applies: 1 (curvature sign change, an extra inflection),
        2 (curvature extreme: ``Delta K`` changes sign), 3 (convexity condition violated).
    value : float
        Local fairing value ``z_i = D_i**2``.
    kinds : tuple of int
        Every kind that applies, increasing.
    """

    index: int
    kind: int
    value: float
    kinds: tuple[int, ...]


def bad_point_kinds(K: FloatArray, dK: FloatArray, t: FloatArray, valid: np.ndarray,
                    closed: bool) -> FloatArray:
    """Boolean ``(3, n)`` array: row ``k-1`` flags bad points of kind ``k`` (vectorised)."""
    Kp = np.roll(K, 1)
    Kn = np.roll(K, -1)
    dKn = np.roll(dK, -1)
    k1 = (K * Kn <= 0.0) & (Kp * K > 0.0)
    k2 = dK * dKn < 0.0
    same = ((Kp > 0) & (K > 0) & (Kn > 0)) | ((Kp < 0) & (K < 0) & (Kn < 0))
    k3 = same & ~(np.abs(K) > 0.5 * ((1.0 - t) * np.abs(Kp) + t * np.abs(Kn)))
    return np.stack([k1, k2, k3]) & valid[None, :]


def bad_points(curve: Any) -> list[BadPoint]:
    """The bad control points of a cubic B-spline, ranked by ``z_i = D_i**2`` (Cheng & Yu).

    Parameters
    ----------
    curve : BSplineCurve
        Cubic, open or closed.

    Returns
    -------
    list of BadPoint
        Sorted by decreasing ``value`` (ties: smaller index first). Each control point appears
        once, with every kind that applies.

    Notes
    -----
    With ``K_i`` and its differences from :func:`second_discrete_curvature`, control point ``i``
    is bad of

    1. the first kind if ``K_i K_{i+1} <= 0`` and ``K_{i-1} K_i > 0`` (the curvature changes sign
       after the joint ``u_{i+2}``: an extra inflection);
    2. the second kind if ``Delta K_i Delta K_{i+1} < 0`` (a curvature extreme at ``u_{i+2}``);
    3. the third kind if ``K_{i-1}``, ``K_i``, ``K_{i+1}`` have one strict sign and the convexity
       condition ``K_i > [(1 - t_i) K_{i-1} + t_i K_{i+1}] / 2`` fails -- applied to ``|K|`` so that
       the criterion does not depend on the orientation (as printed the condition assumes
       positive curvature). The weights are as printed (note they are swapped with respect to
       ``D_i``).

    Only the indices flagged ``valid`` by :func:`second_discrete_curvature` are examined (open
    curves: ``2 .. n-3``, so the conventional end values ``K_0 = K_{n-1} = 0`` never create bad
    points). In 3-D, ``K >= 0`` and kind 1 only flags exact zeros. The local fairing value is
    ``z_i = D_i**2`` and the whole-curve indicator ``x = sum z_i`` (section "Fairing algorithm").

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import BSplineCurve
    >>> a = np.linspace(0, 2 * np.pi, 13)[:-1]
    >>> pts = np.c_[np.cos(a), np.sin(a)]
    >>> pts[4] *= 1.2                       # a bump
    >>> c = BSplineCurve(pts, np.arange(13.0), 3, closed=True)
    >>> [(b.index, b.kind) for b in bad_points(c)][:1]
    [(4, 2)]
    """
    sdc = second_discrete_curvature(curve)
    flags = bad_point_kinds(sdc.K, sdc.first_difference, sdc.weights, sdc.valid, sdc.closed)
    idx = np.flatnonzero(flags.any(axis=0))
    z = sdc.second_difference[idx] ** 2
    order = np.lexsort((idx, -z))
    idx, z = idx[order], z[order]
    # the kinds of a point as a 3-bit code (bit k-1: kind k), one tuple per code
    code = flags[0, idx] + 2 * flags[1, idx].astype(np.int8) + 4 * flags[2, idx].astype(np.int8)
    table = [tuple(k + 1 for k in range(3) if c >> k & 1) for c in range(8)]
    return [BadPoint(index=i, kind=table[c][0], value=v, kinds=table[c])
            for i, c, v in zip(idx.tolist(), code.tolist(), z.tolist(), strict=True)]


#: control points per block of :func:`bad_point_count` and :func:`fairing_indicator` on open
#: curves
COUNT_BLOCK = 65_536


def _open_blocks(curve: Any) -> Iterator[tuple[FloatArray, FloatArray]]:
    """``(K, t)`` of an open cubic B-spline block by block, for the points ``a .. b-1`` of each
    block of the valid range ``2 .. n-3`` with one point either side (``K`` and ``t`` of the
    points ``a-1 .. b``): the kinds and ``D_i`` of point ``i`` depend on control points
    ``i-2 .. i+2`` only, and each value is computed elementwise by the same functions as for the
    whole curve (the same bits). A corner raises the whole curve's error (naming the control
    point)."""
    n = curve.n_ctrl
    ctrl = np.asarray(curve.control_points, dtype=float)
    lw, mw = corner_cut_ratios(np.asarray(curve.knots, dtype=float), n, False)
    try:
        for a in range(2, n - 2, COUNT_BLOCK):
            b = min(a + COUNT_BLOCK, n - 2)
            # the interior of control points a-2 .. b+1: points a-1 .. b
            K = second_curvature_values(ctrl[a - 2:b + 2], lw[a - 2:b + 2], mw[a - 2:b + 2],
                                        False)[1:-1]
            yield K, _difference_weights(ctrl[a - 2:b + 2], False)[1:-1]
    except InputError:  # a corner: the whole curve's message (with the control point)
        second_discrete_curvature(curve)
        raise


def bad_point_count(curve: Any) -> int:
    """The number of bad control points of a cubic B-spline: ``len(bad_points(curve))``
    without a Python object per point (what a fairing report states). An open curve is counted
    block by block (the temporaries of one block instead of several times the coordinates'
    bytes), a closed one on the whole curve."""
    return _indicator_and_count(curve, "bad_point_count", False, True)[1]


def fairing_indicator(curve: Any) -> float:
    """Cheng & Yu's fairing indicator ``x = sum D_i**2`` of a cubic B-spline: bit for bit
    ``second_discrete_curvature(curve).indicator``, without its per-point arrays. An open
    curve's ``D_i**2`` are written block by block into one array, summed as that attribute
    sums them (numpy's pairwise sum of the same values in the same order)."""
    return _indicator_and_count(curve, "fairing_indicator", True, False)[0]


def cheng_yu_figures(curve: Any) -> tuple[float, int]:
    """``(fairing_indicator(curve), bad_point_count(curve))`` in one pass over the curve: the
    second discrete curvature of each block is computed once for both (each figure by the
    same operations as alone, so the same bits). What the ``cheng-yu`` method reports of its
    input and its result."""
    return _indicator_and_count(curve, "cheng_yu_figures", True, True)


def _indicator_and_count(curve: Any, name: str, want_x: bool,
                         want_count: bool) -> tuple[float, int]:
    curve = check_cubic_bspline(curve, name)
    if curve.closed or curve.n_ctrl < 5:  # (no block: the whole curve's checks)
        sdc = second_discrete_curvature(curve)
        count = 0
        if want_count:
            flags = bad_point_kinds(sdc.K, sdc.first_difference, sdc.weights, sdc.valid, True)
            count = int(np.count_nonzero(flags.any(axis=0)))
        return (sdc.indicator if want_x else 0.0), count
    n = curve.n_ctrl
    z = np.empty(max(n - 4, 0) if want_x else 0)
    j = 0
    count = 0
    for K, t in _open_blocks(curve):
        if want_count:
            dK = np.zeros_like(K)
            dK[1:] = np.diff(K)
            valid = np.ones(K.shape[0], dtype=bool)
            valid[0] = valid[-1] = False
            flags = bad_point_kinds(K, dK, t, valid, False)
            count += int(np.count_nonzero(flags.any(axis=0)))
        if want_x:
            m = K.shape[0] - 2
            D = z[j:j + m]
            np.multiply(t[1:-1], K[:-2], out=D)
            D += (1.0 - t[1:-1]) * K[2:]
            D -= K[1:-1]
            np.multiply(D, D, out=D)
            j += m
    return (float(np.sum(z)) if want_x else 0.0), count
