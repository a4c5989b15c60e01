"""
Noisy points within a tolerance, through a file
===============================================

A NACA 2412 upper surface aft of x = 0.09 (the 4-digit thickness and camber formulas), 41 points
rounded to 4 decimals as a coordinate file would hold them, is written to a CSV file, read back
with :func:`curvefair.read_curves`, faired with ``tol = 2e-4`` chord, and written with
:func:`curvefair.write_curves`. Reading the written file again, every point is within the
tolerance of the original: the guarantee holds for the numbers in the file, after rounding.
"""

import tempfile
from pathlib import Path

import numpy as np

import curvefair
from curvefair.plot import figure

# NACA 2412: maximum camber m = 0.02 at p = 0.4, thickness t = 0.12
m, p, t = 0.02, 0.4, 0.12
beta = np.linspace(0.6, np.pi, 41)
x = 0.5 * (1.0 - np.cos(beta))  # cosine spacing from x = 0.09 to the trailing edge
yt = 5 * t * (0.2969 * np.sqrt(x) - 0.1260 * x - 0.3516 * x**2 + 0.2843 * x**3 - 0.1015 * x**4)
yc = np.where(x < p, m / p**2 * (2 * p * x - x**2),
              m / (1 - p) ** 2 * (1 - 2 * p + 2 * p * x - x**2))
dyc = np.where(x < p, 2 * m / p**2 * (p - x), 2 * m / (1 - p) ** 2 * (p - x))
theta = np.arctan(dyc)
upper = np.column_stack([x - yt * np.sin(theta), yc + yt * np.cos(theta)])
upper = np.round(upper, 4)

tol = 2e-4
with tempfile.TemporaryDirectory() as tmp:
    src = Path(tmp) / "naca2412_upper.csv"
    np.savetxt(src, upper, delimiter=",", fmt="%.4f", header="x,y", comments="")
    (record,) = curvefair.read_curves(src)
    res = curvefair.fair(record.curve, tol=tol)
    out = Path(tmp) / "naca2412_upper_faired.csv"
    curvefair.write_curves(out, [record.with_curve(res.curve)])
    back = np.loadtxt(out, delimiter=",", skiprows=1)

print(f"method {res.report['method']}, {res.report['steps']} steps")
moved = np.linalg.norm(back - upper, axis=1).max()
print(f"largest point move in the written file: {moved:.2e} (tol {tol:g})")
assert moved <= tol

# %%
# The curvature combs show what fairing removed: the rounding to 4 decimals makes the
# curvature of the interpolant oscillate; the faired curve keeps the shape within ``tol``.
fig = figure(record.curve, compare=res.curve, labels=("read", "faired"), tol=tol,
             title="NACA 2412 upper surface, 4 decimals, tol = 2e-4")
