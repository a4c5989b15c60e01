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
Without a template: a new file through OCC's IGES writer (curves as entity 126, millimetres)
or STEP writer (``AsIs``: B-spline curves as ``b_spline_curve_with_knots`` in a geometric set).

With ``template=`` (the file the records were read from) the template's own text is edited,
never re-translated by OCC, so entity numbering, product structure, names, colours, styles
and layers stay as they were:

- no curve changed: the template's bytes are copied unchanged;
- STEP: each faired edge is matched to the one ``B_SPLINE_CURVE_WITH_KNOTS`` instance whose
  degree, knots and control points are the edge's curve as OCC read it (control points times
  the file's length unit, before the edge's location); the ``CARTESIAN_POINT`` instances of
  the poles that moved get the new coordinates (a point shared with another instance, e.g. a
  vertex, is left alone and the curve gets a new point), knots only if they changed;
- IGES: the same match against the free entities 126 (not those under a trimmed surface 144,
  a bounded surface 143 or a BRep edge list 504); its parameter data is rewritten and the
  parameter section renumbered (directory pointers, line counts, terminate section);
- numbers are written as the shortest text that reads back to the same float64.

The written file is then read again with OCC and checked: the same number of solids, shells,
faces, wires, edges and vertices, every free edge that was not faired where it was, every
faired one on its faired curve (1e-9 of the model's size). Where no unique match exists
(OCC built the edge from another entity, e.g. the 2-D curve of a curve on a surface 142, or
converted it; periodic curves; an IGES transformation matrix; curves from other files to add)
or the check fails, nothing is written and :class:`~curvefair.FileFormatError` (or
:class:`~curvefair.InputError` for foreign curves) says why.
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import warnings
from collections.abc import Sequence
from typing import Any

import numpy as np

from .._typing import FloatArray
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


def _fmt_of(path: str | os.PathLike[str]) -> str:
    ext = os.path.splitext(os.fspath(path))[1].lower()
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

    p = os.fspath(path)  # type: ignore[call-overload]
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
         format: str | None = None, **_: Any) -> list[CurveRecord]:
    """Read the free B-spline curves of an IGES or STEP file (``format`` ``"iges"`` or
    ``"step"``, else by the extension); see the module docstring."""
    fmt = format if format in ("iges", "step") else _fmt_of(path)
    shape = _read_shape(path, fmt, f"reading {fmt.upper()} files")
    records: list[CurveRecord] = []
    model: dict[str, Any] = {}           # the IGES text's entities, parsed once when needed
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
        if fmt == "iges":
            why = _iges_surface_bound(path, edge, k, model)
            if why:
                msg = f"edge {k}: unsupported {why}"
                if on_unsupported == "raise":
                    raise FileFormatError(msg + " (read_curves(..., on_unsupported='skip') "
                                          "skips it)", path)
                warnings.warn(f"{os.fspath(path)}: skipped {msg}; kept untouched", UserWarning,
                              stacklevel=3)
                continue
        src = {"format": fmt, "path": os.path.abspath(path), "index": len(records), "edge": k,
               "z": z}
        records.append(CurveRecord(curve, f"edge{k}", "bspline", src))
    return records


def _iges_surface_bound(path: object, edge: Any, k: int, model: dict[str, Any]) -> str:
    """Why the free edge ``k`` cannot be faired in this IGES file, or "": OCC built it from
    a curve on a surface (142) whose preferred representation is its 2-D curve on the
    surface, not from a free 126 entity. A faired 3-D curve is off that surface (by up to
    tol), so it could be written neither as the 142's image of its 2-D curve nor as its
    model-space curve without making the 142 contradict itself."""
    try:
        if not model:
            with open(os.fspath(path), "rb") as fh:  # type: ignore[call-overload]
                model.update(_iges_model(fh.read().decode("latin-1")) or {"bad": True})
        bs, _trsf = _orig_curve(edge)
    except (_Refuse, OSError, LookupError, ValueError, IndexError):
        model.setdefault("bad", True)
        return ""
    if "cands" not in model:
        return ""
    mod = model
    local, knots, p = _local_poles(bs)
    if any(_match(c[2], c[3], c[4], local, knots, p) is not None for c in mod["cands"]):
        return ""
    note = _surface_curve_note(mod["ents"], mod["params"])
    if not note:
        return ""
    return ("curve bound to a surface: no free 126 entity holds it" + note
            + "; a faired 3-D curve would leave its surface")


def _geom(curve: BSplineCurve, z: float | None) -> Any:
    from OCP.Geom import Geom_BSplineCurve
    from OCP.gp import gp_Pnt

    try:  # cadquery-ocp >= 8: NCollection arrays live in OCP.OCP.collections
        from OCP.OCP import collections as _c

        pnt_a, real_a, int_a = _c.Array1_gp_Pnt, _c.Array1_double, _c.Array1_int
    except (ImportError, AttributeError):  # 7.x
        import OCP.TColgp as _tg
        import OCP.TColStd as _ts

        pnt_a = _tg.TColgp_Array1OfPnt
        int_a, real_a = _ts.TColStd_Array1OfInteger, _ts.TColStd_Array1OfReal

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


def _compound_of(records: Sequence[CurveRecord]) -> Any:
    from OCP.BRep import BRep_Builder
    from OCP.TopoDS import TopoDS_Compound

    builder = BRep_Builder()
    comp = TopoDS_Compound()
    builder.MakeCompound(comp)
    groups: dict[Any, list[CurveRecord]] = {}
    for i, r in enumerate(records):
        key = (r.path, r.format, r.source.get("handle"), r.source.get("id"),
               r.source.get("element")) if "indices" in r.source else ("single", i)
        groups.setdefault(key, []).append(r)
    for recs in groups.values():
        rec = recs[0]
        if "indices" in rec.source:
            pts = joined_points(recs, "write_curves")
            rec = rec.with_curve(points_curve(pts, bool(rec.source.get("closed"))))
        builder.Add(comp, _edge(bspline_of(rec.curve, "write_curves"), rec.source.get("z")))
    return comp


def _write_new(path: str | os.PathLike[str], fmt: str, records: Sequence[CurveRecord]) -> None:
    from OCP.IFSelect import IFSelect_ReturnStatus
    from OCP.IGESControl import IGESControl_Writer
    from OCP.STEPControl import STEPControl_StepModelType, STEPControl_Writer

    comp = _compound_of(records)
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


def _same_curve(a: BSplineCurve, b: BSplineCurve) -> bool:
    return (a.degree == b.degree and a.closed == b.closed
            and np.array_equal(a.knots, b.knots)
            and np.array_equal(np.asarray(a.control_points), np.asarray(b.control_points)))


def _edge_samples(edge: Any, m: int = 33) -> FloatArray:
    from OCP.BRepAdaptor import BRepAdaptor_Curve

    ad = BRepAdaptor_Curve(edge)
    u = np.linspace(ad.FirstParameter(), ad.LastParameter(), m)
    return np.array([(ad.Value(t).X(), ad.Value(t).Y(), ad.Value(t).Z()) for t in u])


def _census(shape: Any) -> dict[str, int]:
    """Distinct solids, shells, faces, wires, edges and vertices of a shape."""
    from OCP.TopAbs import TopAbs_ShapeEnum
    from OCP.TopExp import TopExp_Explorer

    out = {}
    for name in ("SOLID", "SHELL", "FACE", "WIRE", "EDGE", "VERTEX"):
        seen = _ShapeSet()
        ex = TopExp_Explorer(shape, getattr(TopAbs_ShapeEnum, f"TopAbs_{name}"))
        n = 0
        while ex.More():
            n += seen.add(ex.Current())
            ex.Next()
        out[name.lower()] = n
    return out


def _verify(written: object, fmt: str, shape: Any, edges: list[Any],
            patches: list[_Patch]) -> None:
    """Re-read the patched file with OCC: the same topology, every edge that was not faired
    where it was (1e-9 of the model's size), every faired one on its faired curve."""
    back = _read_shape(written, fmt, "checking the written file")
    if _census(back) != _census(shape):
        raise _Refuse(f"OCC reads the patched file with {_census(back)} instead of "
                      f"{_census(shape)}")
    bedges = _free_edges(back)
    if len(bedges) != len(edges):
        raise _Refuse(f"OCC reads {len(bedges)} free edges in the patched file, not "
                      f"{len(edges)}")
    want = {pa.k: pa for pa in patches}
    ref = [_edge_samples(e) for e in edges]
    size = max(max(float(np.abs(r).max()) for r in ref), 1.0)
    for k, (e, r) in enumerate(zip(bedges, ref, strict=True)):
        got = _edge_samples(e)
        if k in want:
            c = bspline_of(want[k].rec.curve, "write_curves")
            u = np.linspace(*c.domain, got.shape[0])
            exp = c(u)
            exp = np.c_[exp, np.full(exp.shape[0], want[k].rec.source.get("z") or 0.0)] \
                if exp.shape[1] == 2 else exp
        else:
            exp = r
        err = float(np.abs(got - exp).max())
        if not err <= 1e-9 * size:
            raise _Refuse(f"edge {k} of the patched file is {err:.3g} from "
                          f"{'the faired curve' if k in want else 'the original'}")


def write(path: str | os.PathLike[str], records: Sequence[CurveRecord], *,
          template: str | None = None, format: str | None = None, **_: Any) -> None:
    """Write an IGES or STEP file (``format`` ``"iges"`` or ``"step"``, else by the
    extension: a temporary file or an output without one); see the module docstring."""
    fmt = format if format in ("iges", "step") else _fmt_of(path)
    _occ(f"writing {fmt.upper()} files")
    if template is None:
        _write_new(path, fmt, records)
        return
    tfmt = _fmt_of(template)
    ours = [r for r in records if r.format == tfmt and r.path is not None
            and os.path.abspath(r.path) == os.path.abspath(template)]
    mine = {id(r) for r in ours}  # (a set: a drawing's 10,000 records, not 10,000 squared)
    others = [r for r in records if id(r) not in mine]
    if tfmt != fmt or others:
        why = (f"the template is {tfmt.upper()}" if tfmt != fmt else
               f"{len(others)} curve(s) do not come from {os.fspath(template)!r}")
        raise InputError(f"write_curves: {fmt.upper()} write-back edits the template's own "
                         f"curves only and {why}; write them to a new file (no template)")
    shape = _read_shape(template, tfmt, f"writing {fmt.upper()} files")
    edges = _free_edges(shape)
    patches = []
    for r in ours:
        k = int(r.source["edge"])
        if not 0 <= k < len(edges):
            raise InputError(f"write_curves: the template has no free edge {k}")
        try:
            orig, _z = _bspline_of_edge(edges[k])
        except (LookupError, Unsupported, CurvefairError):
            raise InputError(f"write_curves: free edge {k} of the template is not a "
                             "B-spline curve curvefair reads") from None
        new = bspline_of(r.curve, "write_curves")
        if _same_curve(new, orig):
            continue
        try:
            patches.append(_Patch(k, edges[k], r, orig))
        except _Refuse as exc:
            raise _refused(template, fmt, str(exc)) from None
    if not patches:                     # nothing changed: the template's bytes as they are
        with atomic_path(path) as tmp:
            shutil.copyfile(os.fspath(template), tmp)
        return
    with open(os.fspath(template), "rb") as fh:
        raw = fh.read()
    try:
        text = raw.decode("latin-1")
        out = _patch_step(text, patches) if fmt == "step" else _patch_iges(text, patches)
        with atomic_path(path) as tmp:
            with open(tmp, "wb") as fh:
                fh.write(out.encode("latin-1"))
            _verify(tmp, fmt, shape, edges, patches)
    except _Refuse as exc:
        raise _refused(template, fmt, str(exc)) from None


def _refused(template: object, fmt: str, why: str) -> FileFormatError:
    return FileFormatError(f"cannot write the faired curves back into this {fmt.upper()} file "
                           f"without losing or changing what was not faired ({why}); nothing "
                           "was written. Write the curves to a new file (no template) to get "
                           "them without the rest of the model", template)


# ------------------------------------------------------------------------------------------
# write-back into the template's own text (STEP Part 21 / IGES fixed format)
# ------------------------------------------------------------------------------------------
def _num(v: float, exp: str = "E") -> str:
    """A real as the shortest text that reads back to the same float64, with a decimal point
    (STEP and IGES reals need one: ``1.``, ``1.5E-05``)."""
    s = repr(float(v))
    mant, _, ex = s.partition("e")
    if "." not in mant:
        mant += "."
    return mant + (exp + ex if ex else "")


def _orig_curve(edge: Any) -> tuple[Any, Any]:
    """(local Geom_BSplineCurve, edge location gp_Trsf) of a free edge."""
    from OCP.BRep import BRep_Tool
    from OCP.GeomAbs import GeomAbs_CurveType
    from OCP.GeomAdaptor import GeomAdaptor_Curve
    from OCP.TopLoc import TopLoc_Location

    loc = TopLoc_Location()
    c = BRep_Tool.Curve_s(edge, loc, 0.0, 0.0)
    ad = GeomAdaptor_Curve(c)
    if ad.GetType() != GeomAbs_CurveType.GeomAbs_BSplineCurve:
        raise LookupError("not a B-spline")
    return ad.BSpline(), loc.Transformation()


def _local_poles(bs: Any) -> tuple[FloatArray, FloatArray, int]:
    n = bs.NbPoles()
    xyz = np.array([(bs.Pole(i).X(), bs.Pole(i).Y(), bs.Pole(i).Z()) for i in range(1, n + 1)])
    ks = bs.KnotSequence()
    flat = np.array([ks.Value(i) for i in range(ks.Lower(), ks.Upper() + 1)], dtype=float)
    return xyz, flat, int(bs.Degree())


def _apply(trsf: Any, xyz: FloatArray, inverse: bool = False) -> FloatArray:
    from OCP.gp import gp_XYZ

    t = trsf.Inverted() if inverse else trsf
    out = np.empty_like(xyz)
    for i, q in enumerate(xyz):
        v = gp_XYZ(float(q[0]), float(q[1]), float(q[2]))
        t.Transforms(v)
        out[i] = (v.X(), v.Y(), v.Z())
    return out


def _new_poles(curve: BSplineCurve, z: float | None) -> tuple[FloatArray, FloatArray, int]:
    """Global 3-D poles, full knot vector and degree of a record's curve as OCC holds it."""
    g = _geom(curve, z)
    return _local_poles(g)


def _match(raw: FloatArray, raw_knots: FloatArray, degree: int, poles: FloatArray,
           knots: FloatArray, p: int) -> float | None:
    """Scale s with ``poles == s * raw`` (the file's length unit in OCC's millimetres) if the
    raw entity is this curve (same degree, knots, poles to 1e-9 of the curve's size)."""
    if degree != p or raw.shape != poles.shape or raw_knots.shape != knots.shape:
        return None
    span = max(abs(knots[-1] - knots[0]), 1e-300)
    size = max(float(np.abs(poles).max()), 1e-300)
    den = float(np.sum(raw * raw))
    if den == 0.0:
        return None
    s = float(np.sum(raw * poles)) / den
    if not s > 0:
        return None
    if np.max(np.abs(raw * s - poles)) > 1e-9 * size:
        return None
    # OCC keeps the file's knots as they are (possibly scaled: compare normalised)
    a = (raw_knots - raw_knots[0]) / max(raw_knots[-1] - raw_knots[0], 1e-300)
    b = (knots - knots[0]) / span
    if np.max(np.abs(a - b)) > 1e-9:
        return None
    return s


class _Patch:
    """One faired edge to write into the template's text."""

    def __init__(self, k: int, edge: Any, rec: CurveRecord, orig: BSplineCurve) -> None:
        self.k = k
        self.rec = rec
        bs, self.trsf = _orig_curve(edge)
        self.old_geom = bs
        self.old_local, self.old_knots, self.p = _local_poles(bs)
        curve = bspline_of(rec.curve, "write_curves")
        # poles the fairing did not move keep their text exactly
        a, b = np.asarray(curve.control_points), np.asarray(orig.control_points)
        self.kept = np.all(a == b, axis=1) if a.shape == b.shape and \
            np.array_equal(curve.knots, orig.knots) else np.zeros(a.shape[0], dtype=bool)
        new_glob, self.new_knots, self.new_p = _new_poles(curve, rec.source.get("z"))
        self.new_local = _apply(self.trsf, new_glob, inverse=True)
        self.periodic = bool(curve.closed or bs.IsPeriodic())
        if self.periodic != bool(bs.IsPeriodic()):
            raise _Refuse(f"edge {k}: a periodic curve faired into an open one or back")
        self.geom = _geom(curve, rec.source.get("z"))

    def raw_poles(self, scale: float) -> FloatArray:
        return self.new_local / scale

    def raw_knots(self, old_raw: FloatArray) -> FloatArray:
        """The new knots in the file's own parameterisation (OCC keeps it; an affine map)."""
        if np.array_equal(self.new_knots, self.old_knots):
            return old_raw
        a = (old_raw[-1] - old_raw[0]) / (self.old_knots[-1] - self.old_knots[0])
        return old_raw[0] + (self.new_knots - self.old_knots[0]) * a


class _Refuse(Exception):
    """The faired curves cannot be written into the template's text without loss."""


def _mults(flat: FloatArray) -> tuple[list[float], list[int]]:
    knots: list[float] = []
    mults: list[int] = []
    for v in flat:
        if knots and v == knots[-1]:
            mults[-1] += 1
        else:
            knots.append(float(v))
            mults.append(1)
    return knots, mults


# ---- STEP -------------------------------------------------------------------------------
def _step_instances(text: str) -> list[tuple[int, int, int, str]]:
    """(id, start, end, body) of every ``#id = ...;`` instance of the DATA section; ``end`` is
    the index after the ``;``. Strings ('...', '' inside) and comments are skipped."""
    out = []
    m = re.search(r"^\s*DATA\s*(?:\([^;]*\))?\s*;", text, re.M)
    if m is None:
        raise _Refuse("no DATA section")
    i, n = m.end(), len(text)
    head = re.compile(r"\s*#(\d+)\s*=\s*")
    while i < n:
        h = head.match(text, i)
        if h is None:
            rest = text[i:].lstrip()
            if rest.startswith("ENDSEC") or rest.startswith("/*"):
                if rest.startswith("/*"):
                    j = text.index("*/", i) + 2
                    i = j
                    continue
                break
            raise _Refuse(f"cannot parse the DATA section near character {i}")
        j = h.end()
        start = i + (len(text[i:h.end()]) - len(text[i:h.end()].lstrip()))
        while j < n:
            c = text[j]
            if c == "'":
                j += 1
                while j < n:
                    if text[j] == "'":
                        if j + 1 < n and text[j + 1] == "'":
                            j += 2
                            continue
                        break
                    j += 1
            elif c == "/" and text.startswith("/*", j):
                j = text.index("*/", j) + 1
            elif c == ";":
                break
            j += 1
        out.append((int(h.group(1)), start, j + 1, text[h.end():j]))
        i = j + 1
    return out


def _step_parse(body: str) -> tuple[str, list[Any]]:
    """``NAME(args)`` -> (NAME, args); args nested lists of atom strings."""
    m = re.match(r"\s*([A-Z_][A-Z0-9_]*)\s*\(", body)
    if m is None:
        raise ValueError("not a simple instance")
    pos = m.end()

    def items(i: int) -> tuple[list[Any], int]:
        out: list[Any] = []
        cur = ""
        while i < len(body):
            c = body[i]
            if c == "'":
                j = i + 1
                while True:
                    j = body.index("'", j)
                    if body.startswith("''", j):
                        j += 2
                        continue
                    break
                cur += body[i:j + 1]
                i = j + 1
                continue
            if c == "(":
                sub, i = items(i + 1)
                out.append((cur.strip(), sub) if cur.strip() else sub)
                cur = ""
                continue
            if c == ")":
                if cur.strip():
                    out.append(cur.strip())
                return out, i + 1
            if c == ",":
                if cur.strip():
                    out.append(cur.strip())
                cur = ""
                i += 1
                continue
            cur += c
            i += 1
        raise ValueError("unbalanced parentheses")

    args, end = items(pos)
    if body[end:].strip():
        raise ValueError("trailing text")
    return m.group(1), args


def _strip_strings(body: str) -> str:
    return re.sub(r"'(?:[^']|'')*'", "''", body)


def _patch_step(text: str, patches: list[_Patch]) -> str:
    inst = _step_instances(text)
    by_id = {i: (s, e, b) for i, s, e, b in inst}
    refs: dict[int, int] = {}
    for _, _, _, b in inst:
        for r in re.findall(r"#(\d+)", _strip_strings(b)):
            refs[int(r)] = refs.get(int(r), 0) + 1
    points: dict[int, FloatArray] = {}
    names: dict[int, str] = {}

    def point(pid: int) -> FloatArray:
        if pid not in points:
            name, args = _step_parse(by_id[pid][2])
            if name != "CARTESIAN_POINT":
                raise ValueError(name)
            points[pid] = np.array([float(v) for v in args[1]], dtype=float)
            names[pid] = args[0] if isinstance(args[0], str) else "''"
        return points[pid]

    cands = []
    for i, _, _, b in inst:
        try:
            cur = _StepBSpline.of(b)
            if cur is None:
                continue
            pids = cur.pole_ids()
            raw = np.array([point(q) for q in pids])
            if raw.ndim != 2 or raw.shape[1] != 3:
                continue
            flat = cur.flat_knots(len(pids))
        except (ValueError, KeyError, IndexError, TypeError):
            continue
        cands.append((i, cur, pids, raw, flat, cur.degree))
    trims: dict[int, list[tuple[int, str, list[Any]]]] = {}
    for i, _, _, b in inst:
        if b.lstrip().startswith("TRIMMED_CURVE"):
            try:
                name, targs = _step_parse(b)
                trims.setdefault(int(targs[1][1:]), []).append((i, name, targs))
            except (ValueError, IndexError):
                continue
    next_id = max(by_id) + 1
    edits: dict[int, str] = {}
    new_lines: list[str] = []
    for pa in patches:
        hits = [(c, s) for c in cands
                if (s := _match(_unwrapped(c[3], pa), c[4], c[5], pa.old_local, pa.old_knots,
                                pa.p)) is not None]
        if len(hits) != 1:
            raise _Refuse(f"edge {pa.k}: {'no' if not hits else len(hits)} "
                          "B-spline curve instance(s) hold its curve as OCC read it")
        (cid, cur, pids, raw, flat, _), scale = hits[0]
        if cid in edits:
            raise _Refuse(f"edge {pa.k}: its curve #{cid} is shared with another faired edge")
        new = pa.raw_poles(scale)
        nknots = pa.raw_knots(flat)
        kept = pa.kept
        if pa.periodic:      # Part 42 lists a closed curve's first poles again at its end
            wrap = len(pids) - pa.old_local.shape[0]
            if new.shape[0] != pa.old_local.shape[0]:
                raise _Refuse(f"edge {pa.k}: a periodic curve with a new number of poles")
            new = np.vstack([new, new[:wrap]])
            kept = np.r_[kept, kept[:wrap]]
        for tid, _tname, targs in trims.get(cid, []):
            edits.update(_trim_edits(tid, targs, pa, scale, flat, nknots, by_id, refs, point,
                                     edits))
        new_ids: list[str] = []
        for j, q in enumerate(new):
            if j < len(pids) and (kept[j] or np.array_equal(q, raw[j])):
                new_ids.append(f"#{pids[j]}")
                continue
            label = names.get(pids[j], "''") if j < len(pids) else "''"
            body = f"CARTESIAN_POINT({label},(" + ",".join(_num(v) for v in q) + "))"
            if j < len(pids) and refs.get(pids[j], 0) == 1 and pids[j] not in edits:
                edits[pids[j]] = body
                new_ids.append(f"#{pids[j]}")
            else:
                new_lines.append(f"#{next_id}={body};")
                new_ids.append(f"#{next_id}")
                next_id += 1
        for q in pids[len(new):]:
            if refs.get(q, 0) == 1:
                edits[q] = ""               # an unshared pole no longer used: removed
        new_body = cur.render(pa.new_p, new_ids,
                              None if np.array_equal(nknots, flat) else nknots)
        if new_body is not None:
            edits[cid] = new_body
    out = []
    last = 0
    for i, s, e, b in inst:
        if i in edits:
            out.append(text[last:s])
            if edits[i]:
                out.append(text[s:e - 1 - len(b)] + edits[i] + ";")  # the same "#id = "
            elif text[e:e + 1] == "\n":
                e += 1
            last = e
    out.append(text[last:])
    result = "".join(out)
    if new_lines:
        at = _step_data_end(result)
        result = result[:at] + "\n".join(new_lines) + "\n" + result[at:]
    return result


def _unwrapped(raw: FloatArray, pa: _Patch) -> FloatArray:
    """The file's pole list of a closed curve without the repeated first poles (Part 42
    lists ``n + p`` poles of a periodic curve that OCC holds with ``n``), else as it is."""
    n = pa.old_local.shape[0]
    if pa.periodic and raw.shape[0] > n and np.array_equal(raw[n:], raw[:raw.shape[0] - n]):
        return raw[:n]
    return raw


class _StepBSpline:
    """A B-spline curve instance of a STEP file in any of its Part 42 forms: the simple
    ``B_SPLINE_CURVE_WITH_KNOTS``, ``QUASI_UNIFORM_CURVE``, ``UNIFORM_CURVE``,
    ``BEZIER_CURVE`` (knots implied by the subtype, ISO 10303-42 sec. 4.4.6 / 8.3), or a
    complex instance of ``B_SPLINE_CURVE`` with ``B_SPLINE_CURVE_WITH_KNOTS`` and a
    ``RATIONAL_B_SPLINE_CURVE`` whose weights are all 1 (the same polynomial curve).

    The control-point list is edited in place; the knots are written only when they
    changed (a subtype with implied knots then becomes a ``B_SPLINE_CURVE_WITH_KNOTS`` of
    the same name)."""

    IMPLIED = ("QUASI_UNIFORM_CURVE", "UNIFORM_CURVE", "BEZIER_CURVE")

    def __init__(self, kind: str, parts: list[tuple[str, list[Any]]]) -> None:
        self.kind = kind
        self.parts = parts

    @classmethod
    def of(cls, body: str) -> _StepBSpline | None:
        b = body.lstrip()
        if b.startswith("("):
            parts = _step_parse_complex(b)
            names = [n for n, _ in parts]
            if "B_SPLINE_CURVE" not in names or "B_SPLINE_CURVE_WITH_KNOTS" not in names \
                    or not set(names) <= {"BOUNDED_CURVE", "B_SPLINE_CURVE", "CURVE",
                                          "B_SPLINE_CURVE_WITH_KNOTS", "REPRESENTATION_ITEM",
                                          "GEOMETRIC_REPRESENTATION_ITEM",
                                          "RATIONAL_B_SPLINE_CURVE"}:
                return None
            if "RATIONAL_B_SPLINE_CURVE" in names:
                w = dict(parts)["RATIONAL_B_SPLINE_CURVE"][0]
                if not all(float(v) == 1.0 for v in w):
                    return None             # a rational curve: not read, so never matched
            return cls("complex", parts)
        for kind in ("B_SPLINE_CURVE_WITH_KNOTS",) + cls.IMPLIED:
            if b.startswith(kind) and re.match(kind + r"\s*\(", b):
                return cls(kind, [_step_parse(b)])
        return None

    def _bs(self) -> list[Any]:
        """Arguments (degree, poles, form, closed, self_intersect) of the B-spline part."""
        if self.kind == "complex":
            return dict(self.parts)["B_SPLINE_CURVE"]
        return self.parts[0][1][1:]

    @property
    def degree(self) -> int:
        return int(self._bs()[0])

    def pole_ids(self) -> list[int]:
        return [int(a[1:]) for a in self._bs()[1]]

    def flat_knots(self, n: int) -> FloatArray:
        p = self.degree
        if self.kind == "complex":
            k = dict(self.parts)["B_SPLINE_CURVE_WITH_KNOTS"]
            return np.repeat([float(v) for v in k[1]], [int(v) for v in k[0]])
        if self.kind == "B_SPLINE_CURVE_WITH_KNOTS":
            a = self.parts[0][1]
            return np.repeat([float(v) for v in a[7]], [int(v) for v in a[6]])
        if self.kind == "UNIFORM_CURVE":
            return np.arange(n + p + 1, dtype=float) - p
        if self.kind == "BEZIER_CURVE":
            return np.r_[np.zeros(p + 1), np.ones(p + 1)]
        return np.r_[np.zeros(p), np.arange(n - p + 1, dtype=float), np.full(p, n - p)]

    def render(self, p: int, ids: list[str], knots: FloatArray | None) -> str | None:
        """The instance's new body, or None when nothing changed."""
        bs = list(self._bs())
        new_bs = [str(p), ids] + bs[2:]
        kk, mm = _mults(knots) if knots is not None else ([], [])
        if self.kind == "complex":
            parts = []
            for name, args in self.parts:
                if name == "B_SPLINE_CURVE":
                    args = new_bs
                elif name == "B_SPLINE_CURVE_WITH_KNOTS" and knots is not None:
                    args = [[str(v) for v in mm], [_num(v) for v in kk]] + list(args[2:])
                elif name == "RATIONAL_B_SPLINE_CURVE" and len(args[0]) != len(ids):
                    args = [["1."] * len(ids)]
                parts.append((name, args))
            if parts == self.parts:
                return None
            return "(" + "\n".join(f"{n}({_step_join(a)})" for n, a in parts) + ")"
        name, args = self.parts[0]
        a = [args[0]] + new_bs
        if knots is not None:
            if name != "B_SPLINE_CURVE_WITH_KNOTS":
                name, a = "B_SPLINE_CURVE_WITH_KNOTS", a + [[], [], ".UNSPECIFIED."]
            a[6] = [str(v) for v in mm]
            a[7] = [_num(v) for v in kk]
        if name == self.parts[0][0] and a == list(args):
            return None
        return f"{name}(" + _step_join(a) + ")"


def _step_parse_complex(body: str) -> list[tuple[str, list[Any]]]:
    """``(A(..) B(..) ...)`` -> [(A, args), (B, args), ...] (a complex instance, Part 21
    sec. 11.2.5.3)."""
    inner = body.strip()
    if not (inner.startswith("(") and inner.endswith(")")):
        raise ValueError("not a complex instance")
    inner = inner[1:-1]
    out = []
    i = 0
    while inner[i:].strip():
        m = re.compile(r"\s*([A-Z_][A-Z0-9_]*)\s*\(").match(inner, i)
        if m is None:
            raise ValueError("bad complex instance")
        depth, j = 0, m.end() - 1
        while True:
            c = inner[j]
            if c == "'":
                j = inner.index("'", j + 1)
                while inner.startswith("''", j):
                    j = inner.index("'", j + 2)
            elif c == "(":
                depth += 1
            elif c == ")":
                depth -= 1
                if depth == 0:
                    break
            j += 1
        out.append(_step_parse(inner[m.start(1):j + 1]))
        i = j + 1
    return out


def _bare_real(v: Any) -> bool:
    if not isinstance(v, str) or v.startswith(("#", "$", ".", "'")):
        return False
    try:
        float(v)
    except ValueError:
        return False
    return True


def _trim_edits(tid: int, targs: list[Any], pa: _Patch, scale: float, flat: FloatArray,
                nknots: FloatArray, by_id: dict[int, tuple[int, int, str]],
                refs: dict[int, int], point: Any, edits: dict[int, str]) -> dict[int, str]:
    """Edits that keep a ``TRIMMED_CURVE`` of a faired basis curve consistent: parameter
    trims stay (the basis keeps its parameterisation; a trim at an end of the domain follows
    the end when the knots changed), a cartesian-point trim becomes the faired curve's point
    at the trim's parameter (the point is edited when only this trim refers to it; a trim
    given by a point alone is at an end of the domain, OCC having read the whole basis)."""
    out: dict[int, str] = {}
    params: list[float | None] = []
    for sel in (targs[2], targs[3]):
        vals = [float(v[1][0]) for v in sel if isinstance(v, tuple)
                and v[0] == "PARAMETER_VALUE"]
        vals += [float(v) for v in sel if _bare_real(v)]   # "(0.E0)": written by some
        params.append(vals[0] if vals else None)
    a = list(targs)
    placed: dict[int, FloatArray] = {}
    changed_knots = not np.array_equal(nknots, flat)
    lo, hi = flat[pa.p], flat[-pa.p - 1]
    forward = str(targs[4]).strip() != ".F."
    for k, sel in ((2, targs[2]), (3, targs[3])):
        u = params[k - 2]
        if u is None:
            # cartesian trims only: OCC read the edge over the basis's whole domain (else the
            # reader skips it as trimmed), so the trims are its ends, in the sense given
            u = float(lo if (k == 2) == forward else hi)
        if changed_knots:
            if u not in (lo, hi):
                raise _Refuse(f"trimmed curve #{tid}: the faired knots move its trim "
                              f"parameter {u!r}")
            nu = nknots[pa.new_p] if u == lo else nknots[-pa.new_p - 1]
        else:
            nu = u
        # the OCC parameter of the trim: the file's parameterisation mapped affinely
        t = pa.new_knots[0] + (nu - nknots[0]) * (
            (pa.new_knots[-1] - pa.new_knots[0]) / max(nknots[-1] - nknots[0], 1e-300))
        q = pa.geom.Value(float(t))
        q0 = pa.old_geom.Value(float(pa.old_knots[0] + (u - flat[0]) * (
            (pa.old_knots[-1] - pa.old_knots[0]) / max(flat[-1] - flat[0], 1e-300))))
        still = (q.X(), q.Y(), q.Z()) == (q0.X(), q0.Y(), q0.Z())   # the curve did not move there
        local = _apply(pa.trsf, np.array([[q.X(), q.Y(), q.Z()]]), inverse=True)[0] / scale
        new_sel: list[Any] = []
        for v in sel:
            if isinstance(v, tuple) and v[0] == "PARAMETER_VALUE":
                new_sel.append(v if nu == u else ("PARAMETER_VALUE", [_num(nu)]))
            elif _bare_real(v):
                new_sel.append(v if nu == u else _num(nu))
            elif isinstance(v, str) and v.startswith("#"):
                pid = int(v[1:])
                old = point(pid)
                if old.shape != local.shape:
                    raise _Refuse(f"trimmed curve #{tid}: trim point #{pid} is not 3-D")
                if (still or np.array_equal(old, local)) and pid not in placed:
                    placed[pid] = local
                    new_sel.append(v)
                    continue
                text = "(" + ",".join(_num(x) for x in local) + ")"
                if pid in placed:
                    # one point for both trims (the ends of a closed curve): the same point
                    # to rounding, else the trims contradict each other
                    size = max(float(np.abs(local).max()), 1.0)
                    if float(np.abs(placed[pid] - local).max()) > 1e-12 * size:
                        raise _Refuse(f"trimmed curve #{tid}: trim point #{pid} names two "
                                      "different points of the faired curve")
                    new_sel.append(v)
                    continue
                placed[pid] = local
                own = sum(1 for w in (targs[2] + targs[3]) if w == v)
                if refs.get(pid, 0) != own or pid in edits:
                    raise _Refuse(f"trimmed curve #{tid}: its trim point #{pid} is shared "
                                  "with other entities")
                _name, pargs = _step_parse(by_id[pid][2])
                out[pid] = f"CARTESIAN_POINT({pargs[0]},{text})"
                new_sel.append(v)
            else:
                new_sel.append(v)
        a[k] = new_sel
    if a != list(targs):
        out[tid] = "TRIMMED_CURVE(" + _step_join(a) + ")"
    return out


def _step_data_end(text: str) -> int:
    m = re.search(r"^\s*DATA\s*(?:\([^;]*\))?\s*;", text, re.M)
    e = re.compile(r"^\s*ENDSEC\s*;", re.M).search(text, m.end() if m else 0)
    if m is None or e is None:
        raise _Refuse("no end of the DATA section")
    return e.start() + (len(e.group(0)) - len(e.group(0).lstrip()))


def _step_join(items: list[Any]) -> str:
    parts = []
    for it in items:
        if isinstance(it, tuple):
            parts.append(f"{it[0]}({_step_join(it[1])})")
        elif isinstance(it, list):
            parts.append(f"({_step_join(it)})")
        else:
            parts.append(it)
    return ",".join(parts)


# ---- IGES -------------------------------------------------------------------------------
def _iges_sections(text: str) -> tuple[list[str], str]:
    lines = text.splitlines()
    nl = "\r\n" if "\r\n" in text[:200] else "\n"
    for k, ln in enumerate(lines):
        if len(ln) < 73 or ln[72] not in "SGDPT":
            if ln.strip() == "" and k == len(lines) - 1:
                continue
            raise _Refuse(f"line {k + 1} is not an 80-column IGES record")
    return lines, nl


def _iges_delims(glines: list[str]) -> tuple[str, str]:
    g = "".join(ln[:72] for ln in glines)
    delims = []
    i = 0
    for default in (",", ";"):
        if g.startswith("1H", i):
            delims.append(g[i + 2])
            i += 3
            if len(delims) == 1:
                # the field after the parameter delimiter is separated by it
                i += 1
        else:
            delims.append(default)
            i += 1
    return delims[0], delims[1]


def _iges_fields(data: str, pd: str, rd: str) -> list[str]:
    """Parameter data of one entity split at the delimiters (126 holds no strings)."""
    data = data.split(rd, 1)[0]
    return [f.strip() for f in data.split(pd)]


def _iges_real(s: str) -> float:
    return float(s.replace("D", "E").replace("d", "e")) if s else 0.0


def _iges_model(text: str) -> dict[str, Any]:
    """The sections, directory entries, parameter blocks and the free 126 entities (those
    under no face: trimmed surface 144, bounded surface 143, BRep edge list 504) of an IGES
    text, for matching OCC's edges to the file's entities."""
    lines, nl = _iges_sections(text)
    sec = {c: [ln for ln in lines if len(ln) >= 73 and ln[72] == c] for c in "SGDPT"}
    pd, rd = _iges_delims(sec["G"])
    de = sec["D"]
    if len(de) % 2:
        raise _Refuse("odd number of directory entry lines")
    blocks: dict[int, list[str]] = {}
    order: list[int] = []
    for ln in sec["P"]:
        d = int(ln[65:72])
        if d not in blocks:
            order.append(d)
            blocks[d] = []
        blocks[d].append(ln)
    ents = {}
    for j in range(0, len(de), 2):
        a, b = de[j], de[j + 1]
        dnum = j + 1
        ents[dnum] = (int(a[0:8]), a[48:56].strip(), b)
    # 126 entities that bound a face (144 -> 142 -> 102 -> 126) are not free edges
    in_face: set[int] = set()

    def params(d: int) -> list[str]:
        return _iges_fields("".join(ln[:64] for ln in blocks.get(d, [])), pd, rd)

    def mark(d: int, depth: int = 0) -> None:
        if d not in ents or depth > 8:
            return
        t = ents[d][0]
        f = params(d)
        if t == 126:
            in_face.add(d)
        elif t == 102:
            for q in f[2:2 + int(f[1])]:
                mark(int(q), depth + 1)
        elif t == 142:
            for q in f[3:5]:
                if q and int(q):
                    mark(int(q), depth + 1)
        elif t == 144:
            n2 = int(f[3])
            for q in [f[4]] + f[5:5 + n2]:
                if q and int(q):
                    mark(int(q), depth + 1)
        elif t == 141:
            n = int(f[4])
            i = 5
            for _ in range(n):
                mark(int(f[i]), depth + 1)
                k = int(f[i + 2])
                i += 3 + k

    for d, (t, _, _) in ents.items():
        if t in (144, 143):
            try:
                if t == 144:
                    mark(d)
                else:
                    f = params(d)
                    for q in f[4:4 + int(f[3])]:
                        mark(int(q))
            except (ValueError, IndexError):
                raise _Refuse(f"cannot follow the face entity at DE {d}") from None
        if t == 504:                    # edge list of BRep faces: N, then (CURV, SVP, SV, EVP, EV)
            try:
                f = params(d)
                for e in range(int(f[1])):
                    mark(int(f[2 + 5 * e]))
            except (ValueError, IndexError):
                raise _Refuse(f"cannot follow the edge list at DE {d}") from None
    cands = []
    for d, (t, tm, _) in ents.items():
        if t != 126 or d in in_face:
            continue
        try:
            f = params(d)
            k, m = int(f[1]), int(f[2])
            n_knots = k + m + 2
            base = 7
            knots = np.array([_iges_real(v) for v in f[base:base + n_knots]])
            w = np.array([_iges_real(v) for v in f[base + n_knots:base + n_knots + k + 1]])
            c0 = base + n_knots + k + 1
            raw = np.array([_iges_real(v) for v in f[c0:c0 + 3 * (k + 1)]]).reshape(-1, 3)
        except (ValueError, IndexError):
            continue
        if tm not in ("", "0"):
            continue                    # a transformation matrix: not matched (refused below)
        if not np.all(w == w[0]):
            continue
        cands.append((d, f, raw, knots, m, c0))
    return {"nl": nl, "sec": sec, "pd": pd, "rd": rd, "de": de, "blocks": blocks,
            "order": order, "ents": ents, "params": params, "cands": cands}


def _patch_iges(text: str, patches: list[_Patch]) -> str:
    mod = _iges_model(text)
    nl, sec, pd, rd, de = mod["nl"], mod["sec"], mod["pd"], mod["rd"], mod["de"]
    blocks, order, ents, params, cands = (mod["blocks"], mod["order"], mod["ents"],
                                          mod["params"], mod["cands"])
    new_blocks = dict(blocks)
    done: set[int] = set()
    first = sec["P"][0] if sec["P"] else " " * 80
    zpad = first[73:80].startswith("0") or first[65:72].startswith("0")   # "0000003P0000012"
    seq = "{:07d}" if zpad else "{:7d}"
    for pa in patches:
        hits = [(c, s) for c in cands
                if (s := _match(c[2], c[3], c[4], pa.old_local, pa.old_knots, pa.p)) is not None]
        if len(hits) != 1:
            raise _Refuse(f"edge {pa.k}: {'no' if not hits else len(hits)} free 126 "
                          "entities hold its curve as OCC read it; OCC may have built the "
                          "edge from another entity, e.g. a curve on a surface (142)"
                          + _surface_curve_note(ents, params))
        (d, f, raw, knots, m, c0), scale = hits[0]
        if pa.periodic:
            raise _Refuse(f"edge {pa.k} is a periodic curve")
        if d in done:
            raise _Refuse(f"edge {pa.k}: entity {d} is shared with another faired edge")
        done.add(d)
        new = pa.raw_poles(scale)
        nk = pa.raw_knots(knots)
        kk = new.shape[0] - 1
        same_layout = nk.shape == knots.shape and kk == raw.shape[0] - 1
        nf = f[:1] + [str(kk), str(pa.new_p)] + f[3:7]
        if same_layout:
            nf += [ov if v == o else _num(v) for v, o, ov in
                   zip(nk, knots, f[7:7 + len(knots)], strict=True)]
            nf += f[7 + len(knots):c0]
        else:
            nf += [_num(v) for v in nk] + ["1."] * (kk + 1)
        for j, pt in enumerate(new):
            for c in range(3):
                idx = c0 + 3 * j + c
                same = same_layout and (bool(pa.kept[j]) or pt[c] == raw[j, c])
                nf.append(f[idx] if same else _num(pt[c]))
        tail = f[c0 + 3 * raw.shape[0]:]
        if not same_layout or nk[pa.new_p] != knots[m] or nk[-pa.new_p - 1] != knots[-m - 1]:
            tail = [_num(nk[pa.new_p]), _num(nk[-pa.new_p - 1])] + tail[2:]
        nf += tail
        new_blocks[d] = _iges_block(nf, pd, rd, d, zpad)
    # renumber the parameter section and the directory entries' pointers and counts
    out_p: list[str] = []
    start: dict[int, int] = {}
    for d in order:
        start[d] = len(out_p) + 1
        for ln in new_blocks[d]:
            out_p.append(ln[:73] + seq.format(len(out_p) + 1))
    new_de = []
    for j in range(0, len(de), 2):
        a, b = de[j], de[j + 1]
        d = j + 1
        if d in start and int(a[8:16]) != start[d]:
            a = a[:8] + _pad(start[d], a[8:16]) + a[16:]
        if d in start and int(b[24:32]) != len(new_blocks[d]):
            b = b[:24] + _pad(len(new_blocks[d]), b[24:32]) + b[32:]
        new_de += [a, b]
    tr = sec["T"][0]
    if int(tr[25:32]) != len(out_p):
        tr = tr[:24] + "P" + _pad(len(out_p), tr[25:32]) + tr[32:]
    return nl.join(sec["S"] + sec["G"] + new_de + out_p + [tr]) + nl


def _surface_curve_note(ents: dict[int, Any], params: Any) -> str:
    """Why a curve on a surface cannot take a faired curve, naming the entities: a 142 whose
    preferred representation is its 2-D curve on the surface (PREF 1, or 0 with a 2-D curve)
    is read by OCC as the image of that curve on the surface; the faired 3-D curve has moved
    off the surface (by up to tol), so it can be neither that image nor a model-space curve
    (CPTR) of the same 142 without making the entity contradict itself, and pointing CPTR at
    it with PREF 2 changes how OCC splits every other edge of the 142."""
    notes = []
    for d, (t, _, _) in sorted(ents.items()):
        if t != 142:
            continue
        try:
            f = params(d)
            sptr, bptr, cptr, pref = int(f[2]), int(f[3]), int(f[4]), int(f[5])
        except (ValueError, IndexError):
            continue
        if bptr and pref in (0, 1):
            notes.append(f"DE {d}: the 2-D curve DE {bptr} on surface DE {sptr}, preference "
                         f"{pref}" + (f", model-space curve DE {cptr} not used" if cptr else ""))
    if not notes:
        return ""
    return ("; OCC built edges from curves on a surface (" + "; ".join(notes) + "): a faired "
            "3-D curve is off that surface, so it cannot be written there without making the "
            "142 inconsistent")


def _pad(v: int, like: str) -> str:
    """``v`` in a fixed field as wide as ``like``, zero-padded if ``like`` is."""
    w = len(like)
    return f"{v:0{w}d}" if like.startswith("0") else f"{v:{w}d}"


def _iges_block(fields: list[str], pd: str, rd: str, d: int, zpad: bool) -> list[str]:
    toks = [f + pd for f in fields[:-1]] + [fields[-1] + rd]
    rows, cur = [], ""
    for tk in toks:
        if len(cur) + len(tk) > 64:
            rows.append(cur)
            cur = ""
        cur += tk
    rows.append(cur)
    de = f"{d:07d}" if zpad else f"{d:7d}"
    return [f"{r:<64s} {de}P{0:07d}" for r in rows]
