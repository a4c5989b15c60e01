"""Bad-point measures of the papers' local loops and the B-spline structure option, on the
quality benchmark's corpora (the same cases, tolerances, start curves and metrics as
``run.py``).

Usage (from the repository root)::

    python benchmarks/quality/measures.py                 # full corpora, 2 processes
    python benchmarks/quality/measures.py --quick         # a tiny subset
    python benchmarks/quality/measures.py --only bspline  # only the B-spline rows

Rows: every Hermite method (``kjellander``, ``poliakoff``, ``wang-cao``, ``wang-quintic``)
with every value of ``fair(..., measure=...)`` it accepts, each with the method's default
``eps`` and with ``eps=0``; the B-spline methods that keep the structure (``global``,
``eck-hadenfeld``), the B-spline default (``fair(curve)`` without a method) and ``global``
with ``structure="free"`` (``--only structure``: only the last two). Prints a Markdown summary per
corpus (ground truth: true extrema / inflection counts reached, extrema - true; airfoils and
glyphs: median / p90 of the extrema ratio to the input) and writes the per-case rows to
``measures.csv`` next to this file (not committed).
"""

from __future__ import annotations

import argparse
import csv
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import corpus as C  # noqa: E402
import peers as P  # noqa: E402
import run as R  # noqa: E402

import curvefair as cf  # noqa: E402

HERMITE_MEASURES = {"kjellander": ("jump", "energy", "sapidis", "move"),
                    "poliakoff": ("jump", "energy", "sapidis", "move"),
                    "wang-cao": ("jump", "energy", "sapidis", "move"),
                    "wang-quintic": ("energy", "move")}


def tools(only: str | None) -> list[tuple[str, str, dict[str, Any]]]:
    out: list[tuple[str, str, dict[str, Any]]] = []
    if only in (None, "hermite"):
        for m, ms in HERMITE_MEASURES.items():
            for meas in ms:
                out.append((f"{m}/{meas}", m, {"measure": meas}))
                out.append((f"{m}/{meas}+eps0", m, {"measure": meas, "eps": 0.0}))
    if only in (None, "bspline"):
        out += [("eck-hadenfeld", "eck-hadenfeld", {}),
                ("global", "global", {}),
                ("global/l3", "global", {"l": 3}),
                ("default(bspline)", None, {})]
    if only in (None, "bspline", "structure"):
        out += [("global/l3" if only == "structure" else "", "global", {"l": 3}),
                ("global/l3+free", "global", {"l": 3, "structure": "free"})]
        out = [o for o in out if o[0]]
    return out


_CASES: list[C.Case] = []
_TOOLS: list[tuple[str, str, dict[str, Any]]] = []


def _case(i: int) -> list[dict[str, Any]]:
    import warnings

    warnings.simplefilter("ignore")
    case = _CASES[i]
    rows = []
    base = cf.analyze(R.initial_curve("poliakoff", case.points, case.closed)[0])
    for name, method, kw in _TOOLS:
        row: dict[str, Any] = {"corpus": case.corpus, "family": case.family, "case": case.name,
                               "tool": name, "tol": case.tol, "input_extrema": int(base.extrema)}
        try:
            c0, u = R.initial_curve(method or "global", case.points, case.closed)
            t0 = time.perf_counter()
            res = cf.fair(c0, method, tol=case.tol, **kw)
            row["time_s"] = time.perf_counter() - t0
            d, _ = P.data_deviation(res.curve, case.points, u)
            row.update(ok=1, dev_over_tol=d / case.tol, steps=res.report.get("steps"),
                       stop=res.report.get("stop_reason"),
                       n_moved=res.report.get("n_moved"))
            row.update(R.metrics(case, res.curve))
            row["true_extrema"] = case.true_extrema
            row["true_inflections"] = case.true_inflections
        except Exception as exc:  # noqa: BLE001
            row.update(ok=0, error=repr(exc)[:200])
        rows.append(row)
    return rows


def summary(rows: list[dict[str, Any]], names: list[str]) -> str:
    out = []
    for corpus in ("ground-truth", "airfoils", "glyphs"):
        rs = [r for r in rows if r["corpus"] == corpus]
        if not rs:
            continue
        out.append(f"\n### {corpus} ({len({r['case'] for r in rs})} curves)\n")
        if corpus == "ground-truth":
            out.append("| tool | extrema reached | inflections reached | extrema - true "
                       "(median / p90) | max dev / tol | median steps | median ms | failed |")
            out.append("|---|---|---|---|---|---|---|---|")
        else:
            out.append("| tool | extrema / input (median / p90) | fewer than input | "
                       "max dev / tol | median steps | median ms | failed |")
            out.append("|---|---|---|---|---|---|---|")
        for t in names:
            tr = [r for r in rs if r["tool"] == t]
            ok = [r for r in tr if r.get("ok")]
            if not tr:
                continue
            fail = len(tr) - len(ok)
            mdev = max((r["dev_over_tol"] for r in ok), default=float("nan"))
            steps = np.median([r["steps"] or 0 for r in ok]) if ok else float("nan")
            ms = 1e3 * np.median([r["time_s"] for r in ok]) if ok else float("nan")
            if corpus == "ground-truth":
                he = sum(r["extrema"] == r["true_extrema"] for r in ok)
                inf = [r for r in ok if r["true_inflections"] is not None]
                hi = sum(r["inflections"] == r["true_inflections"] for r in inf)
                ex = [r["extrema"] - r["true_extrema"] for r in ok]
                out.append(f"| {t} | {he}/{len(tr)} | {hi}/{len(inf)} | {np.median(ex):.3g} / "
                           f"{np.percentile(ex, 90):.3g} | {mdev:.3g} | {steps:.0f} | {ms:.3g} "
                           f"| {fail} |")
            else:
                rat = [r["extrema"] / max(r["input_extrema"], 1) for r in ok]
                fewer = sum(r["extrema"] < r["input_extrema"] for r in ok)
                out.append(f"| {t} | {np.median(rat):.3g} / {np.percentile(rat, 90):.3g} | "
                           f"{fewer}/{len(ok)} | {mdev:.3g} | {steps:.0f} | {ms:.3g} | {fail} |")
    return "\n".join(out)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--jobs", type=int, default=min(2, os.cpu_count() or 1))
    ap.add_argument("--only", choices=("hermite", "bspline", "structure"), default=None)
    ap.add_argument("--csv", type=Path, default=HERE / "measures.csv")
    ap.add_argument("--airfoils", type=int, default=240)
    ap.add_argument("--glyphs", type=int, default=80)
    ap.add_argument("--instances", type=int, default=4,
                    help="ground-truth instances per family and noise level")
    args = ap.parse_args(argv)
    global _CASES, _TOOLS
    if args.quick:
        _CASES = (C.ground_truth_cases(instances=1, levels=(1e-3,)) + C.airfoil_cases(6)
                  + C.glyph_cases(6))
    else:
        _CASES = (C.ground_truth_cases(instances=args.instances)
                  + C.airfoil_cases(args.airfoils) + C.glyph_cases(args.glyphs))
    _TOOLS = tools(args.only)
    t0 = time.perf_counter()
    order = sorted(range(len(_CASES)), key=lambda i: -len(_CASES[i].points))
    rows: list[dict[str, Any]] = []
    import multiprocessing as mp

    with ProcessPoolExecutor(args.jobs, mp_context=mp.get_context("fork")) as ex:
        for got in ex.map(_case, order):
            rows += got
    cols: list[str] = []
    for r in rows:
        cols += [k for k in r if k not in cols]
    with open(args.csv, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=cols)
        w.writeheader()
        w.writerows(rows)
    cmd = " ".join(["python benchmarks/quality/measures.py"] + (argv if argv is not None
                                                                 else sys.argv[1:]))
    print(f"`{cmd}` ({len(_CASES)} cases, {time.perf_counter() - t0:.0f} s, "
          f"{args.jobs} processes)")
    print(summary(rows, [t for t, _, _ in _TOOLS]))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
