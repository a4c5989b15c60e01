"""Parametric Hermite splines: C1 cubic (seed 001) and C2 quintic (seed 000).

Indices are 0-based here; the papers number points from 1 (paper's ``P_k`` is our ``points[k-1]``).
"""

from __future__ import annotations

from typing import Any, cast

import numpy as np

from .._kernels.hermite_power import (
    cubic_power_kernel,
    cubic_power_rows,
    quintic_power_kernel,
    quintic_power_rows,
)
from .._typing import ArrayLike, FloatArray
from .._validate import as_params, as_points, as_vectors, magnitude
from ..errors import InputError
from .piecewise import (
    PiecewiseCurve,
    PiecewisePolynomial,
    _frozen,
    readonly,
    shares_whole_frozen,
)

__all__ = ["CubicHermite", "QuinticHermite", "HermiteSpline"]


def _check_closed(name: str, arrs: list[tuple[str, FloatArray]]) -> list[FloatArray]:
    """The arrays with the last row exactly the first (a copy where it was only within
    ``1e-10`` of the size: the caller's arrays are never written)."""
    out = []
    for label, a in arrs:
        scale = magnitude(a)
        if not np.allclose(a[0], a[-1], rtol=0.0, atol=1e-10 * scale):
            raise InputError(
                f"closed {name}: {label}[0] = {a[0].tolist()} must equal {label}[-1] = "
                f"{a[-1].tolist()} (a closed curve repeats its first point last)"
            )
        if a[-1].tobytes() != a[0].tobytes():  # (bitwise: a -0.0 becomes row 0's 0.0)
            a = a.copy()
            a[-1] = a[0]
        out.append(a)
    return out



def _own(arr: FloatArray) -> FloatArray:
    """The curve's read-only copy of ``arr``; none when ``arr`` is already the whole of a
    frozen buffer (another curve's array: immutable, so it can be shared). A frozen part of a
    larger buffer is copied, so that a curve never keeps a larger one alive."""
    if shares_whole_frozen(arr):
        return arr
    # readonly() returns any frozen array as it is: a frozen part is copied first
    return readonly(np.array(arr) if _frozen(arr) else arr)

class HermiteSpline(PiecewiseCurve):
    """Common machinery of :class:`CubicHermite` and :class:`QuinticHermite`.

    Data are held per point: ``points`` and the derivative arrays (``_derivs``), ``params``.
    A closed curve repeats its first point (and derivatives) as the last one; its distinct data
    points are ``0 .. n-2``.
    """

    _deriv_names: tuple[str, ...] = ()

    def _init(self, points: ArrayLike, derivs: list[ArrayLike], params: ArrayLike,
              closed: bool, _valid: tuple[bool, bool] = (False, False)) -> None:
        # ``_valid`` (internal): ``points`` is already a float64 array that as_points(...,
        # min_points=2) accepted, and ``params`` one that as_params accepted
        # (interpolate_cubic's): not validated again
        # validated where they are (no copy of a float64 array): readonly() below makes the
        # curve's one copy, or none of an array already frozen (another curve's)
        pts = (cast(FloatArray, points) if _valid[0]
               else as_points(points, "points", min_points=2, copy=False))
        n, dim = pts.shape
        ders = [as_vectors(d, (n, dim), name, copy=False)
                for d, name in zip(derivs, self._deriv_names, strict=True)]
        t = (cast(FloatArray, params) if _valid[1]
             else as_params(params, n, "params", copy=False))
        closed = bool(closed)
        if closed:
            if n < 3:
                raise InputError("a closed curve needs at least 3 points (first repeated last), "
                                 f"got {n}")
            pts, *ders = _check_closed(
                type(self).__name__,
                [("points", pts)] + list(zip(self._deriv_names, ders, strict=True)))
        self._points = _own(pts)
        self._derivs = [_own(d) for d in ders]
        self._params = _own(t)
        self._closed = closed

    # -- data -------------------------------------------------------------------------------
    @property
    def points(self) -> FloatArray:
        """Data points, shape ``(n, dim)`` (read-only)."""
        return self._points

    @property
    def params(self) -> FloatArray:
        """Parameter values ``t_i``, shape ``(n,)`` (read-only)."""
        return self._params

    @property
    def domain(self) -> tuple[float, float]:
        """``(t_start, t_end)``: the first and last parameter (no power form needed)."""
        return float(self._params[0]), float(self._params[-1])

    @property
    def dim(self) -> int:
        return int(self._points.shape[1])

    def _rows(self, lo: int, hi: int) -> FloatArray:
        """The power form's coefficients of the segments between points ``lo .. hi-1``."""
        raise NotImplementedError

    def _make_piecewise(self) -> PiecewisePolynomial:
        return PiecewisePolynomial(np.array(self._params), self._rows(0, len(self._params)))

    def span_coefficients(self, which: ArrayLike) -> FloatArray:
        """The power-form coefficients of the segments ``which`` (0-based, any order, repeats
        allowed): shape ``(k, degree + 1, dim)``, bit for bit the rows
        ``piecewise.coeffs[which]`` (each segment's coefficients come from its own two points
        by the same compiled code), without building the whole form."""
        idx = np.ascontiguousarray(np.asarray(which, dtype=np.int64).reshape(-1))
        m = self._params.shape[0] - 1
        if idx.size and (int(idx.min()) < 0 or int(idx.max()) >= m):
            raise InputError(f"span_coefficients: segment indices must lie in 0 .. {m - 1}")
        return self._segment_rows(idx)

    def _segment_rows(self, idx: np.ndarray) -> FloatArray:
        raise NotImplementedError

    def _partial_form(self, u: FloatArray) -> tuple[FloatArray, FloatArray] | None:
        """The coefficients of the segments holding ``u``, each from its own two points (as
        the whole form computes them), and the local offsets; None for a short curve."""
        t = self._params
        m = t.shape[0] - 1
        if 64 * u.size >= m:
            return None
        seg = np.clip(np.searchsorted(t, u, side="right") - 1, 0, m - 1)
        return self._segment_rows(np.ascontiguousarray(seg, dtype=np.int64)), u - t[seg]

    @property
    def closed(self) -> bool:
        return self._closed

    @property
    def n_points(self) -> int:
        """Number of stored data points (a closed curve counts its repeated first point twice)."""
        return int(self._points.shape[0])

    def __len__(self) -> int:
        return self.n_points

    def __repr__(self) -> str:
        return (f"{type(self).__name__}(n={self.n_points}, dim={self.dim}, "
                f"closed={self.closed}, domain={self.domain})")

    def replace(self, **changes: Any) -> "HermiteSpline":
        """A new curve with some data replaced (``points=``, derivative arrays, ``params=``)."""
        kw: dict[str, Any] = {"points": self._points, "params": self._params,
                              "closed": self._closed}
        kw.update(dict(zip(self._deriv_names, self._derivs, strict=True)))
        unknown = set(changes) - set(kw)
        if unknown:
            raise InputError(f"replace() got unknown fields {sorted(unknown)}; valid: {sorted(kw)}")
        kw.update(changes)
        return type(self)(**kw)

    def coefficients(self) -> FloatArray:
        """Per-segment power coefficients ``a[i, j]``, shape ``(n-1, degree+1, dim)``.

        ``r(t) = sum_j a[i, j] (t - t_i)**j`` on ``[t_i, t_{i+1}]`` (seed 001 eq. (6) for
        cubics, seed 000 eq. (2) for quintics). Returns a copy.
        """
        return np.array(self.piecewise.coeffs)


class CubicHermite(HermiteSpline):
    """C1 parametric cubic Hermite spline through ``points`` with ``tangents`` at ``params``.

    Parameters
    ----------
    points : array_like, shape (n, dim)
        Data points ``r_i``, dim 2 or 3.
    tangents : array_like, shape (n, dim)
        First derivatives ``r'_i`` with respect to the parameter.
    params : array_like, shape (n,)
        Strictly increasing parameters ``t_i``.
    closed : bool
        Closed curve: ``points[-1]`` must repeat ``points[0]`` (and the tangents too).

    Notes
    -----
    On segment ``i`` with ``D_i = t_{i+1} - t_i`` (Wang & Cao 2006, eq. (6)):

    ``a_{i,0} = r_i``, ``a_{i,1} = r'_i``,
    ``a_{i,2} = 3 (r_{i+1} - r_i) / D_i^2 - (2 r'_i + r'_{i+1}) / D_i``,
    ``a_{i,3} = 2 (r_i - r_{i+1}) / D_i^3 + (r'_i + r'_{i+1}) / D_i^2``.

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import CubicHermite
    >>> c = CubicHermite([[0, 0], [1, 1]], [[1, 0], [1, 0]], [0.0, 1.0])
    >>> c(0.5).round(3).tolist()
    [0.5, 0.5]
    """

    degree = 3
    _deriv_names = ("tangents",)
    #: set by :func:`curvefair.interpolate_cubic` on the chord-length natural (periodic) cubic
    #: it makes, the curve a point file is read as (``fair()``'s guard then need not rebuild
    #: it to recognise it); never set on a curve made any other way
    _chord_natural: bool = False

    def __init__(self, points: ArrayLike, tangents: ArrayLike, params: ArrayLike,
                 closed: bool = False) -> None:
        self._init(points, [tangents], params, closed)

    @property
    def tangents(self) -> FloatArray:
        """First derivatives ``r'_i``, shape ``(n, dim)`` (read-only)."""
        return self._derivs[0]

    def _rows(self, lo: int, hi: int) -> FloatArray:
        return cubic_hermite_coefficients(self._points[lo:hi], self.tangents[lo:hi],
                                          self._params[lo:hi])

    def _segment_rows(self, idx: np.ndarray) -> FloatArray:
        out = np.empty((idx.shape[0], 4, self.dim))
        cubic_power_rows(self._points, self.tangents, self._params, idx, out)
        return out


class QuinticHermite(HermiteSpline):
    """C2 parametric quintic Hermite spline (position, first and second derivative per point).

    Parameters
    ----------
    points, d1, d2 : array_like, shape (n, dim)
        ``r_i``, ``r'_i``, ``r''_i``.
    params : array_like, shape (n,)
        Strictly increasing parameters.
    closed : bool
        As for :class:`CubicHermite`.

    Notes
    -----
    Wang 2005, eq. (2): with ``b1 = r_{i+1} - r_i - r'_i D - r''_i D^2/2``,
    ``b2 = r'_{i+1} - r'_i - r''_i D``, ``b3 = r''_{i+1} - r''_i``:
    ``a_{i,3} = (10 b1 - 4 b2 D + b3 D^2/2) / D^3``,
    ``a_{i,4} = (-15 b1 + 7 b2 D - b3 D^2) / D^4``,
    ``a_{i,5} = (6 b1 - 3 b2 D + b3 D^2/2) / D^5``.

    Examples
    --------
    >>> from curvefair import QuinticHermite
    >>> q = QuinticHermite([[0, 0], [1, 0]], [[1, 0], [1, 0]], [[0, 0], [0, 0]], [0, 1])
    >>> q(0.25).tolist()
    [0.25, 0.0]
    """

    degree = 5
    _deriv_names = ("d1", "d2")

    def __init__(self, points: ArrayLike, d1: ArrayLike, d2: ArrayLike, params: ArrayLike,
                 closed: bool = False) -> None:
        self._init(points, [d1, d2], params, closed)

    @property
    def d1(self) -> FloatArray:
        """First derivatives, shape ``(n, dim)`` (read-only)."""
        return self._derivs[0]

    @property
    def d2(self) -> FloatArray:
        """Second derivatives, shape ``(n, dim)`` (read-only)."""
        return self._derivs[1]

    @property
    def tangents(self) -> FloatArray:
        """Alias of :attr:`d1`."""
        return self._derivs[0]

    def _rows(self, lo: int, hi: int) -> FloatArray:
        return quintic_hermite_coefficients(self._points[lo:hi], self.d1[lo:hi], self.d2[lo:hi],
                                            self._params[lo:hi])

    def _segment_rows(self, idx: np.ndarray) -> FloatArray:
        out = np.empty((idx.shape[0], 6, self.dim))
        quintic_power_rows(self._points, self.d1, self.d2, self._params, idx, out)
        return out


def _c64(a: ArrayLike) -> FloatArray:
    return np.ascontiguousarray(a, dtype=np.float64)


def cubic_hermite_coefficients(p: FloatArray, m: FloatArray, t: FloatArray) -> FloatArray:
    """Seed 001 eq. (6): ``(n-1, 4, dim)`` (:class:`CubicHermite`'s Notes), one compiled
    pass (:func:`curvefair._kernels.hermite_power.cubic_power_kernel`)."""
    p, m, t = _c64(p), _c64(m), _c64(t)
    c = np.empty((max(p.shape[0] - 1, 0), 4, p.shape[1]))
    cubic_power_kernel(p, m, t, c)
    return c


def quintic_hermite_coefficients(p: FloatArray, m: FloatArray, s: FloatArray,
                                 t: FloatArray) -> FloatArray:
    """Seed 000 eq. (2): ``(n-1, 6, dim)`` (:class:`QuinticHermite`'s Notes), one compiled
    pass (:func:`curvefair._kernels.hermite_power.quintic_power_kernel`)."""
    p, m, s, t = _c64(p), _c64(m), _c64(s), _c64(t)
    c = np.empty((max(p.shape[0] - 1, 0), 6, p.shape[1]))
    quintic_power_kernel(p, m, s, t, c)
    return c
