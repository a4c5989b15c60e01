"""curvefair: fairing of spline curves by the published local methods, within a tolerance.

Curves: :class:`CubicHermite`, :class:`QuinticHermite` (and :class:`BSplineCurve`), built by
:func:`interpolate_cubic`, :func:`interpolate_quintic`. Analysis: :func:`energy`,
:func:`curvature`, :func:`analyze`, :func:`deviation`. Fairing: :mod:`curvefair.steps` (one
local step per published method) and :func:`fair` (the automatic loop).

Indices are 0-based everywhere; the papers number from 1.
"""

from ._version import __version__
from .curves import (
    BSplineCurve,
    CubicHermite,
    PiecewiseCurve,
    PiecewisePolynomial,
    QuinticHermite,
    fit_bspline,
    interpolate_bspline,
    interpolate_cubic,
    interpolate_quintic,
    parameterize,
)
from .errors import CurvefairError, FileFormatError, InputError, MissingDependencyError
from .io import CurveRecord, read_curves, write_curves  # noqa: I001
from .analysis.discrete import (BadPoint, SecondDiscreteCurvature, bad_points,  # noqa: I001
                                 discrete_curvature, second_discrete_curvature)
from .analysis import (Analysis, Deviation, analyze, curvature,  # noqa: I001
                       curvature_derivative, deviation, energy, torsion)
from . import steps  # noqa: I001
from .fairing import FairingResult, fair  # noqa: I001
from .fairing.pipeline import PointFairingResult, fair_points  # noqa: I001
from .interop import as_curve  # noqa: I001

__all__ = [
    "energy",
    "curvature",
    "curvature_derivative",
    "torsion",
    "analyze",
    "Analysis",
    "deviation",
    "Deviation",
    "fair",
    "FairingResult",
    "fair_points",
    "as_curve",
    "PointFairingResult",
    "steps",
    "read_curves",
    "write_curves",
    "CurveRecord",
    "__version__",
    "CubicHermite",
    "QuinticHermite",
    "BSplineCurve",
    "interpolate_bspline",
    "fit_bspline",
    "PiecewiseCurve",
    "PiecewisePolynomial",
    "interpolate_cubic",
    "interpolate_quintic",
    "parameterize",
    "CurvefairError",
    "InputError",
    "FileFormatError",
    "MissingDependencyError",
    "discrete_curvature",
    "second_discrete_curvature",
    "bad_points",
    "BadPoint",
    "SecondDiscreteCurvature",
]
