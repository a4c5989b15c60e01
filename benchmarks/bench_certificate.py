"""The curve certificate of a fairing call: piece by piece against the whole form.

``fair()`` certifies the whole curve's deviation from its input (a Hermite method also after
each loop run): ``max_t |a(t) - b(t)|`` with its certified upper bound, ``a`` the input and
``b`` the result on the same parameters or knots. Timed here, best of ``--repeat``, on the
chord-length cubic spline (``--curve quintic``: quintic; ``--curve bspline``: the
interpolating cubic B-spline) through ``bench_scale.py``'s data and a copy whose data
(points and derivatives, or control points) are moved by about 0.01:

- ``whole form``: the difference curve's power form, then :func:`curvefair.deviation`
  against the zero curve (``fairing._tolerance.delta_deviation``: what the certificate did
  before session 33, and still does with a non-finite coefficient);
- ``by piece``: :func:`curvefair.analysis.hermite_delta_deviation` /
  :func:`curvefair.analysis.bspline_delta_deviation` (one compiled pass that forms, bounds and
  samples each piece; two threads from 50,000 pieces).

The two give the same figures bit for bit (checked on every run).

Usage::

    python benchmarks/bench_certificate.py --sizes 1e6 1e7 [--curve cubic|quintic|bspline]
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from bench_scale import data

import curvefair as cf
from curvefair.analysis import bspline_delta_deviation, hermite_delta_deviation
from curvefair.fairing._tolerance import delta_deviation


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", type=float, nargs="+", default=[1e5, 1e6])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--curve", choices=("cubic", "quintic", "bspline"), default="cubic")
    args = ap.parse_args()
    build = {"cubic": lambda P: cf.interpolate_cubic(P, "chord"), "quintic": cf.interpolate_quintic,
             "bspline": cf.interpolate_bspline}[args.curve]
    bsp = args.curve == "bspline"

    def fields(c: cf.PiecewiseCurve) -> list[np.ndarray]:
        return [np.asarray(c.control_points)] if bsp else [np.asarray(c.points),
                                                           *map(np.asarray, c._derivs)]

    def names(c: cf.PiecewiseCurve) -> tuple[str, ...]:
        if bsp:
            return ("control_points",)
        return ("points", "d1", "d2") if args.curve == "quintic" else ("points", "tangents")

    def piece(c: cf.PiecewiseCurve, moved: list[np.ndarray]) -> object:
        if bsp:
            return bspline_delta_deviation(c, moved[0])
        return hermite_delta_deviation(c, moved[0], tuple(moved[1:]))

    small = build(data(400))
    piece(small, [f + 1e-3 for f in fields(small)])  # compiled (cached) outside the timing
    print(f"{'n':>10} {'whole form s':>13} {'by piece s':>11} {'ratio':>7}")
    for size in args.sizes:
        n = int(size)
        P = data(n)
        c = build(P)
        del P
        rng = np.random.default_rng(1)
        base = fields(c)
        moved = [f + 0.01 * rng.normal(size=f.shape) for f in base]
        tw = tp = float("inf")
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            ref = delta_deviation(c, {k: m - b for k, m, b in
                                      zip(names(c), moved, base, strict=True)})
            t1 = time.perf_counter()
            got = piece(c, moved)
            t2 = time.perf_counter()
            if got != (ref.max_distance, ref.upper_bound, ref.param):
                raise SystemExit(f"n={n}: the figures differ: {got} vs {ref}")
            tw, tp = min(tw, t1 - t0), min(tp, t2 - t1)
        print(f"{n:>10} {tw:13.3f} {tp:11.3f} {tw / tp:6.1f}x")


if __name__ == "__main__":
    main()
