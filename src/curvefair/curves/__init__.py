"""Curve types and builders."""

from .hermite import CubicHermite, HermiteSpline, QuinticHermite
from .interpolate import interpolate_cubic, interpolate_quintic
from .parameterize import parameterize
from .piecewise import PiecewiseCurve, PiecewisePolynomial

__all__ = [
    "CubicHermite",
    "HermiteSpline",
    "QuinticHermite",
    "PiecewiseCurve",
    "PiecewisePolynomial",
    "interpolate_cubic",
    "interpolate_quintic",
    "parameterize",
]
