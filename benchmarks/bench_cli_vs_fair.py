"""The ``curvefair fair`` command on a point CSV against the same work done in Python.

Seeded data: ``n`` samples of ``(t, sin t)``, ``t`` in [0, 20], plus Gaussian noise in y of
``--noise`` (default 0.1) times the spacing ``h = 20 / (n - 1)``, written with ``np.savetxt``
(``%.8f``, header ``x,y``) to a CSV in a temporary folder. For each size the benchmark times,
in the same run:

* ``cli``: the whole command a user runs, ``python -m curvefair fair in.csv -o out.csv --tol T``
  with ``T`` = ``--tol`` (default 1) times ``h`` (default method, default options), in a
  subprocess, after one warm-up run (numba's cache compiled); wall time, and the child's CPU
  time and peak RSS from ``resource.getrusage(RUSAGE_CHILDREN)`` (CPU: difference
  before/after; peak RSS: the largest child so far, so only a rise is meaningful). ``--cold``
  also reports the first (warm-up) run.
* ``py``: what a Python user does for the same result, in this process:
  ``read_curves(in.csv)``, ``fair(record.curve, tol=T, protect=record.corners)`` per record (the
  options the command passes by default: method None, clamp "g0", mode "spline"),
  ``write_curves(out.csv, faired, template=in.csv, reference=records, tol=T)`` (the command
  writes to a temporary file, reads it back and measures it against the records read, as
  ``write_curves`` does). The read, fair and write parts are reported on their own.
  The kernels of this process are warmed up first on a 200-point file.
* ``fair``: the bare ``fair()`` calls (the records already read).
* ``import``: ``python -c "import curvefair.cli"`` in a subprocess (the command's start-up).

The subprocesses use compiled bytecode, as an installed package does (pip compiles it at
install): where ``PYTHONDONTWRITEBYTECODE`` is set (this project's machines set it, to keep
the checkout clean), the children run without it and with ``PYTHONPYCACHEPREFIX`` in the
temporary folder, so the warm-up run writes the bytecode there and the timed runs read it
(without it every start compiles about 130 modules from source, about 0.2 s). ``--source``
keeps the environment as it is.

The output files of ``cli`` and ``py`` are compared byte for byte (``same`` column).
Ratios: cli / fair and cli / py (wall), and ``cpu cli/fair``: the command's CPU time over that of
the ``fair()`` calls (``time.process_time``, every thread of this process), the ratio that holds
when other work shares the machine.

Usage::

    python benchmarks/bench_cli_vs_fair.py                  # sizes 1e5 1e6
    python benchmarks/bench_cli_vs_fair.py --sizes 1e4 --tol 2 --cold
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np

import curvefair as cf


def spacing(n: int) -> float:
    return 20.0 / (n - 1)


def make_points(n: int, noise: float, seed: int = 0) -> np.ndarray:
    """``noise`` in units of the spacing (noise much larger than the spacing makes the
    reader's corner search scan many neighbours per point)."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 20.0, n)
    return np.c_[t, np.sin(t) + noise * spacing(n) * rng.normal(size=n)]


CHILD_ENV: dict[str, str] | None = None  # the subprocesses' environment (None: this one's)


def run_child(cmd: list[str]) -> dict[str, float]:
    """Wall time, CPU time and peak RSS (MiB, the largest child so far) of one subprocess."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                          env=CHILD_ENV)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode:
        raise SystemExit(f"{' '.join(cmd)} failed ({proc.returncode}):\n{proc.stderr}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return {"wall": wall, "cpu": cpu, "rss": after.ru_maxrss / 1024.0}


def python_user(src: str, out: str, tol: float) -> dict[str, float]:
    """read_curves + fair + write_curves with the command's default options, timed in parts."""
    t0 = time.perf_counter()
    records = cf.read_curves(src)
    t1 = time.perf_counter()
    faired = []
    fair_s = fair_cpu = 0.0
    for rec in records:
        f0 = time.perf_counter()
        c0 = time.process_time()
        res = cf.fair(rec.curve, None, tol=tol, clamp="g0", protect=sorted(rec.corners),
                      mode="spline")
        fair_s += time.perf_counter() - f0
        fair_cpu += time.process_time() - c0
        faired.append(rec.with_curve(res.curve))
    t2 = time.perf_counter()
    cf.write_curves(out, faired, template=src, reference=records, tol=tol)
    t3 = time.perf_counter()
    return {"read": t1 - t0, "fair": fair_s, "fair_cpu": fair_cpu, "fair_loop": t2 - t1,
            "write": t3 - t2,
            "total": t3 - t0, "n_curves": float(len(records))}


def bench(n: int, tol: float, noise: float, d: str, cold: bool) -> dict[str, float]:
    src = os.path.join(d, f"in{n}.csv")
    np.savetxt(src, make_points(n, noise), fmt="%.8f", delimiter=",", header="x,y",
               comments="")
    tol = tol * spacing(n)
    out_cli = os.path.join(d, f"cli{n}.csv")
    out_py = os.path.join(d, f"py{n}.csv")
    cmd = [sys.executable, "-m", "curvefair", "fair", src, "-o", out_cli, "--tol", repr(tol)]
    first = run_child(cmd)  # warm-up: numba's cache compiled or loaded
    os.remove(out_cli)
    warm = run_child(cmd)
    py = python_user(src, out_py, tol)
    with open(out_cli, "rb") as a, open(out_py, "rb") as b:
        same = a.read() == b.read()
    imp = run_child([sys.executable, "-c", "import curvefair.cli"])
    r = {"cli": warm["wall"], "cli_cpu": warm["cpu"], "rss": warm["rss"], "imp": imp["wall"],
         "same": float(same), **{f"py_{k}": v for k, v in py.items()}}
    if cold:
        r["cold"] = first["wall"]
    return r


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", nargs="*", type=float, default=[1e5, 1e6])
    ap.add_argument("--tol", type=float, default=1.0, help="in units of the spacing")
    ap.add_argument("--noise", type=float, default=0.1, help="in units of the spacing")
    ap.add_argument("--cold", action="store_true", help="also show the first (warm-up) run")
    ap.add_argument("--source", action="store_true",
                    help="children as this environment has them (PYTHONDONTWRITEBYTECODE "
                    "kept: modules compiled from source at every start)")
    args = ap.parse_args()
    global CHILD_ENV
    print(f"tol {args.tol:g} h, noise {args.noise:g} h (h: the point spacing); seconds "
          "(wall) unless noted")
    print(f"{'n':>9} {'curves':>6} {'cli_s':>8} {'cli_cpu':>8} {'rss_MiB':>8} {'fair_s':>8} "
          f"{'py_s':>8} {'read_s':>7} {'write_s':>8} {'import_s':>8} {'cli/fair':>8} "
          f"{'cli/py':>7} {'same':>5} {'fair_cpu':>8} {'cpu cli/fair':>12}"
          + (f" {'cold_s':>8}" if args.cold else ""), flush=True)
    with tempfile.TemporaryDirectory() as d:
        if not args.source and os.environ.get("PYTHONDONTWRITEBYTECODE"):
            CHILD_ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
            CHILD_ENV["PYTHONPYCACHEPREFIX"] = os.path.join(d, "pycache")
            run_child([sys.executable, "-c", "import curvefair.cli"])  # writes the bytecode
        warm = os.path.join(d, "warm.csv")  # this process's compiled kernels, loaded once
        np.savetxt(warm, make_points(200, args.noise), fmt="%.8f", delimiter=",",
                   header="x,y", comments="")
        python_user(warm, os.path.join(d, "warm_out.csv"), args.tol * spacing(200))
        for size in args.sizes:
            n = int(size)
            r = bench(n, args.tol, args.noise, d, args.cold)
            print(f"{n:>9d} {int(r['py_n_curves']):>6d} {r['cli']:>8.3f} {r['cli_cpu']:>8.3f} "
                  f"{r['rss']:>8.0f} {r['py_fair']:>8.3f} {r['py_total']:>8.3f} "
                  f"{r['py_read']:>7.3f} {r['py_write']:>8.3f} {r['imp']:>8.3f} "
                  f"{r['cli'] / r['py_fair']:>8.2f} {r['cli'] / r['py_total']:>7.2f} "
                  f"{'yes' if r['same'] else 'NO':>5} {r['py_fair_cpu']:>8.3f} "
                  f"{r['cli_cpu'] / r['py_fair_cpu']:>12.2f}"
                  + (f" {r['cold']:>8.3f}" if args.cold else ""), flush=True)


if __name__ == "__main__":
    main()
