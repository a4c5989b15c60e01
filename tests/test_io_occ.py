"""IGES and STEP through Open CASCADE (cadquery-ocp): free B-spline curves, write-back.

References: OCC's own evaluation of the edges in the file (``BRepAdaptor_Curve.Value``),
independent of curvefair. IGES stores about 10 significant digits and STEP 12, so geometry
is compared to those precisions, not bit for bit.
"""

from __future__ import annotations

import sys

import numpy as np
import pytest

from curvefair import (
    BSplineCurve,
    FileFormatError,
    MissingDependencyError,
    interpolate_cubic,
    read_curves,
    write_curves,
)

pytest.importorskip("OCP")

from OCP.BRep import BRep_Builder  # noqa: E402
from OCP.BRepAdaptor import BRepAdaptor_Curve  # noqa: E402
from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox  # noqa: E402
from OCP.IGESControl import IGESControl_Writer  # noqa: E402
from OCP.STEPControl import STEPControl_StepModelType, STEPControl_Writer  # noqa: E402
from OCP.TopoDS import TopoDS_Compound  # noqa: E402

from curvefair.io.occ import _edge, _free_edges, _quiet, _read_shape  # noqa: E402

TOL = {"igs": 2e-9, "step": 1e-11}


def _curves():
    rng = np.random.default_rng(4)
    open3 = BSplineCurve(rng.random((7, 3)) * 10, [0, 0, 0, 0, .3, .5, .8, 1, 1, 1, 1], 3)
    a = np.arange(7.0)
    per = BSplineCurve(np.c_[np.cos(a), np.sin(1.3 * a)] * 5, np.arange(8.0), 3, closed=True)
    quart = BSplineCurve(rng.random((6, 2)), [0, 0, 0, 0, 0, .5, 1, 1, 1, 1, 1], 4)
    herm = interpolate_cubic(np.c_[np.arange(5.0), np.sqrt(np.arange(5.0))])
    return [open3, per, quart, herm]


def _occ_points(path, ext):
    """Every free edge of the file evaluated by OCC at 41 parameters of its range."""
    shape = _read_shape(path, "iges" if ext == "igs" else "step", "test")
    out = []
    for e in _free_edges(shape):
        ad = BRepAdaptor_Curve(e)
        u = np.linspace(ad.FirstParameter(), ad.LastParameter(), 41)
        out.append((u, np.array([[ad.Value(t).X(), ad.Value(t).Y(), ad.Value(t).Z()]
                                 for t in u])))
    return out


@pytest.mark.parametrize("ext", ["igs", "step"])
def test_write_read_against_occ_evaluation(tmp_path, ext):
    curves = _curves()
    p = tmp_path / f"c.{ext}"
    write_curves(p, curves)
    recs = read_curves(p)
    assert [r.kind for r in recs] == ["bspline"] * 4
    occ = _occ_points(p, ext)
    assert len(occ) == 4
    for c, r, (u, ref) in zip(curves, recs, occ, strict=True):
        assert r.curve.degree == c.degree and r.curve.dim == c.dim
        got = r.curve(u)
        np.testing.assert_allclose(got, ref[:, : c.dim], atol=TOL[ext] * 10)
        # and the same geometry as written (same parameterisation)
        np.testing.assert_allclose(r.curve.domain, c.domain, atol=TOL[ext] * 10)
        uu = np.linspace(*c.domain, 41)
        np.testing.assert_allclose(r.curve(np.clip(uu, *r.curve.domain)), c(uu),
                                   atol=TOL[ext] * 10)
    # the Hermite curve is written with double knots (C1), not split at every point
    assert recs[3].curve.n_ctrl == 10
    if ext == "step":
        assert recs[1].curve.closed and recs[1].curve.n_ctrl == 7
        np.testing.assert_array_equal(recs[1].curve.knots, curves[1].knots)


@pytest.mark.parametrize("ext", ["igs", "step"])
def test_template_write_back_keeps_the_solid(tmp_path, ext):
    box = BRepPrimAPI_MakeBox(10.0, 20.0, 30.0).Shape()
    curves = _curves()[:2]
    comp = TopoDS_Compound()
    b = BRep_Builder()
    b.MakeCompound(comp)
    b.Add(comp, box)
    for c in curves:
        b.Add(comp, _edge(c, None))
    src = tmp_path / f"src.{ext}"
    with _quiet():
        if ext == "igs":
            w = IGESControl_Writer("MM", 1)
            w.AddShape(comp)
            w.ComputeModel()
            assert w.Write(str(src))
        else:
            sw = STEPControl_Writer()
            sw.Transfer(comp, STEPControl_StepModelType.STEPControl_AsIs)
            sw.Write(str(src))
    recs = read_curves(src)
    assert len(recs) == 2                     # the box's 12 edges bound faces: not read
    cp = np.array(recs[0].curve.control_points)
    cp[3] += [0.5, -0.5, 0.25]
    faired = recs[0].curve.replace(control_points=cp)
    out = tmp_path / f"out.{ext}"
    write_curves(out, [recs[0].with_curve(faired), recs[1]], template=src)
    back = read_curves(out)
    assert len(back) == 2
    u = np.linspace(*faired.domain, 30)
    np.testing.assert_allclose(back[0].curve(u), faired(u), atol=TOL[ext] * 100)
    u = np.linspace(*recs[1].curve.domain, 30)
    np.testing.assert_allclose(back[1].curve(u), recs[1].curve(u), atol=TOL[ext] * 100)
    from OCP.TopAbs import TopAbs_ShapeEnum
    from OCP.TopExp import TopExp_Explorer

    shape = _read_shape(out, "iges" if ext == "igs" else "step", "test")
    n = 0
    ex = TopExp_Explorer(shape, TopAbs_ShapeEnum.TopAbs_FACE)
    while ex.More():
        n += 1
        ex.Next()
    assert n == 6


def test_bad_files(tmp_path):
    (tmp_path / "e.step").write_bytes(b"")
    with pytest.raises(FileFormatError, match="empty"):
        read_curves(tmp_path / "e.step")
    (tmp_path / "g.step").write_text("ISO-10303-21;\nHEADER;\ngarbage(((\n")
    with pytest.raises(FileFormatError, match="not a readable STEP|no shapes"):
        read_curves(tmp_path / "g.step")
    (tmp_path / "g.igs").write_bytes(b"\x00\x01\x02 not iges at all\n" * 10)
    with pytest.raises(FileFormatError, match="IGES"):
        read_curves(tmp_path / "g.igs")
    box = BRepPrimAPI_MakeBox(1.0, 1.0, 1.0).Shape()
    with _quiet():
        sw = STEPControl_Writer()
        sw.Transfer(box, STEPControl_StepModelType.STEPControl_AsIs)
        sw.Write(str(tmp_path / "box.step"))
    with pytest.raises(FileFormatError, match="no curves"):
        read_curves(tmp_path / "box.step")


def test_missing_ocp(tmp_path, monkeypatch):
    p = tmp_path / "a.step"
    p.write_text("x")
    monkeypatch.setitem(sys.modules, "OCP", None)
    with pytest.raises(MissingDependencyError, match=r"curvefair\[occ\]"):
        read_curves(p)
