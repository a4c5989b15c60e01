"""The whole ``fair()`` call: its fixed costs against one csaps fit, and the Hermite step cost.

Seeded data as in ``bench_bspline_e2e.py``: ``N`` samples ``(t, 20 sin(t/7) + 50 sin(t/31))``
at ``t = 0, 1, ...`` plus Gaussian noise 0.05.

Table 1 (per size): one csaps fit of the points (``csaps.CubicSmoothingSpline(t, P.T,
smooth=0.5)``, best of ``--repeat``), the whole ``fair(interpolate_bspline(P), "eck-hadenfeld",
tol=0.02)`` call, and the pieces of its fixed cost timed one by one on the same curves, as
``fair()`` runs them: the before and after analysis (``fairness_figures`` of a fresh copy: a
planar B-spline's span forms made range by range; a 3-D result's power form built together with
the difference curve's), the joins plan, ``enforce_tolerance`` (the deviation certificate on
the difference curve: for a planar result its power form is made there), the point report and
``report.to_dict()`` (JSON-ready, what the CLI's ``--report`` pays). Ratios are against the csaps
fit measured in the same run.

Table 1b (``--methods``): the whole call ``fair(interpolate_bspline(P), m, tol=0.02)`` of each
B-spline method ``m`` with its default options (best of ``--repeat``, each on a fresh copy of the
curve), against one csaps fit measured in the same run (the goal: at most one csaps fit for
every B-spline method, at most 0.5x for the default, ``global``).

Table 2: ``fair(interpolate_cubic(P), "poliakoff", tol=0.005, eps=0, max_steps=s,
guard=False)`` for two step counts; the marginal cost of a step is the difference over the
difference of the steps taken, and its ratio to the smallest size's is printed (goal: within
1.5x). ``guard=False``: the never-worse guard re-analyses the curve only when a result has more
extrema than the input, which depends on where the run stops, not on the step count (with it,
the shorter run can cost more than the longer one).

Usage::

    python benchmarks/bench_call_cost.py 1e3 1e4 1e5 1e6 --repeat 3
    python benchmarks/bench_call_cost.py 1e6 --repeat 2 --skip-hermite --skip-table1 \
        --methods eck-hadenfeld knot-removal cheng-yu global
"""

from __future__ import annotations

import argparse
import time
from typing import Any

import numpy as np

import curvefair as cf
from curvefair.analysis import fairness_figures
from curvefair.fairing import joins as _joins
from curvefair.fairing import point_report
from curvefair.fairing._tolerance import enforce_tolerance, prime_power_forms


def data(n: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    t = np.arange(n, dtype=float)
    pts = np.c_[t, 20.0 * np.sin(t / 7.0) + 50.0 * np.sin(t / 31.0)]
    return t, pts + 0.05 * rng.normal(size=pts.shape)


CLOCK = time.perf_counter


def best(f: Any, repeat: int) -> tuple[float, Any]:
    out, tb = None, float("inf")
    for _ in range(repeat):
        t0 = CLOCK()
        out = f()
        tb = min(tb, CLOCK() - t0)
    return tb, out


def fresh(c: Any) -> Any:
    """The same curve without its cached power form."""
    if hasattr(c, "control_points"):
        return c.replace(control_points=np.array(c.control_points))
    return type(c)(np.array(c.points), np.array(c.tangents), c.params, closed=c.closed)


def after_analysis(c: Any, new: Any) -> Any:
    f = fresh(new)
    if f.dim == 3:  # as fair(): a 3-D result's form and the difference form in one pass
        prime_power_forms(c, f)
    return fairness_figures(f)


def enforce_primed(c: Any, new: Any) -> float:
    """Time of ``enforce_tolerance`` as fair() calls it (a 3-D result: given the primed
    difference form, whose making is counted in the after-analysis)."""
    f = fresh(new)
    pr = prime_power_forms(c, f) if f.dim == 3 else None
    t0 = CLOCK()
    enforce_tolerance(c, f, 0.02, primed=pr)
    return CLOCK() - t0


def table1(sizes: list[int], repeat: int) -> None:
    from csaps import CubicSmoothingSpline

    print("Table 1: fair(interpolate_bspline(P), 'eck-hadenfeld', tol=0.02), seconds "
          f"(best of {repeat}); x = ratio to one csaps fit in the same run")
    hdr = (f"{'n':>9} {'csaps':>8} {'fair()':>8} {'x':>6} {'analysis x2':>11} {'joins':>7} "
           f"{'enforce':>8} {'pt rep':>7} {'to_dict':>8} {'fixed':>7} {'fixed x':>7}")
    print(hdr)
    for n in sizes:
        t, P = data(n)
        tc, _ = best(lambda t=t, P=P: CubicSmoothingSpline(t, P.T, smooth=0.5), repeat)
        c = cf.interpolate_bspline(P)
        cf.fair(cf.interpolate_bspline(P[:200]), "eck-hadenfeld", tol=0.02)  # warm
        tf, res = best(lambda c=c: cf.fair(fresh(c), "eck-hadenfeld", tol=0.02), repeat)
        new = res.curve
        ta0, _ = best(lambda c=c: fairness_figures(fresh(c)), repeat)
        ta1, _ = best(lambda c=c, new=new: after_analysis(c, new), repeat)
        tj, _ = best(lambda c=c: _joins.plan(c, ("g0", "g0"), frozenset(),
                                             _joins.DEFAULT_G1_ANGLE, 0.02), repeat)
        te = min(enforce_primed(c, new) for _ in range(repeat))
        tp, _ = best(lambda c=c, new=new: point_report(c, new), repeat)
        td, _ = best(lambda res=res: res.report.to_dict(), repeat)
        fixed = ta0 + ta1 + tj + te + tp
        print(f"{n:>9} {tc:8.3f} {tf:8.3f} {tf / tc:6.2f} {ta0 + ta1:11.3f} {tj:7.3f} "
              f"{te:8.3f} {tp:7.3f} {td:8.3f} {fixed:7.3f} {fixed / tc:7.2f}", flush=True)
    print("fixed = analysis x2 + joins + enforce + point report (to_dict only when a JSON file "
          "is asked for)")


def table1b(sizes: list[int], methods: list[str], repeat: int) -> None:
    from csaps import CubicSmoothingSpline

    print(f"\nTable 1b: fair(interpolate_bspline(P), m, tol=0.02), default options, seconds "
          f"(best of {repeat}); x = ratio to one csaps fit in the same run")
    print(f"{'n':>9} {'csaps':>8}" + "".join(f" {m:>14} {'x':>6}" for m in methods))
    for m in methods:  # compile / warm each method first (long curves take other paths)
        for w in (300, 20_000):
            cf.fair(cf.interpolate_bspline(data(w)[1]), m, tol=0.02)
    for n in sizes:
        t, P = data(n)
        tc, _ = best(lambda t=t, P=P: CubicSmoothingSpline(t, P.T, smooth=0.5), repeat)
        c = cf.interpolate_bspline(P)
        line = f"{n:>9} {tc:8.3f}"
        for m in methods:
            tf, _ = best(lambda c=c, m=m: cf.fair(fresh(c), m, tol=0.02), repeat)
            line += f" {tf:14.3f} {tf / tc:6.2f}"
        print(line, flush=True)


def table2(sizes: list[int], steps: tuple[int, int], repeat: int) -> None:
    s0, s1 = steps
    print(f"\nTable 2: fair(interpolate_cubic(P), 'poliakoff', tol=0.005, eps=0, max_steps=s, "
          f"guard=False), seconds (best of {repeat})")
    print(f"{'n':>9} {'s=' + str(s0):>9} {'s=' + str(s1):>9} {'steps':>11} {'re-runs':>8} "
          f"{'us/step':>8} {'x smallest':>10}")
    # compile / warm the Hermite kernels first (else the first call carries the compilation)
    _, Pw = data(300)
    cf.fair(cf.interpolate_cubic(Pw), "poliakoff", tol=0.005, eps=0.0, max_steps=50)
    base = None
    for n in sizes:
        _, P = data(n)
        c = cf.interpolate_cubic(P)
        r = []
        for s in (s0, s1):
            ts, res = best(lambda c=c, s=s: cf.fair(c, "poliakoff", tol=0.005, eps=0.0,
                                                    max_steps=s, guard=False), repeat)
            r.append((ts, res))
        reruns = [x[1].report.get("curve_tolerance", {}).get("reruns") for x in r]
        taken = [int(x[1].report["steps"]) for x in r]
        # the marginal cost over the steps actually taken (a tolerance may stop a run early)
        marg = ((r[1][0] - r[0][0]) / (taken[1] - taken[0]) * 1e6 if taken[1] > taken[0]
                else float("nan"))
        base = marg if base is None else base
        print(f"{n:>9} {r[0][0]:9.3f} {r[1][0]:9.3f} {str(taken):>11} {str(reruns):>8} "
              f"{marg:8.2f} {marg / base:10.2f}", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("sizes", nargs="*", default=["1e3", "1e4", "1e5", "1e6"])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--steps", type=int, nargs=2, default=(500, 2500))
    ap.add_argument("--skip-hermite", action="store_true")
    ap.add_argument("--skip-bspline", action="store_true")
    ap.add_argument("--skip-table1", action="store_true")
    ap.add_argument("--methods", nargs="*", default=[],
                    help="B-spline methods whose whole call table 1b times against csaps")
    ap.add_argument("--cpu", action="store_true",
                    help="process CPU time instead of wall time (a loaded machine)")
    args = ap.parse_args()
    global CLOCK
    if args.cpu:
        CLOCK = time.process_time
        print("times are process CPU seconds (--cpu)")
    sizes = [int(float(s)) for s in args.sizes]
    if not args.skip_bspline and not args.skip_table1:
        table1(sizes, args.repeat)
    if not args.skip_bspline and args.methods:
        table1b(sizes, args.methods, args.repeat)
    if not args.skip_hermite:
        table2(sizes, tuple(args.steps), args.repeat)


if __name__ == "__main__":
    main()
