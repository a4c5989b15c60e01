"""Cheng & Yu's local fairing of cubic B-splines with the second discrete curvature (seed 002).

* :func:`cheng_yu` -- one step: move one control point (eq. (8), ERRATA: plus sign) or two
  consecutive ones (eq. (9)) towards the minimiser of the local strain energy ``E_2``, by the
  modifying factor ``d`` chosen from the error bound ``e`` (Theorem 3, ERRATA: measured from the
  ORIGINAL control point so that it holds after any number of steps).
* :func:`cheng_yu_driver` -- the automatic method (steps 1-6 of "Fairing algorithm"): rank the bad
  points by ``z_i = D_i**2``, adjust the worst one (with its neighbour when the next in the ranking
  is adjacent), keep the adjustment when the fairing indicator ``x = sum D_i**2`` decreases.

Indices are 0-based (the paper's ``Q_0 .. Q_n`` are ``control_points[0 .. n]``).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from .._kernels import cheng_yu as _k
from .._typing import FloatArray
from .._validate import as_nonnegative, as_step_count
from ..analysis.discrete import (
    check_cubic_bspline,
    cheng_yu_figures,
    corner_cut_ratios,
)
from ..errors import InputError
from .stop import StopReason

if TYPE_CHECKING:
    from .problem import FairingProblem, Outcome

__all__ = ["cheng_yu", "cheng_yu_driver", "CYResult"]


# --------------------------------------------------------------------------------------------
# the single / double step
# --------------------------------------------------------------------------------------------
def _as_index(m: object, n: int, closed: bool, pair: bool) -> int:
    if isinstance(m, bool) or not isinstance(m, (int, np.integer)):
        raise InputError(f"m must be an integer control point index, got {m!r}")
    m = int(m)
    if not 0 <= m < n:
        raise InputError(f"m = {m} is out of range for {n} control points (0-based)")
    if pair and not closed and m + 1 >= n:
        raise InputError(f"pair=True moves m and m + 1, but m + 1 = {m + 1} is past the last "
                         f"control point {n - 1}")
    return m


def _original_points(original: Any, curve: Any) -> FloatArray:
    from ..curves.bspline import BSplineCurve

    ctrl = np.asarray(curve.control_points, dtype=float)
    if original is None:
        return ctrl
    if isinstance(original, BSplineCurve):
        q0 = np.asarray(original.control_points, dtype=float)
    else:
        q0 = np.asarray(original, dtype=float)
    if q0.shape != ctrl.shape:
        raise InputError(f"original must have the curve's control point shape {ctrl.shape}, "
                         f"got {q0.shape}")
    if not np.all(np.isfinite(q0)):
        raise InputError("original contains a non-finite value")
    return q0


def cheng_yu(curve: Any, m: int, e: float | None = None, pair: bool = False, *,
             d: float | None = None, original: Any = None,
             return_factor: bool = False) -> Any:
    """One Cheng-Yu step: move control point ``m`` (or ``m`` and ``m + 1``) of a cubic B-spline.

    Parameters
    ----------
    curve : BSplineCurve
        Cubic, open or closed, dim 2 or 3.
    m : int
        0-based control point index (paper: ``Q_m``). Closed curves: ``m + 1`` wraps around.
    e : float, optional
        Error bound: every moved control point stays within distance ``e`` of its position in
        ``original``, so the curve moves by at most ``e`` from the original curve (convex hull
        property, Theorem 3). ``None``: no bound (``d = 0``, the full energy step).
    pair : bool
        Move ``Q_m`` and ``Q_{m+1}`` together (eq. (9)) instead of ``Q_m`` alone (eq. (8)).
    d : float in [0, 1], optional
        Force the modifying factor instead of deriving it from ``e`` (``d = 1``: no change,
        ``d = 0``: the energy minimiser). Exclusive with ``e``.
    original : BSplineCurve or array_like (n, dim), optional
        The control points the bound ``e`` is measured from (default: the current ones, as in
        the paper, which then holds for one step only).
    return_factor : bool
        Also return the factor ``d`` used.

    Returns
    -------
    BSplineCurve or (BSplineCurve, float)
        A new curve; only the moved control points differ.

    Raises
    ------
    InputError
        Not a cubic :class:`~curvefair.BSplineCurve`; ``m`` out of range; ``e`` not > 0;
        ``d`` outside ``[0, 1]``; both ``e`` and ``d``; the current point already farther than
        ``e`` from ``original``.

    Notes
    -----
    With ``G_ij = int N_i''(u) N_j''(u) du`` over the domain (the paper's ``[a, b]`` is the part
    of the support of ``N_m`` inside it) and ``d_i = -G_im / G_mm``, eq. (8) corrected by the
    ERRATA reads::

        Q~_m = d Q_m + (1 - d) sum_{i != m} d_i Q_i,

    the minimiser of ``(1 - d) E_2 + d |Q~_m - Q_m|**2 G_mm``; ``d = 0`` is exactly the
    Eck-Hadenfeld ``l = 2`` step. Eq. (9) for two points: ``Q~_j = d Q_j + (1 - d) sum_{i != j}
    d_i^j Q~_i`` for ``j = m, m+1`` (the other points fixed), a 2x2 system; ``d = 0`` is the joint
    minimiser of ``E_2`` over both points. The factor: Theorem 3 takes
    ``d = max(0, 1 - e / |Q_m - sum d_i Q_i|)``; here the smallest ``d`` for which the moved
    points stay within ``e`` of ``original`` (ERRATA), which equals the paper's value when
    ``original`` is the current curve and one point moves. For two points the paper's formula
    does not bound the displacement of eq. (9); the factor here does.

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import BSplineCurve
    >>> pts = np.c_[np.arange(8.0), np.zeros(8)]
    >>> pts[4, 1] = 1.0
    >>> c = BSplineCurve(pts, np.r_[0, 0, 0, np.arange(6.0), 5, 5, 5], 3)
    >>> c2, d = cheng_yu(c, 4, e=0.25, return_factor=True)
    >>> round(float(np.linalg.norm(c2.control_points[4] - pts[4])), 12), 0 < d < 1
    (0.25, True)
    >>> bool(cheng_yu(c, 4).control_points[4, 1] == 0.0)   # d = 0: the E_2 minimiser
    True
    """
    curve = check_cubic_bspline(curve, "cheng_yu")
    n = curve.n_ctrl
    closed = bool(curve.closed)
    pair = bool(pair)
    m = _as_index(m, n, closed, pair)
    if e is not None and d is not None:
        raise InputError("give either the error bound e or the factor d, not both")
    ebound = np.inf
    dfix = -1.0
    if e is not None:
        try:
            ebound = float(e)
        except (TypeError, ValueError):
            raise InputError(f"e must be a number > 0, got {e!r}") from None
        if not np.isfinite(ebound) or ebound <= 0:
            raise InputError(f"e must be a finite number > 0, got {e!r}")
    if d is not None:
        try:
            dfix = float(d)
        except (TypeError, ValueError):
            raise InputError(f"d must be a number in [0, 1], got {d!r}") from None
        if not 0.0 <= dfix <= 1.0:
            raise InputError(f"d must be in [0, 1], got {d!r}")
    Q = np.array(curve.control_points, dtype=float)
    Q0 = _original_points(original, curve)
    moved = [m, (m + 1) % n] if pair else [m]
    if ebound < np.inf:
        for j in moved:
            dist = float(np.linalg.norm(Q[j] - Q0[j]))
            if dist > ebound * (1 + 1e-12):
                raise InputError(f"control point {j} is already {dist!r} from original, more than "
                                 f"e = {ebound!r}")
    W = np.asarray(curve.gram_band(2), dtype=float)
    dim = Q.shape[1]
    new0 = np.zeros(dim)
    new1 = np.zeros(dim)
    dused = _k.plan(Q, Q0, W, n, closed, m, pair, ebound, dfix, new0, new1)
    Q[m] = new0
    if pair:
        Q[moved[1]] = new1
    out = curve.replace(control_points=Q)
    return (out, float(dused)) if return_factor else out


# --------------------------------------------------------------------------------------------
# the automatic method: compiled ranking loop with local updates
# --------------------------------------------------------------------------------------------
_STOP: dict[int, StopReason] = {_k.NONE_LEFT: "no_improvement", _k.EPS: "eps",
                                 _k.CONVERGED: "converged", _k.MAX_STEPS: "max_steps"}


@dataclass(frozen=True)
class CYResult:
    """Outcome of :func:`cheng_yu_driver`.

    Attributes
    ----------
    curve : BSplineCurve
    steps : int
        Accepted adjustments (one or two control points each).
    stop_reason : str
        ``"eps"`` (the largest ``z_i`` of a movable bad point is below the threshold),
        ``"converged"`` (no movable bad point left), ``"no_improvement"`` (movable bad points
        remain, but adjusting any of them does not lower ``x`` by more than the threshold),
        ``"max_steps"``.
    indicator_before, indicator_after : float
        The fairing indicator ``x = sum D_i**2`` of the input and of the result.
    threshold : float
        The absolute threshold used for ``z_i`` and for the drop of ``x`` per step.
    history : dict of ndarray
        ``"step"`` (0 .. steps), ``"x"`` (indicator after that many steps), ``"index"`` (first
        moved control point, -1 at step 0), ``"n_moved"`` (1 or 2; 0 at step 0), ``"z"`` (the
        local fairing value of the top-ranked bad point the step acted on; NaN at step 0),
        ``"displacement"`` (largest move of the step).
    bad_points_before, bad_points_after : int
        The number of bad control points (:func:`curvefair.analysis.discrete.bad_point_count`)
        of the input and of the result.
    """

    curve: Any
    steps: int
    stop_reason: StopReason
    indicator_before: float
    indicator_after: float
    threshold: float
    history: dict[str, np.ndarray] = field(default_factory=dict)
    bad_points_before: int = 0
    bad_points_after: int = 0


def cheng_yu_driver(curve: Any, *, tol: float | None = None, eps: float = 1e-8,
                    relative: bool = True, max_steps: int | None = None,
                    clamp: Any = (None, None), protect: Iterable[int] = (),
                    pair: bool = True) -> CYResult:
    """Cheng & Yu's automatic fairing of a cubic B-spline (section "Fairing algorithm").

    Parameters
    ----------
    curve : BSplineCurve
        Cubic, open or closed, dim 2 or 3.
    tol : float or None
        Error bound ``e``: no control point ends farther than ``tol`` from its ORIGINAL position
        (ERRATA), so the curve deviates at most ``tol`` from the input at equal parameter.
        ``None``: unbounded (every step is the full energy step, ``d = 0``).
    eps : float
        Threshold ``eps * x(input)`` (``relative=True``) or ``eps``: stop when the largest local
        fairing value ``z_i`` of a movable bad point is below it; an adjustment is kept only if
        it lowers ``x`` by more than it.
    max_steps : int or None
        Cap on accepted adjustments (default ``100 n``).
    clamp : (left, right)
        ``None``, ``"g0"``, ``"g1"``, ``"g2"`` per end (one string: both ends): fix 0, 1, 2, 3 end
        control points (keeps position, tangent, curvature at that end). Ignored for closed
        curves.
    protect : iterable of int
        Control points that never move.
    pair : bool
        Adjust two consecutive bad points together (eq. (9)) when they are next to each other in
        the ranking (step 4). ``False``: always one point (eq. (8)).

    Returns
    -------
    CYResult

    Notes
    -----
    Steps 1-6 of the paper as a ranking list: the bad points (:func:`curvefair.bad_points`)
    are ranked by ``z_i = D_i**2`` (step 3); the first is adjusted alone, or together with the
    second when their indices are adjacent (step 4), by :func:`cheng_yu` with the factor ``d``
    derived from ``tol`` measured from the original control points; the adjustment is kept only
    if the fairing indicator ``x = sum D_i**2`` decreases (step 5), otherwise it is undone and
    the point is set aside until a neighbouring adjustment changes its surroundings (a rejected
    pair is retried as a single point). ``K``, ``D``, the kinds and ``z`` are recomputed only for
    the indices an adjustment touches (``O(log N)`` per step with a tournament tree). The
    paper's literal step 5 ("if x' decreases, output; otherwise return to step 2") is one pass;
    here the loop goes on while movable bad points with ``z_i >= eps`` remain.

    On open curves the bad points and ``x`` use control points ``2 .. n-3`` (see
    :func:`curvefair.second_discrete_curvature`); only bad points are moved, so control points
    0, 1, n-2, n-1 of an open curve never move whatever the clamp.

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import interpolate_bspline
    >>> x = np.linspace(0, 6, 30)
    >>> y = np.sin(x) + 0.02 * np.random.default_rng(0).normal(size=30)
    >>> res = cheng_yu_driver(interpolate_bspline(np.c_[x, y]), tol=0.05)
    >>> bool(res.indicator_after < res.indicator_before)
    True
    """
    from .problem import make_problem

    curve = check_cubic_bspline(curve, "method 'cheng-yu' (Cheng & Yu's second discrete curvature)")
    prob = make_problem(curve, tol=tol, eps=as_nonnegative(eps, "eps"), max_steps=max_steps,
                        clamp=clamp, protect=protect)
    return _solve(prob, pair=pair, relative=relative)


#: first length of the step history buffers; they grow with the steps taken
HISTORY_START = 4096


def _solve(problem: FairingProblem, *, pair: bool, relative: bool) -> CYResult:
    from .problem import eps_threshold

    curve = check_cubic_bspline(problem.curve,
                           "method 'cheng-yu' (Cheng & Yu's second discrete curvature)")
    n = curve.n_ctrl
    closed = bool(curve.closed)
    e = problem.tol
    max_steps = as_step_count(problem.max_steps, default=100 * n)
    mask = problem.movable
    # validates (raises at a true corner); the indicator and the bad points' count in one pass,
    # without second_discrete_curvature's per-point arrays (2.5x the coordinates' bytes, its
    # temporaries more)
    x0, bad0 = cheng_yu_figures(curve)
    knots = np.asarray(curve.knots, dtype=float)
    lw, mw = corner_cut_ratios(knots, n, closed)
    corner = np.flatnonzero((lw == 0.0) & (mw == 0.0))
    if not closed:
        corner = corner[(corner > 0) & (corner < n - 1)]
    for i in corner:  # K_i undefined once Q_{i-1}, Q_i, Q_{i+1} stop being collinear
        mask[np.arange(i - 1, i + 2) % n] = False
    Q = np.array(curve.control_points, dtype=float, order="C")
    # the original points: the input curve's own (read-only, never written), no copy
    Q0 = np.ascontiguousarray(curve.control_points, dtype=float)
    W = np.ascontiguousarray(curve.gram_band(2), dtype=float)
    if relative:
        _, eps_abs = eps_threshold(problem.eps, x0, 1e-8)
    else:
        eps_abs = 0.0 if problem.eps is None else problem.eps
    # the history buffers grow with the steps taken (the kernel doubles them when full)
    cap = min(int(max_steps), HISTORY_START)
    hist = np.zeros(cap + 1)
    moves = np.zeros((cap, 4))
    planar = Q.shape[1] == 2
    steps, code, hist, moves = _k.cy_loop(Q, Q0, W, lw, mw, closed, planar, mask, e, eps_abs,
                                          int(max_steps), bool(pair), hist, moves)
    steps = int(steps)
    del Q0, W, lw, mw, mask
    out = curve.replace(control_points=Q)  # (a copy: Q is freed before the measure)
    del Q
    x1, bad1 = cheng_yu_figures(out)
    history = {
        "step": np.arange(steps + 1),
        "x": hist[: steps + 1].copy(),
        "index": np.r_[-1, moves[:steps, 0]].astype(np.int64),
        "n_moved": np.r_[0, moves[:steps, 1]].astype(np.int64),
        "z": np.r_[np.nan, moves[:steps, 2]],
        "displacement": np.r_[0.0, moves[:steps, 3]],
    }
    return CYResult(out, steps, _STOP[int(code)], float(x0), float(x1), float(eps_abs), history,
                    bad0, bad1)


# --------------------------------------------------------------------------------------------
# registration with curvefair.fair
# --------------------------------------------------------------------------------------------
def solve(problem: FairingProblem, *, pair: bool = True, relative: bool = True) -> Outcome:
    """Cheng & Yu as a solver of ``problem`` (``fair(curve, "cheng-yu", ...)``).

    ``eps`` is relative to the input's fairing indicator ``x = sum D_i**2`` (default ``1e-8``);
    ``relative=False`` makes it an absolute threshold on ``z_i = D_i**2`` (default 0).
    """
    from .problem import FairingHistory, Outcome

    res = _solve(problem, pair=bool(pair), relative=bool(relative))
    h = res.history
    history = FairingHistory.from_arrays(h["index"][1:], h["z"][1:], h["displacement"][1:],
                                         "control point")
    extra = {
        "indicator_before": res.indicator_before,
        "indicator_after": res.indicator_after,
        "pair_steps": int(np.sum(h["n_moved"] == 2)),
        "bad_points_before": res.bad_points_before,
        "bad_points_after": res.bad_points_after,
    }
    epsv = (1e-8 if relative else 0.0) if problem.eps is None else problem.eps
    n = problem.curve.n_ctrl  # type: ignore[attr-defined]
    return Outcome(res.curve, res.steps, res.stop_reason, history, eps=epsv,
                   max_steps=100 * n if problem.max_steps is None else problem.max_steps,
                   extra=extra, eps_absolute=res.threshold)


def _register() -> None:
    from ..curves.bspline import BSplineCurve
    from .fair import MethodSpec, register_method

    register_method(MethodSpec(
        name="cheng-yu",
        curve_types=(BSplineCurve,),
        solver=solve,
        accepts=lambda c: c.degree == 3,
        summary="Cheng & Yu: move the worst bad control points (second discrete curvature) "
                "towards the local E2 minimiser within the tolerance",
        source="Cheng & Yu, second discrete curvature: Definitions 1-2, bad points, eqs. (8)-(9) "
               "(ERRATA: plus sign), Theorem 3 (ERRATA: bound from the original points), "
               "fairing algorithm steps 1-6",
    ))


_register()
