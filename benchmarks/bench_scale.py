"""Every method from 1e6 to 1e7 points: time of the whole ``fair()`` call and peak memory.

Issue 14's goal at 1e7 points: every method within 12x its own 1e6 time, the peak memory at
most 16x the input's coordinate bytes (``n * dim * 8``: 2.56 GB for 1e7 planar points).

Seeded data as in ``bench_call_cost.py``: ``(t, 20 sin(t/7) + 50 sin(t/31))`` at ``t = 0, 1,
...`` plus Gaussian noise 0.05. Each (method, size) runs in its own spawned process
(``_child.in_child``), which builds the curve the method fairs (``interpolate_bspline`` for the
B-spline methods, ``interpolate_cubic`` / ``interpolate_quintic`` for the Hermite ones) and
then calls ``fair(curve, method, tol=--tol)`` with every other option at its default, except
that the Hermite methods (a few steps per point on this data, each a local re-interpolation: at
the default threshold poliakoff takes 7 steps per point, about 5 minutes at 1e6) get
``max_steps = --hermite-steps * n`` (default 0.1 n: the same work per point at every size, so
the growth column measures the call, not a longer run). Columns:

* ``build s``: the interpolation (not part of the call);
* ``fair s``: the ``fair()`` call, process CPU seconds (``--wall`` for wall time);
* ``x10``: the growth of that time per tenfold size from the smallest size (``t / t0`` times
  ``10 n0 / n``; the goal, 12x from 1e6 to 1e7, reads as at most 12 whatever the sizes);
* ``before MB``: resident memory just before the call (interpreter, libraries, the input
  curve);
* ``peak MB``: the process's resident high-water mark during the call (``VmHWM``, reset through
  ``/proc/self/clear_refs`` just before the call);
* ``peak/in``: ``peak MB`` over the input's coordinate bytes (the whole process, the strict
  reading of the goal), ``call/in``: ``peak MB - before MB`` over them (what the call itself
  added);
* ``steps`` and ``stop``: from the report (a faster result that did less work shows here).

With ``--runs K`` every (method, size) runs in K fresh processes, one after the other, and the
row gives the median of the K times (and of the peaks), with the smallest and largest time
in ``range``: a single fresh run at 1e6 moves by 20-50 % from run to run (the state of the
machine's memory), so a growth figure needs medians.

Usage::

    python benchmarks/bench_scale.py                         # 1e6 1e7, every method
    python benchmarks/bench_scale.py --sizes 1e5 1e6 --methods eck-hadenfeld global
    python benchmarks/bench_scale.py --sizes 1e6 1e7 --methods eck-hadenfeld --runs 3
"""

from __future__ import annotations

import argparse
import gc
import time
from typing import Any

import numpy as np
from _child import in_child

BSPLINE = ("eck-hadenfeld", "global", "knot-removal", "cheng-yu")
CUBIC = ("poliakoff", "wang-cao", "kjellander")
QUINTIC = ("wang-quintic",)
METHODS = BSPLINE + CUBIC + QUINTIC


def data(n: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    t = np.arange(n, dtype=float)
    pts = np.c_[t, 20.0 * np.sin(t / 7.0) + 50.0 * np.sin(t / 31.0)]
    return pts + 0.05 * rng.normal(size=pts.shape)


def _status_kb(key: str) -> int:
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(key + ":"):
                return int(line.split()[1])
    return -1


def _reset_hwm() -> bool:
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
        return True
    except OSError:
        return False


def _run(method: str, n: int, tol: float, wall: bool, hsteps: float, q: Any) -> None:
    try:
        q.put(_measure(method, n, tol, wall, hsteps))
    except BaseException as exc:  # the parent waits on the queue: always answer
        q.put({"error": f"{type(exc).__name__}: {exc}"})


def _measure(method: str, n: int, tol: float, wall: bool, hsteps: float) -> dict[str, Any]:
    import curvefair as cf

    def build(P: np.ndarray) -> Any:
        if method in BSPLINE:
            return cf.interpolate_bspline(P)
        if method in QUINTIC:
            return cf.interpolate_quintic(P)
        # Kjellander's step is defined on uniform parameters
        return cf.interpolate_cubic(P, "uniform" if method == "kjellander" else "chord")

    small = build(data(400))
    cf.fair(small, method, tol=tol)  # kernels loaded (compiled once, cached) outside the timing
    P = data(n)
    t0 = time.perf_counter()
    c = build(P)
    t_build = time.perf_counter() - t0
    del P
    gc.collect()
    clock = time.perf_counter if wall else time.process_time
    kw = {} if method in BSPLINE else {"max_steps": max(int(hsteps * n), 1)}
    before = _status_kb("VmRSS")
    reset = _reset_hwm()
    t0 = clock()
    res = cf.fair(c, method, tol=tol, **kw)
    t_fair = clock() - t0
    peak = _status_kb("VmHWM") if reset else -1
    rep = res.report
    return {"build": t_build, "fair": t_fair, "before_mb": before / 1024.0,
            "peak_mb": peak / 1024.0, "steps": int(rep["steps"]),
            "stop": str(rep["stop_reason"]), "dim": int(c.dim),
            "max_dev": float(rep["max_deviation"])}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", nargs="+", default=["1e6", "1e7"])
    ap.add_argument("--methods", nargs="+", default=list(METHODS), choices=METHODS)
    ap.add_argument("--tol", type=float, default=0.02)
    ap.add_argument("--wall", action="store_true", help="wall time instead of process CPU time")
    ap.add_argument("--hermite-steps", type=float, default=0.1,
                    help="max_steps of the Hermite methods, per point (default 0.1)")
    ap.add_argument("--runs", type=int, default=1,
                    help="fresh processes per row; the row gives medians (default 1)")
    args = ap.parse_args()
    sizes = [int(float(s)) for s in args.sizes]
    print(f"fair(curve, method, tol={args.tol:g}), default options; "
          f"{'wall' if args.wall else 'process CPU'} seconds; one spawned process per row")
    print(f"Hermite methods: max_steps = {args.hermite_steps:g} n")
    hdr = (f"{'method':>14} {'n':>9} {'build s':>8} {'fair s':>8} {'x10':>6} {'before MB':>9} "
           f"{'peak MB':>8} {'peak/in':>8} {'call/in':>8} {'steps':>9} {'stop':>9} "
           f"{'dev/tol':>8}" + (f" {'range s':>13}" if args.runs > 1 else ""))
    print(hdr, flush=True)
    for method in args.methods:
        base = None
        for n in sizes:
            runs = [in_child(_run, method, n, args.tol, args.wall, args.hermite_steps)
                    for _ in range(max(args.runs, 1))]
            bad = [r for r in runs if "error" in r]
            if bad:
                print(f"{method:>14} {n:>9} failed: {bad[0]['error']}", flush=True)
                continue
            r = dict(runs[0])
            times = [x["fair"] for x in runs]
            for key in ("build", "fair", "before_mb", "peak_mb"):
                r[key] = float(np.median([x[key] for x in runs]))
            spread = f" {min(times):6.2f}-{max(times):6.2f}" if len(runs) > 1 else ""
            if base is None:
                base = (n, r["fair"])
                growth = "-"
            else:
                growth = f"{r['fair'] / base[1] * 10.0 * base[0] / n:.2f}"
            inp = n * r["dim"] * 8 / 2**20
            print(f"{method:>14} {n:>9} {r['build']:8.2f} {r['fair']:8.2f} {growth:>6} "
                  f"{r['before_mb']:9.0f} {r['peak_mb']:8.0f} {r['peak_mb'] / inp:8.1f} "
                  f"{(r['peak_mb'] - r['before_mb']) / inp:8.1f} {r['steps']:>9} "
                  f"{r['stop']:>9} {r['max_dev'] / args.tol:8.3f}{spread}", flush=True)
    print("goal (issue 14): x10 <= 12 from 1e6 to 1e7, peak/in <= 16")


if __name__ == "__main__":
    main()
