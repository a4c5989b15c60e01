"""Curves from scipy's spline objects: :func:`as_curve`.

:func:`curvefair.fair`, :func:`curvefair.analyze` and the plotting functions pass their curve
argument through :func:`as_curve`, so a notebook user can hand them what scipy built:

* :class:`scipy.interpolate.BSpline` with coefficients ``(n, dim)`` (``make_interp_spline``,
  ``make_splprep``'s spline) -> :class:`~curvefair.BSplineCurve` by
  :meth:`BSplineCurve.from_scipy <curvefair.BSplineCurve.from_scipy>` (same knots and
  coefficients: exact).
* ``make_splprep``'s result ``(BSpline, u)`` and ``splprep``'s ``(tck, u)``, a tck tuple
  ``(t, c, k)`` with ``c`` a list of ``dim`` coefficient arrays (``splprep``) or an ``(n, dim)``
  array -> the same B-spline (FITPACK's trailing padding coefficients, ``len(t) - k - 1`` and
  beyond, are dropped: they multiply no basis function).
* :class:`~scipy.interpolate.PPoly` (:class:`~scipy.interpolate.CubicSpline`,
  :class:`~scipy.interpolate.CubicHermiteSpline`, ``PchipInterpolator``,
  ``Akima1DInterpolator``, ``make_interp_spline(...).to_ppoly()`` ...) and
  :class:`~scipy.interpolate.BPoly` (converted with ``PPoly.from_bernstein_basis``) with values
  of shape ``(dim,)``: a C1 cubic -> :class:`~curvefair.CubicHermite` with ``points = p(x_i)``,
  ``tangents = p'(x_i)``, ``params = x_i`` (a cubic is fixed by its end values and end
  derivatives, so the conversion is exact); a C2 quintic -> :class:`~curvefair.QuinticHermite`
  likewise with ``p''``; any other degree or smoothness -> a B-spline on the breakpoints, each
  interior one repeated ``degree - c`` times where the polynomial is ``C^c`` there
  (interpolation at the Greville abscissae in that space: exact up to rounding).
* Scalar (1-D valued) splines ``y = f(x)`` of any of these kinds are taken as the planar graph
  curve ``(x, f(x))``: exact, since ``x`` itself lies in every spline space of degree >= 1
  (B-splines: its control values are the Greville abscissae, de Boor, *A Practical Guide to
  Splines*, ch. IX; power form: ``x = x_i + (x - x_i)``).

A curvefair curve is returned as it is; anything else raises :class:`~curvefair.InputError`.
The conversion is checked: the result is evaluated at the breakpoints and segment midpoints and
compared with scipy's own evaluation (relative ``1e-9`` of the curve's size), so a failed
conversion is an error, never a silently different curve.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .curves.piecewise import PiecewiseCurve
from .errors import InputError

__all__ = ["as_curve"]

_CHECK_RTOL = 1e-9


def as_curve(obj: Any, name: str = "curve", *, closed: bool | None = None) -> PiecewiseCurve:
    """``obj`` as a curvefair curve (see the module docstring for what is accepted).

    Parameters
    ----------
    obj : curvefair curve, scipy spline object, tck tuple or ``(spline, u)`` pair
    name : str
        The argument's name in error messages.
    closed : bool, optional
        For B-splines: passed to :meth:`BSplineCurve.from_scipy` (default: detect a periodic
        spline). For piecewise polynomials: ``None`` detects a closed curve (end values and
        derivatives up to ``degree - 1`` equal to ``1e-12`` of the size, e.g. ``CubicSpline``
        with ``bc_type="periodic"``).

    Returns
    -------
    PiecewiseCurve

    Examples
    --------
    >>> import numpy as np
    >>> from scipy.interpolate import CubicSpline
    >>> from curvefair import as_curve
    >>> t = np.linspace(0, 1, 6)
    >>> cs = CubicSpline(t, np.c_[t, np.sin(3 * t)])
    >>> c = as_curve(cs)
    >>> type(c).__name__, bool(np.allclose(c(0.37), cs(0.37), rtol=0, atol=1e-14))
    ('CubicHermite', True)
    """
    if isinstance(obj, PiecewiseCurve):
        return obj
    try:
        from scipy import interpolate as si
    except ImportError:  # pragma: no cover - scipy is a dependency
        si = None
    if si is None:
        raise InputError(f"{name} must be a curvefair curve, got {type(obj).__name__}")
    if isinstance(obj, si.BSpline):
        return _from_bspline(obj, name, closed)
    if isinstance(obj, si.BPoly):
        return _from_ppoly(si.PPoly.from_bernstein_basis(obj), name, closed)
    if isinstance(obj, si.PPoly):
        return _from_ppoly(obj, name, closed)
    if isinstance(obj, (tuple, list)):
        # make_splprep: (BSpline, u); splprep: ((t, c, k), u) or ([t, c, k], u)
        if len(obj) == 2 and isinstance(obj[0], si.BSpline):
            return _from_bspline(obj[0], name, closed)
        if len(obj) == 2 and isinstance(obj[0], (tuple, list)) and len(obj[0]) == 3:
            return _from_tck(obj[0], f"{name}[0]", closed)
        if len(obj) == 3:
            return _from_tck(obj, name, closed)
    raise InputError(
        f"{name} must be a curvefair curve or a scipy spline (BSpline, a tck tuple (t, c, k), "
        f"splprep/make_splprep's result, CubicSpline, PPoly, BPoly), got {type(obj).__name__}")


def _scale(values: np.ndarray) -> float:
    v = values[np.isfinite(values)]
    return float(np.max(np.abs(v))) if v.size else 0.0


def _check(curve: PiecewiseCurve, reference: Any, u: np.ndarray, name: str) -> PiecewiseCurve:
    """The converted curve evaluates as scipy's object does (else an InputError)."""
    ref = np.asarray(reference(u), dtype=float)
    got = curve(u)
    size = max(_scale(ref), 1e-300)
    err = float(np.max(np.abs(got - ref))) if ref.size else 0.0
    if not np.isfinite(err) or err > _CHECK_RTOL * size:
        raise InputError(f"{name}: the converted curve differs from scipy's evaluation by "
                         f"{err:.3g} (size {size:.3g}); it cannot be represented exactly")
    return curve


def _graph_bspline(t: np.ndarray, c: np.ndarray, k: int) -> np.ndarray:
    """Control points of the graph ``(x, f(x))``: x's coefficients are the Greville abscissae."""
    n = c.shape[0]
    xg = np.array([t[i + 1:i + k + 1].mean() for i in range(n)]) if k >= 1 else t[:n]
    return np.column_stack([xg, c])


def _from_bspline(spl: Any, name: str, closed: bool | None) -> PiecewiseCurve:
    from scipy.interpolate import BSpline

    from .curves.bspline import BSplineCurve

    t = np.asarray(spl.t, dtype=float)
    k = int(spl.k)
    c = np.asarray(spl.c, dtype=float)
    n = t.shape[0] - k - 1
    axis = int(getattr(spl, "axis", 0))
    if axis != 0 and c.ndim == 2:  # make_splprep: values come out as (dim, m)
        f = spl
        spl = BSpline(t, c, k, extrapolate=spl.extrapolate)
        ref0 = lambda u, f=f: np.moveaxis(np.asarray(f(u), dtype=float), axis, 0)  # noqa: E731
    else:
        ref0 = spl
    if c.ndim == 1:
        if k < 1:
            raise InputError(f"{name}: a scalar spline of degree 0 is not a curve")
        c2 = _graph_bspline(t, c[:n], k)
        spl2 = BSpline(t, c2, k, extrapolate=spl.extrapolate)
        ref = _graph_reference(spl)
    elif c.ndim == 2 and c.shape[1] in (2, 3):
        spl2, ref = spl, ref0
    else:
        raise InputError(f"{name}: the spline's coefficients have shape {c.shape}; a curve "
                         "needs (n, 2) or (n, 3) (or (n,) for a graph y = f(x))")
    try:
        curve = BSplineCurve.from_scipy(spl2, closed=closed)
    except InputError as exc:
        raise InputError(f"{name}: {exc}") from None
    lo, hi = float(t[k]), float(t[n])
    br = np.unique(t[k:n + 1])
    u = np.unique(np.concatenate([br, 0.5 * (br[:-1] + br[1:])]))
    u = u[(u >= lo) & (u <= hi)]
    return _check(curve, ref, u, name)


def _graph_reference(f: Any) -> Any:
    return lambda u: np.column_stack([u, np.asarray(f(u), dtype=float).reshape(len(u))])


def _from_tck(tck: Any, name: str, closed: bool | None) -> PiecewiseCurve:
    from scipy.interpolate import BSpline

    try:
        t, c, k = tck
        t = np.asarray(t, dtype=float)
        k = int(k)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a tck tuple (t, c, k)") from None
    if t.ndim != 1 or k < 0 or t.shape[0] < 2 * (k + 1):
        raise InputError(f"{name}: a tck tuple needs a knot vector of at least 2 (k + 1) = "
                         f"{2 * (k + 1)} knots, got shape {t.shape}")
    n = t.shape[0] - k - 1
    if isinstance(c, (list, tuple)) and c and np.ndim(c[0]) == 1:
        arrs = [np.asarray(ci, dtype=float).reshape(-1) for ci in c]
        if any(a.shape[0] < n for a in arrs):
            raise InputError(f"{name}: each coefficient array needs at least len(t) - k - 1 = "
                             f"{n} values")
        cc = np.column_stack([a[:n] for a in arrs])
    else:
        cc = np.asarray(c, dtype=float)
        if cc.shape[0] < n:
            raise InputError(f"{name}: the coefficients need at least len(t) - k - 1 = {n} rows, "
                             f"got {cc.shape[0]}")
        cc = cc[:n]
    return _from_bspline(BSpline(t, cc, k), name, closed)


def _from_ppoly(pp: Any, name: str, closed: bool | None) -> PiecewiseCurve:
    from scipy.interpolate import PPoly

    x = np.asarray(pp.x, dtype=float)
    c = np.asarray(pp.c, dtype=float)
    if int(getattr(pp, "axis", 0)) != 0:
        # scipy stores ``c`` as (k + 1, m, values) whatever the axis; only the evaluation puts
        # the values first (``axis=1``: shape (dim, len(u)), e.g. csaps' spline form): the same
        # polynomial pieces with the parameter axis first
        pp = PPoly(c, x, extrapolate=pp.extrapolate)
    if x.shape[0] >= 2 and np.all(np.diff(x) >= 0) and np.any(np.diff(x) == 0):
        # empty intervals (PPoly.from_spline keeps the repeated end knots): no part of the curve
        keep = np.diff(x) > 0
        x = np.r_[x[:-1][keep], x[-1]]
        c = c[:, keep]
        pp = PPoly(c, x, extrapolate=pp.extrapolate)
    if x.shape[0] < 2 or np.any(np.diff(x) <= 0):
        raise InputError(f"{name}: the breakpoints must be strictly increasing")
    ref = pp
    if c.ndim == 2:  # scalar: the graph (x, f(x))
        k = c.shape[0] - 1
        if k < 1:
            raise InputError(f"{name}: a piecewise constant function is not a curve")
        cx = np.zeros_like(c)
        cx[-1] = x[:-1]
        cx[-2] = 1.0
        c = np.stack([cx, c], axis=2)
        ref = _graph_reference(pp)
        pp = PPoly(c, x, extrapolate=False)
    elif not (c.ndim == 3 and c.shape[2] in (2, 3)):
        raise InputError(f"{name}: the piecewise polynomial's values have shape {c.shape[2:]}; "
                         "a curve needs (2,) or (3,) (or scalars for a graph y = f(x))")
    if not np.all(np.isfinite(c)):
        raise InputError(f"{name}: the piecewise polynomial has non-finite coefficients")
    k = c.shape[0] - 1
    m = c.shape[1]
    size = max(_scale(c[-1]), 1e-300)
    # continuity at each interior breakpoint: highest order with equal one-sided derivatives
    cont = np.full(m - 1, k, dtype=int)
    for j in range(1, m):
        xj = x[j]
        cont[j - 1] = -1
        for nu in range(k + 1):
            left = _poly_derivative(c[:, j - 1], nu, xj - x[j - 1])
            right = _poly_derivative(c[:, j], nu, 0.0)
            h = min(x[j] - x[j - 1], x[j + 1] - x[j])
            if np.max(np.abs(left - right)) * h**nu > 1e-12 * size:
                break
            cont[j - 1] = nu
    if np.any(cont < 0):
        j = int(np.flatnonzero(cont < 0)[0]) + 1
        raise InputError(f"{name}: the piecewise polynomial jumps at breakpoint {j} "
                         f"(x = {x[j]!r}); a curve must be continuous")
    xs = x
    # data at the breakpoints: the power coefficients c_{k-nu} nu! of each segment's start
    # (exact), and the last segment evaluated at its end
    vals = []
    for nu in range(min(k, 2) + 1):
        start = c[k - nu] * float(np.prod(np.arange(1, nu + 1)))
        end = _poly_derivative(c[:, -1], nu, x[-1] - x[-2])
        vals.append(np.vstack([start, end[None, :]]))
    if closed is None:
        closed = bool(np.all([np.max(np.abs(v[0] - v[-1])) * (x[-1] - x[0])**nu <= 1e-12 * size
                              for nu, v in enumerate(vals[:max(1, k)])]))
    u = np.unique(np.concatenate([x, 0.5 * (x[:-1] + x[1:])]))
    if k == 3 and np.all(cont >= 1):
        from .curves.hermite import CubicHermite

        p, d1 = _closed_fix(vals[0], closed), _closed_fix(vals[1], closed)
        return _check(CubicHermite(p, d1, xs, closed=closed), ref, u, name)
    if k == 5 and np.all(cont >= 2):
        from .curves.hermite import QuinticHermite

        p, d1, d2 = (_closed_fix(v, closed) for v in vals)
        return _check(QuinticHermite(p, d1, d2, xs, closed=closed), ref, u, name)
    return _check(_ppoly_bspline(pp, x, k, cont), ref, u, name)


def _closed_fix(v: np.ndarray, closed: bool) -> np.ndarray:
    v = np.array(v, dtype=float)
    if closed:
        v[-1] = v[0]
    return v


def _poly_derivative(coef: np.ndarray, nu: int, h: float) -> np.ndarray:
    """``nu``-th derivative at local coordinate ``h`` of the power form ``sum c_i h^(k-i)``."""
    k = coef.shape[0] - 1
    out = np.zeros(coef.shape[1:])
    for i in range(k + 1 - nu):
        p = k - i
        f = float(np.prod(np.arange(p, p - nu, -1))) if nu else 1.0
        out = out + f * coef[i] * h ** (p - nu)
    return out


def _ppoly_bspline(pp: Any, x: np.ndarray, k: int, cont: np.ndarray) -> PiecewiseCurve:
    """The same curve as a B-spline: breakpoint ``j`` repeated ``k - cont_j`` times."""
    from scipy.interpolate import make_interp_spline

    from .curves.bspline import BSplineCurve

    inner = np.concatenate([np.repeat(x[j], max(1, k - int(cont[j - 1])))
                            for j in range(1, len(x) - 1)]) if len(x) > 2 else np.empty(0)
    t = np.r_[[x[0]] * (k + 1), inner, [x[-1]] * (k + 1)]
    n = t.shape[0] - k - 1
    xg = np.array([t[i + 1:i + k + 1].mean() for i in range(n)])
    spl = make_interp_spline(xg, np.asarray(pp(xg), dtype=float), k=k, t=t, axis=0)
    return BSplineCurve(spl.c, t, k, closed=False)
