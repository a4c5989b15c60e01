"""Point data faired as it is rebuilt: the natural cubic through moved points, sparse r''' jumps.

A point file (CSV, airfoil ``.dat``, polyline) stores only points. Whoever reads the written
file back -- curvefair itself, or any CAD tool -- rebuilds the curve as the chord-length natural
cubic spline through them. :func:`points_l1` therefore optimises the moved data points
``q_i`` themselves, and the fairness it minimises is that of ``S_q``, the natural cubic
interpolant of the ``q_i`` at the input's parameters (its chord lengths for a point file;
see "Parameters and the tolerance" below for why not those of ``q``):

    minimise    Phi(q) = sum_k w_k |J_k(q)|^2 + beta E3(q)
    subject to  |q_i - p_i| <= tol   (every data point i; held points: q_i = p_i)
                |S_q(t) - S_p(t)| <= tol   (every parameter t of the domain)

with ``J_k = S_q'''(u_k+) - S_q'''(u_k-)`` the jump of the third derivative at the interior
parameter ``u_k`` and ``E3 = int |S_q'''|^2 du`` (``beta`` small, it only ties the null space).

Why the third-derivative jumps. Between two parameters a cubic has at most a few curvature
extrema; each jump of ``r'''`` is where a new cubic piece starts, i.e. a possible new extremum.
A curve whose jumps are *sparse* is a cubic spline with few active knots -- the shape a
least-squares spline with few knots (``make_splprep``) finds, here at the given maximum
deviation and on the interpolant that will be rebuilt. Sparsity comes from the weighted L1
norm ``sum_k |J_k|`` (group norm over the coordinates, rotation invariant), minimised by
iterative reweighting (Candes, Wakin & Boyd 2008): each round solves the quadratic problem
above with ``w_k = 1 / (|J_k^prev| + delta)``, which is a majorant of
``sum_k log(|J_k| + delta)``.

Linear structure. At fixed parameters ``u`` the natural cubic interpolant is linear in the
points. It is written as a clamped cubic B-spline with a knot at every ``u_i``: coefficients
``c_0 .. c_{n+2}`` (``n + 1`` points), of which ``c_0`` and ``c_{n+2}`` are eliminated by the
natural end conditions ``S''(u_0) = S''(u_n) = 0``:

    c_0 = (1 + r_0) c_1 - r_0 c_2,   r_0 = h_0 / (h_0 + h_1)  (and mirrored at the end),

leaving ``x = (c_1 .. c_{n+1})``, one unknown per point. Then ``q = A x`` with ``A``
tridiagonal (the B-spline values at the knots, de Boor ch. IX), the span-wise third derivative
``g = D3 D2 D1 c`` by the derivative recursion ``d^(r)_j = (k - r + 1)(d^(r-1)_j -
d^(r-1)_{j-1}) / (t_{j+k-r+1} - t_j)``, and ``J = Dj g`` (first differences), a banded
operator of 5 coefficients per jump. ``Phi`` is ``x^T K x`` per coordinate with
``K = Jm^T W Jm + beta sum_k h_k G_k^T G_k`` of half-bandwidth 4.

Solver. Primal-dual interior point with strictly feasible iterates (Boyd & Vandenberghe,
*Convex Optimization*, sec. 11.7) on the second-order-cone constraints
``f_i = (|A_i x - p_i|^2 / r_i^2 - 1) / 2 <= 0``; its Newton matrix
``2 K / Phi_0 (x) I + A^T blockdiag(B_i) A`` is block banded (bandwidth ``5 dim - 1``) and is
factorised by the band Cholesky kernel of :mod:`curvefair._kernels.global_fair`: ``O(n)``
time and memory per Newton step. The whole loop (residuals, assembly, factorisation, step
length, line search) runs compiled, :func:`curvefair._kernels.points.tube_ipm`.

Jump costs and the choice among them. The L1 norm weighs every jump alike, so on data whose
spacing varies 1:100 (an airfoil's leading edge) the dense end's jumps -- ``(h_max /
h_min)^3`` larger for the same noise -- dominate it. ``scale`` sets per-jump costs ``c_k`` in
``sum_k c_k |J_k|`` (:func:`_jump_costs`): ``"spacing"``, ``c_k = hbar_k^3`` (the jump measured
by the move that would undo it), ``"input"``, ``c_k = 1 / median_9(|J(p)|)_k`` (against the
noise around it); the reweighting becomes ``w_k = c_k^2 / (c_k |J_k| + delta)``. No single
cost wins everywhere (measured on the quality benchmark's airfoils and point files), so the
driver (``select``, default 3 up to ``SELECT_MAX_POINTS``) solves with each and keeps the
result whose written points rebuild -- chord-length natural cubic, as a reader does -- into
the fewest curvature extrema (then inflections).

Closed point lists. The periodic cubic through the points (``closed=True``) is a cubic
B-spline on the parameters extended periodically, coefficients wrapping
(:func:`periodic_operators`): the same unknowns (one per point), every point's jump, and
matrices banded with corner terms. Reordered ``0, N-1, 1, N-2, ...`` (:func:`_zigzag`) they
are ordinary bands of twice the width; the interior point (:func:`_tube_qp_cyclic`, the same
steps in numpy) factorises each Newton matrix in that order with LAPACK's band Cholesky.

Parameters and the tolerance. The problem is solved at the input's own parameters ``u``
(chord lengths of the input points for a point file) and the result is the natural cubic
through ``q`` at those parameters, on the input's domain: the difference ``S_q - S_p`` is the
natural cubic through ``q - p`` at fixed parameters, linear in the moves, so the
equal-parameter deviation ``max_t |S_q(t) - S_p(t)|`` that :func:`curvefair.fair` certifies
is a convex constraint. It is imposed at the data points and at ``samples`` points inside
every span (the same second-order cones, rows of four B-spline values); the interpolant of
alternating moves can still overshoot between them, so the certified bound (Bernstein form of
the difference curve) is computed and, where it exceeds ``tol``, the radii are shrunk by the
excess and the problem solved again (scaling the moves instead would bring the noise back).
The curve a reader rebuilds from the written points uses the chord lengths of ``q``; at
fixed parameters the points of a fair curve sit along it, so the rebuilt curve is the same
curve up to a smooth change of parameter and close to it (its Hausdorff distance from the
input's chord interpolant is checked too, ``curve_tol``). Where it strays farther, it does so
on a few spans: short spans where the noisy input's interpolant kinks and a smooth curve
cannot follow it. Lists of up to ``LOCAL_SHRINK_MIN_POINTS`` points shrink every radius by
the excess (a local halving on a coarse list leaves a visible jump); longer lists whose excess
would need a harsh global factor shrink the radii near those spans only
(:func:`_local_factors`), so that a handful of spans among thousands do not narrow the whole
tube. Keeping the chord parameters of
``q`` instead (affinely onto the input's domain) is not an option: the chord lengths of noisy
samples drift from those of the smoothed points like a random walk (45 tol at 10,000 noisy
points of ``benchmarks/bench_points_l1.py``), far beyond any equal-parameter tolerance.
"""

from __future__ import annotations

import weakref
from collections.abc import Iterable
from dataclasses import dataclass, field, replace
from typing import Any, cast

import numpy as np
import scipy.sparse as sp

from .._typing import ArrayLike, FloatArray
from .._validate import as_points, as_positive
from ..analysis import matched_hermite_bound
from ..curves.hermite import CubicHermite
from ..curves.interpolate import interpolate_cubic
from ..curves.parameterize import parameterize
from ..errors import InputError
from ._guard import is_chord_interpolant as _is_natural_chord_interpolant
from ._guard import rebuilt_analysis
from .problem import FairingHistory, FairingProblem, Outcome
from .stop import StopReason

__all__ = ["points_l1", "PointsL1Result", "natural_operators"]


@dataclass(frozen=True, eq=False)
class PointsL1Result:
    """Result of :func:`points_l1`.

    Attributes
    ----------
    points : ndarray, shape (n + 1, dim)
        The moved points ``q``; ``|q_i - p_i| <= tol`` in float64 for every ``i``.
    curve : CubicHermite
        ``interpolate_cubic(points, params, "natural")``: on the input's parameters, within
        ``tol`` of the input's natural cubic at equal parameter (certified).
    report : dict
        ``rounds`` (reweighting rounds), ``newton_steps``, ``stop_reason``, ``n_active``,
        ``jumps_l1_before`` / ``jumps_l1_after`` (``sum_k |J_k|`` on the input's parameters),
        ``attempts`` (solves with shrunk radii), ``param_deviation`` (certified bound of the
        equal-parameter deviation), ``curve_deviation`` (upper bound of the Hausdorff
        distance of the curve rebuilt from the points, chord lengths of ``q``, from the
        input's chord interpolant, :func:`_rebuilt_distance`; None without ``curve_tol``),
        ``scale`` (factor of a final scaling of the moves, 1.0: none), ``tube_radius`` (only
        when ``tol`` exceeds ``SHRINK_CAP`` of the input's size, :func:`_size`: the radius
        used).
    """

    points: np.ndarray
    curve: CubicHermite
    report: dict[str, Any] = field(default_factory=dict)
    #: internal: the curve rebuilt from ``points`` when points_l1 made it (else None)
    _rebuilt: CubicHermite | None = field(default=None, repr=False, compare=False)


# ------------------------------------------------------------------------------------------
# operators
# ------------------------------------------------------------------------------------------
def _diff_op(t: FloatArray, ncoef: int, k: int, shift: int) -> sp.csr_matrix:
    """Derivative of a degree-``k`` spline: ``d_j = k (c_{j+1} - c_j) / (t_{j+k+1+shift} -
    t_{j+1+shift})``, ``j = 0 .. ncoef - 2`` (``shift`` offsets the knot vector)."""
    j = np.arange(ncoef - 1)
    den = t[j + k + 1 + shift] - t[j + 1 + shift]
    f = k / den
    return sp.csr_matrix((np.r_[-f, f], (np.r_[j, j], np.r_[j, j + 1])),
                         shape=(ncoef - 1, ncoef))


@dataclass(frozen=True)
class NaturalOperators:
    """Linear maps of the natural cubic through points at parameters ``u`` (see module doc).

    ``A`` (N x N, tridiagonal): ``q = A x``; ``G`` ((N - 1) x N): ``S'''`` on each span;
    ``Jm`` ((N - 2) x N): third-derivative jumps at the interior parameters; ``E`` ((N + 2) x N):
    the B-spline coefficients ``c = E x``; ``t`` the knot vector.
    """

    u: FloatArray
    t: FloatArray
    A: sp.csr_matrix
    G: sp.csr_matrix
    Jm: sp.csr_matrix
    E: sp.csr_matrix
    #: products that depend on the operators only, built once (see :func:`_energy_matrix`)
    cache: dict[Any, Any] = field(default_factory=dict, compare=False, repr=False)


def natural_operators(u: ArrayLike) -> NaturalOperators:
    """The operators of :class:`NaturalOperators` for parameters ``u`` (N >= 3, increasing).

    The factors (end conditions, derivative differences) are made as CSR arrays directly and
    multiplied by :func:`curvefair._kernels.points.csr_matmat`, scipy's own product (the same
    sums in the same order, the same stored order): bitwise the matrices of
    :func:`_natural_operators_sparse`, without a dozen scipy.sparse constructions."""
    from scipy.interpolate import BSpline

    from .._kernels import points as _pk

    u = np.asarray(u, dtype=float)
    N = u.shape[0]
    n = N - 1
    t = np.r_[[u[0]] * 4, u[1:-1], [u[-1]] * 4]
    h = np.diff(u)
    r0 = h[0] / (h[0] + h[1])
    r1 = h[-1] / (h[-1] + h[-2])
    i32 = np.int32
    # E ((N + 2) x N), canonical CSR: row 0 (1 + r0, -r0), rows 1 .. N the identity, row N + 1
    # (-r1 at N - 2, 1 + r1 at N - 1)
    Ep = np.r_[0, 2 + np.arange(N + 1), N + 4].astype(i32)
    Ej = np.r_[0, 1, np.arange(N), N - 2, N - 1].astype(i32)
    Ex = np.r_[1.0 + r0, -r0, np.ones(N), -r1, 1.0 + r1]
    E = sp.csr_matrix((Ex, Ej, Ep), shape=(N + 2, N))
    Bd = BSpline.design_matrix(u, t, 3).tocsr()  # (N, N + 2)
    Ap, Aj, Ax = _pk.csr_matmat(N, N, Bd.indptr, Bd.indices, Bd.data, Ep, Ej, Ex)
    A = type(Bd)((Ax, Aj, Ap), shape=(N, N))  # Bd @ E is of Bd's class

    def diff(ncoef: int, k: int, shift: int) -> tuple[np.ndarray, np.ndarray, FloatArray]:
        # the matrix of _diff_op, canonical CSR: row j (-f_j at j, f_j at j + 1); k = 0: the
        # plain first differences (-1, 1)
        j = np.arange(ncoef - 1)
        f = k / (t[j + k + 1 + shift] - t[j + 1 + shift]) if k else np.ones(ncoef - 1)
        p = (2 * np.arange(ncoef)).astype(i32)
        c = np.empty(2 * (ncoef - 1), dtype=i32)
        c[0::2] = j
        c[1::2] = j + 1
        x = np.empty(2 * (ncoef - 1))
        x[0::2] = -f
        x[1::2] = f
        return p, c, x

    D1 = diff(N + 2, 3, 0)
    D2 = diff(N + 1, 2, 1)
    D3 = diff(N, 1, 2)
    P32 = _pk.csr_matmat(n, N + 1, *D3, *D2)
    P321 = _pk.csr_matmat(n, N + 2, *P32, *D1)
    Gp, Gj, Gx = _pk.csr_matmat(n, N, *P321, Ep, Ej, Ex)
    G = sp.csr_matrix((Gx, Gj, Gp), shape=(n, N))  # (n, N): S''' on span k
    Jp, Jj, Jx = _pk.csr_matmat(n - 1, N, *diff(n, 0, 0), Gp, Gj, Gx)
    Jm = sp.csr_matrix((Jx, Jj, Jp), shape=(n - 1, N))
    A.eliminate_zeros()
    return NaturalOperators(u, t, A, G, Jm, E)


def _natural_operators_sparse(u: ArrayLike) -> NaturalOperators:
    """:func:`natural_operators` built with scipy.sparse products (the reference its compiled
    products are tested against)."""
    from scipy.interpolate import BSpline
    u = np.asarray(u, dtype=float)
    N = u.shape[0]
    n = N - 1
    t = np.r_[[u[0]] * 4, u[1:-1], [u[-1]] * 4]
    h = np.diff(u)
    r0 = h[0] / (h[0] + h[1])
    r1 = h[-1] / (h[-1] + h[-2])
    # c = E x: x_j = c_{j+1}; c_0 and c_{N+1} from the natural end conditions
    rows = np.r_[0, 0, np.arange(1, N + 1), N + 1, N + 1]
    cols = np.r_[0, 1, np.arange(N), N - 1, N - 2]
    vals = np.r_[1.0 + r0, -r0, np.ones(N), 1.0 + r1, -r1]
    E = sp.csr_matrix((vals, (rows, cols)), shape=(N + 2, N))
    Bd = BSpline.design_matrix(u, t, 3).tocsr()  # (N, N + 2)
    A = (Bd @ E).tocsr()
    D1 = _diff_op(t, N + 2, 3, 0)
    D2 = _diff_op(t, N + 1, 2, 1)
    D3 = _diff_op(t, N, 1, 2)
    G = (D3 @ D2 @ D1 @ E).tocsr()  # (n, N): S''' on span k
    jj = np.arange(n - 1)
    Dj = sp.csr_matrix((np.r_[-np.ones(n - 1), np.ones(n - 1)],
                        (np.r_[jj, jj], np.r_[jj, jj + 1])), shape=(n - 1, n))
    Jm = (Dj @ G).tocsr()
    A.eliminate_zeros()
    return NaturalOperators(u, t, A, G, Jm, E)


def periodic_operators(u: ArrayLike) -> NaturalOperators:
    """The operators of :class:`NaturalOperators` for the periodic cubic through ``N`` points at
    parameters ``u`` (``N + 1`` values, ``u_N`` the parameter of the closing point, N >= 3).

    The periodic cubic is a cubic B-spline on the knots ``u`` extended by three spans at each
    side by the period ``P = u_N - u_0``; its ``N + 3`` coefficients wrap,
    ``c_{N + s} = c_s`` (``s = 0, 1, 2``), leaving ``x = (c_0 .. c_{N-1})``, one unknown per
    point (``E`` maps ``x`` to the ``N + 3`` coefficients). ``A`` (N x N): the values at
    ``u_0 .. u_{N-1}``, cyclic tridiagonal; ``G`` (N x N): ``S'''`` on span ``[u_k, u_{k+1}]``;
    ``Jm`` (N x N): the jump ``S'''(u_k+) - S'''(u_k-)`` at every point, cyclic (``k = 0``:
    span 0 minus span ``N - 1``). The matrices are banded with corner terms (the wrap).
    """
    from scipy.interpolate import BSpline
    u = np.asarray(u, dtype=float)
    N = u.shape[0] - 1
    P = u[-1] - u[0]
    t = np.r_[u[N - 3:N] - P, u, u[1:4] + P]
    rows = np.r_[np.arange(N), N + np.arange(3)]
    cols = np.r_[np.arange(N), np.arange(3)]
    E = sp.csr_matrix((np.ones(N + 3), (rows, cols)), shape=(N + 3, N))
    # the knots t[3] .. t[N + 3] are u_0 .. u_N: basis j is non-zero on (t_j, t_{j+4})
    Bd = BSpline.design_matrix(u[:-1], t, 3).tocsr()  # (N, N + 3)
    A = (Bd @ E).tocsr()
    D1 = _diff_op(t, N + 3, 3, 0)
    D2 = _diff_op(t, N + 2, 2, 1)
    D3 = _diff_op(t, N + 1, 1, 2)
    G3 = (D3 @ D2 @ D1 @ E).tocsr()  # (N, N): degree-0 coefficient j on (t_{j+3}, t_{j+4})
    G = G3
    k = np.arange(N)
    Dj = sp.csr_matrix((np.r_[np.ones(N), -np.ones(N)], (np.r_[k, k], np.r_[k, (k - 1) % N])),
                       shape=(N, N))
    Jm = (Dj @ G).tocsr()
    A.eliminate_zeros()
    return NaturalOperators(u, t, A, G, Jm, E)


def _band_lower(K: sp.spmatrix, width: int) -> FloatArray:
    """``Kb[j, o] = K[j + o, j]`` for ``o = 0 .. width``."""
    N = K.shape[0]
    Kc = K.tocoo()
    keep = (Kc.row >= Kc.col) & (Kc.row - Kc.col <= width)
    idx = Kc.col[keep].astype(np.int64) * (width + 1) + (Kc.row[keep] - Kc.col[keep])
    Kb = np.bincount(idx, weights=Kc.data[keep], minlength=N * (width + 1))
    return cast(FloatArray, Kb.astype(np.float64, copy=False).reshape(N, width + 1))


def _tridiag(A: sp.csr_matrix) -> FloatArray:
    """``Aw[i, s] = A[i, i - 1 + s]``."""
    N = A.shape[0]
    Ac = A.tocoo()
    s = Ac.col - Ac.row + 1
    if np.any((s < 0) | (s > 2)):  # pragma: no cover - the natural cubic's A is tridiagonal
        raise AssertionError("collocation is not tridiagonal")
    Aw = np.bincount(Ac.row.astype(np.int64) * 3 + s, weights=Ac.data, minlength=3 * N)
    return cast(FloatArray, Aw.astype(np.float64, copy=False).reshape(N, 3))


# ------------------------------------------------------------------------------------------
# the interior point for one quadratic problem
# ------------------------------------------------------------------------------------------
def _rows4(C: sp.spmatrix, width: int = 4) -> tuple[np.ndarray, FloatArray]:
    """``(start, W)`` with ``C[i, start_i + s] = W[i, s]`` (``s = 0 .. width - 1``): every row
    of ``C`` has its non-zeros in ``width`` consecutive columns (four for curve values of a
    cubic B-spline, five for a third-derivative jump)."""
    Cc = sp.csr_matrix(C)
    Cc.sum_duplicates()
    m, N = Cc.shape
    counts = np.diff(Cc.indptr)
    row = np.repeat(np.arange(m, dtype=np.int64), counts)
    # canonical CSR: the first stored column of a row is its smallest
    first = np.where(counts > 0, Cc.indices[np.minimum(Cc.indptr[:-1], max(Cc.nnz - 1, 0))],
                     0)
    start = np.minimum(first, N - width).astype(np.int64)
    s = Cc.indices - start[row]
    if np.any((s < 0) | (s >= width)):  # pragma: no cover - rows of the operators are banded
        raise AssertionError(f"operator row wider than {width} coefficients")
    W = np.bincount(row * width + s, weights=Cc.data, minlength=width * m)
    return start, cast(FloatArray, W.astype(np.float64, copy=False).reshape(m, width))


def _energy_band(ops: NaturalOperators, jrows: tuple[np.ndarray, FloatArray],
                 grows: tuple[np.ndarray, FloatArray], w: FloatArray, beta: float,
                 P: FloatArray, tau: float) -> FloatArray:
    """The lower band (``kd = 5 dim - 1``) of :func:`_energy_matrix`, assembled directly from
    the rows of ``Jm`` (``jrows``, :func:`_rows4` with width 5) and ``G`` (``grows``): no
    sparse products, ``O(n)`` time and memory."""
    from .._kernels import points as _pk

    dim = P.shape[1]
    N = ops.A.shape[0]
    eye = np.eye(dim)
    Wk = np.ascontiguousarray(w[:, None, None] * (P + tau * (eye[None] - P)))
    gw = beta * np.diff(ops.u) if beta > 0 else np.zeros(0)
    gs = grows[0] if beta > 0 else np.zeros(0, dtype=np.int64)
    L = np.empty((N * dim, 5 * dim))
    _pk.energy_band(jrows[0], jrows[1], Wk, gs, grows[1], gw, L)
    return L


def _tube_qp(K: sp.csr_matrix | FloatArray, A: sp.csr_matrix | None, x0: FloatArray,
             pts: FloatArray, rad: FloatArray, max_steps: int = 80, gap: float = 1e-9,
             lam0: FloatArray | None = None, stall: float = 0.0,
             rows: tuple[np.ndarray, FloatArray] | None = None
             ) -> tuple[FloatArray, FloatArray, int, str]:
    """``min sum_a x_a^T K x_a`` s.t. ``|A_i x - p_i| <= rad_i`` from a strictly feasible ``x0``.

    ``A`` any constraint matrix whose rows are curve values (four consecutive non-zeros at
    most); the interior point runs compiled (:func:`curvefair._kernels.points.tube_ipm`).
    Returns ``(x, lam, steps, reason)``; ``lam`` the multipliers of ``f_i`` (scaled problem:
    energy ``x^T K x / E0``, ``E0`` the energy of ``x0``). ``lam0`` warm-starts them. The
    surrogate gap has a rounding floor that grows with the number of constraints: below
    ``stall`` an iteration whose gap no longer halves in three steps counts as converged.
    ``rows``: :func:`_rows4` of ``A`` when the caller has it (then ``A`` may be None); ``K``
    may be given as its lower band (:func:`_energy_band`).
    """
    from .._kernels import points as _pk

    N, dim = x0.shape
    m = pts.shape[0]
    x = np.array(x0, dtype=np.float64, order="C")
    xf = x.reshape(-1)
    band = isinstance(K, np.ndarray)
    E0 = float(_pk.band_quad(K, xf)) if band else float(xf @ (K @ xf))
    if not E0 > 0:
        return x, np.zeros(m), 0, "zero_energy"
    Kb = K * (2.0 / E0) if band else _band_lower(K * (2.0 / E0), 5 * dim - 1)
    if rows is None:
        assert A is not None
        rows = _rows4(A)
    start, W = rows
    lam = np.ones(m) if lam0 is None else np.array(lam0, dtype=np.float64)
    steps, code = _pk.tube_ipm(Kb, start, W, np.ascontiguousarray(pts, dtype=np.float64),
                               np.ascontiguousarray(rad, dtype=np.float64), x, lam,
                               int(max_steps), float(gap), float(max(gap, stall)))
    if code == 0:
        reason = "converged"
    elif code == 1:
        reason = "max_steps"
    else:
        Cx = np.empty((m, dim))
        _pk.apply_rows(start, W, x, Cx)
        eta = float(-(lam @ (0.5 * (np.sum((Cx - pts) ** 2, axis=1) / rad ** 2 - 1.0))))
        reason = "converged" if eta < 1e-6 else "numerical"
    return x, lam, int(steps), reason


def _zigzag(N: int) -> np.ndarray:
    """Positions ``pos[j]`` of the order ``0, N-1, 1, N-2, 2, ...``: indices at cyclic
    distance ``d`` end at most ``2 d`` apart, so a cyclic band of half-width ``b`` becomes an
    ordinary band of half-width ``2 b`` (no fill-in outside it)."""
    pos = np.empty(N, dtype=np.int64)
    j = np.arange((N + 1) // 2)
    pos[j] = 2 * j
    r = np.arange(N // 2)
    pos[N - 1 - r] = 2 * r + 1
    return pos


def _tube_qp_cyclic(K: sp.csr_matrix, C: sp.csr_matrix, x0: FloatArray, pts: FloatArray,
                    rad: FloatArray, max_steps: int = 80, gap: float = 1e-9,
                    lam0: FloatArray | None = None
                    ) -> tuple[FloatArray, FloatArray, int, str]:
    """:func:`_tube_qp` for closed curves: the same primal-dual interior point (Boyd &
    Vandenberghe sec. 11.7, the steps of
    :func:`curvefair._kernels.points.tube_ipm`), in numpy, for a ``K`` and constraint
    rows ``C`` that wrap around (cyclic band). Each Newton matrix is put in the order of
    :func:`_zigzag`, where it is an ordinary band, and factorised by LAPACK's band Cholesky:
    ``O(n)`` per step."""
    from scipy.linalg import cho_solve_banded, cholesky_banded

    from .._kernels import points as _pk

    N, dim = x0.shape
    m = pts.shape[0]
    n = N * dim
    x = np.array(x0, dtype=np.float64)
    xf = x.reshape(-1)
    E0 = float(xf @ (K @ xf))
    if not E0 > 0:
        return x, np.zeros(m), 0, "zero_energy"
    Ks = (K * (2.0 / E0)).tocsr()
    Cc = sp.csr_matrix(C)
    # the sparse products of each step run compiled on the CSR arrays, in scipy's summation
    # orders (:func:`curvefair._kernels.points.cyclic_newton_band`, ``csr_matvecs``,
    # ``csr_t_matvecs``): bitwise the scipy.sparse figures, without a matrix built per step
    cp, ci, cx = (np.asarray(Cc.indptr, dtype=np.int64), np.asarray(Cc.indices, dtype=np.int64),
                  np.asarray(Cc.data, dtype=np.float64))
    kp, ki, kx = (np.asarray(Ks.indptr, dtype=np.int64), np.asarray(Ks.indices, dtype=np.int64),
                  np.asarray(Ks.data, dtype=np.float64))
    zpos = _zigzag(N)
    # Pm @ y (Pm the permutation matrix of the zigzag order) is y[i] at pos_full[i], added
    # onto 0.0 as scipy's matvec does
    pos_full = (zpos[:, None] * dim + np.arange(dim)[None, :]).reshape(-1)
    t2 = rad * rad
    lam = np.ones(m) if lam0 is None else np.array(lam0, dtype=np.float64)

    def c_mul(y: FloatArray) -> FloatArray:
        out = np.empty((m, dim))
        _pk.csr_matvecs(cp, ci, cx, np.ascontiguousarray(y), out)
        return out

    def ct_mul(z: FloatArray) -> FloatArray:
        out = np.empty((N, dim))
        _pk.csr_t_matvecs(cp, ci, cx, np.ascontiguousarray(z), out)
        return out

    def resid(x: FloatArray, lam: FloatArray, tinv: float
              ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        v = c_mul(x) - pts
        fi = 0.5 * (np.sum(v * v, axis=1) / t2 - 1.0)
        rc = -lam * fi - tinv
        kxv = np.empty((n, 1))
        _pk.csr_matvecs(kp, ki, kx, np.ascontiguousarray(x).reshape(n, 1), kxv)
        rd = kxv.reshape(N, dim) + ct_mul((lam / t2)[:, None] * v)
        return v, fi, rd, rc

    v, fi, rd, rc = resid(x, lam, 0.0)
    gscale = float(np.abs(rd).max()) or 1.0
    steps = 0
    code = 1
    while steps < max_steps:
        eta = float(-(fi @ lam))
        tinv = eta / (10.0 * m)
        v, fi, rd, rc = resid(x, lam, tinv)
        if eta < gap and float(np.abs(rd).max()) < 1e-8 * gscale:
            code = 0
            break
        ww = lam / (-fi)
        a = v / t2[:, None]
        blocks = ww[:, None, None] * a[:, :, None] * a[:, None, :] \
            + (lam / t2)[:, None, None] * np.eye(dim)[None]
        band, kd = _pk.cyclic_newton_band(cp, ci, cx, np.ascontiguousarray(blocks), kp, ki, kx,
                                          zpos, dim)
        ab = band[:kd + 1]
        rhs = -rd - ct_mul((rc / fi)[:, None] * a)
        try:
            cb = cholesky_banded(ab, lower=True)
        except np.linalg.LinAlgError:
            code = 2
            break
        yp = np.empty(n)
        yp[pos_full] = rhs.reshape(-1)
        dxp = cho_solve_banded((cb, True), yp + 0.0)
        dx = (dxp[pos_full] + 0.0).reshape(N, dim)
        if not np.all(np.isfinite(dx)):
            code = 2
            break
        Cdx = c_mul(dx)
        adx = np.sum(a * Cdx, axis=1)
        dlam = (rc - lam * adx) / fi
        neg = dlam < 0
        smax = min(1.0, float(np.min(-lam[neg] / dlam[neg]))) if np.any(neg) else 1.0
        a2 = np.sum(Cdx * Cdx, axis=1)
        a1 = np.sum(v * Cdx, axis=1)
        c0 = np.sum(v * v, axis=1) - t2
        ok2 = a2 > 0
        disc = np.maximum(a1[ok2] ** 2 - a2[ok2] * c0[ok2], 0.0)
        tmax = float(np.min((-a1[ok2] + np.sqrt(disc)) / a2[ok2])) if np.any(ok2) else np.inf
        st = min(0.99 * smax, 0.99 * tmax)
        rnorm = np.sqrt(float(np.sum((rd / gscale) ** 2) + np.sum(rc * rc)))
        while st > 1e-14:
            x1 = x + st * dx
            lam1 = lam + st * dlam
            v1, fi1, rd1, rc1 = resid(x1, lam1, tinv)
            if np.all(fi1 < 0.0):
                r1 = np.sqrt(float(np.sum((rd1 / gscale) ** 2) + np.sum(rc1 * rc1)))
                if r1 <= (1.0 - 0.01 * st) * rnorm:
                    break
            st *= 0.5
        if st <= 1e-14:
            code = 2
            break
        x, lam, fi = x1, lam1, fi1
        steps += 1
    if code == 0:
        reason = "converged"
    elif code == 1:
        reason = "max_steps"
    else:
        eta = float(-(lam @ (0.5 * (np.sum((Cc @ x - pts) ** 2, axis=1) / t2 - 1.0))))
        reason = "converged" if eta < 1e-6 else "numerical"
    return x, lam, int(steps), reason


# ------------------------------------------------------------------------------------------
# the method
# ------------------------------------------------------------------------------------------
def _jump_norms(ops: NaturalOperators, x: FloatArray, P: FloatArray | None = None
                ) -> FloatArray:
    """``|J_k|``, or ``|P_k J_k|`` with the per-jump projections ``P`` (shape (k, dim, dim))."""
    # ``ops.Jm @ x`` compiled on its CSR arrays as they are now (scipy's summation order: the
    # same values; the arrays are read at every call, since ``_rows4`` puts ``Jm`` in
    # canonical order in place after the first one)
    from .._kernels import points as _pk

    Jm = ops.Jm
    xa = np.ascontiguousarray(x, dtype=np.float64)
    J = np.empty((Jm.shape[0], xa.shape[1]))
    _pk.csr_matvecs(np.asarray(Jm.indptr, dtype=np.int64), np.asarray(Jm.indices, dtype=np.int64),
                    np.asarray(Jm.data, dtype=np.float64), xa, J)
    if P is not None:
        J = np.einsum("kab,kb->ka", P, J)
    return np.sqrt(np.sum(J * J, axis=1))


def _normal_projections(q: FloatArray, closed: bool = False) -> FloatArray:
    """``I - t_k t_k^T`` at every interior point (closed: every point), ``t_k`` the unit
    central chord direction."""
    d = np.roll(q, -1, axis=0) - np.roll(q, 1, axis=0) if closed else q[2:] - q[:-2]
    t = d / np.maximum(np.linalg.norm(d, axis=1), 1e-300)[:, None]
    dim = q.shape[1]
    return np.eye(dim)[None] - t[:, :, None] * t[:, None, :]


def _energy_matrix(ops: NaturalOperators, w: FloatArray, beta: float, P: FloatArray,
                   tau: float) -> sp.csr_matrix:
    """Interleaved ``sum_k J_k^T W_k J_k + beta sum_k h_k g_k^T g_k`` with
    ``W_k = w_k (P_k + tau (I - P_k))`` (``P_k`` the projection on the normal space)."""
    dim = P.shape[1]
    eye = np.eye(dim)
    Wk = w[:, None, None] * (P + tau * (eye[None] - P))
    Wb = _block_diag(Wk)
    # the interleaved jump operator and the E3 term depend on the parameters only: built
    # once per problem (the same matrices every round, so bitwise the same sums)
    JI = ops.cache.get(("JI", dim))
    if JI is None:
        JI = sp.kron(ops.Jm, sp.identity(dim), format="csr")
        ops.cache[("JI", dim)] = JI
    K = JI.T @ Wb @ JI
    if beta > 0:
        E3 = ops.cache.get(("E3", dim))
        if E3 is None:
            h = np.diff(ops.u)
            GI = sp.kron(ops.G, sp.identity(dim), format="csr")
            E3 = GI.T @ sp.diags(np.repeat(h, dim)) @ GI
            ops.cache[("E3", dim)] = E3
        K = K + beta * E3
    return K.tocsr()


def _block_diag(W: FloatArray) -> sp.csr_matrix:
    k, dim, _ = W.shape
    base = np.arange(k)[:, None, None] * dim
    r = np.broadcast_to(base + np.arange(dim)[None, :, None], W.shape).reshape(-1)
    c = np.broadcast_to(base + np.arange(dim)[None, None, :], W.shape).reshape(-1)
    return sp.csr_matrix((W.reshape(-1), (r, c)), shape=(k * dim, k * dim))


def _jump_costs(scale: str, u: FloatArray, ops: NaturalOperators, xp: FloatArray,
                P: FloatArray) -> FloatArray:
    """The cost ``c_k`` of the jump at interior parameter ``u_k`` in ``sum_k c_k |J_k|``.

    ``"none"``: 1. ``"spacing"``: ``hbar_k^3``, ``hbar_k`` the mean of the two spans at
    ``u_k`` -- a move ``m`` of one point changes the jumps next to it by about
    ``6 m / h^3``, so this measures every jump by the move that would undo it (where the
    points are dense, e.g. an airfoil's leading edge, the same noise makes jumps ``(h_TE /
    h_LE)^3`` larger). ``"input"``: ``1 / s_k``, ``s_k`` the running median (9 knots) of the
    input's own jumps, i.e. each jump measured against the noise around it."""
    n_int = ops.Jm.shape[0]
    if scale == "none":
        return np.ones(n_int)
    if scale == "spacing":
        h = np.diff(u)
        hb = 0.5 * (h[:-1] + h[1:]) if n_int == h.shape[0] - 1 else 0.5 * (h + np.roll(h, 1))
        c = hb ** 3
    elif scale == "input":
        from scipy.ndimage import median_filter

        j0 = _jump_norms(ops, xp, P)
        sm = median_filter(j0, size=min(9, max(1, n_int)), mode="nearest")
        top = float(sm.max()) if sm.size else 0.0
        if not top > 0:  # no jump anywhere (points on a line or a parabola): one cost
            return np.ones(n_int)
        c = 1.0 / np.maximum(sm, 1e-12 * top)  # the data are of unit size: top >> 1e-290
    else:
        raise InputError(f"scale must be 'none', 'spacing' or 'input', got {scale!r}")
    return c / float(c.max())


def _size(pts: FloatArray) -> float:
    """The size of a point set that rotating it does not change, for ``SHRINK_CAP``: twice
    the largest distance of a point from their mean (the diameter for a segment or a circle,
    at most twice it). The largest coordinate extent, used before, changes with the rotation:
    the same 7-point loop, rotated, was solved in a capped tube in one orientation and not in
    the other, and the results were 0.0066 apart at tol 0.5."""
    d = pts - pts.mean(axis=0)
    return 2.0 * float(np.sqrt(np.max(np.einsum("ij,ij->i", d, d))))


def points_l1(points: ArrayLike, tol: float, *, params: ArrayLike | None = None,
              hold: Iterable[int] | ArrayLike = (), rounds: int = 5, delta: float = 1e-5,
              beta: float = 1e-6,
              tau: float = 1.0, max_steps: int = 80, curve_tol: bool = True,
              samples: int = 3, max_attempts: int = 4, warm: float = 0.9,
              round_gap: float = 1e-6, warm_lam: bool = True,
              scale: str = "none", closed: bool = False,
              _shared: dict[str, Any] | None = None) -> PointsL1Result:
    """The natural cubic through moved points with the sparsest third-derivative jumps.

    Parameters
    ----------
    points : array_like, shape (n + 1, dim)
        Data points of an open curve (dim 2 or 3, n + 1 >= 4, no two consecutive equal).
    tol : float
        ``|q_i - p_i| <= tol`` for every moved point (float64), > 0, and
        ``max_t |S_q(t) - S_p(t)| <= tol`` at equal parameter (certified).
    params : array_like, shape (n + 1,), optional
        The parameters of the input's natural cubic ``S_p`` (default: its chord lengths); the
        result ``S_q`` lives on the same parameters.
    hold : iterable of int
        Indices of points that do not move (e.g. the end points).
    rounds : int
        Reweighting rounds (1: the plain quadratic problem with unit weights).
    delta : float
        Reweighting floor relative to the largest jump of the first round's solution:
        ``w_k = 1 / (|J_k| + delta max_k |J_k|)``.
    beta : float
        Weight of ``E3`` relative to the jump term (scaled so that the two are comparable on
        the input: ``beta * E3(p) / sum |J_k(p)|^2``).
    max_steps : int
        Interior-point iteration cap per solve.
    curve_tol : bool
        Also keep the curve rebuilt from the written points (the chord-length natural cubic
        through ``q``) within ``tol`` of the input's chord-length natural cubic as a curve
        (Hausdorff distance, :func:`_rebuilt_distance`), as the read-back check
        of a written point file measures it: when it strays farther, the radii are scaled by
        ``0.98 tol / bound`` (long lists with a large excess: near the offending spans only,
        ``LOCAL_SHRINK_*``) and the problem solved again (``max_attempts`` times at most; the
        equal-parameter bound shrinks them all by ``0.97 tol / bound``).
    samples : int
        Curve samples per span (equally spaced inside it) constrained like the data points:
        ``|S_q(s) - S_p(s)| <= tol``; the certified bound then rarely needs the final scaling.
    scale : {"none", "spacing", "input"}
        Per-jump costs ``c_k`` of the L1 norm ``sum_k c_k |J_k|`` (module docstring,
        :func:`_jump_costs`).
    closed : bool
        ``points`` are the ``N`` distinct points of a closed list (no repeated closing point;
        ``params`` then has ``N + 1`` values): the periodic cubic (:func:`periodic_operators`).

    _shared : dict, optional
        Internal: a dict kept by the caller across calls on the same ``points``, ``params``,
        ``hold``, ``closed``, ``samples``, ``beta`` and ``curve_tol`` (only ``tol`` and the
        reweighting options may differ), e.g. the formulations and tolerance back-offs of
        :func:`solve`. The work that does not depend on ``tol`` (validation, parameters,
        operators, constraint rows, the input's curves) is done by the first call and reused
        by the others: the same arrays, so the same results bit for bit.

    Returns
    -------
    PointsL1Result

    Notes
    -----
    The equations are in the module docstring. Each solve runs a rounding margin inside
    ``tol`` (``min(tol/4, 1e-9 tol + 64 eps max|p|)``); held points get radius
    ``1e-4 tol`` and are set back to ``p_i`` exactly before the curve is built. The result
    passes through :func:`curvefair.fairing._tolerance.enforce_tolerance`: data points pulled
    back inside ``tol`` in float64, the equal-parameter deviation certified on the difference
    curve ``S_{q - p}`` (linear in the moves at fixed parameters), every move scaled by one
    factor if the bound exceeds ``tol``.
    """
    from ._tolerance import _pull_back, difference_deviation, enforce_tolerance

    sh: dict[str, Any] = {} if _shared is None else _shared
    first = "p_in" not in sh
    if first:
        sh["p_in"] = as_points(points, "points", min_points=4)
    tolv = as_positive(tol, "tol")
    assert tolv is not None
    pts = sh["p_in"]
    N, dim = pts.shape
    bc = "periodic" if closed else "natural"

    def spline(q: FloatArray, u: Any) -> CubicHermite:
        return interpolate_cubic(np.vstack([q, q[:1]]) if closed else q, u, bc)

    if first:
        # a closed list: the N distinct points, parameters N + 1 (the closing point's last)
        sh["u_in"] = parameterize(np.vstack([pts, pts[:1]]) if closed else pts,
                                  "chord" if params is None else params)
        held = np.zeros(N, dtype=bool)
        for i in np.asarray(list(cast(Iterable[int], hold)), dtype=int).reshape(-1):
            if not -N <= i < N:
                raise InputError(f"hold index {i} out of range for {N} points")
            held[i] = True
        sh["held"] = held
        sh["ref_in"] = spline(pts, sh["u_in"])
        # solved on centred, unit-size data (conditioning; a tol of 1e300 or 1e-300 must not
        # overflow): a radius beyond 1e6 sizes binds nothing, one below 1e-12 moves nothing
        sh["centre"] = 0.5 * (pts.max(axis=0) + pts.min(axis=0))
        sh["size"] = float(np.ptp(pts, axis=0).max())
        sh["reach"] = _size(pts)
    u_in, held, ref_in = sh["u_in"], sh["held"], sh["ref_in"]
    centre, size, reach = sh["centre"], sh["size"], sh["reach"]
    p_in = pts
    if not size > 0 or tolv < 1e-12 * size:
        q0 = np.array(p_in)
        q0.setflags(write=False)
        return PointsL1Result(q0, ref_in, {"rounds": 0, "newton_steps": 0,
                                           "stop_reason": "tolerance", "n_active": 0,
                                           "attempts": 0, "pulled_back": 0, "scale": 1.0})
    tol_out = tolv
    # the objective falls with the curve's scale: a curve that fits in the tube would shrink
    # towards a point (an 8-point circle 3.5 across at tol 5 came out 4e-12 across); the
    # radius is at most SHRINK_CAP of the size (:func:`_size`, which a rotation does not
    # change; ``size`` above only scales the data for conditioning)
    cap = SHRINK_CAP * reach / size
    capped = tolv / size > cap
    tolv = min(tolv / size, cap)
    ns = max(0, int(samples))

    def setup(u: FloatArray) -> tuple[NaturalOperators, FloatArray, Any, FloatArray, float]:
        """Operators at parameters ``u``, the input's natural cubic ``xp`` there, the
        constraint rows ``C`` (data points, then ``ns`` samples per span) with their
        centres ``Y``, and the E3 weight ``b``."""
        from scipy.interpolate import BSpline
        ops = periodic_operators(u) if closed else natural_operators(u)
        xp = _solve(ops.A, pts, closed, ops.cache)  # the input's cubic at these parameters
        if ns:
            fr = np.arange(1, ns + 1) / (ns + 1.0)
            us = (u[:-1, None] + np.diff(u)[:, None] * fr[None, :]).reshape(-1)
            us = np.clip(us, u[0], u[-1])
            Bs = (BSpline.design_matrix(us, ops.t, 3) @ ops.E).tocsr()
            C = sp.vstack([ops.A, Bs]).tocsr()
            Y = np.vstack([pts, Bs @ xp])
        else:
            C, Y = ops.A, pts
        jn0 = _jump_norms(ops, xp)
        h = np.diff(u)
        e3 = float(np.sum(h[:, None] * (ops.G @ xp) ** 2))
        jj = float(np.sum(jn0 * jn0))
        b = beta * jj / e3 if e3 > 0 and jj > 0 else beta
        return ops, xp, C, Y, b

    if "ops" not in sh:
        pts = (pts - centre) / size
        sh["pts"] = pts
        # the parameters, affinely onto the chord length of the unit-size data (conditioning)
        chord = float(np.sum(np.sqrt(np.sum(np.diff(np.vstack([pts, pts[:1]]) if closed
                                                    else pts, axis=0) ** 2, axis=1))))
        u = (u_in - u_in[0]) * (chord / (u_in[-1] - u_in[0]))
        sh["u"] = u
        ops, xp, C, Y, b = setup(u)
        sh["ops"], sh["xp"], sh["Y"], sh["b"] = ops, xp, Y, b
        sh["n_samples"] = C.shape[0] - N
        # open curves: the compiled solver needs the rows of C only (four B-spline values
        # each) and the energy's band (no sparse matrix kept); closed ones wrap around (numpy
        # solver)
        if closed:
            sh["C"] = C
        else:
            sh["rows"] = _rows4(C)
            sh["jrows"], sh["grows"] = _rows4(ops.Jm, 5), _rows4(ops.G)
        sh["j_before"] = float(_jump_norms(ops, xp).sum())
        sh["Pn"] = _normal_projections(pts, closed)
        sh["ref"] = spline(p_in, "chord") if curve_tol else None
        sh["cost"] = {}
    pts, u, ops, xp, Y, b = sh["pts"], sh["u"], sh["ops"], sh["xp"], sh["Y"], sh["b"]
    C = sh.get("C")
    rows = sh.get("rows")
    if not closed:
        jrows, grows = sh["jrows"], sh["grows"]
    margin = min(0.25 * tolv, 1e-9 * tolv + 64.0 * np.finfo(float).eps * float(np.abs(pts).max()))
    rad_s = np.full(sh["n_samples"], tolv - margin)
    rad_p = np.where(held, 1e-4 * tolv, tolv - margin)
    j_before = sh["j_before"]
    Pn = sh["Pn"]
    newton = 0
    rounds_done = 0
    attempts = 0
    curve_dev = None
    ref = sh["ref"]
    reason = "converged"
    # per-jump cost c_k of the L1 norm sum_k c_k |J_k| (see ``scale``)
    if scale not in sh["cost"]:
        sh["cost"][scale] = _jump_costs(scale, u, ops, xp, Pn)
    cost = sh["cost"][scale]
    nj = cost.shape[0]
    w = cost * cost
    w *= nj / float(w.sum())
    x = xp
    lam = None
    floor = None
    shrink = 1.0
    went_local = False
    while True:
        attempts += 1
        rad = np.r_[rad_p, rad_s]
        # a new attempt (radii shrunk by ``shrink``) goes on from the weights and the solution
        # of the last one, with two more rounds
        nr = max(1, int(rounds)) if attempts == 1 else min(2, max(1, int(rounds)))
        for r in range(nr):
            K = (_energy_matrix(ops, w, b, Pn, tau) if closed
                 else _energy_band(ops, jrows, grows, w, b, Pn, tau))
            # strictly feasible start: the last solution pulled toward the input's curve
            x0 = xp + (warm * shrink) * (x - xp) if (r > 0 or attempts > 1) else xp
            shrink = 1.0
            last = r == nr - 1
            if closed:
                x, lam, st, reason = _tube_qp_cyclic(
                    K, C, x0, Y, rad, max_steps=max_steps, gap=1e-9 if last else round_gap,
                    lam0=None if (lam is None or not warm_lam) else np.maximum(lam, 1e-3))
            else:
                x, lam, st, reason = _tube_qp(
                    K, None, x0, Y, rad, max_steps=max_steps, gap=1e-9 if last else round_gap,
                    stall=0.0 if last else 100.0 * round_gap, rows=rows,
                    lam0=None if (lam is None or not warm_lam) else np.maximum(lam, 1e-3))
            newton += st
            rounds_done += 1
            z = cost * _jump_norms(ops, x, Pn)
            if floor is None:
                floor = delta * float(z.max()) if z.size and z.max() > 0 else 1.0
            # sum_k w_k |J_k|^2 with w_k = c_k^2 / (z_k + floor) majorises sum_k z_k
            w = cost * cost / (z + floor)
            w *= nj / float(w.sum())
        q = ops.A @ x
        q[held] = pts[held]
        # back to the data's units; float64 tolerance: pull back anything rounding put
        # outside (along its move)
        q_out = centre + size * q
        q_out[held] = p_in[held]
        q_out, pulled = _pull_back(p_in, q_out, tol_out)
        curve = spline(np.array(q_out), u_in)
        # equal parameter: the certified bound of the difference curve S_{q - p}; where it
        # exceeds tol (the interpolant of alternating moves overshoots between its samples),
        # the radii are shrunk by the excess and the problem solved again (a re-solve keeps
        # the sparsity, scaling the moves would not)
        # the global factor (equal-parameter bound, mild rebuilt-curve excess) and, for long
        # lists with a harsh rebuilt-curve excess, per-span local factors (LOCAL_SHRINK_*)
        shrink = 1.0
        local: tuple[FloatArray, FloatArray] | None = None
        _, ub, _ = difference_deviation(ref_in, curve)
        if ub > tol_out:
            shrink = 0.97 * tol_out / ub
        if ref is not None:
            # the curve rebuilt from the written points (chord-length parameters of q): the
            # read-back check of a point file measures its (Hausdorff) distance from the
            # input's chord-length interpolant
            # (:func:`_rebuilt_distance`: an O(n) bound, sampled where it is not sharp; the
            # geometric distance of :func:`curvefair.deviation` takes seconds at 10,000 points)
            rebuilt: Any = spline(np.array(q_out), "chord")
            per = matched_hermite_bound(ref, rebuilt)
            curve_dev = _rebuilt_distance(ref, rebuilt, tol_out, per=per)
            if curve_dev > tol_out:
                g = 0.98 * tol_out / curve_dev
                if (N > LOCAL_SHRINK_MIN_POINTS and (went_local or g < LOCAL_SHRINK_BELOW)
                        and np.any(per > tol_out)):
                    went_local = True
                    local = _local_factors(per, tol_out, closed)
                else:
                    shrink = min(shrink, g)
        if local is None and shrink >= 1.0 or attempts > max_attempts:
            break
        if local is None:
            rad_p = np.where(held, rad_p, rad_p * shrink)
            rad_s = rad_s * shrink
        else:
            pf, sf = local
            rad_p = np.where(held, rad_p, rad_p * np.minimum(pf, shrink))
            rad_s = (rad_s.reshape(sf.shape[0], -1) * np.minimum(sf, shrink)[:, None]
                     ).reshape(-1)
            # the warm start of the next attempt is pulled toward the input by the smallest
            # factor (strictly inside every shrunk ball)
            shrink = min(shrink, float(pf.min()))
    # equal parameter: certified on the difference curve, every move scaled if needed
    curve_in = curve
    curve_e, cert = enforce_tolerance(ref_in, curve, tol_out, curve_bound=True)
    curve = cast(CubicHermite, curve_e)
    q_out = np.array(curve.points)[:N]
    x1 = _solve(ops.A, (q_out - centre) / size, closed, ops.cache)
    dev = np.sqrt(np.sum((q_out - p_in) ** 2, axis=1))
    report = {"rounds": rounds_done, "newton_steps": newton, "stop_reason": reason,
              "n_active": int(np.sum(dev > (1.0 - 1e-6) * tol_out)),
              "jumps_l1_before": j_before / size ** 2,
              "jumps_l1_after": float(_jump_norms(ops, x1).sum()) / size ** 2,
              "pulled_back": int(pulled) + int(cert.pulled_back), "attempts": attempts,
              "curve_deviation": curve_dev, "param_deviation": float(cert.upper_bound),
              "scale": float(cert.scale)}
    if capped:
        report["tube_radius"] = SHRINK_CAP * reach
    q_out.setflags(write=False)
    out = PointsL1Result(q_out, curve, report)
    if curve_e is curve_in and ref is not None:
        # the last attempt's rebuilt curve is that of the points returned (for :func:`solve`)
        object.__setattr__(out, "_rebuilt", rebuilt)
    return out


#: the largest tube radius of :func:`points_l1`, as a fraction of the input's size
#: (:func:`_size`; a larger ``tol`` is used as this; ``report["tube_radius"]`` then says
#: the radius used): sparse third-derivative jumps are cheaper on a smaller curve, so without
#: it a curve smaller than the tolerance collapses to a point (the small closed polygons of
#: OCCT's ``modeling_data_continuity_curves.svg`` at tol 2 and 5, whose written files read
#: back without them)
SHRINK_CAP = 0.125

#: above this many points (and only when a global factor would be harsh, see
#: ``LOCAL_SHRINK_BELOW``) the radii are shrunk near the spans whose rebuilt curve strays
#: beyond ``tol`` instead of everywhere: with tens of thousands of points the offending spans
#: are a small fraction (short spans where the noisy input's interpolant kinks), and one global
#: factor spends the whole tube on them (100,000 noisy spiral points: four global shrinks to
#: 0.21 tol for the last 3 offending spans). On coarse files a local halving leaves a visible
#: jump instead (33-point airfoils of the quality benchmark: up to 7 more curvature extrema),
#: so small lists keep the global factor
LOCAL_SHRINK_MIN_POINTS = 5_000

#: the global factor ``0.98 tol / distance`` below which the shrink goes local (and stays so
#: for the later attempts of the same call)
LOCAL_SHRINK_BELOW = 0.9

#: a span whose per-span bound ``b_s`` exceeds ``tol`` has its radii, and those of the points
#: and spans within ``LOCAL_SHRINK_REACH`` spans of it, multiplied by
#: ``LOCAL_SHRINK_FACTOR * 0.98 tol / b_s``: decisively, since the interpolant's overshoot on a
#: span depends on the moves of the points around it (a factor of just ``0.98 tol / b_s``
#: moved the excess to the neighbouring spans attempt after attempt)
LOCAL_SHRINK_FACTOR = 0.5
LOCAL_SHRINK_REACH = 5


def _local_factors(per: FloatArray, tol: float, closed: bool
                   ) -> tuple[FloatArray, FloatArray]:
    """``(point factors, span factors)`` of a local shrink from the per-span bounds ``per``
    (one per span; closed: the spans wrap around, as many as points): each span and point
    gets the smallest factor ``LOCAL_SHRINK_FACTOR * 0.98 tol / per_s`` of the spans ``s``
    within ``LOCAL_SHRINK_REACH`` spans of it whose bound exceeds ``tol``, 1 where there is
    none (point ``i`` ends spans ``i - 1`` and ``i``)."""
    from scipy.ndimage import minimum_filter1d

    f = np.where(per > tol, LOCAL_SHRINK_FACTOR * 0.98 * tol / np.maximum(per, 1e-300), 1.0)
    sf = minimum_filter1d(f, 2 * LOCAL_SHRINK_REACH + 1, mode="wrap" if closed else "constant",
                          cval=1.0)
    if closed:
        pf = np.minimum(sf, np.roll(sf, 1))
    else:
        pf = np.minimum(np.r_[sf, 1.0], np.r_[1.0, sf])
    return cast(FloatArray, pf), cast(FloatArray, sf)


def _polyline_distance(x: FloatArray, poly: FloatArray,
                       seg_ok: np.ndarray | None = None) -> FloatArray:
    """Distance of every row of ``x`` to the polyline ``poly`` (k-d tree: the segments next to
    the two nearest vertices); ``seg_ok[j]`` False leaves segment ``poly[j] -> poly[j + 1]``
    out (a polyline of several pieces: every vertex is still on a segment of its own piece)."""
    from scipy.spatial import cKDTree

    from .._kernels import points as _pk

    _, idx = cKDTree(poly).query(x, k=2)
    x = np.ascontiguousarray(x, dtype=np.float64)
    best = np.empty(x.shape[0])
    ok = np.ones(1, dtype=bool) if seg_ok is None else np.ascontiguousarray(seg_ok, dtype=bool)
    _pk.polyline_distance(x, np.ascontiguousarray(poly, dtype=np.float64),
                          np.ascontiguousarray(idx, dtype=np.int64), ok, seg_ok is not None,
                          best)
    return best


def _polyline_distance_numpy(x: FloatArray, poly: FloatArray,
                             seg_ok: np.ndarray | None = None) -> FloatArray:
    """:func:`_polyline_distance` in numpy (the reference its kernel is tested against)."""
    from scipy.spatial import cKDTree

    _, idx = cKDTree(poly).query(x, k=2)
    best = np.full(x.shape[0], np.inf)
    for col in range(idx.shape[1]):
        for off in (-1, 0):
            i0 = np.clip(idx[:, col] + off, 0, poly.shape[0] - 2)
            a, b = poly[i0], poly[i0 + 1]
            d = b - a
            dd = np.maximum(np.sum(d * d, axis=1), 1e-300)
            s = np.clip(np.sum((x - a) * d, axis=1) / dd, 0.0, 1.0)
            dist = np.linalg.norm(x - a - s[:, None] * d, axis=1)
            if seg_ok is not None:
                dist = np.where(seg_ok[i0], dist, np.inf)
            best = np.minimum(best, dist)
    return best


#: :func:`_rebuilt_distance`'s samples of its first curve on every span, by curve (read-only)
_SAMPLES_MEMO: weakref.WeakKeyDictionary[Any, tuple[int, FloatArray]] = \
    weakref.WeakKeyDictionary()


def _rebuilt_distance(a: CubicHermite, b: CubicHermite, tol: float, dense: int = 32,
                      per: FloatArray | None = None) -> float:
    """The Hausdorff distance of ``a`` and ``b`` (same number of points), as far as it matters
    against ``tol``: the per-span upper bound
    :func:`curvefair.analysis.matched_hermite_bound` where it is within
    ``tol``; on the spans where it is not, both curves sampled ``dense`` times per span and
    measured against the other, sampled ``dense`` times per span, as a polyline (exact to
    ``O(h^2 / dense^2)`` curvature terms). The other curve is sampled only on the spans within
    ``4 max(bound)`` (chord length along ``a``'s points) of a refined span: the matched point
    is within the bound, so the nearest point is within twice of it; a nearest point left out
    could only make the figure larger, never smaller than the true distance."""
    per = matched_hermite_bound(a, b) if per is None else per  # the caller's, if it has it
    bad = np.flatnonzero(per > tol)
    if bad.size == 0:
        return float(per.max()) if per.size else 0.0
    fr = np.arange(dense + 1) / dense
    ns = per.size
    cum = np.r_[0.0, np.cumsum(np.sqrt(np.sum(np.diff(np.asarray(a.points), axis=0) ** 2,
                                              axis=1)))]
    reach = 4.0 * float(per[bad].max())
    lo = np.maximum(np.searchsorted(cum, cum[bad] - reach, side="left") - 1, 0)
    hi = np.minimum(np.searchsorted(cum, cum[bad + 1] + reach, side="right"), ns)
    mark = np.cumsum(np.bincount(lo, minlength=ns + 1) - np.bincount(hi, minlength=ns + 1))
    near = np.flatnonzero(mark[:ns] > 0)

    def samples(c: CubicHermite, spans: np.ndarray) -> FloatArray:
        u = np.asarray(c.params)
        t = (u[spans, None] + np.diff(u)[spans, None] * fr[None, :]).reshape(-1)
        return np.asarray(c(np.clip(t, u[0], u[-1])))

    def samples_a(spans: np.ndarray) -> FloatArray:
        # ``a`` (points-l1's reference, the input's rebuilt curve) is measured against every
        # attempt of every solve: its samples of all spans are made once (each sample is
        # evaluated on its own, so the rows taken are those of ``samples(a, spans)``)
        got = _SAMPLES_MEMO.get(a)
        if got is None or got[0] != dense:
            got = (dense, samples(a, np.arange(ns)).reshape(ns, dense + 1, -1))
            _SAMPLES_MEMO[a] = got
        return cast(FloatArray, got[1][spans].reshape(-1, got[1].shape[2]))

    # segments of the sampled polyline: inside a span, or between the samples of two
    # consecutive spans (the same point); never across a gap between sampled spans
    inner = np.ones((near.size, dense + 1), dtype=bool)
    inner[:, -1] = np.r_[near[1:] == near[:-1] + 1, False]
    seg_ok = inner.reshape(-1)
    pa, pb = samples_a(near), samples(b, near)
    worst = float(np.max(per[per <= tol])) if np.any(per <= tol) else 0.0
    worst = max(worst, float(_polyline_distance(samples(b, bad), pa, seg_ok).max()),
                float(_polyline_distance(samples_a(bad), pb, seg_ok).max()))
    return worst


def _solve(A: sp.csr_matrix, rhs: FloatArray, closed: bool,
           cache: dict[Any, Any] | None = None) -> FloatArray:
    """``A^{-1} rhs``: :func:`_solve_tri`, or for the cyclic tridiagonal ``A`` of a closed
    curve the same banded solve in the order of :func:`_zigzag` (half-bandwidth 4)."""
    if not closed:
        return _solve_tri(A, rhs, cache)
    from scipy.linalg import solve_banded

    N = A.shape[0]
    pos = _zigzag(N)
    Ac = A.tocoo()
    r, c = pos[Ac.row], pos[Ac.col]
    kl = ku = int(np.max(np.abs(r - c)))
    ab = np.zeros((kl + ku + 1, N))
    np.add.at(ab, (ku + r - c, c), Ac.data)
    y = np.empty_like(np.asarray(rhs, dtype=float))
    y[pos] = rhs
    z = solve_banded((kl, ku), ab, y)
    return np.asarray(z[pos])


def _solve_tri(A: sp.csr_matrix, rhs: FloatArray, cache: dict[Any, Any] | None = None
               ) -> FloatArray:
    """``A^{-1} rhs`` for the tridiagonal collocation (LAPACK banded solve); ``cache``: a
    dict kept with ``A`` (:attr:`NaturalOperators.cache`) that holds its band."""
    from scipy.linalg import solve_banded

    ab = None if cache is None else cache.get("A_band")
    if ab is None:
        Aw = _tridiag(A)
        N = Aw.shape[0]
        ab = np.zeros((3, N))
        ab[0, 1:] = Aw[:-1, 2]
        ab[1] = Aw[:, 1]
        ab[2, :-1] = Aw[1:, 0]
        if cache is not None:  # the operators' cache: made once per matrix
            ab.setflags(write=False)
            cache["A_band"] = ab
    return solve_banded((1, 1), ab, rhs)


# ------------------------------------------------------------------------------------------
# registration with fair()
# ------------------------------------------------------------------------------------------
def _accepts(curve: Any) -> bool:
    return isinstance(curve, CubicHermite) and curve.n_points >= (5 if curve.closed else 4)


#: the largest point count for which ``points-l1`` is the default (its interior point is
#: O(n) per Newton step but takes a few hundred steps, so its cost per point is large: the
#: figures are in docs/benchmarks.md); longer point lists default to ``poliakoff``
DEFAULT_MAX_POINTS = 20_000

#: whether ``points-l1`` is registered as a default at all: True, for the curves :func:`_prefer`
#: accepts (open chord-length natural cubics, i.e. point files, up to ``DEFAULT_MAX_POINTS``);
#: False leaves ``poliakoff`` the default for point data
DEFAULT_ENABLED = True

#: up to this many points ``fair(curve, "points-l1")`` runs 10 reweighting rounds and solves
#: with three jump costs (``select=3``: the call's own, ``"spacing"``, ``"input"``), keeping
#: the one whose written points rebuild into the fewest curvature extrema; longer lists get
#: one solve of 5 rounds (about a third of the time)
SELECT_MAX_POINTS = 5_000

#: whether ``points-l1`` is also the default for closed point lists (chord-length periodic
#: cubics, e.g. a CSV whose last row repeats the first); False: ``poliakoff``
DEFAULT_CLOSED = True


def _has_natural_ends(curve: CubicHermite) -> bool:
    """Whether ``curve`` is the natural cubic spline through its points at its own parameters
    (zero second derivative at both ends, C2): the curve :func:`points_l1` returns for
    unmoved points (closed: the periodic cubic)."""
    try:
        ref = interpolate_cubic(curve.points, np.asarray(curve.params),
                                "periodic" if curve.closed else "natural")
    except InputError:
        return False
    d, dr = np.asarray(curve.tangents), np.asarray(ref.tangents)
    scale = max(float(np.max(np.abs(dr))), 1e-300)
    return bool(np.max(np.abs(d - dr)) <= 1e-7 * scale)


def _prefer(curve: Any) -> bool:
    return (_accepts(curve) and curve.n_points <= DEFAULT_MAX_POINTS
            and (DEFAULT_CLOSED or not curve.closed)
            and _is_natural_chord_interpolant(curve))


def solve(problem: FairingProblem, *, rounds: int | None = None, delta: float = 1e-5,
          curve_tol: bool = True, samples: int = 3, backoff: int = 4, scale: str = "none",
          select: int | None = None) -> Outcome:
    """``points-l1`` as a solver of ``problem`` (``fair(curve, "points-l1", ...)``): the
    points of ``problem.curve`` moved by :func:`points_l1` within ``problem.tol``, the clamp
    pair and protected points held; ``eps`` has no meaning here (one convex problem, no
    ranking loop). ``rounds`` (default 10 up to ``SELECT_MAX_POINTS`` points, else 5),
    ``select`` (formulations tried, default 3 up to ``SELECT_MAX_POINTS``, else 1), ``scale``,
    ``delta``, ``curve_tol``, ``samples``: as in :func:`points_l1`; ``backoff``: how many
    times the problem is solved again in half the tube when the result adds inflections or
    curvature extrema, on the input's parameters or (point data) on the curve rebuilt from its
    points; if that rebuilt curve is still worse than the input after the last one, the input
    is returned unmoved (``extra["points_l1"]["kept"] == "input"``)."""
    curve = cast(CubicHermite, problem.curve)
    tol, max_steps, clamp, protect = (problem.tol_or_none, problem.max_steps, problem.clamp,
                                      problem.protect)
    if tol is None:
        # no bound on the moves: the convex problem has no tube to work in (its minimiser
        # would be a straight line); the local Poliakoff loop is run instead, and said so
        from .fair import METHODS

        out = METHODS["poliakoff"].run(replace(problem, mode="spline", options={}),
                                       {})
        out.extra["points_l1"] = "no tol given: the poliakoff loop was run instead"
        return out
    n = curve.n_points
    closed = bool(curve.closed)
    if n < (5 if closed else 4):
        raise InputError(f"method 'points-l1' needs at least 4 points, got "
                         f"{n - 1 if closed else n} distinct")
    if not closed and any(c in ("g1", "g2") for c in clamp):
        # g1 and g2 hold the end tangent (g2 the curvature too): the natural cubic's end
        # tangent depends on every moved point, so it cannot be held exactly
        raise InputError(f"method 'points-l1' rebuilds the natural cubic through the moved "
                         f"points: its end tangent cannot be held (clamp {clamp!r}); use "
                         f"clamp 'g0' (the ends stay natural: zero curvature, before and "
                         f"after), or 'poliakoff' for a G1/G2 clamp")
    if not _has_natural_ends(curve):
        raise InputError("method 'points-l1' returns the natural (closed: periodic) cubic "
                         "through the moved points on the input's parameters: this curve is "
                         "not that spline through its points (not-a-knot or clamped ends, "
                         "or not C2), so the result would differ from it even where nothing "
                         "moves; use 'poliakoff' or 'wang-cao'")
    if closed:
        # no ends; the closing point is point 0
        hold = {int(i) % (n - 1) for i in protect}
    else:
        hold = set(int(i) for i in protect) | {0, n - 1}
    steps = 80 if max_steps is None else int(max_steps)
    p_all = np.asarray(curve.points)
    p0 = p_all[:-1] if closed else p_all
    if steps == 0:
        return Outcome(curve=curve, steps=0, stop_reason="max_steps",
                       history=FairingHistory.empty(), curve_within_tol=False)
    # ``select`` formulations, the call's own first, then the jump costs of
    # :func:`_jump_costs` it does not use (defaults: SELECT_MAX_POINTS)
    small = n <= SELECT_MAX_POINTS
    if rounds is None:
        rounds = 10 if small else 5
    if select is None:
        select = 3 if small else 1
    variants: list[dict[str, Any]] = [{"scale": scale, "rounds": rounds}]
    for sc in ("spacing", "input", "none"):
        if len(variants) < max(1, int(select)) and sc != scale:
            variants.append({"scale": sc, "rounds": 5})
    chosen = variants[0]
    # every solve below is on the same points, parameters and held points: the work that does
    # not depend on the tube's radius is done once (points_l1's ``_shared``)
    shared: dict[str, Any] = {}

    def solve_at(t: float, v: dict[str, Any] | None = None) -> PointsL1Result:
        v = chosen if v is None else v
        return points_l1(p0, t, params=np.asarray(curve.params), hold=sorted(hold),
                         rounds=int(v["rounds"]), delta=delta, max_steps=steps,
                         curve_tol=curve_tol, samples=samples, scale=str(v["scale"]),
                         closed=closed, _shared=shared)

    res = solve_at(tol)
    total = int(res.report["newton_steps"])
    from .fair import _analysis_block

    seen: dict[int, tuple[PointsL1Result, dict[str, Any]]] = {}

    def rebuilt(r: PointsL1Result) -> dict[str, Any]:
        """Analysis of the curve a reader rebuilds from the result's points (chord-length
        natural or periodic cubic), made once per result (the curve's points are the result's:
        :func:`rebuilt_curve` of it, which fair()'s guard asks for again)."""
        if id(r) not in seen:
            a = rebuilt_analysis(r.curve, _analysis_block, r._rebuilt)
            if a is None:  # coincident points: the error of the interpolation itself
                a = _analysis_block(interpolate_cubic(
                    np.vstack([r.points, r.points[:1]]) if closed else np.array(r.points),
                    "chord", "periodic" if closed else "natural"))
            seen[id(r)] = (r, a)
        return seen[id(r)][1]

    if len(variants) > 1:
        # the formulation whose written points rebuild into the curve with the fewest
        # curvature extrema (then inflections) wins: that curve is what a reader of the
        # file gets, and the jump norm is only a proxy for its extrema
        def rebuilt_counts(r: PointsL1Result) -> tuple[int, int]:
            a = rebuilt(r)
            return int(a["extrema"]), int(a["inflections"])

        best = rebuilt_counts(res)
        for v in variants[1:]:
            r2 = solve_at(tol, v)
            total += int(r2.report["newton_steps"])
            c2 = rebuilt_counts(r2)
            if c2 < best:
                res, best, chosen = r2, c2, v
        res.report["variant"] = dict(chosen)
    # tolerance back-off: in a wide tube (a few tenths of a percent of the size and more)
    # the sparsest jumps can take a shape whose curvature crosses zero where the input's does
    # not (naca2412.dat at tol 0.01 chord: 3 -> 6 inflections, on the flat aft surfaces);
    # then the problem is solved again in half the tube, up to ``backoff`` times, and the
    # first result that adds neither inflections nor curvature extrema (curvefair's counts,
    # as fair()'s never-worse guard counts them) is kept -- a fair curve in a narrower tube,
    # where the guard could only scale the moves back (and with them the noise).
    # Point data (the input is the chord-length interpolant of its points, as a point file is
    # read) are judged on the curve rebuilt from the result's points too: fair()'s guard sees
    # the curve on the input's parameters only, and the two can differ widely (100,000 noisy
    # points: 400 curvature extrema on the input's parameters, 15,820 rebuilt, input 2,154).
    # If even the narrowest tube tried rebuilds worse than the input, the input is kept
    used = tol
    tries = 0
    kept_input = False
    if backoff > 0:
        point_data = _is_natural_chord_interpolant(curve)
        a0 = _analysis_block(curve)

        def adds(a: dict[str, Any]) -> bool:
            return bool(a["inflections"] > a0["inflections"] or a["extrema"] > a0["extrema"])

        def worse(r: PointsL1Result) -> bool:
            return adds(_analysis_block(r.curve)) or (point_data and adds(rebuilt(r)))

        bad = worse(res)
        while bad and tries < int(backoff):
            tries += 1
            used = tol * 0.5 ** tries
            res = solve_at(used)
            total += int(res.report["newton_steps"])
            bad = worse(res)
        kept_input = bad and point_data and adds(rebuilt(res))
    res.report["tol_used"] = used
    res.report["backoff"] = tries
    if kept_input:
        res.report["kept"] = "input"
        res.report["reason"] = (f"the points rebuild into a curve with more inflections or "
                                f"curvature extrema than the input's in every tube tried "
                                f"(down to {used:.6g}): the input is kept")
        return Outcome(curve=curve, steps=total,
                       stop_reason=cast(StopReason, res.report["stop_reason"]),
                       history=FairingHistory.empty(), max_steps=steps,
                       extra={"points_l1": res.report}, curve_within_tol=True)
    p1 = np.asarray(res.points)
    moved = np.flatnonzero(np.any(p0 != p1, axis=1))
    disp = np.sqrt(np.sum((p1[moved] - p0[moved]) ** 2, axis=1))
    hist = FairingHistory.from_arrays(moved, np.zeros(moved.size), disp)
    return Outcome(curve=res.curve, steps=total,
                   stop_reason=cast(StopReason, res.report["stop_reason"]), history=hist,
                   max_steps=steps, extra={"points_l1": res.report,
                                           "history_is": "one entry per moved point "
                                                         "(simultaneous solve)"},
                   curve_within_tol=True)


def _register() -> None:
    from .fair import MethodSpec, register_method

    register_method(MethodSpec(
        name="points-l1",
        curve_types=(CubicHermite,),
        solver=solve,
        summary="Point data: moves the points (each within tol, the curve within tol at equal "
                "parameter) so that their natural cubic on the input's parameters -- and the "
                "one rebuilt from the written file -- has the sparsest third-derivative jumps "
                "(reweighted L1, banded interior point, O(n)). "
                "Default for point data (open or closed) up to 20,000 points.",
        source="convex problem over the data points of the natural cubic interpolant; "
               "reweighted L1 (Candes, Wakin & Boyd 2008); interior point (Boyd & "
               "Vandenberghe sec. 11.7)",
        # DEFAULT_ENABLED: see there
        default=DEFAULT_ENABLED,
        accepts=_accepts,
        prefer=_prefer,
        clamps=("g0", "none"),
        default_reason="default for point files (chord-length natural or periodic cubics, up to "
                       "20,000 points): fewest curvature extrema on the curve rebuilt from the "
                       "written points of the tools in docs/benchmarks_default.md (240 UIUC "
                       "airfoils at tol 1e-4 chord, five point-file families)",
    ))


_register()
