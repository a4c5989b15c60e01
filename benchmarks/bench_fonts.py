"""Glyph outlines read from the font itself: curvefair against the input and a peer.

For each glyph contour of a TrueType font (DejaVuSans from matplotlib: quadratic ``glyf``) and
an OpenType/CFF font (the Lobster subset in tests/data/real: cubic), read with
``read_curves`` (the outline's own B-spline, not sampled points), faired with
``fair(curve, tol=T, protect=corners)`` and turned into the points that ``write_curves``
writes (``curvefair.io.fonts.record_points``: same structure, integers). Measured here, by
dense sampling of each Bezier segment (independent of curvefair's B-spline code), on the
smooth runs between corner nodes:

- ``E``: ``int kappa^2 ds`` (bending energy) relative to the input;
- curvature extrema: local extrema of the sampled ``kappa(s)`` (changes below 1e-3 of the
  run's largest ``|kappa|`` ignored);
- max deviation: largest distance between the outlines at equal parameters.

Peer at equal deviation: scipy's ``splprep`` smoothing spline (cubic, through 40 samples per
segment of each smooth run, ends fixed by weight), its smoothing factor bisected until its
largest distance from the input run equals curvefair's on that contour. The peer does not
keep the outline's structure (its number of control points is printed); it shows what a
general smoother reaches at the same deviation (on a run curvefair leaves unchanged, the peer's
figures are the input's). The "floats" column is the same fairing written without rounding to
integers (as into a UFO). What is written passes ``record_points``' never-worse guard (no
contour with more curvature extrema or more energy than its input; the run counts include
the runs it kept as they were).

Usage::

    python benchmarks/bench_fonts.py --tol 2 --glyphs a,o,S,e,g,B,R
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import time

import numpy as np
from scipy.interpolate import splev, splprep

from curvefair import fair, read_curves
from curvefair.io.fonts import record_points

M = 40


def _seg_eval(P, t):
    """Points, first and second derivatives of one Bezier segment (degree len(P)-1)."""
    P = np.asarray(P, float)
    n = len(P) - 1
    from math import comb

    def bern(k, deg):
        return comb(deg, k) * t ** k * (1 - t) ** (deg - k)

    x = sum(bern(k, n)[:, None] * P[k] for k in range(n + 1))
    D = n * np.diff(P, axis=0)
    d1 = sum(bern(k, n - 1)[:, None] * D[k] for k in range(n))
    if n >= 2:
        DD = (n - 1) * np.diff(D, axis=0)
        d2 = sum(bern(k, n - 2)[:, None] * DD[k] for k in range(n - 1))
    else:
        d2 = np.zeros_like(d1)
    return x, d1, d2


def runs(rec, pts):
    """Smooth runs of a contour written as ``pts``: lists of Bezier segments, split at the
    corner nodes (the record's held points that are on-curve nodes)."""
    c = rec.source["outline"]
    n = len(c.on)
    P = np.asarray(pts, float)
    if not any(c.on):  # implied-only TrueType contour: one closed run
        segs = []
        for i in range(n):
            a = (P[i - 1] + P[i]) / 2
            b = (P[i] + P[(i + 1) % n]) / 2
            segs.append([a, P[i], b])
        return [segs]
    from curvefair.io._outline import _node_kinds

    smooth, corners, line = _node_kinds(c)
    start = corners[0] if corners else next(k for k in range(n) if c.on[k])
    order = [(start + i) % n for i in range(n)] + [start]
    out, cur, i = [], [], 0
    while i < len(order) - 1:
        j = i + 1
        while not c.on[order[j]]:
            j += 1
        a, b = P[order[i]], P[order[j]]
        offs = [P[k] for k in order[i + 1:j]]
        if not offs:
            if cur:
                out.append(cur)
            cur = []
        elif c.quadratic and len(offs) > 1:
            mids = [(offs[m] + offs[m + 1]) / 2 for m in range(len(offs) - 1)]
            ends = [a] + mids + [b]
            for m, o in enumerate(offs):
                cur.append([ends[m], o, ends[m + 1]])
        else:
            cur.append([a, *offs, b])
        if order[j] in corners and cur:
            out.append(cur)
            cur = []
        i = j
    if cur:
        out.append(cur)
    return out


def sample_run(segs, m=M):
    t = np.linspace(0, 1, m)
    xs, es = [], []
    for S in segs:
        x, d1, d2 = _seg_eval(S, t)
        sp = np.linalg.norm(d1, axis=1)
        k = (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / np.maximum(sp, 1e-300) ** 3
        xs.append(x)
        es.append((k, sp))
    return xs, es


def energy_and_extrema(kap, speed, dt):
    E = float(np.sum(kap ** 2 * speed) * dt)
    k = np.concatenate([kap])
    scale = max(np.max(np.abs(k)), 1e-300)
    d = np.diff(k)
    d = d[np.abs(d) > 1e-3 * scale / M]
    ext = int(np.sum(np.sign(d[1:]) != np.sign(d[:-1])))
    return E, ext


def run_metrics(segs):
    xs, es = sample_run(segs)
    kap = np.concatenate([k for k, _ in es])
    sp = np.concatenate([s for _, s in es])
    E, ext = energy_and_extrema(kap, sp, 1.0 / (M - 1))
    return np.concatenate(xs), E, ext


def peer(x_in, target, n_samples):
    """splprep smoothing of the sampled input run, smoothing bisected to deviation target."""
    _, idx = np.unique(np.round(x_in, 9), axis=0, return_index=True)
    x = x_in[np.sort(idx)]
    if len(x) < 6 or target <= 0:
        return None
    w = np.ones(len(x))
    w[0] = w[-1] = 1e3
    lo, hi = 0.0, len(x) * target ** 2 * 4
    best = None
    for _ in range(30):
        s = (lo + hi) / 2
        try:
            tck, u = splprep(x.T, w=w, s=s, k=3)
        except Exception:
            hi = s
            continue
        y = np.array(splev(u, tck)).T
        dev = float(np.max(np.linalg.norm(y - x, axis=1)))
        if dev > target:
            hi = s
        else:
            lo = s
            best = (tck, u)
    if best is None:
        return None
    tck, u = best
    uu = np.linspace(0, 1, n_samples)  # the density the outlines are measured at
    d1 = np.array(splev(uu, tck, der=1)).T
    d2 = np.array(splev(uu, tck, der=2)).T
    sp = np.linalg.norm(d1, axis=1)
    kap = (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / np.maximum(sp, 1e-300) ** 3
    E = float(np.sum(kap ** 2 * sp) / (len(uu) - 1))
    d = np.diff(kap)
    scale = max(np.max(np.abs(kap)), 1e-300)
    d = d[np.abs(d) > 1e-3 * scale / M]
    return E, int(np.sum(np.sign(d[1:]) != np.sign(d[:-1]))), len(tck[1][0])


def bench(path, glyphs, tol, method=None):
    recs = read_curves(path, glyphs=glyphs, on_unsupported="skip")
    tot = {"E_in": 0.0, "E_cf": 0.0, "E_peer": 0.0, "ext_in": 0, "ext_cf": 0, "ext_peer": 0,
           "dev_cf": 0.0, "n": 0, "ctl_in": 0, "ctl_peer": 0, "t": 0.0,
           "E_fl": 0.0, "ext_fl": 0}
    for r in recs:
        t0 = time.perf_counter()
        res = fair(r.curve, method, tol=tol, protect=r.corners)
        pts = record_points(r.with_curve(res.curve), tol)
        tot["t"] += time.perf_counter() - t0
        c = r.source["outline"]
        # the same fairing written in floating point (a UFO): what the integer grid costs
        src = dict(r.source, outline=dataclasses.replace(c, grid=False))
        rf = dataclasses.replace(r, source=src)
        rf_runs = runs(rf, record_points(rf.with_curve(res.curve), tol))
        for ra, rb in zip(runs(r, c.points), runs(r, pts), strict=True):
            xa, Ea, ea = run_metrics(ra)
            xb, Eb, eb = run_metrics(rb)
            dev = float(np.max(np.linalg.norm(xb - xa, axis=1)))
            p = peer(xa, dev, M * len(ra))
            xf, Ef, ef = run_metrics(rf_runs.pop(0))
            if p is None:  # curvefair left the run as it was (deviation 0): so does the peer
                p = (Ea, ea, sum(len(s) - 1 for s in ra) + 1)
            tot["E_in"] += Ea
            tot["E_cf"] += Eb
            tot["E_peer"] += p[0]
            tot["E_fl"] += Ef
            tot["ext_fl"] += ef
            tot["ext_in"] += ea
            tot["ext_cf"] += eb
            tot["ext_peer"] += p[1]
            tot["dev_cf"] = max(tot["dev_cf"], dev)
            tot["ctl_in"] += sum(len(s) - 1 for s in ra) + 1
            tot["ctl_peer"] += p[2]
            tot["n"] += 1
    return len(recs), tot


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tol", type=float, default=2.0)
    ap.add_argument("--method", default=None, help="curvefair method (default: the default)")
    ap.add_argument("--glyphs", default="a,o,S,e,g,B,R,s,c,C,G,O,Q,two,three,eight")
    a = ap.parse_args()
    import matplotlib

    here = os.path.dirname(os.path.abspath(__file__))
    fonts = [(os.path.join(os.path.dirname(matplotlib.__file__), "mpl-data", "fonts", "ttf",
                           "DejaVuSans.ttf"), a.glyphs.split(",")),
             (os.path.join(here, "..", "tests", "data", "real", "fonttools",
                           "Lobster.subset.otf"), None)]
    print(f"method {a.method or 'default'}, tol {a.tol:g} font units; E = int kappa^2 ds "
          "summed over smooth runs, relative to the input; extrema = curvature extrema summed")
    print("| font | contours (runs) | E curvefair / input | E curvefair floats / input | "
          "E peer / input | extrema input -> curvefair / floats / peer | max dev curvefair | "
          "control points input / peer | curvefair time s |")
    print("|---|---|---|---|---|---|---|---|---|")
    for path, glyphs in fonts:
        n, t = bench(path, glyphs, a.tol, a.method)
        print(f"| {os.path.basename(path)} | {n} ({t['n']}) | {t['E_cf'] / t['E_in']:.3f} | "
              f"{t['E_fl'] / t['E_in']:.3f} | "
              f"{t['E_peer'] / t['E_in']:.3f} | {t['ext_in']} -> {t['ext_cf']} / "
              f"{t['ext_fl']} / {t['ext_peer']} | {t['dev_cf']:.3g} | "
              f"{t['ctl_in']} / {t['ctl_peer']} | "
              f"{t['t']:.2f} |")


if __name__ == "__main__":
    main()
