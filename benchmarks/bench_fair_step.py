"""Cost of one automatic fairing step vs. curve size (it must not grow with n).

Seeded noisy samples of a smooth 3-D curve (noise and tolerance proportional to the point
spacing, so every size looks the same locally), interpolated by the C2 cubic / C4 quintic spline
(chord params, natural ends). The O(n) set-up of ``fair`` (initial interpolation, ranking build)
is done once by ``local_hermite.prepare``; only the compiled loop is timed, on fresh copies of
its state, best of ``--repeat``. ``--steps`` must stay well below the smallest size so that
every size is timed in the same phase of the loop (a few steps per point at most).

Peer, measured in the same run: building scipy's ``CubicSpline`` on the same data, i.e. what a
loop that re-interpolates the whole curve after every step would pay per step.

Usage::

    python benchmarks/bench_fair_step.py --sizes 1000 10000 100000 1000000 --steps 400
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from scipy.interpolate import CubicSpline

from curvefair import interpolate_cubic, interpolate_quintic
from curvefair._kernels import hermite as _k
from curvefair.fairing.local_hermite import prepare

_MUTABLE = (0, 1, 22, 23, 24, 25, 26, 27)  # P, D and the loop state in the kernel arguments


def data(n: int, seed: int = 0) -> tuple[np.ndarray, float]:
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 20.0, n)
    spacing = 20.0 / (n - 1)
    pts = np.c_[t, np.sin(t), 0.3 * np.cos(0.7 * t)]
    return pts + 0.2 * spacing * rng.normal(size=pts.shape), spacing


def time_loop(curve, method: str, mode: str, steps: int, tol: float, repeat: int
              ) -> tuple[float, int]:
    st = prepare(curve, method=method, tol=tol, eps=0.0, max_steps=steps, clamp=("g0", "g0"),
                 protect=frozenset(), mode=mode)
    best = np.inf
    made = 0
    for _ in range(repeat):
        args = list(st["args"])
        for i in _MUTABLE:
            args[i] = args[i].copy()
        t0 = time.perf_counter()
        out = _k.drive(*args)
        dt = time.perf_counter() - t0
        made = int(out[0])
        best = min(best, dt / max(made, 1))
    return best * 1e6, made


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--sizes", type=int, nargs="+", default=[1000, 10000, 100000, 1000000])
    ap.add_argument("--steps", type=int, default=400)
    ap.add_argument("--methods", nargs="+", default=["poliakoff", "wang-cao", "wang-quintic"])
    ap.add_argument("--mode", default="spline", choices=["spline", "hermite"])
    ap.add_argument("--repeat", type=int, default=5, help="best of N")
    args = ap.parse_args()

    pts, sp = data(60)  # compile
    for m in args.methods:
        c = interpolate_quintic(pts) if m == "wang-quintic" else interpolate_cubic(pts)
        time_loop(c, m, args.mode, 5, 0.05 * sp, 1)

    print(f"mode={args.mode}  steps={args.steps}  per-step microseconds (best of {args.repeat}); "
          "ratio to the smallest size in parentheses")
    print(f"{'n':>9} " + " ".join(f"{m:>18}" for m in args.methods) + f" {'CubicSpline build':>18}")
    base: dict[str, float] = {}
    for n in args.sizes:
        pts, sp = data(n)
        cubic = interpolate_cubic(pts)
        quintic = interpolate_quintic(pts) if "wang-quintic" in args.methods else None
        row = [f"{n:>9}"]
        for m in args.methods:
            c = quintic if m == "wang-quintic" else cubic
            us, made = time_loop(c, m, args.mode, args.steps, 0.05 * sp, args.repeat)
            base.setdefault(m, us)
            row.append(f"{us:9.2f} ({us / base[m]:4.2f}x)")
        t_cs = np.inf
        params = np.asarray(cubic.params)
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            CubicSpline(params, pts, bc_type="natural", axis=0)
            t_cs = min(t_cs, time.perf_counter() - t0)
        row.append(f"{t_cs * 1e6:15.0f} us")
        print(" ".join(row), flush=True)


if __name__ == "__main__":
    main()
