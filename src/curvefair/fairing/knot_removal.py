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
from typing import TYPE_CHECKING, Any, Literal, cast

import numpy as np

from .._jit import njit
from .._kernels.ranking import tt_build, tt_update, tt_update_range
from .._typing import FloatArray
from .._validate import as_step_count
from ..curves.bspline import BSplineCurve, basis_derivatives
from ..errors import InputError
from .eck_hadenfeld import check_bspline
from .stop import StopReason

if TYPE_CHECKING:
    from .problem import FairingProblem, Outcome

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
        # one-sided basis derivatives at t_j up to order max(p, 2) (each order is bitwise the
        # same whatever the highest one asked): right limit from span j (N_{j-p..j}), left
        # limit from span j-1 (N_{j-1-p..j-1})
        nder = max(p, 2)
        right = basis_derivatives(t, p, js, np.zeros(js.size), nder, local=True)
        left = basis_derivatives(t, p, js - 1, t[js] - t[js - 1], nder, local=True)
        c = np.zeros((js.size, p + 2))  # as _jump_coefficients
        c[:, 1:] += right[:, p, :]
        c[:, :-1] -= left[:, p, :]
        self.c = c  # (k, p+2)
        self.right = np.ascontiguousarray(right[:, 1:3, :])  # r', r'' (right limits)
        self.left2 = np.ascontiguousarray(left[:, 2, :])  # r'' (left limit)
        self.ctrl = np.ascontiguousarray(  # (k, p+2)
            curve.control_index(js[:, None] + np.arange(-p - 1, 1)[None, :]), dtype=np.int64)

    def jumps(self, d: FloatArray, k: np.ndarray | slice = slice(None)) -> FloatArray:
        """Sapidis-Farin measure at knots ``js[k]``: :func:`sapidis_measure` of the one-sided
        derivatives, computed per knot by the same compiled scalar code as the loop's local
        updates (:func:`_knot_measure`), so the initial ranking and the updated one agree
        bitwise and neither depends on the CPU's SIMD width."""
        ks = np.ascontiguousarray(np.arange(self.js.size)[k], dtype=np.int64)
        out = np.empty(ks.size)
        _measure_all(np.ascontiguousarray(d, dtype=np.float64), ks, self.p, self.ctrl, self.c,
                     self.right, self.left2, out)
        return out


def _speed_power(speed: FloatArray, k: int) -> FloatArray:
    """``speed ** k`` for a whole ``k >= 1`` as ``k - 1`` multiplications in turn (the order of
    :func:`_ipow`): exactly rounded at each step, so it is the same on every CPU, unlike a
    vectorised ``pow``."""
    out = speed
    for _ in range(k - 1):
        out = out * speed
    return out


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
            return np.abs(_cross(r1, r2r) - _cross(r1, r2_left)) / _speed_power(speed, 3)
        kr = np.linalg.norm(np.cross(r1, r2r), axis=-1)
        kl = np.linalg.norm(np.cross(r1, r2_left), axis=-1)
        return np.abs(kr - kl) / _speed_power(speed, 3)
    cj = _cross(r1, J)
    if r1.shape[-1] == 2:
        return np.abs(cj) / _speed_power(speed, p + 1)
    b = np.cross(r1, r2_right)
    nb = np.linalg.norm(b, axis=-1)
    scale = np.linalg.norm(r1, axis=-1) * np.linalg.norm(r2_right, axis=-1)
    ok = nb > 1e-12 * scale
    proj = np.abs(np.sum(b * cj, axis=-1)) / np.where(ok, nb, 1.0)
    full = np.linalg.norm(cj, axis=-1)
    return np.where(ok, proj, full) / _speed_power(speed, p + 1)


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
        ``"tolerance"`` (every knot whose ``z`` is above the threshold is blocked by the
        tolerance or by fixed points),
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
    stop_reason: StopReason
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

    Ties and rounding (the same choices on every CPU): every ``z_j`` is computed by one compiled
    scalar routine in a fixed operation order, with ``|r'|^(p+1)`` as repeated multiplication
    (no vectorised ``pow``, no reassociation), so the ranking does not depend on the CPU's SIMD
    width. Equal ``z`` go to the smaller knot index. A ``z`` at or below :data:`ROUNDING_FLOOR`
    times the largest initial ``z`` is rounding noise and counts as zero (an ``eps`` stop, also
    when ``eps = 0``), and a step has to lower ``sum z_j`` by more than that floor, else the loop
    stops with ``no_decrease``: the loop never acts on a difference that rounding alone made.

    The loop is compiled (numba): the per-knot data that depends only on the knots (jump
    coefficients, one-sided basis derivative rows, Boehm's ratios) is set up vectorised, then
    each step costs the removal moves (one point, or a ``p x (p-1)`` least-squares solve), the
    measure at the ``<= 2p + 1`` touched knots and ``O(log N)`` updates of an indexed tournament
    tree (:mod:`curvefair._kernels.ranking`).

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
    from .problem import make_problem

    prob = make_problem(check_bspline(curve), tol=tol, eps=eps, max_steps=max_steps,
                        clamp=clamp, protect=protect)
    out = solve(prob, variant=variant, eps_relative=eps_relative, on_tol=on_tol)
    h = out.history
    assert h is not None
    hist = np.column_stack([h.index.astype(np.float64), h.measure, h.displacement])
    return KRResult(cast(BSplineCurve, out.curve), out.steps, out.stop_reason,
                    out.extra["sum_jump_before"], out.extra["sum_jump_after"],
                    hist.reshape(-1, 3), out.extra["blocked_knots"], out.extra["sum_tracked"])


def solve(problem: FairingProblem, *, variant: Variant = "one-point",
          eps_relative: bool = True, on_tol: str = "skip") -> Outcome:
    """Knot removal as a solver of ``problem`` (``fair(curve, "knot-removal")``): ``eps``
    relative to the largest initial jump ``max z_j`` (default ``1e-6``; ``eps_relative=False``:
    absolute, default 0). The history counts knots (index ``j`` of the knot vector)."""
    from .problem import FairingHistory, Outcome, eps_threshold

    curve = check_bspline(problem.curve)
    if not isinstance(variant, str) or variant not in VARIANTS:
        raise InputError(f"unknown variant {variant!r}; valid values are: "
                         + ", ".join(repr(v) for v in VARIANTS))
    if on_tol not in ("skip", "stop"):
        raise InputError(f"on_tol must be 'skip' or 'stop', got {on_tol!r}")
    tolv = problem.tol
    mask = problem.movable
    kd = _KnotData(curve)
    js = kd.js
    nk = js.size
    d = np.array(curve.control_points)
    orig = d.copy()
    max_steps = as_step_count(problem.max_steps, default=10 * nk)

    def outcome(c: BSplineCurve, steps: int, reason: StopReason, hist: FloatArray,
                epsv: float, eps_abs: float | None, sums: tuple[float, float, float],
                blocked: list[int]) -> Outcome:
        history = FairingHistory.from_arrays(hist[:, 0].astype(np.int64), hist[:, 1],
                                             hist[:, 2], "knot")
        return Outcome(
            curve=c, steps=steps, stop_reason=reason, history=history, eps=epsv,
            max_steps=max_steps, eps_absolute=eps_abs,
            extra={"variant": variant, "sum_jump_before": sums[0], "sum_jump_after": sums[1],
                   "sum_tracked": sums[2], "blocked_knots": blocked,
                   "history_index_is": "knot index j"})

    if nk == 0:
        e0 = (1e-6 if eps_relative else 0.0) if problem.eps is None else problem.eps
        return outcome(curve, 0, "no_knots", np.zeros((0, 3)), e0, None, (0.0, 0.0, 0.0), [])
    z = kd.jumps(d)
    sum0 = float(z.sum())
    if eps_relative:
        epsv, eps_abs = eps_threshold(problem.eps, float(z.max()), 1e-6)
    else:
        epsv = eps_abs = 0.0 if problem.eps is None else problem.eps
    floor = ROUNDING_FLOOR * float(z.max())
    out, steps, reason, total, hist, blocked = _run_loop(curve, kd, d, orig, mask, variant,
                                                         tolv, eps_abs, max_steps, on_tol, z,
                                                         floor)
    if reason == "eps" and blocked:
        # every knot still worth removing is blocked: the tolerance stopped the loop (as in
        # eck_hadenfeld_fair); the unblocked ones left are the removed knots, z ~ 0
        pos = np.searchsorted(js, np.asarray(blocked, dtype=np.int64))
        if float(kd.jumps(d, pos).max()) > eps_abs:
            reason = "tolerance"
    return outcome(out, steps, reason, hist, epsv, eps_abs,
                   (sum0, float(kd.jumps(d).sum()), total), blocked)


_REASONS: tuple[StopReason, ...] = ("max_steps", "tolerance", "eps", "no_decrease")

#: Relative rounding floor of the Sapidis-Farin loop: a jump at or below ``ROUNDING_FLOOR``
#: times the largest initial jump counts as zero (the loop stops there as at ``eps``), and a step
#: must lower the tracked sum by more than that much (else ``no_decrease``). ``2**-40`` is about
#: 4000 ulps: far above the rounding of the jumps, far below any jump that shows in a
#: curvature plot.
ROUNDING_FLOOR = 2.0 ** -40


def _run_loop(curve: BSplineCurve, kd: _KnotData, d: FloatArray, orig: FloatArray,
              mask: np.ndarray, variant: str, tolv: float, eps_abs: float, max_steps: int,
              on_tol: str, z: FloatArray, floor: float = 0.0
              ) -> tuple[BSplineCurve, int, StopReason, float, FloatArray, list[int]]:
    """Run the compiled loop on the set-up of :func:`_loop_args`; ``d`` is updated in place."""
    steps, code, total, hist, blocked, nb = _kr_loop(
        *_loop_args(curve, kd, d, orig, mask, variant, tolv, eps_abs, max_steps, on_tol, z,
                    floor))
    out = curve.replace(control_points=d)
    return (out, int(steps), _REASONS[code], float(total), hist[:steps].copy(),
            [int(j) for j in blocked[:nb]])


def _loop_args(curve: BSplineCurve, kd: _KnotData, d: FloatArray, orig: FloatArray,
               mask: np.ndarray, variant: str, tolv: float, eps_abs: float, max_steps: int,
               on_tol: str, z: FloatArray, floor: float = 0.0) -> tuple[Any, ...]:
    """Arguments of :func:`_kr_loop`: the per-knot data (vectorised, depends on the knots only),
    the ranking tree over ``z`` and the state (``d``, ``z`` are used in place); ``floor`` is the
    absolute rounding floor (:data:`ROUNDING_FLOOR` times the largest initial jump)."""
    p = curve.degree
    n = curve.n_ctrl
    js = kd.js
    nk = js.size
    t = np.asarray(curve.knots)
    pos = np.full(t.size, -1, dtype=np.int64)
    pos[js] = np.arange(nk)
    C = np.ascontiguousarray(kd.c)
    ctrl = np.ascontiguousarray(kd.ctrl, dtype=np.int64)
    # one-point: the moved basis function a (of j-p-1 .. j; _one_point_index) and the sum of
    # the jump coefficients of its control point (a closed curve's wrapped copies add up)
    if p % 2 == 1:
        a1 = np.full(nk, p + 1 - (p + 1) // 2, dtype=np.int64)
    else:
        h = p // 2
        a1 = np.where(np.abs(C[:, h]) >= np.abs(C[:, h + 1]), h, h + 1).astype(np.int64)
    rows = np.arange(nk)
    denom = np.where(ctrl == ctrl[rows, a1][:, None], C, 0.0).sum(axis=1)
    if variant == "least-squares":
        i = js[:, None] + np.arange(-p, 0)[None, :]  # Boehm ratios (_alphas), i = j-p .. j-1
        alphas = np.ascontiguousarray((t[js][:, None] - t[i]) / (t[i + p + 1] - t[i]))
    else:
        alphas = np.zeros((0, p))
    rank = z.copy()
    tv, ti = tt_build(rank)  # indexed tournament tree: O(log N) per update
    cap = int(min(max_steps, max(1024, 2 * nk)))
    return (d, orig, mask, float(tolv), p, n, bool(curve.closed), js, pos, C,
            np.ascontiguousarray(kd.right), np.ascontiguousarray(kd.left2), ctrl, a1, denom,
            alphas, variant == "least-squares", float(eps_abs), int(max_steps), on_tol == "stop",
            z, rank, tv, ti, float(z.sum()), cap, float(floor))


# ------------------------------------------------------------------------------------------
# the compiled loop
# ------------------------------------------------------------------------------------------
@njit(cache=True)
def _pw_sum_long(v, m):  # type: ignore[no-untyped-def]
    """numpy's pairwise summation above 128 values (recursive halves, multiples of 8)."""
    if m <= 128:
        return _pw_sum(v, m)
    m2 = m // 2
    m2 -= m2 % 8
    return _pw_sum_long(v[:m2], m2) + _pw_sum_long(v[m2:], m - m2)


@njit(cache=True, inline="always")
def _pw_sum(v, m):  # type: ignore[no-untyped-def]
    """``v[:m].sum()`` in numpy's order (pairwise summation: sequential below 8 values, eight
    accumulators up to 128), so that the tracked sum is bitwise the vectorised one."""
    if m < 8:
        res = 0.0
        for i in range(m):
            res += v[i]
        return res
    if m > 128:
        return _pw_sum_long(v, m)
    r0, r1, r2, r3 = v[0], v[1], v[2], v[3]
    r4, r5, r6, r7 = v[4], v[5], v[6], v[7]
    i = 8
    while i < m - (m % 8):
        r0 += v[i]
        r1 += v[i + 1]
        r2 += v[i + 2]
        r3 += v[i + 3]
        r4 += v[i + 4]
        r5 += v[i + 5]
        r6 += v[i + 6]
        r7 += v[i + 7]
        i += 8
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < m:
        res += v[i]
        i += 1
    return res


@njit(cache=True, inline="always")
def _ipow(x, k):  # type: ignore[no-untyped-def]
    """``x ** k`` for a whole ``k >= 1`` as ``k - 1`` multiplications in turn (no ``pow``: the
    same bits on every CPU; :func:`_speed_power` is its numpy twin)."""
    out = x
    for _ in range(k - 1):
        out = out * x
    return out


@njit(cache=True, inline="always")
def _knot_measure(d, k, p, ctrl, C, right, left2):  # type: ignore[no-untyped-def]
    """:meth:`_KnotData.jumps` / :func:`sapidis_measure` at one knot, same operation order."""
    num, speed = _measure_parts(d, k, p, ctrl, C, right, left2)
    return num / _ipow(speed, 3 if p == 2 else p + 1)


@njit(cache=True, inline="always")
def _measure_parts(d, k, p, ctrl, C, right, left2):  # type: ignore[no-untyped-def]
    """Numerator and ``|r'|`` (``inf`` if zero) of the measure at knot ``k``: the measure is
    ``num / speed ** (p + 1)`` (``p = 2``: ``** 3``); numpy's operation order."""
    dim = d.shape[1]
    J0 = J1 = J2 = 0.0
    a0 = a1 = a2 = 0.0  # r'
    b0 = b1 = b2 = 0.0  # r'' right
    l0 = l1 = l2 = 0.0  # r'' left
    for a in range(p + 2):
        q = ctrl[k, a]
        c = C[k, a]
        J0 += c * d[q, 0]
        J1 += c * d[q, 1]
        if dim == 3:
            J2 += c * d[q, 2]
    for a in range(p + 1):
        q = ctrl[k, a + 1]
        c = right[k, 0, a]
        a0 += c * d[q, 0]
        a1 += c * d[q, 1]
        c = right[k, 1, a]
        b0 += c * d[q, 0]
        b1 += c * d[q, 1]
        if dim == 3:
            a2 += right[k, 0, a] * d[q, 2]
            b2 += c * d[q, 2]
    if p == 2:
        for a in range(p + 1):
            q = ctrl[k, a]
            c = left2[k, a]
            l0 += c * d[q, 0]
            l1 += c * d[q, 1]
            if dim == 3:
                l2 += c * d[q, 2]
    if dim == 2:
        ss = a0 * a0 + a1 * a1
    else:
        ss = a0 * a0 + a1 * a1 + a2 * a2
    speed = np.sqrt(ss)
    if not speed > 0:
        speed = np.inf
    if p == 2:
        if dim == 2:
            return abs((a0 * b1 - a1 * b0) - (a0 * l1 - a1 * l0)), speed
        x0 = a1 * b2 - a2 * b1
        x1 = a2 * b0 - a0 * b2
        x2 = a0 * b1 - a1 * b0
        kr = np.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
        x0 = a1 * l2 - a2 * l1
        x1 = a2 * l0 - a0 * l2
        x2 = a0 * l1 - a1 * l0
        kl = np.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
        return abs(kr - kl), speed
    if dim == 2:
        return abs(a0 * J1 - a1 * J0), speed
    c0 = a1 * J2 - a2 * J1
    c1 = a2 * J0 - a0 * J2
    c2 = a0 * J1 - a1 * J0
    x0 = a1 * b2 - a2 * b1
    x1 = a2 * b0 - a0 * b2
    x2 = a0 * b1 - a1 * b0
    nb = np.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
    scale = np.sqrt(a0 * a0 + a1 * a1 + a2 * a2) * np.sqrt(b0 * b0 + b1 * b1 + b2 * b2)
    if nb > 1e-12 * scale:
        v = abs(x0 * c0 + x1 * c1 + x2 * c2) / nb
    else:
        v = np.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
    return v, speed


@njit(cache=True)
def _measure_all(d, ks, p, ctrl, C, right, left2, out):  # type: ignore[no-untyped-def]
    for u in range(ks.shape[0]):
        out[u] = _knot_measure(d, ks[u], p, ctrl, C, right, left2)


@njit(cache=True, inline="always")
def _ls_moves(d, k, p, ctrl, alphas, new, Q, A, f):  # type: ignore[no-untyped-def]
    """Least-squares removal (seed 004 eqs. (8.24)-(8.30)) at knot ``k``: the ``p`` new control
    points of basis functions ``j-p .. j-1`` into ``new``; ``Q`` (p+2, dim), ``A`` (p, p-1),
    ``f`` (p, dim) are work arrays. Householder QR of the ``p x (p-1)`` removal system."""
    dim = d.shape[1]
    for a in range(p + 2):
        q = ctrl[k, a]
        for e in range(dim):
            Q[a, e] = d[q, e]
    A[:, :] = 0.0
    for r in range(p):
        al = alphas[k, r]
        for e in range(dim):
            f[r, e] = Q[r + 1, e]
        if r <= p - 2:
            A[r, r] = al
        else:
            for e in range(dim):
                f[r, e] -= al * Q[p + 1, e]
        if r >= 1:
            A[r, r - 1] = 1.0 - al
        else:
            for e in range(dim):
                f[r, e] -= (1.0 - al) * Q[0, e]
    m = p
    nc = p - 1
    for c in range(nc):  # Householder: zero A[c+1:, c], apply to f
        s = 0.0
        for r in range(c, m):
            s += A[r, c] * A[r, c]
        nrm = np.sqrt(s)
        if nrm == 0.0:
            continue
        alpha = -nrm if A[c, c] >= 0 else nrm
        v0 = A[c, c] - alpha
        vv = s - A[c, c] * A[c, c] + v0 * v0
        A[c, c] = v0
        if vv > 0:
            for c2 in range(c + 1, nc):
                s2 = 0.0
                for r in range(c, m):
                    s2 += A[r, c] * A[r, c2]
                g = 2.0 * s2 / vv
                for r in range(c, m):
                    A[r, c2] -= g * A[r, c]
            for e in range(dim):
                s2 = 0.0
                for r in range(c, m):
                    s2 += A[r, c] * f[r, e]
                g = 2.0 * s2 / vv
                for r in range(c, m):
                    f[r, e] -= g * A[r, c]
        A[c, c] = alpha
    for e in range(dim):  # back substitution R P = (Q^T f)[:p-1]
        for c in range(nc - 1, -1, -1):
            s = f[c, e]
            for c2 in range(c + 1, nc):
                s -= A[c, c2] * f[c2, e]
            f[c, e] = s / A[c, c]
    # reinsertion (8.29)-(8.30): new_r = al_r P_r + (1 - al_r) P_{r-1}, with P_{-1} = Q_0 and
    # P_{p-1} = Q_{p+1}
    for r in range(p):
        al = alphas[k, r]
        for e in range(dim):
            hi = f[r, e] if r <= p - 2 else Q[p + 1, e]
            lo = f[r - 1, e] if r >= 1 else Q[0, e]
            new[r, e] = al * hi + (1.0 - al) * lo


@njit(cache=True)
def _kr_loop(d, orig, mask, tol, p, n, closed, js, pos, C, right, left2, ctrl, a1, denom,
             alphas, lsq, eps_abs, max_steps, stop_on_tol, z, rank, tv, ti, total,
             cap, floor):  # type: ignore[no-untyped-def]
    """The Sapidis-Farin loop (see :func:`knot_removal_fair`); returns ``(steps, reason code,
    tracked sum, history, blocked knots, number blocked)``. ``d``, ``z``, ``rank`` and the tree
    are updated in place. Per step: the removal moves (one point, or a ``p x (p-1)`` least
    squares solve), the measure at the ``<= 2p+1`` touched knots, ``O(log N)`` tree updates."""
    dim = d.shape[1]
    nk = js.shape[0]
    nt = pos.shape[0]
    nm = p if lsq else 1
    idx = np.empty(nm, dtype=np.int64)
    new = np.empty((nm, dim))
    old = np.empty((nm, dim))
    Q = np.empty((p + 2, dim))
    A = np.empty((p, max(p - 1, 1)))
    f = np.empty((p, dim))
    tk = np.empty(nm * (p + 2), dtype=np.int64)
    zold = np.empty(nm * (p + 2))
    znew = np.empty(nm * (p + 2))
    hist = np.empty((max(cap, 1), 3))
    blocked = np.empty(nk, dtype=np.int64)
    nb = 0
    steps = 0
    code = 0  # max_steps
    while steps < max_steps:
        k = ti[1]
        zk = tv[1]
        if zk < 0:  # every knot blocked
            code = 1
            break
        if zk <= eps_abs or zk <= floor:
            code = 2
            break
        j = js[k]
        if lsq:
            _ls_moves(d, k, p, ctrl, alphas, new, Q, A, f)
            for r in range(p):
                idx[r] = ctrl[k, r + 1]
        else:
            a = a1[k]
            q = ctrl[k, a]
            idx[0] = q
            g = denom[k]
            for e in range(dim):
                # the jump c @ d[idx] summed as numpy's matmul does (OpenBLAS dgemv: the first
                # four products pairwise, then the rest in turn), so that the move is bitwise
                # the vectorised one for p <= 5
                s = ((C[k, 0] * d[ctrl[k, 0], e] + C[k, 1] * d[ctrl[k, 1], e])
                     + (C[k, 2] * d[ctrl[k, 2], e] + C[k, 3] * d[ctrl[k, 3], e]))
                for b in range(4, p + 2):
                    s += C[k, b] * d[ctrl[k, b], e]
                new[0, e] = d[q, e] - s / g
        ok = True
        for r in range(nm):
            if not mask[idx[r]]:
                ok = False
        if ok and tol < np.inf:
            for r in range(nm):
                q = idx[r]
                ss = 0.0
                for e in range(dim):
                    x = new[r, e] - orig[q, e]
                    ss += x * x
                if not np.sqrt(ss) <= tol:
                    ok = False
        if not ok:
            if stop_on_tol:
                code = 1
                break
            rank[k] = -1.0
            tt_update(tv, ti, k, -1.0)
            blocked[nb] = j
            nb += 1
            continue
        for r in range(nm):
            q = idx[r]
            for e in range(dim):
                old[r, e] = d[q, e]
        for r in range(nm):
            q = idx[r]
            for e in range(dim):
                d[q, e] = new[r, e]
        # knot j's measure depends on the control points of basis functions j-p-1 .. j, so a
        # moved control point b touches the knots b .. b+p+1 (closed: their period copies);
        # sorted and unique, as np.unique gives them
        m = 0
        for r in range(nm):
            for a in range(p + 2):
                jj = idx[r] + a
                if closed:
                    jj = p + (jj - p) % n
                if jj < 0 or jj >= nt:
                    continue
                kk = pos[jj]
                if kk < 0:
                    continue
                dup = False
                for u in range(m):
                    if tk[u] == kk:
                        dup = True
                        break
                if dup:
                    continue
                u = m  # insertion sort (at most 2p+1 entries)
                while u > 0 and tk[u - 1] > kk:
                    tk[u] = tk[u - 1]
                    u -= 1
                tk[u] = kk
                m += 1
        for u in range(m):
            kk = tk[u]
            zold[u] = z[kk]
            znew[u] = _knot_measure(d, kk, p, ctrl, C, right, left2)
        new_total = total - _pw_sum(zold, m) + _pw_sum(znew, m)
        if new_total >= total - floor:
            for r in range(nm - 1, -1, -1):
                q = idx[r]
                for e in range(dim):
                    d[q, e] = old[r, e]
            code = 3
            break
        total = new_total
        for u in range(m):
            kk = tk[u]
            zz = znew[u]
            z[kk] = zz
            if rank[kk] >= 0:
                rank[kk] = zz
        # the tree holds a function of the leaves (ties to the smaller index), so one range
        # repair over a contiguous run of touched knots leaves it as the single updates would
        if m > 0 and tk[m - 1] - tk[0] < 2 * m:
            tt_update_range(tv, ti, tk[0], tk[m - 1], rank)
        else:
            for u in range(m):
                kk = tk[u]
                if rank[kk] >= 0:
                    tt_update(tv, ti, kk, rank[kk])
        if steps >= hist.shape[0]:
            h2 = np.empty((2 * hist.shape[0], 3))
            h2[:steps] = hist[:steps]
            hist = h2
        mv = -np.inf
        for r in range(nm):
            ss = 0.0
            for e in range(dim):
                x = new[r, e] - old[r, e]
                ss += x * x
            v = np.sqrt(ss)
            if v > mv or v != v:
                mv = v
        hist[steps, 0] = j
        hist[steps, 1] = zk
        hist[steps, 2] = mv
        steps += 1
    return steps, code, total, hist, blocked, nb


# ------------------------------------------------------------------------------------------
# registration with fair()
# ------------------------------------------------------------------------------------------
def _register() -> None:
    from .fair import MethodSpec, register_method

    register_method(MethodSpec(
        name="knot-removal",
        curve_types=(BSplineCurve,),
        solver=solve,
        summary="Farin / Sapidis-Farin: remove and reinsert the knot with the largest jump of "
                "d kappa/ds, while the sum of jumps decreases, within tol",
        source="seed 004 (lecture notes) eqs. (8.19)-(8.36); one-point formulas in ERRATA",
    ))


_register()
