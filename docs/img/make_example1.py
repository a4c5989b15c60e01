"""Regenerate docs/img/example1_poliakoff.png: Wang & Cao 2006 (seed 001), Example 1.

Seven points (i, 1), i = 1..7, with P4 moved to (4.3, 1.6); chord-length parameters and natural
ends as in the paper; faired by Poliakoff's method (the default for cubic splines) with no
tolerance. Run from the repository root::

    python docs/img/make_example1.py
"""

from pathlib import Path

import numpy as np

from curvefair import fair, interpolate_cubic
from curvefair.plot import figure

pts = np.column_stack([np.arange(1.0, 8.0), np.ones(7)])
pts[3] = (4.3, 1.6)
before = interpolate_cubic(pts, "chord", "natural")
res = fair(before, "poliakoff")
p4 = res.curve.points[3]
fig = figure(before, compare=res.curve, labels=("before", "after"),
             title=f"Wang & Cao 2006, Example 1: Poliakoff's method moves P4 from (4.3, 1.6) "
                   f"to ({p4[0]:.3f}, {p4[1]:.3f}) in {res.report['steps']} steps")
out = Path(__file__).with_name("example1_poliakoff.png")
fig.savefig(out, dpi=110)
print(out)
