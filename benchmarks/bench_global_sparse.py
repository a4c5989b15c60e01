"""Global fairing with few active constraints: noisy straight lines and nearly straight curves.

Seeded data: ``N`` samples ``(t, A (20 sin(t / 7) + 50 sin(t / 31)), A 10 cos(t / 13))`` (the
first ``dim`` coordinates) at ``t = 0, 1, 2, ...`` plus Gaussian noise ``sigma`` in every
coordinate, interpolated by a cubic B-spline at ``t``; ``A = 0`` is a noisy straight line, where
few control points end on their ball (the energy of a line is 0: only the noise is removed).
For each case: the best of ``--repeat`` timed :func:`global_fair` calls (fresh curve objects,
after a warm-up), its Newton iterations, the share of active points and the path taken: whether
the active-set Newton iteration converged from the ADMM warm start or the interior point had
to take over.

Usage::

    python benchmarks/bench_global_sparse.py --n 50000
    PYTHONPATH=<other checkout>/src python benchmarks/bench_global_sparse.py  # another version
"""

from __future__ import annotations

import argparse
import importlib
import time

import numpy as np

from curvefair import BSplineCurve, interpolate_bspline

gf = importlib.import_module("curvefair.fairing.global_fair")

CASES = [  # (A, sigma, tol)
    (0.0, 0.05, 0.15), (0.0, 0.05, 0.2), (0.0, 0.05, 0.25), (0.0, 0.05, 0.3),
    (0.0, 0.01, 0.05), (0.02, 0.05, 0.2), (0.02, 0.05, 0.3), (0.02, 0.05, 0.5),
    (0.02, 0.01, 0.05), (1.0, 0.05, 0.3),
]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--n", type=int, default=50_000)
    ap.add_argument("--dims", type=int, nargs="*", default=[2, 3])
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    calls: list[tuple[int, bool]] = []
    orig = gf._active_set_newton

    def recorded(*a, **k):  # (iterations, converged) of every active-set Newton call
        out = orig(*a, **k)
        calls.append((out[2], out[3]))
        return out

    gf._active_set_newton = recorded
    print(f"n = {args.n}, threads {gf._THREADS}")
    print(f"{'dim':>3} {'A':>5} {'sigma':>6} {'tol':>5} {'time s':>7} {'iter':>5} "
          f"{'active':>7}  path")
    for dim in args.dims:
        for amp, sigma, tol in CASES:
            rng = np.random.default_rng(0)
            t = np.arange(args.n, dtype=float)
            pts = np.c_[t, amp * (20.0 * np.sin(t / 7.0) + 50.0 * np.sin(t / 31.0)),
                        amp * 10.0 * np.cos(t / 13.0)][:, :dim]
            c = interpolate_bspline(pts + sigma * rng.normal(size=pts.shape), param=t)
            gf.global_fair(c, tol=tol)  # warm-up
            best = np.inf
            for _ in range(max(args.repeat, 1)):
                cc = BSplineCurve(c.control_points, c.knots, c.degree)
                calls.clear()
                t0 = time.perf_counter()
                res = gf.global_fair(cc, tol=tol)
                best = min(best, time.perf_counter() - t0)
            path = ("Newton from the ADMM start" if calls and calls[0][1]
                    else f"interior point (Newton calls {calls})")
            print(f"{dim:>3} {amp:>5g} {sigma:>6g} {tol:>5g} {best:>7.3f} {res.iterations:>5d} "
                  f"{100 * res.active.size / args.n:>6.1f}%  {res.stop_reason}; {path}")


if __name__ == "__main__":
    main()
