"""The final tolerance guarantee every result of :func:`curvefair.fair` passes through.

Each method keeps its moves inside the tolerance ball in exact arithmetic, with a rounding
margin where it is cheap. What the user checks is float64: ``|moved_i - original_i| <= tol``
with the coordinates as stored, and the distance between the two curves. Near the sphere
(a point clamped onto it, coordinates far from the origin so that an ulp of a coordinate is
not small against ``tol``) rounding can put a point a few ulp outside. :func:`enforce_tolerance`
makes the promise exact:

1. every data point (B-spline control points, Hermite points) that is farther than ``tol``
   from its original by any of the usual float64 formulas (:func:`curvefair._distance.exceeds`)
   is pulled back along its own move, ``o + s (m - o)`` with ``s`` shrinking from
   ``tol / |m - o|`` in steps that grow geometrically, until the float64 check passes
   (``s = 0`` returns the original, so this ends);
2. the curve deviation ``max_t |a(t) - b(t)|`` is certified on the DIFFERENCE curve: every
   curve type here is linear in its data (B-spline control points, Hermite points and
   derivatives) for fixed knots / parameters, so ``a(t) - b(t)`` is the curve of the data
   differences, whose Bernstein bound (:func:`curvefair.deviation`) carries no rounding of
   the coordinates' offset. Where the method promises the curve within ``tol`` (the B-spline
   methods by the convex hull property, the Hermite methods with ``tol_on="curve"``) and the
   certified bound exceeds ``tol``, all data differences are scaled by one factor ``s < 1``
   (linear, so clamp conditions ``A (data - original) = 0`` and protected points -- zero
   difference -- are kept bitwise) and step 1 is repeated.

Only moved points change: a point with zero difference stays bitwise equal to its original.
A pulled-back Hermite point keeps its derivatives, so a ``mode="spline"`` result is then a
spline interpolant only up to the pull-back (a few ulp of the coordinates).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass
from typing import Any, cast

import numpy as np

from .._distance import exceeds
from .._typing import FloatArray
from ..curves.bspline import POWER_FORM_MAX_DEGREE, BSplineCurve, power_form
from ..curves.hermite import (
    CubicHermite,
    QuinticHermite,
    cubic_hermite_coefficients,
    quintic_hermite_coefficients,
)
from ..curves.piecewise import PiecewiseCurve, PiecewisePolynomial, readonly

__all__ = ["Certificate", "enforce_tolerance", "curve_fields", "difference_deviation",
           "point_report", "prime_power_forms"]

_MAX_SCALINGS = 8
_ZERO = np.frombuffer(bytes(8), dtype=np.float64).reshape(1, 1, 1)  # immutable +0.0


@dataclass(frozen=True)
class Certificate:
    """What :func:`enforce_tolerance` measured on the final curve.

    ``max_distance`` / ``upper_bound``: lower and certified upper bound of
    ``max_t |a(t) - b(t)|`` at equal parameter; ``param``: where the lower bound is attained;
    ``pulled_back``: number of data points moved back inside ``tol``; ``scale``: the factor the
    data differences were multiplied by to certify the curve (1.0: none).
    """

    max_distance: float
    upper_bound: float
    param: float
    pulled_back: int
    scale: float


def curve_fields(curve: PiecewiseCurve) -> dict[str, FloatArray] | None:
    """The data arrays the curve is linear in, position first; None for other curve types."""
    if isinstance(curve, BSplineCurve):
        return {"control_points": np.asarray(curve.control_points)}
    if isinstance(curve, QuinticHermite):
        return {"points": np.asarray(curve.points), "d1": np.asarray(curve.d1),
                "d2": np.asarray(curve.d2)}
    if isinstance(curve, CubicHermite):
        return {"points": np.asarray(curve.points), "tangents": np.asarray(curve.tangents)}
    return None


def _comparable(a: PiecewiseCurve, b: PiecewiseCurve) -> bool:
    """Same type, degree, closedness, knots / parameters (bitwise) and data shapes."""
    if type(a) is not type(b) or a.closed != b.closed or a.degree != b.degree:
        return False
    fa, fb = curve_fields(a), curve_fields(b)
    if fa is None or fb is None or any(fa[k].shape != fb[k].shape for k in fa):
        return False
    if isinstance(a, BSplineCurve):
        return bool(np.array_equal(a.knots, b.knots))  # type: ignore[attr-defined]
    return bool(np.array_equal(a.params, b.params))  # type: ignore[attr-defined]


def same_curve(a: PiecewiseCurve, b: PiecewiseCurve) -> bool:
    """Whether ``b`` is ``a`` or has bit for bit its type, knots / parameters and data (then
    every figure of the two is the same; a method that moved nothing returns such a curve)."""
    if a is b:
        return True
    if not _comparable(a, b):
        return False
    fa, fb = curve_fields(a), curve_fields(b)
    assert fa is not None and fb is not None
    # compared as 64-bit patterns: -0.0 and 0.0 differ, a NaN equals itself
    return all(np.array_equal(np.ascontiguousarray(fa[k]).view(np.uint64),
                              np.ascontiguousarray(fb[k]).view(np.uint64)) for k in fa)


class _PowerForm(PiecewiseCurve):
    """A bare piecewise polynomial as a curve (the difference curve; not exported)."""

    def __init__(self, pp: PiecewisePolynomial, closed: bool) -> None:
        self._pp = pp
        self._closed = closed
        self.degree = pp.degree

    @property
    def dim(self) -> int:
        return int(self._pp.dim)

    @property
    def closed(self) -> bool:
        return self._closed

    def _make_piecewise(self) -> PiecewisePolynomial:
        return self._pp


def _difference_form(a: PiecewiseCurve, delta: dict[str, FloatArray]) -> PiecewisePolynomial:
    """Power form of the curve with ``a``'s knots / parameters and data ``delta``."""
    if isinstance(a, BSplineCurve):
        # the compiled pass of BSplineCurve's own power form, on the differences:
        # c[m, k] = sum_a N_{s-p+a}^(k)(t_s) delta_{s-p+a} / k!
        p = a.degree
        t = np.ascontiguousarray(a.knots)
        s = np.ascontiguousarray(a.spans, dtype=np.int64)
        d = np.ascontiguousarray(delta["control_points"], dtype=np.float64)
        coeffs = np.empty((s.size, p + 1, d.shape[1]))
        power_form(t, p, s, d, bool(a.closed), coeffs)
        return PiecewisePolynomial._borrowed(a.span_breaks, coeffs)
    params = np.asarray(a.params)  # type: ignore[attr-defined]
    if isinstance(a, QuinticHermite):
        c = quintic_hermite_coefficients(delta["points"], delta["d1"], delta["d2"], params)
    else:
        c = cubic_hermite_coefficients(delta["points"], delta["tangents"], params)
    return PiecewisePolynomial._borrowed(params, c)


def prime_power_forms(original: PiecewiseCurve, new: PiecewiseCurve
                      ) -> tuple[PiecewiseCurve, tuple[float, float, float]] | None:
    """For two comparable B-splines (same knots, degree, closedness, shapes): ``new``'s power
    form (cached on it, as its :attr:`~curvefair.PiecewiseCurve.piecewise` would be) and
    the power form of the difference curve ``new - original`` in one pass
    (:func:`curvefair._kernels.bspline.power_form_pair_kernel`: the basis derivatives once
    for both, bitwise the two separate results), and the difference curve's
    :func:`difference_deviation` figures at once, so that its power form is freed before the
    result's analysis (the call's peak memory). Returns ``(new, (max_distance, upper_bound,
    param))`` for :func:`enforce_tolerance`'s ``primed``, or None (other curves, high degree,
    ``new``'s form already built, a non-finite form: the usual paths then)."""
    if (not isinstance(new, BSplineCurve) or "piecewise" in new.__dict__
            or new.degree > POWER_FORM_MAX_DEGREE or not _comparable(original, new)):
        return None
    p = new.degree
    t = np.ascontiguousarray(new.knots)
    s = np.ascontiguousarray(new.spans, dtype=np.int64)
    ctrl = np.ascontiguousarray(new.control_points, dtype=np.float64)
    base = np.ascontiguousarray(original.control_points, dtype=np.float64)  # type: ignore[attr-defined]
    coeffs = np.empty((s.size, p + 1, ctrl.shape[1]))
    diff = np.empty_like(coeffs)
    power_form(t, p, s, ctrl, bool(new.closed), coeffs, base, diff)
    if not (np.isfinite(coeffs).all() and np.isfinite(diff).all()):
        return None  # new.piecewise raises its own message when asked
    breaks = readonly(new.span_breaks)
    # the certificate first, then the frozen copy of new's form: the difference form is freed
    # before that copy is made, so the two forms and the copy are never alive together
    figures = difference_deviation(original, new, PiecewisePolynomial._borrowed(breaks, diff))
    del diff
    new.__dict__["piecewise"] = PiecewisePolynomial(breaks, coeffs)  # the cached_property
    return new, figures


def delta_deviation(a: PiecewiseCurve, delta: dict[str, FloatArray]) -> Any:
    """:func:`curvefair.deviation` between ``a`` and the curve with ``a``'s knots / parameters
    and data ``a``'s plus ``delta`` (:func:`curve_fields` names), measured on the difference
    curve itself: one power form of the data's differences (exactly linear, no rounding of
    the coordinates' offset) against the zero curve, no power form of the second curve."""
    pp = _difference_form(a, delta)
    return _against_zero(pp, a.closed)


def _against_zero(pp: PiecewisePolynomial, closed: bool) -> Any:
    """:func:`curvefair.deviation` of the power form ``pp`` from the zero curve."""
    from ..analysis import deviation

    # the zero curve on the same breaks: one frozen 0.0 broadcast to the coefficients'
    # shape (no 8-byte-per-entry zeros, no copy of the breaks)
    zero = PiecewisePolynomial._borrowed(pp.breaks, np.broadcast_to(_ZERO, pp.coeffs.shape))
    return deviation(_PowerForm(pp, closed), _PowerForm(zero, closed))


#: :func:`difference_deviation` of two cubic Hermite curves (their data are read-only), by
#: the second curve, with the first: points-l1 certifies each attempt's curve and then hands
#: the last one to :func:`enforce_tolerance`, which certifies the same pair again
_DEVIATION_MEMO: weakref.WeakKeyDictionary[Any, tuple[Any, tuple[float, float, float]]] = \
    weakref.WeakKeyDictionary()


def difference_deviation(a: PiecewiseCurve, b: PiecewiseCurve,
                         form: PiecewisePolynomial | None = None) -> tuple[float, float, float]:
    """``(max_distance, upper_bound, param)`` of ``max_t |a(t) - b(t)|``.

    On the difference curve when ``a`` and ``b`` share type, knots / parameters and data
    shapes (exactly linear, no rounding of the coordinates' offset), else
    :func:`curvefair.deviation` of the two curves. ``form``: the difference curve's power
    form when the caller has it (:func:`prime_power_forms`). The figures of a pair of
    :class:`CubicHermite` curves are computed once per pair of objects.
    """
    memo = form is None and type(a) is CubicHermite and type(b) is CubicHermite
    if memo:
        got = _DEVIATION_MEMO.get(b)
        if got is not None and _same_data(got[0](), a):
            return got[1]
    out = _difference_deviation(a, b, form)
    if memo:
        _DEVIATION_MEMO[b] = (weakref.ref(a), out)
    return out


def _same_data(x: Any, y: Any) -> bool:
    """Whether ``x`` is ``y`` or a cubic Hermite curve with bit for bit the same data (then
    every figure of the two is the same: fair() certifies the method's result against the
    input curve, points-l1 against its own equal copy of it)."""
    if x is y:
        return True
    if type(x) is not CubicHermite or x.closed != y.closed:
        return False
    return all(p.shape == q.shape and p.tobytes() == q.tobytes()
               for p, q in ((x.params, y.params), (x.points, y.points),
                            (x.tangents, y.tangents)))


def _difference_deviation(a: PiecewiseCurve, b: PiecewiseCurve,
                          form: PiecewisePolynomial | None) -> tuple[float, float, float]:
    from ..analysis import bspline_delta_deviation, deviation, hermite_delta_deviation

    if form is not None:
        d = _against_zero(form, a.closed)
    elif _comparable(a, b):
        # the difference curve one piece at a time (the same figures, without its power form);
        # its whole form only when a coefficient is not finite (deviation() then reports it)
        got = None
        bb = cast(Any, b)
        if isinstance(a, (CubicHermite, QuinticHermite)):
            got = hermite_delta_deviation(a, bb.points, tuple(bb._derivs))
        elif isinstance(a, BSplineCurve):
            got = bspline_delta_deviation(a, bb.control_points)
        if got is not None:
            return got
        fa, fb = curve_fields(a), curve_fields(b)
        assert fa is not None and fb is not None
        d = delta_deviation(a, {k: fb[k] - fa[k] for k in fa})
    else:
        d = deviation(a, b)
    # a geometric deviation (other parameter domains, e.g. point data re-interpolated at
    # new chord lengths) may come without an upper bound or parameter
    ub = float("inf") if d.upper_bound is None else float(d.upper_bound)
    par = float("nan") if d.param is None else float(d.param)
    return float(d.max_distance), ub, par


def _rebuild(template: PiecewiseCurve, fields: dict[str, FloatArray]) -> PiecewiseCurve:
    return template.replace(**fields)  # type: ignore[attr-defined]


def _pull_back(orig: FloatArray, moved: FloatArray, tol: float) -> tuple[FloatArray, int]:
    """``moved`` with every row outside ``tol`` (any float64 formula) pulled back along its move."""
    bad = np.flatnonzero(exceeds(moved, orig, tol))
    if bad.size == 0:
        return moved, 0
    out = np.array(moved, dtype=np.float64)
    for i in bad.tolist():
        o = orig[i]
        d = moved[i] - o
        r = float(np.linalg.norm(d))
        base = tol / r if r > 0.0 else 0.0
        row = o.copy()
        for k in range(60):
            shrink = 1.0 - 2.0 ** (-52 + k) if k < 52 else 0.0
            cand = o + (base * shrink) * d
            if not exceeds(cand[None, :], o[None, :], tol)[0]:
                row = cand
                break
        out[i] = row
    return out, int(bad.size)


def enforce_tolerance(original: PiecewiseCurve, new: PiecewiseCurve, tol: float | None,
                      curve_bound: bool = True,
                      primed: tuple[PiecewiseCurve, tuple[float, float, float]] | None = None
                      ) -> tuple[PiecewiseCurve, Certificate]:
    """``new`` made to satisfy the tolerance exactly in float64 (see the module docstring).

    Parameters
    ----------
    original, new : PiecewiseCurve
        The input of a fairing method and its result.
    tol : float or None
        ``None``: nothing is enforced, only the deviation is measured.
    curve_bound : bool
        The method promises the curve within ``tol`` too (certify and scale if needed).
    primed : (curve, (max_distance, upper_bound, param)) or None
        :func:`prime_power_forms` of ``(original, new)``: its deviation figures stand for
        :func:`difference_deviation` while the curve checked is that very ``curve`` object
        (not after a pull-back or scaling).

    Returns
    -------
    (curve, Certificate)
    """
    def measure(cur: PiecewiseCurve) -> tuple[float, float, float]:
        if primed is not None and primed[0] is cur:
            return primed[1]
        return difference_deviation(original, cur)

    fo = curve_fields(original)
    fn = curve_fields(new)
    if (tol is None or fo is None or fn is None or type(original) is not type(new)
            or fo[next(iter(fo))].shape != fn[next(iter(fn))].shape):
        dmax, ub, t = measure(new)
        return new, Certificate(dmax, ub, t, 0, 1.0)
    pos = next(iter(fo))
    if not _comparable(original, new):
        # other knots / parameters: the data points are still bounded (pulled back), but the
        # curve change is not the curve of the data differences, so it is measured, not scaled
        fixed, pulled = _pull_back(fo[pos], fn[pos], tol)
        cur = new
        if pulled:
            cf = dict(fn)
            cf[pos] = fixed
            cur = _rebuild(new, cf)
        dmax, ub, t = difference_deviation(original, cur)
        return cur, Certificate(dmax, ub, t, pulled, 1.0)
    delta: dict[str, FloatArray] = {}  # the data's differences, when a scaling needs them
    pulled_total = 0
    scale = 1.0
    cur = new
    for attempt in range(_MAX_SCALINGS + 1):
        moved = (fn[pos] if attempt == 0 and scale == 1.0
                 else np.asarray(curve_fields(cur)[pos]))  # type: ignore[index]
        fixed, pulled = _pull_back(fo[pos], moved, tol)
        if pulled:
            pulled_total += pulled
            cf = dict(curve_fields(cur))  # type: ignore[arg-type]
            cf[pos] = fixed
            cur = _rebuild(new, cf)
        dmax, ub, t = measure(cur)
        if not curve_bound or ub <= tol:
            return cur, Certificate(dmax, ub, t, pulled_total, scale)
        if attempt == _MAX_SCALINGS:
            break
        # the curve strays past tol between points: scale every data difference by one factor
        scale *= (tol / ub) * (1.0 - 2.0 ** (-40 + 4 * attempt))
        delta = delta or {k: fn[k] - fo[k] for k in fo}
        cf = {k: fo[k] + scale * delta[k] for k in fo}
        cur = _rebuild(new, cf)
    # could not certify by scaling (cannot happen unless the bound is dominated by rounding):
    # give the input back, which is within every tolerance
    dmax, ub, t = difference_deviation(original, original)
    return original, Certificate(dmax, ub, t, pulled_total, 0.0)


def point_report(original: PiecewiseCurve, new: PiecewiseCurve
                 ) -> tuple[np.ndarray, FloatArray, float, int | None]:
    """The data points a fair moved and how far: the ``moved``, ``n_moved``,
    ``max_point_displacement`` and ``max_point_index`` figures of a :func:`curvefair.fair`
    report.

    Parameters
    ----------
    original, new : curve
        A curve and its faired version, whose data points correspond one to one: the control
        points of B-splines, else the points (a closed Hermite curve's repeated last point
        left out).

    Returns
    -------
    moved : ndarray of int
        The 0-based indices, ascending, of the data points that differ in any coordinate.
    displacement : ndarray of float
        Their distances ``|new_i - original_i|``, in the order of ``moved``: the float64
        Euclidean norm every curvefair report uses for a point's move.
    max_displacement : float
        The largest of them; 0.0 when no point moved.
    max_index : int or None
        The index of that point (the first of equal ones); None when no point moved.

    Notes
    -----
    When the two curves' data points differ in number or dimension (nothing to compare point
    by point), every index of ``new`` is returned as moved, with no displacements, 0.0 and
    None. :func:`curvefair.analysis.point_displacement` gives the largest displacement alone
    (every point counted, a closed Hermite curve's repeated point included).
    """
    from .fair import data_points

    p0 = data_points(original)
    p1 = data_points(new)
    if p0.shape != p1.shape:
        return np.arange(len(p1)), np.zeros(0), 0.0, None
    from .._kernels.deviation import moved_points_kernel

    # one compiled pass: the rows that differ and their distances (point_distances' formula)
    idx = np.empty(p0.shape[0], dtype=np.int64)
    dist = np.empty(p0.shape[0])
    k = moved_points_kernel(np.ascontiguousarray(p0, dtype=np.float64),
                            np.ascontiguousarray(p1, dtype=np.float64), idx, dist)
    moved, disp = idx[:k], dist[:k]  # (the rows past k were never written: never mapped)
    if disp.size == 0:
        return moved, disp, 0.0, None
    k = int(np.argmax(disp))
    return moved, disp, float(disp[k]), int(moved[k])
