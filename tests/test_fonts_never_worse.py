"""Fonts (issue 16): fairing never makes a written contour less fair.

The faired font is written through ``write_curves`` (TrueType: integers, smooth nodes exact),
read back with fontTools, and every contour's curvature extrema are counted here from the
file's own points, independently of curvefair: the segments as fontTools decomposes them
(``decomposeQuadraticSegment`` for TrueType runs), each sampled at 40 parameters of its
Bernstein form, curvature ``(x' y'' - x'' y') / |x'|^3`` from the hodographs, extrema = sign
changes of the successive curvature differences along each smooth run (runs split at corner
nodes -- on-curve points whose neighbours are not exactly collinear -- and at lines; the walk
starts at the first corner, else the first on-curve point; differences below 1e-3/40 of the
run's largest curvature ignored).
"""

from __future__ import annotations

from math import comb
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("fontTools")

from fontTools.pens.basePen import decomposeQuadraticSegment  # noqa: E402
from fontTools.pens.recordingPen import RecordingPen  # noqa: E402
from fontTools.ttLib import TTFont  # noqa: E402

from curvefair import fair, read_curves, write_curves  # noqa: E402
from curvefair.io.fonts import record_points  # noqa: E402

HERE = Path(__file__).parent
LOBSTER = HERE / "data" / "real" / "fonttools" / "Lobster.subset.otf"
# DejaVu glyphs whose contours got more curvature extrema before the write-side guard
DEJAVU_GLYPHS = ["three", "B", "G", "Q", "R", "S", "o", "s"]
M = 40


def _dejavu() -> Path:
    mpl = pytest.importorskip("matplotlib")
    p = Path(mpl.__file__).parent / "mpl-data" / "fonts" / "ttf" / "DejaVuSans.ttf"
    if not p.is_file():
        pytest.skip("matplotlib ships no DejaVuSans.ttf")
    return p


def file_contours(font, name):
    """[(points (n, 2), on-curve flags, quadratic)] of a glyph, from the binary's tables."""
    if "glyf" in font:
        glyf = font["glyf"]
        g = glyf[name]
        if g.isComposite() or g.numberOfContours <= 0:
            return []
        coords, ends, flags = g.getCoordinates(glyf)
        xy = np.array(coords, float)
        out, start = [], 0
        for e in ends:
            out.append((xy[start:e + 1], [bool(f & 1) for f in flags[start:e + 1]], True))
            start = e + 1
        return out
    pen = RecordingPen()
    font.getGlyphSet()[name].draw(pen)
    out, pts, on = [], [], []
    for op, args in pen.value:
        if op == "moveTo":
            pts, on = [args[0]], [True]
        elif op == "lineTo":
            pts.append(args[0])
            on.append(True)
        elif op == "curveTo":
            pts += list(args)
            on += [False, False, True]
        elif op in ("closePath", "endPath"):
            if len(pts) > 1 and tuple(pts[-1]) == tuple(pts[0]):
                pts, on = pts[:-1], on[:-1]
            out.append((np.array(pts, float), on, False))
    return out


def _is_corner(P, on, k):
    n = len(on)
    a, b = P[(k - 1) % n], P[(k + 1) % n]
    if on[(k - 1) % n] and on[(k + 1) % n]:
        return True
    u, v = P[k] - a, b - P[k]
    return not (u[0] * v[1] - u[1] * v[0] == 0 and u @ v > 0)


def smooth_runs(P, on, quadratic):
    """Lists of Bezier control polygons between corners and lines."""
    n = len(on)
    if not any(on):  # TrueType: every on-curve point implied
        offs = [tuple(p) for p in P]
        segs, prev = [], (P[-1] + P[0]) / 2
        for c, e in decomposeQuadraticSegment(offs + [tuple(prev)]):
            segs.append([prev, np.array(c), np.array(e)])
            prev = np.array(e)
        return [segs]
    corners = [k for k in range(n) if on[k] and _is_corner(P, on, k)]
    start = corners[0] if corners else on.index(True)
    order = [(start + i) % n for i in range(n + 1)]
    runs, cur, i = [], [], 0
    while i < n:
        j = i + 1
        while not on[order[j]]:
            j += 1
        a, offs, b = P[order[i]], [P[k] for k in order[i + 1:j]], P[order[j]]
        if not offs:
            if cur:
                runs.append(cur)
            cur = []
        elif quadratic:
            prev = a
            for c, e in decomposeQuadraticSegment([tuple(o) for o in offs] + [tuple(b)]):
                cur.append([prev, np.array(c), np.array(e)])
                prev = np.array(e)
        else:
            cur.append([a, *offs, b])
        if order[j] in corners and cur:
            runs.append(cur)
            cur = []
        i = j
    if cur:
        runs.append(cur)
    return runs


def _bezier_derivative(P, t, r):
    """r-th derivative of the Bezier curve with control points P at parameters t."""
    P = np.asarray(P, float)
    for _ in range(r):
        P = (len(P) - 1) * np.diff(P, axis=0)
    deg = len(P) - 1
    return sum(comb(deg, i) * (t ** i * (1 - t) ** (deg - i))[:, None] * P[i]
               for i in range(deg + 1))


def extrema(P, on, quadratic):
    t = np.linspace(0, 1, M)
    total = 0
    for run in smooth_runs(P, on, quadratic):
        ks = []
        for S in run:
            d1, d2 = _bezier_derivative(S, t, 1), _bezier_derivative(S, t, 2)
            ks.append((d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])
                      / np.linalg.norm(d1, axis=1) ** 3)
        k = np.concatenate(ks)
        d = np.diff(k)
        d = d[np.abs(d) > 1e-3 * np.abs(k).max() / M]
        total += int(np.sum(np.sign(d[1:]) != np.sign(d[:-1])))
    return total


@pytest.mark.parametrize("which", ["dejavu", "lobster"])
def test_no_written_contour_has_more_curvature_extrema(tmp_path, which):
    src, names = (_dejavu(), DEJAVU_GLYPHS) if which == "dejavu" else (LOBSTER, None)
    recs = read_curves(src, glyphs=names)
    faired = [r.with_curve(fair(r.curve, tol=2.0, protect=r.corners).curve) for r in recs]
    out = tmp_path / ("faired" + src.suffix)
    write_curves(out, faired, template=src)
    f, g = TTFont(src), TTFont(out)
    glyphs = sorted({r.source["glyph"] for r in recs})
    changed, total_in, total_out = 0, 0, 0
    for name in glyphs:
        for (p0, on0, q0), (p1, on1, _) in zip(file_contours(f, name), file_contours(g, name),
                                                strict=True):
            assert on0 == on1
            e0, e1 = extrema(p0, on0, q0), extrema(p1, on1, q0)
            assert e1 <= e0, (name, e0, e1)
            changed += not np.array_equal(p0, p1)
            total_in, total_out = total_in + e0, total_out + e1
    assert changed > 0  # something was faired and written
    # the guard is what keeps this: without it, some contour written from the same fair
    # has more extrema (counted the same way) -- the test can fail
    worse = 0
    for r, fr in zip(recs, faired, strict=True):
        c = r.source["outline"]
        pts = record_points(fr, guard=False)
        worse += extrema(pts, list(c.on), c.quadratic) > extrema(c.points, list(c.on),
                                                                 c.quadratic)
    if which == "dejavu":
        assert worse > 0


def test_cli_says_which_contours_were_written_unchanged(tmp_path):
    """The CLI's report marks a contour the guard kept (``written: "input"``); on disk it is
    the input exactly."""
    import json
    import shutil

    from click.testing import CliRunner

    from curvefair.cli import main

    shutil.copy(LOBSTER, tmp_path / "L.otf")
    res = CliRunner().invoke(main, ["fair", str(tmp_path / "L.otf"), "-o",
                                    str(tmp_path / "F.otf"), "--tol", "2", "--glyphs",
                                    "B,zero", "--report", str(tmp_path / "r.json")])
    assert res.exit_code == 0, res.output
    rep = json.loads((tmp_path / "r.json").read_text())
    f, g = TTFont(LOBSTER), TTFont(tmp_path / "F.otf")
    kept = [r["name"] for r in rep["curves"] if r.get("report", {}).get("written") == "input"]
    for r in rep["curves"]:
        name, ci = r["name"].split("#")
        p0 = file_contours(f, name)[int(ci)][0]
        p1 = file_contours(g, name)[int(ci)][0]
        assert np.array_equal(p0, p1) == (r["name"] in kept), r["name"]
    assert kept and len(kept) < len(rep["curves"])
