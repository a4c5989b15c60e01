"""B-spline curves of any degree >= 2: clamped open curves and periodic (closed) curves.

Representation
--------------
*Open* curves are clamped: ``n`` control points ``d_0 .. d_{n-1}``, ``n + degree + 1`` knots
``t_0 <= ... <= t_{n+p}`` (``p = degree``) with ``t_0 = ... = t_p`` and
``t_n = ... = t_{n+p}``; the domain is ``[t_p, t_n]`` and ``r(t) = sum_i d_i N_{i,p}(t)``.

*Closed* curves store the ``n`` DISTINCT control points in :attr:`BSplineCurve.control_points`
and the full periodic knot vector of length ``n + 2p + 1`` in :attr:`BSplineCurve.knots`:
the spline is ``r(t) = sum_{i=0}^{n+p-1} d_{i mod n} N_{i,p}(t)`` on ``[t_p, t_{p+n}]`` (the
first ``p`` control points wrapped at the end, exactly scipy's periodic ``BSpline`` layout), and
``t_{i+n} - t_i = T`` (the period) for every ``i``. The constructor also accepts only one period
of knots (``n + 1`` values ``t_p .. t_{p+n}``) and extends it.

Indices are 0-based; the papers number from 1 (Eck & Hadenfeld write ``N_{i,k}`` with the
order ``k = p + 1``).
"""

from __future__ import annotations

from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np
from scipy.sparse import csr_matrix

from .. import _threads
from .._kernels.bspline import (
    band_energy,
    ders_kernel,
    first_coincident,
    gram_kernel,
    natural_cubic_kernel,
    power_form_kernel,
    power_form_pair_kernel,
)
from .._typing import ArrayLike, FloatArray
from .._validate import MAX_DEGREE as MAX_DEGREE  # the degree limit, also known here
from .._validate import (
    as_degree,
    as_float,
    as_params,
    as_points,
    check_steps,
    magnitude,
)
from ..errors import InputError
from .parameterize import closed_point_data, parameterize
from .piecewise import PiecewiseCurve, PiecewisePolynomial, readonly

if TYPE_CHECKING:  # scipy.interpolate is imported where used (0.3 s of `import curvefair`)
    from scipy.interpolate import BSpline

__all__ = ["BSplineCurve", "interpolate_bspline", "fit_bspline", "basis_derivatives"]


# ------------------------------------------------------------------------------------------
# basis functions
# ------------------------------------------------------------------------------------------
def basis_derivatives(knots: FloatArray, degree: int, span: np.ndarray, x: FloatArray,
                      nder: int, local: bool = False) -> FloatArray:
    """Non-zero B-spline basis functions and derivatives, vectorised over parameters.

    Parameters
    ----------
    knots : ndarray, shape (K,)
    degree : int
    span : int ndarray, shape (m,)
        Knot span ``s`` of each parameter, ``knots[s] <= x < knots[s+1]`` (``knots[s] <
        knots[s+1]``); the non-zero functions there are ``N_{s-p} .. N_s``.
    x : ndarray, shape (m,)
    nder : int
        Highest derivative.
    local : bool
        ``x`` holds offsets ``x - knots[span]`` (then equal knot patterns give bitwise equal
        results wherever they sit on the line).

    Returns
    -------
    ndarray, shape (m, nder+1, degree+1)
        ``out[q, k, a] = N_{span[q]-p+a}^{(k)}(x[q])``.

    Notes
    -----
    Piegl & Tiller, *The NURBS Book*, algorithm A2.3 (compiled loop over the parameters).
    """
    p = int(degree)
    x = np.ascontiguousarray(x, dtype=np.float64)
    s = np.ascontiguousarray(span, dtype=np.int64)
    out = np.zeros((x.shape[0], int(nder) + 1, p + 1))
    ders_kernel(np.ascontiguousarray(knots, dtype=np.float64), p, s, x, int(nder), bool(local),
                out)
    return out


_GAUSS: dict[int, tuple[FloatArray, FloatArray]] = {}


def _gauss(nq: int) -> tuple[FloatArray, FloatArray]:
    """Gauss-Legendre nodes and weights of ``nq`` points on ``[0, 1]``: numpy's ``leggauss``
    (an eigenproblem and a Newton polish, tens of microseconds: felt by small curves, whose
    whole ``fair()`` call is a millisecond or two) made once per ``nq``; fresh copies
    returned."""
    got = _GAUSS.get(nq)
    if got is None:
        x, w = np.polynomial.legendre.leggauss(nq)
        got = _GAUSS[nq] = (0.5 * (x + 1.0), 0.5 * w)
    return got[0].copy(), got[1].copy()


# ------------------------------------------------------------------------------------------
# the curve
# ------------------------------------------------------------------------------------------
#: Highest degree evaluated through the power form. Above it, values and derivatives come from
#: the B-spline basis itself (Piegl & Tiller A2.3 on local offsets, the stable recurrence scipy's
#: ``BSpline`` uses too): the power form's Horner sum cancels like ``2**p`` (relative errors
#: against exact rational evaluation on one Bezier span: 3e-15 at degree 4, 8e-14 at 8, 8e-11
#: at 15, 1.5e-6 at 25; the basis stays within 1e-15 throughout).
POWER_FORM_MAX_DEGREE = 5

#: Knot spans: from this many on, the power form is computed in ranges on two threads.
POWER_FORM_PAR_MIN = 50_000
#: Spans from which :meth:`BSplineCurve.gram_band` runs its two halves on two threads.
GRAM_PAR_MIN = 50_000


def power_form(knots: FloatArray, p: int, spans: np.ndarray, ctrl: FloatArray, closed: bool,
               out: FloatArray, base: FloatArray | None = None,
               out_diff: FloatArray | None = None) -> None:
    """:func:`~curvefair._kernels.bspline.power_form_kernel` (``base`` None) or
    :func:`~curvefair._kernels.bspline.power_form_pair_kernel` (the form of ``ctrl`` and of
    ``ctrl - base``) over ranges of the spans, on two threads for long curves
    (:mod:`curvefair._threads`). Each span's coefficients depend on its own knots and control
    points only, so the result is bitwise that of one pass."""
    closed = bool(closed)
    if base is None:
        def run(a: int, b: int) -> None:
            power_form_kernel(knots, p, spans[a:b], ctrl, closed, out[a:b])
    else:
        assert out_diff is not None

        def run(a: int, b: int) -> None:
            power_form_pair_kernel(knots, p, spans[a:b], ctrl, base, closed, out[a:b],
                                   out_diff[a:b])
    _threads.ranges(run, 0, spans.shape[0], _threads.THREADS, POWER_FORM_PAR_MIN)



class BSplineCurve(PiecewiseCurve):
    """Polynomial B-spline curve of any degree >= 2, clamped open or periodic closed.

    Parameters
    ----------
    control_points : array_like, shape (n, dim)
        Control points ``d_i``, dim 2 or 3 (for a closed curve: the ``n`` distinct ones).
    knots : array_like
        Open: ``n + degree + 1`` non-decreasing knots, clamped (the first ``degree + 1`` equal,
        the last ``degree + 1`` equal), interior multiplicity ``<= degree``.
        Closed: the periodic knot vector of ``n + 2 degree + 1`` knots
        (``t_{i+n} - t_i`` constant), or one period ``t_p .. t_{p+n}`` (``n + 1`` values,
        strictly increasing up to multiplicity ``<= degree``).
    degree : int
        Polynomial degree ``p >= 2``.
    closed : bool
        Periodic curve (see the module docstring for the layout).

    Attributes
    ----------
    control_points : ndarray, shape (n, dim), read-only
    knots : ndarray, read-only
        Full knot vector (periodic one for closed curves).
    degree : int
    closed : bool

    Notes
    -----
    ``r(t) = sum_i d_i N_{i,p}(t)`` (Eck & Hadenfeld, eq. (9), with order ``k = p + 1`` and
    0-based indices). The local power form (:attr:`piecewise`) is built per distinct knot span
    from the basis derivatives at the span's left end (Piegl & Tiller algorithm A2.3).

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import BSplineCurve
    >>> c = BSplineCurve([[0, 0], [1, 2], [3, 2], [4, 0]], [0, 0, 0, 0, 1, 1, 1, 1], 3)
    >>> c(0.5).tolist()
    [2.0, 1.5]
    >>> c.to_scipy()(0.5).tolist()
    [2.0, 1.5]
    """

    def __init__(self, control_points: ArrayLike, knots: ArrayLike, degree: int,
                 closed: bool = False) -> None:
        p = as_degree(degree)
        closed = bool(closed)
        pts = as_points(control_points, "control_points", min_points=p + 1,
                        allow_coincident=True)
        n = pts.shape[0]
        t = as_float(knots, "knots")
        if t.ndim != 1:
            raise InputError(f"knots must be 1-D, got shape {t.shape}")
        check_steps(t, "knots", strict=False)
        if closed:
            t = self._periodic_knots(t, n, p)
        else:
            self._check_open_knots(t, n, p)
        self._ctrl = readonly(pts)
        self._knots = readonly(t)
        self.degree = p
        self._closed = closed
        self._gram_cache: dict[int, FloatArray] = {}

    @classmethod
    def _trusted(cls, control_points: FloatArray, knots: FloatArray, degree: int,
                 closed: bool, *, same_knots_as: "BSplineCurve | None" = None
                 ) -> "BSplineCurve":
        """A curve from arrays the caller has built valid (float64 ``(n, dim)`` finite control
        points it owns, a full valid knot vector): no checks, no copies (both made read-only).
        ``same_knots_as``: a curve with these very knots, whose Gram matrices are shared."""
        out = cls.__new__(cls)
        out._ctrl = readonly(control_points)
        out._knots = readonly(knots)
        out.degree = int(degree)
        out._closed = bool(closed)
        out._gram_cache = {} if same_knots_as is None else same_knots_as._gram_cache
        return out

    # -- validation -------------------------------------------------------------------------
    @staticmethod
    def _check_open_knots(t: FloatArray, n: int, p: int) -> None:
        if t.shape[0] != n + p + 1:
            raise InputError(f"knots must have n + degree + 1 = {n + p + 1} values for {n} control "
                             f"points of degree {p} (open curve), got {t.shape[0]}")
        for i in range(1, p + 1):
            if t[i] != t[0]:
                raise InputError(f"open curves must be clamped: knots[0..{p}] must be equal, but "
                                 f"knots[{i}] = {float(t[i])!r} != knots[0] = {float(t[0])!r}")
            k = n + p - i
            if t[k] != t[-1]:
                raise InputError(f"open curves must be clamped: knots[{n}..{n + p}] must be equal, "
                                 f"but knots[{k}] = {float(t[k])!r} != "
                                 f"knots[{n + p}] = {float(t[-1])!r}")
        if not t[p] < t[n]:
            raise InputError(f"the domain [knots[{p}], knots[{n}]] = "
                             f"[{float(t[p])!r}, {float(t[n])!r}] is empty")
        # end multiplicity exactly degree + 1: a (p+2)-fold end knot makes N_0 (or N_{n-1})
        # vanish on the domain, so its control point would be no point of the curve
        if not t[p + 1] > t[p]:
            raise InputError(f"knot {float(t[0])!r} at the start has multiplicity > degree + 1 = "
                             f"{p + 1} (knots[0..{p + 1}] are equal): an open clamped knot "
                             f"vector repeats each end knot exactly degree + 1 times")
        if not t[n - 1] < t[n]:
            raise InputError(f"knot {float(t[-1])!r} at the end has multiplicity > degree + 1 = "
                             f"{p + 1} (knots[{n - 1}..{n + p}] are equal): an open clamped "
                             f"knot vector repeats each end knot exactly degree + 1 times")
        BSplineCurve._check_multiplicity(t[p + 1:n], p, offset=p + 1)

    @staticmethod
    def _check_multiplicity(inner: FloatArray, p: int, offset: int) -> None:
        if inner.shape[0] <= p:
            return
        # p+1 equal consecutive knots <=> inner[i] == inner[i+p]
        same = inner[p:] == inner[:-p]
        bad = np.flatnonzero(same)
        if bad.size:
            i = int(bad[0])
            raise InputError(f"interior knot {float(inner[i])!r} at knots[{i + offset}] has "
                             f"multiplicity > degree = {p}")

    @staticmethod
    def _periodic_knots(t: FloatArray, n: int, p: int) -> FloatArray:
        if t.shape[0] == n + 1:
            period = t
        elif t.shape[0] == n + 2 * p + 1:
            period = t[p:p + n + 1]
            T = period[-1] - period[0]
            dt = np.diff(t)
            scale = magnitude(t)
            bad = np.flatnonzero(np.abs(dt[n:] - dt[:-n]) > 1e-10 * scale)
            if bad.size:
                i = int(bad[0])
                raise InputError(
                    f"closed curve: knots must be periodic (knots[i+{n}] - knots[i] = period "
                    f"{float(T)!r}), but knots[{i + n + 1}] - knots[{i + n}] = "
                    f"{float(dt[i + n])!r} != "
                    f"knots[{i + 1}] - knots[{i}] = {float(dt[i])!r}")
        else:
            raise InputError(
                f"closed curve with {n} control points of degree {p}: knots must have "
                f"n + 2 degree + 1 = {n + 2 * p + 1} values (periodic knot vector) or n + 1 = "
                f"{n + 1} (one period), got {t.shape[0]}")
        T = period[-1] - period[0]
        if not T > 0:
            raise InputError(f"closed curve: the period knots[{p}..{p + n}] is empty")
        # multiplicity over the cyclic sequence of one period (the seam counts once)
        cyc = np.concatenate([period[:-1], period[:p] + T])
        same = cyc[p:] == cyc[:-p]
        bad = np.flatnonzero(same)
        if bad.size:
            i = int(bad[0])
            raise InputError(f"knot {float(cyc[i])!r} at knots[{i + p}] has multiplicity > "
                             f"degree = {p}")
        full = np.empty(n + 2 * p + 1)
        full[p:p + n + 1] = period
        full[:p] = period[n - p:n] - T
        full[p + n + 1:] = period[1:p + 1] + T
        return full

    # -- data -------------------------------------------------------------------------------
    @property
    def control_points(self) -> FloatArray:
        """Control points, shape ``(n, dim)`` (the distinct ones for a closed curve; read-only)."""
        return self._ctrl

    @property
    def knots(self) -> FloatArray:
        """Knot vector (read-only): ``n + p + 1`` values (open) or ``n + 2p + 1`` (closed)."""
        return self._knots

    @property
    def closed(self) -> bool:
        return self._closed

    @property
    def dim(self) -> int:
        return int(self._ctrl.shape[1])

    @property
    def n_ctrl(self) -> int:
        """Number of (distinct) control points ``n``."""
        return int(self._ctrl.shape[0])

    def __len__(self) -> int:
        return self.n_ctrl

    @property
    def extended_control_points(self) -> FloatArray:
        """Control points multiplying ``N_0 .. N_{K-p-2}`` of :attr:`knots`: for a closed curve
        the first ``degree`` points are repeated at the end, shape ``(n + p, dim)``."""
        if not self._closed:
            return self._ctrl
        return readonly(self._ctrl[np.arange(self.n_ctrl + self.degree) % self.n_ctrl])

    @property
    def domain(self) -> tuple[float, float]:
        p = self.degree
        return float(self._knots[p]), float(self._knots[-p - 1])

    @cached_property
    def spans(self) -> np.ndarray:
        """Indices ``s`` of the non-empty knot spans ``[knots[s], knots[s+1])`` of the domain."""
        p = self.degree
        t = self._knots
        K = t.shape[0]
        s = np.flatnonzero(t[p + 1:K - p] > t[p:K - p - 1])  # slices: no index gathers
        s += p
        return readonly(s)

    @property
    def span_breaks(self) -> FloatArray:
        """The breakpoints of the power form (:attr:`piecewise`'s ``breaks``, the same values):
        the left knot of each of :attr:`spans` and the end of the domain, without building the
        form."""
        t, s = self._knots, self.spans
        return np.append(t[s], t[s[-1] + 1])

    def __repr__(self) -> str:
        return (f"BSplineCurve(n_ctrl={self.n_ctrl}, degree={self.degree}, dim={self.dim}, "
                f"closed={self.closed}, domain={self.domain})")

    def replace(self, **changes: Any) -> "BSplineCurve":
        """A new curve with some of control_points, knots, degree, closed changed."""
        kw: dict[str, Any] = {"control_points": self._ctrl, "knots": self._knots,
                              "degree": self.degree, "closed": self._closed}
        unknown = set(changes) - set(kw)
        if unknown:
            raise InputError(f"replace() got unknown fields {sorted(unknown)}; valid: {sorted(kw)}")
        kw.update(changes)
        out = type(self)(**kw)
        if set(changes) <= {"control_points"} and out.n_ctrl == self.n_ctrl:
            out._gram_cache = self._gram_cache  # same knots: the Gram matrices are shared
        return out

    def control_index(self, i: ArrayLike) -> np.ndarray:
        """Map indices of basis functions ``N_i`` of :attr:`knots` to control-point indices
        (``i mod n`` for closed curves)."""
        i = np.asarray(i)
        return i % self.n_ctrl if self._closed else i

    # -- piecewise form ---------------------------------------------------------------------
    def _make_piecewise(self) -> PiecewisePolynomial:
        """Power form per knot span: ``c[m, k] = sum_a N_{s-p+a}^(k)(t_s) d_{s-p+a} / k!``
        (Taylor coefficients at the span's left knot), one compiled pass over the spans."""
        p = self.degree
        t = self._knots
        s = np.ascontiguousarray(self.spans, dtype=np.int64)
        coeffs = np.empty((s.size, p + 1, self._ctrl.shape[1]))
        power_form(np.ascontiguousarray(t), p, s, np.ascontiguousarray(self._ctrl),
                   self._closed, coeffs)
        breaks = self.span_breaks
        if p > POWER_FORM_MAX_DEGREE:
            return PiecewisePolynomial(breaks, coeffs, evaluator=self._span_values)
        return PiecewisePolynomial(breaks, coeffs)

    def span_coefficients(self, which: np.ndarray) -> FloatArray:
        """The power-form coefficients of the spans ``which`` (indices into :attr:`spans`, any
        order, repeats allowed): shape ``(k, degree + 1, dim)``, bit for bit the rows
        ``piecewise.coeffs[which]`` (each span's coefficients depend on its own knots and
        control points only), without building the whole form (72 bytes a cubic planar span)."""
        idx = np.asarray(which, dtype=np.int64).reshape(-1)
        all_spans = np.asarray(self.spans)
        if idx.size and (int(idx.min()) < 0 or int(idx.max()) >= all_spans.shape[0]):
            raise InputError(f"span_coefficients: span indices must lie in 0 .. "
                             f"{all_spans.shape[0] - 1}")
        spans = np.ascontiguousarray(all_spans[idx])
        out = np.empty((spans.shape[0], self.degree + 1, self._ctrl.shape[1]))
        if spans.shape[0]:
            power_form_kernel(np.ascontiguousarray(self._knots), self.degree, spans,
                              np.ascontiguousarray(self._ctrl), self._closed, out)
        return out

    def _partial_form(self, u: FloatArray) -> tuple[FloatArray, FloatArray] | None:
        """The power form of the spans holding ``u`` (see
        :meth:`PiecewiseCurve._evaluate <curvefair.PiecewiseCurve>`), or None for a short curve,
        a degree above :data:`POWER_FORM_MAX_DEGREE` or a non-finite form (whose whole form
        raises its own message)."""
        p = self.degree
        s = np.asarray(self.spans)
        if p > POWER_FORM_MAX_DEGREE or 64 * u.size >= s.shape[0]:
            return None
        t = self._knots
        # the non-empty span [t_k, t_k+1) holding each u (right-continuous, the last one closed:
        # the whole form's segment_of on its breaks t[spans]), found in the knots themselves
        k = np.clip(np.searchsorted(t, u, side="right") - 1, s[0], s[-1])
        pos = np.searchsorted(s, k)
        rows = self.span_coefficients(pos)
        if not np.isfinite(rows).all():
            return None
        return rows, u - t[s[pos]]

    def _span_values(self, seg: np.ndarray, s: FloatArray, nu: int) -> FloatArray:
        """``r^(nu)`` on power-form segments ``seg`` at local offsets ``s`` from the basis:
        ``sum_a N_{k-p+a}^(nu)(t_k + s) d_{k-p+a}`` with ``k = spans[seg]`` (control indices
        mod ``n`` for a closed curve); shape ``(len(s), dim)``."""
        p = self.degree
        span = np.asarray(self.spans)[seg]
        N = basis_derivatives(self._knots, p, span, s, nu, local=True)[:, nu, :]  # (k, p+1)
        idx = span[:, None] - p + np.arange(p + 1)[None, :]
        if self._closed:
            idx %= self.n_ctrl
        return np.einsum("ka,kad->kd", N, self._ctrl[idx])

    # -- Gram matrices ----------------------------------------------------------------------
    def gram_band(self, l: int) -> FloatArray:  # noqa: E741
        """Exact Gram matrix ``G_ij = int N_i^(l) N_j^(l) dt`` over the domain, banded.

        Parameters
        ----------
        l : int
            Derivative order, ``1 <= l <= degree``.

        Returns
        -------
        ndarray, shape (n, 2 degree + 1), read-only (cached: it depends on the knots only)
            ``W[i, p + o] = G[i, (i + o)]`` for ``-p <= o <= p`` (open curves: zero where
            ``i + o`` is out of range; closed curves: the column index is ``(i + o) mod n``, and
            when ``n < 2p + 1`` several offsets may name the same column -- their entries add).

        Notes
        -----
        Gauss-Legendre quadrature with ``p - l + 1`` nodes per knot span is exact for the
        degree ``2 (p - l)`` integrand (Eck & Hadenfeld, eq. (15) and the remark after (16)).

        Examples
        --------
        >>> import numpy as np
        >>> from curvefair import BSplineCurve
        >>> c = BSplineCurve(np.zeros((10, 2)), np.arange(11.0), 3, closed=True)
        >>> (c.gram_band(2)[0] * 6).round(12).tolist() == [1, 0, -9, 16, -9, 0, 1]  # l = 2
        True
        """
        p = self.degree
        if isinstance(l, bool) or not isinstance(l, (int, np.integer)) or not 1 <= l <= p:
            raise InputError(f"l must be an integer in [1, degree = {p}], got {l!r}")
        W = self._gram_cache.get(int(l))
        if W is None:
            W = readonly(self._gram_band(int(l)))
            self._gram_cache[int(l)] = W
        return W

    def _gram_band(self, l: int) -> FloatArray:  # noqa: E741
        p = self.degree
        xq, wq = _gauss(p - int(l) + 1)
        t = np.ascontiguousarray(self._knots)
        s = np.ascontiguousarray(self.spans, dtype=np.int64)
        n = self.n_ctrl
        W = np.zeros((n, 2 * p + 1))
        if self._closed or s.shape[0] < GRAM_PAR_MIN or _threads.THREADS < 2:
            return gram_kernel(t, p, s, int(l), xq, wq, n, self._closed, W, 0)
        # two halves of the spans on two threads: the first accumulates into W, the second
        # (from p spans before its own: every span of its rows) rows row0 .. into its own
        # zeros, which then replace W's rows there (the first half's partial sums): each row
        # is one pass's sum, in one pass's order, bitwise
        k = s.shape[0] // 2
        row0 = int(s[k]) - p
        lead = int(np.searchsorted(s, row0, side="left"))
        tail = np.zeros((n - row0, 2 * p + 1))

        def half(a: int, b: int) -> None:
            if a == 0:
                gram_kernel(t, p, s[:k], int(l), xq, wq, n, False, W, 0)
            else:
                gram_kernel(t, p, s[lead:], int(l), xq, wq, n, False, tail, row0)

        _threads.ranges(half, 0, 2, 2, 0, chunks=2)
        W[row0:] = tail
        return W

    def gram_matrix(self, l: int) -> Any:  # noqa: E741
        """The Gram matrix of :meth:`gram_band` as a ``scipy.sparse`` CSR matrix ``(n, n)``."""
        W = self.gram_band(l)
        n, w = W.shape
        p = self.degree
        rows = np.repeat(np.arange(n), w)
        cols = (np.arange(n)[:, None] + np.arange(-p, p + 1)[None, :]).reshape(-1)
        vals = W.reshape(-1)
        if self._closed:
            cols = cols % n
        keep = (cols >= 0) & (cols < n) & (vals != 0)
        return csr_matrix((vals[keep], (rows[keep], cols[keep])), shape=(n, n))

    def energy_l(self, l: int) -> float:  # noqa: E741
        """``E_l = int |r^(l)(t)|^2 dt`` over the domain, from the exact Gram matrix (in the
        difference form of :func:`curvefair._kernels.bspline.band_energy`, accurate whatever
        the coordinates)."""
        W = np.ascontiguousarray(self.gram_band(l))
        return float(band_energy(W, self.degree, self._closed, np.ascontiguousarray(self._ctrl)))

    # -- scipy interop ----------------------------------------------------------------------
    def to_scipy(self) -> BSpline:
        """The same curve as a :class:`scipy.interpolate.BSpline` (periodic extrapolation for
        closed curves; coefficients shape ``(n + p, dim)`` there)."""
        from scipy.interpolate import BSpline
        c = np.array(self.extended_control_points)
        return BSpline(np.array(self._knots), c, self.degree,
                       extrapolate="periodic" if self._closed else True)

    @classmethod
    def from_scipy(cls, spl: BSpline, closed: bool | None = None) -> "BSplineCurve":
        """Build from a :class:`scipy.interpolate.BSpline` with coefficients ``(n, dim)``.

        ``closed=None`` detects a periodic spline (``extrapolate == "periodic"``, periodic knots,
        last ``k`` coefficients repeating the first ``k``). An unclamped open spline is converted
        to the clamped knot vector with the same interior knots (the same curve on its domain
        ``[t_k, t_n]``, found by interpolation at the Greville abscissae: exact up to rounding).
        End knots repeated more than ``k + 1`` times are reduced to ``k + 1`` (the dropped basis
        functions vanish on the domain), so scipy splines with them convert exactly.
        """
        from scipy.interpolate import BSpline, make_interp_spline
        if not isinstance(spl, BSpline):
            raise InputError(f"spl must be a scipy.interpolate.BSpline, got "
                             f"{type(spl).__name__}")
        t = as_float(spl.t, "spl.t")
        k = as_degree(spl.k)
        c = as_float(spl.c, "spl.c")
        if c.ndim != 2:
            raise InputError(f"spl.c must have shape (n, dim) with dim 2 or 3, got {c.shape}")
        c = c[: t.shape[0] - k - 1]
        if closed is None:
            closed = spl.extrapolate == "periodic"
        if closed:
            n = c.shape[0] - k
            if n < k + 1:
                raise InputError(f"periodic spline has too few coefficients ({c.shape[0]})")
            scale = magnitude(c)
            if not np.allclose(c[n:], c[:k], rtol=0.0, atol=1e-10 * scale):
                raise InputError("closed=True needs the last k coefficients of spl.c to repeat "
                                 "the first k (scipy's periodic layout)")
            return cls(c[:n], t, k, closed=True)
        n = c.shape[0]
        # an end knot repeated more than k + 1 times (scipy allows it) makes N_0 (N_{n-1})
        # vanish on the domain [t_k, t_n]: its coefficient is no point of the curve, drop both
        while n > k + 1 and t[k + 1] == t[k]:
            t, c, n = t[1:], c[1:], n - 1
        while n > k + 1 and t[n - 1] == t[n]:
            t, c, n = t[:n + k], c[:n - 1], n - 1
        if k >= 2 and n >= k + 1 and (np.any(t[:k + 1] != t[0]) or np.any(t[n:] != t[-1])):
            # unclamped: the same curve on [t_k, t_n] on the clamped knot vector (the space is
            # the same there), by interpolation at the Greville abscissae -- exact up to rounding
            if not t[k] < t[n]:
                raise InputError(f"the spline's domain [t[{k}], t[{n}]] is empty")
            tc = np.r_[[t[k]] * (k + 1), t[k + 1:n], [t[n]] * (k + 1)]
            xg = np.array([tc[i + 1:i + k + 1].mean() for i in range(n)])
            old = BSpline(t, c, k)
            new = make_interp_spline(xg, old(xg), k=k, t=tc, axis=0)
            return cls(new.c, tc, k, closed=False)
        return cls(c, t, k, closed=False)


# ------------------------------------------------------------------------------------------
# builders
# ------------------------------------------------------------------------------------------
def interpolate_bspline(points: ArrayLike, degree: int = 3, param: str | ArrayLike = "chord",
                        closed: bool = False) -> BSplineCurve:
    """B-spline curve of the given degree through ``points``.

    Parameters
    ----------
    points : array_like, shape (m, dim)
        Data points (no two consecutive equal). For ``closed=True`` the first point may be
        repeated last or not.
    degree : int
        ``>= 2``.
    param : {"uniform", "chord", "centripetal"} or array_like
        Parameterisation (:func:`curvefair.parameterize`); for closed curves one value per
        distinct point plus one for the closing point.
    closed : bool
        Periodic interpolation.

    Returns
    -------
    BSplineCurve
        Open cubic: natural end conditions (``r'' = 0``, as :func:`interpolate_cubic`), so it is
        the same curve; other open degrees: scipy's not-a-knot knot placement
        (``make_interp_spline(..., bc_type=None)``). Closed: knots at the data parameters.

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import interpolate_bspline
    >>> pts = np.c_[np.arange(6.0), np.sin(np.arange(6.0))]
    >>> c = interpolate_bspline(pts)
    >>> bool(np.allclose(c(c.knots[3]), pts[0]))
    True
    """
    from scipy.interpolate import make_interp_spline
    p = as_degree(degree)
    if closed:
        pts, t = closed_point_data(points, param)
        if pts.shape[0] < p + 1:
            raise InputError(f"a closed degree-{p} interpolant needs at least {p + 1} distinct "
                             f"points, got {pts.shape[0]}")
        loop = np.vstack([pts, pts[:1]])
        spl = make_interp_spline(t, loop, k=p, bc_type="periodic", axis=0)
        return BSplineCurve.from_scipy(spl, closed=True)
    # the coincident-points check of as_points in one compiled pass (numpy's temporaries cost
    # ~0.03 s at 1e6 points); on a hit as_points itself raises its usual message
    pts = as_points(points, "points", min_points=p + 1, allow_coincident=True)
    if first_coincident(pts) >= 0:
        as_points(pts, "points", min_points=p + 1)
    t = as_params(param, pts.shape[0], "param") if not isinstance(param, str) \
        else parameterize(pts, param)
    if p == 3 and pts.shape[0] >= 4:
        return _natural_cubic(t, pts)
    bc = "natural" if p == 3 else None
    spl = make_interp_spline(t, pts, k=p, bc_type=bc, axis=0)
    return BSplineCurve.from_scipy(spl, closed=False)


def _natural_cubic(u: FloatArray, pts: FloatArray) -> BSplineCurve:
    """Clamped cubic B-spline through ``pts`` at ``u`` (m >= 4) with ``r'' = 0`` at both ends:
    the tridiagonal system of the interior control points, solved for all coordinates at once
    by a compiled elimination (:func:`curvefair._kernels.bspline.natural_cubic_kernel`; LAPACK
    ``gbsv`` if a pivot were tiny), the same curve as ``make_interp_spline(u, pts, 3,
    bc_type="natural")`` in O(m).

    At a simple knot ``t_k`` the cubic B-splines are ``N_{k-3}(t_k) = (t_{k+1} - t_k)^2 /
    ((t_{k+1} - t_{k-1}) (t_{k+1} - t_{k-2}))``, ``N_{k-1}(t_k) = (t_k - t_{k-1})^2 /
    ((t_{k+1} - t_{k-1}) (t_{k+2} - t_{k-1}))`` and ``N_{k-2} = 1 - N_{k-3} - N_{k-1}``; the
    natural end rows are ``(d_2 - d_1) / (u_2 - u_0) = (d_1 - d_0) / (u_1 - u_0)`` and its
    mirror image (Piegl & Tiller, The NURBS Book, eq. (3.9) for the second derivative)."""
    m = u.shape[0]
    u = np.ascontiguousarray(u, dtype=float)
    pts = np.ascontiguousarray(pts, dtype=float)
    T = np.empty(m + 6)
    d = np.empty((m + 2, pts.shape[1]))
    if not natural_cubic_kernel(u, pts, T, d, np.empty(m)):
        d[1:-1] = _natural_cubic_gbsv(u, pts, T)
        d[0], d[-1] = pts[0], pts[-1]
    return BSplineCurve._trusted(d, T, 3, False)


def _natural_cubic_gbsv(u: FloatArray, pts: FloatArray, T: FloatArray) -> FloatArray:
    """The interior control points of :func:`_natural_cubic` by LAPACK ``gbsv`` (partial
    pivoting): the fallback of the compiled elimination."""
    from scipy.linalg import solve_banded

    m = u.shape[0]
    k = np.arange(4, m + 2)  # the interior data knots t_k = u_{k-3}, k = 4 .. m + 1
    tk = T[k]
    den = T[k + 1] - T[k - 1]
    lo_ = (T[k + 1] - tk) ** 2 / (den * (T[k + 1] - T[k - 2]))
    up_ = (tk - T[k - 1]) ** 2 / (den * (T[k + 2] - T[k - 1]))
    ab = np.zeros((3, m))  # unknowns d_1 .. d_m; ab[1 + i - j, j] = A[i, j]
    rhs = np.empty((m, pts.shape[1]))
    a0, b0 = 1.0 / (u[2] - u[0]), 1.0 / (u[1] - u[0])
    ab[1, 0], ab[0, 1] = -(a0 + b0), a0
    rhs[0] = -b0 * pts[0]
    rows = np.arange(1, m - 1)  # data j = 1 .. m - 2: d_j, d_{j+1}, d_{j+2}
    ab[2, rows - 1] = lo_
    ab[1, rows] = 1.0 - lo_ - up_
    ab[0, rows + 1] = up_
    rhs[1:m - 1] = pts[1:m - 1]
    a1, b1 = 1.0 / (u[-1] - u[-3]), 1.0 / (u[-1] - u[-2])
    ab[2, m - 2], ab[1, m - 1] = a1, -(a1 + b1)
    rhs[m - 1] = -b1 * pts[-1]
    return solve_banded((1, 1), ab, rhs, check_finite=False)


def _solve_normal(AtA: Any, rhs: FloatArray, n: int, p: int) -> FloatArray:
    """Solve the least-squares normal equations ``AtA x = rhs`` of :func:`fit_bspline` by a
    sparse LU factorisation; refuse a (numerically) singular system -- some control point not
    determined by the data -- by the ratio of the smallest to the largest pivot."""
    from scipy.sparse.linalg import splu

    try:
        lu = splu(AtA.tocsc())
    except RuntimeError:  # "Factor is exactly singular"
        piv = np.zeros(1)
    else:
        piv = np.abs(lu.U.diagonal())
    if not (piv.size and np.isfinite(piv).all() and piv.min() > 1e-12 * piv.max()):
        raise InputError(f"fit_bspline: the least-squares system for {n} control points of "
                         f"degree {p} is singular for these parameters (some control point is "
                         f"not determined by the data); use fewer control points")
    x = np.asarray(lu.solve(np.asarray(rhs)))
    return x.reshape(n, -1)


def fit_bspline(points: ArrayLike, n_ctrl: int, degree: int = 3,
                param: str | ArrayLike = "chord", closed: bool = False) -> BSplineCurve:
    """Least-squares B-spline curve with ``n_ctrl`` control points approximating ``points``.

    Parameters
    ----------
    points : array_like, shape (m, dim)
    n_ctrl : int
        Number of (distinct) control points; ``degree + 1 <= n_ctrl <= m``.
    degree : int
    param : as for :func:`interpolate_bspline`.
    closed : bool

    Returns
    -------
    BSplineCurve
        Minimises ``sum_q |r(u_q) - points_q|^2`` over all control points (plain least
        squares: the ends are not forced through the first and last data points). Open curves:
        knots by Piegl & Tiller's averaging rule (The NURBS Book, eq. (9.69)), so every span
        holds data; closed curves: period knots at equally spaced data indices.

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import fit_bspline
    >>> u = np.linspace(0, 3, 50)
    >>> c = fit_bspline(np.c_[u, u**2], 8, param=u)   # a parabola is reproduced exactly
    >>> c.n_ctrl, c(1.5).round(12).tolist()
    (8, [1.5, 2.25])
    """
    from scipy.interpolate import BSpline, make_lsq_spline
    p = as_degree(degree)
    if isinstance(n_ctrl, bool) or not isinstance(n_ctrl, (int, np.integer)):
        raise InputError(f"n_ctrl must be an integer, got {n_ctrl!r}")
    n = int(n_ctrl)
    if closed:
        pts, t = closed_point_data(points, param)
        m = pts.shape[0]
        if not p + 1 <= n <= m:
            raise InputError(f"n_ctrl must be in [degree + 1, number of distinct points] = "
                             f"[{p + 1}, {m}], got {n}")
        # period knots at equally spaced (fractional) data indices, on the periodic extension
        # of the parameters; for even degree shifted by half a step, so that with n == m the
        # data sit mid-span (odd degree: at the knots) -- the placement that keeps periodic
        # interpolation regular (de Boor, A Practical Guide to Splines, ch. XIII: at the knots
        # an even-degree uniform periodic collocation matrix is singular for even n)
        T = t[-1] - t[0]
        ext = np.r_[t, t[1:] + T]
        shift = 0.5 * (m / n) if p % 2 == 0 else 0.0
        period = np.interp(np.arange(n + 1) * (m / n) + shift, np.arange(2 * m + 1), ext)
        curve0 = BSplineCurve(np.zeros((n, pts.shape[1])), period, p, closed=True)
        full = np.array(curve0.knots)
        x = t[:-1]
        if shift:
            x = period[0] + np.mod(x - period[0], period[-1] - period[0])
            x = np.minimum(x, np.nextafter(period[-1], -np.inf))
        A = BSpline.design_matrix(x, full, p).tocoo()
        A = csr_matrix((A.data, (A.row, A.col % n)), shape=(m, n))
        AtA = (A.T @ A).tocsc()
        ctrl = _solve_normal(AtA, A.T @ pts, n, p)
        return BSplineCurve(ctrl, full, p, closed=True)
    pts = as_points(points, "points", min_points=p + 1)
    m = pts.shape[0]
    if not p + 1 <= n <= m:
        raise InputError(f"n_ctrl must be in [degree + 1, number of points] = [{p + 1}, {m}], "
                         f"got {n}")
    u = parameterize(pts, param)
    d = m / (n - p)
    j = np.arange(1, n - p)
    i = np.floor(j * d).astype(int)
    alpha = j * d - i
    inner = (1.0 - alpha) * u[i - 1] + alpha * u[i]
    knots = np.r_[[u[0]] * (p + 1), inner, [u[-1]] * (p + 1)]
    spl = make_lsq_spline(u, pts, knots, k=p, axis=0)
    return BSplineCurve.from_scipy(spl, closed=False)
