"""Distributions of the measures behind ``curvefair check``'s thresholds on real files.

Run: ``PYTHONPATH=src python benchmarks/calibrate_check.py [--out FILE.json]``.

Every record of every file under tests/data/real (the CAD/SVG/airfoil corpus and the committed
fonts) plus DejaVuSans (matplotlib's copy; a-z, A-Z, 0-9) is measured as ``curvefair check``
measures it (``curvefair._check``): the tangent angle at every regular join (degrees), the
relative curvature jump at every join whose angle is at most the kink threshold and whose
sides are both curved (``check`` does not G2-test a line beside a curve), the gap
between consecutive inflections over the arc length, and the scale-free Sapidis-Farin
bad-point measure at every breakpoint. It prints quantiles per source kind (fonts / other)
and how many findings each threshold candidate would give; docs/benchmarks.md quotes the run.
"""

from __future__ import annotations

import argparse
import json
import os
import time
import warnings
from pathlib import Path

import numpy as np

from curvefair import analyze, read_curves
from curvefair._check import (
    THRESHOLDS,
    _angle,
    _arc,
    _kvec,
    _regular,
    _side_derivatives,
    _straight_segments,
)

ROOT = Path(__file__).resolve().parents[1] / "tests" / "data" / "real"
FONT_EXT = {".ttf", ".otf", ".ufo", ".glyphs", ".designspace"}


def measures(rec):
    curve = rec.curve
    pp = curve.piecewise
    br = np.asarray(pp.breaks, dtype=float)
    m = len(br) - 1
    a = analyze(curve)
    L = float(a.arc_length)
    d1r, d2r, d1l, d2l = _side_derivatives(pp)
    outline = rec.source.get("outline")
    closed = curve.closed or (outline is not None and outline.closed and m > 1)
    joins = [(k - 1, k) for k in range(1, m)] + ([(m - 1, 0)] if closed else [])
    width = float(br[-1] - br[0])
    straight = _straight_segments(pp)
    ang, g2 = [], []
    for left, right in joins:
        if not _regular(d1l[left], d1r[right], width, L):
            continue
        t = _angle(d1l[left], d1r[right])
        ang.append(t)
        if straight[left] or straight[right]:
            continue  # a line beside a curve: G1 by design, not G2-tested by check
        kl, kr = _kvec(d1l[left], d2l[left]), _kvec(d1r[right], d2r[right])
        sc = max(float(np.linalg.norm(kl)), float(np.linalg.norm(kr)), 1.0 / L if L > 0 else 0)
        g2.append((t, float(np.linalg.norm(kr - kl)) / sc if sc > 0 else 0.0))
    ip = np.sort(np.asarray(a.inflection_params, dtype=float))
    gaps = []
    if ip.size >= 2 and L > 0:
        uu, s = _arc(pp, ip)
        gaps = list(np.diff(np.interp(ip, uu, s)) / L)
    z = []
    if len(a.sapidis):
        ju = np.asarray(a.jump_params, dtype=float)
        d1, d2 = pp.evaluate(ju, 1), pp.evaluate(ju, 2)
        kap = np.array([float(np.linalg.norm(_kvec(x, y))) for x, y in zip(d1, d2, strict=True)])
        zz = np.asarray(a.sapidis, dtype=float) / (kap ** 2 + (1.0 / L ** 2 if L > 0 else 0.0))
        reg = np.array([_regular(d1l[(j - 1) % m], d1r[j % m], width, L)
                        for j in np.asarray(a.jump_indices, dtype=int)], dtype=bool)
        z = list(np.where(reg & np.isfinite(zz), zz, 0.0))
    return ang, g2, gaps, z


def files():
    out = []
    for p in sorted(ROOT.rglob("*")):
        if p.suffix.lower() in (".txt", ".md") or p.name.startswith("LICENSE") or \
                p.name.startswith("OCCT_") or (p.is_dir() and p.suffix != ".ufo"):
            continue
        if any(q.suffix == ".ufo" for q in p.parents):
            continue
        out.append(p)
    try:
        import matplotlib
        dv = Path(matplotlib.__file__).parent / "mpl-data" / "fonts" / "ttf" / "DejaVuSans.ttf"
        if dv.is_file():
            out.append(dv)
    except ImportError:
        pass
    return out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=None)
    args = ap.parse_args()
    data: dict[str, dict[str, list]] = {k: {"ang": [], "g2": [], "gap": [], "z": [],
                                            "curves": [0], "files": []} for k in ("font", "other")}
    t0 = time.process_time()
    for p in files():
        kind = "font" if p.suffix.lower() in FONT_EXT else "other"
        glyphs = None
        if p.name == "DejaVuSans.ttf":
            glyphs = [chr(c) for c in range(ord("a"), ord("z") + 1)] + \
                [chr(c) for c in range(ord("A"), ord("Z") + 1)] + \
                ["zero", "one", "two", "three", "four", "five", "six", "seven", "eight", "nine"]
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                recs = read_curves(p, on_unsupported="skip",
                                   **({"glyphs": glyphs} if glyphs else {}))
        except Exception as exc:  # noqa: BLE001 - a calibration run lists what it skipped
            print(f"skip {p.name}: {type(exc).__name__}: {str(exc)[:80]}")
            continue
        d = data[kind]
        d["files"].append(p.name)
        for r in recs:
            try:
                ang, g2, gaps, z = measures(r)
            except Exception as exc:  # noqa: BLE001
                print(f"skip {p.name} {r.name}: {type(exc).__name__}")
                continue
            d["ang"] += ang
            d["g2"] += g2
            d["gap"] += gaps
            d["z"] += z
            d["curves"][0] += 1
    print(f"CPU {time.process_time() - t0:.1f} s")
    q = [0.5, 0.9, 0.95, 0.99, 0.999]
    summary = {}
    for kind, d in data.items():
        ang = np.array(d["ang"])
        g2 = np.array([r for t, r in d["g2"] if t <= THRESHOLDS["kink_angle"]])
        gap = np.array(d["gap"])
        z = np.array(d["z"])
        s = {"files": len(d["files"]), "curves": d["curves"][0], "joins": int(ang.size)}
        print(f"== {kind}: {s['files']} files, {s['curves']} curves, {ang.size} joins")
        for name, arr, cands in (
                ("join angle (deg)", ang, [0.01, 0.05, 0.1, 0.5, 1.0, 2.0, 10.0]),
                ("g2 rel jump (joins <= kink)", g2, [0.05, 0.1, 0.2, 0.5]),
                ("inflection gap / L", gap, [0.005, 0.01, 0.02, 0.05]),
                ("bad-point z", z, [100, 500, 1000, 5000, 20000])):
            if arr.size == 0:
                print(f"  {name}: none")
                continue
            qs = np.quantile(arr, q)
            low = name.startswith("inflection")
            counts = {c: int(np.sum(arr < c) if low else np.sum(arr > c)) for c in cands}
            print(f"  {name}: n={arr.size} quantiles {dict(zip(q, np.round(qs, 6), strict=True))}")
            print(f"     {'below' if low else 'above'}: {counts}")
            s[name] = {"n": int(arr.size),
                       "quantiles": dict(zip(map(str, q), qs.tolist(), strict=True)),
                       "counts": {str(k): v for k, v in counts.items()}}
        if True:
            nz = ang[(ang > 0)]
            if nz.size:
                hist, edges = np.histogram(np.log10(nz), bins=np.arange(-12, 3.01, 1))
                s["angle_log10_hist"] = dict(zip([f"1e{int(e)}" for e in edges[:-1]],
                                                 hist.tolist(), strict=True))
                print("  nonzero join angles per decade (deg):", s["angle_log10_hist"])
                print("  exactly 0:", int(np.sum(ang == 0)))
        summary[kind] = s
    if args.out:
        Path(args.out).write_text(json.dumps(summary, indent=1))


if __name__ == "__main__":
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    main()
