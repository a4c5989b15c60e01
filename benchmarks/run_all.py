"""Run every speed benchmark in turn (``make bench``); each prints its own table.

Each script measures curvefair against a peer in the same run (scipy's CubicSpline, csaps,
ezdxf, bare matplotlib) and prints ratios. Pass ``--quick`` for small sizes only.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent

FULL = [
    ["bench_analyze.py"],
    ["bench_fair_step.py"],
    ["bench_bspline_eh_steps.py"],
    ["bench_cheng_yu.py"],
    ["bench_knot_removal.py", "--sizes", "1000", "10000", "100000", "1000000", "--old-max", "100000"],
    ["bench_bspline_e2e.py"],
    ["bench_io.py"],
    ["bench_plot.py"],
]
QUICK = [
    ["bench_analyze.py", "1e3", "1e4", "1e5", "--repeat", "3"],
    ["bench_fair_step.py", "--sizes", "1000", "100000", "--repeat", "3"],
    ["bench_bspline_eh_steps.py", "--sizes", "1000", "100000", "--steps", "300000", "--repeat", "1"],
    ["bench_cheng_yu.py", "--sizes", "1000", "100000", "--steps", "10000", "--repeat", "1"],
    ["bench_knot_removal.py", "--sizes", "1000", "10000", "--repeat", "1"],
    ["bench_bspline_e2e.py", "--n", "100000"],
    ["bench_io.py", "--sizes", "1000", "10000"],
    ["bench_plot.py", "1e3", "--repeat", "1"],
]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="small sizes only")
    args = ap.parse_args()
    failed = []
    for cmd in QUICK if args.quick else FULL:
        print(f"\n=== {' '.join(cmd)}", flush=True)
        rc = subprocess.call([sys.executable, str(HERE / cmd[0]), *cmd[1:]])
        if rc:
            failed.append(cmd[0])
    if failed:
        print(f"\nfailed: {', '.join(failed)}")
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
