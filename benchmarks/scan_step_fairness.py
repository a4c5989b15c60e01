"""Scan STEP files: does default fairing ever add curvature extrema or inflections?

For every ``.stp``/``.step`` file given (default: tests/data/real/occt/), each free B-spline
edge read by :func:`curvefair.io.read_curves` is faired with ``fair()``'s defaults (the CLI's
method choice) at tolerances relative to the file's bounding-box diagonal (and with no
tolerance, the CLI's default), with and without the never-worse guard; the faired records are
written back into a copy of the file, read again with OCC, and counted on what was read back
(what a user gets). Each file runs in its own process with a time limit.

    PYTHONPATH=src python benchmarks/scan_step_fairness.py [FILES...] [--timeout 300]
        [--rel 1e-3 1e-2 none]

Prints one line per (file, edge, tolerance): inflections and extrema before, after the method
alone (guard off), after fair() (guard on) and after the write/read-back; ``WORSE`` marks a
count above the input's.
"""

from __future__ import annotations

import argparse
import glob
import multiprocessing as mp
import os
import sys
import tempfile
import time
import traceback
import warnings


def _counts(curve):
    from curvefair import analyze

    a = analyze(curve)
    return int(a.inflections), int(a.extrema)


def _scan_file(path, rels, methods, q):
    try:
        warnings.simplefilter("ignore")
        import numpy as np

        from curvefair import fair
        from curvefair.io import read_curves, write_curves

        recs = read_curves(path, on_unsupported="skip")
        rows = []
        if not recs:
            q.put((path, rows, None))
            return
        pts = [np.asarray(r.curve.control_points if hasattr(r.curve, "control_points")
                          else r.curve.points) for r in recs]
        allp = np.vstack([np.c_[q, np.zeros((len(q), 3 - q.shape[1]))] for q in pts])
        diag = float(np.linalg.norm(allp.max(0) - allp.min(0)))
        for method, rel in [(m, r) for m in methods for r in rels]:
            tol = None if rel is None else rel * diag
            faired = []
            for r in recs:
                row = {"file": os.path.basename(path), "edge": r.name, "rel": rel, "tol": tol,
                       "degree": getattr(r.curve, "degree", None),
                       "n_ctrl": getattr(r.curve, "n_ctrl", None)}
                row["before"] = _counts(r.curve)
                t = time.perf_counter()
                raw = fair(r.curve, method, tol=tol, protect=r.corners, guard=False)
                row["method"] = raw.report.get("method")
                row["raw"] = _counts(raw.curve)
                res = fair(r.curve, method, tol=tol, protect=r.corners)
                row["time"] = time.perf_counter() - t
                row["guarded"] = _counts(res.curve)
                row["guard"] = dict(res.report.get("guard", {}))
                row["joins"] = {k: v for k, v in dict(res.report.get("joins", {})).items()
                                if not isinstance(v, (list, tuple)) or len(v) < 20}
                faired.append(r.with_curve(res.curve))
                rows.append(row)
            with tempfile.TemporaryDirectory() as d:
                out = os.path.join(d, os.path.basename(path))
                try:
                    write_curves(out, faired, template=path, tol=tol)
                    back = read_curves(out, on_unsupported="skip")
                    by = {b.name: b for b in back}
                    for row in rows[-len(recs):]:
                        b = by.get(row["edge"])
                        row["disk"] = _counts(b.curve) if b is not None else None
                except Exception as exc:  # a refused write is a finding, not a crash
                    for row in rows[-len(recs):]:
                        row["disk"] = f"write failed: {type(exc).__name__}: {exc}"[:120]
        q.put((path, rows, None))
    except Exception:
        q.put((path, [], traceback.format_exc()))


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("files", nargs="*")
    ap.add_argument("--timeout", type=float, default=300.0)
    ap.add_argument("--rel", nargs="*", default=["1e-3", "1e-2", "none"])
    ap.add_argument("--methods", nargs="*", default=["default"],
                    help="fair() methods; 'default' is the curve type's default (the CLI's)")
    args = ap.parse_args(argv)
    files = args.files or sorted(glob.glob("tests/data/real/occt/*.stp")
                                 + glob.glob("tests/data/real/occt/*.step"))
    rels = [None if s.lower() == "none" else float(s) for s in args.rel]
    methods = [None if m == "default" else m for m in args.methods]
    ctx = mp.get_context("spawn")
    n_worse = n_rows = 0
    for f in files:
        q = ctx.Queue()
        p = ctx.Process(target=_scan_file, args=(f, rels, methods, q))
        t0 = time.perf_counter()
        p.start()
        try:
            path, rows, err = q.get(timeout=args.timeout)
        except Exception:
            p.kill()
            print(f"{f}: TIMEOUT after {args.timeout:g} s")
            continue
        p.join()
        if err:
            print(f"{f}: ERROR\n{err}")
            continue
        print(f"{f}: {len(rows)} rows in {time.perf_counter() - t0:.1f} s")
        for r in rows:
            n_rows += 1
            b = r["before"]
            flags = []
            for key in ("raw", "guarded", "disk"):
                v = r.get(key)
                if isinstance(v, tuple) and (v[0] > b[0] or v[1] > b[1]):
                    flags.append(f"{key}-WORSE")
            if any(k != "raw-WORSE" for k in flags):
                n_worse += 1
            rel = "none" if r["rel"] is None else f"{r['rel']:g}"
            print(f"  {r['edge']:>7} p={r['degree']} n={r['n_ctrl']:>3} rel={rel:>5} "
                  f"{r['method']:>13} infl/extr before {b} raw {r['raw']} "
                  f"guarded {r['guarded']} disk {r['disk']} "
                  f"guard={r['guard'].get('kept')} {r['time']:.2f}s {' '.join(flags)}")
    print(f"rows {n_rows}, worse after guard or on disk: {n_worse}")
    return 1 if n_worse else 0


if __name__ == "__main__":
    sys.exit(main())
