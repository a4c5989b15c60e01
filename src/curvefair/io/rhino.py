"""Rhino ``.3dm`` models through rhino3dm / openNURBS (``pip install 'curvefair[rhino]'``).

Read
----
Every object whose geometry is a ``NurbsCurve`` or a ``PolylineCurve`` (instance definitions
are not read; lines, arcs and other geometry are left alone):

- non-rational ``NurbsCurve`` of degree >= 2 -> ``kind="bspline"``: clamped knots give an open
  curve, periodic ones (``IsPeriodic``: the first ``degree`` control points repeated at the
  end) a closed curve. openNURBS stores ``n + p - 1`` knots; the two "superfluous" end knots
  are added back (``Knots.SuperfluousKnot``), so the knot vector is the usual full one;
- degree-1 ``NurbsCurve`` and ``PolylineCurve`` (also as a ``PolyCurve``'s one segment):
  **drawn shapes, not read** by default (a polyline's vertices are its design, as in DXF and
  SVG: docs/formats.md); ``polylines=True`` (CLI ``--polylines``) reads them as
  ``kind="polyline"`` (vertices, split at corners like every point list);
- ``PolyCurve`` (joined curves; Rhino 2 saved every curve as one): one segment -> read as
  that ``NurbsCurve``; several -> one ``kind="bspline"`` record per run of segments
  (:func:`_polycurve`: clamped non-rational ``NurbsCurve`` segments of degree >= 2 and one
  degree, meeting exactly), the other segments kept, the ends of a run next to them held;
  written back into the segments in place. Nested PolyCurves are unsupported;
- rational curves, unclamped non-periodic knots: unsupported (``on_unsupported``).

A curve whose control points all have the same z is 2-D (``source["z"]`` keeps that z).
``source`` keys: ``id`` (the object's GUID as a string), ``object`` (index in the object
table), ``layer`` (layer name), ``geometry`` (class name), ``polylines`` (the reading's
choice), ``z``, ``nurbs_layout``
(``"clamped"``/``"periodic"``), ``polycurve`` and ``segments`` (a PolyCurve's run: its segment
indices), plus the point-list keys for polylines.

Write
-----
With ``template=`` the model is read again, each record's object is found by id and its
geometry is edited in place (control points and knots, or vertices: same number, same
degree) -- attributes, layers, materials, every other object untouched -- and the model is
written (same archive version) to a temporary file next to the destination and moved into
place. A curve whose control-point count or degree changed replaces the object's geometry
(same attributes and id). Without a template: a new model (version 7) with the curves.

Guard
-----
openNURBS never returns from ``File3dm.Read`` on some corrupted files (a busy loop in
rhino3dm 8.x) and may crash the interpreter on others. Every file is therefore first read once
in a separate Python process; if that process does not finish within
``CURVEFAIR_3DM_TIMEOUT`` seconds (environment variable; default 20 s plus 1 s per MB of
file; ``0`` turns the guard off) or dies, a :class:`~curvefair.FileFormatError` is raised and
the caller's process is never exposed to the file. Cost: one extra process start and read
(about 0.1 s for a small model).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import warnings
from collections.abc import Sequence
from typing import Any

import numpy as np

from .._typing import FloatArray
from ..curves.bspline import BSplineCurve
from ..errors import CurvefairError, FileFormatError, InputError
from ._common import (
    CurveRecord,
    DrawnShapesOnly,
    Unsupported,
    atomic_path,
    bspline_of,
    check_points,
    data_points,
    drop_duplicates,
    is_clamped,
    joined_points,
    lazy_import,
    piece_values,
    planar,
    point_records,
    points_curve,
    warn_drawn,
)

__all__ = ["read", "write"]

FORMAT = "3dm"


def _rhino(what: str) -> Any:
    return lazy_import("rhino3dm", "rhino3dm", "rhino", what)


def _load(path: str | os.PathLike[str], what: str) -> Any:
    rh = _rhino(what)
    p = os.fspath(path)
    try:
        size = os.path.getsize(p)
    except OSError as exc:
        raise FileFormatError(f"cannot read the file: {exc.strerror or exc}", path) from None
    if size == 0:
        raise FileFormatError("empty 3dm file", path)
    _probe(p, size, path)
    model = rh.File3dm.Read(p)
    if model is None:
        raise FileFormatError("not a readable 3dm file (openNURBS could not read it)", path)
    return model


_PROBE = ("import sys, rhino3dm\n"
          "sys.exit(0 if rhino3dm.File3dm.Read(sys.argv[1]) is not None else 3)\n")


def probe_timeout(size: int) -> float:
    """Seconds allowed for the guard read of a ``size``-byte file (0: no guard)."""
    env = os.environ.get("CURVEFAIR_3DM_TIMEOUT", "").strip()
    if env:
        try:
            value = float(env)
        except ValueError:
            raise InputError(f"CURVEFAIR_3DM_TIMEOUT must be a number of seconds, got {env!r}") \
                from None
        if not value >= 0:
            raise InputError(f"CURVEFAIR_3DM_TIMEOUT must be >= 0, got {env!r}")
        return value
    return 20.0 + size / 1e6


def _probe(p: str, size: int, path: object) -> None:
    """Read the file once in a child process first (see the module docstring: Guard)."""
    timeout = probe_timeout(size)
    if timeout == 0:
        return
    try:
        proc = subprocess.run([sys.executable, "-c", _PROBE, p], timeout=timeout,
                              capture_output=True, stdin=subprocess.DEVNULL)
    except subprocess.TimeoutExpired:
        raise FileFormatError(f"openNURBS (rhino3dm) did not finish reading the file within "
                              f"{timeout:g} s: corrupted 3dm file? (set CURVEFAIR_3DM_TIMEOUT "
                              f"to allow longer)", path) from None
    if proc.returncode == 3:
        raise FileFormatError("not a readable 3dm file (openNURBS could not read it)", path)
    if proc.returncode != 0:
        err = proc.stderr.decode(errors="replace").strip().splitlines()
        why = f": {err[-1]}" if err else ""
        raise FileFormatError(f"openNURBS (rhino3dm) failed reading the file in a guard "
                              f"process (exit code {proc.returncode}){why}", path)


def _nurbs(g: Any) -> tuple[FloatArray, FloatArray, FloatArray, int]:
    pts = g.Points
    n = len(pts)
    xyzw = np.array([(pts[i].X, pts[i].Y, pts[i].Z, pts[i].W) for i in range(n)], dtype=float)
    knots = np.array(list(g.Knots), dtype=float)
    full = np.r_[g.Knots.SuperfluousKnot(True), knots, g.Knots.SuperfluousKnot(False)]
    return xyzw[:, :3], xyzw[:, 3], full, int(g.Degree)


def _is_curve(obj: Any, rh: Any) -> bool:
    """Whether ``obj`` holds a curve curvefair reads (or would report as unsupported)."""
    return isinstance(obj.Geometry, (rh.PolylineCurve, rh.NurbsCurve, rh.PolyCurve))


def _records_of(obj: Any, i: int, base: dict[str, Any], path: object, rh: Any,
                corner_angle: float | None, index: int) -> list[CurveRecord]:
    g = obj.Geometry
    if isinstance(g, rh.PolylineCurve):
        xyz = np.array([tuple(_p3(g.Point(k))) for k in range(g.PointCount)], dtype=float)
        return _polyline(xyz, base, path, corner_angle, index)
    if isinstance(g, rh.PolyCurve):
        return _polycurve(g, base, path, rh, corner_angle, index)
    if not isinstance(g, rh.NurbsCurve):
        return []
    return _nurbs_records(g, base, path, corner_angle, index)


def _nurbs_records(g: Any, base: dict[str, Any], path: object, corner_angle: float | None,
                   index: int) -> list[CurveRecord]:
    if g.IsRational:
        xyz, w, _, _ = _nurbs(g)
        if not np.all(w == 1.0):
            raise Unsupported("rational NurbsCurve (weights other than 1)")
    xyz, _, full, p = _nurbs(g)
    if not np.isfinite(xyz).all() or not np.isfinite(full).all():
        raise FileFormatError(f"object {base['id']}: non-finite control point or knot", path)
    if p == 1:
        return _polyline(xyz, dict(base, nurbs_layout="degree1"), path, corner_angle, index)
    if p < 1:
        raise Unsupported(f"degree-{p} NurbsCurve")
    pts, z = planar(xyz)
    N = pts.shape[0]
    try:
        if is_clamped(full, p):
            curve = BSplineCurve(pts, full, p, closed=False)
            layout = "clamped"
        elif g.IsPeriodic and N > 2 * p - 1 and np.array_equal(xyz[N - p:], xyz[:p]):
            if N - p < p + 1:
                raise Unsupported(f"periodic degree-{p} NurbsCurve with {N - p} distinct "
                                  f"control points (curvefair's closed B-spline needs at "
                                  f"least degree + 1 = {p + 1})")
            curve = BSplineCurve(pts[: N - p], full, p, closed=True)
            layout = "periodic"
        else:
            raise Unsupported("knot vector neither clamped nor periodic")
    except CurvefairError as exc:
        if isinstance(exc, FileFormatError):
            raise
        # a curve curvefair's B-spline does not take (e.g. a periodic degree-5 curve with 5
        # distinct control points, which Rhino draws): the object is unsupported, not the
        # file broken -- skipped and written back untouched
        raise Unsupported(f"NurbsCurve: {exc}") from None
    src = dict(base, z=z, nurbs_layout=layout, index=index)
    return [CurveRecord(curve, base["name"], "bspline", src)]


def _segment(s: Any, rh: Any) -> tuple[FloatArray, FloatArray, int] | None:
    """Control points (x, y, z), full knots and degree of a PolyCurve segment curvefair fairs:
    a clamped non-rational ``NurbsCurve`` of degree >= 2 with finite numbers and some length;
    None for every other segment (lines, arcs, rational or unclamped curves), which is kept."""
    if not isinstance(s, rh.NurbsCurve) or int(s.Degree) < 2:
        return None
    xyz, w, full, p = _nurbs(s)
    if not (np.all(w == 1.0) and np.isfinite(xyz).all() and np.isfinite(full).all()
            and is_clamped(full, p) and full[-1] > full[0]
            and np.any(xyz[1:] != xyz[:-1])):
        return None
    return xyz, full, p


def _join_held(left: Any, right: Any, size: float) -> int:
    """How many control points each side of a join between a faired run and a kept segment
    (or another run) holds: 2 (the point and its neighbour: the tangent, so a G1 join stays
    G1 and a corner keeps its angle), 3 where the two sides' curvature vectors agree (a G2
    join: the curvature at an end depends on the first three control points)."""
    ka = np.array(_p3(left.CurvatureAt(left.Domain.T1)))
    kb = np.array(_p3(right.CurvatureAt(right.Domain.T0)))
    ta = np.array(_p3(left.TangentAtEnd))
    tb = np.array(_p3(right.TangentAtStart))
    g1 = float(np.dot(ta, tb)) > np.cos(np.radians(0.01))
    g2 = g1 and float(np.linalg.norm(ka - kb)) <= 1e-6 * (max(np.linalg.norm(ka),
                                                              np.linalg.norm(kb)) + 1.0 / size)
    return 3 if g2 else 2


def _polycurve(g: Any, base: dict[str, Any], path: object, rh: Any,
               corner_angle: float | None, index: int) -> list[CurveRecord]:
    """The records of a ``PolyCurve``: one per run of consecutive segments curvefair fairs
    (:func:`_segment`) that have one degree and meet exactly (the end control point of one is
    the start of the next, float for float).

    A run is one clamped B-spline: its segments' control points in order, the shared ones
    once, and each segment's knots mapped linearly onto an interval as long as its control
    polygon, with a knot of multiplicity ``degree`` between segments (a C0 join, which the
    fairing keeps G1 where it was; :mod:`curvefair.fairing.joins`). A linear map of a
    segment's knots does not change its shape, and only control points are written back,
    into each segment with its own knots. Where a run meets a kept segment or another run,
    its end point and one or two neighbours are held (:func:`_join_held`); a closed
    PolyCurve that is one run ending on its start has its seam planned like an open chain's.
    """
    n_seg = int(g.SegmentCount)
    segs = [g.SegmentCurve(i) for i in range(n_seg)]
    if any(isinstance(s, rh.PolyCurve) for s in segs):
        raise Unsupported("nested PolyCurve")
    if n_seg == 1 and isinstance(segs[0], rh.NurbsCurve):
        # one segment (how Rhino 2 saved every curve): read as the NurbsCurve it holds,
        # periodic ones included
        return [CurveRecord(r.curve, r.name, r.kind, dict(r.source, polycurve=True,
                                                          segments=(0,)), r.points, r.corners)
                for r in _nurbs_records(segs[0], base, path, corner_angle, index)]
    found = [_segment(s, rh) for s in segs]
    info = {i: f for i, f in enumerate(found) if f is not None}
    runs: list[list[int]] = []
    for i, inf in info.items():
        prev = info.get(i - 1)  # when there, it ends the last run
        if prev is not None and prev[2] == inf[2] and np.array_equal(prev[0][-1], inf[0][0]):
            runs[-1].append(i)
        else:
            runs.append([i])
    if not runs:
        raise Unsupported("PolyCurve: no segment is a non-rational NurbsCurve of degree >= 2")
    closed = bool(g.IsClosed)
    box = g.GetBoundingBox()
    size = float(np.linalg.norm(np.subtract(_p3(box.Max), _p3(box.Min)))) or 1.0
    out = []
    for run in runs:
        p = info[run[0]][2]
        pts = [info[run[0]][0][:1]]
        knots = [np.zeros(p + 1)]
        off = 0.0
        for j, i in enumerate(run):
            xyz, full, _ = info[i]
            length = float(np.linalg.norm(np.diff(xyz, axis=0), axis=1).sum())
            a, b = full[p], full[-p - 1]
            if j:
                knots.append(np.full(p, off))
            knots.append(off + (full[p + 1: -p - 1] - a) / (b - a) * length)
            pts.append(xyz[1:])
            off += length
        knots.append(np.full(p + 1, off))
        xyz = np.vstack(pts)
        held: list[int] = []
        # a closed PolyCurve that is one run ending exactly on its start: the fairing plans
        # its seam; else the closing join is held like any other
        whole = closed and len(runs) == 1 and run[0] == 0 and run[-1] == n_seg - 1 \
            and np.array_equal(xyz[0], xyz[-1])
        if not whole:
            if run[0] > 0 or closed:
                k = _join_held(segs[run[0] - 1], segs[run[0]], size)
                held += list(range(min(k, xyz.shape[0])))
            if run[-1] < n_seg - 1 or closed:
                k = _join_held(segs[run[-1]], segs[(run[-1] + 1) % n_seg], size)
                held += list(range(max(xyz.shape[0] - k, 0), xyz.shape[0]))
        pts2, z = planar(xyz)
        try:
            curve = BSplineCurve(pts2, np.concatenate(knots), p, closed=False)
        except CurvefairError as exc:
            raise Unsupported(f"PolyCurve segments {run[0]}-{run[-1]}: {exc}") from None
        name = base["name"] if len(runs) == 1 else f"{base['name']}[{run[0]}:{run[-1] + 1}]"
        src = dict(base, z=z, nurbs_layout="clamped", polycurve=True, segments=tuple(run),
                   index=index)
        out.append(CurveRecord(curve, name, "bspline", src, corners=tuple(sorted(set(held)))))
        index += 1
    return out


def _p3(p: Any) -> tuple[float, float, float]:
    return (float(p.X), float(p.Y), float(p.Z))


def _polyline(xyz: FloatArray, base: dict[str, Any], path: object,
              corner_angle: float | None, index: int) -> list[CurveRecord]:
    if xyz.shape[0] < 2:
        raise FileFormatError(f"object {base['id']}: fewer than 2 vertices", path)
    what = f"object {base['id']} vertex"
    xyz, where = drop_duplicates(xyz, path, None, what=what)
    if xyz.shape[0] < 2:
        raise FileFormatError(f"object {base['id']}: fewer than 2 distinct vertices", path)
    check_points(xyz, path, None, what=what)
    pts, z = planar(xyz)
    n = pts.shape[0]
    closed = n >= 4 and bool(np.array_equal(pts[0], pts[-1]))
    distinct = pts[:-1] if closed else pts
    row_map = (np.r_[np.arange(n - 1), 0] if closed else np.arange(n))[where]
    src = dict(base, z=z, row_map=tuple(int(k) for k in row_map))
    return point_records(distinct, closed=closed, corner_angle=corner_angle, kind="polyline",
                         name=base["name"], source=src, first_index=index)


def _drawn(g: Any, rh: Any) -> bool:
    """Whether geometry ``g`` is a polyline: a ``PolylineCurve``, a degree-1 ``NurbsCurve``
    or a ``PolyCurve`` of one such segment -- a drawn shape, read only with
    ``polylines=True``."""
    if isinstance(g, rh.PolyCurve) and int(g.SegmentCount) == 1:
        g = g.SegmentCurve(0)
    return isinstance(g, rh.PolylineCurve) or (isinstance(g, rh.NurbsCurve)
                                                and int(g.Degree) == 1)


def read(path: str | os.PathLike[str], *, corner_angle: float | None = 60.0,
         on_unsupported: str = "raise", polylines: bool = False,
         **_: Any) -> list[CurveRecord]:
    """Read the curves of a Rhino model; see the module docstring.

    ``polylines=False`` leaves polylines as drawn (no records); a model holding nothing
    else raises :class:`~curvefair.io.DrawnShapesOnly` (a
    :class:`~curvefair.FileFormatError`) saying how many there are and how to read them."""
    rh = _rhino("reading 3dm files")
    model = _load(path, "reading 3dm files")
    layers = [model.Layers[k].Name for k in range(len(model.Layers))]
    # what the model's owner protected (Rhino does not let it be selected or edited): not
    # read, so it is written back as it was
    layer_state = [", ".join(k for k, on in (("locked", model.Layers[j].Locked),
                                             ("hidden", not model.Layers[j].Visible)) if on)
                   for j in range(len(model.Layers))]
    records: list[CurveRecord] = []
    drawn = 0
    for i in range(len(model.Objects)):
        obj = model.Objects[i]
        attr = obj.Attributes
        if attr.Mode == rh.ObjectMode.InstanceDefinitionObject:
            # the geometry of a block definition, drawn by its instances through their
            # transforms (a scaled instance would carry a fairing beyond --tol into the model;
            # every instance would change): not read, like DXF block definitions
            continue
        if not polylines and _drawn(obj.Geometry, rh):
            drawn += 1
            continue
        ident = str(attr.Id)
        li = int(attr.LayerIndex)
        layer = layers[li] if 0 <= li < len(layers) else None
        why = ("locked" if attr.Mode == rh.ObjectMode.Locked
               else "hidden" if attr.Mode == rh.ObjectMode.Hidden else "")
        if not why and 0 <= li < len(layers) and layer_state[li]:
            why = f"on a {layer_state[li]} layer ({layer!r})"
        if why and _is_curve(obj, rh):
            warnings.warn(f"{os.fspath(path)}: skipped object {ident}: it is {why}; left as "
                          "it is (unlock or show it to fair it)", UserWarning, stacklevel=3)
            continue
        name = attr.Name or f"{type(obj.Geometry).__name__}:{ident}"
        base = {"format": FORMAT, "path": os.path.abspath(path), "id": ident, "object": i,
                "layer": layer, "geometry": type(obj.Geometry).__name__,
                "polylines": bool(polylines), "name": name}
        try:
            new = _records_of(obj, i, base, path, rh, corner_angle, len(records))
        except Unsupported as exc:
            msg = f"object {ident} ({base['geometry']}, {name!r}): unsupported {exc}"
            if on_unsupported == "raise":
                raise FileFormatError(msg + " (read_curves(..., on_unsupported='skip') skips "
                                      "it)", path) from None
            warnings.warn(f"{os.fspath(path)}: skipped {msg}", UserWarning, stacklevel=3)
            continue
        for r in new:
            src = dict(r.source)
            src.pop("name", None)
            src["index"] = len(records)
            records.append(CurveRecord(r.curve, r.name, r.kind, src, r.points, r.corners))
    if not records and drawn:
        raise DrawnShapesOnly(drawn, path, FORMAT)
    warn_drawn(path, drawn, FORMAT)
    return records


# ------------------------------------------------------------------------------------------
# write
# ------------------------------------------------------------------------------------------
def _xyz(pts: FloatArray, z: float | None) -> FloatArray:
    pts = np.asarray(pts, dtype=float)
    if pts.shape[1] == 2:
        return np.c_[pts, np.full(pts.shape[0], 0.0 if z is None else z)]
    return pts


def _nurbs_of(rh: Any, curve: BSplineCurve, z: float | None) -> Any:
    p = curve.degree
    cps = _xyz(curve.extended_control_points, z)
    g = rh.NurbsCurve(3, False, p + 1, cps.shape[0])
    for k, (x, y, zz) in enumerate(cps):
        g.Points[k] = rh.Point4d(float(x), float(y), float(zz), 1.0)
    for k, v in enumerate(curve.knots[1:-1]):
        g.Knots[k] = float(v)
    return g


def _edit_nurbs(rh: Any, model: Any, obj: Any, rec: CurveRecord) -> None:
    curve = bspline_of(rec.curve, "write_curves (3dm)")
    g = obj.Geometry
    layout = rec.source.get("nurbs_layout", "clamped")
    if curve.closed != (layout == "periodic"):
        raise InputError(f"write_curves: object {rec.source['id']} was "
                         f"{'closed' if layout == 'periodic' else 'open'}; the curve is not")
    cps = _xyz(curve.extended_control_points, rec.source.get("z"))
    knots = curve.knots[1:-1]
    if int(g.Degree) == curve.degree and len(g.Points) == cps.shape[0]:
        for k, (x, y, zz) in enumerate(cps):
            g.Points[k] = rh.Point4d(float(x), float(y), float(zz), 1.0)
        for k, v in enumerate(knots):
            g.Knots[k] = float(v)
        return
    _replace_geometry(model, obj, _nurbs_of(rh, curve, rec.source.get("z")))


def _edit_polycurve(rh: Any, obj: Any, recs: list[CurveRecord]) -> None:
    """Write each run's control points into its PolyCurve segments (in place: the segments'
    knots, the PolyCurve's parametrisation and every other segment stay as they were)."""
    g = obj.Geometry
    for rec in recs:
        curve = bspline_of(rec.curve, "write_curves (3dm)")
        cps = _xyz(curve.extended_control_points, rec.source.get("z"))
        k = 0
        segs = [g.SegmentCurve(int(i)) for i in rec.source["segments"]]
        if sum(len(s.Points) - 1 for s in segs) + 1 != cps.shape[0] or \
                any(int(s.Degree) != curve.degree for s in segs):
            raise InputError(f"write_curves: object {rec.source['id']} segments "
                             f"{list(rec.source['segments'])}: the faired curve has "
                             f"{cps.shape[0]} control points of degree {curve.degree}; a "
                             "PolyCurve's segments keep theirs (use a method that keeps the "
                             "B-spline's structure)")
        for s in segs:
            for q in range(len(s.Points)):
                x, y, zz = cps[k + q]
                s.Points[q] = rh.Point4d(float(x), float(y), float(zz), 1.0)
            k += len(s.Points) - 1


def _replace_geometry(model: Any, obj: Any, geometry: Any) -> None:
    attr = obj.Attributes
    ident = attr.Id
    model.Objects.Delete(ident)
    model.Objects.Add(geometry, attr)


def _edit_points(rh: Any, g: Any, recs: list[CurveRecord]) -> None:
    src = recs[0].source
    n = int(src["n_points"])
    dim = data_points(recs[0].curve, "write_curves (3dm)").shape[1]
    distinct = piece_values(n, dim, recs, "write_curves (3dm)")
    pts = _xyz(distinct[np.asarray(src["row_map"], dtype=int)], src.get("z"))
    if isinstance(g, rh.PolylineCurve):
        if g.PointCount != pts.shape[0]:
            raise InputError(f"write_curves: object {src['id']} has {g.PointCount} vertices, "
                             f"the records {pts.shape[0]}")
        for k, (x, y, z) in enumerate(pts):
            g.SetPoint(k, rh.Point3d(float(x), float(y), float(z)))
        return
    if len(g.Points) != pts.shape[0]:
        raise InputError(f"write_curves: object {src['id']} has {len(g.Points)} control points, "
                         f"the records {pts.shape[0]}")
    for k, (x, y, z) in enumerate(pts):
        g.Points[k] = rh.Point4d(float(x), float(y), float(z), 1.0)


def _add_new(rh: Any, model: Any, rec: CurveRecord) -> None:
    z = rec.source.get("z")
    attr = rh.ObjectAttributes()
    if rec.name:
        attr.Name = rec.name
    if rec.kind in ("points", "airfoil", "polyline"):
        pts = _xyz(data_points(rec.curve, "write_curves (3dm)"), z)
        geom = rh.PolylineCurve([rh.Point3d(*map(float, q)) for q in pts])
    else:
        geom = _nurbs_of(rh, bspline_of(rec.curve, "write_curves (3dm)"), z)
    model.Objects.Add(geom, attr)


def _geometry_key(g: Any) -> tuple[Any, ...]:
    """Control points (x, y, z, w) and knots, or polyline vertices, of a curve object."""
    if hasattr(g, "Knots") and hasattr(g, "Points"):
        pts = g.Points
        return (int(g.Degree), np.array([(pts[i].X, pts[i].Y, pts[i].Z, pts[i].W)
                                         for i in range(len(pts))]), np.array(list(g.Knots)))
    if hasattr(g, "PointCount"):
        return (np.array([_p3(g.Point(k)) for k in range(g.PointCount)]),)
    if hasattr(g, "SegmentCount"):
        segs = [g.SegmentCurve(i) for i in range(g.SegmentCount)]
        return tuple(_geometry_key(s) if hasattr(s, "Knots") else type(s).__name__
                     for s in segs)
    return (id(g),)


def _same_key(a: tuple[Any, ...], b: tuple[Any, ...]) -> bool:
    return len(a) == len(b) and all(
        np.array_equal(x, y) if isinstance(x, np.ndarray)
        else _same_key(x, y) if isinstance(x, tuple) and isinstance(y, tuple) else x == y
        for x, y in zip(a, b, strict=True))


def write(path: str | os.PathLike[str], records: Sequence[CurveRecord], *,
          template: str | None = None, **_: Any) -> None:
    """Write a Rhino model; see the module docstring."""
    rh = _rhino("writing 3dm files")
    if template is not None:
        model = _load(template, "writing 3dm files")
        version = int(rh.File3dm.ReadArchiveVersion(os.fspath(template)) or 0)
        version = version // 10 if version >= 50 else version
    else:
        model = rh.File3dm()
        version = 7
    ours = [r for r in records if template is not None and r.format == FORMAT
            and r.path is not None and os.path.abspath(r.path) == os.path.abspath(template)]
    mine = {id(r) for r in ours}  # (a set: a drawing's 10,000 records, not 10,000 squared)
    others = [r for r in records if id(r) not in mine]
    groups: dict[str, list[CurveRecord]] = {}
    for r in ours:
        groups.setdefault(r.source["id"], []).append(r)
    changed = False
    for ident, recs in groups.items():
        obj = None
        for k in range(len(model.Objects)):
            if str(model.Objects[k].Attributes.Id) == ident:
                obj = model.Objects[k]
                break
        if obj is None:
            # files of archive version 1 store no object ids: openNURBS makes new random ones
            # at every read, so the object is found by its index in the object table
            ko = recs[0].source.get("object")
            if isinstance(ko, int) and 0 <= ko < len(model.Objects) and \
                    type(model.Objects[ko].Geometry).__name__ == recs[0].source.get("geometry"):
                obj = model.Objects[ko]
        if obj is None:
            raise InputError(f"write_curves: the template has no object with id {ident}")
        before = _geometry_key(obj.Geometry)
        if recs[0].source.get("polycurve") and recs[0].kind == "bspline":
            _edit_polycurve(rh, obj, recs)
        elif recs[0].source.get("polycurve"):     # one degree-1 segment: its vertices
            _edit_points(rh, obj.Geometry.SegmentCurve(0), recs)
        elif recs[0].kind == "bspline":
            _edit_nurbs(rh, model, obj, recs[0])
        else:
            _edit_points(rh, obj.Geometry, recs)
        obj = next((model.Objects[k] for k in range(len(model.Objects))
                    if str(model.Objects[k].Attributes.Id) == str(obj.Attributes.Id)), obj)
        changed = changed or not _same_key(before, _geometry_key(obj.Geometry))
    if template is not None and not others and not changed:
        with atomic_path(path, suffix=".3dm") as tmp:   # nothing faired: the file as it was
            shutil.copyfile(os.fspath(template), tmp)
        return
    joined: dict[Any, list[CurveRecord]] = {}
    for i, r in enumerate(others):
        key = (r.path, r.format, r.source.get("id"), r.source.get("handle"),
               r.source.get("element"), r.source.get("subpath")) \
            if "indices" in r.source else ("single", i)
        joined.setdefault(key, []).append(r)
    for recs in joined.values():
        if "indices" in recs[0].source:
            pts = joined_points(recs, "write_curves (3dm)")
            closed = bool(recs[0].source.get("closed"))
            _add_new(rh, model, recs[0].with_curve(points_curve(pts, closed)))
        else:
            _add_new(rh, model, recs[0])
    with atomic_path(path, suffix=".3dm") as tmp:
        # openNURBS writes no version 1; version 2 turns LineCurves into NurbsCurves
        if not model.Write(os.fspath(tmp), max(min(version, 8), 3)):
            raise InputError(f"write_curves: openNURBS could not write {os.fspath(path)!r}")
