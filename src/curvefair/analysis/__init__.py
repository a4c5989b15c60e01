"""Fairness analysis: exact energies, curvature and torsion, bad-point measures, deviation.

Public: :func:`energy`, :func:`curvature`, :func:`curvature_derivative`, :func:`torsion`,
:func:`analyze` (-> :class:`Analysis`; :func:`fairness_figures`: its scalar figures only;
:func:`lean_by_default`: the sizes from which those keep no samples),
:func:`deviation` (-> :class:`Deviation`; :func:`hermite_delta_deviation`,
:func:`bspline_delta_deviation`: its figures for two Hermite splines on the same parameters,
or two B-splines on the same knots, without their difference's power form),
:func:`matched_hermite_bound` (a cheap Hausdorff bound of two cubic Hermite curves),
:func:`geometric_upper_bound` (the same for any two curves, from one dense pass),
:func:`point_displacement` (the largest move of corresponding data points),
:func:`rank_bad_points` (-> list of :class:`RankedBadPoint`: the one bad-point ranking that
``curvefair analyze`` and the plots show); the discrete
curvature of Cheng & Yu lives in :mod:`curvefair.analysis.discrete`.
"""

from ._analyze import Analysis, analyze, derivative_jumps, fairness_figures, lean_by_default
from ._curvature import curvature, curvature_derivative, torsion
from ._deviation import (
    Deviation,
    bspline_delta_deviation,
    deviation,
    geometric_upper_bound,
    hermite_delta_deviation,
    matched_hermite_bound,
    point_displacement,
)
from ._energy import energy, segment_energies
from ._ranking import RankedBadPoint, c0_pieces, rank_bad_points
from .discrete import (
                       BadPoint,
                       SecondDiscreteCurvature,
                       bad_points,
                       discrete_curvature,
                       second_discrete_curvature,
)

__all__ = [
    "Analysis",
    "analyze",
    "fairness_figures",
    "lean_by_default",
    "derivative_jumps",
    "curvature",
    "curvature_derivative",
    "torsion",
    "Deviation",
    "deviation",
    "hermite_delta_deviation",
    "bspline_delta_deviation",
    "matched_hermite_bound",
    "geometric_upper_bound",
    "point_displacement",
    "energy",
    "segment_energies",
    "discrete_curvature",
    "second_discrete_curvature",
    "bad_points",
    "BadPoint",
    "SecondDiscreteCurvature",
    "rank_bad_points",
    "RankedBadPoint",
    "c0_pieces",
]
