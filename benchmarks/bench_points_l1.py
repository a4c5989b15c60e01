"""Speed, growth and memory of ``fair(curve, "points-l1")`` against one csaps fit (issue 13).

Usage (from the repository root)::

    PYTHONPATH=src python benchmarks/bench_points_l1.py [--sizes 10000 100000 1000000]

For each size ``n``: ``n`` noisy samples of a planar curve (a spiral arc with sigma = 1e-4 of its
size), ``tol = 4 sigma``; times ``csaps.csaps(u, points.T, smooth=0.5)`` (one fit, no tuning)
and ``points_l1(points, tol)`` in the same run, each in a fresh child process for its peak
resident memory (``ru_maxrss``, the whole process: interpreter and imports included). Times
are CPU seconds of the child (``time.process_time``: the benchmark machine is shared, wall
time under load says little), wall seconds in brackets. Prints one line per size (time, ratio
to csaps, peak memory, Newton steps, reweighting rounds, attempts) and the growth ratios.
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import resource
import time

import numpy as np
from _child import in_child


def _data(n: int) -> tuple[np.ndarray, float]:
    rng = np.random.default_rng(n)
    s = np.sort(rng.uniform(0.0, 1.0, n))
    s[0], s[-1] = 0.0, 1.0
    th = 6.0 * s
    r = 1.0 + 0.5 * s
    pts = np.c_[r * np.cos(th), r * np.sin(th)]
    sigma = 1e-4 * 3.0
    return pts + rng.normal(0.0, sigma, pts.shape), 4.0 * sigma


def _run(tool: str, n: int, q: mp.Queue) -> None:
    pts, tol = _data(n)
    if tool == "csaps":
        import csaps

        u = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))]
        t0, w0 = time.process_time(), time.perf_counter()
        csaps.csaps(u, pts.T, smooth=0.5)
        dt, wt = time.process_time() - t0, time.perf_counter() - w0
        extra = ""
    else:
        from curvefair.fairing.points_l1 import points_l1

        points_l1(pts[:50], tol)  # compile / load the kernels outside the timing
        t0, w0 = time.process_time(), time.perf_counter()
        res = points_l1(pts, tol, hold=[0, n - 1])
        dt, wt = time.process_time() - t0, time.perf_counter() - w0
        dev = float(np.sqrt(((np.asarray(res.points) - pts) ** 2).sum(1)).max())
        r = res.report
        extra = (f"max dev/tol {dev / tol:.6f}, newton steps {r['newton_steps']}, rounds "
                 f"{r['rounds']}, attempts {r['attempts']}, stop {r['stop_reason']}")
    q.put((dt, wt, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0, extra))


def measure(tool: str, n: int) -> tuple[float, float, float, str]:
    return in_child(_run, tool, n)  # type: ignore[no-any-return]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", type=int, nargs="+", default=[10_000, 100_000, 1_000_000])
    args = ap.parse_args()
    times = {}
    for n in args.sizes:
        tc, wc, mc, _ = measure("csaps", n)
        tp, wp, mp_, extra = measure("points-l1", n)
        times[n] = tp
        print(f"n={n}: csaps {tc:.3f} s cpu ({wc:.3f} wall, peak {mc:.0f} MiB); points-l1 "
              f"{tp:.3f} s cpu ({wp:.3f} wall, peak {mp_:.0f} MiB), ratio {tp / tc:.1f}; "
              f"{extra}", flush=True)
    ns = sorted(times)
    for a, b in zip(ns, ns[1:], strict=False):
        print(f"growth {a} -> {b}: {times[b] / times[a]:.2f}x for {b / a:.0f}x the points")


if __name__ == "__main__":
    main()
