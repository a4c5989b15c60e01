"""
One moved point: Wang & Cao 2006, Example 1
===========================================

Seven points :math:`(i, 1)`, :math:`i = 1, \\dots, 7`, with :math:`P_4` moved to
:math:`(4.3, 1.6)`, interpolated by a cubic Hermite spline with chord-length parameters and
natural ends, as in the paper. :func:`curvefair.fair` with Poliakoff's method (the default for
cubic splines) and no tolerance repeatedly moves the point whose curvature-derivative jump is
largest; the bump is removed, and the neighbours of :math:`P_4` move a little too (with
no tolerance every point may move).
"""

import numpy as np

from curvefair import fair, interpolate_cubic
from curvefair.plot import figure

pts = np.column_stack([np.arange(1.0, 8.0), np.ones(7)])
pts[3] = (4.3, 1.6)
before = interpolate_cubic(pts, "chord", "natural")
res = fair(before, "poliakoff")

p4 = res.curve.points[3]
print(f"P4: (4.3, 1.6) -> ({p4[0]:.4f}, {p4[1]:.4f}) in {res.report['steps']} steps")
others = np.delete(np.linalg.norm(res.curve.points - pts, axis=1), 3)
print(f"the other points moved by at most {others.max():.4f}")

# %%
# The standard figure: both curves with their curvature combs, curvature against arc
# length, and the deviation of the faired curve from the original.
fig = figure(before, compare=res.curve, labels=("before", "after"),
             title="Poliakoff's method on Wang & Cao's Example 1")
