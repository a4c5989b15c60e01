"""Farin's knot removal and reinsertion (seed 004, eqs. (8.19)-(8.30)) and the Sapidis-Farin loop.

Removing a simple interior knot ``t_j`` and inserting it again leaves the knot vector unchanged
but makes the curve ``C^p`` (a single polynomial) across ``t_j``: the jump of the ``p``-th
derivative there vanishes. For a cubic this is the jump of ``r'''`` that drives the jump of
``d kappa / ds`` (Sapidis & Farin's fairness measure).

Indices are 0-based. ``j`` indexes the knot vector :attr:`BSplineCurve.knots`: for an open curve
``degree + 1 <= j <= n - 1`` (the interior knots), for a closed curve ``degree <= j <= degree +
n - 1`` (one period; ``j = degree`` is the seam). Works for any degree ``p >= 2``.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from .._typing import FloatArray
from .._validate import as_nonnegative, as_step_count
from ..curves.bspline import BSplineCurve, basis_derivatives
from ..errors import InputError
from .eck_hadenfeld import check_bspline, movable_mask
from .ranking import tt_build, tt_top, tt_update

__all__ = ["knot_removal", "knot_jumps", "interior_knots", "knot_removal_fair", "KRResult"]

Variant = Literal["one-point", "least-squares"]
VARIANTS = ("one-point", "least-squares")


# ------------------------------------------------------------------------------------------
# knots and jump coefficients
# ------------------------------------------------------------------------------------------
def interior_knots(curve: BSplineCurve) -> np.ndarray:
    """Knot-vector indices ``j`` of the knots a removal can act on (see the module docstring),
    simple knots only (a multiple knot has no single removable copy here)."""
    t = curve.knots
    p = curve.degree
    n = curve.n_ctrl
    j = np.arange(p, p + n) if curve.closed else np.arange(p + 1, n)
    if j.size == 0:
        return j
    simple = (t[j - 1] < t[j]) & (t[j] < t[j + 1])
    return j[simple]


def _check_knot(curve: BSplineCurve, j: object) -> int:
    if isinstance(j, bool) or not isinstance(j, (int, np.integer)):
        raise InputError(f"j must be an integer knot index, got {j!r}")
    j = int(j)
    p, n = curve.degree, curve.n_ctrl
    if curve.closed and n < p + 2:
        raise InputError(f"knot removal on a closed curve needs at least degree + 2 = {p + 2} "
                         f"control points, got {n}")
    lo, hi = (p, p + n - 1) if curve.closed else (p + 1, n - 1)
    if not lo <= j <= hi:
        raise InputError(f"j = {j} is not an interior knot index: valid knots[{lo}..{hi}] "
                         f"({'one period of a closed' if curve.closed else 'an open'} curve)")
    t = curve.knots
    if not (t[j - 1] < t[j] < t[j + 1]):
        raise InputError(f"knots[{j}] = {float(t[j])!r} is a multiple knot; knot removal acts on "
                         "simple knots")
    return j


def _jump_coefficients(curve: BSplineCurve, js: np.ndarray) -> FloatArray:
    """``c[k, a]``: jump of ``N_{j-p-1+a}^(p)`` at ``t_j`` (``a = 0 .. p+1``) for ``j = js[k]``.

    The jump of the ``p``-th derivative of the curve is ``sum_a c[k, a] d_{j-p-1+a}``.
    """
    p = curve.degree
    t = np.asarray(curve.knots)
    js = np.asarray(js, dtype=np.int64)
    right = basis_derivatives(t, p, js, np.zeros(js.size), p, local=True)[:, p, :]
    left = basis_derivatives(t, p, js - 1, t[js] - t[js - 1], p, local=True)[:, p, :]
    c = np.zeros((js.size, p + 2))
    c[:, 1:] += right  # N_{j-p} .. N_j
    c[:, :-1] -= left  # N_{j-1-p} .. N_{j-1}
    return c


def _alphas(t: FloatArray, j: int, p: int) -> FloatArray:
    """Boehm's insertion ratios for re-inserting ``t_j``: ``alpha_i = (t_j - t_i) /
    (t_{i+p+1} - t_i)`` for ``i = j-p .. j-1`` (seed 004 eq. (8.30), in the indices of the
    full knot vector)."""
    i = np.arange(j - p, j)
    return (t[j] - t[i]) / (t[i + p + 1] - t[i])


# ------------------------------------------------------------------------------------------
# the step
# ------------------------------------------------------------------------------------------
def _one_point_index(c: FloatArray, j: int, p: int) -> int:
    """Basis index ``m`` of the control point the one-point variant moves: the middle of
    ``d_{j-p} .. d_{j-1}`` (cubic: ``j - 2``, Farin); for even degree, of the two middle ones the
    one with the larger jump coefficient (the smaller move)."""
    if p % 2 == 1:
        return j - (p + 1) // 2
    m1, m2 = j - p // 2 - 1, j - p // 2
    a1, a2 = m1 - (j - p - 1), m2 - (j - p - 1)
    return m1 if abs(c[a1]) >= abs(c[a2]) else m2


def _removal_moves(curve: BSplineCurve, d: FloatArray, j: int, variant: str,
                   c: FloatArray | None = None) -> tuple[np.ndarray, FloatArray]:
    """Control indices and their new positions for removing and reinserting ``t_j``."""
    p = curve.degree
    t = np.asarray(curve.knots)
    if variant == "one-point":
        if c is None:
            c = _jump_coefficients(curve, np.array([j]))[0]
        m = _one_point_index(c, j, p)
        basis = np.arange(j - p - 1, j + 1)
        idx = curve.control_index(basis)
        a = m - (j - p - 1)
        jump = c @ d[idx]
        new = d[idx[a]] - jump / c[idx == idx[a]].sum()  # closed: wrapped copies add up
        return np.array([idx[a]]), new[None, :]
    # least squares, seed 004 eqs. (8.24)-(8.28): unknowns P_{j-p} .. P_{j-2} of the curve
    # without t_j, equations alpha_i P_i + (1 - alpha_i) P_{i-1} = Q_i for i = j-p .. j-1,
    # knowns P_{j-p-1} = Q_{j-p-1} and P_{j-1} = Q_j
    al = _alphas(t, j, p)
    Q = d[curve.control_index(np.arange(j - p - 1, j + 1))]  # Q_{j-p-1} .. Q_j
    A = np.zeros((p, p - 1))
    f = np.array(Q[1:p + 1], dtype=float)  # Q_{j-p} .. Q_{j-1}
    for r in range(p):  # equation i = j - p + r
        if r <= p - 2:
            A[r, r] = al[r]  # P_i, unknown number r
        else:
            f[r] -= al[r] * Q[p + 1]  # P_{j-1} = Q_j
        if r >= 1:
            A[r, r - 1] = 1.0 - al[r]  # P_{i-1}, unknown number r - 1
        else:
            f[r] -= (1.0 - al[r]) * Q[0]  # P_{j-p-1} = Q_{j-p-1}
    P, *_ = np.linalg.lstsq(A, f, rcond=None)
    Pfull = np.vstack([Q[:1], P, Q[p + 1:]])  # P_{j-p-1} .. P_{j-1}
    new = al[:, None] * Pfull[1:] + (1.0 - al[:, None]) * Pfull[:-1]  # eq. (8.23)
    return curve.control_index(np.arange(j - p, j)), new


def knot_removal(curve: BSplineCurve, j: int, variant: Variant = "one-point") -> BSplineCurve:
    """Remove the interior knot ``t_j`` and insert it again (Farin's fairing step).

    Parameters
    ----------
    curve : BSplineCurve
        Any degree ``p >= 2``, open or closed.
    j : int
        Index into ``curve.knots`` of a simple interior knot (see the module docstring).
    variant : {"one-point", "least-squares"}
        ``"one-point"``: only ``d_{j-(p+1)/2}`` moves (cubic: ``d_{j-2}``) and the curve becomes
        ``C^p`` at ``t_j``. ``"least-squares"``: the removal system (8.24) solved in the least
        squares sense (8.26)-(8.28), then reinsertion (8.29)-(8.30); ``p`` control points move,
        the curve becomes ``C^p`` at ``t_j`` as well.

    Returns
    -------
    BSplineCurve
        Same knots.

    Notes
    -----
    One-point, cubic (ERRATA, from seed 004 (8.23)-(8.25)):
    ``l_j = [(t_{j+1} - t_{j-3}) d_{j-3} - (t_{j+1} - t_j) d_{j-4}] / (t_j - t_{j-3})``,
    ``r_j = [(t_{j+3} - t_{j-1}) d_{j-1} - (t_j - t_{j-1}) d_j] / (t_{j+3} - t_j)``,
    ``d~_{j-2} = [(t_{j+2} - t_j) l_j + (t_j - t_{j-2}) r_j] / (t_{j+2} - t_{j-2})``; uniform
    knots: ``(-d_{j-4} + 4 d_{j-3} + 4 d_{j-1} - d_j) / 6``. For any degree the same result is
    the unique position of that one control point that zeroes the jump of ``r^(p)`` at ``t_j``
    (a spline that is ``C^p`` at a simple knot lies in the space without it), which is how it
    is computed here: ``d~_m = d_m - J / c_m`` with ``J = sum_i c_i d_i`` the jump and ``c_i`` the
    jumps of ``N_i^(p)``.

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import BSplineCurve, steps
    >>> d = np.c_[np.arange(9.0), np.zeros(9)]
    >>> d[4, 1] = 6.0
    >>> c = BSplineCurve(d, np.r_[0, 0, 0, np.arange(7.0), 6, 6, 6], 3)
    >>> float(steps.knot_removal(c, 6).control_points[4, 1])   # (-0 + 4*0 + 4*0 - 0) / 6
    0.0
    """
    curve = check_bspline(curve)
    if not isinstance(variant, str) or variant not in VARIANTS:
        raise InputError(f"unknown variant {variant!r}; valid values are: "
                         + ", ".join(repr(v) for v in VARIANTS))
    j = _check_knot(curve, j)
    d = np.array(curve.control_points)
    idx, new = _removal_moves(curve, d, j, variant)
    d[idx] = new
    return curve.replace(control_points=d)


# ------------------------------------------------------------------------------------------
# the Sapidis-Farin measure
# ------------------------------------------------------------------------------------------
class _KnotData:
    """Per-knot basis data for fast local recomputation of the jumps (depends on knots only)."""

    def __init__(self, curve: BSplineCurve) -> None:
        p = curve.degree
        t = np.asarray(curve.knots)
        self.p = p
        self.js = interior_knots(curve)
        js = self.js
        self.c = _jump_coefficients(curve, js)  # (k, p+2)
        # right-limit r', r'' at t_j from span j: N_{j-p..j}; left limit r'' from span j-1
        self.right = basis_derivatives(t, p, js, np.zeros(js.size), 2, local=True)[:, 1:3, :]
        self.left2 = basis_derivatives(t, p, js - 1, t[js] - t[js - 1], 2,
                                       local=True)[:, 2, :]
        self.ctrl = curve.control_index(js[:, None] + np.arange(-p - 1, 1)[None, :])  # (k, p+2)

    def jumps(self, d: FloatArray, k: np.ndarray | slice = slice(None)) -> FloatArray:
        """Sapidis-Farin measure at knots ``js[k]``."""
        p = self.p
        Q = d[self.ctrl[k]]  # (m, p+2, dim)
        J = np.einsum("ma,mad->md", self.c[k], Q)
        r1 = np.einsum("ma,mad->md", self.right[k][:, 0, :], Q[:, 1:, :])
        r2 = np.einsum("ma,mad->md", self.right[k][:, 1, :], Q[:, 1:, :])
        l2 = np.einsum("ma,mad->md", self.left2[k], Q[:, :-1, :])
        return sapidis_measure(r1, r2, l2, J, p)


def _cross(a: FloatArray, b: FloatArray) -> FloatArray:
    if a.shape[-1] == 2:
        return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return np.cross(a, b)


def sapidis_measure(r1: FloatArray, r2_right: FloatArray, r2_left: FloatArray,
                    J: FloatArray, p: int) -> FloatArray:
    """Jump of ``d^(p-2) kappa / ds^(p-2)`` at knots from the one-sided derivatives.

    ``p = 3``: the jump of ``d kappa / ds``; planar ``|r' x [r''']| / |r'|^4`` (ERRATA). In general
    only the highest derivative jumps (``[r^(p)] = J``), so the jump is
    ``b . (r' x J) / |r'|^(p+1)`` with ``b`` the unit binormal (planar: the signed form);
    at an inflection of a 3-D curve (``r' x r'' = 0``) ``|r' x J| / |r'|^(p+1)``.
    ``p = 2`` (curvature itself jumps): ``|kappa+ - kappa-|``.
    """
    speed = np.sqrt(np.sum(r1 * r1, axis=-1))
    speed = np.where(speed > 0, speed, np.inf)  # a stationary point carries no curvature jump
    if p == 2:
        r2r = r2_right
        if r1.shape[-1] == 2:
            return np.abs(_cross(r1, r2r) - _cross(r1, r2_left)) / speed**3
        kr = np.linalg.norm(np.cross(r1, r2r), axis=-1)
        kl = np.linalg.norm(np.cross(r1, r2_left), axis=-1)
        return np.abs(kr - kl) / speed**3
    cj = _cross(r1, J)
    if r1.shape[-1] == 2:
        return np.abs(cj) / speed ** (p + 1)
    b = np.cross(r1, r2_right)
    nb = np.linalg.norm(b, axis=-1)
    scale = np.linalg.norm(r1, axis=-1) * np.linalg.norm(r2_right, axis=-1)
    ok = nb > 1e-12 * scale
    proj = np.abs(np.sum(b * cj, axis=-1)) / np.where(ok, nb, 1.0)
    full = np.linalg.norm(cj, axis=-1)
    return np.where(ok, proj, full) / speed ** (p + 1)


def knot_jumps(curve: BSplineCurve) -> tuple[np.ndarray, FloatArray]:
    """Sapidis-Farin ranking numbers of the removable knots.

    Returns
    -------
    js : int ndarray
        Knot indices (:func:`interior_knots`).
    z : ndarray
        ``z_j = |kappa_s(t_j+) - kappa_s(t_j-)|``, the jump of the arc-length derivative of the
        curvature (cubics; see :func:`sapidis_measure` for other degrees).

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import interpolate_bspline
    >>> from curvefair.fairing.knot_removal import knot_jumps
    >>> from curvefair.fairing.knot_removal import knot_removal
    >>> th = np.linspace(0, 3, 12)
    >>> c = interpolate_bspline(np.c_[np.cos(th), np.sin(th)])
    >>> js, z = knot_jumps(c)
    >>> k = int(np.argmax(z))                     # the worst knot ...
    >>> z2 = knot_jumps(knot_removal(c, int(js[k])))[1]
    >>> bool(z2[k] < 1e-9 * z[k])                 # ... has no jump after removal
    True
    """
    curve = check_bspline(curve)
    kd = _KnotData(curve)
    return kd.js.copy(), kd.jumps(np.asarray(curve.control_points))


# ------------------------------------------------------------------------------------------
# the automatic loop
# ------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class KRResult:
    """Outcome of :func:`knot_removal_fair`.

    Attributes
    ----------
    curve : BSplineCurve
    steps : int
    stop_reason : str
        ``"eps"``, ``"no_decrease"`` (the last removal did not lower ``sum z``; it was undone),
        ``"tolerance"`` (every knot left is blocked by the tolerance or protected points),
        ``"max_steps"``, ``"no_knots"``.
    sum_before, sum_after : float
        ``sum_j z_j`` of the input and of the result.
    history : ndarray, shape (steps, 3)
        ``(knot index j, z_j, largest control point move of that step)``.
    blocked : list of int
        Knots skipped because their removal would break the tolerance or move a protected point.
    sum_tracked : float
        ``sum z_j`` as maintained by the loop's local updates (equals ``sum_after`` up to
        rounding; kept for checking).
    """

    curve: BSplineCurve
    steps: int
    stop_reason: str
    sum_before: float
    sum_after: float
    history: np.ndarray
    blocked: list[int] = field(default_factory=list)
    sum_tracked: float = 0.0


def knot_removal_fair(curve: BSplineCurve, *, variant: Variant = "one-point",
                      tol: float | None = None, eps: float | None = None,
                      eps_relative: bool = True, max_steps: int | None = None,
                      clamp: Any = (None, None), protect: Iterable[int] = (),
                      on_tol: Literal["skip", "stop"] = "skip") -> KRResult:
    """Sapidis-Farin automatic fairing by knot removal and reinsertion.

    Parameters
    ----------
    curve : BSplineCurve
    variant : {"one-point", "least-squares"}
        The removal step (:func:`knot_removal`).
    tol : float or None
        No control point ends farther than ``tol`` from its ORIGINAL position, so by the convex
        hull property (seed 004 eqs. (8.34)-(8.36)) the curve deviates at most ``tol`` at equal
        parameter.
    eps : float, optional
        Stop when the largest ``z_j`` is below ``eps * max z_j(input)`` (``eps_relative``,
        default ``1e-6``) or below ``eps``.
    max_steps : int, optional
        Default ``10 * number of interior knots``.
    clamp, protect
        As for :func:`~curvefair.fairing.eck_hadenfeld.movable_mask`; a removal that would move
        a fixed control point is not made.
    on_tol : {"skip", "stop"}
        A removal that would break the tolerance (or move a fixed point): ``"skip"`` that knot and
        go on with the next worst (default), or ``"stop"`` the loop.

    Returns
    -------
    KRResult

    Notes
    -----
    Sapidis & Farin's loop as summarised in ERRATA: rank the simple interior knots by
    ``z_j = |kappa_s(t_j+) - kappa_s(t_j-)|`` (planar closed form ``|r' x [r''']| / |r'|^4``),
    remove and reinsert the worst, recompute ``z`` at the knots whose basis functions share a
    moved control point, and stop when ``sum z_j`` stops decreasing (the last step is undone),
    at the step cap, or at the tolerance.

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import interpolate_bspline
    >>> from curvefair.fairing.knot_removal import knot_removal_fair
    >>> x = np.linspace(0, 6, 30)
    >>> c = interpolate_bspline(np.c_[x, np.sin(x) + 0.02 * np.cos(17 * x)])
    >>> res = knot_removal_fair(c, tol=0.05, clamp="g2")
    >>> bool(res.sum_after < res.sum_before)
    True
    """
    curve = check_bspline(curve)
    if not isinstance(variant, str) or variant not in VARIANTS:
        raise InputError(f"unknown variant {variant!r}; valid values are: "
                         + ", ".join(repr(v) for v in VARIANTS))
    if on_tol not in ("skip", "stop"):
        raise InputError(f"on_tol must be 'skip' or 'stop', got {on_tol!r}")
    tolv = as_nonnegative(tol, "tol", none_means=np.inf)
    mask = movable_mask(curve, clamp, protect)
    kd = _KnotData(curve)
    js = kd.js
    nk = js.size
    d = np.array(curve.control_points)
    orig = d.copy()
    max_steps = as_step_count(max_steps, default=10 * nk)
    if nk == 0:
        return KRResult(curve, 0, "no_knots", 0.0, 0.0, np.zeros((0, 3)))
    z = kd.jumps(d)
    sum0 = float(z.sum())
    epsv = (1e-6 if eps_relative else 0.0) if eps is None else as_nonnegative(eps, "eps")
    eps_abs = epsv * float(z.max()) if eps_relative else epsv
    # knot j's measure depends on the control points of basis functions j-p-1 .. j, so a moved
    # control point i touches the knots j = b .. b+p+1 for every basis index b of i
    p = curve.degree
    n = curve.n_ctrl
    pos = np.full(len(curve.knots), -1, dtype=np.int64)
    pos[js] = np.arange(nk)

    def touched_knots(idx: np.ndarray) -> np.ndarray:
        jj = (idx[:, None] + np.arange(p + 2)[None, :]).ravel()
        if curve.closed:
            jj = p + (jj - p) % n  # the period's copy of each knot
        jj = jj[(jj >= 0) & (jj < pos.size)]
        kk = pos[jj]
        return np.unique(kk[kk >= 0])
    rank = z.copy()
    tv, ti = tt_build(rank)  # indexed tournament tree: O(log N) per update
    blocked: list[int] = []
    hist: list[tuple[int, float, float]] = []
    total = sum0
    steps = 0
    reason = "max_steps"
    while steps < max_steps:
        k, zk = tt_top(tv, ti)
        k, zk = int(k), float(zk)
        if zk < 0:  # every knot blocked
            reason = "tolerance"
            break
        if zk <= eps_abs or zk == 0.0:
            reason = "eps"
            break
        j = int(js[k])
        idx, new = _removal_moves(curve, d, j, variant, kd.c[k])
        ok = bool(np.all(mask[idx]))
        if ok and tolv < np.inf:
            ok = bool(np.all(np.sqrt(np.sum((new - orig[idx]) ** 2, axis=1)) <= tolv))
        if not ok:
            if on_tol == "stop":
                reason = "tolerance"
                break
            rank[k] = -1.0
            tt_update(tv, ti, k, -1.0)
            blocked.append(j)
            continue
        old = d[idx].copy()
        d[idx] = new
        tk = touched_knots(np.asarray(idx, dtype=np.int64))
        znew = kd.jumps(d, tk)
        new_total = total - float(z[tk].sum()) + float(znew.sum())
        if new_total >= total:
            d[idx] = old
            reason = "no_decrease"
            break
        total = new_total
        z[tk] = znew
        for kk, zz in zip(tk.tolist(), znew.tolist(), strict=True):
            if rank[kk] >= 0:
                rank[kk] = zz
                tt_update(tv, ti, kk, zz)
        # a move can unblock nothing: blocked knots stay blocked (their z may change, the
        # tolerance they would break is measured from the original points)
        steps += 1
        hist.append((j, zk, float(np.sqrt(np.sum((new - old) ** 2, axis=1)).max())))
    out = curve.replace(control_points=d)
    h = np.array(hist, dtype=float).reshape(-1, 3)
    return KRResult(out, steps, reason, sum0, float(kd.jumps(d).sum()), h, blocked, total)


# ------------------------------------------------------------------------------------------
# registration with fair()
# ------------------------------------------------------------------------------------------
def _driver(curve: BSplineCurve, *, tol: float | None, eps: float | None, max_steps: int | None,
            clamp: Any, protect: Iterable[int], variant: Variant = "one-point",
            eps_relative: bool = True, on_tol: str = "skip") -> Any:
    from .fair import DriverOutput, FairingHistory

    res = knot_removal_fair(curve, variant=variant, tol=tol, eps=eps, eps_relative=eps_relative,
                            max_steps=max_steps, clamp=clamp, protect=protect,
                            on_tol=on_tol)  # type: ignore[arg-type]
    h = res.history
    # history index: the knot index j (the control points moved are listed in the report)
    hist = FairingHistory.from_arrays(h[:, 0].astype(np.int64), h[:, 1], h[:, 2])
    return DriverOutput(
        curve=res.curve, steps=res.steps, stop_reason=res.stop_reason, history=hist,
        eps=(1e-6 if eps_relative else 0.0) if eps is None else eps,
        max_steps=10 * interior_knots(curve).size if max_steps is None else max_steps,
        extra={"variant": variant, "sum_jump_before": res.sum_before,
               "sum_jump_after": res.sum_after, "blocked_knots": res.blocked,
               "history_index_is": "knot index j"})


def _register() -> None:
    from .fair import MethodSpec, register_method

    register_method(MethodSpec(
        name="knot-removal",
        curve_types=(BSplineCurve,),
        driver=_driver,
        summary="Farin / Sapidis-Farin: remove and reinsert the knot with the largest jump of "
                "d kappa/ds, while the sum of jumps decreases, within tol",
        source="seed 004 (lecture notes) eqs. (8.19)-(8.36); one-point formulas in ERRATA",
    ))


_register()
