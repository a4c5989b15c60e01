"""
A B-spline with a disturbed control point: Eck & Hadenfeld
==========================================================

A cubic B-spline whose control points lie on a circular arc, with one control point pushed
outwards. Eck & Hadenfeld's local method moves one control point at a time to the position
that minimises the curve's energy locally, each point staying within the tolerance of where it
was; the curvature spike the disturbed point made is removed, and the whole curve stays within
``tol`` of the original.
"""

import numpy as np

from curvefair import BSplineCurve, deviation, fair
from curvefair.plot import figure

n, degree = 12, 3
phi = np.linspace(0.0, 0.75 * np.pi, n)
ctrl = np.column_stack([np.cos(phi), np.sin(phi)])
ctrl[5] *= 1.08
knots = np.concatenate([np.zeros(degree), np.linspace(0.0, 1.0, n - degree + 1),
                        np.ones(degree)])
before = BSplineCurve(ctrl, knots, degree)

tol = 0.05
res = fair(before, "eck-hadenfeld", tol=tol)
print(f"{res.report['steps']} steps; stop reason: {res.report['stop_reason']}")
print(f"largest control-point move: "
      f"{np.linalg.norm(res.curve.control_points - ctrl, axis=1).max():.4f} (tol {tol})")
print(f"largest distance between the curves: {deviation(before, res.curve).max_distance:.4f}")

# %%
fig = figure(before, compare=res.curve, labels=("before", "after"), tol=tol,
             title="Eck & Hadenfeld's method on a disturbed arc")
