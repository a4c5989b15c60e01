"""DXF drawings through ezdxf (``pip install 'curvefair[dxf]'``).

Read
----
Every ``SPLINE``, ``LWPOLYLINE`` and 2-D / 3-D ``POLYLINE`` of the model space and the paper
space layouts (block definitions are not read: editing them would change every insert).

``SPLINE`` with control points -> ``kind="bspline"``, a :class:`~curvefair.BSplineCurve` with
the entity's degree, knots and control points:

- clamped knot vector: an open curve; with the DXF *closed* flag and the first control point
  repeated last (what libdxfrw and LibreCAD write for closed splines) a closed curve whose
  seam knot has multiplicity ``degree`` (the same curve exactly; ``spline_layout``
  ``"clamped_closed"``), written back in the file's clamped layout;
- periodic layout (closed flag, the first ``degree`` control points repeated at the end,
  ``n + 2 degree + 1`` knots -- what ezdxf's ``set_closed`` and most CAD programs write, or
  ``n + 1`` knots as in AutoCAD's documentation): a closed curve;
- weights other than 1 (rational), degree < 2 or any other knot layout: unsupported.

``SPLINE`` with fit points only -> ``kind="fit_points"``: the curve through the fit points
(periodic if the spline is closed). Polylines (``LWPOLYLINE``, 2-D / 3-D ``POLYLINE``) are
**drawn shapes, not read** by default: a polyline's vertices are its design, not samples of a
curve (of 491 polylines in the DXF and 3dm files of ezdxf's, dxf-parser's, openNURBS' and
rhino3dm's repositories 12 look like samples: docs/formats.md), so they are left exactly as
drawn. ``polylines=True`` (CLI ``--polylines``) reads them as point lists,
``kind="polyline"``, split at corners like every point list; polylines with arc segments
(bulges) are then unsupported. Spline-fit or curve-fit ``POLYLINE`` entities are
unsupported. Coordinates are the entity's own (OCS for 2-D polylines); a curve whose points
all have the same z is 2-D and keeps that z (``source["z"]``).

``source`` keys: ``handle``, ``dxftype``, ``layer``, ``layout``, ``polylines`` (the reading's
choice: the write-back's check reads the file again the same way), ``z`` (None for 3-D), and
``spline_layout`` (``"clamped"``, ``"clamped_closed"``, ``"periodic"``,
``"periodic_short"``) or the point-list keys.

Write
-----
With ``template=`` the source drawing is loaded, each record's entity is found by handle and
only its geometry is replaced (control points and knots, with the same layout; fit points;
vertex positions -- widths, bulges, flags, layer, colour, linetype, handle and every other
entity untouched), then saved to a temporary file next to the destination and moved into
place. A control-point spline that also had fit points loses them (they no longer describe
the faired curve). Records that do not come from the template, and every record when there is
no template, are added to the model space of the drawing (a new R2010 drawing without a
template): B-splines and Hermite curves as ``SPLINE`` (Hermite pieces as Bezier segments, the
same curve exactly), point kinds as ``LWPOLYLINE`` (2-D) or 3-D ``POLYLINE``, fit-point records
as fit-point ``SPLINE``. A template read as DXF R12 (``AC1009``, which is also what a header
without ``$ACADVER`` gives) that holds entities R12 cannot store (SPLINE, LWPOLYLINE, ...) is
written as DXF R2000 (``AC1015``) with a warning, so that none of them is dropped.
"""

from __future__ import annotations

import os
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
    piece_values,
    planar,
    point_records,
    points_curve,
    warn_drawn,
)

__all__ = ["read", "write"]

FORMAT = "dxf"


def _ezdxf(what: str) -> Any:
    from ._common import lazy_import

    return lazy_import("ezdxf", "ezdxf", "dxf", what)


def _ring(pts: FloatArray, closed_flag: bool) -> tuple[FloatArray, np.ndarray, bool]:
    """Distinct points, vertex -> distinct index map, closed.

    A closed polyline that repeats its first vertex last, or an open one that ends where it
    starts (4 vertices or more), is a closed loop.
    """
    n = pts.shape[0]
    if n >= 3 and np.array_equal(pts[0], pts[-1]) and (closed_flag or n >= 4):
        return pts[:-1], np.r_[np.arange(n - 1), 0], True
    return pts, np.arange(n), bool(closed_flag)


def _spline_record(e: Any, base: dict[str, Any], path: object, corner_angle: float | None,
                   index: int) -> list[CurveRecord]:
    p = int(e.dxf.degree)
    weights = np.asarray(e.weights, dtype=float)
    if weights.size and not np.all(weights == 1.0):
        raise Unsupported("rational spline (weights other than 1)")
    cps = np.asarray([tuple(v) for v in e.control_points], dtype=float).reshape(-1, 3)
    fits = np.asarray([tuple(v) for v in e.fit_points], dtype=float).reshape(-1, 3)
    closed_flag = bool(e.closed)
    if cps.shape[0] == 0:
        if fits.shape[0] < 2:
            raise FileFormatError(f"SPLINE {base['handle']} has neither control points nor 2 "
                                  "fit points", path)
        what = f"SPLINE {base['handle']} fit point"
        fits, where = drop_duplicates(fits, path, None, what=what)
        check_points(fits, path, None, what=what)
        pts, z = planar(fits)
        distinct, row_map, closed = _ring(pts, closed_flag)
        if closed and distinct.shape[0] < 3:
            raise Unsupported(f"closed SPLINE with {distinct.shape[0]} distinct fit points (a "
                              "segment drawn there and back, not a closed curve)")
        row_map = row_map[where]
        src = dict(base, z=z, row_map=tuple(int(i) for i in row_map),
                   has_end_tangents=bool(e.dxf.hasattr("start_tangent")))
        return point_records(distinct, closed=closed, corner_angle=None, kind="fit_points",
                             name=base["name"], source=src, first_index=index)
    if not np.isfinite(cps).all():
        raise FileFormatError(f"SPLINE {base['handle']} has a non-finite control point", path)
    if p < 2:
        raise Unsupported(f"degree-{p} spline")
    knots = np.asarray(e.knots, dtype=float)
    N = cps.shape[0]
    pts, z = planar(cps)
    try:
        if closed_flag and knots.shape[0] == N + p + 1 and is_clamped(knots, p) and \
                N - p - 1 >= 1 and np.array_equal(cps[0], cps[-1]):
            curve = BSplineCurve(pts[: N - 1], _closed_knots(knots, p), p, closed=True)
            layout = "clamped_closed"
        elif knots.shape[0] == N + p + 1 and is_clamped(knots, p):
            curve = BSplineCurve(pts, knots, p, closed=False)
            layout = "clamped"
        elif closed_flag and knots.shape[0] == N + p + 1 and N > 2 * p and \
                np.array_equal(cps[N - p:], cps[:p]):
            curve = BSplineCurve(pts[: N - p], knots, p, closed=True)
            layout = "periodic"
        elif closed_flag and knots.shape[0] == N + 1:
            curve = BSplineCurve(pts, knots, p, closed=True)
            layout = "periodic_short"
        else:
            raise Unsupported(f"knot layout ({knots.shape[0]} knots for {N} control points "
                               f"of degree {p}, neither clamped nor periodic)")
    except CurvefairError as exc:
        if isinstance(exc, FileFormatError):
            raise
        # a knot vector curvefair's B-spline does not take (e.g. an interior knot of
        # multiplicity degree + 1, a Bezier-style chain that ezdxf and CAD read): the entity
        # is unsupported, not the file broken -- skipped and written back untouched
        raise Unsupported(f"knot vector: {exc}") from None
    src = dict(base, z=z, spline_layout=layout, had_fit_points=bool(fits.shape[0]))
    return [CurveRecord(curve, base["name"], "bspline", src)]


def _closed_knots(knots: FloatArray, p: int) -> FloatArray:
    """The periodic knot vector of a clamped closed spline (closed flag, first control point
    repeated last): the clamped curve on ``[a, b]`` with interior knots ``I`` is exactly the
    periodic spline with the distinct control points ``d_0 .. d_{N-2}`` and the full knots
    ``[I[-1] - T, a (p times), I, b (p times), ([I, b (p times)])[:p] + T]``, ``T = b - a``:
    a seam knot of multiplicity ``p`` (C0, like the clamped ends), every span's knots ``t_{j-p+1} ..
    t_{j+p}`` the same as the clamped vector's on ``[a, b]`` (Piegl & Tiller, section 2.2)."""
    a, b = float(knots[p]), float(knots[-p - 1])
    interior = np.asarray(knots[p + 1: -p - 1], dtype=float)
    T = b - a
    head = np.r_[interior, np.full(p, b)][:p]     # t_{N+p+j} = t_{p+1+j} + T
    return np.r_[interior[-1] - T, np.full(p, a), interior, np.full(p, b), head + T]


def _polyline_record(e: Any, base: dict[str, Any], path: object,
                     corner_angle: float | None, index: int) -> list[CurveRecord]:
    kind = e.dxftype()
    if kind == "LWPOLYLINE":
        raw = np.asarray(e.get_points("xyb"), dtype=float).reshape(-1, 3)
        if np.any(raw[:, 2] != 0):
            raise Unsupported("polyline with arc segments (bulges)")
        pts = raw[:, :2]
        z: float | None = float(e.dxf.get("elevation", 0.0))
    else:
        if not (e.is_2d_polyline or e.is_3d_polyline):
            return []                     # polyface / mesh: not a curve
        if e.dxf.flags & 6:
            raise Unsupported("spline-fit or curve-fit POLYLINE")
        verts = list(e.vertices)
        if any(v.dxf.get("bulge", 0.0) for v in verts):
            raise Unsupported("polyline with arc segments (bulges)")
        xyz = np.asarray([tuple(v.dxf.location) for v in verts], dtype=float).reshape(-1, 3)
        pts, z = planar(xyz)
    if pts.shape[0] < 2:
        raise Unsupported(f"{kind} with fewer than 2 vertices")
    what = f"{kind} {base['handle']} vertex"
    pts, where = drop_duplicates(pts, path, None, what=what)
    if pts.shape[0] < 2:
        raise Unsupported(f"{kind} with fewer than 2 distinct vertices (a point, not a curve)")
    check_points(pts, path, None, what=what)
    closed_flag = bool(e.closed) if kind == "LWPOLYLINE" else bool(e.is_closed)
    distinct, row_map, closed = _ring(pts, closed_flag)
    if closed and distinct.shape[0] < 3:
        raise Unsupported(f"closed {kind} with {distinct.shape[0]} distinct vertices (a segment "
                          "drawn there and back, not a closed curve)")
    row_map = row_map[where]
    src = dict(base, z=z, row_map=tuple(int(i) for i in row_map))
    return point_records(distinct, closed=closed, corner_angle=corner_angle, kind="polyline",
                         name=base["name"], source=src, first_index=index)


def _load(path: str | os.PathLike[str], what: str) -> Any:
    ezdxf = _ezdxf(what)
    try:
        return ezdxf.readfile(os.fspath(path))
    except OSError as exc:
        if _truncated(path) == "the file is empty":
            raise FileFormatError("not a readable DXF file: the file is empty", path) from None
        raise FileFormatError(f"not a readable DXF file ({exc})", path) from None
    except Exception as exc:  # ezdxf raises its own DXFStructureError, ValueError, ...
        detail = f"{type(exc).__name__}: {exc}" if str(exc) else type(exc).__name__
        cut = _truncated(path)
        if cut:
            raise FileFormatError(f"not a readable DXF file: {cut} ({detail})", path) from None
        raise FileFormatError(f"not a readable DXF file ({detail})", path) from None


_BINARY_SENTINEL = b"AutoCAD Binary DXF\r\n\x1a\x00"


def _truncated(path: str | os.PathLike[str]) -> str | None:
    """Why the DXF file at ``path`` looks cut short, or None.

    Every DXF file ends with the group ``0 / EOF`` (ASCII: the lines ``0`` and ``EOF``;
    binary DXF: group code 0 then ``EOF`` and a NUL byte), AutoCAD DXF Reference, "DXF File
    Structure". ezdxf's parser meets the missing end as StopIteration, IndexError, a struct
    error or a missing ENDSEC, none of which tells the user that the file is incomplete.
    """
    try:
        with open(os.fspath(path), "rb") as fh:
            head = fh.read(len(_BINARY_SENTINEL))
            fh.seek(0, os.SEEK_END)
            size = fh.tell()
            fh.seek(max(0, size - 4096))
            tail = fh.read()
    except OSError:
        return None
    if size == 0:
        return "the file is empty"
    if head == _BINARY_SENTINEL:
        if tail.endswith(b"EOF\x00"):
            return None
        return (f"binary DXF file ends at byte {size} without the closing EOF group: it "
                "looks truncated")
    lines = [ln.strip() for ln in tail.splitlines() if ln.strip()]
    if len(lines) >= 2 and lines[-1].upper() == b"EOF" and lines[-2] == b"0":
        return None
    if any(ln.upper() == b"EOF" for ln in lines):
        return None  # data after EOF (ezdxf ignores it): not a truncation
    with open(os.fspath(path), "rb") as fh:
        nlines = sum(chunk.count(b"\n") for chunk in iter(lambda: fh.read(1 << 20), b""))
    if not tail.endswith(b"\n"):
        nlines += 1
    return (f"the file ends at line {nlines} without the closing '0 / EOF' group: it looks "
            "truncated")


def _drawn(e: Any, t: str) -> bool:
    """Whether entity ``e`` (of DXF type ``t``) is a polyline of straight segments and arcs: a
    drawn shape, read only with ``polylines=True``. A spline-fit or curve-fit ``POLYLINE``
    is a curve (reported as unsupported), a polyface or mesh no curve at all."""
    if t == "LWPOLYLINE":
        return True
    return t == "POLYLINE" and bool(e.is_2d_polyline or e.is_3d_polyline) \
        and not e.dxf.flags & 6


def read(path: str | os.PathLike[str], *, corner_angle: float | None = 60.0,
         on_unsupported: str = "raise", polylines: bool = False,
         **_: Any) -> list[CurveRecord]:
    """Read the curves of a DXF drawing; see the module docstring.

    ``polylines=False`` leaves polylines as drawn (no records); a drawing holding nothing
    else raises :class:`~curvefair.io.DrawnShapesOnly` (a
    :class:`~curvefair.FileFormatError`) saying how many there are and how to read them."""
    doc = _load(path, "reading DXF files")
    records: list[CurveRecord] = []
    drawn = 0
    for layout in doc.layouts:
        for e in layout:
            t = e.dxftype()
            if t not in ("SPLINE", "LWPOLYLINE", "POLYLINE"):
                continue
            if not polylines and _drawn(e, t):
                drawn += 1
                continue
            handle = e.dxf.handle
            layer = e.dxf.get("layer", "0")
            why = _protected(doc, layer)
            if why:
                # what the drawing's owner protected (CAD tools do not let it be selected or
                # edited) is not read, so it is written back as it was
                warnings.warn(f"{os.fspath(path)}: skipped {t} {handle}: its layer "
                              f"{layer!r} is {why}; left as it is (unlock or thaw it to fair "
                              "it)", UserWarning, stacklevel=3)
                continue
            base = {"format": FORMAT, "path": os.path.abspath(path), "handle": handle,
                    "dxftype": t, "layer": layer, "layout": layout.name,
                    "polylines": bool(polylines), "name": f"{layer}:{t}:{handle}"}
            try:
                if t == "SPLINE":
                    new = _spline_record(e, base, path, corner_angle, len(records))
                else:
                    new = _polyline_record(e, base, path, corner_angle, len(records))
            except Unsupported as exc:
                msg = f"{t} {handle} on layer {layer!r}: unsupported {exc}"
                if on_unsupported == "raise":
                    raise FileFormatError(msg + " (read_curves(..., on_unsupported='skip') "
                                          "skips it)", path) from None
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


def _protected(doc: Any, layer: str) -> str:
    """``"locked"``, ``"frozen"`` (both: ``"locked and frozen"``) or ``""`` for the layer
    named ``layer`` (a layer missing from the table is not protected)."""
    from ezdxf.lldxf.const import DXFTableEntryError

    try:
        lay = doc.layers.get(layer)
    except DXFTableEntryError:
        return ""
    kinds = [k for k, on in (("locked", lay.is_locked()), ("frozen", lay.is_frozen())) if on]
    return " and ".join(kinds)


# ------------------------------------------------------------------------------------------
# write
# ------------------------------------------------------------------------------------------
def _xyz(pts: FloatArray, z: float | None) -> list[tuple[float, float, float]]:
    pts = np.asarray(pts, dtype=float)
    if pts.shape[1] == 2:
        zz = 0.0 if z is None else z
        return [(float(x), float(y), zz) for x, y in pts]
    return [tuple(float(v) for v in row) for row in pts]  # type: ignore[misc]


def _set_spline(e: Any, rec: CurveRecord) -> None:
    curve = bspline_of(rec.curve, "write_curves (DXF)")
    layout = rec.source.get("spline_layout", "clamped")
    z = rec.source.get("z")
    if curve.closed != (layout != "clamped"):
        raise InputError(f"write_curves: SPLINE {rec.source['handle']} was "
                         f"{'closed' if layout != 'clamped' else 'open'}; the curve is not")
    p = curve.degree
    if layout == "clamped_closed":
        t, n = curve.knots, curve.n_ctrl
        if not (np.all(t[1:p + 1] == t[p]) and np.all(t[n + 1:n + p + 1] == t[p + n])):
            raise InputError(f"write_curves: SPLINE {rec.source['handle']} is a clamped closed "
                             "spline; the curve no longer has a seam knot of multiplicity "
                             f"{p} and cannot be written in that layout")
        cps = np.r_[curve.control_points, curve.control_points[:1]]
        knots = np.r_[np.full(p + 1, t[p]), t[p + 1:n + 1], np.full(p + 1, t[p + n])]
    elif layout == "periodic_short":
        cps = curve.control_points
        knots = curve.knots[p: p + curve.n_ctrl + 1]
    else:
        cps = curve.extended_control_points
        knots = curve.knots
    e.dxf.degree = p
    e.control_points = _xyz(cps, z)
    e.knots = [float(k) for k in knots]
    e.weights = []
    if len(e.fit_points):
        e.fit_points = []


def _group(records: Sequence[CurveRecord]) -> dict[str, list[CurveRecord]]:
    out: dict[str, list[CurveRecord]] = {}
    for r in records:
        out.setdefault(r.source["handle"], []).append(r)
    return out


def _set_points(e: Any, recs: list[CurveRecord]) -> None:
    src = recs[0].source
    n = int(src["n_points"])
    dim = data_points(recs[0].curve, "write_curves (DXF)").shape[1]
    distinct = piece_values(n, dim, recs, "write_curves (DXF)")
    pts = distinct[np.asarray(src["row_map"], dtype=int)]
    t = e.dxftype()
    if t == "SPLINE":
        e.fit_points = _xyz(pts, src.get("z"))
        return
    if t == "LWPOLYLINE":
        old = list(e.get_points("xyseb"))
        if len(old) != pts.shape[0]:
            raise InputError(f"write_curves: LWPOLYLINE {src['handle']} has {len(old)} "
                             f"vertices in the template, the records {pts.shape[0]}")
        rows = np.array(old, dtype=float).reshape(-1, 5)
        rows[:, :2] = pts[:, :2]
        lw = getattr(e, "lwpoints", None)
        if lw is not None and hasattr(lw, "set"):
            lw.set(rows)           # one array assignment (set_points appends one by one)
        else:  # pragma: no cover - older ezdxf
            e.set_points([tuple(map(float, r)) for r in rows], format="xyseb")
        return
    verts = list(e.vertices)
    if len(verts) != pts.shape[0]:
        raise InputError(f"write_curves: POLYLINE {src['handle']} has {len(verts)} vertices "
                         f"in the template, the records {pts.shape[0]}")
    for v, xyz in zip(verts, _xyz(pts, src.get("z")), strict=True):
        v.dxf.location = xyz


def _add_new(msp: Any, rec: CurveRecord, z: float | None) -> None:
    if rec.kind in ("points", "airfoil", "polyline"):
        pts = data_points(rec.curve, "write_curves (DXF)")
        closed = bool(rec.curve.closed)
        if closed:
            pts = pts[:-1]
        if pts.shape[1] == 2:
            msp.add_lwpolyline([tuple(map(float, q)) for q in pts], format="xy",
                               close=closed, dxfattribs={"elevation": z or 0.0})
        else:
            msp.add_polyline3d(_xyz(pts, None), close=closed)
        return
    if rec.kind == "fit_points":
        pts = data_points(rec.curve, "write_curves (DXF)")
        s = msp.add_spline(fit_points=_xyz(pts[:-1] if rec.curve.closed else pts, z))
        s.closed = bool(rec.curve.closed)
        return
    curve = bspline_of(rec.curve, "write_curves (DXF)")
    p = curve.degree
    s = msp.add_spline(degree=p)
    s.control_points = _xyz(curve.extended_control_points, z)
    s.knots = [float(k) for k in curve.knots]
    if curve.closed:
        s.dxf.flags = s.dxf.flags | s.CLOSED | s.PERIODIC


def write(path: str | os.PathLike[str], records: Sequence[CurveRecord], *,
          template: str | None = None, **_: Any) -> None:
    """Write a DXF drawing; see the module docstring."""
    ezdxf = _ezdxf("writing DXF files")
    if template is not None:
        doc = _load(template, "writing DXF files")
    else:
        doc = ezdxf.new("R2010")
    msp = doc.modelspace()
    ours = [r for r in records if template is not None and r.format == FORMAT
            and r.path is not None and os.path.abspath(r.path) == os.path.abspath(template)]
    mine = {id(r) for r in ours}  # (a set: a drawing's 10,000 records, not 10,000 squared)
    others = [r for r in records if id(r) not in mine]
    before: dict[str, tuple[FloatArray, FloatArray | None]] = {}
    for handle, recs in _group(ours).items():
        e = doc.entitydb.get(handle)
        if e is None or e.dxftype() != recs[0].source["dxftype"]:
            raise InputError(f"write_curves: the template has no {recs[0].source['dxftype']} "
                             f"with handle {handle}")
        old = _outline(e)
        if recs[0].kind == "bspline":
            _set_spline(e, recs[0])
        else:
            _set_points(e, recs)
        new_geom = _outline(e)
        if old is not None and new_geom is not None and not (
                np.array_equal(old[0], new_geom[0]) and _eq(old[1], new_geom[1])):
            before[handle] = old
    if before:
        _follow_hatches(doc, before, template)
    if others and template is not None and doc.dxfversion < "AC1015":
        # new curves are SPLINE / LWPOLYLINE entities, which R12 cannot hold (ezdxf refuses
        # to add them): written as R2000, like a template that holds such entities
        doc.dxfversion = "AC1015"
        warnings.warn(f"{os.fspath(template)}: read as DXF R12 ({doc.loaded_dxfversion}), which "
                      "cannot hold the new curves (SPLINE / LWPOLYLINE entities); the output is "
                      "written as DXF R2000 (AC1015)", UserWarning, stacklevel=3)
    # records from another DXF file that were split into pieces: join them again
    for _key, recs in _group_foreign(others).items():
        if len(recs) > 1 or "indices" in recs[0].source:
            pts = joined_points(recs, "write_curves (DXF)")
            closed = bool(recs[0].source.get("closed"))
            whole = recs[0].with_curve(points_curve(pts, closed) if pts.shape[0] > 1 else
                                       recs[0].curve)
            _add_new(msp, whole, recs[0].source.get("z"))
        else:
            _add_new(msp, recs[0], recs[0].source.get("z"))
    if template is not None:
        _upgrade_r12(doc, template)
    # a binary DXF template is written back binary (ezdxf saves ASCII unless told)
    fmt = "bin" if template is not None and _is_binary(template) else "asc"
    with atomic_path(path, suffix=".dxf") as tmp:
        doc.saveas(os.fspath(tmp), fmt=fmt)


def _is_binary(path: str | os.PathLike[str]) -> bool:
    """Whether the DXF file at ``path`` is a binary DXF (starts with its sentinel)."""
    try:
        with open(os.fspath(path), "rb") as fh:
            return fh.read(len(_BINARY_SENTINEL)) == _BINARY_SENTINEL
    except OSError:
        return False


def _eq(a: FloatArray | None, b: FloatArray | None) -> bool:
    return (a is None and b is None) or (a is not None and b is not None
                                         and np.array_equal(a, b))


def _outline(e: Any) -> tuple[FloatArray, FloatArray | None] | None:
    """(2-D points, knots) an associative hatch boundary copies from a source entity: the
    control points (or fit points) and knots of a SPLINE, the vertices of a polyline."""
    t = e.dxftype()
    if t == "SPLINE":
        cps = np.asarray([tuple(v) for v in e.control_points], dtype=float).reshape(-1, 3)
        if cps.shape[0] == 0:
            cps = np.asarray([tuple(v) for v in e.fit_points], dtype=float).reshape(-1, 3)
        return cps[:, :2], np.asarray(e.knots, dtype=float)
    if t == "LWPOLYLINE":
        return np.asarray(e.get_points("xy"), dtype=float).reshape(-1, 2), None
    if t == "POLYLINE":
        return np.asarray([tuple(v.dxf.location)[:2] for v in e.vertices],
                          dtype=float).reshape(-1, 2), None
    return None


def _follow_hatches(doc: Any, before: dict[str, tuple[FloatArray, FloatArray | None]],
                    template: object) -> None:
    """Associative HATCHes whose boundary comes from a faired entity (DXF group 330 source
    boundary objects): the boundary is moved with it -- a polyline path copied from its one
    source polyline, an edge path's line ends at the old vertices moved to the new ones and a
    spline edge equal to the old spline replaced by the new one. A boundary that cannot be
    matched that way keeps its old geometry and loses the association (flag 0, no source
    objects), with a warning: an associative hatch that no longer follows its boundary would
    be re-computed by the CAD program at an unknown moment."""
    for h in doc.entitydb.values():
        if h.dxftype() != "HATCH" or not h.dxf.get("associative", 0) or h.is_alive is False:
            continue
        hit = False
        ok = True
        for path in h.paths:
            src = [s for s in path.source_boundary_objects if s in before]
            if not src:
                continue
            hit = True
            ok = _move_path(doc, path, src, before) and ok
        if hit and not ok:
            h.dxf.associative = 0
            for path in h.paths:
                path.source_boundary_objects = []
            for e in doc.entitydb.values():
                if hasattr(e, "reactors") and e.reactors is not None and \
                        h.dxf.handle in e.reactors.get():
                    e.discard_reactor_handle(h.dxf.handle)
            warnings.warn(f"{template}: HATCH {h.dxf.handle} was associative to a "
                          "faired curve whose new shape its boundary path cannot take; the "
                          "association is removed and the hatch keeps its old boundary",
                          UserWarning, stacklevel=4)


def _move_path(doc: Any, path: Any, src: list[str],
               before: dict[str, tuple[FloatArray, FloatArray | None]]) -> bool:
    kind = type(path).__name__
    if kind == "PolylinePath":
        if len(path.source_boundary_objects) != 1:
            return False
        e = doc.entitydb.get(src[0])
        if e is None or e.dxftype() != "LWPOLYLINE":
            return False
        old = np.asarray([v[:2] for v in path.vertices], dtype=float)
        if old.shape != before[src[0]][0].shape or not np.array_equal(old, before[src[0]][0]):
            return False
        bulges = [v[2] if len(v) > 2 else 0.0 for v in path.vertices]
        new = _outline(e)[0]  # type: ignore[index]
        path.set_vertices([(float(x), float(y), b) for (x, y), b in
                           zip(new, bulges, strict=True)], is_closed=path.is_closed)
        return True
    if kind != "EdgePath":
        return False
    moved: dict[tuple[float, float], tuple[float, float]] = {}
    splines = []
    for hd in src:
        e = doc.entitydb.get(hd)
        new = _outline(e) if e is not None else None
        if new is None:
            return False
        if e.dxftype() == "SPLINE":
            splines.append((before[hd], e))
        else:
            for a, b in zip(before[hd][0], new[0], strict=True):
                moved[(float(a[0]), float(a[1]))] = (float(b[0]), float(b[1]))
    done_splines = 0
    for ed in path.edges:
        name = type(ed).__name__
        if name == "LineEdge":
            for attr in ("start", "end"):
                q = tuple(map(float, getattr(ed, attr)))
                if q in moved:
                    setattr(ed, attr, moved[q])
        elif name == "SplineEdge":
            cps = np.asarray([tuple(v)[:2] for v in ed.control_points], dtype=float)
            for (old_cps, old_knots), e in splines:
                if cps.shape == old_cps.shape and np.array_equal(cps, old_cps) and \
                        old_knots is not None and \
                        np.array_equal(np.asarray(ed.knot_values, dtype=float), old_knots):
                    ed.control_points = [tuple(v)[:2] for v in e.control_points]
                    ed.knot_values = [float(k) for k in e.knots]
                    ed.degree = int(e.dxf.degree)
                    done_splines += 1
                    break
    if done_splines != len(splines):
        return False
    # every moved vertex must now be where its polyline has it
    ends = {tuple(map(float, getattr(ed, a))) for ed in path.edges
            if type(ed).__name__ == "LineEdge" for a in ("start", "end")}
    return all(v in ends or k == v for k, v in moved.items()) or not moved


#: Graphical entities a DXF R12 (AC1009) file can hold; ezdxf drops every other kind when it
#: saves a drawing as R12.
_R12_ENTITIES = frozenset({
    "LINE", "POINT", "CIRCLE", "ARC", "TRACE", "SOLID", "3DFACE", "SHAPE", "INSERT", "ATTDEF",
    "ATTRIB", "TEXT", "POLYLINE", "VERTEX", "SEQEND", "DIMENSION", "VIEWPORT", "BLOCK",
    "ENDBLK"})


def _upgrade_r12(doc: Any, template: str | os.PathLike[str]) -> None:
    """Save a drawing loaded as R12 as R2000 when it holds entities R12 cannot store.

    ezdxf loads a file without ``$ACADVER`` (or with ``AC1009``) as R12 and saves it as R12,
    which has no SPLINE (nor LWPOLYLINE, ELLIPSE, HATCH, ...): they would be dropped without a
    word. ezdxf keeps the R2000 structures of every drawing it loads, so setting
    ``doc.dxfversion`` to ``AC1015`` writes them all; a warning says so.
    """
    if doc.dxfversion >= "AC1015":
        return
    kinds = sorted({e.dxftype() for blk in doc.blocks for e in blk} - _R12_ENTITIES)
    if not kinds:
        return
    doc.dxfversion = "AC1015"
    warnings.warn(f"{os.fspath(template)}: read as DXF R12 ({doc.loaded_dxfversion}; also what a "
                  f"header without $ACADVER gives), which cannot hold {', '.join(kinds)} "
                  "entities; the output is written as DXF R2000 (AC1015) so that none is lost",
                  UserWarning, stacklevel=3)


def _group_foreign(records: Sequence[CurveRecord]) -> dict[Any, list[CurveRecord]]:
    out: dict[Any, list[CurveRecord]] = {}
    for i, r in enumerate(records):
        if "indices" in r.source and r.path is not None:
            key: Any = (r.path, r.source.get("handle"), r.format)
        else:
            key = ("single", i)
        out.setdefault(key, []).append(r)
    return out
