"""A new B-spline structure when the user accepts one: ``fair(curve, structure="free")``.

By default :func:`curvefair.fair` keeps a B-spline's degree, knot vector and number of control
points (the file's structure). With ``structure="free"`` the curve may first lose knots:

1. :func:`reduce_knots`: the fewest simple interior knots (found by bisection on their number,
   evenly spread over the curve's own simple knots; knots of multiplicity > 1 -- joins,
   corners -- stay) for which the least-squares B-spline of the same degree, fitted to dense
   samples of the curve at their own parameters, stays within ``tol_a`` of the curve at equal
   parameter (the certified bound of :func:`curvefair.deviation`);
2. fair the reduced curve with the method under the remaining tolerance ``tol - d_a``
   (``d_a`` the certified deviation of step 1), so the result is within ``tol`` of the input by
   the triangle inequality, certified once more on the result.

Fewer pieces leave fewer places where the curvature can turn (a knot is where the third
derivative of a cubic may jump), and the fairing energy (E3 for the default ``global``,
``l=3``) is then minimised in the smaller space under the same tolerance.
"""

from __future__ import annotations

from typing import Any, cast

import numpy as np

from ..curves.bspline import BSplineCurve

__all__ = ["reduce_knots", "STRUCTURES"]

STRUCTURES = ("keep", "free")


def _lsq(curve: BSplineCurve, inner: np.ndarray, samples: int = 8) -> BSplineCurve | None:
    from scipy.interpolate import make_lsq_spline

    p = curve.degree
    t = np.asarray(curve.knots, dtype=float)
    a, b = curve.domain
    br = np.unique(t[p:-p])
    x = np.concatenate([np.linspace(br[i], br[i + 1], samples, endpoint=False)
                        for i in range(br.size - 1)] + [np.array([b])])
    y = np.asarray(curve(x), dtype=float)
    knots = np.concatenate([np.full(p + 1, a), inner, np.full(p + 1, b)])
    try:
        spl = make_lsq_spline(x, y, knots, k=p, axis=0)
    except (ValueError, np.linalg.LinAlgError):
        return None
    c = np.asarray(spl.c, dtype=float)
    if not np.all(np.isfinite(c)):
        return None
    return BSplineCurve(c, knots, p)


def reduce_knots(curve: BSplineCurve, tol: float) -> tuple[BSplineCurve, float, int]:
    """Fewer knots within ``tol`` (step 1 of the module docstring).

    Returns ``(curve, certified deviation, knots removed)``; the input itself (deviation 0)
    when no reduction stays within ``tol`` or the curve is closed.
    """
    from ..analysis import deviation

    if curve.closed or not np.isfinite(tol) or tol <= 0:
        return curve, 0.0, 0
    p = curve.degree
    t = np.asarray(curve.knots, dtype=float)
    inner = t[p + 1:-p - 1]
    vals, counts = np.unique(inner, return_counts=True)
    fixed = vals[counts > 1]
    free = vals[counts == 1]
    best, best_dev, removed = curve, 0.0, 0
    fixed_rep = np.repeat(fixed, counts[counts > 1])

    def attempt(m: int) -> tuple[BSplineCurve, float] | None:
        keep = free[np.unique(np.round(np.linspace(0, free.size - 1, m)).astype(int))] \
            if m > 0 else free[:0]
        cand = _lsq(curve, np.sort(np.concatenate([keep, fixed_rep])))
        if cand is None:
            return None
        d = float(cast(float, deviation(curve, cand, kind="parametric").upper_bound))
        return (cand, d) if d <= tol else None

    lo, hi = 0, free.size  # hi: the smallest count known to pass (the input itself)
    while hi - lo > 1:  # bisection on the number of simple knots kept
        mid = (lo + hi) // 2
        got = attempt(mid)
        if got is None:
            lo = mid
        else:
            hi = mid
            best, best_dev = got
    if best is not curve:
        removed = inner.size - (best.knots.shape[0] - 2 * (p + 1))
    return best, best_dev, removed


def fair_new_structure(curve: BSplineCurve, method: str | None, tol: float | None,
                       fair_fn: Any, **kw: Any) -> Any:
    """``fair(curve, method, tol=tol, structure="free", **kw)`` (module docstring)."""
    from ..analysis import deviation
    from .fair import FairingReport, FairingResult

    if tol is None:
        return fair_fn(curve, method, tol=tol, **kw)
    reduced, d_a, removed = reduce_knots(curve, 0.5 * tol)
    res = fair_fn(reduced, method, tol=tol - d_a, **kw)
    dev = float(cast(float, deviation(curve, res.curve, kind="parametric").upper_bound))
    if not dev <= tol:  # pragma: no cover - the triangle inequality makes this impossible
        res = fair_fn(curve, method, tol=tol, **kw)
        removed, dev = 0, float(res.report["max_deviation"])
    rep = dict(res.report)
    from ..analysis import fairness_figures

    a = fairness_figures(curve)  # (the counts alone: analyze()'s, without its arrays)
    rep["structure"] = {
        "kept": removed == 0, "knots_removed": int(removed),
        "n_ctrl_before": int(curve.n_ctrl), "n_ctrl_after": int(res.curve.n_ctrl),
        "reduction_deviation": d_a, "deviation_upper_bound": dev,
        "note": "moved/max_point_displacement compare with the reduced curve; "
                "extrema/inflections before are the input's"}
    rep["extrema_before"] = int(a["extrema"])
    rep["inflections_before"] = int(a["inflections"])
    rep["max_deviation_upper_bound"] = dev
    rep["tol"] = tol
    return FairingResult(res.curve, FairingReport(rep), res.history, curve)
