"""SVG paths through svgpathtools: Bezier chains as B-splines, polylines, element write-back.

References: Bezier chains are made from known scipy B-splines by knot insertion
(``scipy.interpolate.insert``, independent of curvefair) and evaluated with svgpathtools'
own ``point``; tests/data/matplotlib_logo.svg was written by matplotlib (see
tests/data/README.md).
"""

from __future__ import annotations

import re
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.interpolate import BSpline, insert

from curvefair import (
    BSplineCurve,
    FileFormatError,
    InputError,
    MissingDependencyError,
    interpolate_cubic,
    read_curves,
    write_curves,
)
from curvefair.io import DrawnShapesLeft
from curvefair.io.svg import bezier_chain_to_bspline

spt = pytest.importorskip("svgpathtools")

DATA = Path(__file__).parent / "data"


def _beziers_of(t, c):
    """Bezier segments of a scipy cubic B-spline by inserting every interior knot to
    multiplicity 3 (scipy.interpolate.insert); returns (m, 4, 2) and the breaks."""
    tck = (np.asarray(t, float), [np.asarray(c)[:, 0], np.asarray(c)[:, 1]], 3)
    breaks = np.unique(t[3:-3])
    for b in breaks[1:-1]:
        mult = int(np.sum(tck[0] == b))
        if mult < 3:
            tck = insert(b, tck, m=3 - mult)
    cx, cy = tck[1]
    cp = np.c_[cx, cy][: len(tck[0]) - 4]
    m = len(breaks) - 1
    return np.array([cp[3 * i: 3 * i + 4] for i in range(m)]), breaks


def test_c2_chain_recovers_the_b_spline():
    t = np.r_[[0] * 4, 0.7, 1.1, 2.0, 2.2, 3.5, [4.5] * 4]
    rng = np.random.default_rng(5)
    c = rng.random((9, 2)) * 10
    P, breaks = _beziers_of(t, c)
    got = bezier_chain_to_bspline(P, closed=False)
    # all interior knots simple, the same knot spacing up to an affine map
    inner = got.knots[4:-4]
    assert len(np.unique(inner)) == len(inner) == len(breaks) - 2
    span_old = np.diff(breaks)
    span_new = np.diff(np.r_[got.knots[3], inner, got.knots[-4]])
    np.testing.assert_allclose(span_new / span_new[0], span_old / span_old[0], rtol=1e-10)
    ref = BSpline(t, c, 3)
    s = np.linspace(0, 1, 11)
    for i in range(len(breaks) - 1):
        u_old = breaks[i] + s * span_old[i]
        u_new = got.piecewise.breaks[i] + s * span_new[i]
        np.testing.assert_allclose(got(u_new), ref(u_old), atol=1e-9)
    np.testing.assert_allclose(got.control_points, c, atol=1e-9)


def test_c1_and_c0_joins_get_multiplicity_2_and_3():
    # C1 chain: a C1 spline with a double knot at 2.0
    t = np.r_[[0] * 4, 1.0, 2.0, 2.0, 3.0, [4.0] * 4]
    c = np.array([[0, 0], [1, 2], [2, 3], [3, 1], [4, 2], [5, 0], [6, 1], [7, 0]], float)
    P, _ = _beziers_of(t, c)
    got = bezier_chain_to_bspline(P, closed=False)
    _, counts = np.unique(got.knots[4:-4], return_counts=True)
    assert sorted(counts.tolist()) == [1, 1, 2]
    # a kink: segments meet at an angle
    K = np.array([[[0, 0], [1, 1], [2, 1], [3, 0]], [[3, 0], [4, 1], [5, 1], [6, 0]]], float)
    got = bezier_chain_to_bspline(K, closed=False)
    np.testing.assert_array_equal(got.knots[4:-4], [got.knots[4]] * 3)
    np.testing.assert_array_equal(got.control_points, K.reshape(-1, 2)[[0, 1, 2, 3, 5, 6, 7]])


def test_closed_c2_chain_is_periodic():
    ref = BSplineCurve(np.c_[np.cos(np.arange(7) * 0.9), np.sin(np.arange(7) * 1.1)],
                       np.cumsum(np.r_[0, 1, 1.5, 1, 2, 1, 1, 1.2]), 3, closed=True)
    pp = ref.piecewise
    from curvefair.io._common import bezier_pieces
    P = bezier_pieces(ref, "t")
    got = bezier_chain_to_bspline(P, closed=True)
    assert got.closed and got.n_ctrl == 7
    s = np.linspace(0, 1, 7)
    for i in range(pp.n_segments):
        a = got.piecewise.breaks[i] + s * got.piecewise.widths[i]
        b = pp.breaks[i] + s * pp.widths[i]
        np.testing.assert_allclose(got(a), ref(b), atol=1e-9)


def _svg(body):
    return ('<?xml version="1.0"?>\n<svg xmlns="http://www.w3.org/2000/svg" '
            'viewBox="0 0 100 100">\n' + body + "</svg>\n")


def test_read_kinds_and_svgpathtools_evaluation(tmp_path):
    p = tmp_path / "a.svg"
    p.write_text(_svg(
        '<path id="wave" d="M 10 50 C 20 20 30 20 40 50 S 60 80 70 50" stroke="red"/>\n'
        '<g transform="scale(2)"><path id="poly" d="M0,0 L10,0 L20,5 L30,0 L30,30 L0,30 Z"/>'
        '</g>\n<path id="quad" d="M 0 0 Q 5 10 10 0 T 20 0"/>\n'
        '<rect x="1" y="1" width="5" height="5"/>\n'))
    # by default the hexagon and the rectangle are drawn shapes, left as drawn
    assert [r.source["id"] for r in read_curves(p)] == ["wave", "quad"]
    recs = read_curves(p, polylines=True)
    assert [r.source["polylines"] for r in recs] == [True] * len(recs)
    by = {}
    for r in recs:
        by.setdefault(r.source["id"], []).append(r)
    (w,) = by["wave"]
    assert w.kind == "bspline" and w.source["n_subpaths"] == 1
    # the S command reflects the handle: C1 join, uniform widths -> a double knot
    assert np.unique(w.curve.knots[4:-4], return_counts=True)[1].tolist() == [2]
    path = spt.parse_path("M 10 50 C 20 20 30 20 40 50 S 60 80 70 50")
    for i, seg in enumerate(path):
        a, b = w.curve.piecewise.breaks[i: i + 2]
        for s in np.linspace(0, 1, 9):
            z = seg.point(s)
            np.testing.assert_allclose(w.curve(a + s * (b - a)), [z.real, z.imag], atol=1e-10)
    poly = by["poly"]
    assert all(r.kind == "polyline" for r in poly) and poly[0].source["transform"] is None
    assert sum(len(r.points) - 1 for r in poly) == 6      # a closed hexagon cut at its corners
    (q,) = by["quad"]
    assert q.kind == "bspline"
    qp = spt.parse_path("M 0 0 Q 5 10 10 0 T 20 0")
    a, b = q.curve.piecewise.breaks[:2]
    for s in np.linspace(0, 1, 5):
        z = qp[0].point(s)
        np.testing.assert_allclose(q.curve(a + s * (b - a)), [z.real, z.imag], atol=1e-12)


def test_real_matplotlib_svg_round_trip_and_element_write_back(tmp_path):
    src = DATA / "matplotlib_logo.svg"
    assert [r.kind for r in read_curves(src)] == ["bspline"] * 3  # the polygons as drawn
    recs = read_curves(src, polylines=True)
    kinds = [r.kind for r in recs]
    assert kinds.count("bspline") == 3 and kinds.count("polyline") >= 30
    circle = next(r for r in recs if r.kind == "bspline")
    # matplotlib's circle: 8 cubic arcs with C1 (not C2) joins
    _, counts = np.unique(circle.curve.knots[4:-4], return_counts=True)
    assert counts.tolist() == [2] * 7 and circle.source["svg_closed"]
    u = np.linspace(*circle.curve.domain, 200)
    r = np.hypot(*(circle.curve(u) - [36, 36]).T)
    assert np.abs(r - 34.2).max() < 0.02
    out = tmp_path / "same.svg"
    write_curves(out, recs, template=src)
    assert out.read_bytes() == src.read_bytes()
    # fair (here: move) one control point of the circle: only its d attribute changes
    cp = np.array(circle.curve.control_points)
    cp[5] += [0.3, 0.1]
    faired = circle.curve.replace(control_points=cp)
    new = [x.with_curve(faired) if x is circle else x for x in recs]
    write_curves(tmp_path / "f.svg", new, template=src)
    a = src.read_text().splitlines()
    b = (tmp_path / "f.svg").read_text().splitlines()
    changed = [ln for ln in b if ln not in a]
    # the subpath's text is replaced up to its last command; the line break before the
    # closing quote and the rest of the element are kept
    assert len(changed) == 1 and changed[0].lstrip().startswith("<path d=")
    assert b[b.index(changed[0]) + 1] == '" style="fill:#ffffff;"/>'
    assert len(b) == len(a) - 9
    assert len(re.findall(r"\bC\b", changed[0])) == 8
    back = read_curves(tmp_path / "f.svg", polylines=True)
    c2 = next(x for x in back if x.source["element"] == circle.source["element"])
    np.testing.assert_allclose(c2.curve(c2.curve.piecewise.breaks),
                               faired(faired.piecewise.breaks), atol=1e-6)  # 6 decimals
    assert c2.curve.knots.shape == faired.knots.shape
    # a polyline written back keeps its vertex count
    pl = next(x for x in recs if x.kind == "polyline" and len(x.points) > 100)
    moved = pl.curve.replace(points=np.array(pl.curve.points) + 0.5)
    write_curves(tmp_path / "g.svg", [x.with_curve(moved) if x is pl else x for x in recs],
                 template=src, decimals=4)
    # read the whole subpath back unsplit: the moved piece's vertices moved, the rest did not
    whole = next(x for x in read_curves(src, corner_angle=None, polylines=True)
                 if x.source["element"] == pl.source["element"])
    expect = np.array(whole.points)
    expect[list(pl.source["indices"])] = moved.points
    if whole.curve.closed:                     # the closing point repeats the first
        expect[-1] = expect[0]
    bp = next(x for x in read_curves(tmp_path / "g.svg", corner_angle=None, polylines=True)
              if x.source["element"] == pl.source["element"])
    assert len(bp.points) == len(expect)
    # 4 decimals, rounded toward the input's values (so no point moves farther than faired):
    # within one unit of the last decimal
    np.testing.assert_allclose(bp.points, expect, rtol=0, atol=1e-4)


def test_fresh_svg_from_curves(tmp_path):
    ref = BSplineCurve([[0, 0], [1, 2], [3, 3], [4, 1], [6, 0]], [0, 0, 0, 0, .4, 1, 1, 1, 1], 3)
    h = interpolate_cubic([[0, 5], [2, 6], [4, 5.5], [6, 7]])
    write_curves(tmp_path / "n.svg", [ref, h])
    back = read_curves(tmp_path / "n.svg")
    assert [b.kind for b in back] == ["bspline", "bspline"]
    for orig, b in zip([ref, h], back, strict=True):
        for i in range(orig.piecewise.n_segments):
            s = np.linspace(0, 1, 7)
            x = orig.piecewise.breaks[i] + s * orig.piecewise.widths[i]
            y = b.curve.piecewise.breaks[i] + s * b.curve.piecewise.widths[i]
            np.testing.assert_allclose(b.curve(y), orig(x), atol=1e-9)
    with pytest.raises(Exception, match="dimension|2-D"):
        write_curves(tmp_path / "3d.svg", interpolate_cubic([[0, 0, 0], [1, 1, 1], [2, 0, 1]]))


def test_arcs_are_unsupported(tmp_path):
    p = tmp_path / "arc.svg"
    p.write_text(_svg('<path id="a" d="M 0 0 A 5 5 0 0 1 10 0"/>\n'
                      '<path id="b" d="M 0 0 L 5 5 L 10 0"/>\n'))
    with pytest.raises(FileFormatError, match="Arc"):
        read_curves(p)
    with pytest.warns(UserWarning, match="Arc"):
        recs = read_curves(p, on_unsupported="skip", corner_angle=None, polylines=True)
    assert [r.source["id"] for r in recs] == ["b"]
    # the arc element stays untouched on write-back
    moved = recs[0].curve.replace(points=np.array(recs[0].curve.points) + [0, 1])
    write_curves(tmp_path / "o.svg", [recs[0].with_curve(moved)], template=p)
    text = (tmp_path / "o.svg").read_text()
    assert 'd="M 0 0 A 5 5 0 0 1 10 0"' in text and 'd="M 0,1 L 5,6 L 10,1"' in text


@pytest.mark.parametrize("text, match, line", [
    ("", "empty", None),
    ("<svg><path d='M 0 0 L 1 1'></svg>", "not well-formed", 1),
    ("<html><path d='M 0 0 L 1 1'/></html>", "not <svg>", None),
    ("<svg xmlns='http://www.w3.org/2000/svg'><path d='M 0 0 L 1 nan L 2 2'/></svg>",
     "bad path data|non-finite", None),
    ("<svg xmlns='http://www.w3.org/2000/svg'><text>1</text><rect width='0' height='1'/>"
     "</svg>", "no curves", None),
])
def test_malformed_svg(tmp_path, text, match, line):
    p = tmp_path / "bad.svg"
    p.write_text(text)
    with pytest.raises(FileFormatError, match=match) as exc:
        read_curves(p)
    assert exc.value.path == str(p) and exc.value.line == line


def test_missing_svgpathtools(tmp_path, monkeypatch):
    p = tmp_path / "a.svg"
    p.write_text(_svg('<path d="M 0 0 L 1 1 L 2 0"/>'))
    monkeypatch.setitem(sys.modules, "svgpathtools", None)
    with pytest.raises(MissingDependencyError, match=r"curvefair\[svg\]"):
        read_curves(p)



def _moveto_pieces(d):
    """The text of ``d`` cut before every moveto (test-side, by a regular expression)."""
    cuts = [m.start() for m in re.finditer("[Mm]", d)] + [len(d)]
    return [d[a:b].strip() for a, b in zip(cuts[:-1], cuts[1:], strict=False)]


def _d_span(raw, el_id):
    """Byte span of the d attribute of the <path> with id ``el_id`` (test-side regex)."""
    hits = [m for m in re.finditer(rb"<path\b[^>]*>", raw) if b'id="' + el_id + b'"' in m[0]]
    assert len(hits) == 1
    m = re.search(rb'\sd="([^"]*)"', hits[0][0])
    a = hits[0].start() + m.start(1)
    return raw[a:a + len(m[1])].decode(), a, a + len(m[1])


def _span_beziers(c):
    """Bezier points of every knot span of a cubic B-spline, from 4 scipy evaluations per
    span (the Bernstein system solved; independent of curvefair)."""
    bs = BSpline(c.knots, np.asarray(c.control_points), 3)
    brk = np.unique(c.knots[3:-3])
    s = np.array([0.0, 1 / 3, 2 / 3, 1.0])
    M = np.stack([(1 - s) ** 3, 3 * s * (1 - s) ** 2, 3 * s**2 * (1 - s), s**3], axis=1)
    out = []
    for u0, u1 in zip(brk[:-1], brk[1:], strict=False):
        u = u0 + s * (u1 - u0)
        u[-1] = np.nextafter(u1, u0)            # the span's own end (left of the knot)
        out.append(np.linalg.solve(M, bs(u)))
    return np.array(out)


@pytest.mark.parametrize("name, which", [
    ("path64/0", "end"),      # next subpath starts with a relative m: its moveto goes absolute
    ("path64/3", "mid"),
    ("path70/1", "end"),      # subpaths continued by "m0 0" pieces
    ("path98/5", "mid"),      # 23 subpaths in 124 moveto pieces, relative commands
    ("path98/20", "end"),
])
def test_untouched_subpaths_keep_their_text(tmp_path, name, which):
    """In a path with several subpaths, writing back one changed subpath leaves the text of
    every other subpath as it was (trimesh's MIL.svg: relative commands, 3 decimals), the
    file outside the d attribute byte for byte, and svgpathtools reads exactly the same
    segments for every other subpath."""
    src = DATA / "real" / "trimesh" / "MIL.svg"
    recs = read_curves(src)
    r = next(x for x in recs if x.name == name)
    j = r.source["subpath"]
    q = np.array(r.curve.control_points)
    q[-1 if which == "end" else len(q) // 2] += [0.7, -0.3]
    moved = r.curve.replace(control_points=q)
    out = tmp_path / "out.svg"
    write_curves(out, [x.with_curve(moved) if x is r else x for x in recs], template=src)
    raw0, raw1 = src.read_bytes(), out.read_bytes()
    el_id = name.split("/")[0].encode()
    d0, a0, b0 = _d_span(raw0, el_id)
    d1, a1, b1 = _d_span(raw1, el_id)
    assert raw0[:a0] == raw1[:a1] and raw0[b0:] == raw1[b1:]
    subs0 = spt.parse_path(d0).continuous_subpaths()
    subs1 = spt.parse_path(d1).continuous_subpaths()
    assert len(subs0) == len(subs1)
    for k, (s0, s1) in enumerate(zip(subs0, subs1, strict=False)):
        if k != j:
            assert list(s0) == list(s1), k            # exactly the same segments
    # the changed subpath has the new geometry, at the element's 3 decimals
    # (a segment still a line is written as L: its handles are at the thirds)
    got = np.array([[[z.real, z.imag] for z in (
        (g.start, g.control1, g.control2, g.end) if isinstance(g, spt.CubicBezier)
        else (g.start, (2 * g.start + g.end) / 3, (g.start + 2 * g.end) / 3, g.end))]
        for g in subs1[j]])
    np.testing.assert_allclose(got, _span_beziers(moved), rtol=0, atol=5e-4 + 1e-9)
    # text: the moveto pieces before and after the changed subpath's own pieces are those
    # of the input, except a relative moveto right after it when its end point moved
    p0, p1 = _moveto_pieces(d0), _moveto_pieces(d1)
    own = sum(1 for p in _piece_subpaths(d0) if p == j)
    assert _piece_subpaths(d0).index(j) == _piece_subpaths(d1).index(j)
    first = _piece_subpaths(d0).index(j)
    assert p0[:first] == p1[:first]
    after0, after1 = p0[first + own:], p1[first + 1:]
    assert len(after0) == len(after1)
    for i, (x, y) in enumerate(zip(after0, after1, strict=False)):
        if x != y:
            # the written end of the new text is not the float the relative moveto was
            # counted from (an end moved, or rounded to the element's decimals): the same
            # absolute point, the rest of the piece verbatim
            assert i == 0 and x[0] == "m" and y[0] == "M", (x, y)
            rest_x = re.sub(r"^m\s*[-+]?[\d.e-]+[\s,]*[-+]?[\d.e-]+\s*", "", x)
            rest_y = re.sub(r"^M\s*[-+]?[\d.e-]+[\s,]*[-+]?[\d.e-]+\s*(l\s*)?", "", y)
            assert rest_x == rest_y
    assert "".join(p1[first:first + 1]).count("M") == 1   # the new text of subpath j


def _piece_subpaths(d):
    """For each moveto piece of ``d``, the continuous subpath its segments belong to
    (test-side: every prefix of the text parsed by svgpathtools)."""
    cuts = [m.start() for m in re.finditer("[Mm]", d)] + [len(d)]
    ends = np.cumsum([len(s) for s in spt.parse_path(d).continuous_subpaths()])
    return [int(np.searchsorted(ends, len(spt.parse_path(d[:b])) - 1, side="right"))
            for b in cuts[1:]]


# ------------------------------------------------------------------------------------------
# session 18: rounding-level segments and vertices, open paths ending at their start
# ------------------------------------------------------------------------------------------
REAL = DATA / "real"


def _spt_subpaths(path):
    """Dense samples of every continuous subpath of every <path> element (svgpathtools
    only; no transforms in these files)."""
    paths, _ = spt.svg2paths(str(path), convert_lines_to_paths=False,
                                 convert_polylines_to_paths=False,
                                 convert_polygons_to_paths=False,
                                 convert_rectangles_to_paths=False)
    out = []
    for p in paths:
        if not len(p):
            continue
        for sub in p.continuous_subpaths():
            z = np.concatenate([np.array([g.point(t) for t in _ts(g)]) for g in sub])
            out.append(np.c_[z.real, z.imag])
    return out


def _ts(g):
    """Parameters 1/100 of a unit apart or closer along a segment (its control polygon)."""
    cps = [g.start, g.end] + [getattr(g, c) for c in ("control", "control1", "control2")
                              if hasattr(g, c)]
    if isinstance(g, spt.Arc):
        cps = [g.point(t) for t in np.linspace(0.0, 1.0, 33)]
    n = max(65, int(sum(abs(b - a) for a, b in zip(cps[:-1], cps[1:], strict=True)) * 100))
    return np.linspace(0.0, 1.0, n)


def _hausdorff(a, b):
    """Hausdorff distance of two dense sample sets (scipy), plus half the larger sample gap
    (an upper bound for the curves they sample)."""
    from scipy.spatial import cKDTree

    gap = max(float(np.linalg.norm(np.diff(x, axis=0), axis=1).max()) for x in (a, b))
    return max(cKDTree(b).query(a)[0].max(), cKDTree(a).query(b)[0].max()) + gap / 2


def test_closing_segment_of_rounding_length_is_dropped_real_logo(tmp_path, monkeypatch):
    """ezdxf's logo: relative commands closed by z leave closing segments ~1e-15 long; they
    used to give a knot of multiplicity 5 and refuse the file. Every subpath is read, a closed
    one ends exactly at its start, and a changed subpath written back reads back."""
    src = REAL / "ezdxf" / "ezdxf-logo-dark-bg.svg"
    n_sub = len(_spt_subpaths(src))
    with warnings.catch_warnings():
        warnings.simplefilter("error")   # nothing dropped or skipped; its 3 lines are noted
        warnings.filterwarnings("ignore", category=DrawnShapesLeft)
        recs = read_curves(src)
    keys = sorted({(r.source["element"], r.source["subpath"]) for r in recs
                   if r.source["tag"] == "path"})
    assert len(keys) == n_sub == 7
    curves = [r for r in recs if r.kind == "bspline"]
    assert len(curves) == 7
    for r in curves:
        assert r.source["svg_closed"]
        cp = np.asarray(r.curve.control_points)
        assert r.curve.closed or np.array_equal(cp[0], cp[-1])
        assert np.diff(np.unique(r.curve.knots)).min() > 1e-9
    # move every Bezier subpath a little and write back: the file reads back, same subpaths
    shift = np.array([0.01, -0.02])
    moved = [r.with_curve(r.curve.replace(control_points=np.asarray(r.curve.control_points)
                                          + shift)) if r.kind == "bspline" else r
             for r in recs]
    out = tmp_path / "o.svg"
    write_curves(out, moved, template=src)
    back = read_curves(out)
    assert len(back) == len(recs)
    bkeys = {(r.source["element"], r.source["subpath"]) for r in curves}
    for key, a, b in zip(keys, _spt_subpaths(src), _spt_subpaths(out), strict=True):
        # written at the element's 3 decimals (<= 7.1e-4), sampled 1/100 apart (<= 0.01)
        assert _hausdorff(a + (shift if key in bkeys else 0), b) <= 0.011, key
    # an error that remains names the file and the path element
    import curvefair.io.svg as svgmod

    def refuse(P, closed):
        raise InputError("knot refused")

    monkeypatch.setattr(svgmod, "bezier_chain_to_bspline", refuse)
    with pytest.raises(FileFormatError, match=r"<path> element 2 .*subpath 0: knot refused"
                       ) as exc:
        read_curves(src)
    assert exc.value.path == str(src)


def test_fair_real_icon_with_rounding_length_closing_segment(tmp_path):
    """simple-icons' sparkfun.svg through the CLI: written, every subpath kept, closed ones
    still closed by Z, within tol of the input (svgpathtools samples)."""
    from test_cli import cli

    (tmp_path / "in.svg").write_bytes((REAL / "simple-icons" / "sparkfun.svg").read_bytes())
    res = cli(["fair", "in.svg", "-o", "out.svg", "--tol", "0.6", "-q"], tmp_path)
    assert res.returncode == 0, res.stderr
    a, b = _spt_subpaths(tmp_path / "in.svg"), _spt_subpaths(tmp_path / "out.svg")
    assert len(a) == len(b) == 1
    assert all(_hausdorff(x, y) <= 0.6 + 0.01 for x, y in zip(a, b, strict=True))
    d_in = spt.svg2paths(str(tmp_path / "in.svg"))[1][0]["d"]
    d_out = spt.svg2paths(str(tmp_path / "out.svg"))[1][0]["d"]
    assert d_in != d_out and d_in.lower().count("z") == d_out.lower().count("z") == 1


@pytest.mark.parametrize("name, n_sub", [("simple-icons/volvo.svg", (7, 9)),
                                         ("occt/operations_image013.svg", None)])
def test_vertices_equal_up_to_rounding_real(name, n_sub):
    """Closed subpaths of straight segments whose last vertex equals the first up to float
    noise (relative commands) used to be refused as coincident points: read, every subpath."""
    src = REAL / name
    recs = read_curves(src, on_unsupported="skip", corner_angle=None, polylines=True)
    subs = {(r.source["element"], r.source["subpath"]) for r in recs}
    if n_sub is not None:
        # every subpath read but the two with arcs (skipped, kept untouched)
        assert (len(subs), len(_spt_subpaths(src))) == n_sub
    for r in recs:
        if r.kind == "polyline":
            p = np.asarray(r.points)
            step = np.abs(np.diff(p, axis=0)).max(axis=1)
            assert step.min() > 1e-9


def test_vertex_equal_up_to_rounding_dropped_with_warning(tmp_path):
    p = tmp_path / "n.svg"
    p.write_text(_svg('<polyline id="pl" points="0,0 10.1,0 10.100000000000001,0 10,5 0,7"/>'))
    with pytest.warns(UserWarning, match=r"<polyline> element 0 \(id='pl'\).*up to rounding"):
        recs = read_curves(p, corner_angle=None, polylines=True)
    assert len(recs) == 1 and np.asarray(recs[0].points).shape == (4, 2)


def test_open_path_ending_at_its_start_stays_open(tmp_path):
    """svgpathtools' path.svg: an open path (no z) whose last point is its first. Faired and
    written back it stays open (two caps, not a join), within tol."""
    from test_cli import cli

    (tmp_path / "in.svg").write_bytes((REAL / "svgpathtools" / "path.svg").read_bytes())
    res = cli(["fair", "in.svg", "-o", "out.svg", "--tol", "0.257", "-q"], tmp_path)
    assert res.returncode == 0, res.stderr
    d_in = spt.svg2paths(str(tmp_path / "in.svg"))[1][0]["d"]
    d_out = spt.svg2paths(str(tmp_path / "out.svg"))[1][0]["d"]
    assert d_in != d_out                                   # it was rewritten
    assert "z" not in d_in.lower() and "z" not in d_out.lower()
    a, b = _spt_subpaths(tmp_path / "in.svg"), _spt_subpaths(tmp_path / "out.svg")
    assert len(a) == len(b) == 1 and _hausdorff(a[0], b[0]) <= 0.257 + 0.01
    # a polyline subpath ending at its start without z, changed: written without Z too
    q = tmp_path / "pl.svg"
    q.write_text(_svg('<path id="o" d="M 0 0 L 10 0 L 10 10 L 0 10 L 0 0"/>'))
    recs = read_curves(q, corner_angle=None, polylines=True)
    moved = [r.with_curve(r.curve.replace(points=np.asarray(r.curve.points) + [0, 1]))
             for r in recs]
    write_curves(tmp_path / "pl2.svg", moved, template=q)
    d2 = spt.svg2paths(str(tmp_path / "pl2.svg"))[1][0]["d"]
    assert "z" not in d2.lower() and d2.count("L") == 4, d2


# a command after a closepath starts a new subpath at the closed one's initial point
# (SVG 1.1 sec. 8.3.3); svgpathtools joins the two into one continuous subpath
LOOP_THEN_TAIL = ("M10,10 C 60,0 110,20 160,10 C 170,60 150,110 160,160 "
                  "C 110,170 60,150 10,160 Z C 40,60 60,90 100,100 C 140,110 150,140 160,160")


def _loop_svg(tmp_path, d=LOOP_THEN_TAIL):
    src = tmp_path / "loop.svg"
    src.write_text('<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 200 200">\n'
                   f'<path id="p" d="{d}" fill="none" stroke="black"/>\n</svg>\n')
    return src


@pytest.mark.parametrize("d", [LOOP_THEN_TAIL, LOOP_THEN_TAIL.replace("Z C", "z m 0,0 C")])
def test_closepath_then_a_drawing_command_is_two_subpaths(tmp_path, d):
    """Read: the loop (closed by its Z, 4 segments with the closing line) and the tail from
    its initial point are two curves. Before, they were one open curve of 6 segments, and
    the write-back dropped the Z (the closing line became a cubic in an open subpath)."""
    recs = read_curves(_loop_svg(tmp_path, d), corner_angle=None)
    assert [r.source["subpath"] for r in recs] == [0, 1]
    loop, tail = recs
    assert loop.source["svg_closed"]        # (a corner at its start: read as an open chain)
    for u in loop.curve.domain:
        np.testing.assert_allclose(loop.curve(u), [10.0, 10.0], rtol=0, atol=1e-12)
    assert not tail.source["svg_closed"] and not tail.curve.closed
    np.testing.assert_allclose(tail.curve(tail.curve.domain[0]), [10.0, 10.0], atol=1e-12)
    np.testing.assert_allclose(tail.curve(tail.curve.domain[1]), [160.0, 160.0], atol=1e-12)


def test_closepath_then_a_drawing_command_is_written_back_with_both_subpaths(tmp_path):
    """Only the loop changed, its start point moved: the tail keeps its text and starts
    where it did (an ``M`` with its old start written before it), the loop keeps its Z.
    svgpathtools reads the tail's segments exactly as in the input."""
    src = _loop_svg(tmp_path)
    loop, tail = read_curves(src, corner_angle=None)
    q = np.array(loop.curve.control_points) + [0.4, -0.3]
    out = tmp_path / "out.svg"
    write_curves(out, [loop.with_curve(loop.curve.replace(control_points=q)), tail],
                 template=src)
    d1 = re.search(r' d="([^"]*)"', out.read_text()).group(1)
    assert d1.endswith("Z M 10,10 C 40,60 60,90 100,100 C 140,110 150,140 160,160")
    p0, p1 = spt.parse_path(LOOP_THEN_TAIL), spt.parse_path(d1)
    assert list(p1)[-2:] == list(p0)[-2:]                  # the tail exactly as it was
    assert list(p1)[3].end == list(p1)[0].start            # the loop closed on itself
    assert abs(list(p1)[0].start - (10.4 + 9.7j)) < 1e-9
    back = read_curves(out, corner_angle=None)
    assert [r.source["svg_closed"] for r in back] == [True, False]


def test_closepath_then_a_drawing_command_through_the_cli(tmp_path):
    """Faired by the command: both subpaths kept (the loop closed by its Z), every node and
    handle within tol of the input, read back with svgpathtools."""
    from test_cli import assert_user_error, cli
    src = _loop_svg(tmp_path)
    res = cli(["fair", src.name, "--tol", "2", "-o", "out.svg", "-q"], tmp_path)
    assert_user_error(res, 0)
    d1 = re.search(r' d="([^"]*)"', (tmp_path / "out.svg").read_text()).group(1)
    pieces = [x for x in re.split(r"(?=[Mm])", d1.strip()) if x]
    assert len(pieces) == 2 and pieces[0].rstrip().endswith("Z")
    a, b = list(spt.parse_path(LOOP_THEN_TAIL)), list(spt.parse_path(d1))
    assert len(a) == len(b)
    for ga, gb in zip(a, b, strict=True):
        pa, pb = list(ga.bpoints()), list(gb.bpoints())
        if len(pa) != len(pb):                 # the closing line written as a cubic
            pa, pb = [pa[0], pa[-1]], [pb[0], pb[-1]]
        assert max(abs(x - y) for x, y in zip(pa, pb, strict=True)) <= 2.0
