"""IGES (entity 126) and STEP (``b_spline_curve_with_knots``) through Open CASCADE.

Needs ``pip install 'curvefair[occ]'`` (the ``cadquery-ocp`` wheels, Open CASCADE 7.7+).

Read
----
The file is translated by OCC's IGES / STEP reader (lengths converted to millimetres, OCC's
default) and every *free* edge -- one that bounds no face: IGES curve entities, STEP
geometric curve sets and wires -- whose 3-D curve is a non-rational B-spline becomes a
``kind="bspline"`` record: clamped curves open, OCC-periodic curves closed. Edges of faces are
not read (fairing a face boundary would tear the face off its surface); lines, circles and
other analytic curves are left alone; rational or trimmed B-splines are unsupported
(``on_unsupported``). A curve whose control points all have the same z is 2-D
(``source["z"]``). ``source`` keys: ``edge`` (index among the free edges), ``z``.

Write
-----
A new file through OCC's IGES writer (curves as entity 126, millimetres) or STEP writer
(``AsIs``: B-spline curves as ``b_spline_curve_with_knots`` in a geometric set). With
``template=`` the template's shape is read and its free edges that the records came from are
replaced by the faired curves (``BRepTools_ReShape``); the rest of the shape (faces, solids,
other edges) is written back geometrically unchanged, but OCC writes the file anew: entity
numbering, names, colours and layers of the original are not kept. STEP stores 12 significant
digits, so a read -> write -> read round trip agrees to about 1e-12 relative, not bit for bit.
"""

from __future__ import annotations

import contextlib
import os
import warnings
from collections.abc import Sequence
from typing import Any

import numpy as np

from ..curves.bspline import BSplineCurve
from ..errors import CurvefairError, FileFormatError, InputError
from ._common import (
    CurveRecord,
    Unsupported,
    atomic_path,
    bspline_of,
    is_clamped,
    joined_points,
    lazy_import,
    points_curve,
)

__all__ = ["read", "write"]


def _occ(what: str) -> Any:
    return lazy_import("OCP", "cadquery-ocp", "occ", what)


def _fmt_of(path: object) -> str:
    ext = os.path.splitext(os.fspath(path))[1].lower()  # type: ignore[arg-type]
    return "iges" if ext in (".igs", ".iges") else "step"


@contextlib.contextmanager
def _quiet() -> Any:
    """OCC's translators print progress on the C-level stdout: send it to /dev/null."""
    import sys

    try:
        sys.stdout.flush()
        fd = os.dup(1)
    except (OSError, ValueError):
        yield
        return
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 1)
        yield
    finally:
        os.dup2(fd, 1)
        os.close(fd)
        os.close(devnull)


def _read_shape(path: object, fmt: str, what: str) -> Any:
    _occ(what)
    from OCP.IFSelect import IFSelect_ReturnStatus
    from OCP.IGESControl import IGESControl_Reader
    from OCP.STEPControl import STEPControl_Reader

    p = os.fspath(path)  # type: ignore[arg-type]
    try:
        if os.path.getsize(p) == 0:
            raise FileFormatError(f"empty {fmt.upper()} file", path)
    except OSError as exc:
        raise FileFormatError(f"cannot read the file: {exc.strerror or exc}", path) from None
    reader = IGESControl_Reader() if fmt == "iges" else STEPControl_Reader()
    with _quiet():
        status = reader.ReadFile(p)
        if status != IFSelect_ReturnStatus.IFSelect_RetDone:
            raise FileFormatError(f"not a readable {fmt.upper()} file (OCC: {status.name})", path)
        reader.TransferRoots()
        if reader.NbShapes() == 0:
            raise FileFormatError(f"no shapes in the {fmt.upper()} file", path)
        return reader.OneShape()


class _ShapeSet:
    """Shapes up to orientation (``IsSame``), hashed by OCC's shape hash."""

    def __init__(self) -> None:
        self._buckets: dict[int, list[Any]] = {}

    def add(self, shape: Any) -> bool:
        """Add; False if an equal shape was there."""
        bucket = self._buckets.setdefault(hash(shape), [])
        if any(shape.IsSame(o) for o in bucket):
            return False
        bucket.append(shape)
        return True

    def __contains__(self, shape: Any) -> bool:
        return any(shape.IsSame(o) for o in self._buckets.get(hash(shape), []))


def _free_edges(shape: Any) -> list[Any]:
    """Edges of ``shape`` that bound no face, each once, in exploration order."""
    from OCP.TopAbs import TopAbs_ShapeEnum
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    in_faces = _ShapeSet()
    ex = TopExp_Explorer(shape, TopAbs_ShapeEnum.TopAbs_FACE)
    while ex.More():
        fe = TopExp_Explorer(ex.Current(), TopAbs_ShapeEnum.TopAbs_EDGE)
        while fe.More():
            in_faces.add(fe.Current())
            fe.Next()
        ex.Next()
    to_edge = getattr(TopoDS, "Edge_s", None) or TopoDS.Edge  # 7.x / 8.x spelling
    seen = _ShapeSet()
    out = []
    ex = TopExp_Explorer(shape, TopAbs_ShapeEnum.TopAbs_EDGE)
    while ex.More():
        e = ex.Current()
        if e not in in_faces and seen.add(e):
            out.append(to_edge(e))
        ex.Next()
    return out


def _bspline_of_edge(edge: Any) -> tuple[BSplineCurve, float | None]:
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.GeomAbs import GeomAbs_CurveType

    ad = BRepAdaptor_Curve(edge)
    if ad.GetType() != GeomAbs_CurveType.GeomAbs_BSplineCurve:
        raise LookupError(ad.GetType().name)
    bs = ad.BSpline()
    n = bs.NbPoles()
    if bs.IsRational():
        w = np.array([bs.Weight(i) for i in range(1, n + 1)])
        if not np.all(w == 1.0):
            raise Unsupported("rational B-spline (weights other than 1)")
    xyz = np.array([(bs.Pole(i).X(), bs.Pole(i).Y(), bs.Pole(i).Z()) for i in range(1, n + 1)])
    ks = bs.KnotSequence()
    flat = np.array([ks.Value(i) for i in range(ks.Lower(), ks.Upper() + 1)], dtype=float)
    p = int(bs.Degree())
    first, last = ad.FirstParameter(), ad.LastParameter()
    tol = 1e-12 * max(1.0, abs(first), abs(last))
    if abs(first - bs.FirstParameter()) > tol or abs(last - bs.LastParameter()) > tol:
        raise Unsupported(f"trimmed B-spline (edge range [{first}, {last}] of "
                           f"[{bs.FirstParameter()}, {bs.LastParameter()}])")
    z: float | None = None
    pts = xyz
    if np.all(xyz[:, 2] == xyz[0, 2]):
        pts, z = xyz[:, :2], float(xyz[0, 2])
    if p < 2:
        raise Unsupported(f"degree-{p} B-spline")
    if bs.IsPeriodic():
        return BSplineCurve(pts, flat, p, closed=True), z
    if not is_clamped(flat, p):
        raise Unsupported("unclamped non-periodic B-spline")
    return BSplineCurve(pts, flat, p, closed=False), z


def read(path: str | os.PathLike[str], *, on_unsupported: str = "raise",
         **_: Any) -> list[CurveRecord]:
    """Read the free B-spline curves of an IGES or STEP file; see the module docstring."""
    fmt = _fmt_of(path)
    shape = _read_shape(path, fmt, f"reading {fmt.upper()} files")
    records: list[CurveRecord] = []
    for k, edge in enumerate(_free_edges(shape)):
        try:
            curve, z = _bspline_of_edge(edge)
        except LookupError:
            continue
        except Unsupported as exc:
            msg = f"edge {k}: unsupported {exc}"
            if on_unsupported == "raise":
                raise FileFormatError(msg + " (read_curves(..., on_unsupported='skip') skips "
                                      "it)", path) from None
            warnings.warn(f"{os.fspath(path)}: skipped {msg}", UserWarning, stacklevel=3)
            continue
        except CurvefairError as exc:
            raise FileFormatError(f"edge {k}: {exc}", path) from None
        src = {"format": fmt, "path": os.path.abspath(path), "index": len(records), "edge": k,
               "z": z}
        records.append(CurveRecord(curve, f"edge{k}", "bspline", src))
    return records


def _geom(curve: BSplineCurve, z: float | None) -> Any:
    from OCP.Geom import Geom_BSplineCurve
    from OCP.gp import gp_Pnt

    try:  # cadquery-ocp >= 8: NCollection arrays live in OCP.OCP.collections
        from OCP.OCP import collections as _c

        pnt_a, real_a, int_a = _c.Array1_gp_Pnt, _c.Array1_double, _c.Array1_int
    except (ImportError, AttributeError):  # 7.x
        from OCP.TColgp import TColgp_Array1OfPnt as pnt_a
        from OCP.TColStd import TColStd_Array1OfInteger as int_a
        from OCP.TColStd import TColStd_Array1OfReal as real_a

    def arr(cls: Any, vals: Sequence[Any]) -> Any:
        a = cls(1, len(vals))
        for i, v in enumerate(vals):
            a.SetValue(i + 1, v)
        return a

    p = curve.degree
    cps = np.asarray(curve.control_points, dtype=float)
    if cps.shape[1] == 2:
        cps = np.c_[cps, np.full(cps.shape[0], 0.0 if z is None else z)]
    if curve.closed:
        flat = curve.knots[p: p + curve.n_ctrl + 1]
    else:
        flat = curve.knots
    knots, mults = np.unique(flat, return_counts=True)
    if curve.closed and mults[0] != mults[-1]:
        raise InputError("write_curves: a periodic curve needs the same knot multiplicity at "
                         "both ends of its period")
    poles = arr(pnt_a, [gp_Pnt(*map(float, q)) for q in cps])
    return Geom_BSplineCurve(poles, arr(real_a, [float(k) for k in knots]),
                             arr(int_a, [int(m) for m in mults]), p, bool(curve.closed))


def _edge(curve: BSplineCurve, z: float | None) -> Any:
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge

    mk = BRepBuilderAPI_MakeEdge(_geom(curve, z))
    if not mk.IsDone():
        raise InputError("write_curves: OCC could not make an edge of the curve")
    return mk.Edge()


def write(path: str | os.PathLike[str], records: Sequence[CurveRecord], *,
          template: str | None = None, **_: Any) -> None:
    """Write an IGES or STEP file; see the module docstring."""
    fmt = _fmt_of(path)
    _occ(f"writing {fmt.upper()} files")
    from OCP.BRep import BRep_Builder
    from OCP.BRepTools import BRepTools_ReShape
    from OCP.IFSelect import IFSelect_ReturnStatus
    from OCP.IGESControl import IGESControl_Writer
    from OCP.STEPControl import STEPControl_StepModelType, STEPControl_Writer
    from OCP.TopoDS import TopoDS_Compound

    builder = BRep_Builder()
    comp = TopoDS_Compound()
    builder.MakeCompound(comp)
    ours: list[CurveRecord] = []
    if template is not None:
        tfmt = _fmt_of(template)
        shape = _read_shape(template, tfmt, f"writing {fmt.upper()} files")
        edges = _free_edges(shape)
        ours = [r for r in records if r.format == tfmt and r.path is not None
                and os.path.abspath(r.path) == os.path.abspath(template)]
        reshape = BRepTools_ReShape()
        for r in ours:
            k = int(r.source["edge"])
            if not 0 <= k < len(edges):
                raise InputError(f"write_curves: the template has no free edge {k}")
            reshape.Replace(edges[k], _edge(bspline_of(r.curve, "write_curves"),
                                            r.source.get("z")))
        builder.Add(comp, reshape.Apply(shape))
    others = [r for r in records if not any(r is o for o in ours)]
    groups: dict[Any, list[CurveRecord]] = {}
    for i, r in enumerate(others):
        key = (r.path, r.format, r.source.get("handle"), r.source.get("id"),
               r.source.get("element")) if "indices" in r.source else ("single", i)
        groups.setdefault(key, []).append(r)
    for recs in groups.values():
        rec = recs[0]
        if "indices" in rec.source:
            pts = joined_points(recs, "write_curves")
            rec = rec.with_curve(points_curve(pts, bool(rec.source.get("closed"))))
        builder.Add(comp, _edge(bspline_of(rec.curve, "write_curves"), rec.source.get("z")))
    with atomic_path(path) as tmp, _quiet():
        if fmt == "iges":
            w = IGESControl_Writer("MM", 0)
            w.AddShape(comp)
            w.ComputeModel()
            ok = w.Write(os.fspath(tmp))
        else:
            sw = STEPControl_Writer()
            sw.Transfer(comp, STEPControl_StepModelType.STEPControl_AsIs)
            ok = sw.Write(os.fspath(tmp)) == IFSelect_ReturnStatus.IFSelect_RetDone
        if not ok:
            raise InputError(f"write_curves: OCC could not write {os.fspath(path)!r}")
