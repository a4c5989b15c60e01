"""The curve certificate of a Hermite fairing call: piece by piece against the whole form.

A Hermite method certifies the whole curve's deviation after each loop run (and ``fair()``
once more at the end): ``max_t |a(t) - b(t)|`` with its certified upper bound, ``a`` the input
and ``b`` the result on the same parameters. Timed here, best of ``--repeat``, on the
chord-length cubic (``--quintic``: quintic) spline through ``bench_scale.py``'s data and a
copy whose points and derivatives are moved by about 0.01:

- ``whole form``: the difference curve's power form, then :func:`curvefair.deviation`
  against the zero curve (``fairing._tolerance.delta_deviation``: what the certificate did
  before session 33, and still does with a non-finite coefficient);
- ``by piece``: :func:`curvefair.analysis.hermite_delta_deviation` (one compiled pass that
  forms, bounds and samples each piece; two threads from 50,000 pieces).

The two give the same figures bit for bit (checked on every run).

Usage::

    python benchmarks/bench_hermite_certificate.py --sizes 1e6 1e7 [--quintic] [--repeat 3]
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from bench_scale import data

import curvefair as cf
from curvefair.analysis import hermite_delta_deviation
from curvefair.fairing._tolerance import delta_deviation


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", type=float, nargs="+", default=[1e5, 1e6])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--quintic", action="store_true")
    args = ap.parse_args()
    small = cf.interpolate_quintic(data(400)) if args.quintic else cf.interpolate_cubic(data(400))
    hermite_delta_deviation(small, np.asarray(small.points) + 1e-3,
                            tuple(np.asarray(d) for d in small._derivs))  # compiled (cached)
    print(f"{'n':>10} {'whole form s':>13} {'by piece s':>11} {'ratio':>7}")
    for size in args.sizes:
        n = int(size)
        P = data(n)
        c = cf.interpolate_quintic(P) if args.quintic else cf.interpolate_cubic(P, "chord")
        del P
        rng = np.random.default_rng(1)
        pts = np.asarray(c.points) + 0.01 * rng.normal(size=c.points.shape)
        ders = [np.asarray(d) + 0.01 * rng.normal(size=d.shape) for d in c._derivs]
        names = ("d1", "d2") if args.quintic else ("tangents",)
        tw = tp = float("inf")
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            delta = {"points": pts - c.points}
            delta.update({k: d - e for k, d, e in zip(names, ders, c._derivs, strict=True)})
            ref = delta_deviation(c, delta)
            del delta
            t1 = time.perf_counter()
            got = hermite_delta_deviation(c, pts, tuple(ders))
            t2 = time.perf_counter()
            if got != (ref.max_distance, ref.upper_bound, ref.param):
                raise SystemExit(f"n={n}: the figures differ: {got} vs {ref}")
            tw, tp = min(tw, t1 - t0), min(tp, t2 - t1)
        print(f"{n:>10} {tw:13.3f} {tp:11.3f} {tw / tp:6.1f}x")


if __name__ == "__main__":
    main()
