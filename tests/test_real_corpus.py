"""Round trips of real CAD files written by other software (tests/data/real, origins in
tests/data/README.md): read, fair with the CLI's defaults (method per curve type, clamp g0,
corners kept) at a tolerance of 1e-3 of the file's size, write back with the file as
template, re-read with the format's own library (ezdxf, rhino3dm, OCP) and check:

- nothing lost: entity counts per (type, layer) / objects and layers / shape census equal;
- untouched entities unchanged: every DXF entity that was not faired has the same DXF
  attributes as after ezdxf's own load + save of the input; 3dm objects keep id, layer, name,
  colour; unfaired OCC free edges keep their geometry;
- tolerance on disk: every control point / vertex read back by the library is within tol of
  the input's (the project's contract ``|moved - original| <= tol``);
- unchanged bytes when nothing changed (3dm, IGES, STEP: the curves written back as read);
- G1 joins stay G1 (B-spline knots of multiplicity ``degree`` where the input turns by less
  than 1e-9 rad).

A check that is still open in issue 11 is ``xfail(strict=True)`` with what is open.
"""

from __future__ import annotations

import collections
import shutil
import warnings
import zipfile
from pathlib import Path

import numpy as np
import pytest

from curvefair import CurvefairError, FileFormatError, fair, read_curves, write_curves
from curvefair.cli import _local_protect
from curvefair.io._common import points_curve

ezdxf = pytest.importorskip("ezdxf")

DATA = Path(__file__).parent / "data"
REAL = DATA / "real"


def _read(path, polylines=None):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return read_curves(path, on_unsupported="skip", polylines=polylines)


def _pts(c):
    return np.asarray(c.control_points if hasattr(c, "control_points") else c.points)


def _fair_all(recs):
    """CLI defaults (cli.fair_cmd): default method, clamp g0, corners protected; a curve that
    fails is written unchanged."""
    allp = np.vstack([_pts(r.curve)[:, :2] for r in recs])
    tol = 1e-3 * float(np.ptp(allp, axis=0).max())
    out, changed = [], []
    for r in recs:
        try:
            res = fair(r.curve, None, tol=tol, clamp="g0", protect=_local_protect(r, []))
        except CurvefairError:
            out.append(r)
            continue
        out.append(r.with_curve(res.curve))
        if not np.array_equal(_pts(res.curve), _pts(r.curve)):
            changed.append(r)
    return out, changed, tol


def _write(path, recs, template):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        write_curves(path, recs, template=template)


# ------------------------------------------------------------------------------------------
# DXF
# ------------------------------------------------------------------------------------------
def _dxf_census(doc):
    c = collections.Counter()
    for layout in doc.layouts:
        for e in layout:
            c[(layout.name, e.dxftype(), e.dxf.get("layer", "0"))] += 1
    for blk in doc.blocks:
        for e in blk:
            c[("block:" + blk.name, e.dxftype(), e.dxf.get("layer", "0"))] += 1
    return c


def _dxf_geom(e):
    t = e.dxftype()
    if t == "SPLINE":
        cps = np.asarray([tuple(v) for v in e.control_points], dtype=float).reshape(-1, 3)
        return cps if cps.shape[0] else np.asarray([tuple(v) for v in e.fit_points], float)
    if t == "LWPOLYLINE":
        return np.asarray(e.get_points("xy"), dtype=float)
    return np.asarray([tuple(v.dxf.location) for v in e.vertices], dtype=float)


def _attrs(e):
    a = dict(e.dxf.all_existing_dxf_attribs())
    return {k: (tuple(v) if hasattr(v, "__iter__") and not isinstance(v, str) else v)
            for k, v in a.items()}


def _hullform(name):
    def get(tmp_path):
        with zipfile.ZipFile(REAL / "hullform" / name) as z:
            inner = z.namelist()[0]
            z.extract(inner, tmp_path)
        return tmp_path / inner
    return get


DXF_FILES = [
    pytest.param(REAL / "ezdxf" / "hatches_2.dxf", id="ezdxf-hatches_2"),
    pytest.param(REAL / "trimesh" / "spline.DXF", id="trimesh-spline"),
    pytest.param(REAL / "trimesh" / "ae.r2013a.dxf", id="trimesh-ae.r2013a"),
    pytest.param(DATA / "libdxfrw_closed_splines.dxf", id="ezdxf-no_layouts(libdxfrw)"),
    pytest.param(REAL / "dxf-parser" / "splines.dxf", id="dxf-parser-splines"),  # no $ACADVER
    pytest.param(_hullform("2ddxf.zip"), id="hullform-2d"),  # duplicate consecutive vertices
    pytest.param(_hullform("3ddxf.zip"), id="hullform-3d"),
]


# a numpy overflow/invalid warning is a NaN or inf somewhere in the fair (points-l1's jump costs
# overflowed on Hullform's straight runs): an error here
@pytest.mark.filterwarnings("error::RuntimeWarning")
@pytest.mark.parametrize("src", DXF_FILES)
def test_dxf_round_trip(tmp_path, src):
    if callable(src):
        src = src(tmp_path)
    # polylines too (drawn shapes, left as drawn by default): the hull lines of Hullform's
    # files are sampled curves, and every entity's round trip is checked
    recs = _read(src, polylines=True)
    faired, changed, tol = _fair_all(recs)
    out = tmp_path / ("out" + src.suffix)
    _write(out, faired, src)
    a = ezdxf.readfile(src)
    b = ezdxf.readfile(out)
    if b.dxfversion != a.dxfversion:
        # an R12 drawing holding SPLINEs is written as R2000 (else they would be lost): the
        # reference is ezdxf's own save of the input with the same upgrade
        assert a.dxfversion < "AC1015" <= b.dxfversion
        a.dxfversion = b.dxfversion
    a.saveas(tmp_path / "resaved.dxf")          # ezdxf's own load + save: the reference
    base = ezdxf.readfile(tmp_path / "resaved.dxf")
    a = ezdxf.readfile(src)
    assert _dxf_census(b) == _dxf_census(a)
    touched = {r.source["handle"] for r in changed}
    hatch_followers = {h.dxf.handle for h in a.entitydb.values() if h.dxftype() == "HATCH"
                       for p in h.paths for s in p.source_boundary_objects if s in touched}
    # a file without handles (R12, $HANDLING 0: Hullform) gets them from ezdxf at each load,
    # so the same entity is found by its place in the model space instead
    if "$HANDSEED" not in src.read_text(errors="replace"):
        # a file without handles (R12, $HANDLING 0: Hullform) gets new ones from ezdxf at each
        # load: the same entity is the one at the same place in the model space, unchanged or
        # (faired) within tol of the input
        pairs = list(zip(a.modelspace(), b.modelspace(), strict=True))
        n_moved = 0
        for e, f in pairs:
            assert f.dxftype() == e.dxftype()
            assert f.dxf.get("layer", "0") == e.dxf.get("layer", "0")
            if e.dxftype() in ("SPLINE", "LWPOLYLINE", "POLYLINE"):
                g0, g1 = _dxf_geom(e), _dxf_geom(f)
                assert g0.shape == g1.shape
                d = float(np.linalg.norm(g1 - g0, axis=1).max())
                assert d <= tol, (d, tol)
                n_moved += d > 0
        assert n_moved >= len(touched) > 0
        return
    for e in base.entitydb.values():
        h = e.dxf.get("handle")
        if h is None or h in touched or h in hatch_followers or not e.is_alive:
            continue
        f = b.entitydb.get(h)
        assert f is not None and f.dxftype() == e.dxftype(), h
        if e.dxftype() == "DICTIONARYVAR" and " @ " in str(e.dxf.get("value", "")):
            continue                                  # ezdxf's save time stamp (EZDXF_META)
        assert _attrs(f) == _attrs(e), h
        if e.dxftype() in ("SPLINE", "LWPOLYLINE", "POLYLINE"):
            np.testing.assert_array_equal(_dxf_geom(f), _dxf_geom(e), err_msg=h)
    # tolerance on disk, against the input's raw arrays
    for h in touched:
        g0, g1 = _dxf_geom(a.entitydb[h]), _dxf_geom(b.entitydb[h])
        assert g0.shape == g1.shape, h
        d = float(np.linalg.norm(g1 - g0, axis=1).max())
        assert d <= tol, (h, d, tol)
    # closed splines stay closed, in their file's layout
    for e in a.modelspace().query("SPLINE"):
        assert b.entitydb[e.dxf.handle].closed == e.closed


def test_dxf_associative_hatch_follows_the_spline(tmp_path):
    """hatches_2.dxf: HATCH 233's edge path holds a copy of SPLINE 21A; after fairing the
    spline the boundary's spline edge is the new spline (ezdxf re-read), still associative.
    HATCH 570's polyline path (800 vertices) is not a copy of its source LWPOLYLINE 24A (1301
    vertices): the association is removed, with a warning."""
    src = REAL / "ezdxf" / "hatches_2.dxf"
    recs = _read(src)
    moved = []
    for r in recs:
        if r.source["handle"] in ("21A", "24A") and r.kind == "bspline":
            cp = np.array(r.curve.control_points)
            cp[len(cp) // 2] += 0.5
            r = r.with_curve(r.curve.replace(control_points=cp))
        moved.append(r)
    out = tmp_path / "o.dxf"
    write_curves(out, moved, template=src)
    b = ezdxf.readfile(out)
    h = b.entitydb["233"]
    assert h.dxf.associative == 1 and "21A" in h.paths[0].source_boundary_objects
    sp = b.entitydb["21A"]
    edges = [ed for ed in h.paths[0].edges if type(ed).__name__ == "SplineEdge"]
    assert len(edges) == 1
    np.testing.assert_array_equal(np.array([tuple(v)[:2] for v in edges[0].control_points]),
                                  np.array([tuple(v)[:2] for v in sp.control_points]))
    assert list(edges[0].knot_values) == list(sp.knots)
    a = ezdxf.readfile(src)
    old = np.array([tuple(v)[:2] for v in a.entitydb["21A"].control_points])
    assert np.abs(old - np.array([tuple(v)[:2] for v in sp.control_points])).max() == 0.5


def test_dxf_hatch_that_cannot_follow_loses_the_association(tmp_path):
    src = REAL / "ezdxf" / "hatches_2.dxf"
    recs = _read(src, polylines=True)
    out_recs = []
    for r in recs:
        if r.source["handle"] == "24A":
            pts = np.array(r.curve.points)
            pts[5] += 0.25
            r = r.with_curve(points_curve(pts, bool(r.curve.closed)))
        out_recs.append(r)
    out = tmp_path / "o.dxf"
    with pytest.warns(UserWarning, match="HATCH 570 .*association is removed"):
        write_curves(out, out_recs, template=src)
    b = ezdxf.readfile(out)
    h = b.entitydb["570"]
    assert h.dxf.associative == 0 and all(not p.source_boundary_objects for p in h.paths)
    assert "570" not in (b.entitydb["24A"].reactors.get() if b.entitydb["24A"].reactors
                         else [])


def test_dxf_closed_spline_is_read_closed_and_written_closed(tmp_path):
    """trimesh spline.DXF, SPLINE 7A: closed flag, clamped knots, first control point repeated
    last, tangent-continuous at the seam (2e-8 rad): read as one closed curve, the same curve
    as scipy's clamped BSpline of the entity's arrays; written back in the clamped layout with
    the closed flag."""
    from scipy.interpolate import BSpline

    src = REAL / "trimesh" / "spline.DXF"
    recs = {r.source["handle"]: r for r in _read(src)}
    r = recs["7A"]
    assert r.curve.closed and r.source["spline_layout"] == "clamped_closed"
    e = ezdxf.readfile(src).entitydb["7A"]
    raw = np.array([tuple(v) for v in e.control_points])[:, :2]
    u = np.linspace(*r.curve.domain, 400)
    ref = BSpline(np.array(e.knots), raw, e.dxf.degree)(u)
    np.testing.assert_allclose(r.curve(u), ref, rtol=0, atol=1e-12)
    faired, _, tol = _fair_all([r])
    out = tmp_path / "o.dxf"
    _write(out, faired, src)
    f = ezdxf.readfile(out).entitydb["7A"]
    assert f.closed and f.dxf.flags == e.dxf.flags and list(f.knots) == list(e.knots)
    back = np.array([tuple(v) for v in f.control_points])[:, :2]
    np.testing.assert_array_equal(back[0], back[-1])
    assert float(np.linalg.norm(back - raw, axis=1).max()) <= tol


def test_dxf_closed_spline_seam_stays_g1():
    src = REAL / "trimesh" / "spline.DXF"
    r = next(r for r in _read(src) if r.source["handle"] == "7A")
    faired, _, _ = _fair_all([r])
    assert _g1_breaks(faired[0].curve, r.curve) <= 1e-7


@pytest.mark.parametrize("src,why", [
    (REAL / "dxf-parser" / "arcs-as-splines.dxf", "no curves"),        # rational splines only
    (REAL / "p3dtest" / "profileHullFront_v2.dxf", "no curves"),       # ARC and LINE only
    (REAL / "trimesh" / "cycloidal.dxf", "not a readable DXF"),        # ezdxf refuses it
], ids=["dxf-parser-arcs-as-splines", "p3dtest-profileHullFront", "trimesh-cycloidal"])
def test_dxf_files_with_nothing_to_fair_are_refused_cleanly(src, why):
    with pytest.raises(FileFormatError, match=why):
        _read(src)


# ------------------------------------------------------------------------------------------
# Rhino 3dm
# ------------------------------------------------------------------------------------------
RHINO = [
    pytest.param(REAL / "rhino-developer-samples" / "nurbscurve.3dm", id="nurbscurve"),
    pytest.param(REAL / "opennurbs" / "v1_three_curves.3dm", id="opennurbs-v1_three_curves"),
    pytest.param(REAL / "opennurbs" / "v3_my_curves.3dm", id="opennurbs-v3_my_curves"),
]


def _objects(rh, m, with_ids):
    out = []
    for i in range(len(m.Objects)):
        o = m.Objects[i]
        a = o.Attributes
        out.append((str(a.Id) if with_ids else i, type(o.Geometry).__name__, a.LayerIndex,
                    a.Name, str(a.ObjectColor), int(a.ColorSource), a.Visible))
    layers = [(m.Layers[k].Name, str(m.Layers[k].Color), m.Layers[k].Visible)
              for k in range(len(m.Layers))]
    return out, layers, len(m.Materials), len(m.InstanceDefinitions)


@pytest.mark.parametrize("src", RHINO)
def test_3dm_round_trip(tmp_path, src):
    rh = pytest.importorskip("rhino3dm")
    recs = _read(src)
    out = tmp_path / "same.3dm"
    _write(out, recs, src)
    assert out.read_bytes() == src.read_bytes()          # nothing changed: the same bytes
    faired, changed, tol = _fair_all(recs)
    assert changed
    out = tmp_path / "out.3dm"
    _write(out, faired, src)
    a, b = rh.File3dm.Read(str(src)), rh.File3dm.Read(str(out))
    # version-1 archives store no ids (openNURBS invents new ones at every read)
    ids = rh.File3dm.ReadArchiveVersion(str(src)) >= 2
    assert _objects(rh, b, ids) == _objects(rh, a, ids)
    for r in changed:
        k = r.source["object"]
        pa, pb = a.Objects[k].Geometry.Points, b.Objects[k].Geometry.Points
        p0 = np.array([(pa[i].X, pa[i].Y, pa[i].Z) for i in range(len(pa))])
        p1 = np.array([(pb[i].X, pb[i].Y, pb[i].Z) for i in range(len(pb))])
        assert p0.shape == p1.shape
        assert float(np.linalg.norm(p1 - p0, axis=1).max()) <= tol


def _g1_breaks(curve, rec_curve):
    """Largest turning angle (rad) at the C0 knots of ``curve`` where ``rec_curve`` (the
    input) is G1 to 1e-9 rad."""
    p = curve.degree
    t = np.asarray(curve.knots)
    lo, hi = curve.domain
    worst = 0.0
    e = 1e-9 * (hi - lo)
    joins = [(k - e, k + e) for k in np.unique(t[(t > lo) & (t < hi)])
             if np.count_nonzero(t == k) >= p]
    if curve.closed:                               # the seam of a closed curve
        joins.append((hi - e, lo + e))

    def angle(c, u0, u1):
        d0, d1 = c(np.array([u0]), 1)[0], c(np.array([u1]), 1)[0]
        cosv = np.dot(d0, d1) / np.linalg.norm(d0) / np.linalg.norm(d1)
        return float(np.arccos(np.clip(cosv, -1, 1)))

    for u0, u1 in joins:
        if angle(rec_curve, u0, u1) < 1e-6:
            worst = max(worst, angle(curve, u0, u1))
    return worst


def test_3dm_poly_bezier_joins_stay_g1():
    src = REAL / "rhino-developer-samples" / "nurbscurve.3dm"
    recs = _read(src)
    faired, _, _ = _fair_all(recs)
    assert max(_g1_breaks(f.curve, r.curve) for f, r in zip(faired, recs, strict=True)) <= 1e-7


# ------------------------------------------------------------------------------------------
# IGES / STEP (OCC)
# ------------------------------------------------------------------------------------------
OCC = REAL / "occt"
STEP = ["trj7_c2-ac-214.stp", "trj7_c2-ct-203.stp", "trj7_c2-ec-214.stp",
        "trj7_c2-pe-214.stp", "OCC22459-TEST2.stp"]


def _occ_free_poles(path):
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.GeomAbs import GeomAbs_CurveType

    from curvefair.io.occ import _free_edges, _read_shape

    shape = _read_shape(path, "iges" if str(path).endswith(".igs") else "step", "test")
    out = []
    for e in _free_edges(shape):
        ad = BRepAdaptor_Curve(e)
        if ad.GetType() != GeomAbs_CurveType.GeomAbs_BSplineCurve:
            out.append(None)
            continue
        bs = ad.BSpline()
        out.append(np.array([(bs.Pole(i).X(), bs.Pole(i).Y(), bs.Pole(i).Z())
                             for i in range(1, bs.NbPoles() + 1)]))
    return out


def _step_census(path):
    import re
    txt = path.read_text(errors="replace")
    c = collections.Counter(re.findall(r"#\d+\s*=\s*([A-Z_0-9]+)\s*\(", txt))
    names = sorted(re.findall(r"\bPRODUCT\s*\(\s*'([^']*)'", txt))
    return c, names


@pytest.mark.parametrize("name", STEP)
def test_step_round_trip(tmp_path, name):
    pytest.importorskip("OCP")
    src = OCC / name
    recs = _read(src)
    out = tmp_path / "same.stp"
    _write(out, recs, src)
    assert out.read_bytes() == src.read_bytes()
    faired, changed, tol = ([], [], 0.0) if name.startswith("OCC22459") else _fair_all(recs)
    if not changed:
        # OCC22459: 7 curves of ~20 control points each take ~30 s with the default method;
        # trj7_c2-ec-214: the never-worse guard keeps the input (inflections 1 -> 3). A
        # stand-in fairing (the middle control point of each moved by tol / 2) exercises
        # the same write path
        size = float(np.ptp(np.vstack([_pts(r.curve) for r in recs]), axis=0).max())
        tol = 1e-3 * size
        faired = []
        for r in recs:
            cp = np.array(r.curve.control_points)
            cp[len(cp) // 2] += tol / 2 / np.sqrt(cp.shape[1])
            faired.append(r.with_curve(r.curve.replace(control_points=cp)))
        changed = recs
    assert changed
    out = tmp_path / "out.stp"
    _write(out, faired, src)
    c0, n0 = _step_census(src)
    c1, n1 = _step_census(out)
    assert n1 == n0                                  # product names and count
    for k in ("PRODUCT", "STYLED_ITEM", "PRESENTATION_STYLE_ASSIGNMENT", "COLOUR_RGB",
              "DRAUGHTING_PRE_DEFINED_COLOUR", "PRESENTATION_LAYER_ASSIGNMENT",
              "NEXT_ASSEMBLY_USAGE_OCCURRENCE", "B_SPLINE_CURVE_WITH_KNOTS", "ADVANCED_FACE",
              "EDGE_CURVE"):
        assert c1[k] == c0[k], k
    # every free edge read back by OCC: faired ones within tol, the others unchanged
    p0, p1 = _occ_free_poles(src), _occ_free_poles(out)
    assert len(p0) == len(p1)
    moved = {int(r.source["edge"]) for r in changed}
    for k, (a, b) in enumerate(zip(p0, p1, strict=True)):
        if a is None:
            assert b is None
            continue
        assert a.shape == b.shape
        d = float(np.linalg.norm(a - b, axis=1).max())
        if k in moved:
            assert d <= tol * (1 + 1e-12), (k, d, tol)
        else:
            assert d == 0.0, k
    # outside the edited instances the text is the template's
    lines0 = src.read_text(errors="replace").splitlines()
    lines1 = set(out.read_text(errors="replace").splitlines())
    kept = sum(ln in lines1 for ln in lines0)
    assert kept >= len(lines0) - 12 * len(changed) - sum(len(_pts(r.curve)) for r in changed)


def test_iges_unchanged_bytes_and_refusal(tmp_path, monkeypatch):
    """OCC131-6.igs: OCC builds its free edges from the 2-D curves of a curve on a surface
    (142, preferred representation 1), converted to 3-D; no 126 entity of the file holds the
    curve that is read. The reader skips such edges (tests/test_iges_surface_curve.py); read
    with that check switched off, a faired curve still cannot be written into the file: the
    writer refuses and nothing is written. Written back unchanged, the file is the same
    bytes."""
    pytest.importorskip("OCP")
    import curvefair.io.occ as occ

    src = OCC / "OCC131-6.igs"
    with pytest.warns(UserWarning, match="bound to a surface"):
        with pytest.raises(FileFormatError, match="no curves"):
            read_curves(src, on_unsupported="skip")
    monkeypatch.setattr(occ, "_iges_surface_bound", lambda *a, **k: "")
    recs = _read(src)
    assert len(recs) == 3
    out = tmp_path / "same.igs"
    _write(out, recs, src)
    assert out.read_bytes() == src.read_bytes()
    cp = np.array(recs[0].curve.control_points)
    cp[len(cp) // 2] += 0.01
    out = tmp_path / "out.igs"
    with pytest.raises(FileFormatError, match="nothing was written"):
        _write(out, [recs[0].with_curve(recs[0].curve.replace(control_points=cp))] + recs[1:],
                src)
    assert not out.exists()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".out.igs")]


def test_iges_free_curves_patched_in_place(tmp_path):
    """A file of free 126 curves (written here by OCC's IGES writer, as a CAD program would):
    the faired curve's parameter data replaces the entity's, every other line is the same, and
    OCC reads the new curve back."""
    pytest.importorskip("OCP")
    from curvefair import BSplineCurve

    rng = np.random.default_rng(7)
    curves = [BSplineCurve(rng.random((8, 3)) * 50, np.r_[[0.0] * 4, .2, .4, .6, .8, [1.0] * 4], 3)
              for _ in range(3)]
    src = tmp_path / "src.igs"
    write_curves(src, curves)
    recs = _read(src)
    cp = np.array(recs[1].curve.control_points)
    cp[3] += [0.125, -0.25, 0.5]
    new = recs[1].curve.replace(control_points=cp)
    out = tmp_path / "out.igs"
    write_curves(out, [recs[0], recs[1].with_curve(new), recs[2]], template=src)
    p0, p1 = _occ_free_poles(src), _occ_free_poles(out)
    np.testing.assert_array_equal(p1[0], p0[0])
    np.testing.assert_array_equal(p1[2], p0[2])
    np.testing.assert_allclose(p1[1], cp, rtol=0, atol=1e-12)
    a = src.read_text().splitlines()
    b = out.read_text().splitlines()
    diff = [x for x in b if x not in set(a)]
    assert a[0] == b[0] and len(diff) <= 8      # only the P lines of one 126 and its pointers
    assert sum(ln[72] == "D" for ln in a) == sum(ln[72] == "D" for ln in b)
    shutil.copyfile(out, tmp_path / "again.igs")
    assert len(read_curves(tmp_path / "again.igs")) == 3
