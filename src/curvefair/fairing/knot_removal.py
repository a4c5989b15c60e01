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

from .. import _threads
from .._kernels import knot_removal as _k
from .._kernels.ranking import tt_build
from .._typing import FloatArray
from .._validate import as_step_count
from ..curves.bspline import BSplineCurve, basis_derivatives
from ..errors import InputError
from .problem import check_bspline
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
_KNOT_BLOCK = 65536  # knots per block of control indices in _KnotData
#: knots from which :class:`_KnotData`'s basis tables are made on two threads
TABLES_PAR_MIN = 50_000


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
        # limit from span j-1 (N_{j-1-p..j-1}); per knot, compiled, on two threads for long
        # curves (:func:`curvefair._kernels.knot_removal.knot_tables`: each knot's rows are its
        # own, so one thread or two give the same bits)
        nder = max(p, 2)
        k = js.size
        c = np.empty((k, p + 2))  # as _jump_coefficients
        # the measure (sapidis_measure) reads r'' only for a quadratic (both sides) or a 3-D
        # curve (the right one, for the binormal): a planar curve of degree >= 3 keeps r' alone
        # (32 bytes a knot instead of 96 for a cubic; the kernel then reads no other row)
        two = p == 2 or curve.dim == 3
        self.right = np.empty((k, 2 if two else 1, p + 1))  # r'[, r''] (right limits)
        self.left2 = np.empty((k if p == 2 else 0, p + 1))  # r'' (left limit)
        tk = np.ascontiguousarray(t, dtype=np.float64)
        jsk = np.ascontiguousarray(js, dtype=np.int64)
        _threads.ranges(lambda a, b: _k.knot_tables(tk, p, jsk, a, b, nder, two, c, self.right,
                                                    self.left2),
                        0, k, _threads.THREADS, TABLES_PAR_MIN)
        self.c = c  # (k, p+2)
        # (k, p+2) control point indices, int32 below 2**31 control points: 20 bytes a knot
        # less at a cubic's ten million knots (the kernels only index with them); made in the
        # same blocks of knots (no int64 table of every knot's indices on the way)
        self.ctrl = np.empty((k, p + 2), dtype=np.int32 if curve.n_ctrl < 2**31 else np.int64)
        offs = np.arange(-p - 1, 1)[None, :]
        for a in range(0, k, _KNOT_BLOCK):
            b = min(a + _KNOT_BLOCK, k)
            self.ctrl[a:b] = curve.control_index(js[a:b, None] + offs)

    def jumps(self, d: FloatArray, k: np.ndarray | slice = slice(None)) -> FloatArray:
        """Sapidis-Farin measure at knots ``js[k]``: :func:`sapidis_measure` of the one-sided
        derivatives, computed per knot by the same compiled scalar code as the loop's local updates
        (:func:`curvefair._kernels.knot_removal.knot_measure`), so the initial ranking and the
        updated one agree bitwise and neither depends on the CPU's SIMD width."""
        ks = np.ascontiguousarray(np.arange(self.js.size)[k], dtype=np.int64)
        out = np.empty(ks.size)
        dc = np.ascontiguousarray(d, dtype=np.float64)
        # each knot's measure is its own: on two threads for long curves, the same bits
        _threads.ranges(lambda a, b: _k.measure_all(dc, ks[a:b], self.p, self.ctrl, self.c,
                                                    self.right, self.left2, out[a:b]),
                        0, ks.size, _threads.THREADS, TABLES_PAR_MIN)
        return out


def _speed_power(speed: FloatArray, k: int) -> FloatArray:
    """``speed ** k`` for a whole ``k >= 1`` as ``k - 1`` multiplications in turn (the order of
    :func:`curvefair._kernels.knot_removal.ipow`): exactly rounded at each step, so it is the same
    on every CPU, unlike a vectorised ``pow``."""
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
                    hist.reshape(-1, 3), np.asarray(out.extra["blocked_knots"]).tolist(),
                    out.extra["sum_tracked"])


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
    orig = np.asarray(curve.control_points)  # frozen, only read: no second copy
    max_steps = as_step_count(problem.max_steps, default=10 * nk)

    def outcome(c: BSplineCurve, steps: int, reason: StopReason, hist: FloatArray,
                epsv: float, eps_abs: float | None, sums: tuple[float, float, float],
                blocked: np.ndarray) -> Outcome:
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
        return outcome(curve, 0, "no_knots", np.zeros((0, 3)), e0, None, (0.0, 0.0, 0.0),
                       np.zeros(0, dtype=np.int64))
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
    if reason == "eps" and blocked.size:
        # every knot still worth removing is blocked: the tolerance stopped the loop (as in
        # eck_hadenfeld_fair); the unblocked ones left are the removed knots, z ~ 0
        pos = np.searchsorted(js, blocked)
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
              ) -> tuple[BSplineCurve, int, StopReason, float, FloatArray, np.ndarray]:
    """Run the compiled loop on the set-up of :func:`_loop_args`; ``d`` is updated in place."""
    steps, code, total, hist, blocked, nb = _k.kr_loop(
        *_loop_args(curve, kd, d, orig, mask, variant, tolv, eps_abs, max_steps, on_tol, z,
                    floor))
    out = curve.replace(control_points=d)
    return (out, int(steps), _REASONS[code], float(total), hist[:steps].copy(),
            np.array(blocked[:nb], dtype=np.int64))


def _loop_args(curve: BSplineCurve, kd: _KnotData, d: FloatArray, orig: FloatArray,
               mask: np.ndarray, variant: str, tolv: float, eps_abs: float, max_steps: int,
               on_tol: str, z: FloatArray, floor: float = 0.0) -> tuple[Any, ...]:
    """Arguments of :func:`curvefair._kernels.knot_removal.kr_loop`: the per-knot data (vectorised,
    depends on the knots only), the ranking tree over ``z`` and the state (``d``, ``z`` are used in
    place); ``floor`` is the absolute rounding floor (:data:`ROUNDING_FLOOR` times the largest
    initial jump)."""
    p = curve.degree
    n = curve.n_ctrl
    js = kd.js
    nk = js.size
    t = np.asarray(curve.knots)
    # knot index -> position in js (-1: not removable); int32 below 2**31 knots
    pos = np.full(t.size, -1, dtype=np.int32 if nk < 2**31 else np.int64)
    pos[js] = np.arange(nk)
    C = np.ascontiguousarray(kd.c)
    ctrl = np.ascontiguousarray(kd.ctrl)
    # one-point: the moved basis function a (of j-p-1 .. j; _one_point_index) and the sum of
    # the jump coefficients of its control point (a closed curve's wrapped copies add up)
    # (int16: 6 bytes a knot less than int64 at the loop's peak; a1 <= p + 1)
    if p % 2 == 1:
        a1 = np.full(nk, p + 1 - (p + 1) // 2, dtype=np.int16)
    else:
        h = p // 2
        a1 = np.where(np.abs(C[:, h]) >= np.abs(C[:, h + 1]), h, h + 1).astype(np.int16)
    # (in blocks of knots, as _KnotData's tables: the (nk, p+2) mask and masked copy of C
    # were 60 bytes a knot of fresh memory at the call's peak; each row's sum is its own)
    denom = np.empty(nk)
    for lo in range(0, nk, _KNOT_BLOCK):
        hi = min(lo + _KNOT_BLOCK, nk)
        cb = ctrl[lo:hi]
        mine = cb[np.arange(hi - lo), a1[lo:hi]]
        denom[lo:hi] = np.where(cb == mine[:, None], C[lo:hi], 0.0).sum(axis=1)
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
