"""Rhino .3dm through rhino3dm (openNURBS): NURBS curves, polylines, write-back by object id.

References: curves read are evaluated against openNURBS' own ``NurbsCurve.PointAt`` (an
implementation independent of curvefair). No .3dm file written by other software with a
usable licence could be found on PyPI (see tests/data/README.md), so the models are built
here with rhino3dm, i.e. with openNURBS itself.
"""

from __future__ import annotations

import sys

import numpy as np
import pytest

from curvefair import (
    BSplineCurve,
    FileFormatError,
    InputError,
    MissingDependencyError,
    interpolate_cubic,
    read_curves,
    write_curves,
)

rh = pytest.importorskip("rhino3dm")


def _p(x, y, z=0.0):
    return rh.Point3d(float(x), float(y), float(z))


def _model(path):
    m = rh.File3dm()
    lay = rh.Layer()
    lay.Name = "Curves"
    lay.Color = (200, 30, 30, 255)
    m.Layers.Add(lay)
    lay2 = rh.Layer()
    lay2.Name = "Other"
    m.Layers.Add(lay2)
    ids = {}

    def add(geom, name, layer=0):
        a = rh.ObjectAttributes()
        a.Name = name
        a.LayerIndex = layer
        ids[name] = str(m.Objects.Add(geom, a))

    rng = np.random.default_rng(2)
    open3 = rh.NurbsCurve.Create(False, 3, [_p(*q) for q in rng.random((7, 3)) * 5])
    for k, v in enumerate([0, 0, 0, 0.5, 1.5, 3, 4, 4, 4]):
        open3.Knots[k] = v
    add(open3, "open3d")
    add(rh.NurbsCurve.Create(False, 4, [_p(x, np.sin(x), 1.25) for x in np.linspace(0, 6, 9)]),
        "planar_deg4")
    a = np.linspace(0, 2 * np.pi, 10)[:-1]
    add(rh.NurbsCurve.Create(True, 3, [_p(3 * np.cos(t), 2 * np.sin(t)) for t in a]),
        "periodic")
    add(rh.PolylineCurve([_p(0, 0), _p(1, 0.1), _p(2, 0.3), _p(3, 0.2), _p(4, 0), _p(4, 1),
                          _p(4.2, 2)]), "polyline")
    add(rh.LineCurve(_p(0, 0), _p(10, 10)), "line", 1)
    a2 = rh.ObjectAttributes()
    a2.Name = "circle"
    a2.LayerIndex = 1
    ids["circle"] = str(m.Objects.AddCircle(rh.Circle(_p(5, 5), 2.0), a2))
    m.Objects.AddPoint(_p(1, 2, 3))
    m.Write(str(path), 7)
    return ids


def _read(p, polylines=True):
    # the model's circle is stored by openNURBS as a rational NURBS curve: not faired, skipped
    with pytest.warns(UserWarning, match="'circle'.*rational"):
        return read_curves(p, on_unsupported="skip", polylines=polylines)


def _pointat(g, u):
    return np.array([[g.PointAt(float(t)).X, g.PointAt(float(t)).Y, g.PointAt(float(t)).Z]
                     for t in u])


def test_read_matches_opennurbs_evaluation(tmp_path):
    p = tmp_path / "m.3dm"
    ids = _model(p)
    # by default the polyline is a drawn shape, left as drawn
    assert {r.source["id"] for r in _read(p, polylines=False)} == \
        {ids[k] for k in ("open3d", "planar_deg4", "periodic")}
    recs = _read(p)
    by = {}
    for r in recs:
        by.setdefault(r.source["id"], []).append(r)
    assert set(by) == {ids[k] for k in ("open3d", "planar_deg4", "periodic", "polyline")}
    model = rh.File3dm.Read(str(p))
    geo = {str(model.Objects[i].Attributes.Id): model.Objects[i].Geometry
           for i in range(len(model.Objects))}
    for key, dim, closed, deg in [("open3d", 3, False, 3), ("planar_deg4", 2, False, 4),
                                  ("periodic", 2, True, 3)]:
        (r,) = by[ids[key]]
        c = r.curve
        assert isinstance(c, BSplineCurve) and (c.dim, c.closed, c.degree) == (dim, closed, deg)
        assert r.name == key and r.source["layer"] == "Curves"
        g = geo[ids[key]]
        u = np.linspace(g.Domain.T0, g.Domain.T1, 101)
        ref = _pointat(g, u)
        np.testing.assert_allclose(c.domain, (g.Domain.T0, g.Domain.T1), atol=1e-14)
        np.testing.assert_allclose(c(u), ref[:, :dim], atol=1e-12)
        if dim == 2:
            np.testing.assert_allclose(ref[:, 2], r.source["z"])
    assert by[ids["periodic"]][0].curve.n_ctrl == 9
    pl = by[ids["polyline"]]
    assert [x.source["indices"].tolist() for x in pl] == [[0, 1, 2, 3, 4], [4, 5, 6]]


def test_write_back_edits_only_the_faired_objects(tmp_path):
    p = tmp_path / "m.3dm"
    ids = _model(p)
    recs = _read(p)
    out = []
    for r in recs:
        c = r.curve
        if r.source["id"] == ids["periodic"]:
            cp = np.array(c.control_points)
            cp[0] += [0.2, -0.1]
            out.append(r.with_curve(c.replace(control_points=cp)))
        elif r.source["id"] == ids["polyline"]:
            pts = np.array(c.points)
            pts[1:-1] += 0.05
            out.append(r.with_curve(c.replace(points=pts)))
        else:
            out.append(r)
    dst = tmp_path / "o.3dm"
    write_curves(dst, out, template=p)
    a, b = rh.File3dm.Read(str(p)), rh.File3dm.Read(str(dst))
    assert len(a.Objects) == len(b.Objects)
    assert [a.Layers[i].Name for i in range(len(a.Layers))] == \
        [b.Layers[i].Name for i in range(len(b.Layers))]
    for i in range(len(a.Objects)):
        oa, ob = a.Objects[i], b.Objects[i]
        assert str(oa.Attributes.Id) == str(ob.Attributes.Id)
        assert oa.Attributes.Name == ob.Attributes.Name
        assert oa.Attributes.LayerIndex == ob.Attributes.LayerIndex
        assert type(oa.Geometry) is type(ob.Geometry)
        if str(oa.Attributes.Id) in (ids["periodic"], ids["polyline"]):
            continue
        bb_a, bb_b = oa.Geometry.GetBoundingBox(), ob.Geometry.GetBoundingBox()
        assert (bb_a.Min.X, bb_a.Min.Y, bb_a.Max.X, bb_a.Max.Y) == \
            (bb_b.Min.X, bb_b.Min.Y, bb_b.Max.X, bb_b.Max.Y)
    back = _read(dst)
    for r, f in zip(back, out, strict=True):
        assert r.source["id"] == f.source["id"] and r.kind == f.kind
        if r.kind == "bspline":
            np.testing.assert_array_equal(r.curve.control_points, f.curve.control_points)
            np.testing.assert_array_equal(r.curve.knots, f.curve.knots)
            assert r.curve.closed == f.curve.closed
        else:
            np.testing.assert_array_equal(r.curve.points, f.curve.points)
    g = next(b.Objects[i].Geometry for i in range(len(b.Objects))
             if str(b.Objects[i].Attributes.Id) == ids["periodic"])
    assert g.IsPeriodic


def test_changed_degree_replaces_geometry_keeping_id(tmp_path):
    p = tmp_path / "m.3dm"
    ids = _model(p)
    recs = _read(p)
    r = next(x for x in recs if x.source["id"] == ids["open3d"])
    # a degree-5 curve through the same ends
    u = np.linspace(0, 1, 8)
    new = BSplineCurve(np.c_[u, u**2, u**3], np.r_[[0] * 6, 0.3, 0.6, [1] * 6], 5)
    write_curves(tmp_path / "o.3dm", [x.with_curve(new) if x is r else x for x in recs],
                 template=p)
    back = {x.source["id"]: x for x in _read(tmp_path / "o.3dm")}
    c = back[ids["open3d"]].curve
    assert c.degree == 5 and back[ids["open3d"]].name == "open3d"
    np.testing.assert_allclose(c(np.linspace(0, 1, 9)), new(np.linspace(0, 1, 9)), atol=1e-12)


def test_new_model_without_template(tmp_path):
    h = interpolate_cubic(np.c_[np.arange(5.0), np.sqrt(np.arange(5.0))])
    b = BSplineCurve(np.c_[np.cos(np.arange(6)), np.sin(np.arange(6))], np.arange(7.0), 3,
                     closed=True)
    write_curves(tmp_path / "n.3dm", [h, b])
    back = read_curves(tmp_path / "n.3dm")
    assert [x.kind for x in back] == ["bspline", "bspline"]
    u = np.linspace(*h.domain, 30)
    np.testing.assert_allclose(back[0].curve(u), h(u), atol=1e-12)
    assert back[1].curve.closed
    np.testing.assert_array_equal(back[1].curve.knots, b.knots)


def test_unsupported_and_garbage(tmp_path):
    m = rh.File3dm()
    c = rh.NurbsCurve.Create(False, 2, [_p(0, 0), _p(1, 1), _p(2, 0)])
    c.Points.MakeRational()
    c.Points[1] = rh.Point4d(2.0, 2.0, 0.0, 2.0)
    m.Objects.AddCurve(c)
    m.Objects.AddCurve(rh.NurbsCurve.Create(False, 3, [_p(0, 0), _p(1, 1), _p(2, 0),
                                                       _p(3, 1)]))
    m.Write(str(tmp_path / "r.3dm"), 7)
    with pytest.raises(FileFormatError, match="rational"):
        read_curves(tmp_path / "r.3dm")
    with pytest.warns(UserWarning, match="rational"):
        assert len(read_curves(tmp_path / "r.3dm", on_unsupported="skip")) == 1
    (tmp_path / "g.3dm").write_bytes(b"3D Geometry File Format " + b"\x00garbage" * 50)
    with pytest.raises(FileFormatError, match="not a readable 3dm"):
        read_curves(tmp_path / "g.3dm")
    (tmp_path / "e.3dm").write_bytes(b"")
    with pytest.raises(FileFormatError, match="empty"):
        read_curves(tmp_path / "e.3dm")
    m = rh.File3dm()
    m.Objects.AddPoint(_p(0, 0))
    m.Write(str(tmp_path / "n.3dm"), 7)
    with pytest.raises(FileFormatError, match="no curves"):
        read_curves(tmp_path / "n.3dm")
    p = tmp_path / "m.3dm"
    _model(p)
    with pytest.raises(InputError, match="overwrite"):
        write_curves(p, _read(p), template=p)


def test_missing_rhino3dm(tmp_path, monkeypatch):
    p = tmp_path / "m.3dm"
    p.write_bytes(b"x")
    monkeypatch.setitem(sys.modules, "rhino3dm", None)
    with pytest.raises(MissingDependencyError, match=r"curvefair\[rhino\]"):
        read_curves(p)


def test_periodic_curve_with_few_control_points_is_skipped_not_fatal(tmp_path):
    # openNURBS' v5_example_file.3dm (see tests/data/README.md): a periodic degree-5
    # NurbsCurve with 10 control points, 5 of them distinct -- a curve Rhino draws and
    # curvefair's closed B-spline cannot hold (it needs degree + 1). It is skipped with a
    # warning and written back as it was; the file's other curves are faired.
    from pathlib import Path

    from click.testing import CliRunner

    from curvefair.cli import main

    src = Path(__file__).parent / "data" / "real" / "opennurbs" / "v5_example_file.3dm"
    m0 = rh.File3dm.Read(str(src))
    ident = "e43f7908-793f-4793-85d3-c11d2d7bffb5"
    obj0 = {str(o.Attributes.Id): o for o in m0.Objects}
    g0 = obj0[ident].Geometry
    assert g0.IsPeriodic and g0.Degree == 5 and len(g0.Points) == 10  # the case
    with pytest.raises(FileFormatError, match=f"{ident}.*periodic degree-5.*5 distinct"):
        read_curves(src)
    out = tmp_path / "out.3dm"
    res = CliRunner().invoke(main, ["fair", str(src), "-o", str(out), "--tol", "0.05"])
    assert res.exit_code == 0, res.output
    assert ident in res.output and "wrote" in res.output
    m1 = rh.File3dm.Read(str(out))
    obj1 = {str(o.Attributes.Id): o for o in m1.Objects}
    assert set(obj1) == set(obj0)
    g1 = obj1[ident].Geometry
    def cps(g):
        return [(q.X, q.Y, q.Z, q.W) for q in (g.Points[i] for i in range(len(g.Points)))]

    assert cps(g1) == cps(g0)
    assert list(g1.Knots) == list(g0.Knots)
    # at least one other curve was faired, each within tol where it moved
    moved = 0
    for k, o in obj0.items():
        g, h = o.Geometry, obj1[k].Geometry
        if k == ident or not isinstance(g, rh.NurbsCurve) or not isinstance(h, rh.NurbsCurve):
            continue
        a, b = np.array(cps(g)), np.array(cps(h))
        if a.shape == b.shape and np.any(a != b):
            moved += 1
            t = np.linspace(g.Domain.T0, g.Domain.T1, 400)
            pa = np.array([(q.X, q.Y, q.Z) for q in map(g.PointAt, t)])
            pb = np.array([(q.X, q.Y, q.Z) for q in map(h.PointAt, t)])
            assert np.max(np.linalg.norm(pa - pb, axis=1)) <= 0.05 + 1e-9
    assert moved >= 1
