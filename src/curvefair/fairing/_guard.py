"""Never worse: the guard :func:`curvefair.fair` applies to a method's result.

A local fairing step lowers an energy; it does not promise fewer inflections or curvature
extrema, and on a curve that is already fair it can add some. When the result has more of either
than the input (by :func:`curvefair.analyze`'s counts), the guard tries the fractions ``lam =
1/2, 1/4, 1/8`` of the move, ``C_lam = (1 - lam) C_in + lam C_out`` -- the data (control points,
or points and derivatives with the same parameters) are blended, so the curve is blended the
same way and stays within ``lam`` times the method's deviation: inside the tolerance, with every
fixed point, clamp and held join unchanged (each is the same in both curves, and the
derivatives at an end are linear in the data) -- and keeps the largest that is not worse; if
none is, the input itself. The report says which and why.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ..curves.bspline import BSplineCurve
from ..curves.hermite import CubicHermite, HermiteSpline, QuinticHermite
from ..curves.piecewise import PiecewiseCurve

FRACTIONS = (0.5, 0.25, 0.125)


def blend(a: PiecewiseCurve, b: PiecewiseCurve, lam: float) -> PiecewiseCurve | None:
    """``(1 - lam) a + lam b`` when both have the same structure (knots / parameters), else
    None."""
    if isinstance(a, BSplineCurve) and isinstance(b, BSplineCurve):
        if (a.degree != b.degree or a.closed != b.closed or a.n_ctrl != b.n_ctrl
                or not np.array_equal(a.knots, b.knots)):
            return None
        P = (1.0 - lam) * np.asarray(a.control_points) + lam * np.asarray(b.control_points)
        return a.replace(control_points=P)
    if isinstance(a, HermiteSpline) and type(a) is type(b):
        assert isinstance(b, HermiteSpline)
        if a.closed != b.closed or not np.array_equal(a.params, b.params):
            return None
        P = (1.0 - lam) * np.asarray(a.points) + lam * np.asarray(b.points)
        D = [(1.0 - lam) * np.asarray(x) + lam * np.asarray(y)
             for x, y in zip(a._derivs, b._derivs, strict=True)]
        if a.closed:  # keep the seam bitwise closed
            P[-1] = P[0]
            for d in D:
                d[-1] = d[0]
        if isinstance(a, QuinticHermite):
            return QuinticHermite(P, D[0], D[1], a.params, closed=a.closed)
        if isinstance(a, CubicHermite):
            return CubicHermite(P, D[0], a.params, closed=a.closed)
    return None


def never_worse(curve: PiecewiseCurve, new: PiecewiseCurve, before: dict[str, Any],
                after: dict[str, Any], jp: Any, work_out: PiecewiseCurve,
                analysis: Callable[[PiecewiseCurve], dict[str, Any]]
                ) -> tuple[PiecewiseCurve, dict[str, Any], dict[str, Any]]:
    """The guarded result ``(curve, its analysis block, report entry)`` (module docstring).

    ``jp`` is the :class:`~curvefair.fairing.joins.JoinPlan`: blending happens on the curve
    the method faired (``jp.curve`` and ``work_out``), then :meth:`JoinPlan.restore`.
    """
    worse = []
    if after["inflections"] > before["inflections"]:
        worse.append(f"inflections {before['inflections']} -> {after['inflections']}")
    if after["extrema"] > before["extrema"]:
        worse.append(f"curvature extrema {before['extrema']} -> {after['extrema']}")
    why = "the method's result has more " + " and ".join(worse)
    info: dict[str, Any] = {"method_result": {"inflections": after["inflections"],
                                              "extrema": after["extrema"]}}
    for lam in FRACTIONS:
        b = blend(jp.curve, work_out, lam)
        if b is None:
            break
        cand = jp.restore(b)
        a = analysis(cand)
        if a["inflections"] <= before["inflections"] and a["extrema"] <= before["extrema"]:
            info.update(kept="partial", fraction=lam,
                        reason=f"{why}; kept {lam:g} of the move, which adds neither")
            return cand, a, info
    info.update(kept="input", fraction=0.0,
                reason=f"{why}; kept the input (no fraction of the move tried was not worse)")
    return curve, before, info
