"""Global energy fairing of a B-spline curve within a tolerance (a convex QP with ball constraints).

Minimise ``E = w2 E_2 + w3 E_3`` (``E_l = int |x^(l)(t)|^2 dt`` over the domain) over every
free control point subject to ``|d_i - d_i^orig| <= tol`` (the ORIGINAL control points; by the
convex hull property the curve then deviates at most ``tol`` at equal parameter, seed 004
eqs. (8.34)-(8.36)). Fixed points (end clamps, ``protect``) keep their position.

This is the problem every local method of :func:`curvefair.fair` on B-splines works on one
control point at a time (Eck & Hadenfeld's ranking list is block Gauss-Seidel on it), solved
here for all points at once: it is never worse than any of them at the same tolerance.

Solver (see :func:`global_fair`): curves start with a few dozen ADMM iterations that share
ONE ``n x n`` band factorisation (the Gram matrix is the same for every coordinate), then an
active-set (semismooth) Newton iteration that converges quadratically once the active balls
are known (a damped, Levenberg-Marquardt step while its steps are too long, see
:func:`global_fair`); tiny closed curves (and any Newton failure) use a Mehrotra
predictor-corrector interior point with strictly feasible iterates, finished by the same Newton
iteration. Each Newton iteration factorises one symmetric block-banded matrix (bandwidth
``(degree + 1) dim - 1``, coordinates interleaved) by a compiled band Cholesky (closed curves:
the cyclic band bordered by a small Schur complement), see
:mod:`curvefair._kernels.global_fair`: ``O(n)`` time and memory per iteration; typically 4-8
Newton iterations after the warm start (10-20 with the interior point).
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from functools import partial
from typing import TYPE_CHECKING, Any

import numpy as np
import scipy.sparse as sp

from .. import _threads
from .._kernels import global_fair as _k
from .._kernels.bspline import band_energy
from .._typing import FloatArray
from .._validate import as_step_count
from ..curves.bspline import BSplineCurve
from ..errors import InputError
from .problem import check_bspline
from .stop import StopReason

if TYPE_CHECKING:
    from .problem import FairingProblem, Outcome

__all__ = ["global_fair", "GlobalResult", "energy_matrix"]


def _weights(l: Any, degree: int) -> dict[int, float]:  # noqa: E741
    """``l`` = 2, 3, or a blend ``(w2, w3)`` / ``{2: w2, 3: w3}``."""
    if isinstance(l, (int, np.integer)) and not isinstance(l, bool):
        w = {int(l): 1.0}
    elif isinstance(l, dict):
        w = {int(k): float(v) for k, v in l.items()}
    else:
        try:
            w2, w3 = l
            w = {2: float(w2), 3: float(w3)}
        except (TypeError, ValueError):
            raise InputError(f"l must be 2, 3, (w2, w3) or {{2: w2, 3: w3}}, got {l!r}") from None
    for k, v in w.items():
        if k not in (2, 3):
            raise InputError(f"energy order {k} not supported: l must use orders 2 and 3")
        if not (np.isfinite(v) and v >= 0):
            raise InputError(f"energy weight for order {k} must be a finite number >= 0, got {v!r}")
        if v > 0 and k > degree:
            raise InputError(f"E_{k} needs degree >= {k}, the curve has degree {degree}")
    w = {k: v for k, v in w.items() if v > 0}
    if not w:
        raise InputError(f"l gives no positive energy weight: {l!r}")
    return w


def energy_matrix(curve: BSplineCurve, l: Any = 2) -> sp.csr_matrix:  # noqa: E741
    """``G = sum_l w_l G_l`` (exact Gram matrices, :meth:`BSplineCurve.gram_matrix`), so that
    ``E = sum_coords d^T G d``."""
    curve = check_bspline(curve)
    w = _weights(l, curve.degree)
    G = None
    for k, v in w.items():
        Gk = curve.gram_matrix(k) * v
        G = Gk if G is None else G + Gk
    assert G is not None  # _weights raises when no weight is positive
    return G.tocsr()


def _absmax(a: FloatArray) -> float:
    """``max |a|`` without an ``|a|`` temporary (NaN propagates)."""
    return max(float(a.max()), -float(a.min())) if a.size else 0.0

# ------------------------------------------------------------------------------------------
# two threads for the per-point passes of the Newton iteration (curvefair._threads)
# ------------------------------------------------------------------------------------------
_THREADS = _threads.THREADS  # 1: everything on the calling thread
_PAR_MIN = 100_000  # points: below, one range on the calling thread
_PAR_CHUNKS = _threads.CHUNKS
_ASM_SPLIT = 0.5  # open planar cubics: the worker assembles the columns from this fraction on
_pool = _threads.pool


def _ranges(fn: Callable[[int, int], Any], lo: int, hi: int) -> list[Any]:
    """:func:`curvefair._threads.ranges` with this module's settings (read at each call)."""
    return _ranges_start(fn, lo, hi)()


def _ranges_start(fn: Callable[[int, int], Any], lo: int, hi: int
                  ) -> Callable[[], list[Any]]:
    """:func:`curvefair._threads.ranges_start` with this module's settings."""
    return _threads.ranges_start(fn, lo, hi, _THREADS, _PAR_MIN, _PAR_CHUNKS)


class _Prefault:
    """Map the pages of a new work array on the worker thread while the calling thread does
    other work (a page's first touch is a kernel fault; figures in docs/benchmarks.md).
    :meth:`join` before the array is first used: the calling thread zeroes
    the chunks the worker has not claimed and waits only for those it has started. Only the
    speed depends on how the work is shared (the array is zeroed either way and then
    overwritten before it is read)."""

    def __init__(self, flat: FloatArray, chunks: int = 16) -> None:
        m = flat.size
        self.flat = flat
        self.bounds = [(m * q) // chunks for q in range(chunks + 1)]
        self.k = chunks
        self.next = 0
        self.pending = 0
        self.lock = threading.Lock()
        self.idle = threading.Event()
        self.idle.set()
        _pool().submit(self._work, True)

    def _work(self, worker: bool) -> None:
        while True:
            with self.lock:
                q = self.next
                if q >= self.k:
                    return
                self.next = q + 1
                if worker:
                    self.pending += 1
                    self.idle.clear()
            try:
                self.flat[self.bounds[q]:self.bounds[q + 1]] = 0.0  # releases the GIL
            finally:
                if worker:
                    with self.lock:
                        self.pending -= 1
                        if self.pending == 0:
                            self.idle.set()

    def join(self) -> None:
        self._work(False)
        while True:
            with self.lock:
                if self.pending == 0:
                    return
            self.idle.wait()

def _frames(nrm: FloatArray) -> FloatArray:
    """Orthonormal frames ``Q_i`` (shape (m, dim, dim)) whose first column is the unit vector
    ``nrm_i`` (2-D: the tangent is ``nrm`` turned by 90 degrees; 3-D: Duff et al. 2017,
    "Building an orthonormal basis, revisited")."""
    m, dim = nrm.shape
    Q = np.zeros((m, dim, dim))
    Q[:, :, 0] = nrm
    if dim == 2:
        Q[:, 0, 1] = -nrm[:, 1]
        Q[:, 1, 1] = nrm[:, 0]
        return Q
    x, y, z = nrm[:, 0], nrm[:, 1], nrm[:, 2]
    sgn = np.where(z >= 0.0, 1.0, -1.0)
    a = -1.0 / (sgn + z)
    b = x * y * a
    Q[:, 0, 1] = 1.0 + sgn * x * x * a
    Q[:, 1, 1] = sgn * b
    Q[:, 2, 1] = -sgn * x
    Q[:, 0, 2] = b
    Q[:, 1, 2] = sgn + y * y * a
    Q[:, 2, 2] = -y
    return Q



def _band_storage(n: int, dim: int, p: int, closed: bool
                  ) -> tuple[FloatArray, _Prefault | None] | None:
    """The Newton band storage of :class:`_System`, allocated early: with two threads and a
    large curve its pages are mapped on the worker while the Gram band, the energy and the
    gradient are computed. None for the dense (tiny closed) systems."""
    N = n * dim
    kd = (p + 1) * dim - 1
    if closed and N < 3 * (kd + 1):
        return None
    L = np.empty((N, kd + 1))
    pre = _Prefault(L.reshape(-1)) if _THREADS >= 2 and n >= _PAR_MIN else None
    return L, pre


def _readonly_view(a: FloatArray) -> FloatArray:
    """``a`` as a read-only array (a view if it is writeable, no copy): the kernels then see one
    array type whether a band is the curve's cached one (read only) or a weighted sum, and are
    compiled once (see :mod:`curvefair._kernels.global_fair`). Internal arguments only: unlike
    :func:`curvefair.curves.piecewise.readonly` (one copy, for arrays a user receives) the
    view's flag could be set back."""
    if not a.flags.writeable:
        return a
    v = a.view()
    v.flags.writeable = False
    return v


class _System:
    """Newton systems ``Q^T (kron(K, I) + blockdiag(B)) Q`` with fixed unknowns (see
    :mod:`curvefair._kernels.global_fair`): band Cholesky (open curves), bordered cyclic band
    (closed), dense for tiny closed curves. ``K`` is given by its band rows
    ``K[i, p + o] = K_{i, i+o}``; ``fixed`` points never move. Work arrays are allocated once
    and reused."""

    def __init__(self, K: FloatArray, ks: float, p: int, dim: int, closed: bool,
                 fixed: np.ndarray, band: tuple[FloatArray, _Prefault | None] | None = None
                 ) -> None:
        n = K.shape[0]
        K = _readonly_view(K)
        self.K, self.ks, self.p, self.dim, self.closed, self.n = K, ks, p, dim, closed, n
        self.N = N = n * dim
        self.kd = kd = (p + 1) * dim - 1
        self.fix0 = np.repeat(fixed[:, None], dim, axis=1)
        self.fixed_points = np.flatnonzero(fixed)
        self.anyrot = False
        self.dense = closed and N < 3 * (kd + 1)
        if self.dense:
            Kd = np.zeros((n, n))
            for o in range(-p, p + 1):
                np.add.at(Kd, (np.arange(n), (np.arange(n) + o) % n), K[:, p + o] * ks)
            self.Kd = np.kron(Kd, np.eye(dim))
        else:
            if band is None or band[0].shape != (N, kd + 1):
                band = (np.empty((N, kd + 1)), None)
            self._L, self._pre = band
            if closed:
                self.Y = np.empty((N - kd, kd))
                self.S = np.empty((kd, kd))
        self.Q = np.zeros((n, dim, dim))
        self.rot = np.zeros(n, dtype=np.bool_)
        self.fix = self.fix0.copy()
        self.B = np.zeros((n, dim, dim))
        self.czero = np.zeros(n)
        self.then: Any = None  # what factor()'s ``then`` returned
        # max |dx_i|^2 over the rot points and over the others of the last solve (if measured)
        self.step2: tuple[float, float] | None = None

    @property
    def L(self) -> FloatArray:  # noqa: N802
        """The band storage (its background page mapping finished first)."""
        if self._pre is not None:
            self._pre.join()
            self._pre = None
        return self._L

    def factor(self, B: FloatArray, rot: np.ndarray | None = None,
               nrm: FloatArray | None = None, nrot: int | None = None,
               then: Callable[[], Any] | None = None) -> bool:
        """Factorise for blocks ``B`` (n, dim, dim); points ``rot`` get the frame whose first
        axis is ``nrm`` and that axis fixed (a prescribed normal displacement). ``nrot``: the
        caller has already written ``self.rot``, ``self.Q`` and ``self.fix`` for ``nrot``
        such points (:func:`curvefair._kernels.global_fair.ssn_eval_prep`). False if the
        matrix is not positive definite in floating point."""
        self.B = B
        self.then = None
        if nrot is not None:
            self.anyrot = nrot > 0
        else:
            self.anyrot = rot is not None and bool(rot.any())
        if nrot is not None:
            pass
        elif not self.anyrot:
            self.fix[:] = self.fix0
            self.rot[:] = False
        else:
            self.rot[:] = rot
            _k.set_frames(nrm, rot, self.Q, self.fix, self.fix0)
        if self.dense:
            if self.dim == 2:  # planar frames may hold their first column only
                self.Q[:, 0, 1] = -self.Q[:, 1, 0]
                self.Q[:, 1, 1] = self.Q[:, 0, 0]
            M = self.Kd + _blockdiag(B)
            Qf = _blockdiag(np.where(self.rot[:, None, None], self.Q,
                                     np.eye(self.dim)[None]))
            M = Qf.T @ M @ Qf
            f = self.fix.reshape(-1)
            M[f, :] = 0.0
            M[:, f] = 0.0
            M[f, f] = 1.0
            try:
                self.C = np.linalg.cholesky(M)
            except np.linalg.LinAlgError:
                return False
            return True
        split = (not self.closed and self.kd == 7 and _THREADS >= 2
                 and self.n >= max(_PAR_MIN, 64))
        if not split:
            self.then = then() if then is not None else None
        if self.closed:
            _k.assemble(self.K, self.ks, self.p, True, B, self.Q, self.rot, self.fix, self.L)
            info = _k.cyclic_cholesky(self.L, self.Y, self.S)
        elif split:
            # the columns of the last points assembled on the worker thread meanwhile, then
            # (queued after them) ``then``, e.g. the right-hand side (prep_start); the same
            # operations (bitwise)
            args = (self.K, self.ks, self.p, B, self.Q, self.rot, self.fix, self.L)
            m = int(self.n * _ASM_SPLIT)
            fin = _ranges_start(lambda a, b: _k.assemble_range(
                self.K, self.ks, self.p, False, B, self.Q, self.rot, self.fix, self.L, a, b),
                m, self.n)
            self.then = then() if then is not None else None
            info, j = _k.assemble_ldl_head(*args, m)
            fin()
            if info == 0:
                info = _k.assemble_ldl_tail(*args, j)
        else:
            info = _k.assemble_ldl(self.K, self.ks, self.p, B, self.Q, self.rot, self.fix, self.L)
        return info == 0

    def prep_start(self, B: FloatArray, nrot: int, rhs: FloatArray, c: FloatArray,
                   out: FloatArray, sgn: float) -> Callable[[], list[Any]] | None:
        """Start the planar right-hand side of :meth:`solve` (for the blocks ``B`` and the
        frames, flags and ``nrot`` already written for the next :meth:`factor`) on the worker
        thread, so that it runs while the calling thread factorises (the factorisation reads
        the blocks and frames and writes only the band storage; the preparation writes only
        ``out``). Call the returned function after :meth:`factor`, then
        :meth:`solve` with ``prepped=True``. None: nothing started (prepare in :meth:`solve`)."""
        if self.dense or self.dim != 2 or nrot <= 0 or _THREADS < 2 or self.n < _PAR_MIN:
            return None
        args = (self.K, self.ks, self.p, self.closed, B, self.Q, self.rot, self.fix, self.fix0,
                rhs, c, out, float(sgn))
        return _ranges_start(lambda a, b: _k.prep_rhs2_range(*args, a, b), 0, self.n)

    def solve(self, rhs: FloatArray, c: FloatArray | None = None,
              out: FloatArray | None = None, sgn: float = 1.0,
              prepped: bool = False) -> FloatArray:
        """Displacement ``dx`` (n, dim): ``M dx = sgn rhs`` on the unfixed unknowns, ``dx = 0``
        at fixed points, ``nrm_i . dx_i = c_i`` at the ``rot`` points. ``prepped``: ``out``
        already holds the prepared right-hand side (:meth:`prep_start`). With frames,
        ``self.step2`` is set to ``max_i |dx_i|^2`` over the ``rot`` points and over the
        others (else None)."""
        y = np.empty_like(rhs) if out is None else out
        if prepped:
            assert out is not None and self.anyrot and self.dim == 2
        elif self.anyrot and self.dim == 2:  # per point: in ranges (two threads)
            args = (self.K, self.ks, self.p, self.closed, self.B, self.Q, self.rot, self.fix,
                    self.fix0, rhs, self.czero if c is None else c, y, float(sgn))
            _ranges(lambda a, b: _k.prep_rhs2_range(*args, a, b), 0, self.n)
        elif self.anyrot:
            _k.prep_rhs(self.K, self.ks, self.p, self.closed, self.B, self.Q, self.rot, self.fix,
                        self.fix0, rhs, self.czero if c is None else c, y, sgn)
        else:
            if sgn != 1.0:
                np.multiply(rhs, sgn, out=y)
            elif y is not rhs:
                y[:] = rhs
            y[self.fixed_points] = 0.0
        b = y.reshape(-1)
        if self.dense:
            b[:] = np.linalg.solve(self.C.T, np.linalg.solve(self.C, b))
        elif self.closed:
            _k.cyclic_solve_full(self.L, self.Y, self.S, b)
        else:
            _k.ldl_solve(self.L, self.N, b)
        if self.anyrot:
            parts = _ranges(lambda a, b: _k.post_solve_range(y, self.Q, self.rot, self.fix0,
                                                             a, b), 0, self.n)
            r2, m2 = parts[0]
            for q, w in parts[1:]:  # NaN propagates
                r2 = q if not q <= r2 else r2
                m2 = w if not w <= m2 else m2
            self.step2 = (r2, m2)
        else:
            y[self.fixed_points] = 0.0
            self.step2 = None
        return y


def _blockdiag(B: FloatArray) -> FloatArray:
    n, dim, _ = B.shape
    out = np.zeros((n * dim, n * dim))
    for a in range(dim):
        for b in range(dim):
            out[np.arange(n) * dim + a, np.arange(n) * dim + b] = B[:, a, b]
    return out


@dataclass(frozen=True)
class GlobalResult:
    """Outcome of :func:`global_fair`.

    Attributes
    ----------
    curve : BSplineCurve
    energy_before, energy_after : float
        ``E`` (the blend being minimised) of the input and the result.
    multipliers : ndarray, shape (n,)
        KKT multipliers ``lambda_i >= 0`` of the ball constraints (0 for fixed points and
        unconstrained solves): ``2 (G d)_i + lambda_i (d_i - d_i^orig) = 0`` at every free
        point.
    iterations : int
        Newton iterations (active set and interior point, including the steps that reuse a
        factorisation; the start counts as 1; 1 for an unconstrained solve; 0 with
        ``max_steps=0``).
    stop_reason : str
        ``"converged"`` (duality gap below ``gap``), ``"unconstrained"``, ``"max_steps"``,
        ``"numerical"`` (rounding stopped it early), ``"no_movable_point"``, ``"zero_energy"``.
    active : ndarray of int
        Free points on their ball (``|d_i - d_i^orig| > (1 - 1e-6) tol``).
    """

    curve: BSplineCurve
    energy_before: float
    energy_after: float
    multipliers: np.ndarray
    iterations: int
    stop_reason: StopReason
    active: np.ndarray


def global_fair(curve: BSplineCurve, *, tol: float | None = None, l: Any = 2,  # noqa: E741
                clamp: Any = (None, None), protect: Iterable[int] = (), gap: float = 1e-13,
                max_steps: int | None = 500) -> GlobalResult:
    """Minimise the fairness energy over all free control points within ``tol``.

    Parameters
    ----------
    curve : BSplineCurve
    tol : float or None
        Ball radius around every ORIGINAL control point; ``None``: unconstrained (the result is
        the limit of the Eck-Hadenfeld iteration with the fixed points held). Refused
        (:class:`~curvefair.errors.InputError`) for a closed curve with fewer than 2 held
        control points, whose limit is a single point.
    l : 2, 3, (w2, w3) or {2: w2, 3: w3}
        The energy ``sum_l w_l E_l``.
    clamp, protect
        Fixed control points, as for :func:`~curvefair.fairing.eck_hadenfeld.movable_mask`.
    gap : float
        Interior-point stopping threshold on the total complementarity
        ``sum_i lambda_i s_i`` (in units of ``E(input)``).
    max_steps : int >= 0 or None
        Cap on the Newton iterations (interior point and active set together; the start
        counts as 1); ``None``: 500. ``0`` makes no iteration: the input is returned unchanged
        with ``iterations = 0`` and ``stop_reason = "max_steps"`` (as the other methods; a
        curve without free points or with zero energy or ``tol = 0`` keeps its own reason).

    Returns
    -------
    GlobalResult

    Notes
    -----
    Convex QP: ``min sum_coords d^T G d`` s.t. ``|d_i - o_i|^2 <= tol^2`` (``G`` the exact Gram
    matrix of :meth:`BSplineCurve.gram_band`), solved on ``F = E(d)/E(o)`` with the constraints
    ``f_i = (|d_i - o_i|^2 / tol^2 - 1) / 2 <= 0``:

    0. warm start by over-relaxed ADMM (Boyd et al., *Distributed Optimization
       and Statistical Learning via ADMM*, 2011, sec. 3.4.3 / 5.1; ``alpha = 1.6``) on the
       splitting ``x = z``, ``z`` in the balls: 20 iterations (40 from 10,000 control points
       on), each one banded solve with the single ``n x n`` factor of ``2G/E(o) + rho I``
       (shared by the coordinates; closed curves: the cyclic band, bordered, except tiny ones)
       and a projection, ``rho`` reset every 10 iterations towards the median
       ``lambda_i / tol^2`` of the projected points (at most 10x each time); then step 3
       directly (at most 15 iterations, 30 once damped; if it does not converge,
       steps 1-3 follow from scratch). From this start a Newton step that
       moves an inactive point further than ``tol`` (an active one further than ``2 tol``)
       is rejected and solved again with a Levenberg-Marquardt term ``mu I`` added to the
       blocks (``mu`` starts at the median ``lambda_i / tol^2`` of the active points, x10 per
       rejection, x0.3 per accepted step, 0 below 1e-6 of its start): few active points leave
       soft directions (points sliding along their tangents, inactive points moving freely)
       in which the plain step diverges; with under 2 % (or 100) of the points active at the
       first rejection the interior point takes over at once (faster there);
    1. start from the smoothing solve ``(2G/E(o) + mu_0 I) d = mu_0 o`` (one banded solve,
       ``mu_0`` = 1 % of the mean diagonal);
    2. Mehrotra predictor-corrector interior point with slacks ``s_i = -f_i`` (Nocedal & Wright,
       *Numerical Optimization*, 2nd ed., alg. 16.4 / sec. 19.3): the Newton system is reduced
       to ``d`` (per-point ``dim x dim`` blocks ``lambda_i I / tol^2 + (lambda_i / s_i) a_i
       a_i^T``, ``a_i = (d_i - o_i) / tol^2``);
    3. once the residuals are below ``1e-3``, a semismooth Newton (primal-dual active set)
       iteration on the KKT system with the active set ``lambda_i + kappa f_i > 0``: the active
       points move in the tangent plane of their sphere (the normal displacement is prescribed,
       the Hessian of the Lagrangian ``2G/E(o) + lambda_i I / tol^2`` is used), which converges
       quadratically once the active set is right; while the active set is unchanged and the
       last step cut the stationarity residual at least 100-fold, the previous factorisation
       is reused (an inexact Newton step); if it has not converged after 8 iterations the
       interior point resumes from where it left.

    Every Newton system is one symmetric block-banded matrix (bandwidth
    ``(degree + 1) dim - 1``, coordinates interleaved) factorised by a compiled band
    ``U D U^T`` (open curves) or band Cholesky bordered by a small Schur complement (closed
    curves, cyclic band): ``O(n)`` per iteration,
    typically 4-8 Newton iterations after the ADMM start, 10-20 with the interior point.
    Planar curves split the per-point passes of every Newton iteration (evaluation,
    right-hand side, back-rotation, update) into point ranges shared by the calling thread and
    one worker thread (when the process may use 2 or more CPUs and the curve has at least
    100000 control points; the factorisation and the substitutions stay sequential, but the
    right-hand side of a refactorised step is prepared on the worker thread while the calling
    thread factorises, the worker then assembles the columns of the second half of the points
    (open planar cubics) while the calling thread assembles and eliminates the first half,
    the pages of the Newton work arrays are mapped on it during the ADMM start, and the final
    pull-in onto the balls is split too); the
    ranges write disjoint points, so the result is bitwise the same as on one thread, and the
    calling thread never waits for a chunk the worker has not started (the environment variable
    ``CURVEFAIR_THREADS=1``, read at import, switches it off; timings: docs/benchmarks.md,
    "Global fairing: threads and page size"). The convergence test is the same
    on every path (the warm start and reused factorisations change only the speed). Converged
    means: dual residual below ``1e-10`` of
    ``|grad F(o)|_inf``, every point within ``tol (1 + 1e-12)`` (then projected onto its ball),
    complementarity exact (active set) or below ``gap`` (interior point). The returned
    multipliers (``E(o) lambda_i / tol^2``) satisfy ``2 (G d)_i + lambda_i (d_i - o_i) = 0``.
    Without a tolerance the free points solve ``G_FF d_F = -G_FC d_C`` (a ``1e-15`` Tikhonov
    term towards the original points picks the closest minimiser when the fixed points do not
    determine one, e.g. a closed curve without protected points).

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import interpolate_bspline
    >>> from curvefair.fairing.global_fair import global_fair
    >>> x = np.linspace(0, 6, 40)
    >>> c = interpolate_bspline(np.c_[x, np.sin(x) + 0.01 * np.cos(23 * x)])
    >>> res = global_fair(c, tol=0.02, clamp="g2")
    >>> bool(res.energy_after < res.energy_before), res.stop_reason
    (True, 'converged')
    """
    from .problem import make_problem

    prob = make_problem(check_bspline(curve), tol=tol, max_steps=max_steps, clamp=clamp,
                        protect=protect)
    return _global_fair(prob, l, gap)


def _global_fair(problem: FairingProblem, l: Any, gap: float) -> GlobalResult:  # noqa: E741
    curve = check_bspline(problem.curve)
    w = _weights(l, curve.degree)
    tol, tolv = problem.tol_or_none, problem.tol
    max_steps = as_step_count(problem.max_steps, default=500)
    mask = problem.movable
    p = curve.degree
    closed = curve.closed
    band = _band_storage(curve.n_ctrl, curve.dim, p, closed)
    W = None
    for k, wgt in w.items():
        Wk = np.asarray(curve.gram_band(k))  # cached, read-only: scaled copies only if needed
        if wgt != 1.0:
            Wk = Wk * wgt
        W = Wk if W is None else W + Wk
    W = _readonly_view(np.ascontiguousarray(W))
    d0 = np.ascontiguousarray(curve.control_points, dtype=float)  # read only: no copy
    n, dim = d0.shape

    def residual(x: FloatArray) -> FloatArray:  # (W ks) x, difference form
        out = np.empty_like(x)
        _k.band_residual_scaled(W, ks, p, closed, np.ascontiguousarray(x), out)
        return out

    def energy(x: FloatArray) -> float:
        return float(band_energy(W, p, closed, _readonly_view(np.ascontiguousarray(x))))

    E0 = energy(d0)
    lam = np.zeros(n)
    # (a count, not an index array of the free points: 8 bytes a point less through the
    # Newton iteration)
    n_free = int(np.count_nonzero(mask))
    if n_free == 0:
        return GlobalResult(curve, E0, E0, lam, 0, "no_movable_point",
                            np.zeros(0, dtype=np.int64))
    if E0 <= 0.0:
        return GlobalResult(curve, E0, E0, lam, 0, "zero_energy", np.zeros(0, dtype=np.int64))
    if max_steps == 0:  # no iteration (not even the start or the unconstrained solve)
        return GlobalResult(curve, E0, E0, lam, 0, "max_steps", np.zeros(0, dtype=np.int64))
    # F = E / E0: grad F = kron(K, I) d with K = W ks, never formed: every kernel reads the
    # entries of W times ks (the same rounded values as a scaled copy, without its 56 MB at
    # 1e6 planar cubic points)
    ks = 2.0 / E0
    system = _System(W, ks, p, dim, closed, ~mask, band)
    eye = np.broadcast_to(np.eye(dim), (n, dim, dim))

    if tol is None:
        if closed and n - n_free < 2:
            # every closed curve's energy falls to 0 as it shrinks: the limit is one point
            # (at most one control point held), and every figure of it is rounding noise
            raise InputError(
                "tol: method 'global' without a tolerance on a closed curve with fewer than 2 "
                "held control points has one answer, a single point (the energy of a closed "
                "curve falls to 0 as it shrinks); give tol, or protect at least 2 control "
                "points")
        # (K + delta I) (d - o) = -K o on the free points
        delta = 1e-15 * float((W[mask, p] * ks).max())
        if not system.factor(delta * eye):
            raise InputError("the energy matrix is singular on the free control points")
        x = d0 + system.solve(-residual(d0))
        out = curve.replace(control_points=x)
        return GlobalResult(out, E0, energy(x), lam, 1, "unconstrained",
                            np.zeros(0, dtype=np.int64))

    g0 = residual(d0)
    v, lam_, steps, reason = _solve_balls(system, g0, mask, tolv, gap, max_steps)
    # strict feasibility in floating point, with a rounding margin (active points end on
    # their sphere): every fl(x_i - o_i) and the evaluated curve stay within tol. Rounding
    # o_i + v_i moves each coordinate by at most half an ulp of |o_i| <= eps max|o| / 2, so
    # 8 eps max|o| covers it (at most a quarter of tol when the coordinates' ulp is not small
    # against tol; fair() then pulls any remaining point back, _tolerance.enforce_tolerance)
    margin = min(0.25 * tolv, 1e-13 * tolv + 8.0 * np.finfo(float).eps * _absmax(d0))
    # x in the (no longer needed) gradient's memory: pages already mapped
    x = g0 if g0.flags.c_contiguous and not np.shares_memory(g0, v) else np.empty_like(d0)
    act = np.empty(n, dtype=np.bool_)
    rmax, ract = tolv - margin, (1 - 1e-6) * tolv
    _ranges(partial(_k.finish_points_range, d0, v, mask, rmax, ract, x, act), 0, n)
    # the Newton band storage (8x the coordinates' bytes) and work arrays (v is a view of
    # them) are freed before the result curve is validated and analysed
    del v, system
    # 2 (G d)_i + lam_i (d_i - o_i) = 0 (in place: no temporaries)
    lam = np.multiply(lam_, E0, out=lam_ if lam_.flags.writeable else None)
    lam /= tolv * tolv
    lam[~mask] = 0.0
    out = curve.replace(control_points=x)
    active = np.flatnonzero(act)
    return GlobalResult(out, E0, energy(x), lam, steps, reason, active)


def _solve_balls(system: _System, g0: FloatArray, free: np.ndarray, tol: float, gap: float,
                 max_steps: int, switch: float = 1e-2
                 ) -> tuple[FloatArray, FloatArray, int, StopReason]:
    """``min F(v) = F(o) + g0.v + v.K v / 2`` (``K = system.K``) over the displacements ``v``
    from the original points, s.t. ``|v_i| <= tol`` at the free points (``v = 0`` at the
    others): interior point, then active-set Newton (see :func:`global_fair`). Working with
    displacements keeps full relative precision whatever the coordinates. Returns
    ``(v, lambda, iterations, stop_reason)`` with ``g0 + K v + lambda v / tol^2 = 0`` at the
    free points (``g0`` is overwritten: 0 at the fixed points)."""
    n, dim = g0.shape
    K, ks, p, closed = system.K, system.ks, system.p, system.closed
    t2 = tol * tol
    m = int(free.sum())
    g0 = np.ascontiguousarray(g0)  # (the caller's fresh residual: zeroed in place)
    g0[~free] = 0.0
    gscale = _absmax(g0)
    if gscale == 0.0:  # already stationary: the input is optimal
        return np.zeros_like(g0), np.zeros(n), 0, "converged"
    eye = np.broadcast_to(np.eye(dim), (n, dim, dim))
    steps = 1
    if _ADMM_ITERS > 0 and n > 2 * p + 2 and max_steps > 1 and not system.dense:
        # 0. ADMM warm start (one n x n band factorisation), then the active-set Newton; the
        # Newton work arrays' pages mapped on the worker thread during the ADMM iterations
        work = _ssn_work(n, dim, prefault=_THREADS >= 2 and n >= _PAR_MIN)
        if closed:
            start = _admm_start_closed(K, ks, p, g0, free, tol)
        else:
            start = _admm_start(K, ks, p, g0, free, tol, system.L.reshape(-1))
        if start is not None:
            maxit = min(_ADMM_SSN_MAXIT, max_steps - 1)
            res = _active_set_newton(system, g0, free, tol, start[0], start[1], start[2],
                                     gscale, maxit, own=True, work=work,
                                     damp=min(_DAMPED_EXTRA, max_steps - 1 - maxit))
            steps += res[2]
            if res[3]:
                return res[0], res[1], steps, "converged"
    # 1. start: smoothing solve (K + mu0 I) v = -g0, pulled inside the balls (|v| <= tol / 2)
    mu0 = 0.01 * float((K[free, p] * ks).mean())
    v = np.zeros_like(g0)
    if system.factor(np.ascontiguousarray(mu0 * eye)):
        v = system.solve(-g0)
    r = np.sqrt(np.sum(v * v, axis=1))
    big = r > 0.5 * tol
    v[big] *= (0.5 * tol / r[big])[:, None]
    vv = np.sum(v * v, axis=1)
    g = g0 + _matvec(K, ks, p, closed, v)
    lam_floor = 0.1 * float(np.sqrt(np.sum(g0 * g0, axis=1))[free].mean()) * tol
    with np.errstate(divide="ignore", invalid="ignore"):
        lam = np.where(vv > 0, -np.sum(g * v, axis=1) * t2 / vv, 0.0)
    lam = np.where(free, np.maximum(lam, lam_floor), 0.0)
    may_switch = True
    rd = np.empty_like(v)
    rhs = np.empty_like(v)
    s = np.empty(n)
    rc = np.empty(n)
    rp = np.empty(n)
    ds = np.empty(n)
    dl = np.empty(n)
    B = np.empty((n, dim, dim))
    reason: StopReason = "max_steps"
    while steps < max_steps:
        rdm, smin, ls = _k.ip_eval(g0, K, ks, p, closed, v, lam, free, t2, rd, s)
        rdn = rdm / gscale
        mu = ls / m
        if rdn <= 1e-10 and ls <= gap:
            reason = "converged"
            break
        if may_switch and rdn < switch and ls < _SWITCH_GAP:
            kappa = float(lam[free].mean()) / float(s[free].mean())
            res = _active_set_newton(system, g0, free, tol, v, lam, kappa, gscale,
                                     min(8, max_steps - steps))
            steps += res[2]
            if res[3]:
                return res[0], res[1], steps, "converged"
            may_switch = False  # resume the interior point from its last iterate
            continue
        _k.ip_blocks(v, lam, s, free, t2, B)
        if not system.factor(B):
            reason = "converged" if rdn <= 1e-8 and ls <= max(1e3 * gap, 1e-8) else "numerical"
            break
        # predictor (affine scaling): target lam s = 0, i.e. rc = lam s
        np.multiply(lam, s, out=rc)
        rp[:] = 0.0
        _k.ip_rhs(rd, v, rc, rp, lam, s, free, t2, rhs)
        dv = system.solve(rhs, out=rhs)
        bm, lm = _k.ip_recover(dv, v, rc, rp, lam, s, free, t2, ds, dl)
        ap, ad = min(1.0, bm), min(1.0, lm)
        mu_aff = _k.ip_corrector(lam, s, dl, ds, ap, ad, free, rc) / m
        sigma = min(1.0, (mu_aff / mu) ** 3) if mu > 0 else 0.0
        # corrector: rc = lam s + dl_aff ds_aff - sigma mu, and the slack the predictor step
        # loses to the curvature of the spheres
        rc -= sigma * mu  # (fixed points: ignored by the kernels)
        _k.second_order(dv, free, t2, rp)
        _k.ip_rhs(rd, v, rc, rp, lam, s, free, t2, rhs)
        dv = system.solve(rhs, out=rhs)
        bm, lm = _k.ip_recover(dv, v, rc, rp, lam, s, free, t2, ds, dl)
        st = min(1.0, 0.995 * min(bm, lm))
        if not st > 1e-14:
            reason = "converged" if rdn <= 1e-8 and ls <= max(1e3 * gap, 1e-8) else "numerical"
            break
        _k.ip_update(v, dv, lam, dl, st)
        steps += 1
    return v, lam, steps, reason


_SWITCH_GAP = 1e-5
_RETRACT = True
# ADMM warm start: 20 iterations, 40 from _ADMM_LONG control points on (_admm_iters), rho
# adapted every 10 (at most 10x each time). On curves with most points active rho reaches the
# median curvature of the projected points only at the second adaptation, after 20 iterations:
# a 20-iteration start ran with rho 4-40x too small and left the Newton iteration a long damped
# phase (21 steps on bench_call_cost.py's 1e6 points, 3.6 s, against 7 steps, 2.3 s, with 40).
# An ADMM sweep costs about a tenth of a Newton step (more on closed curves); where fewer points
# are active the extra 20 sweeps gain nothing (3-25 % slower on 14 of 37 curves measured over
# sizes, noise levels, open/closed, 2-D/3-D, degrees 3 and 5, up to 4x faster on others:
# docs/benchmarks.md, session 41). Below _ADMM_LONG the call is mostly fixed costs (1e3 points:
# the same times either way), and where the energy does not determine the minimiser (a glyph
# outline held at its corners) another start lands on another one of the same energy: small
# curves keep the 20-iteration start, and the results they had.
_ADMM_ITERS = 20  # 0: no ADMM warm start
_ADMM_ITERS_LONG = 40
_ADMM_LONG = 10_000
_ADMM_ADAPT = 10
_ADMM_RHO0 = 0.03
_ADMM_ALPHA = 1.6
_ADMM_SSN_MAXIT = 15
_CHORD_RATE = 1e-2
# Newton step safeguard (_ssn_loop, from the ADMM start): largest accepted point displacement
# (in tol), damping increase per rejected step and decrease per accepted step, damping
# switched off below _MU_OFF of its first value, at most _MAX_REJECT rejections in a row,
# extra iterations allowed once damping has started. Measured on noisy lines / nearly straight
# curves (5e4 points, 2-D and 3-D, 6-65 % active at the end): 10-29 Newton iterations instead
# of 17-31 interior-point ones after a diverging first step (0.5-0.9x the time); with under 2 %
# active at the first rejection it took 30+ iterations, so those go to the interior point
_STEP_MAX = 1.0
_MU_UP = 10.0
_MU_DOWN = 0.3
_MU_OFF = 1e-6
_MAX_REJECT = 8
_DAMPED_EXTRA = 15
_DAMP_MIN_ACTIVE = 0.02  # damping only with at least this fraction of free points active
_DAMP_MIN_POINTS = 100  # and at least this many


def _admm_iters(n: int) -> int:
    """The ADMM warm start's iteration count for ``n`` control points (see ``_ADMM_ITERS``)."""
    return _ADMM_ITERS_LONG if _ADMM_ITERS > 0 and n >= _ADMM_LONG else _ADMM_ITERS


def _admm_start(K: FloatArray, ks: float, p: int, g0: FloatArray, free: np.ndarray, tol: float,
                scratch: FloatArray | None = None) -> tuple[FloatArray, FloatArray, float] | None:
    """Approximate solution ``(v, lambda, kappa)`` of the ball-constrained QP (open curves)
    by over-relaxed ADMM (Boyd et al. 2011, sec. 5.1): every iteration is one banded solve with
    the single ``n x n`` factor of ``K + rho I`` (the coordinates share it) and a projection
    onto the balls. ``rho`` starts at ``_ADMM_RHO0`` times the mean diagonal of ``K`` and is
    reset every ``_ADMM_ADAPT`` iterations to the median curvature ``lambda_i / tol^2`` of the
    projected points (the scale at which the splitting converges fastest). Cubics keep the
    vectors coordinate-major (:func:`curvefair._kernels.global_fair.admm_sweep_t`). The work
    arrays are carved from ``scratch`` (the
    Newton system's band storage, unused until then: its pages are then already mapped when
    the Newton iteration factorises) if it is large enough; the returned ``v`` may be a view
    of it. None if the factorisation fails."""
    n, dim = g0.shape
    iters = _admm_iters(n)
    t2 = tol * tol
    rho = _ADMM_RHO0 * float((K[:, p] * ks).mean())
    if not rho > 0.0:
        return None
    cubic = p == 3 and n >= 4  # U D U^T factor, coordinate-major vectors (admm_sweep_t)
    vec = (dim, n) if cubic else (n, dim)
    shapes = [(n, p + 1), vec, vec, vec, vec, (n, 1)]
    sizes = [a * b for a, b in shapes]
    if scratch is not None and scratch.size >= sum(sizes):
        offs = np.cumsum([0] + sizes)[:-1]
        L, z, u, y, g, un = (scratch[o:o + m].reshape(sh)
                             for o, m, sh in zip(offs, sizes, shapes, strict=True))
        z[:] = 0.0
        u[:] = 0.0
    else:
        L, z, u, y, g, un = (np.zeros(sh) for sh in shapes)
    un = un.reshape(-1)
    r2 = None if cubic else np.where(free, t2, 0.0)
    # (n, dim) views for the per-point bookkeeping
    zp, up, yp, gp = (a.T for a in (z, u, y, g)) if cubic else (z, u, y, g)
    gp[:] = g0
    np.negative(gp, out=yp)

    def factor(rho: float) -> bool:
        return _k.admm_factor(K, ks, p, rho, L) == 0

    if not factor(rho):
        return None
    for it in range(1, iters + 1):
        if cubic:
            _k.admm_sweep_t(L, y, z, u, g, rho, t2, free, _ADMM_ALPHA)
        else:
            _k.admm_sweep(L, y, z, u, g, rho, r2, _ADMM_ALPHA)
        if it % _ADMM_ADAPT == 0 and it < iters:
            m = _k.admm_active_norms(up, free, un)
            if m:
                new = float(np.median(un[:m])) * rho / tol
                new = min(max(new, 0.1 * rho), 10.0 * rho)
                if new != rho:
                    rho_old, rho = rho, new
                    if not factor(rho):
                        return None
                    _k.admm_rescale(z, u, g, rho_old / rho, rho, y)  # elementwise
    lam = np.empty(n)
    sl, ss, m = _k.admm_multipliers(zp, up, free, rho, t2, lam)
    if not (np.isfinite(sl) and np.isfinite(ss) and np.isfinite(z).all()):
        return None
    kappa = (sl / m) / max(ss / m, 1e-3)
    if not kappa > 0.0:
        kappa = rho * t2
    return zp, lam, kappa


def _admm_start_closed(K: FloatArray, ks: float, p: int, g0: FloatArray, free: np.ndarray,
                       tol: float) -> tuple[FloatArray, FloatArray, float] | None:
    """:func:`_admm_start` for closed curves: the same over-relaxed ADMM iteration (the same
    ``rho`` rule), with the cyclic band ``K + rho I`` factorised once per ``rho`` by the
    bordered band Cholesky of :class:`_System` (one unknown per point, shared by the
    coordinates); the point updates vectorised. None if the factorisation fails."""
    n, dim = g0.shape
    iters = _admm_iters(n)
    t2 = tol * tol
    rho = _ADMM_RHO0 * float((K[:, p] * ks).mean())
    if not rho > 0.0:
        return None
    sysA = _System(K, ks, p, 1, True, np.zeros(n, dtype=np.bool_))
    if sysA.dense:
        return None

    def factor(rho: float) -> bool:
        return sysA.factor(np.full((n, 1, 1), rho))

    if not factor(rho):
        return None
    r2 = np.where(free, t2, 0.0)
    z = np.zeros((n, dim))
    u = np.zeros((n, dim))
    x = np.empty((n, dim))
    un = np.empty(n)
    a1 = 1.0 - _ADMM_ALPHA
    for it in range(1, iters + 1):
        # x = (K + rho I)^{-1} y, the coordinates side by side (sysA has no fixed points)
        np.subtract(rho * (z - u), g0, out=x)
        _k.cyclic_solve_columns(sysA.L, sysA.Y, sysA.S, x)
        w = _ADMM_ALPHA * x + a1 * z + u  # over-relaxed x, plus u
        q2 = np.einsum("ij,ij->i", w, w)
        with np.errstate(divide="ignore", invalid="ignore"):
            f = np.where(q2 > r2, np.sqrt(r2 / q2), 1.0)
        np.multiply(w, f[:, None], out=z)  # projection onto the balls
        np.subtract(w, z, out=u)
        if it % _ADMM_ADAPT == 0 and it < iters:
            m = _k.admm_active_norms(u, free, un)
            if m:
                new = float(np.median(un[:m])) * rho / tol
                new = min(max(new, 0.1 * rho), 10.0 * rho)
                if new != rho:
                    u *= rho / new
                    rho = new
                    if not factor(rho):
                        return None
    lam = np.empty(n)
    sl, ss, m = _k.admm_multipliers(z, u, free, rho, t2, lam)
    if not (np.isfinite(sl) and np.isfinite(ss) and np.isfinite(z).all()) or m == 0:
        return None
    kappa = (sl / m) / max(ss / m, 1e-3)
    if not kappa > 0.0:
        kappa = rho * t2
    return z, lam, kappa


def _copy_into(out: FloatArray, a: FloatArray) -> FloatArray:
    out[...] = a
    return out


def _matvec(K: FloatArray, ks: float, p: int, closed: bool, x: FloatArray) -> FloatArray:
    out = np.empty_like(x)
    _k.band_matvec(K, ks, p, closed, np.ascontiguousarray(x), out)
    return out


def _ssn_work(n: int, dim: int, prefault: bool = False
              ) -> tuple[dict[str, FloatArray], _Prefault | None]:
    """Work arrays of :func:`_active_set_newton` (zeroed), carved from one buffer; with
    ``prefault`` its pages are mapped (zeroed) on the worker thread meanwhile (first touch
    of a page is a kernel fault: figures in docs/benchmarks.md).
    Planar blocks ``B`` (isotropic: the semismooth Newton writes only their diagonal, whose
    two entries are equal) are a strided view of ``2 n + 1`` doubles ``0, b_0, 0, b_1, 0, ...``:
    ``B[i, a, a] = b_i``, ``B[i, 0, 1] = B[i, 1, 0] = 0`` (16 MB instead of 32 at 1e6)."""
    planar = dim == 2
    shapes = {"v": (n, dim), "rd": (n, dim), "B": (2 * n + 1,) if planar else (n, dim, dim),
              "nrm": (n, dim), "c": (n,), "dv": (n, dim)}
    if not prefault:
        arrs = {k: np.zeros(sh) for k, sh in shapes.items()}
        pre = None
    else:
        sizes = [int(np.prod(sh)) for sh in shapes.values()]
        flat = np.empty(sum(sizes))
        offs = np.cumsum([0] + sizes)
        arrs = {k: flat[offs[q]:offs[q + 1]].reshape(sh)
                for q, (k, sh) in enumerate(shapes.items())}
        pre = _Prefault(flat)
    if planar:
        b = arrs["B"]
        arrs["B"] = np.lib.stride_tricks.as_strided(
            b[1:], shape=(n, 2, 2), strides=(2 * b.strides[0], b.strides[0], -b.strides[0]))
    return arrs, pre


def _active_set_newton(system: _System, g0: FloatArray, free: np.ndarray, tol: float,
                       v: FloatArray, lam: FloatArray, kappa: float, gscale: float, maxit: int,
                       own: bool = False,
                       work: tuple[dict[str, FloatArray], _Prefault | None] | None = None,
                       damp: int = -1) -> tuple[FloatArray, FloatArray, int, bool]:
    """Semismooth Newton on the KKT system from ``(v, lam)`` (not modified unless ``own``:
    then ``lam`` is used in place); returns ``(v, lam, iterations, converged)``. The active
    set is written straight into the system's frame flags. ``work``: zeroed work arrays
    (:func:`_ssn_work`; used once)."""
    n, dim = v.shape
    if work is None:
        work = _ssn_work(n, dim)
    if work[1] is not None:
        work[1].join()
    w = work[0]
    v = _copy_into(w["v"], v)  # a copy (the ADMM start is a coordinate-major view)
    if not own:
        lam = lam.copy()
    rd = w["rd"]
    B = w["B"]  # ssn_eval_prep writes the diagonal (planar: one shared entry, see _ssn_work)
    nrm = w["nrm"]  # written at the active points only
    Q = system.Q
    if dim == 2 and not system.dense:
        # the planar kernels read (and the evaluation writes) only the first column of the
        # frames, which is the normal: Q[i, :, 0] is nrm[i] (a view; no 32 MB array at 1e6)
        Q = np.lib.stride_tricks.as_strided(nrm, shape=(n, 2, 2),
                                            strides=(nrm.strides[0], nrm.strides[1], 0))
    Q_saved, system.Q = system.Q, Q
    try:
        return _ssn_loop(system, g0, free, tol, v, lam, kappa, gscale, maxit, rd, B, nrm,
                         w["c"], w["dv"], damp)
    finally:
        system.Q = Q_saved


def _ssn_loop(system: _System, g0: FloatArray, free: np.ndarray, tol: float, v: FloatArray,
              lam: FloatArray, kappa: float, gscale: float, maxit: int, rd: FloatArray,
              B: FloatArray, nrm: FloatArray, c: FloatArray, dv: FloatArray, damp: int
              ) -> tuple[FloatArray, FloatArray, int, bool]:
    n, dim = v.shape
    K, ks, p, closed = system.K, system.ks, system.p, system.closed
    t2 = tol * tol
    delta = 1e-14 * _absmax(K[:, p] * ks)
    S = system.rot
    S_fac = np.zeros(n, dtype=np.bool_)  # active set of the current factorisation
    have_fac = False
    stat_prev = np.inf
    step2 = (_STEP_MAX * tol) ** 2
    mu = 0.0  # Levenberg-Marquardt damping (0: the plain Newton step)
    mu0 = 0.0  # its scale, set at the first rejected step
    rejects = 0
    it = 0
    while True:
        parts = _ranges(partial(_k.ssn_eval_range,  # (mu = 0: delta)
            g0, K, ks, p, closed, v, lam, free, t2, kappa, delta + mu, S, rd, B, nrm, c,
            system.Q, system.fix, system.fix0), 0, n)
        rdm, feas, fS, nS = parts[0]
        for a_, b_, c_, d_ in parts[1:]:  # as one pass: maxima (NaN propagates), a count
            rdm = a_ if not a_ <= rdm else rdm
            feas = b_ if not b_ <= feas else feas
            fS = c_ if not c_ <= fS else fS
            nS += d_
        stat = rdm / gscale
        if not np.isfinite(stat):
            return v, lam, it, False
        if stat <= 1e-10 and feas <= 1e-12 and fS <= 1e-12:
            return v, lam, it, True
        # feas > 1 (once damped: 4): a point went past sqrt(3) tol (3 tol): diverging
        if it >= maxit or feas > (4.0 if mu0 > 0.0 else 1.0):
            return v, lam, it, False
        # in the fast (quadratic) phase with an unchanged active set the matrix has changed
        # only by the last, small step (frames, multipliers): reuse its factorisation (an
        # inexact Newton step; the next step refactorises unless it too reduced the residual
        # by _CHORD_RATE)
        chord = have_fac and stat <= _CHORD_RATE * stat_prev and np.array_equal(S, S_fac)
        stat_prev = stat
        prepped = False
        if not chord:
            # the right-hand side prepared on the worker thread during the factorisation
            ok = system.factor(B, nrot=nS,
                               then=partial(system.prep_start, B, nS, rd, c, dv, -1.0))
            fin, system.then = system.then, None
            if fin is not None:
                fin()
                prepped = True
            if not ok:
                return v, lam, it, False
            S_fac[:] = S
            have_fac = True
        system.solve(rd, c, out=dv, sgn=-1.0, prepped=prepped)
        it += 1
        # safeguard: a step that moves some inactive point further than _STEP_MAX tol (an
        # active one, along its tangent plane, further than twice that) is not trusted
        # (the linearisation lets points slide freely along the tangents of their spheres and
        # inactive points move freely: soft directions when few points are active); it is
        # discarded and the system solved again with the damping mu I added to the blocks
        # (Levenberg-Marquardt, a trust region on the point displacements). Accepted damped
        # steps shrink mu geometrically back to 0 (then quadratic convergence again).
        r2, m2 = system.step2 if system.step2 is not None else (0.0, _k.max_point_norm2(dv))
        if damp >= 0 and not (m2 <= step2 and r2 <= 4.0 * step2):
            if not (np.isfinite(m2) and np.isfinite(r2)) or rejects >= _MAX_REJECT:
                return v, lam, it, False
            if mu0 == 0.0:  # first rejection: the scale, and a longer budget
                if nS < max(_DAMP_MIN_ACTIVE * np.count_nonzero(free), _DAMP_MIN_POINTS):
                    # very few active points: the damped iteration finds the active set
                    # slowly (measured: more iterations than the interior point)
                    return v, lam, it, False
                lS = lam[S]
                mu0 = float(np.median(lS)) / t2 if lS.size else 0.0
                mu0 = max(mu0, 1e-6 * float((K[:, p] * ks).mean()))
                maxit += damp
            if not chord:  # (a rejected chord step is first retried with a new factor)
                mu = max(_MU_UP * mu, mu0)
            rejects += 1
            have_fac = False
            continue
        rejects = 0
        if dim == 2 and p == 3 and n > 6:  # interior points in ranges (two threads)
            _ranges(lambda a, b: _k.ssn_update23_range(K, ks, closed, v, dv, rd, lam, S, nrm,
                                                       t2, _RETRACT, a, b), 3, n - 3)
            _k.ssn_update_k(K, ks, p, closed, v, dv, rd, lam, S, nrm, t2, _RETRACT, True)
        else:
            _k.ssn_update_k(K, ks, p, closed, v, dv, rd, lam, S, nrm, t2, _RETRACT)
        if mu > 0.0:
            mu = mu * _MU_DOWN if mu * _MU_DOWN >= _MU_OFF * mu0 else 0.0


# ------------------------------------------------------------------------------------------
# registration with fair()
# ------------------------------------------------------------------------------------------
def solve(problem: FairingProblem, *, l: Any = 2) -> Outcome:  # noqa: E741
    """The global minimiser as a solver of ``problem`` (``fair(curve, "global")``): ``eps`` is
    the interior point's ``gap``, relative to ``E(input)`` (default ``1e-13``, at least
    ``1e-16``); ``max_steps`` caps the Newton iterations (default 500). The history lists each
    moved control point once (measure 0: a simultaneous solve ranks nothing)."""
    from .problem import FairingHistory, Outcome

    gap = 1e-13 if problem.eps is None else max(float(problem.eps), 1e-16)
    max_steps = 500 if problem.max_steps is None else problem.max_steps
    res = _global_fair(problem, l, gap)
    curve = problem.curve
    p0 = np.asarray(curve.control_points)  # type: ignore[attr-defined]
    p1 = np.asarray(res.curve.control_points)
    moved = np.flatnonzero(np.any(p0 != p1, axis=1))
    disp = np.sqrt(np.sum((p1[moved] - p0[moved]) ** 2, axis=1))
    hist = FairingHistory.from_arrays(moved, np.zeros(moved.size), disp, "control point")
    return Outcome(
        curve=res.curve, steps=res.iterations, stop_reason=res.stop_reason, history=hist,
        eps=gap, max_steps=max_steps, eps_absolute=gap * res.energy_before,
        extra={"l": l if isinstance(l, (int, np.integer)) else str(l),
               "energy_l_before": res.energy_before, "energy_l_after": res.energy_after,
               "n_active": int(res.active.size),
               "history_is": "one entry per moved control point (simultaneous solve)"})


def _register() -> None:
    from .fair import MethodSpec, register_method

    register_method(MethodSpec(
        name="global",
        curve_types=(BSplineCurve,),
        solver=solve,
        summary="Global minimiser of E_l (l=2, 3 or a blend) over all free control points, "
                "each within tol of the original (convex QP, interior point, banded solves)",
        source="the problem of Eck & Hadenfeld (seed 003 eq. (12)) solved for all points at "
               "once; deviation bound seed 004 eqs. (8.34)-(8.36)",
        default=True,
        prefer=_prefer_default,
        default_options=_default_options,
        default_reason=DEFAULT_REASON,
        two_threads=True,  # (its Newton passes and set-up run in ranges on both threads)
    ))


#: the largest control-point count for which ``global`` (l=3) is the B-spline default: its
#: interior point takes ~30x one csaps fit at 1e6 points (docs/benchmarks.md); larger curves
#: default to ``eck-hadenfeld`` (sweep), whose whole call stays within a few csaps fits
DEFAULT_MAX_CTRL = 200_000


def _prefer_default(curve: Any) -> bool:
    return isinstance(curve, BSplineCurve) and curve.n_ctrl <= DEFAULT_MAX_CTRL


#: Why ``global`` with ``l = 3`` is the B-spline default (``curvefair methods``).
DEFAULT_REASON = (
    "fairest method that keeps degree, knots and control-point count: with l=3 it reaches "
    "the true curvature-extrema count on 16/84 ground-truth curves (eck-hadenfeld 2/84), "
    "airfoil extrema ratio median 0.521 (eck-hadenfeld 0.923), glyph runs 0.368 (0.478) "
    "[make bench-quality, docs/benchmarks.md, 2026-12-01]")


def _default_options(curve: BSplineCurve) -> dict[str, Any]:
    """l=3 on degree >= 3, else l=2

    (E_l needs degree >= l)."""
    return {"l": 3} if curve.degree >= 3 else {}


_register()
