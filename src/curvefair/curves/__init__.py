"""Curve types and builders."""

from .bspline import BSplineCurve, fit_bspline, interpolate_bspline
from .hermite import CubicHermite, HermiteSpline, QuinticHermite
from .interpolate import interpolate_cubic, interpolate_quintic
from .parameterize import parameterize
from .piecewise import PiecewiseCurve, PiecewisePolynomial

__all__ = [
    "BSplineCurve",
    "fit_bspline",
    "interpolate_bspline",
    "CubicHermite",
    "HermiteSpline",
    "QuinticHermite",
    "PiecewiseCurve",
    "PiecewisePolynomial",
    "interpolate_cubic",
    "interpolate_quintic",
    "parameterize",
]
