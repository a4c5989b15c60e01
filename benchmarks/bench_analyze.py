"""Speed of :func:`curvefair.analyze` against building the same curve with scipy's CubicSpline.

For each size ``n`` a seeded noisy planar curve (a sine arc plus Gaussian noise of 1/10 of the
point spacing, chord-length parameters) is interpolated by :func:`curvefair.interpolate_cubic`;
the benchmark times

* ``scipy.interpolate.CubicSpline(t, pts, bc_type="natural", axis=0)`` on the same
  parameters and points (the peer), and
* ``curvefair.analyze(curve)`` on a FRESH curve each repeat (so the curve's cached power form,
  ``curve.piecewise``, is built inside the timed call), and
* ``analyze`` again on the same curve (power form cached) for reference.

Both are measured in the same run, interleaved, ``--repeat`` times; the table shows the best and
the median of each and the ratios analyze / CubicSpline. The compiled kernels are warmed up on
a small curve first (numba compiles or loads its cache once per process).

Usage::

    python benchmarks/bench_analyze.py                 # sizes 1e3 1e4 1e5 1e6
    python benchmarks/bench_analyze.py 1e6 --repeat 9
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np
from scipy.interpolate import CubicSpline

import curvefair as cf


def make_points(n: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    x = np.linspace(0.0, 20.0, n)
    spacing = x[1] - x[0]
    pts = np.c_[x, np.sin(x)]
    return pts + 0.1 * spacing * rng.standard_normal((n, 2))


def bench(n: int, repeat: int) -> dict[str, float]:
    pts = make_points(n)
    base = cf.interpolate_cubic(pts)
    t = np.array(base.params)
    t_cs: list[float] = []
    t_an: list[float] = []
    t_cached: list[float] = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        CubicSpline(t, pts, bc_type="natural", axis=0)
        t_cs.append(time.perf_counter() - t0)
        fresh = cf.CubicHermite(base.points, base.tangents, base.params)
        t0 = time.perf_counter()
        cf.analyze(fresh)
        t_an.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        cf.analyze(fresh)
        t_cached.append(time.perf_counter() - t0)
    return {
        "cs_min": min(t_cs), "cs_med": statistics.median(t_cs),
        "an_min": min(t_an), "an_med": statistics.median(t_an),
        "cached_min": min(t_cached),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("sizes", nargs="*", type=float, default=[1e3, 1e4, 1e5, 1e6])
    ap.add_argument("--repeat", type=int, default=7)
    args = ap.parse_args()
    cf.analyze(cf.interpolate_cubic(make_points(50)))  # warm up the compiled kernels
    print(f"{'n':>9} {'CubicSpline s':>14} {'analyze s':>11} {'ratio(best)':>12} "
          f"{'ratio(median)':>14} {'analyze, pp cached s':>21}")
    for size in args.sizes:
        n = int(size)
        r = bench(n, args.repeat)
        print(f"{n:>9d} {r['cs_min']:>14.4f} {r['an_min']:>11.4f} "
              f"{r['an_min'] / r['cs_min']:>12.2f} {r['an_med'] / r['cs_med']:>14.2f} "
              f"{r['cached_min']:>21.4f}")


if __name__ == "__main__":
    main()
