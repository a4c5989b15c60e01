"""Piecewise-polynomial form shared by every curve type.

Every curve in curvefair (cubic and quintic Hermite splines, B-splines) can hand out its
*local power form*: breakpoints ``t_0 < ... < t_m`` and coefficients ``a[i, j]`` with

    r(t) = sum_j a[i, j] (t - t_i)**j     for t_i <= t <= t_{i+1}

(seed 001 eq. (6), seed 000 eq. (2)). All exact analysis (energies, jumps, curvature
polynomials) works on this form, vectorised over segments.
"""

from __future__ import annotations

import abc
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property
from math import factorial

import numpy as np

from .._typing import ArrayLike, FloatArray
from .._validate import as_count, as_eval_params, check_fits
from ..errors import InputError

__all__ = ["PiecewisePolynomial", "PiecewiseCurve", "horner_rows", "readonly"]


def _frozen_buffer(arr: np.ndarray) -> bytes | None:
    """The immutable ``bytes`` object whose memory a read-only ``arr`` views, else None."""
    if arr.flags.writeable:
        return None
    base: object = arr
    while isinstance(base, np.ndarray):
        base = base.base
    return base if isinstance(base, bytes) else None


def _frozen(arr: np.ndarray) -> bool:
    """True if ``arr`` is read-only and its memory is an immutable ``bytes`` object."""
    return _frozen_buffer(arr) is not None


def shares_whole_frozen(arr: np.ndarray) -> bool:
    """True if ``arr`` is frozen (:func:`readonly`) and spans its whole ``bytes`` buffer."""
    buf = _frozen_buffer(arr)
    return buf is not None and arr.flags.c_contiguous and len(buf) == arr.nbytes


def readonly(arr: np.ndarray) -> np.ndarray:
    """A read-only array with the values of ``arr`` whose memory nobody can write.

    ``setflags(write=False)`` alone can be undone (``setflags(write=True)`` on an array that
    owns its data), which would make an immutable curve mutable and its cached evaluation
    stale. The returned array is a view of an immutable ``bytes`` object: numpy refuses
    ``setflags(write=True)`` on it and on every view of it. An array already like that is
    returned as it is; otherwise this costs one copy. Use the returned array, not ``arr``.
    """
    if _frozen(arr):
        return arr
    a = arr if isinstance(arr, np.ndarray) else np.asarray(arr)
    # tobytes() copies any layout into C order: one copy, also for a strided view
    return np.frombuffer(a.tobytes(), dtype=a.dtype).reshape(a.shape)


def horner_rows(rows: FloatArray, s: FloatArray, nu: int) -> FloatArray:
    """``nu``-th derivative of the power-form rows ``rows`` (shape ``(k, p+1, dim)``) at local
    offsets ``s`` (shape ``(k, 1)``), one row each: Horner's rule, shape ``(k, dim)``."""
    c = derivative_coefficients(rows, nu)
    out = c[:, -1, :].copy()
    for j in range(c.shape[1] - 2, -1, -1):
        out *= s
        out += c[:, j, :]
    return out


def derivative_coefficients(coeffs: FloatArray, nu: int) -> FloatArray:
    """Coefficients of the ``nu``-th derivative in the same local power basis.

    ``coeffs`` has shape ``(m, p+1, dim)``; the result has shape ``(m, max(p+1-nu, 1), dim)``.
    """
    p1 = coeffs.shape[1]
    if nu == 0:
        return coeffs
    if nu >= p1:
        return np.zeros((coeffs.shape[0], 1, coeffs.shape[2]))
    j = np.arange(nu, p1)
    fac = np.array([factorial(int(k)) // factorial(int(k - nu)) for k in j], dtype=float)
    return coeffs[:, nu:, :] * fac[None, :, None]


@dataclass(frozen=True, eq=False)
class PiecewisePolynomial:
    """Local power form of a piecewise-polynomial curve.

    Attributes
    ----------
    breaks : ndarray, shape (m+1,)
        Strictly increasing breakpoints.
    coeffs : ndarray, shape (m, p+1, dim)
        ``coeffs[i, j]`` multiplies ``(t - breaks[i])**j`` on segment ``i``.
    evaluator : callable or None
        ``evaluator(seg, s, nu)`` -> ``(k, dim)``: the ``nu``-th derivative on segments ``seg``
        (int, shape ``(k,)``) at local offsets ``s = t - breaks[seg]``, computed from the
        curve's own representation. Set by curves of high degree, where the power form is
        ill-conditioned: summing ``c_j s**j`` loses about ``eps * sum_j |c_j| s**j`` while the
        curve is only of size ``|r(t)|``; for a single Bezier span of degree ``p`` the ratio
        grows like ``2**p`` times the binomials (about 1e-6 relative at degree 25, measured
        against exact rational evaluation). :meth:`evaluate`, :meth:`evaluate_local`,
        :meth:`segment_values` and :meth:`at` use it when set; ``coeffs`` stay the Taylor
        coefficients for the exact polynomial analysis.
    """

    breaks: FloatArray
    coeffs: FloatArray
    evaluator: Callable[[np.ndarray, FloatArray, int], FloatArray] | None = field(
        default=None, compare=False, repr=False)

    def __post_init__(self) -> None:
        # immutable like the curves: float64 arrays in memory nobody can write (readonly)
        for name in ("breaks", "coeffs"):
            a = getattr(self, name)
            if not (isinstance(a, np.ndarray) and a.dtype == np.float64):
                a = np.asarray(a, dtype=np.float64)
            object.__setattr__(self, name, readonly(a))

    @classmethod
    def _borrowed(cls, breaks: FloatArray, coeffs: FloatArray) -> PiecewisePolynomial:
        """A power form over float64 arrays the caller has just made and never writes again,
        marked read-only but not copied into frozen memory: for internal temporaries that are
        never handed to a user (the difference curves of fair()'s tolerance checks; at 1e7
        cubic pieces the frozen copy of the coefficients alone is 640 MB of fresh memory)."""
        obj = cls.__new__(cls)
        for name, a in (("breaks", breaks), ("coeffs", coeffs)):
            a = np.asarray(a, dtype=np.float64)
            if a.flags.writeable:
                a = a.view()
                a.flags.writeable = False
            object.__setattr__(obj, name, a)
        object.__setattr__(obj, "evaluator", None)
        return obj

    @property
    def degree(self) -> int:
        return self.coeffs.shape[1] - 1

    @property
    def dim(self) -> int:
        return self.coeffs.shape[2]

    @property
    def n_segments(self) -> int:
        return self.coeffs.shape[0]

    @property
    def widths(self) -> FloatArray:
        return np.diff(self.breaks)

    def segment_of(self, u: FloatArray) -> np.ndarray:
        """Index of the segment containing each parameter (right-continuous, last segment
        closed)."""
        i = np.searchsorted(self.breaks, u, side="right") - 1
        return np.clip(i, 0, self.n_segments - 1)

    def evaluate(self, u: ArrayLike, nu: int = 0, segment: np.ndarray | None = None) -> FloatArray:
        """Value (``nu=0``) or ``nu``-th derivative at parameters ``u``; shape ``u.shape + (dim,)``.

        ``segment`` forces the segment used (e.g. the left limit at a breakpoint).
        """
        u = np.asarray(u, dtype=float)
        shape = u.shape
        uf = u.reshape(-1)
        seg = self.segment_of(uf) if segment is None else np.asarray(segment).reshape(-1)
        if self.evaluator is not None:
            seg = np.broadcast_to(seg, uf.shape)
            return self.at(seg, uf - self.breaks[seg], nu).reshape(shape + (self.dim,))
        s = (uf - self.breaks[seg])[:, None]
        if seg.shape[0] < self.n_segments:
            # fewer parameters than segments (a few knots of a long curve): the derivative
            # coefficients of the segments asked for only (the same products, O(k) not O(m))
            return horner_rows(self.coeffs[seg], s, nu).reshape(shape + (self.dim,))
        c = derivative_coefficients(self.coeffs, nu)
        out = c[seg, -1, :].copy()
        for j in range(c.shape[1] - 2, -1, -1):
            out *= s
            out += c[seg, j, :]
        return out.reshape(shape + (self.dim,))

    def at(self, seg: np.ndarray, s: FloatArray, nu: int = 0) -> FloatArray:
        """``nu``-th derivative on segments ``seg`` (shape ``(k,)``) at local offsets ``s``
        (shape ``(k,)``): ``(k, dim)``. Uses :attr:`evaluator` when set, else Horner's rule on
        the power form."""
        seg = np.asarray(seg).reshape(-1)
        s = np.asarray(s, dtype=float).reshape(-1)
        if self.evaluator is not None:
            if nu > self.degree:
                return np.zeros((s.shape[0], self.dim))
            return self.evaluator(seg, s, int(nu))
        c = (derivative_coefficients(self.coeffs[seg], nu) if seg.shape[0] < self.n_segments
             else derivative_coefficients(self.coeffs, nu)[seg])
        out = c[:, -1, :].copy()
        for j in range(c.shape[1] - 2, -1, -1):
            out *= s[:, None]
            out += c[:, j, :]
        return out

    def evaluate_local(self, s: FloatArray, nu: int = 0) -> FloatArray:
        """Evaluate every segment at local offsets ``s`` (shape ``(k,)``): result
        ``(m, k, dim)``."""
        s = np.asarray(s, dtype=float)
        if self.evaluator is not None:
            m, k = self.n_segments, s.shape[0]
            seg = np.repeat(np.arange(m), k)
            return self.at(seg, np.tile(s, m), nu).reshape(m, k, self.dim)
        c = derivative_coefficients(self.coeffs, nu)
        out = np.broadcast_to(c[:, -1:, :], (c.shape[0], s.shape[0], c.shape[2])).copy()
        for j in range(c.shape[1] - 2, -1, -1):
            out *= s[None, :, None]
            out += c[:, j : j + 1, :]
        return out

    def segment_values(self, frac: FloatArray, nu: int = 0) -> FloatArray:
        """Evaluate segment ``i`` at ``breaks[i] + frac * width_i`` for each ``frac``:
        ``(m, k, dim)``."""
        s = self.widths[:, None] * np.asarray(frac, dtype=float)[None, :]
        if self.evaluator is not None:
            m, k = s.shape
            seg = np.repeat(np.arange(m), k)
            return self.at(seg, s.reshape(-1), nu).reshape(m, k, self.dim)
        c = derivative_coefficients(self.coeffs, nu)
        out = np.repeat(c[:, -1:, :], s.shape[1], axis=1)
        for j in range(c.shape[1] - 2, -1, -1):
            out *= s[:, :, None]
            out += c[:, j : j + 1, :]
        return out


class PiecewiseCurve(abc.ABC):
    """Base of every curvefair curve: immutable, parametric, piecewise polynomial.

    Subclasses provide :meth:`_make_piecewise`; evaluation and all analysis go through
    :attr:`piecewise`.
    """

    degree: int

    @property
    @abc.abstractmethod
    def dim(self) -> int:
        """Space dimension, 2 or 3."""

    @property
    @abc.abstractmethod
    def closed(self) -> bool:
        """True for a closed (periodic) curve."""

    @abc.abstractmethod
    def _make_piecewise(self) -> PiecewisePolynomial: ...

    def __setstate__(self, state: dict[str, object]) -> None:
        """Unpickling / deep copies: the arrays come back writeable, so freeze them again
        (:func:`readonly`) and drop the caches (rebuilt on demand)."""
        st = {}
        for k, v in state.items():
            if k in ("piecewise", "spans"):
                continue
            if k == "_gram_cache":
                v = {}
            elif isinstance(v, np.ndarray):
                v = readonly(v)
            elif isinstance(v, list):
                v = [readonly(x) if isinstance(x, np.ndarray) else x for x in v]
            st[k] = v
        self.__dict__.update(st)

    def _repr_html_(self) -> str:
        """Notebook display: a small inline SVG with the comb (:func:`curvefair.view.curve_svg`)."""
        from ..view import curve_repr_html

        return curve_repr_html(self)

    @cached_property
    def piecewise(self) -> PiecewisePolynomial:
        """The local power form (cached; the curve is immutable; refused if it overflows)."""
        pp = self._make_piecewise()
        coeffs = pp.coeffs
        if not np.isfinite(coeffs).all():
            i = int(np.flatnonzero(~np.isfinite(coeffs).all(axis=(1, 2)))[0])
            w = float(pp.breaks[i + 1] - pp.breaks[i])
            raise InputError(
                f"the power form of this degree-{self.degree} curve overflows float64 on segment "
                f"{i} (parameter width {w!r}): coordinates divided by the width to the power "
                f"{self.degree} leave the float64 range; rescale the parameters (knots) or the "
                f"coordinates")
        return pp

    @property
    def domain(self) -> tuple[float, float]:
        """``(t_start, t_end)`` of the parameter range."""
        b = self.piecewise.breaks
        return float(b[0]), float(b[-1])

    @property
    def max_derivative(self) -> int:
        return self.degree

    def __call__(self, u: ArrayLike, nu: int = 0) -> FloatArray:
        """Evaluate the curve (``nu=0``) or its ``nu``-th derivative at parameters ``u``.

        Parameters
        ----------
        u : float or array_like
            Parameters in :attr:`domain`. Closed curves wrap around periodically; on an open
            curve a parameter outside the domain raises :class:`~curvefair.errors.InputError`.
        nu : int
            Derivative order, ``0 <= nu <= degree``.

        Returns
        -------
        ndarray, shape ``np.shape(u) + (dim,)``
        """
        if (isinstance(nu, bool) or not isinstance(nu, (int, np.integer)) or nu < 0
                or nu > self.max_derivative):
            raise InputError(f"nu must be an integer in [0, {self.max_derivative}], got {nu!r}")
        return self._evaluate(self._in_domain(as_eval_params(u, "u")), int(nu))

    def _in_domain(self, u: FloatArray) -> FloatArray:
        """Parameters as :meth:`__call__` evaluates them: a closed curve's wrapped around
        periodically, an open one's clipped to the domain (farther out than rounding:
        :class:`~curvefair.errors.InputError`)."""
        t0, t1 = self.domain
        if self.closed:
            return t0 + np.mod(u - t0, t1 - t0)
        slack = 1e-12 * (t1 - t0)
        bad = (u < t0 - slack) | (u > t1 + slack)
        if np.any(bad):
            v = u.reshape(-1)[np.flatnonzero(bad.reshape(-1))[0]]
            raise InputError(f"u = {v!r} is outside the curve's domain [{t0!r}, {t1!r}]")
        return np.clip(u, t0, t1)

    def _evaluate(self, u: FloatArray, nu: int) -> FloatArray:
        """:meth:`__call__` on parameters already in the domain. A few parameters of a long
        curve whose power form is not built yet are evaluated from their segments' forms only
        (:meth:`_partial_form`): each segment's coefficients depend on its own data, so the
        values are bitwise those of the whole form, without its 72 bytes per segment of a
        planar cubic for one point (:func:`curvefair.fair` evaluates its input at the
        certificate's parameter after dropping the form it built)."""
        if "piecewise" not in self.__dict__ and u.size <= 64:
            uf = u.reshape(-1)
            part = self._partial_form(uf)
            if part is not None:
                rows, local = part
                return horner_rows(rows, local[:, None], nu).reshape(u.shape + (self.dim,))
        return self.piecewise.evaluate(u, nu)

    def _partial_form(self, u: FloatArray) -> tuple[FloatArray, FloatArray] | None:
        """The power-form rows of the segments holding ``u`` (as the whole form's
        :meth:`PiecewisePolynomial.segment_of` chooses them) and the local offsets, or None
        (build the whole form)."""
        return None

    def sample(self, n: int = 200) -> FloatArray:
        """``n`` points at equally spaced parameters over the domain, shape ``(n, dim)``
        (``n >= 0`` an integer)."""
        m = as_count(n, "n", minimum=0)
        # the parameters, the points and the evaluation's temporaries: about 4 arrays of (m, dim)
        check_fits(32.0 * m * (self.dim + 1), f"sample({m})")
        t0, t1 = self.domain
        return self(np.linspace(t0, t1, m))
