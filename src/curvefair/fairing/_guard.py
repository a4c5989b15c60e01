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

Point data. A point file (CSV, airfoil ``.dat``, polyline) is read as the chord-length natural
(closed: periodic) cubic through its points, and what a reader of the written file gets back is
that cubic through the *moved* points, at their own chord lengths -- not the curve a Hermite
method returns on the input's parameters (the tangents it holds or moves are not written). When
the input is such an interpolant (:func:`is_chord_interpolant`) and the result a cubic Hermite
curve on the same parameters, the guard also judges the rebuilt curve
(:func:`rebuilt_curve`): a result whose rebuilt curve adds inflections or curvature extrema is
worse, and a fraction of the move is kept only if neither curve adds any.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable
from typing import Any, cast

import numpy as np

from ..curves.bspline import BSplineCurve
from ..curves.hermite import CubicHermite, HermiteSpline, QuinticHermite
from ..curves.piecewise import PiecewiseCurve

FRACTIONS = (0.5, 0.25, 0.125)


def is_chord_interpolant(curve: PiecewiseCurve) -> bool:
    """Whether ``curve`` is the chord-length natural (closed: periodic) cubic through its points
    -- what a point file is read as -- up to an affine change of parameter: only then is the
    curve rebuilt from written points the same kind of curve as the input."""
    from ..curves.interpolate import interpolate_cubic
    from ..curves.parameterize import parameterize
    from ..errors import InputError

    if type(curve) is not CubicHermite:
        return False
    if curve._chord_natural:
        return True  # made by interpolate_cubic(points, "chord", natural or periodic)
    # the parameters first (O(n), no solve): the chord lengths interpolate_cubic would use
    t, r = np.asarray(curve.params), parameterize(curve.points, "chord")
    st, sr = t[-1] - t[0], r[-1] - r[0]
    if not (st > 0 and sr > 0):
        return False
    if not np.allclose((t - t[0]) / st, (r - r[0]) / sr, rtol=0.0, atol=1e-9):
        return False
    try:
        ref = interpolate_cubic(curve.points, "chord",
                                "periodic" if curve.closed else "natural")
    except InputError:
        return False
    # ref's parameters are r (the same parameterize of the same points)
    d, dr = np.asarray(curve.tangents) * st, np.asarray(ref.tangents) * sr
    scale = max(float(np.max(np.abs(dr))), 1e-300)
    return bool(np.max(np.abs(d - dr)) <= 1e-7 * scale)


def rebuilt_curve(curve: CubicHermite) -> CubicHermite | None:
    """The curve a reader rebuilds from ``curve``'s points: the chord-length natural (closed:
    periodic) cubic through them; None if they do not make one (coincident points)."""
    from ..curves.interpolate import interpolate_cubic
    from ..errors import InputError

    try:
        # curve's own (frozen) points: the rebuilt curve shares them, no copy
        return interpolate_cubic(curve.points, "chord", "periodic" if curve.closed else "natural")
    except InputError:
        return None


#: the analysis blocks of the curves rebuilt from cubic Hermite curves' points, by the curve
#: (its data are read-only; small dicts, no curve kept): points-l1 judges its result's rebuilt
#: curve and fair()'s guard judges it again
_REBUILT_ANALYSIS: weakref.WeakKeyDictionary[Any, Any] = weakref.WeakKeyDictionary()
_NONE = object()


def rebuilt_analysis(curve: PiecewiseCurve,
                     analysis: Callable[[PiecewiseCurve], dict[str, Any]],
                     rebuilt: CubicHermite | None = None) -> dict[str, Any] | None:
    """``analysis(rebuilt_curve(curve))`` (None if the points make no curve), made once per
    cubic Hermite curve object (a fresh dict each time). ``rebuilt``: that curve when the
    caller already made it (``interpolate_cubic`` of the same points, ``"chord"``, natural or
    periodic)."""
    memo = type(curve) is CubicHermite
    if memo:
        got = _REBUILT_ANALYSIS.get(curve)
        if got is not None:
            return None if got is _NONE else dict(got)
    rc = rebuilt if rebuilt is not None else rebuilt_curve(cast(CubicHermite, curve))
    out = None if rc is None else analysis(rc)
    if memo:
        _REBUILT_ANALYSIS[curve] = _NONE if out is None else dict(out)
    return out


def _counts(a: dict[str, Any]) -> dict[str, int]:
    return {"inflections": int(a["inflections"]), "extrema": int(a["extrema"])}


def _adds(a: dict[str, Any], before: dict[str, Any]) -> list[str]:
    """What ``a`` has more of than ``before`` (empty: not worse)."""
    out = []
    if a["inflections"] > before["inflections"]:
        out.append(f"inflections {before['inflections']} -> {a['inflections']}")
    if a["extrema"] > before["extrema"]:
        out.append(f"curvature extrema {before['extrema']} -> {a['extrema']}")
    return out


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
                analysis: Callable[[PiecewiseCurve], dict[str, Any]],
                rebuilt: Callable[[PiecewiseCurve], dict[str, Any] | None] | None = None,
                rebuilt_after: dict[str, Any] | None = None
                ) -> tuple[PiecewiseCurve, dict[str, Any], dict[str, Any]]:
    """The guarded result ``(curve, its analysis block, report entry)`` (module docstring).

    ``jp`` is the :class:`~curvefair.fairing.joins.JoinPlan`: blending happens on the curve
    the method faired (``jp.curve`` and ``work_out``), then :meth:`JoinPlan.restore`.
    ``rebuilt`` (point data): the analysis block of the curve rebuilt from a candidate's points
    (None: it cannot be rebuilt, which counts as worse); ``rebuilt_after`` that of ``new``.
    ``before`` is the input's, which is its own rebuilt curve (up to an affine change of
    parameter: the same counts). The report entry's ``"rebuilt"`` holds the rebuilt curve's
    analysis block for a result that moved, its counts when the input is kept.
    """
    worse = _adds(after, before)
    why = "the method's result has more " + " and ".join(worse) if worse else ""
    info: dict[str, Any] = {"method_result": _counts(after)}
    if rebuilt is not None:
        rb = rebuilt_after if rebuilt_after is not None else rebuilt(new)
        info["method_result"]["rebuilt"] = None if rb is None else _counts(rb)
        rworse = ["its points make no curve"] if rb is None else _adds(rb, before)
        if rworse:
            why += ("; " if why else "") + ("the curve rebuilt from the result's points (what "
                                             "a reader of the written file gets) has more "
                                             + " and ".join(rworse))
    for lam in FRACTIONS:
        b = blend(jp.curve, work_out, lam)
        if b is None:
            break
        cand = jp.restore(b)
        a = analysis(cand)
        if _adds(a, before):
            continue
        if rebuilt is not None:
            rc = rebuilt(cand)
            if rc is None or _adds(rc, before):
                continue
            info["rebuilt"] = dict(rc)
        info.update(kept="partial", fraction=lam,
                    reason=f"{why}; kept {lam:g} of the move, which adds neither")
        return cand, a, info
    if rebuilt is not None:  # the input's counts (its figures are on its own parameters)
        info["rebuilt"] = _counts(before)
    info.update(kept="input", fraction=0.0,
                reason=f"{why}; kept the input (no fraction of the move tried was not worse)")
    return curve, before, info
