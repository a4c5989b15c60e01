"""The ranked bad points of a curve: one ranking for ``curvefair analyze`` and the plots."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import CurvefairError

__all__ = ["RankedBadPoint", "rank_bad_points", "c0_pieces", "CHENG_YU_KINDS"]

#: Names of the three kinds of bad control points of Cheng & Yu (see :func:`bad_points`).
CHENG_YU_KINDS = {1: "inflection (Cheng-Yu kind 1)", 2: "curvature extremum (Cheng-Yu kind 2)",
                  3: "convexity (Cheng-Yu kind 3)"}

#: Jumps below ``JUMP_RTOL`` times the largest are rounding noise (a C3 joint), not bad points.
JUMP_RTOL = 1e-9


@dataclass(frozen=True)
class RankedBadPoint:
    """One entry of :func:`rank_bad_points` (0-based indices).

    Attributes
    ----------
    index : int
        The data point (Hermite curve), breakpoint, or control point (cubic B-spline) at fault;
        :attr:`index_of` says which.
    index_of : str
        ``"data point"``, ``"breakpoint"`` or ``"control point"``.
    param : float
        Curve parameter where the defect sits: the breakpoint, or for control point ``i`` of a
        cubic B-spline the joint ``u_{i+2}`` whose curvature ``K_i`` measures
        (:attr:`SecondDiscreteCurvature.params`).
    measure : float
        The ranking value (larger is worse).
    measure_name : str
        ``"|Δr'''|"``, ``"|Δr^(p)|"`` or ``"z = D^2 (Cheng-Yu)"``.
    kind : str
        Human-readable kind of the defect.
    derivative : int or None
        Order of the derivative whose jump is :attr:`measure`; None for Cheng-Yu points.
    kinds : tuple of int
        Cheng-Yu kinds that apply (empty for jumps).
    sapidis : float or None
        Sapidis' bad-point measure at the breakpoint (jumps only).
    piece : int or None
        Index of the C0 piece of a B-spline cut at its C0 knots (None when the curve is one piece).
    """

    index: int
    index_of: str
    param: float
    measure: float
    measure_name: str
    kind: str
    derivative: int | None = None
    kinds: tuple[int, ...] = ()
    sapidis: float | None = None
    piece: int | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (the ``bad_points`` entries of ``curvefair analyze --json``)."""
        d: dict[str, Any] = {"index": self.index, "index_of": self.index_of,
                             "param": self.param, "measure": self.measure,
                             "measure_name": self.measure_name, "kind": self.kind}
        if self.derivative is None:
            d["kinds"] = list(self.kinds)
        else:
            d["sapidis"] = self.sapidis
        if self.piece is not None:
            d["piece"] = self.piece
        return d


def c0_pieces(curve: Any) -> list[tuple[int, Any]]:
    """An open clamped B-spline cut at its C0 knots (interior knots of multiplicity >= degree:
    the curve passes through a control point there, a corner or a kink), as ``(index of the
    piece's first control point in the curve, piece)``; ``[(0, curve)]`` when there are none.

    With ``u = t_{k+1} = ... = t_{k+p}`` the curve is ``P_k`` at ``u``, and the two pieces are
    the B-splines on ``P_0..P_k`` with knots ``t_0..t_{k+p}, u`` and on ``P_k..P_{n-1}`` with
    knots ``u, t_{k+1}..t_{n+p}`` (the B-spline basis is local: no control point changes).
    Closed curves are returned whole (their discrete curvature needs no split unless a C0
    knot is present, which then makes :func:`curvefair.bad_points` refuse them).
    """
    from ..curves.bspline import BSplineCurve

    p = curve.degree
    if curve.closed:
        return [(0, curve)]
    t = np.asarray(curve.knots, dtype=float)
    P = np.asarray(curve.control_points, dtype=float)
    inner, counts = np.unique(t[p + 1:-p - 1], return_counts=True)
    cuts = []
    for u, m in zip(inner, counts, strict=True):
        if m >= p:
            k = int(np.searchsorted(t, u, side="left")) - 1   # t_{k+1} = u
            cuts.append((int(k + m - p), u))
    if not cuts:
        return [(0, curve)]
    out = []
    start = 0
    for k in [c for c, _ in cuts] + [P.shape[0] - 1]:
        # P_start..P_k on the knots t_{start+1}..t_{k+p}, each end knot once more
        knots = np.r_[t[start + 1], t[start + 1:k + p + 1], t[k + p]]
        out.append((start, BSplineCurve(P[start:k + 1], knots, p)))
        start = k
    return out


def rank_bad_points(curve: Any, analysis: Any = None) -> list[RankedBadPoint]:
    """The bad points of a curve, worst first.

    Cubic B-splines: the bad control points of Cheng & Yu (:func:`curvefair.bad_points`),
    ranked by ``z_i = D_i**2``, on each C0 piece (:func:`c0_pieces`) with indices into the whole
    curve; a piece with no discrete curvature (a single Bezier segment) contributes none.
    Other curves (Hermite curves, B-splines of degree other than 3): breakpoints ranked by the
    jump of the third derivative ``|r'''(u+) - r'''(u-)|`` (Wang & Cao 2006), or of the
    highest derivative when a curve of degree > 3 has no third-derivative jump (a C4 quintic);
    jumps below ``1e-9`` of the largest are dropped as rounding noise. For a Hermite curve the
    breakpoint index is the data-point index. Ties keep the smaller index first.

    Parameters
    ----------
    curve : PiecewiseCurve
    analysis : Analysis, optional
        ``analyze(curve)``, if already computed (the jump ranking reads it).

    Returns
    -------
    list of RankedBadPoint
    """
    from ..curves.bspline import BSplineCurve
    from .discrete import bad_points, second_discrete_curvature

    if isinstance(curve, BSplineCurve) and curve.degree == 3:
        out: list[RankedBadPoint] = []
        pieces = c0_pieces(curve)
        for piece, (offset, sub) in enumerate(pieces):
            try:
                found = bad_points(sub)
            except CurvefairError:
                continue   # a single Bezier segment, or a closed curve with a C0 knot
            joints = second_discrete_curvature(sub).params
            out += [RankedBadPoint(index=int(b.index) + offset, index_of="control point",
                                   param=float(joints[b.index]), measure=float(b.value),
                                   measure_name="z = D^2 (Cheng-Yu)",
                                   kind=CHENG_YU_KINDS.get(int(b.kind), str(b.kind)),
                                   kinds=tuple(int(k) for k in b.kinds),
                                   piece=piece if len(pieces) > 1 else None) for b in found]
        out.sort(key=lambda b: -b.measure)
        return out
    if analysis is None:
        from ._analyze import analyze

        analysis = analyze(curve)
    a = analysis
    jumps, name, kind, order = np.asarray(a.jumps), "|Δr'''|", "third-derivative jump", 3
    if a.degree > 3 and not a.max_jump > JUMP_RTOL * a.max_top_jump:
        jumps, name = np.asarray(a.top_jumps), f"|Δr^({a.degree})|"
        kind, order = f"derivative-{a.degree} jump", int(a.degree)
    if jumps.size == 0 or float(jumps.max()) <= 0.0:
        return []
    top = float(jumps.max())
    rank = np.argsort(-jumps, kind="stable")
    of = "data point" if hasattr(curve, "points") else "breakpoint"
    return [RankedBadPoint(index=int(a.jump_indices[i]), index_of=of,
                           param=float(a.jump_params[i]), measure=float(jumps[i]),
                           measure_name=name, kind=kind, derivative=order,
                           sapidis=float(a.sapidis[i]))
            for i in rank if jumps[i] > JUMP_RTOL * top]
