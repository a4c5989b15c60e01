"""Speed of :func:`curvefair.analyze` on small curves, 2-D and 3-D, against scipy's CubicSpline.

The fixed cost of a ``fair()`` call on a short curve (a DXF polyline, a glyph contour, the
tolerance property tests' 12,000 cases) is mostly its two or three analyses. This benchmark
draws ``--cases`` seeded random curves of 6-9 points (a sine arc or an ellipse with noise,
open and closed, 2-D and 3-D: the generator of ``tests/test_tolerance_exact.py``, without its
offsets) and times, per curve, interleaved:

* ``scipy.interpolate.CubicSpline`` through the same points and parameters (the peer: the
  cheapest thing a user does with such a curve), and
* ``curvefair.analyze`` on a fresh copy of the curve (its power form built inside the call).

It prints the mean, median and 90th percentile of each per dimension, and the ratios. The
kernels are warmed up first.

Usage::

    python benchmarks/bench_analyze_small.py                  # 400 cases
    python benchmarks/bench_analyze_small.py --cases 2000
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from scipy.interpolate import CubicSpline

import curvefair as cf


def random_curve(rng: np.random.Generator, dim: int) -> tuple[np.ndarray, bool]:
    n = int(rng.integers(6, 10))
    closed = bool(rng.integers(2))
    if closed:
        th = np.linspace(0, 2 * np.pi, n, endpoint=False) + rng.uniform(-0.2, 0.2, n) * (
            2 * np.pi / n)
        p = np.c_[2.0 * np.cos(th), np.sin(th), 0.3 * np.sin(2 * th)]
    else:
        s = np.cumsum(rng.uniform(0.4, 1.0, n))
        p = np.c_[s, np.sin(s), 0.3 * np.cos(1.3 * s)]
    return p[:, :dim] + rng.choice([0.02, 0.1, 0.3]) * rng.normal(size=(n, dim)), closed


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cases", type=int, default=400)
    args = ap.parse_args()
    cf.analyze(cf.interpolate_cubic(np.c_[np.arange(8.0), np.sin(np.arange(8.0))]))
    cf.analyze(cf.interpolate_cubic(np.c_[np.arange(8.0), np.sin(np.arange(8.0)),
                                          np.cos(np.arange(8.0))]))
    print(f"{args.cases} curves per dimension, 6-9 points, open and closed")
    print("| dim | analyze mean ms | median | p90 | CubicSpline mean ms | analyze / CubicSpline "
          "(means) |")
    print("|---|---|---|---|---|---|")
    for dim in (2, 3):
        rng = np.random.default_rng(2026 + dim)
        t_an, t_cs = [], []
        for _ in range(args.cases):
            pts, closed = random_curve(rng, dim)
            bc = "periodic" if closed else "natural"
            c = cf.interpolate_cubic(pts, "chord", bc)
            fresh = c.replace(points=np.array(c.points))
            t0 = time.perf_counter()
            CubicSpline(np.asarray(c.params), np.asarray(c.points), bc_type=bc, axis=0)
            t1 = time.perf_counter()
            cf.analyze(fresh)
            t2 = time.perf_counter()
            t_cs.append(t1 - t0)
            t_an.append(t2 - t1)
        a, s = np.array(t_an) * 1e3, np.array(t_cs) * 1e3
        print(f"| {dim} | {a.mean():.3f} | {np.median(a):.3f} | {np.percentile(a, 90):.3f} | "
              f"{s.mean():.3f} | {a.mean() / s.mean():.1f} |")


if __name__ == "__main__":
    main()
