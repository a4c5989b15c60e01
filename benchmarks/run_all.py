"""Run every speed benchmark in turn (``make bench``); each prints its own table.

Each script measures curvefair against a peer in the same run (scipy's CubicSpline, csaps,
ezdxf, bare matplotlib) and prints ratios. Pass ``--quick`` for small sizes only, or
``--sizes 1e3,1e6`` (``make bench SIZES=1e3,1e6``) to run every size-taking script at those
sizes (``bench_bspline_e2e.py``, one size per run, at the largest; ``--only NAME,...`` to run
some scripts only).
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
    ["bench_knot_removal.py", "--sizes", "1000", "10000", "100000", "1000000",
     "--old-max", "100000"],
    ["bench_bspline_e2e.py"],
    ["bench_call_cost.py", "--cpu"],  # CPU time: the machines are shared
    ["bench_io.py"],
    ["bench_cli_vs_fair.py"],
    ["bench_plot.py"],
    ["bench_dxf_entities.py", "1000", "10000", "--cpu"],  # entity counts: not given --sizes
    ["bench_scale.py", "--sizes", "1e6", "1e7"],
    ["bench_certificate.py", "--sizes", "1e5", "1e6", "1e7"],
    ["bench_airfoil_files.py", "--airfoils", "240"],  # a corpus, not a size: not given --sizes
]
# how each script takes sizes: "pos" positional, "--sizes" an option, "--n" one size (largest)
SIZE_ARG = {"bench_analyze.py": "pos", "bench_fair_step.py": "--sizes",
            "bench_bspline_eh_steps.py": "--sizes", "bench_cheng_yu.py": "--sizes",
            "bench_knot_removal.py": "--sizes", "bench_bspline_e2e.py": "--n",
            "bench_call_cost.py": "pos", "bench_io.py": "--sizes", "bench_plot.py": "pos",
            "bench_cli_vs_fair.py": "--sizes", "bench_scale.py": "--sizes",
            "bench_certificate.py": "--sizes"}


def with_sizes(cmd: list[str], sizes: list[int]) -> list[str]:
    """``cmd`` with its own size arguments replaced by ``sizes``."""
    how = SIZE_ARG.get(cmd[0])
    if how is None:
        return cmd
    out = [cmd[0]]
    rest = cmd[1:]
    i = 0
    while i < len(rest):  # drop the script's own sizes
        a = rest[i]
        if a in ("--sizes", "--n"):
            i += 1
            while i < len(rest) and not rest[i].startswith("--"):
                i += 1
            continue
        if how == "pos" and not a.startswith("--") and (i == 0 or not rest[i - 1].startswith("--")):
            i += 1
            continue
        out.append(a)
        i += 1
    vals = [str(v) for v in sizes]
    if how == "pos":
        return [out[0], *vals, *out[1:]]
    if how == "--n":
        return [*out, "--n", str(max(sizes))]
    return [*out, "--sizes", *vals]
QUICK = [
    ["bench_analyze.py", "1e3", "1e4", "1e5", "--repeat", "3"],
    ["bench_fair_step.py", "--sizes", "1000", "100000", "--repeat", "3"],
    ["bench_bspline_eh_steps.py", "--sizes", "1000", "100000", "--steps", "300000",
     "--repeat", "1"],
    ["bench_cheng_yu.py", "--sizes", "1000", "100000", "--steps", "10000", "--repeat", "1"],
    ["bench_knot_removal.py", "--sizes", "1000", "10000", "--repeat", "1"],
    ["bench_bspline_e2e.py", "--n", "100000"],
    ["bench_call_cost.py", "1e3", "1e4", "--repeat", "1", "--cpu"],
    ["bench_io.py", "--sizes", "1000", "10000"],
    ["bench_cli_vs_fair.py", "--sizes", "10000"],
    ["bench_certificate.py", "--sizes", "1e4", "1e5", "--repeat", "1"],
    ["bench_plot.py", "1e3", "--repeat", "1"],
    ["bench_dxf_entities.py", "100", "--cpu"],
    ["bench_scale.py", "--sizes", "1e4", "1e5", "--methods", "eck-hadenfeld", "poliakoff"],
    ["bench_airfoil_files.py", "--airfoils", "30"],
]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="small sizes only")
    ap.add_argument("--sizes", default="", help="comma-separated sizes, e.g. 1e3,1e6")
    ap.add_argument("--only", default="", help="comma-separated script names")
    args = ap.parse_args()
    failed = []
    cmds = QUICK if args.quick else FULL
    if args.only:
        names = {n if n.endswith(".py") else n + ".py" for n in args.only.split(",") if n}
        cmds = [c for c in cmds if c[0] in names]
    if args.sizes:
        sizes = [int(float(v)) for v in args.sizes.split(",") if v.strip()]
        cmds = [with_sizes(c, sizes) for c in cmds]
    for cmd in cmds:
        print(f"\n=== {' '.join(cmd)}", flush=True)
        rc = subprocess.call([sys.executable, str(HERE / cmd[0]), *cmd[1:]])
        if rc:
            failed.append(cmd[0])
    if failed:
        print(f"\nfailed: {', '.join(failed)}")
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
