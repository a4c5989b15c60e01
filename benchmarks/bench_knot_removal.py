"""Sapidis-Farin knot-removal loop: steps per second, compiled loop vs the old Python loop.

Data (seeded): ``n`` points on three quarters of the unit circle with Gaussian noise of
``--rel`` times the point spacing, interpolated by ``curvefair.interpolate_bspline`` (open cubic
by default); ``knot_removal_fair(curve, variant=..., eps=0, eps_relative=False)``, i.e. the loop
runs until the sum of jumps stops decreasing (about ``n / 5`` steps at ``--rel 0.01``).

Measured in the same run, best of ``--repeat``:

* ``new``: :func:`knot_removal_fair` end to end (the vectorised per-knot set-up, the compiled loop,
  the final measure) and the compiled loop alone (``curvefair._kernels.knot_removal.kr_loop`` on
  fresh copies of its state);
* ``old``: the Python ``while`` loop that ``knot_removal_fair`` was up to session 2 (the reference
  kept in ``tests/test_knot_removal_compiled.py``), only for ``n <= --old-max``; its per-step cost
  is ``(t(full) - t(max_steps=0)) / steps`` (the same set-up and final measure subtracted).

Per step: ``us/step`` of the compiled loop should stay roughly flat in ``n`` (``O(log N)`` tree
updates, ``<= 2p + 1`` touched knots). Both loops' results are compared (steps, knot sequence,
``bitwise`` control points or the largest difference).

Usage::

    python benchmarks/bench_knot_removal.py --sizes 1000 10000 100000 1000000 --old-max 100000
"""

from __future__ import annotations

import argparse
import importlib.util
import time
from pathlib import Path

import numpy as np

from curvefair import interpolate_bspline
from curvefair._kernels import knot_removal as kk
from curvefair.fairing import knot_removal as kr
from curvefair.fairing.eck_hadenfeld import movable_mask

_REF = Path(__file__).resolve().parents[1] / "tests" / "test_knot_removal_compiled.py"


def load_reference():
    spec = importlib.util.spec_from_file_location("_kr_reference", _REF)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.reference_knot_removal_fair


def make_curve(n: int, degree: int, rel: float, seed: int = 0):
    rng = np.random.default_rng(seed)
    th = np.linspace(0.0, 1.5 * np.pi, n)
    pts = np.c_[np.cos(th), np.sin(th)]
    pts += rel * (th[1] - th[0]) * rng.normal(size=pts.shape)
    return interpolate_bspline(pts, degree=degree)


def best(f, repeat: int) -> float:
    ts = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        f()
        ts.append(time.perf_counter() - t0)
    return min(ts)


def loop_only(curve, variant: str, repeat: int) -> tuple[float, int]:
    """Time ``kr_loop`` alone on fresh copies of the state set up as knot_removal_fair does."""
    kd = kr._KnotData(curve)
    d0 = np.array(curve.control_points)
    z0 = kd.jumps(d0)
    mask = movable_mask(curve)
    args0 = kr._loop_args(curve, kd, d0.copy(), d0.copy(), mask, variant, np.inf, 0.0,
                          10 * kd.js.size, "skip", z0.copy(),
                          kr.ROUNDING_FLOOR * float(z0.max()))
    mutable = (0, 20, 21, 22, 23)  # d, z, rank, tv, ti
    ts, steps = [], 0
    for _ in range(repeat):
        args = list(args0)
        for i in mutable:
            args[i] = args0[i].copy()
        t0 = time.perf_counter()
        steps = int(kk.kr_loop(*args)[0])
        ts.append(time.perf_counter() - t0)
    return min(ts), steps


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[1000, 10000, 100000])
    ap.add_argument("--degree", type=int, default=3)
    ap.add_argument("--rel", type=float, default=0.01)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--old-max", type=int, default=10000,
                    help="run the old Python loop only up to this n")
    args = ap.parse_args()
    ref = load_reference()
    kw = {"eps": 0.0, "eps_relative": False}
    # warm up (compilation / numba cache)
    small = make_curve(200, args.degree, args.rel)
    for v in kr.VARIANTS:
        kr.knot_removal_fair(small, variant=v, **kw)
    print(f"degree {args.degree}, noise {args.rel} x spacing, best of {args.repeat}")
    print(f"{'n':>8} {'variant':>13} {'steps':>7} {'new e2e s':>10} {'loop s':>9} "
          f"{'us/step':>8} {'M steps/s':>9} | {'old e2e s':>9} {'us/step':>8} {'ratio':>7} "
          f"{'same':>8}")
    per_step: dict[str, list[tuple[int, float]]] = {v: [] for v in kr.VARIANTS}
    for n in args.sizes:
        c = make_curve(n, args.degree, args.rel)
        for v in kr.VARIANTS:
            res = kr.knot_removal_fair(c, variant=v, **kw)
            t_e2e = best(lambda: kr.knot_removal_fair(c, variant=v, **kw), args.repeat)  # noqa: B023
            t_loop, steps = loop_only(c, v, args.repeat)
            assert steps == res.steps
            us_new = 1e6 * t_loop / max(steps, 1)
            per_step[v].append((n, us_new))
            line = (f"{n:>8} {v:>13} {steps:>7} {t_e2e:>10.4f} {t_loop:>9.5f} {us_new:>8.3f} "
                    f"{steps / t_loop / 1e6:>9.2f} |")
            if n <= args.old_max:
                rep = max(1, min(args.repeat, int(2e5 // max(n, 1))))
                t0 = time.perf_counter()
                old = ref(c, variant=v, **kw)
                t_old = time.perf_counter() - t0
                if rep > 1:
                    t_old = min(t_old, best(lambda: ref(c, variant=v, **kw), rep - 1))  # noqa: B023
                t_set = best(lambda: ref(c, variant=v, max_steps=0, **kw), max(rep, 3))  # noqa: B023
                us_old = 1e6 * (t_old - t_set) / max(old.steps, 1)
                same = (old.steps == res.steps and old.stop_reason == res.stop_reason
                        and np.array_equal(old.history[:, 0], res.history[:, 0]))
                diff = np.abs(old.curve.control_points - res.curve.control_points).max()
                tag = ("bitwise" if diff == 0 else f"{diff:.0e}") if same else "DIFFERS"
                line += (f" {t_old:>9.3f} {us_old:>8.2f} {us_old / us_new:>6.0f}x {tag:>8}")
            else:
                line += f" {'-':>9} {'-':>8} {'-':>7} {'-':>8}"
            print(line, flush=True)
    for v, rows in per_step.items():
        (n0, u0), (n1, u1) = min(rows), max(rows)
        if n1 > n0:
            print(f"{v}: us/step at n = {n1} / at n = {n0}: {u1 / u0:.2f} "
                  f"(log2 n ratio {np.log2(n1) / np.log2(n0):.2f}, n ratio {n1 / n0:.0f})")


if __name__ == "__main__":
    main()
