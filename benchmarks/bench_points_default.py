"""Which method should fair point data by default at large sizes (issue 13)?

Usage (from the repository root)::

    PYTHONPATH=src python benchmarks/bench_points_default.py [--sizes 20000 100000]
        [--noise 0.1 0.5] [--tools points-l1 poliakoff csaps]

For each size ``n`` and noise level (sigma as a multiple of the mean point spacing): ``n``
noisy samples of a planar spiral arc (r = 1 + s/2, theta = 6 s: curvature monotone, so the
true curve has no curvature extremum and no inflection), ``tol = 4 sigma``. Each tool runs in
a fresh child process (peak resident memory of that process, CPU seconds of the call):

- ``points-l1``, ``poliakoff``: ``fair(interpolate_cubic(P, "chord", "natural"), method,
  tol=tol)``, the call a user makes (kernels compiled on a small list first, outside the
  timing);
- ``csaps``: ``csaps.csaps`` bisected on its smoothing parameter (on ``log10((1 - p) / p)``)
  for the smoothest fit whose values at the data parameters stay within ``tol`` of the points;
  the time is that of one fit (``smooth=0.5``), the peer's unit.

Counted like a reader of the written file: curvature extrema and inflections of the
chord-length natural cubic through the written points (``curvefair.analyze``, exact sign
counts), the largest move of a point over ``tol``.
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import resource
import time

import numpy as np
from _child import in_child


def _data(n: int, noise: float) -> tuple[np.ndarray, float]:
    rng = np.random.default_rng(n)
    s = np.sort(rng.uniform(0.0, 1.0, n))
    s[0], s[-1] = 0.0, 1.0
    th = 6.0 * s
    r = 1.0 + 0.5 * s
    pts = np.c_[r * np.cos(th), r * np.sin(th)]
    length = float(np.sum(np.linalg.norm(np.diff(pts, axis=0), axis=1)))
    sigma = noise * length / (n - 1)
    return pts + rng.normal(0.0, sigma, pts.shape), 4.0 * sigma


def _counts(q: np.ndarray) -> tuple[int, int]:
    import curvefair as cf

    a = cf.analyze(cf.interpolate_cubic(q, "chord", "natural"))
    return int(a.extrema), int(a.inflections)


def _run(tool: str, n: int, noise: float, q: mp.Queue) -> None:
    import curvefair as cf

    pts, tol = _data(n, noise)
    info = ""
    if tool == "csaps":
        import csaps

        u = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))]
        t0 = time.process_time()
        csaps.csaps(u, pts.T, smooth=0.5)
        dt = time.process_time() - t0

        def p_of(s: float) -> float:
            return 1.0 / (1.0 + 10.0 ** s)

        lo, hi, fits = -25.0, 5.0, 0
        while hi - lo > 0.01 and fits < 60:
            mid = 0.5 * (lo + hi)
            fits += 1
            qq = csaps.csaps(u, pts.T, u, smooth=p_of(mid)).T
            if np.sqrt(np.sum((qq - pts) ** 2, axis=1)).max() > tol:
                hi = mid
            else:
                lo = mid
        out = csaps.csaps(u, pts.T, u, smooth=p_of(lo)).T
        info = f"{fits} fits bisected"
    else:
        cf.fair(cf.interpolate_cubic(pts[:200], "chord", "natural"), tool, tol=tol)
        curve = cf.interpolate_cubic(pts, "chord", "natural")
        t0 = time.process_time()
        res = cf.fair(curve, tool, tol=tol)
        dt = time.process_time() - t0
        out = np.asarray(res.curve.points)
        info = f"stop {res.report['stop_reason']}"
    dev = float(np.sqrt(np.sum((out - pts) ** 2, axis=1)).max()) / tol
    ext, inf = _counts(out)
    q.put((dt, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0, ext, inf, dev,
           info))


def measure(tool: str, n: int, noise: float) -> tuple:
    return in_child(_run, tool, n, noise)  # type: ignore[no-any-return]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", type=int, nargs="+", default=[20_000, 100_000])
    ap.add_argument("--noise", type=float, nargs="+", default=[0.1, 0.5])
    ap.add_argument("--tools", nargs="+", default=["points-l1", "poliakoff", "csaps"])
    args = ap.parse_args()
    print("| points | noise / spacing | input extrema / inflections | tool | extrema | "
          "inflections | max move / tol | CPU s | peak RSS MiB | note |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for n in args.sizes:
        for noise in args.noise:
            pts, _ = _data(n, noise)
            e0, i0 = _counts(pts)
            for tool in args.tools:
                dt, rss, ext, inf, dev, info = measure(tool, n, noise)
                unit = " (one fit)" if tool == "csaps" else ""
                print(f"| {n:,} | {noise:g} | {e0} / {i0} | {tool} | {ext} | {inf} | "
                      f"{dev:.4f} | {dt:.2f}{unit} | {rss:.0f} | {info} |", flush=True)


if __name__ == "__main__":
    main()
