"""DXF through ezdxf: splines (clamped, periodic, fit points), polylines, write-back by handle.

References: curves read are evaluated against ezdxf's own B-spline evaluator
(``Spline.construction_tool()``), an implementation independent of curvefair; untouched
entities are compared attribute by attribute after the write-back. tests/data/
libdxfrw_closed_splines.dxf was written by libdxfrw 0.5.10 (LibreCAD's DXF library), see
tests/data/README.md.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.interpolate import BSpline

from curvefair import (
    BSplineCurve,
    FileFormatError,
    InputError,
    MissingDependencyError,
    interpolate_cubic,
    read_curves,
    write_curves,
)

ezdxf = pytest.importorskip("ezdxf")

DATA = Path(__file__).parent / "data"


def _ezdxf_points(e, u):
    tool = e.construction_tool()
    return np.array([tuple(tool.point(float(t))) for t in u])


def _drawing(path):
    doc = ezdxf.new("R2010")
    doc.layers.add("CURVES", color=3)
    doc.layers.add("OTHER", color=5)
    msp = doc.modelspace()
    rng = np.random.default_rng(11)
    h = {}
    # clamped open, 3-D, non-uniform knots
    s = msp.add_open_spline([tuple(p) for p in rng.random((8, 3)) * 10], degree=3,
                            knots=[0, 0, 0, 0, 1, 2, 2.5, 4, 5, 5, 5, 5],
                            dxfattribs={"layer": "CURVES", "color": 1})
    h["open3d"] = s.dxf.handle
    # clamped, planar at z = 2.5, degree 4
    s = msp.add_open_spline([(x, np.sin(x), 2.5) for x in np.linspace(0, 6, 9)], degree=4,
                            dxfattribs={"layer": "CURVES"})
    h["open2d"] = s.dxf.handle
    # periodic, ezdxf's layout (first degree points repeated, n + 2p + 1 knots)
    s = msp.add_spline(dxfattribs={"layer": "CURVES", "linetype": "DASHED"})
    a = np.linspace(0, 2 * np.pi, 10)[:-1]
    s.set_closed([(3 * np.cos(t) + 0.3 * np.cos(3 * t), 2 * np.sin(t), 0) for t in a], degree=3)
    h["periodic"] = s.dxf.handle
    # fit points only
    s = msp.add_spline(fit_points=[(0, 0), (1, 2), (3, 3), (5, 2), (6, 0)],
                       dxfattribs={"layer": "CURVES"})
    h["fit"] = s.dxf.handle
    # lwpolyline with widths, an L-shaped corner and a smooth part
    pts = [(0, 0), (1, 0.1), (2, 0.3), (3, 0.2), (4, 0), (4, 1), (4.2, 2), (4.1, 3)]
    s = msp.add_lwpolyline([(x, y, 0.1, 0.2, 0) for x, y in pts], format="xyseb",
                           dxfattribs={"layer": "CURVES", "elevation": 1.5})
    h["lw"] = s.dxf.handle
    # closed smooth lwpolyline
    b = np.linspace(0, 2 * np.pi, 13)[:-1]
    s = msp.add_lwpolyline([(np.cos(t), 0.5 * np.sin(t)) for t in b], close=True)
    h["lwclosed"] = s.dxf.handle
    # 3-D polyline
    c = np.linspace(0, 4 * np.pi, 25)
    s = msp.add_polyline3d([(np.cos(t), np.sin(t), 0.2 * t) for t in c])
    h["poly3d"] = s.dxf.handle
    # other entities that must stay untouched
    h["line"] = msp.add_line((0, 0), (10, 10), dxfattribs={"layer": "OTHER", "color": 2}).dxf.handle
    h["circle"] = msp.add_circle((5, 5), 2, dxfattribs={"layer": "OTHER"}).dxf.handle
    h["text"] = msp.add_text("curvefair", dxfattribs={"layer": "OTHER", "height": 0.5}).dxf.handle
    blk = doc.blocks.new("B1")
    blk.add_open_spline([(0, 0), (1, 1), (2, 0), (3, 1)], degree=3)
    h["insert"] = msp.add_blockref("B1", (20, 0)).dxf.handle
    doc.saveas(path)
    return h


def test_read_geometry_matches_ezdxf_evaluation(tmp_path):
    p = tmp_path / "d.dxf"
    h = _drawing(p)
    # by default the polylines are drawn shapes, left as drawn: only the splines are read
    assert [r.source["handle"] for r in read_curves(p)] == [h[k] for k in ("open3d", "open2d",
                                                                         "periodic", "fit")]
    recs = read_curves(p, polylines=True)
    by = {}
    for r in recs:
        by.setdefault(r.source["handle"], []).append(r)
    doc = ezdxf.readfile(p)
    # splines: same degree, knots, and the same points as ezdxf evaluates
    for key, dim, closed in [("open3d", 3, False), ("open2d", 2, False), ("periodic", 2, True)]:
        (r,) = by[h[key]]
        e = doc.entitydb[h[key]]
        c = r.curve
        assert r.kind == "bspline" and isinstance(c, BSplineCurve)
        assert c.dim == dim and c.closed == closed and c.degree == e.dxf.degree
        u = np.linspace(*c.domain, 97)
        ref = _ezdxf_points(e, u)
        got = c(u)
        if dim == 2:
            np.testing.assert_allclose(ref[:, 2], r.source["z"], rtol=1e-14)
            ref = ref[:, :2]
        np.testing.assert_allclose(got, ref, atol=1e-9)
    assert by[h["open2d"]][0].source["z"] == 2.5
    assert by[h["periodic"]][0].curve.n_ctrl == 9
    # fit points: the interpolating curve through them
    (r,) = by[h["fit"]]
    assert r.kind == "fit_points"
    np.testing.assert_array_equal(r.points, [(0, 0), (1, 2), (3, 3), (5, 2), (6, 0)])
    np.testing.assert_allclose(r.curve(r.curve.params), r.points, atol=1e-12)
    # polylines: split at the 90 degree corner, closed loop periodic, 3-D kept 3-D
    lw = by[h["lw"]]
    assert [x.source["indices"].tolist() for x in lw] == [[0, 1, 2, 3, 4], [4, 5, 6, 7]]
    assert lw[0].corners == (4,) and lw[1].corners == (0,) and lw[0].source["z"] == 1.5
    (lc,) = by[h["lwclosed"]]
    assert lc.curve.closed and lc.curve.points.shape == (13, 2)
    (p3,) = by[h["poly3d"]]
    assert p3.curve.dim == 3 and p3.points.shape == (25, 3)
    # nothing from the block definition, the line, the circle, the text
    assert set(by) == {h[k] for k in ("open3d", "open2d", "periodic", "fit", "lw", "lwclosed",
                                      "poly3d")}


def _entity_state(e):
    attrs = {k: (tuple(v) if hasattr(v, "__iter__") and not isinstance(v, str) else v)
             for k, v in e.dxfattribs().items()}
    geo = None
    t = e.dxftype()
    if t == "SPLINE":
        geo = ([tuple(v) for v in e.control_points], list(e.knots), list(e.weights),
               [tuple(v) for v in e.fit_points])
    elif t == "LWPOLYLINE":
        geo = list(e.get_points("xyseb"))
    elif t == "POLYLINE":
        geo = [tuple(v.dxf.location) for v in e.vertices]
    return attrs, geo


def test_write_back_replaces_only_the_faired_entities(tmp_path):
    p = tmp_path / "d.dxf"
    h = _drawing(p)
    recs = read_curves(p, polylines=True)
    faired = []
    changed = {h["open3d"], h["periodic"], h["lw"], h["fit"], h["poly3d"]}
    for r in recs:
        c = r.curve
        if r.source["handle"] not in changed:
            faired.append(r)
        elif r.kind == "bspline":
            cp = np.array(c.control_points)
            cp[2] += 0.05
            faired.append(r.with_curve(c.replace(control_points=cp)))
        else:
            pts = np.array(c.points)
            pts[1:-1] += 0.01
            faired.append(r.with_curve(c.replace(points=pts)))
    out = tmp_path / "out.dxf"
    write_curves(out, faired, template=p)
    a, b = ezdxf.readfile(p), ezdxf.readfile(out)
    assert a.dxfversion == b.dxfversion
    assert [e.dxf.handle for e in a.modelspace()] == [e.dxf.handle for e in b.modelspace()]
    assert [ly.dxf.name for ly in a.layers] == [ly.dxf.name for ly in b.layers]
    for ea in a.modelspace():
        eb = b.entitydb[ea.dxf.handle]
        sa, sb = _entity_state(ea), _entity_state(eb)
        if ea.dxf.handle in changed:
            assert sa[1] != sb[1]
            # everything but geometry kept: layer, colour, linetype, flags, degree
            for k in ("layer", "color", "linetype", "flags", "degree", "elevation"):
                assert sa[0].get(k) == sb[0].get(k), k
        else:
            assert sa == sb
    blk_a = [tuple(v) for v in a.blocks["B1"].query("SPLINE")[0].control_points]
    blk_b = [tuple(v) for v in b.blocks["B1"].query("SPLINE")[0].control_points]
    assert blk_a == blk_b
    # the faired geometry reads back exactly, widths kept on the polyline
    back = read_curves(out, polylines=True)
    for r, f in zip(back, faired, strict=True):
        assert r.source["handle"] == f.source["handle"]
        if r.kind == "bspline":
            np.testing.assert_array_equal(r.curve.control_points, f.curve.control_points)
            np.testing.assert_array_equal(r.curve.knots, f.curve.knots)
        else:
            np.testing.assert_array_equal(r.curve.points, f.curve.points)
    lw = b.entitydb[h["lw"]]
    assert all(s == 0.1 and w == 0.2 for _, _, s, w, _ in lw.get_points("xyseb"))
    # the periodic spline kept its DXF layout: wrapped control points, same knots
    ea, eb = a.entitydb[h["periodic"]], b.entitydb[h["periodic"]]
    assert list(ea.knots) == list(eb.knots) and len(ea.control_points) == len(eb.control_points)
    cb = np.array([tuple(v) for v in eb.control_points])
    np.testing.assert_array_equal(cb[-3:], cb[:3])


def test_read_write_read_identical_and_untouched_file(tmp_path):
    p = tmp_path / "d.dxf"
    _drawing(p)
    before = p.read_bytes()
    recs = read_curves(p)
    write_curves(tmp_path / "o.dxf", recs, template=recs)
    assert p.read_bytes() == before
    back = read_curves(tmp_path / "o.dxf")
    assert len(back) == len(recs)
    for r, s in zip(recs, back, strict=True):
        assert (r.kind, r.source["handle"], r.name) == (s.kind, s.source["handle"], s.name)
        u = np.linspace(*r.curve.domain, 50)
        np.testing.assert_array_equal(r.curve(u), s.curve(u))
    with pytest.raises(InputError, match="overwrite=True"):
        write_curves(p, recs, template=p)


def test_new_drawing_without_template(tmp_path):
    p = tmp_path / "d.dxf"
    _drawing(p)
    recs = read_curves(p, polylines=True)
    extra = interpolate_cubic(np.c_[np.arange(5.0), np.arange(5.0) ** 2 / 4])
    write_curves(tmp_path / "new.dxf", recs + [extra])
    back = read_curves(tmp_path / "new.dxf", polylines=True)
    kinds = [r.kind for r in back]
    assert kinds.count("bspline") == 4 and kinds.count("fit_points") == 1
    # pieces of the split polyline were joined into one polyline again
    assert kinds.count("polyline") == 4
    # the Hermite curve became an exact Bezier-knot SPLINE
    u = np.linspace(*extra.domain, 40)
    np.testing.assert_allclose(back[-1].curve(u), extra(u), atol=1e-12)


def test_short_periodic_knot_layout(tmp_path):
    # AutoCAD documents periodic splines with n + 1 knots for n control points
    doc = ezdxf.new("R2010")
    s = doc.modelspace().add_spline()
    a = np.linspace(0, 2 * np.pi, 8)[:-1]
    s.dxf.degree = 3
    s.control_points = [(np.cos(t), np.sin(t), 0) for t in a]
    s.knots = list(np.arange(8.0))
    s.dxf.flags = s.CLOSED | s.PERIODIC
    doc.saveas(tmp_path / "p.dxf")
    (r,) = read_curves(tmp_path / "p.dxf")
    assert r.curve.closed and r.source["spline_layout"] == "periodic_short"
    ref = BSplineCurve(np.c_[np.cos(a), np.sin(a)], np.arange(8.0), 3, closed=True)
    u = np.linspace(0, 7, 30)
    np.testing.assert_allclose(r.curve(u), ref(u), atol=1e-14)
    write_curves(tmp_path / "o.dxf", [r], template=tmp_path / "p.dxf")
    e = ezdxf.readfile(tmp_path / "o.dxf").modelspace().query("SPLINE")[0]
    assert list(e.knots) == list(np.arange(8.0)) and len(e.control_points) == 7


def test_unsupported_entities_raise_or_skip(tmp_path):
    doc = ezdxf.new("R2010")
    msp = doc.modelspace()
    good = msp.add_open_spline([(0, 0), (1, 1), (2, 0), (3, 1)], degree=3).dxf.handle
    rat = msp.add_rational_spline([(0, 0), (1, 1), (2, 0), (3, 1)], [1, 2, 1, 1]).dxf.handle
    msp.add_lwpolyline([(0, 0, 0.5), (1, 0, 0), (2, 1, 0)], format="xyb")
    unc = msp.add_spline()
    unc.dxf.degree = 3
    unc.control_points = [(0, 0, 0), (1, 1, 0), (2, 0, 0), (3, 1, 0), (4, 0, 0)]
    unc.knots = list(range(9))
    doc.saveas(tmp_path / "u.dxf")
    with pytest.raises(FileFormatError, match=f"SPLINE {rat}.*rational") as exc:
        read_curves(tmp_path / "u.dxf")
    assert exc.value.path == str(tmp_path / "u.dxf")
    with pytest.warns(UserWarning) as w:
        recs = read_curves(tmp_path / "u.dxf", on_unsupported="skip", polylines=True)
    msgs = " ".join(str(x.message) for x in w)
    assert "rational" in msgs and "bulges" in msgs and "knot layout" in msgs
    assert [r.source["handle"] for r in recs] == [good]
    # by default the polyline with an arc is a drawn shape like any other: no warning for it
    with pytest.warns(UserWarning) as w:
        recs = read_curves(tmp_path / "u.dxf", on_unsupported="skip")
    msgs = " ".join(str(x.message) for x in w)
    assert "rational" in msgs and "bulges" not in msgs
    assert [r.source["handle"] for r in recs] == [good]


@pytest.mark.parametrize("content, match", [
    (b"", "not a readable DXF"),
    (b"0\nSECTION\n2\nENTITIES\n0\nLINE\n8\n", "not a readable DXF|no curves"),
    (b"\x00\x01garbage\xff" * 20, "not a readable DXF"),
])
def test_garbage_dxf(tmp_path, content, match):
    p = tmp_path / "bad.dxf"
    p.write_bytes(content)
    with pytest.raises(FileFormatError, match=match) as exc:
        read_curves(p)
    assert exc.value.path == str(p)


def test_no_curves_and_nan(tmp_path):
    doc = ezdxf.new("R2010")
    doc.modelspace().add_line((0, 0), (1, 1))
    doc.saveas(tmp_path / "l.dxf")
    with pytest.raises(FileFormatError, match="no curves"):
        read_curves(tmp_path / "l.dxf")
    doc = ezdxf.new("R2010")
    doc.modelspace().add_lwpolyline([(0, 0), (1, float("nan")), (2, 0)])
    doc.saveas(tmp_path / "n.dxf")
    with pytest.raises(FileFormatError, match="non-finite"):
        read_curves(tmp_path / "n.dxf", polylines=True)
    # by default a polyline is left as drawn, and a file of nothing else says so
    with pytest.raises(FileFormatError, match=r"no curves in the dxf file: its 1 polyline "
                                              r"is \(LWPOLYLINE.*\) left as drawn.*"
                                              r"polylines=True") as exc:
        read_curves(tmp_path / "n.dxf")
    assert exc.value.n_drawn == 1
    doc = ezdxf.new("R2010")
    doc.modelspace().add_lwpolyline([(0, 0), (1, 1), (1, 1), (2, 0)])
    doc.saveas(tmp_path / "d.dxf")
    with pytest.warns(UserWarning, match="dropped 1 exactly repeated"):
        recs = read_curves(tmp_path / "d.dxf", corner_angle=None, polylines=True)
    assert recs[0].points.shape == (3, 2)
    doc = ezdxf.new("R2010")
    doc.modelspace().add_lwpolyline([(0, 0), (1, 1), (1 + 2e-16, 1), (2, 0)])
    doc.saveas(tmp_path / "d2.dxf")
    with pytest.raises(FileFormatError, match="duplicate consecutive"):
        read_curves(tmp_path / "d2.dxf", polylines=True)


def test_real_libdxfrw_file(tmp_path):
    src = DATA / "libdxfrw_closed_splines.dxf"
    recs = read_curves(src)
    assert [r.source["handle"] for r in recs] == ["47", "48"]
    doc = ezdxf.readfile(src)
    for r in recs:
        e = doc.entitydb[r.source["handle"]]
        # a closed flag with the first control point repeated last: a closed curve (the
        # repeated point stored once), the same curve as the clamped one of the file
        assert e.closed and r.source["spline_layout"] == "clamped_closed" and r.curve.closed
        assert r.curve.n_ctrl == len(e.control_points) - 1 and r.source["layer"] == "Layer 1"
        u = np.linspace(*r.curve.domain, 80)
        # reference: scipy's BSpline on the entity's raw arrays (ezdxf's construction tool
        # rounds the 12-digit knots of this file to 7 digits, off by ~5e-6 here)
        ref = BSpline(np.array(e.knots), np.array([tuple(v) for v in e.control_points]), 3)(u)
        np.testing.assert_allclose(r.curve(u), ref[:, :2], atol=1e-9)
        np.testing.assert_allclose(r.curve(u), _ezdxf_points(e, u)[:, :2], atol=1e-4)
        # the file's control points, the repeated one once
        raw = np.array([tuple(v) for v in e.control_points])[:, :2]
        np.testing.assert_array_equal(r.curve.control_points, raw[:-1])
        np.testing.assert_array_equal(raw[0], raw[-1])
    c = recs[1].curve
    cp = np.array(c.control_points)
    cp[3] += [0.5, -0.25]
    out = tmp_path / "o.dxf"
    write_curves(out, [recs[0], recs[1].with_curve(c.replace(control_points=cp))], template=src)
    b = ezdxf.readfile(out)
    # untouched entity: as ezdxf itself writes it back (ezdxf drops default attributes such as
    # lineweight -1 on saving, so the reference is ezdxf's own load + save of the file)
    doc.saveas(tmp_path / "ezdxf_resaved.dxf")
    base = ezdxf.readfile(tmp_path / "ezdxf_resaved.dxf")
    assert _entity_state(base.entitydb["47"]) == _entity_state(b.entitydb["47"])
    assert _entity_state(doc.entitydb["47"])[1] == _entity_state(b.entitydb["47"])[1]
    e48 = b.entitydb["48"]
    assert e48.dxf.flags == 11 and e48.dxf.color == 250 and list(e48.knots) == \
        list(doc.entitydb["48"].knots)
    back = np.array([tuple(v) for v in e48.control_points])[:, :2]
    np.testing.assert_array_equal(back, np.r_[cp, cp[:1]])     # written back closed, clamped
    # and the faired-by-hand curve is what the file now holds (scipy on the raw arrays)
    u = np.linspace(*c.domain, 200)
    moved = c.replace(control_points=cp)
    np.testing.assert_allclose(BSpline(np.array(e48.knots), back, 3)(u), moved(u), atol=1e-12)


def test_missing_ezdxf_names_the_extra(tmp_path, monkeypatch):
    p = tmp_path / "d.dxf"
    p.write_text("0\nEOF\n")
    monkeypatch.setitem(sys.modules, "ezdxf", None)
    with pytest.raises(MissingDependencyError, match=r"pip install 'curvefair\[dxf\]'"):
        read_curves(p)
    with pytest.raises(MissingDependencyError, match="ezdxf"):
        write_curves(tmp_path / "o.dxf", interpolate_cubic([[0, 0], [1, 1], [2, 0]]))


def test_bezier_style_spline_is_skipped_not_fatal(tmp_path):
    # bjnortier/dxf's issue50.dxf (see tests/data/README.md): a cubic SPLINE whose interior
    # knots have multiplicity 4 (a chain of Bezier pieces), which ezdxf reads and draws. It
    # is unsupported (skipped and written back untouched), not a broken file: another curve
    # of the same drawing is still faired.
    from click.testing import CliRunner

    from curvefair.cli import main

    src = DATA / "real" / "bjnortier-dxf" / "issue50.dxf"
    orig = ezdxf.readfile(src)
    spl = [e for e in orig.modelspace() if e.dxftype() == "SPLINE"]
    assert len(spl) == 1
    handle = spl[0].dxf.handle
    knots = np.asarray(spl[0].knots)
    assert np.max(np.unique(knots[4:-4], return_counts=True)[1]) == 4  # the case
    with pytest.raises(FileFormatError, match=f"SPLINE {handle}.*multiplicity"):
        read_curves(src)
    with pytest.warns(UserWarning, match=f"skipped SPLINE {handle}.*multiplicity"), \
            pytest.raises(FileFormatError, match="no curves"):
        read_curves(src, on_unsupported="skip")
    # the same drawing with one ordinary spline more
    doc = ezdxf.readfile(src)
    t = np.linspace(0.0, 4.0, 25)
    fit = np.c_[t, 0.5 * np.sin(t) + 0.01 * np.cos(37 * t), np.zeros_like(t)]
    new = doc.modelspace().add_spline(fit).dxf.handle
    doc.saveas(tmp_path / "in.dxf")
    out = tmp_path / "out.dxf"
    res = CliRunner().invoke(main, ["fair", str(tmp_path / "in.dxf"), "-o", str(out),
                                    "--tol", "0.01"])
    assert res.exit_code == 0, res.output
    assert "multiplicity" in res.output and "wrote" in res.output
    back = ezdxf.readfile(out)
    by = {e.dxf.handle: e for e in back.modelspace() if e.dxftype() == "SPLINE"}
    assert set(by) == {handle, new}
    kept = by[handle]  # untouched
    np.testing.assert_array_equal(np.asarray(kept.knots), knots)
    np.testing.assert_array_equal(np.asarray(kept.control_points),
                                  np.asarray(spl[0].control_points))
    faired = np.asarray(by[new].fit_points)
    assert faired.shape == fit.shape and np.all(np.linalg.norm(faired - fit, axis=1) <= 0.01)
    assert np.any(faired != fit)
