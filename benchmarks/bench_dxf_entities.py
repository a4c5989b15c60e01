"""A DXF with many entities: curvefair's read -> fair -> write against ezdxf's own read + write.

The file is built with ezdxf (seeded): ``N`` entities in the model space, alternately a cubic
``SPLINE`` by control points (12 control points on a noisy arc, clamped uniform knots) and an
``LWPOLYLINE`` of 40 vertices on a noisy sine. Timed, best of ``--repeat``, in the same run:

- peer: ``ezdxf.readfile(src).saveas(dst)`` (parse and write back, no curve built);
- curvefair: ``read_curves(src, polylines=True)``, ``fair(record.curve, tol=TOL)`` for every
  record (default method of each curve type), ``write_curves(dst, faired, template=src)``
  (which reads the file back and checks it), each part and the whole;
- with ``--cli``: ``curvefair fair src -o dst --tol TOL --polylines`` as a subprocess (its
  start-up included; since session 42 it shares a long file's curves with worker processes,
  one per core: ``curvefair._records``; the Python columns stay on one process).

The polylines are noisy samples of a curve, so they are read as point data (``polylines=True``;
since session 28 DXF polylines are drawn shapes, left as drawn, by default).

The issue's goal (issue 14) is the whole at most 2x the peer at 10,000 entities.

Usage::

    python benchmarks/bench_dxf_entities.py 1000 10000 --repeat 1 [--cli]
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import subprocess
import sys
import tempfile
import time
from typing import Any

import numpy as np

import curvefair as cf

CLOCK = time.perf_counter
TOL = 0.01


def build(path: str, n: int, seed: int = 0) -> None:
    import ezdxf

    rng = np.random.default_rng(seed)
    doc = ezdxf.new("R2010")
    msp = doc.modelspace()
    for k in range(n):
        x0, y0 = 30.0 * (k % 100), 30.0 * (k // 100)
        if k % 2 == 0:
            a = np.linspace(0.0, 2.5, 12)
            P = np.c_[x0 + 10 * np.cos(a), y0 + 10 * np.sin(a)] + 0.05 * rng.normal(size=(12, 2))
            knots = np.r_[[0.0] * 4, np.arange(1.0, 9.0), [9.0] * 4]
            msp.add_open_spline([tuple(p) for p in P], degree=3, knots=knots.tolist())
        else:
            t = np.linspace(0.0, 20.0, 40)
            P = np.c_[x0 + t, y0 + np.sin(t / 3) * 4] + 0.02 * rng.normal(size=(40, 2))
            msp.add_lwpolyline([tuple(p) for p in P])
    doc.saveas(path)


def best(f: Any, repeat: int) -> tuple[float, Any]:
    out, tb = None, float("inf")
    for _ in range(repeat):
        t0 = CLOCK()
        out = f()
        tb = min(tb, CLOCK() - t0)
    return tb, out


def ours(src: str, dst: str) -> tuple[float, float, float]:
    t0 = CLOCK()
    recs = cf.read_curves(src, polylines=True)
    t1 = CLOCK()
    faired = [dataclasses.replace(r, curve=cf.fair(r.curve, tol=TOL).curve) for r in recs]
    t2 = CLOCK()
    cf.write_curves(dst, faired, template=src, overwrite=True)
    t3 = CLOCK()
    return t1 - t0, t2 - t1, t3 - t2


def main() -> None:
    import ezdxf

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("sizes", nargs="*", type=int, default=[1000, 10000])
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--cli", action="store_true", help="also time the CLI (subprocess)")
    ap.add_argument("--cpu", action="store_true",
                    help="process CPU time instead of wall time (a loaded machine; the CLI "
                    "column then counts the child's CPU time)")
    args = ap.parse_args()
    global CLOCK
    if args.cpu:
        CLOCK = time.process_time
    d = tempfile.mkdtemp()
    if args.cpu:
        print("times are process CPU seconds (--cpu)")
    print(f"DXF, N entities (half SPLINE, half LWPOLYLINE), tol={TOL}, seconds (best of "
          f"{args.repeat}); x = ratio to ezdxf readfile + saveas in the same run")
    print(f"{'N':>7} {'ezdxf r+w':>10} {'read':>8} {'fair':>8} {'write':>8} {'total':>8} "
          f"{'x':>6}" + (f" {'cli':>8} {'x':>6}" if args.cli else ""))
    # warm the compiled kernels on a small file first
    small = os.path.join(d, "warm.dxf")
    build(small, 4)
    ours(small, os.path.join(d, "warm_out.dxf"))
    for n in args.sizes:
        src = os.path.join(d, f"e{n}.dxf")
        build(src, n)
        tp, _ = best(lambda src=src: ezdxf.readfile(src).saveas(os.path.join(d, "peer.dxf")),
                     args.repeat)
        parts = [ours(src, os.path.join(d, "ours.dxf")) for _ in range(args.repeat)]
        tr, tf, tw = min(parts, key=sum)
        tot = tr + tf + tw
        line = (f"{n:>7} {tp:10.3f} {tr:8.3f} {tf:8.3f} {tw:8.3f} {tot:8.3f} "
                f"{tot / tp:6.2f}")
        if args.cli:
            def cli(src: str = src) -> None:
                out = os.path.join(d, "cli.dxf")
                if os.path.exists(out):
                    os.remove(out)
                subprocess.run([sys.executable, "-m", "curvefair", "fair", src, "-o", out,
                                "--tol", str(TOL), "--polylines"], check=False,
                               capture_output=True)
            if args.cpu:  # the child's CPU time
                tc = float("inf")
                for _ in range(args.repeat):
                    c0 = os.times()
                    cli()
                    c1 = os.times()
                    tc = min(tc, (c1.children_user - c0.children_user)
                             + (c1.children_system - c0.children_system))
            else:
                tc, _ = best(cli, args.repeat)
            line += f" {tc:8.3f} {tc / tp:6.2f}"
        print(line, flush=True)


if __name__ == "__main__":
    main()
