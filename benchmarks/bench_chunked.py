"""Peak memory and CPU time of one long point list: chunked (curvefair.batch.fair_chunked)
against unchunked (the single-file ``curvefair fair IN -o OUT --tol T``), same input, same tol.

Each run is a fresh interpreter under GNU ``/usr/bin/time`` (peak resident set size, user +
system CPU); the chunked run uses one process (``jobs=1``) so its RSS is the whole run's.
The compiled kernels are compiled before each run (their cache is keyed by the source), so no
run pays for compiling. Input: a sine of ``n`` points with 0.003 noise, written as CSV;
both runs read through corners (``--no-corners`` / ``corner_angle=None``: noise makes a few).

    python benchmarks/bench_chunked.py --sizes 20000,100000 --unchunked-max 100000
    python benchmarks/bench_chunked.py --sizes 10000000 --unchunked-max 0 --method poliakoff

Figures go to docs/benchmarks.md (measured on a shared, loaded machine: CPU times, not wall).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
TOL = 0.01

CHUNKED = """
import sys
from curvefair.batch import fair_chunked
r = fair_chunked(sys.argv[1], sys.argv[2], tol={tol}, chunk={chunk}, jobs={jobs},
                 corner_angle=None, method={method!r})
print("max_deviation", r["max_deviation"], "chunks", r["n_chunks"], "g2", r["joins_g2_max"])
"""
UNCHUNKED = """
import sys
from curvefair.cli import main
sys.argv = ["curvefair", "fair", sys.argv[1], "-o", sys.argv[2], "--tol", "{tol}", "-q",
            "--no-corners"]
main()
"""


def _data(n: int, path: Path) -> None:
    rng = np.random.default_rng(0)
    s = np.linspace(0.0, 8.0 * np.pi * n / 1000.0, n)
    p = np.c_[s, 3.0 * np.sin(s)] + 0.003 * rng.standard_normal((n, 2))
    with open(path, "w") as f:
        f.write("x,y\n")
        for a in range(0, n, 100000):
            np.savetxt(f, p[a:a + 100000], delimiter=",", fmt="%.10g")


def _run(code: str, src: Path, out: Path) -> tuple[float, float, str]:
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    r = subprocess.run(["/usr/bin/time", "-f", "TIME %M %U %S", sys.executable, "-c", code,
                        str(src), str(out)], capture_output=True, text=True, env=env,
                       check=False)
    line = [ln for ln in r.stderr.splitlines() if ln.startswith("TIME ")][-1].split()
    if r.returncode != 0:
        raise SystemExit(f"run failed: {r.stderr[-2000:]}")
    return float(line[1]) / 1024.0, float(line[2]) + float(line[3]), r.stdout.strip()


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", default="20000,100000")
    ap.add_argument("--unchunked-max", type=int, default=100000)
    ap.add_argument("--chunk", type=int, default=5000)
    ap.add_argument("--method", default=None,
                    help="fairing method per chunk (default: fair()'s default for point data)")
    ap.add_argument("--jobs", type=int, default=1,
                    help="chunked: worker processes (1: the RSS is the whole run's; more: "
                         "the parent's only, CPU of all)")
    a = ap.parse_args()
    warm = "import numpy as np; from curvefair import fair, interpolate_cubic; " \
           "fair(interpolate_cubic(np.c_[np.arange(50.), np.sin(np.arange(50.))]), tol=.1)"

    def warm_up() -> None:  # the kernels' cache is keyed by the source: compile outside timing
        subprocess.run([sys.executable, "-c", warm], env=dict(os.environ,
                       PYTHONPATH=str(ROOT / "src")), check=True)

    warm_up()
    base_mb, base_cpu, _ = _run("import curvefair.batch, curvefair.cli", Path("-"), Path("-"))
    print(f"interpreter + import: {base_mb:.0f} MB, {base_cpu:.2f} s CPU")
    print(f"{'points':>10} {'run':>10} {'peak RSS MB':>12} {'CPU s':>8}  result")
    with tempfile.TemporaryDirectory() as tmp:
        for n in (int(float(x)) for x in a.sizes.split(",")):
            src = Path(tmp) / f"in{n}.csv"
            _data(n, src)
            cases = [("chunked", CHUNKED.format(tol=TOL, chunk=a.chunk, jobs=a.jobs,
                                                method=a.method))]
            if n <= a.unchunked_max:
                cases.append(("unchunked", UNCHUNKED.format(tol=TOL)))
            for name, code in cases:
                warm_up()
                mb, cpu, out = _run(code, src, Path(tmp) / f"out_{name}_{n}.csv")
                print(f"{n:>10} {name:>10} {mb:>12.0f} {cpu:>8.1f}  {out}", flush=True)
            src.unlink()


if __name__ == "__main__":
    main()
