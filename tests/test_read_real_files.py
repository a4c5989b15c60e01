"""Reading what real files contain (issue 11): SVG shapes, transforms, arcs and namespace
prefixes; unsupported entities skipped with a warning in the CLI (``--strict`` refuses);
exact duplicate vertices dropped; two-point pieces "nothing to fair"; ``analyze`` on B-splines
with corner knots; the G2 hold explained.

Expected geometry comes from svgpathtools' own document reader (which applies transforms and
converts polygons), from ezdxf, from ElementTree, or from dense sampling of the curve.
"""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from _helpers import record_points
from click.testing import CliRunner

from curvefair import read_curves, write_curves
from curvefair.analysis import c0_pieces
from curvefair.cli import main
from curvefair.errors import FileFormatError

spt = pytest.importorskip("svgpathtools")

REAL = Path(__file__).parent / "data" / "real"
SPT = REAL / "svgpathtools"


def _run(*args: str):
    return CliRunner().invoke(main, [str(a) for a in args], catch_exceptions=False)


def _xy(z: complex) -> list[float]:
    return [z.real, z.imag]


_vertices = record_points


def _by_node(recs):
    out: dict[int, list] = {}
    for r in recs:
        out.setdefault(r.source["node"], []).append(r)
    return out


# ------------------------------------------------------------------------------------------
# SVG: namespace prefix + commented copy (the real element is edited, the comment not)
# ------------------------------------------------------------------------------------------
def test_svg_prefixed_path_with_commented_copy(tmp_path):
    d = "M 0,0 C 10,20 30,20 40,0 C 50,-20 70,-20 80,0 C 90,20 110,20 120,0"
    text = ('<?xml version="1.0"?>\n<svg:svg xmlns:svg="http://www.w3.org/2000/svg">\n'
            f'<!-- original: <path d="{d}"/> -->\n'
            f'<svg:path id="w" d="{d}"/>\n</svg:svg>\n')
    p = tmp_path / "ns.svg"
    p.write_text(text)
    (rec,) = read_curves(p)
    cp = np.array(rec.curve.control_points)
    cp[3] += [0.0, 1.5]
    write_curves(tmp_path / "o.svg", rec.with_curve(rec.curve.replace(control_points=cp)),
                 template=p)
    out = (tmp_path / "o.svg").read_text()
    assert f'<!-- original: <path d="{d}"/> -->' in out          # the comment untouched
    root = ET.fromstring(out)
    (el,) = [e for e in root.iter() if e.tag.endswith("}path")]
    assert el.get("d") != d                                      # the element rewritten
    path = spt.parse_path(el.get("d"))
    u = np.linspace(0, 1, 9)
    br = rec.curve.replace(control_points=cp).piecewise.breaks
    got = [[_xy(seg.point(s)) for s in u] for seg in path]
    want = [[rec.curve.replace(control_points=cp)(a + s * (b - a)) for s in u]
            for a, b in zip(br[:-1], br[1:], strict=True)]
    np.testing.assert_allclose(np.array(got), np.array(want), atol=1e-9)


# ------------------------------------------------------------------------------------------
# SVG: polygons, transforms, arcs (svgpathtools' test files)
# ------------------------------------------------------------------------------------------
def test_svgpathtools_polygons(tmp_path):
    p = SPT / "polygons.svg"
    with pytest.raises(FileFormatError, match="2 straight-line shapes are .* left as drawn"):
        read_curves(p)                        # drawn shapes unless polylines=True
    recs = read_curves(p, polylines=True)
    paths, _ = spt.svg2paths(str(p))          # svgpathtools converts polygons to paths
    by = _by_node(recs)
    assert len(by) == len(paths) == 2
    for recs_el, ref in zip(by.values(), paths, strict=True):
        want = np.array([_xy(seg.start) for seg in ref])
        got = _vertices(recs_el)
        assert recs_el[0].source["tag"] == "polygon" and recs_el[0].source["closed"]
        np.testing.assert_array_equal(got, want[: got.shape[0]])
    # move one vertex of the first polygon: only its points attribute changes
    r0 = by[min(by)]
    moved = [r.with_curve(r.curve.replace(points=r.points + [0.5, 0.0])) for r in r0]
    write_curves(tmp_path / "o.svg", moved + [r for n, rs in by.items() if n != min(by)
                                               for r in rs], template=p)
    back = _by_node(read_curves(tmp_path / "o.svg", polylines=True))
    np.testing.assert_allclose(_vertices(back[min(by)]), _vertices(r0) + [0.5, 0.0],
                               atol=1e-12)
    orig_lines = p.read_text().splitlines()
    new_lines = (tmp_path / "o.svg").read_text().splitlines()
    assert [a == b for a, b in zip(orig_lines, new_lines, strict=True)] == \
        [True, True, False, True, True]


def _match(got: np.ndarray, want: np.ndarray, atol: float) -> None:
    """Every row of ``got`` equals a different row of ``want`` (the order may differ)."""
    from scipy.optimize import linear_sum_assignment

    assert got.shape == want.shape
    dist = np.abs(got[:, None, :] - want[None, :, :]).max(axis=2)
    rows, cols = linear_sum_assignment(dist)
    assert float(dist[rows, cols].max()) <= atol


def _ends(paths) -> np.ndarray:
    return np.array([_xy(q[0].start) + _xy(q[-1].end) for q in paths])


def test_svgpathtools_groups_transforms_applied_and_undone(tmp_path):
    p = SPT / "groups.svg"
    recs = read_curves(p, polylines=True)
    ref = spt.Document(str(p)).paths()       # svgpathtools applies the transforms
    assert len(recs) == len(ref) == 12
    got = np.array([np.r_[r.points[0], r.points[-1]] for r in recs])
    _match(got, _ends(ref), 1e-9)
    assert sum(r.source["ctm"] is not None for r in recs) >= 10
    # faired (here: moved) in document coordinates, written in each element's own
    moved = [r.with_curve(r.curve.replace(points=r.points + [1.0, 2.0])) for r in recs]
    write_curves(tmp_path / "o.svg", moved, template=p)
    out = spt.Document(str(tmp_path / "o.svg")).paths()
    # the written numbers keep each element's precision (integers here): within rounding
    # of the element's coordinates mapped by its transformation (scales up to 1.875)
    _match(_ends(out), got + [1.0, 2.0, 1.0, 2.0], 1.9)
    back = read_curves(tmp_path / "o.svg", format="svg", polylines=True)
    _match(np.array([np.r_[r.points[0], r.points[-1]] for r in back]), _ends(out), 1e-9)
    # the transform attributes themselves are untouched
    t_in = [e.get("transform") for e in ET.parse(p).getroot().iter()]
    t_out = [e.get("transform") for e in ET.parse(tmp_path / "o.svg").getroot().iter()]
    assert t_in == t_out


def test_transform_inverse_exact_at_full_precision(tmp_path):
    p = tmp_path / "t.svg"
    p.write_text('<svg xmlns="http://www.w3.org/2000/svg"><g transform="rotate(30) '
                 'scale(2 0.5)"><path d="M 0.125,0.25 L 1.5,2.25 L 3.75,2.5 L 5.125,1.75" '
                 'transform="translate(3 -1)"/></g></svg>')
    (rec,) = read_curves(p, corner_angle=None, polylines=True)
    th = np.radians(30)
    M = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]]) @ np.diag([2, 0.5])
    el = np.array([[0.125, 0.25], [1.5, 2.25], [3.75, 2.5], [5.125, 1.75]]) + [3, -1]
    np.testing.assert_allclose(rec.points, el @ M.T, atol=1e-12)
    moved = rec.points + [0.001, -0.002]
    write_curves(tmp_path / "o.svg", rec.with_curve(rec.curve.replace(points=moved)),
                 template=p, decimals=12)
    d = [e.get("d") for e in ET.parse(tmp_path / "o.svg").getroot().iter()
         if e.tag.endswith("path")][0]
    written = np.array([_xy(seg.start) for seg in spt.parse_path(d)] +
                       [_xy(spt.parse_path(d)[-1].end)])
    np.testing.assert_allclose((written + [3, -1]) @ M.T, moved, atol=1e-11)


@pytest.mark.parametrize("name, n_skipped", [("test.svg", 1), ("decorated_ellipse.svg", 3)])
def test_arcs_skipped_with_warning_and_kept(tmp_path, name, n_skipped):
    p = SPT / name
    with pytest.raises(FileFormatError, match="unsupported Arc segment"):
        read_curves(p)
    with pytest.warns(UserWarning, match="skipped .*Arc segment; kept untouched") as rec_w:
        recs = read_curves(p, on_unsupported="skip", polylines=True)
    assert len([w for w in rec_w if "Arc" in str(w.message)]) == n_skipped
    # CLI: skipped by default (exit 0, a Warning line), refused with --strict (exit 1)
    res = _run("fair", p, "-o", tmp_path / "o.svg", "--tol", "0.5")
    assert res.exit_code == 0, res.output
    assert res.output.count("Warning:") >= n_skipped
    paths_in = [e.get("d") for e in ET.parse(p).getroot().iter() if e.tag.endswith("path")]
    paths_out = [e.get("d") for e in ET.parse(tmp_path / "o.svg").getroot().iter()
                 if e.tag.endswith("path")]
    arcs = [i for i, d in enumerate(paths_in) if "A" in d and
            all(r.source["element"] != i for r in recs)]
    assert arcs and all(paths_out[i] == paths_in[i] for i in arcs)
    res = _run("fair", p, "-o", tmp_path / "s.svg", "--tol", "0.5", "--strict")
    assert res.exit_code == 1 and "unsupported Arc segment" in res.output
    assert not (tmp_path / "s.svg").exists()


def test_circle_ellipse_rect_line(tmp_path):
    p = tmp_path / "shapes.svg"
    p.write_text('<svg xmlns="http://www.w3.org/2000/svg">\n'
                 '<circle cx="5" cy="5" r="3"/>\n<ellipse cx="1" cy="1" rx="2" ry="1"/>\n'
                 '<rect x="1" y="2" width="10" height="4"/>\n<line x1="0" y1="0" x2="3" y2="4"/>\n'
                 '<polyline points="0,0 1,2 2,3 4,3.5 6,3"/>\n</svg>\n')
    with pytest.warns(UserWarning) as caught:
        recs = read_curves(p, on_unsupported="skip", corner_angle=None, polylines=True)
    msgs = " ".join(str(w.message) for w in caught)
    assert "unsupported <circle>" in msgs and "unsupported <ellipse>" in msgs
    tags = [r.source["tag"] for r in recs]
    # a rectangle's four vertices are corners even with corner_angle=None (it is written back
    # only unchanged, so nothing of it may move): four two-point sides
    assert tags == ["rect"] * 4 + ["line", "polyline"]
    corners = [[1, 2], [11, 2], [11, 6], [1, 6], [1, 2]]
    for k in range(4):
        np.testing.assert_array_equal(recs[k].points, corners[k:k + 2])
    # a drawing with a rectangle and a straight line: nothing to fair there, exit 0
    res = _run("fair", p, "-o", tmp_path / "o.svg", "--tol", "0.1", "--report",
               tmp_path / "r.json", "--corner-angle", "80", "--polylines")
    assert res.exit_code == 0, res.output
    rep = json.loads((tmp_path / "r.json").read_text())
    assert rep["n_failed"] == 0 and rep["n_nothing_to_fair"] >= 5   # 4 sides + the line
    out = (tmp_path / "o.svg").read_text().splitlines()
    assert out[1:5] == p.read_text().splitlines()[1:5]      # circle, ellipse, rect, line


# ------------------------------------------------------------------------------------------
# real SVG files through the CLI
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("path", [REAL / "fontawesome" / "3.svg", REAL / "trimesh" / "MIL.svg"])
def test_real_svgs_fair_and_analyze(tmp_path, path):
    res = _run("fair", path, "-o", tmp_path / "o.svg", "--tol", "0.5")
    assert res.exit_code == 0, res.output
    res = _run("analyze", path, "--json")
    assert res.exit_code == 0, res.output
    data = json.loads(res.stdout)   # notes (MIL.svg: shapes left as drawn) go to stderr
    assert data["curves"]


def test_analyze_splits_at_corner_knots():
    p = REAL / "fontawesome" / "3.svg"
    (rec,) = read_curves(p)
    c = rec.curve
    t = np.asarray(c.knots)
    _, counts = np.unique(t[4:-4], return_counts=True)
    assert (counts >= 3).sum() >= 5                   # a glyph outline: corner knots
    pieces = c0_pieces(c)
    assert len(pieces) == (counts >= 3).sum() + 1
    for off, sub in pieces:                           # each piece is the curve there
        u = np.linspace(*sub.domain, 101)
        np.testing.assert_allclose(sub(u), c(u), rtol=0, atol=1e-9)
        np.testing.assert_array_equal(sub.control_points[0], c.control_points[off])
    res = _run("analyze", p, "--json")
    assert res.exit_code == 0, res.output
    bad = json.loads(res.output)["curves"][0]["bad_points"]
    assert bad and {b["piece"] for b in bad} <= set(range(len(pieces)))
    assert all(b["measure"] >= bad[i + 1]["measure"] for i, b in enumerate(bad[:-1]))


# ------------------------------------------------------------------------------------------
# duplicate consecutive vertices (DXF) and the G2 hold (e387)
# ------------------------------------------------------------------------------------------
def test_dxf_duplicate_vertex_dropped_and_written_back(tmp_path):
    ezdxf = pytest.importorskip("ezdxf")
    doc = ezdxf.new("R2010")
    pts = [(0, 0), (1, 0.5), (1, 0.5), (2, 0.7), (3, 0.5), (4, 0)]
    doc.modelspace().add_lwpolyline(pts)
    p = tmp_path / "dup.dxf"
    doc.saveas(p)
    with pytest.warns(UserWarning, match="dropped 1 exactly repeated"):
        (rec,) = read_curves(p, polylines=True)
    assert rec.points.shape == (5, 2)
    moved = rec.with_curve(rec.curve.replace(points=rec.points + [0, 0.1]))
    write_curves(tmp_path / "o.dxf", moved, template=p)
    (e,) = ezdxf.readfile(tmp_path / "o.dxf").modelspace().query("LWPOLYLINE")
    got = np.array([v[:2] for v in e.get_points("xy")])
    np.testing.assert_allclose(got, np.array(pts) + [0, 0.1], atol=1e-12)
    res = _run("fair", p, "-o", tmp_path / "c.dxf", "--tol", "0.01", "--polylines")
    assert res.exit_code == 0 and "Warning:" in res.output


def test_g2_hold_on_short_airfoils_and_when_it_covers_everything(tmp_path):
    # e387 (61 points): the hold zone of a C2 spline would hold most points, so the end
    # segment itself is kept (g2_hold "segment") and the interior is faired
    p = REAL / "uiuc" / "e387.dat"
    # the hold rule of the local methods (points-l1 rebuilds a natural cubic: zero end
    # curvature before and after, nothing to hold)
    res = _run("fair", p, "-o", tmp_path / "o.dat", "--tol", "1e-4", "--clamp", "g2",
               "-m", "poliakoff", "--report", tmp_path / "r.json")
    assert res.exit_code == 0
    assert "G2-clamped end" not in res.output
    rep = json.loads((tmp_path / "r.json").read_text())
    (row,) = rep["curves"]
    assert row["report"]["steps"] > 0 and row["report"]["g2_hold"] == ["segment", "segment"]
    got, orig = read_curves(tmp_path / "o.dat")[0].points, read_curves(p)[0].points
    assert not np.array_equal(got, orig)
    np.testing.assert_array_equal(got[[0, 1, -2, -1]], orig[[0, 1, -2, -1]])  # end segments
    # 4 points: the end segments are every interior point; nothing moves, and the run says why
    q = tmp_path / "four.csv"
    q.write_text("0 0\n1 0.5\n2 0.4\n3 0\n")
    res = _run("fair", q, "-o", tmp_path / "f.csv", "--tol", "0.1", "--clamp", "g2",
               "-m", "poliakoff", "--report", tmp_path / "f.json")
    assert res.exit_code == 0
    assert "holds the points next to each G2-clamped end" in res.output
    (row,) = json.loads((tmp_path / "f.json").read_text())["curves"]
    assert row["report"]["steps"] == 0 and row["warnings"]
    np.testing.assert_array_equal(read_curves(tmp_path / "f.csv")[0].points,
                                  read_curves(q)[0].points)


def test_dxf_unsupported_skipped_kept_untouched_and_strict(tmp_path):
    ezdxf = pytest.importorskip("ezdxf")
    doc = ezdxf.new("R2010")
    msp = doc.modelspace()
    rat = msp.add_rational_spline([(0, 0), (1, 2), (3, 2), (4, 0)], [1, 0.5, 2, 1], degree=3)
    x = np.linspace(0, 6, 25)
    line = msp.add_lwpolyline(np.c_[x, np.sin(x) + 0.01 * np.cos(7 * x)].tolist())
    p = tmp_path / "mix.dxf"
    doc.saveas(p)
    res = _run("fair", p, "-o", tmp_path / "o.dxf", "--tol", "0.01")
    assert res.exit_code == 0, res.output
    assert f"skipped SPLINE {rat.dxf.handle}" in res.output and "rational" in res.output
    out = ezdxf.readfile(tmp_path / "o.dxf").modelspace()
    (s2,) = out.query("SPLINE")
    assert s2.dxf.handle == rat.dxf.handle
    np.testing.assert_array_equal(np.asarray(s2.control_points), np.asarray(rat.control_points))
    np.testing.assert_array_equal(np.asarray(s2.weights), np.asarray(rat.weights))
    (l2,) = out.query("LWPOLYLINE")
    assert l2.dxf.handle == line.dxf.handle
    res = _run("fair", p, "-o", tmp_path / "s.dxf", "--tol", "0.01", "--strict")
    assert res.exit_code == 1 and "without --strict" in res.output
    assert not (tmp_path / "s.dxf").exists()
    # a file holding only unsupported entities: nothing to fair, written back unchanged
    # (exit 0, the note says why); --strict refuses it
    doc = ezdxf.new("R2010")
    doc.modelspace().add_rational_spline([(0, 0), (1, 2), (3, 2), (4, 0)], [1, 0.5, 2, 1])
    doc.saveas(tmp_path / "only.dxf")
    res = _run("fair", tmp_path / "only.dxf", "-o", tmp_path / "x.dxf")
    assert res.exit_code == 0 and "1 unsupported entity skipped" in res.output
    assert "nothing to fair" in res.output
    assert (tmp_path / "x.dxf").read_bytes() == (tmp_path / "only.dxf").read_bytes()
    res = _run("fair", tmp_path / "only.dxf", "-o", tmp_path / "y.dxf", "--strict")
    assert res.exit_code == 1 and not (tmp_path / "y.dxf").exists()
    # to another format there is nothing to write: refused, saying why
    res = _run("fair", tmp_path / "only.dxf", "-o", tmp_path / "z.json")
    assert res.exit_code == 1 and "1 unsupported entity skipped" in res.output


def test_dxf_rectangle_is_nothing_to_fair(tmp_path):
    ezdxf = pytest.importorskip("ezdxf")
    doc = ezdxf.new("R2010")
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (10, 0), (10, 5), (0, 5)], close=True)
    x = np.linspace(0, 6, 25)
    msp.add_lwpolyline(np.c_[x, np.sin(x) + 0.01 * np.cos(7 * x)].tolist())
    p = tmp_path / "rect.dxf"
    doc.saveas(p)
    res = _run("fair", p, "-o", tmp_path / "o.dxf", "--tol", "0.01", "--report",
               tmp_path / "r.json", "--polylines")
    assert res.exit_code == 0, res.output
    rep = json.loads((tmp_path / "r.json").read_text())
    assert [r["status"] for r in rep["curves"]] == ["nothing to fair"] * 4 + ["ok"]
    (rect, _) = ezdxf.readfile(tmp_path / "o.dxf").modelspace().query("LWPOLYLINE")
    assert [tuple(v) for v in rect.get_points("xy")] == [(0, 0), (10, 0), (10, 5), (0, 5)]
