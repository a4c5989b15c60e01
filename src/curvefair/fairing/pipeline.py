"""Fair a point sequence directly: the fairest spline passing within ``tol`` of every point.

:func:`fair_points` solves, for data points ``p_i`` at parameters ``u_i``::

    minimise  E_l(C) = int |C^(l)(u)|^2 du   subject to   |C(u_i) - p_i| <= tol  for every i,

over all B-spline curves ``C`` of the given degree with a knot at every data parameter (the
convex QP of :mod:`curvefair.fairing.global_fair`, with the balls around the DATA points
instead of around the control points of the interpolant). With the default ``degree = 5``,
``l = 3`` (``degree = 2 l - 1``) this spline space contains the minimiser over *all* curves
with a square-integrable third derivative (the classical natural-spline argument: between the
data parameters and beyond the ends the minimiser satisfies ``C^(6) = 0``, see the Notes of
:func:`fair_points`), so the result is the fairest curve in that sense that honours the
tolerance -- not only the fairest among small moves of an interpolant.

Why a separate entry point: :func:`curvefair.fair` moves the points (or control points) of a
given curve one ball each; a point held on its ball leaves a jump in the curve's top
derivative, and on a cubic every such jump is a possible curvature extremum. A quintic
minimiser of ``E_3`` is ``C^4``: its curvature derivative is continuous, and the constraints
that are active leave only jumps in the fifth derivative.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

from .._typing import ArrayLike, FloatArray
from .._validate import as_degree, as_points, as_positive
from ..curves.bspline import BSplineCurve
from ..curves.parameterize import closed_point_data, parameterize
from ..errors import InputError

__all__ = ["fair_points", "PointFairingResult", "tube_energy_qp"]


@dataclass(frozen=True, eq=False)
class PointFairingResult:
    """Result of :func:`fair_points`.

    Attributes
    ----------
    curve : BSplineCurve
        The faired curve (clamped open, or periodic closed), on the parameter domain of
        ``params``.
    params : ndarray, shape (m,)
        The parameter of each input point on ``curve`` (for a closed curve the ``m`` distinct
        points; the period ends at the closing parameter). ``|curve(params[i]) - points[i]|
        <= tol`` for every ``i``.
    report : dict
        JSON-serialisable: ``tol``, ``degree``, ``l``, ``n_points``, ``n_ctrl``,
        ``max_deviation`` (``max_i |C(u_i) - p_i|``), ``max_deviation_index``, ``n_active``
        (points on their tolerance ball), ``energy_before`` (``E_l`` of the interpolating
        spline in the same space) and ``energy_after``, ``iterations``, ``stop_reason``.
    multipliers : ndarray, shape (m,)
        KKT multipliers ``mu_i >= 0``: ``2 G d + sum_i mu_i N(u_i) (C(u_i) - p_i) = 0`` (per
        coordinate; ``G`` the Gram matrix of ``E_l``, ``N(u_i)`` the basis row at ``u_i``), and
        ``mu_i = 0`` unless point ``i`` is on its ball.
    """

    curve: BSplineCurve
    params: np.ndarray
    report: dict[str, Any] = field(default_factory=dict)
    multipliers: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def __repr__(self) -> str:
        r = self.report
        return (f"PointFairingResult(n_points={r.get('n_points')}, n_active={r.get('n_active')}, "
                f"max_deviation={r.get('max_deviation')!r}, stop_reason="
                f"{r.get('stop_reason')!r}, curve={self.curve!r})")


# ------------------------------------------------------------------------------------------
# the convex QP
# ------------------------------------------------------------------------------------------
def _energy_weights(l: Any, degree: int) -> dict[int, float]:  # noqa: E741
    if isinstance(l, (int, np.integer)) and not isinstance(l, bool):
        w = {int(l): 1.0}
    elif isinstance(l, dict):
        w = {int(k): float(v) for k, v in l.items()}
    else:
        raise InputError(f"l must be an integer or a dict {{order: weight}}, got {l!r}")
    for k, v in w.items():
        if not 1 <= k <= degree:
            raise InputError(f"energy order {k} must be in [1, degree = {degree}]")
        if not (np.isfinite(v) and v >= 0):
            raise InputError(f"energy weight for order {k} must be a finite number >= 0, got {v!r}")
    w = {k: v for k, v in w.items() if v > 0}
    if not w:
        raise InputError(f"l gives no positive energy weight: {l!r}")
    return w


def _gram(curve: BSplineCurve, w: dict[int, float]) -> sp.csr_matrix:
    """``sum_k w_k G_k`` (exact Gram matrices of the k-th derivatives of the basis)."""
    G: Any = None
    for k, v in w.items():
        Gk = curve.gram_matrix(k) * v
        G = Gk if G is None else G + Gk
    return G.tocsr()


def _collocation(curve: BSplineCurve, u: FloatArray) -> sp.csr_matrix:
    """``A[i, j] = N_j(u_i)`` with the columns of a closed curve folded mod ``n``."""
    from scipy.interpolate import BSpline
    A = BSpline.design_matrix(u, np.asarray(curve.knots), curve.degree).tocoo()
    return sp.csr_matrix((A.data, (A.row, curve.control_index(A.col))),
                         shape=(u.shape[0], curve.n_ctrl))


def tube_energy_qp(curve: BSplineCurve, params: ArrayLike, points: ArrayLike, tol: float, *,
                   l: Any = 3, gap: float = 1e-12,  # noqa: E741
                   max_steps: int = 200) -> tuple[BSplineCurve, np.ndarray, int, str]:
    """Minimise ``sum_k w_k E_k`` over the control points s.t. ``|C(u_i) - p_i| <= tol``.

    Parameters
    ----------
    curve : BSplineCurve
        Knots, degree and a STRICTLY feasible start (``|C(u_i) - p_i| < tol`` for all i).
    params : array_like, shape (m,)
        ``u_i`` inside the curve's domain.
    points : array_like, shape (m, dim)
    tol : float
        > 0.
    l : int or dict
        ``E_l`` or a blend ``{order: weight}`` (orders ``1 .. degree``).
    gap : float
        Stop when the surrogate duality gap is below ``gap`` (the objective is ``E / E(start)``).
    max_steps : int
        Interior-point iteration cap.

    Returns
    -------
    curve : BSplineCurve
    multipliers : ndarray, shape (m,)
        ``mu_i`` of the KKT conditions (see :class:`PointFairingResult`).
    iterations : int
    stop_reason : str
        ``"converged"``, ``"max_steps"``, ``"numerical"`` or ``"zero_energy"``.

    Notes
    -----
    Primal-dual interior point with strictly feasible iterates (Boyd & Vandenberghe, *Convex
    Optimization*, sec. 11.7, ``mu = 10``) on ``F = E(d)/E(d_start)`` with the constraints
    ``f_i = (|A_i d - p_i|^2 / tol^2 - 1) / 2 <= 0``, as in
    :func:`~curvefair.fairing.global_fair.global_fair`; the Newton matrix
    ``2 G / E0 + A^T blockdiag(B_i) A`` is banded (cyclic for closed curves) and factorised by
    SuperLU with a minimum-degree ordering.
    """
    tolv = as_positive(tol, "tol", window=True)
    assert tolv is not None
    w = _energy_weights(l, curve.degree)
    u = np.asarray(params, dtype=float)
    pts = np.asarray(points, dtype=float)
    n, dim = curve.control_points.shape
    m = u.shape[0]
    G = _gram(curve, w)
    A = _collocation(curve, u)
    x = np.array(curve.control_points)
    v0 = A @ x - pts
    if np.any(np.sum(v0 * v0, axis=1) >= tolv * tolv):
        raise InputError("tube_energy_qp needs a strictly feasible start curve "
                         "(|C(u_i) - p_i| < tol at every point)")
    E0 = float(np.sum(x * (G @ x)))
    if not E0 > 0:
        return curve, np.zeros(m), 0, "zero_energy"
    t2 = tolv * tolv
    lam = np.ones(m)
    eye = np.eye(dim)
    Q2 = sp.kron(2.0 * G / E0, sp.identity(dim), format="csc")
    AI = sp.kron(A, sp.identity(dim), format="csr")
    # block-diagonal pattern (m dim x m dim) of the per-point dim x dim blocks
    ii = np.arange(m)[:, None, None] * dim
    brow = np.broadcast_to(ii + np.arange(dim)[None, :, None], (m, dim, dim)).reshape(-1)
    bcol = np.broadcast_to(ii + np.arange(dim)[None, None, :], (m, dim, dim)).reshape(-1)

    def residuals(x: FloatArray, lam: FloatArray, tinv: float
                  ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        v = A @ x - pts
        fi = 0.5 * (np.sum(v * v, axis=1) / t2 - 1.0)
        rd = 2.0 * (G @ x) / E0 + A.T @ (lam[:, None] * v / t2)
        rc = -lam * fi - tinv
        return rd, rc, fi, v

    rd0, _, _, _ = residuals(x, lam, 0.0)
    gscale = float(np.abs(rd0).max()) or 1.0
    steps = 0
    reason = "max_steps"
    eta_prev = np.inf
    stall = 0
    while steps < max_steps:
        v = A @ x - pts
        fi = 0.5 * (np.sum(v * v, axis=1) / t2 - 1.0)
        eta = float(-(fi @ lam))
        tinv = eta / (10.0 * m)
        rd, rc, fi, v = residuals(x, lam, tinv)
        rdn = float(np.abs(rd).max())
        if eta < gap and rdn < 1e-10 * gscale:
            reason = "converged"
            break
        stall = stall + 1 if eta > 0.9 * eta_prev else 0
        if stall >= 3 and eta < 1e-8 and rdn < 1e-8 * gscale:
            reason = "converged"  # rounding-level stall above the target gap
            break
        eta_prev = eta
        a = v / t2
        ww = lam / (-fi)
        blocks = (lam / t2)[:, None, None] * eye + ww[:, None, None] * a[:, :, None] * a[:, None, :]
        B = sp.csr_matrix((blocks.reshape(-1), (brow, bcol)), shape=(m * dim, m * dim))
        H = (Q2 + AI.T @ B @ AI).tocsc()
        rhs = -rd - A.T @ (a * (rc / fi)[:, None])
        try:
            dx = splu(H, permc_spec="MMD_AT_PLUS_A").solve(rhs.reshape(-1)).reshape(n, dim)
        except RuntimeError:
            reason = "converged" if eta < 1e-8 else "numerical"
            break
        if not np.all(np.isfinite(dx)):
            reason = "converged" if eta < 1e-8 else "numerical"
            break
        Adx = A @ dx
        adx = np.sum(a * Adx, axis=1)
        dlam = (rc - lam * adx) / fi
        neg = dlam < 0
        smax = min(1.0, float((-lam[neg] / dlam[neg]).min())) if neg.any() else 1.0
        st = 0.99 * smax
        a2 = np.sum(Adx * Adx, axis=1)
        a1 = np.sum(v * Adx, axis=1)
        c0 = np.sum(v * v, axis=1) - t2
        with np.errstate(divide="ignore", invalid="ignore"):
            tmax = np.where(a2 > 0, (-a1 + np.sqrt(np.maximum(a1 * a1 - a2 * c0, 0.0))) / a2,
                            np.inf)
        st = min(st, 0.99 * float(tmax.min()))
        rnorm = np.sqrt(float(np.sum((rd / gscale) ** 2) + np.sum(rc * rc)))
        while st > 1e-14:
            rd1, rc1, fi1, _ = residuals(x + st * dx, lam + st * dlam, tinv)
            if np.all(fi1 < 0) and np.sqrt(float(np.sum((rd1 / gscale) ** 2)
                                                 + np.sum(rc1 * rc1))) <= (1.0 - 0.01 * st) * rnorm:
                break
            st *= 0.5
        if st <= 1e-14:
            reason = "converged" if eta < 1e-8 else "numerical"
            break
        x = x + st * dx
        lam = lam + st * dlam
        steps += 1
    return curve.replace(control_points=x), E0 * lam / t2, steps, reason


# ------------------------------------------------------------------------------------------
# the pipeline
# ------------------------------------------------------------------------------------------
def _start_curve(pts: FloatArray, u: FloatArray, degree: int, closed: bool,
                 w: dict[int, float]) -> BSplineCurve:
    """The interpolating spline of ``degree`` written on the knot vector with a knot at EVERY
    data parameter (open: clamped, ``m + degree - 1`` control points; closed: periodic, knots
    at the ``m`` data parameters)."""
    from scipy.interpolate import make_interp_spline
    if closed:
        loop = np.vstack([pts, pts[:1]])
        spl = make_interp_spline(u, loop, k=degree, bc_type="periodic", axis=0)
        return BSplineCurve.from_scipy(spl, closed=True)
    # open: the interpolant of least E_l (the natural spline when degree = 2 l - 1), from the
    # KKT system [2 G, A^T; A, 0] [d; nu] = [0; p]
    p = degree
    t = np.r_[[u[0]] * (p + 1), u[1:-1], [u[-1]] * (p + 1)]
    n = t.shape[0] - p - 1
    shell = BSplineCurve(np.zeros((n, pts.shape[1])), t, p)
    G = _gram(shell, w)
    A = _collocation(shell, u)
    K = sp.bmat([[2.0 * G / float(G.diagonal().max()), A.T], [A, None]], format="csc")
    rhs = np.vstack([np.zeros((n, pts.shape[1])), pts])
    sol = splu(K, permc_spec="MMD_AT_PLUS_A").solve(rhs)
    if not np.all(np.isfinite(sol)):  # pragma: no cover - Schoenberg-Whitney holds by design
        raise InputError("could not build the interpolating start curve")
    return shell.replace(control_points=sol[:n])


def fair_points(points: ArrayLike, tol: float, *, degree: int = 5, l: Any = 3,  # noqa: E741
                param: str | ArrayLike = "chord", closed: bool = False,
                max_steps: int = 200) -> PointFairingResult:
    """The fairest spline curve that passes within ``tol`` of every data point.

    Parameters
    ----------
    points : array_like, shape (m, dim)
        Data points, dim 2 or 3 (no two consecutive equal). Closed: the first point may be
        repeated last or not.
    tol : float
        Largest allowed distance ``|C(u_i) - p_i|`` of each point from the curve at its
        parameter, > 0.
    degree : int
        Spline degree (default 5); ``degree >= l``. ``degree = 2 l - 1`` gives the exact
        minimiser over all curves (see Notes).
    l : int or dict
        The energy ``E_l = int |C^(l)|^2 du`` (default 3, the third derivative: the one whose
        sign changes of curvature derivative fairing is about), or a blend ``{order: weight}``.
    param : {"chord", "centripetal", "uniform"} or array_like
        The parameters ``u_i`` (:func:`curvefair.parameterize`); kept fixed. Closed curves: one
        more value for the closing point.
    closed : bool
        Periodic curve.
    max_steps : int
        Interior-point iteration cap (typically 20-60 are used).

    Returns
    -------
    PointFairingResult
        ``curve``, ``params``, ``report``, ``multipliers``.

    Raises
    ------
    InputError
        Bad points, tol, degree, l or param.

    Notes
    -----
    The problem ``min E_l(C)`` s.t. ``|C(u_i) - p_i| <= tol`` is a convex QP (second-order
    cone constraints), solved by :func:`tube_energy_qp` from the interpolating spline (strictly
    feasible) on the knot vector with a knot at every data parameter. The tolerance is
    guaranteed at the data points (every iterate is strictly feasible), not between them:
    there is no reference curve between the points.

    Optimality over all curves (``degree = 2 l - 1``): for any ``C`` with ``C^(l)`` square
    integrable, the natural spline ``S`` of degree ``2l - 1`` with knots at the ``u_i`` that
    interpolates ``C(u_i)`` has ``E_l(S) <= E_l(C)`` (Holladay's theorem, de Boor, *A Practical
    Guide to Splines*, ch. XIII, for each coordinate), so the minimiser lies in this spline
    space (open curves: the natural end conditions ``C^(l..2l-2) = 0`` follow from the
    optimality, they are not imposed). With ``l = 2`` and ``degree = 3`` this is the tolerance
    form of the cubic smoothing spline (Reinsch 1967 minimises ``E_2`` subject to a sum of
    squared residuals instead of one bound per point).

    The analysis of the result is the user's to run (:func:`curvefair.analyze`); ``report``
    holds the deviation at the points, the energy and the solver's state.

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair.fairing.pipeline import fair_points
    >>> t = np.linspace(0, np.pi, 40)
    >>> rng = np.random.default_rng(0)
    >>> pts = np.c_[np.cos(t), np.sin(t)] + rng.normal(0, 1e-3, (40, 2))
    >>> res = fair_points(pts, tol=4e-3)
    >>> bool(res.report["max_deviation"] <= 4e-3), res.report["stop_reason"]
    (True, 'converged')
    """
    p = as_degree(degree)
    tolv = as_positive(tol, "tol", window=True)
    assert tolv is not None
    w = _energy_weights(l, p)
    if isinstance(max_steps, bool) or not isinstance(max_steps, (int, np.integer)) \
            or max_steps < 1:
        raise InputError(f"max_steps must be an integer >= 1, got {max_steps!r}")
    closed = bool(closed)
    if closed:
        pts, u_all = closed_point_data(points, param)
        if pts.shape[0] < p + 1:
            raise InputError(f"a closed degree-{p} curve needs at least {p + 1} distinct "
                             f"points, got {pts.shape[0]}")
        u = u_all[:-1]
    else:
        pts = as_points(points, "points", min_points=p + 1)
        u_all = parameterize(pts, param)
        u = u_all
    c0 = _start_curve(pts, u_all, p, closed, w)
    # the tube is solved a rounding margin inside tol, so that |C(u_i) - p_i| <= tol holds as
    # float64 evaluates it (the interior-point iterate may end within 1e-12 of the constraint)
    margin = min(0.25 * tolv, 1e-10 * tolv + 64.0 * np.finfo(float).eps * float(np.abs(pts).max()))
    curve, mult, its, reason = tube_energy_qp(c0, u, pts, tolv - margin, l=w,
                                              max_steps=int(max_steps))
    dev = np.sqrt(np.sum((curve(u) - pts) ** 2, axis=1))
    i = int(np.argmax(dev))
    G = _gram(curve, w)
    d0 = np.asarray(c0.control_points)
    d1 = np.asarray(curve.control_points)
    report = {
        "tol": tolv, "degree": p, "l": l if isinstance(l, (int, np.integer)) else str(l),
        "n_points": int(pts.shape[0]), "n_ctrl": int(curve.n_ctrl), "closed": closed,
        "max_deviation": float(dev[i]), "max_deviation_index": i,
        "n_active": int(np.sum(dev > (1.0 - 1e-6) * tolv)),
        "energy_before": float(np.sum(d0 * (G @ d0))),
        "energy_after": float(np.sum(d1 * (G @ d1))),
        "iterations": int(its), "stop_reason": reason,
    }
    uu = np.array(u)
    uu.setflags(write=False)
    mult.setflags(write=False)
    return PointFairingResult(curve, uu, report, mult)
