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

from .._kernels import eck_hadenfeld as _k
from .._kernels.bspline import band_energy, band_residual
from .._typing import FloatArray
from .._validate import as_step_count, check_finite, choice, parse_clamp
from ..curves.bspline import BSplineCurve
from ..curves.piecewise import readonly
from ..errors import InputError
from .problem import check_bspline
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


def band_patterns(W: FloatArray) -> tuple[FloatArray, np.ndarray, int, int, int]:
    """Compress a band ``W`` into distinct rows ``Wu`` and ``pat`` with ``W[i] == Wu[pat[i]]``.

    Consecutive equal rows share one entry (uniform knots: a handful of rows in all). ``Wu``
    has one more column: ``1 / G_ii``. Also returns the longest run of one pattern
    ``(upat, ulo, uhi)``: ``pat[ulo:uhi] == upat``."""
    n, w = W.shape
    Wu = np.empty((n, w + 1))
    pat = np.empty(n, dtype=np.int32)
    m, upat, ulo, uhi = _k.patterns(np.ascontiguousarray(W), Wu, pat)
    # a few patterns (uniform knots): their own small array, the buffer freed; many (knots
    # from chord lengths: nearly one per row): the buffer itself -- a copy would touch as
    # many fresh bytes again (640 MB at 1e7 cubic control points, 2.6 s there)
    return (Wu[:m].copy() if 2 * m < n else Wu[:m]), pat, int(upat), int(ulo), int(uhi)


def _tree_buffer(n: int) -> FloatArray:
    """Storage of :func:`curvefair._kernels.eck_hadenfeld.eh_loop`'s tournament tree for ``n``
    control points: ``(2 P, 2)``, ``P`` the smallest power of 4 ``>=`` the number of blocks,
    64-byte aligned."""
    nb = (int(n) + (1 << _k.BLOCK_SHIFT) - 1) >> _k.BLOCK_SHIFT
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
        none does (see ``curvefair._kernels.eck_hadenfeld.eh_sweep``). Same step, same
        tolerance, same stopping test (when it stops, no ranking number is above the
        threshold); only the order differs: the sweep reads memory in order instead of
        jumping across the curve, and leaves most ranking numbers far below the threshold
        where the ranking list leaves them just below it (measurements: docs/benchmarks.md,
        "Eck-Hadenfeld: threshold and schedule").

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
    Compiled loops: ``O(log N)`` per step for the ranking list (see
    ``curvefair._kernels.eck_hadenfeld.eh_loop``), ``O(degree)`` per step for the sweep
    (``curvefair._kernels.eck_hadenfeld.eh_sweep``).

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
    e0 = float(_k.setup_state(W, curve.degree, curve.closed, d, mask, X, z))
    if eps_relative:
        epsv, eps_abs = eps_threshold(problem.eps, e0, default_eps(n))
    else:
        epsv = eps_abs = 0.0 if problem.eps is None else problem.eps
    hist = np.zeros((int(min(history_max, max_steps)), 3))
    Wu, pat, upat, ulo, uhi = band_patterns(W)
    if sched == "ranking":
        steps, drop, code, nh = _k.eh_loop(X, z, Wu, pat, upat, ulo, uhi, dim, curve.degree,
                                           curve.closed, tolv, eps_abs, int(max_steps), hist,
                                           _tree_buffer(n))
    else:
        steps, drop, code, nh = _k.eh_sweep(X, z, Wu, pat, upat, ulo, uhi, dim, curve.degree,
                                            curve.closed, tolv, eps_abs, int(max_steps), hist,
                                            np.empty(n, dtype=np.int64),
                                            np.empty(n, dtype=np.uint8))
    # the loop's state is freed before the result's copy is made (on chord-length knots the
    # band rows Wu hold as many bytes as W again: 4 of the input's coordinate bytes)
    del Wu, pat, z
    # the loop keeps every coordinate finite and the knots are the input's: no re-validation;
    # one copy of the coordinates, straight into frozen memory
    out = BSplineCurve._trusted(readonly(X[:, :dim]), curve.knots, curve.degree,
                                curve.closed, same_knots_as=curve)
    del X
    e1 = _energy(out, W)
    if not np.isfinite(e1):
        check_finite(out.control_points, "control_points")
    reason = STOP_REASONS[int(code)]
    if reason == "converged":
        zfree = float(_k.largest_free_z(W, curve.degree, curve.closed,
                                        np.asarray(out.control_points), mask))
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
