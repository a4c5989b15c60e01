"""Airfoil files faired with the CLI's defaults, counted on the written file (issue 13).

Issue 13's airfoil goal is stated on what a user gets: ``curvefair fair foil.dat -o out.dat
--tol 1e-4`` (tolerance 1e-4 chord, every other option at its default), curvature extrema
counted on the file written, read back. The quality benchmark (``make bench-quality``) counts
on the curves in memory; this script writes the files.

For each UIUC airfoil of ``benchmarks/quality/corpus.airfoil_cases`` (the original ``.dat``
text from the aerosandbox wheel, copied to a temporary folder): ``read_curves``, ``fair`` of
every record with ``tol = 1e-4 chord`` and the default method, ``write_curves`` with the input
as template and reference (what the command does), read back, and ``analyze`` of every curve
read back. Rows:

* ``in memory``: the extrema of the faired curves ``fair()`` returned;
* ``written``: of the file as the command writes it (moved numbers in full float64 precision);
* ``rounded``: of the same file written with ``decimals`` = the file's own (the median number
  of decimals of its numbers), what a writer that keeps the column layout would give; a file
  the rounding puts out of tolerance is not written (``WriteCheckError``) and counted apart.

Figures: the median and 90th percentile over the airfoils of the extrema count over the
input's, how often each is worse than the input, and the inflections in all.

Usage::

    python benchmarks/bench_airfoil_files.py --airfoils 120
"""

from __future__ import annotations

import argparse
import re
import tempfile
import time
import zipfile
from pathlib import Path

import numpy as np
from quality import corpus as C

import curvefair as cf
from curvefair.io import WriteCheckError


def counts(curves: list) -> tuple[int, int]:
    """Extrema and inflections summed over a file's curves."""
    a = [cf.analyze(c) for c in curves]
    return sum(x.extrema for x in a), sum(x.inflections for x in a)


def file_decimals(text: str) -> int:
    decs = [len(m.group(1)) for m in re.finditer(r"\d\.(\d+)", text)]
    return int(np.median(decs)) if decs else 6


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--airfoils", type=int, default=120)
    ap.add_argument("--tol", type=float, default=1e-4, help="tolerance, in chords")
    args = ap.parse_args()
    cases = C.airfoil_cases(args.airfoils)
    whl = C.aerosandbox_wheel(C.CACHE)
    rows: list[dict] = []
    t0 = time.perf_counter()
    with zipfile.ZipFile(whl) as z, tempfile.TemporaryDirectory() as tmp:
        names = {Path(n).stem: n for n in z.namelist()
                 if n.endswith(".dat") and "airfoil_database" in n}
        for case in cases:
            text = z.read(names[case.name]).decode("latin-1")
            src = Path(tmp) / f"{case.name}.dat"
            src.write_text(text, encoding="latin-1")
            try:
                recs = cf.read_curves(src)
            except cf.CurvefairError as exc:
                rows.append({"name": case.name, "error": f"read: {exc}"})
                continue
            tol = args.tol * case.scale
            faired = [r.with_curve(cf.fair(r.curve, tol=tol).curve) for r in recs]
            row = {"name": case.name, "input": counts([r.curve for r in recs]),
                   "in memory": counts([f.curve for f in faired])}
            for label, dec in (("written", None), ("rounded", file_decimals(text))):
                dst = Path(tmp) / f"{case.name}.{label}.dat"
                try:
                    cf.write_curves(dst, faired, template=src, reference=recs, tol=tol,
                                    decimals=dec)
                    row[label] = counts([b.curve for b in cf.read_curves(dst)])
                except WriteCheckError:
                    row[label] = None
            rows.append(row)
    ok = [r for r in rows if "error" not in r]
    print(f"{len(cases)} UIUC airfoils, tol {args.tol:g} chord, default method "
          f"({time.perf_counter() - t0:.0f} s); {len(rows) - len(ok)} not read")
    print(f"{'counted on':>12} {'files':>6} {'median':>7} {'p90':>7} {'worse than input':>17} "
          f"{'inflections':>12} {'not written':>12}")
    print(f"{'input':>12} {len(ok):>6} {1.0:7.3f} {1.0:7.3f} {0:>17} "
          f"{sum(r['input'][1] for r in ok):>12} {'':>12}")
    for label in ("in memory", "written", "rounded"):
        good = [r for r in ok if r[label] is not None]
        ratio = np.array([r[label][0] / max(r["input"][0], 1) for r in good])
        worse = sum(r[label][0] > r["input"][0] or r[label][1] > r["input"][1] for r in good)
        print(f"{label:>12} {len(good):>6} {np.median(ratio):7.3f} "
              f"{np.percentile(ratio, 90):7.3f} {worse:>17} "
              f"{sum(r[label][1] for r in good):>12} {len(ok) - len(good):>12}")
    both = [r for r in ok if r["written"] is not None and r["rounded"] is not None]
    print(f"rounded vs written, extrema on the {len(both)} files written both ways: more on "
          f"{sum(r['rounded'][0] > r['written'][0] for r in both)}, fewer on "
          f"{sum(r['rounded'][0] < r['written'][0] for r in both)}")
    print("goal (issue 13): written median <= 0.35, p90 <= 0.7")


if __name__ == "__main__":
    main()
