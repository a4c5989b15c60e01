"""Write, read back, measure: the tolerance checked in the file the user will read.

:func:`write_checked` writes faired records to a temporary file next to the destination,
reads that file back with the same reader, and measures every curve read back against the
curve read from the input (what the user had before): the parametric deviation
``max_t |a(t) - b(t)|`` when both curves have the same parameter domain (B-spline and
Bezier entities: same knots), else the geometric (Hausdorff) distance
(:func:`curvefair.deviation` with ``kind="auto"``) -- a point file stores only points, and the
curve re-interpolated through moved points has new chord-length parameters.

When a curve read back is farther than ``tol`` from the input:

1. SVG elements rounded to their own number of decimals are written again with exact numbers
   (the rounding is undone);
2. point data (point lists, airfoils, polylines: the curve is re-interpolated on reading)
   get their moves from the input scaled down, ``p = p0 + s (p_faired - p0)`` with
   ``s < 1`` (aiming at ``0.995 tol``), until the curve read back is within ``tol``;
3. otherwise nothing is written (the destination is untouched) and
   :class:`WriteCheckError` says which curve is how far.

Only then is the temporary file moved onto the destination.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from .._typing import FloatArray
from ..errors import CurvefairError, InputError
from ._common import CurveRecord, atomic_path, points_curve

if TYPE_CHECKING:
    from ..curves.bspline import BSplineCurve
    from ..curves.hermite import CubicHermite

__all__ = ["WriteCheck", "WriteCheckError", "write_checked", "rescaled_report"]

#: Record kinds whose curve is re-interpolated from data points on reading.
POINT_KINDS = ("points", "airfoil", "polyline", "fit_points")
_MAX_SHRINK = 12


class WriteCheckError(InputError):
    """The written file would not hold the curves within the tolerance (nothing written)."""


@dataclass(frozen=True)
class WriteCheck:
    """What the read-back check measured on the written file.

    Attributes
    ----------
    max_deviation : float
        Largest distance of a curve read back from the written file to its input curve.
    deviations : tuple of float
        Per input record, in order.
    kinds : tuple of str
        Per record: ``"parametric"``, ``"geometric"`` (the refined Hausdorff distance), or
        ``"geometric upper bound"`` (a cheap bound, used when it already meets ``tol``: for
        point data read back with as many points, the per-span bound
        :func:`curvefair.analysis.matched_hermite_bound`, else the dense sampled bound of
        :func:`curvefair.analysis.geometric_upper_bound`).
    max_point_displacement : float or None
        Largest data/control point displacement read back, where the counts match.
    precision : str
        ``"file"`` (the file's own precision), ``"decimals"`` (as requested), ``"file+"``
        (SVG: the elements' own decimals put a curve beyond the tolerance; three more were
        enough) or ``"exact"`` (the file's rounding exceeded the tolerance and was undone).
    move_scale : tuple of float
        Per record, the factor ``s`` applied to the moves of point data (1.0: as faired).
    notes : tuple of str
        What was changed to meet the tolerance, one sentence each.
    read_back : tuple of curves
        The curves read back from the written file, one per input record (not in
        :meth:`to_dict`).
    """

    max_deviation: float
    deviations: tuple[float, ...]
    kinds: tuple[str, ...]
    max_point_displacement: float | None
    precision: str
    move_scale: tuple[float, ...]
    notes: tuple[str, ...] = field(default_factory=tuple)
    read_back: tuple[Any, ...] = field(default_factory=tuple, compare=False, repr=False)

    def to_dict(self) -> dict[str, Any]:
        return {"max_deviation": self.max_deviation, "deviations": list(self.deviations),
                "kinds": list(self.kinds),
                "max_point_displacement": self.max_point_displacement,
                "precision": self.precision, "move_scale": list(self.move_scale),
                "notes": list(self.notes)}


def _label(rec: CurveRecord, i: int) -> str:
    return f"curve {i}" + (f" ({rec.name})" if rec.name else "")


def _entity(r: CurveRecord) -> tuple[Any, ...] | None:
    """The source entity of a record (3dm object id, DXF handle, SVG element and subpath)."""
    src = r.source
    for k in ("id", "handle"):
        if src.get(k) is not None:
            return (k, src[k])
    if src.get("element") is not None:
        return ("element", src["element"], src.get("subpath"))
    return None


def _ordered(reference: Sequence[CurveRecord], back: Sequence[CurveRecord]
             ) -> list[CurveRecord]:
    """The records read back that correspond to ``reference``, in its order.

    Records that name their source entity are paired by it: a writer may move a replaced
    entity to the end (a 3dm object whose degree changed), and a template's other entities,
    written back untouched, are read back too (a subset of a file's curves written). Records
    without one (bare curves written as new entities, appended by the writers) take the last
    unclaimed records read back, in order. When that cannot be done, ``back`` as read.
    """
    ref_keys = [_entity(r) for r in reference]
    back_keys = [_entity(b) for b in back]
    if all(k is None for k in ref_keys):
        return list(back)
    by: dict[Any, list[CurveRecord]] = {}
    for k, b in zip(back_keys, back, strict=True):
        if k is not None:
            by.setdefault(k, []).append(b)
    wanted = {k for k in ref_keys if k is not None}
    if not wanted <= set(by):
        return list(back)
    unclaimed = [b for k, b in zip(back_keys, back, strict=True) if k not in wanted]
    n_bare = sum(k is None for k in ref_keys)
    if n_bare > len(unclaimed):
        return list(back)
    bare = unclaimed[len(unclaimed) - n_bare:]
    out: list[CurveRecord] = []
    seen: set[Any] = set()
    for k in ref_keys:
        if k is None:
            out.append(bare.pop(0))
        elif k not in seen:
            seen.add(k)
            out.extend(by[k])
    return out


def _lifted(rec: CurveRecord) -> CurveRecord | None:
    """A 2-D record read back with a common z (``source["z"]``) as the same curve in 3-D, or
    None when its curve type cannot be lifted."""
    from ..curves.bspline import BSplineCurve
    from ..curves.hermite import CubicHermite, QuinticHermite

    z = float(rec.source["z"])
    c = rec.curve

    def up(a: Any, value: float) -> FloatArray:
        a = np.asarray(a, dtype=float)
        return np.c_[a, np.full(a.shape[0], value)]

    if isinstance(c, BSplineCurve):
        new: Any = c.replace(control_points=up(c.control_points, z))
    elif isinstance(c, (CubicHermite, QuinticHermite)):
        names = ("tangents",) if isinstance(c, CubicHermite) else ("d1", "d2")
        new = c.replace(points=up(c.points, z),
                        **{k: up(getattr(c, k), 0.0) for k in names})
    else:
        return None
    pts = None if rec.points is None else up(rec.points, z)
    return CurveRecord(new, rec.name, rec.kind, rec.source, pts, rec.corners)


def _as_reference_dims(reference: Sequence[CurveRecord], back: Sequence[CurveRecord]
                       ) -> list[CurveRecord]:
    """``back`` (in ``reference``'s order, :func:`_ordered`) with each 2-D record read back for
    a 3-D reference entity lifted to 3-D at its common z: a 3-D curve the fair made exactly
    planar at constant z (a straight polyline whose z had rounding noise) is read back 2-D,
    the readers' form of a planar curve, and is the same curve. Paired by source entity as
    :func:`_matched` pairs them (:func:`_groups`); unchanged when they cannot be paired."""
    if all(r.curve.dim == 2 for r in reference):
        return list(back)
    rg, bg = _groups(reference), _groups(back)
    if len(rg) != len(bg):
        return list(back)
    out = []
    for rr, bb in zip(rg, bg, strict=True):
        for b in bb:
            if rr[0].curve.dim == 3 and b.curve.dim == 2 and b.source.get("z") is not None:
                b = _lifted(b) or b
            out.append(b)
    return out


def _groups(records: Sequence[CurveRecord]) -> list[list[CurveRecord]]:
    """Records grouped by source entity: the pieces ``0 .. n_pieces-1`` of a point list split
    at corners form one group, any other record a group of its own."""
    out: list[list[CurveRecord]] = []
    for r in records:
        piece = r.source.get("piece")
        if isinstance(piece, int) and piece > 0 and out and \
                out[-1][-1].source.get("piece") == piece - 1:
            out[-1].append(r)
        else:
            out.append([r])
    return out


def _shapes_agree(ref: Sequence[CurveRecord], back: Sequence[CurveRecord]) -> bool:
    """Same number of records and, for point data, the same number of points each."""
    return len(ref) == len(back) and all(
        r.kind not in POINT_KINDS or b.kind not in POINT_KINDS or r.points is None
        or b.points is None or np.shape(r.points) == np.shape(b.points)
        for r, b in zip(ref, back, strict=True))


def _matched(reference: Sequence[CurveRecord], back: Sequence[CurveRecord]
             ) -> list[Any] | None:
    """The curves read back, one per reference record, or None when they cannot be paired.

    Per source entity (see :func:`_groups`): the same pieces in order; otherwise (a point
    list split at other corners when read back, e.g. after moves that made or removed a
    corner) each reference piece is rebuilt from the points read back at its indices.
    """
    if _shapes_agree(reference, back):
        return [b.curve for b in back]
    rg, bg = _groups(reference), _groups(back)
    if len(rg) != len(bg):
        return None
    out: list[Any] = []
    for rr, bb in zip(rg, bg, strict=True):
        if _shapes_agree(rr, bb):
            out.extend(b.curve for b in bb)
            continue
        p0 = rr[0].points if rr[0].points is not None else getattr(rr[0].curve, "points", None)
        if len(rr) == 1 and "indices" not in rr[0].source and isinstance(p0, np.ndarray) and \
                all("indices" in b.source and "n_points" in b.source for b in bb):
            # a bare curve written as points, read back split at corners: the whole list
            n0 = int(p0.shape[0])
            if {int(b.source["n_points"]) for b in bb} != {n0}:
                return None
            full = np.full((n0, p0.shape[1]), np.nan)
            for b in bb:
                full[np.asarray(b.source["indices"], dtype=int)] = np.asarray(b.points)
            if np.isnan(full).any():
                return None
            out.append(points_curve(full, bool(rr[0].curve.closed)))
            continue
        if not all("indices" in r.source and "n_points" in r.source for r in rr + bb):
            return None
        n = {int(r.source["n_points"]) for r in rr + bb}
        if len(n) != 1:
            return None
        full = np.full((n.pop(), bb[0].points.shape[1]), np.nan)  # type: ignore[union-attr]
        for b in bb:
            full[np.asarray(b.source["indices"], dtype=int)] = np.asarray(b.points)
        if np.isnan(full).any():
            return None
        for r in rr:
            idx = np.asarray(r.source["indices"], dtype=int)
            out.append(points_curve(full[idx], bool(r.curve.closed)))
    return out


def _lost_points(reference: Sequence[CurveRecord], back: Sequence[CurveRecord]) -> str | None:
    """Why the point data read back is not the point data written (points merged or dropped
    on reading, e.g. rounded onto each other), or None."""
    if _shapes_agree(reference, back):
        return None
    rg, bg = _groups(reference), _groups(back)
    if len(rg) != len(bg):
        return None  # reported by _matched
    for rr, bb in zip(rg, bg, strict=True):
        if _shapes_agree(rr, bb):
            continue
        i = next(k for k, r in enumerate(reference) if r is rr[0])
        nr = {int(r.source["n_points"]) for r in rr if "n_points" in r.source}
        nb = {int(b.source["n_points"]) for b in bb if "n_points" in b.source}
        if nr and nb:
            if nr != nb:
                return (f"{_label(rr[0], i)} reads back with {sorted(nb)[0]} points, "
                        f"{sorted(nr)[0]} were written")
            continue
        if len(rr) == len(bb):
            for r, b in zip(rr, bb, strict=True):
                if r.points is not None and b.points is not None and \
                        np.shape(r.points) != np.shape(b.points):
                    return (f"{_label(r, i)} reads back with {b.points.shape[0]} points, "
                            f"{r.points.shape[0]} were written")
    return None


def _same_domain(a: Any, b: Any) -> bool:
    (a0, a1), (b0, b1) = a.domain, b.domain
    t = 1e-12 * max(a1 - a0, b1 - b0, abs(a0), abs(a1))
    return abs(a0 - b0) <= t and abs(a1 - b1) <= t


def _measure(reference: Sequence[CurveRecord], curves: Sequence[Any], tol: float | None
             ) -> tuple[list[float], list[str], float | None]:
    """Per curve: the parametric deviation (equal domains), else a cheap upper bound of the
    Hausdorff distance when it already meets ``tol`` (or there is no tol), else the refined
    geometric distance."""
    from ..analysis import (
        deviation,
        geometric_upper_bound,
        matched_hermite_bound,
        point_displacement,
    )
    from ..curves.hermite import CubicHermite

    devs, kinds, mpd = [], [], None
    for r, c in zip(reference, curves, strict=True):
        d_max: float | None = None
        mb: FloatArray | None = None
        if not _same_domain(r.curve, c):
            if (type(r.curve) is CubicHermite and type(c) is CubicHermite
                    and np.shape(r.curve.points) == np.shape(c.points)):
                # point data read back with its points: the O(n) per-span bound (a few array
                # operations; tighter than the sampled bound when tol is small against the
                # curve's length), else the refined distance below
                mb = matched_hermite_bound(r.curve, c)
                ub = float(mb.max()) if mb.size else 0.0
            else:
                ub = geometric_upper_bound(r.curve, c)
            if tol is None or ub <= tol:
                d_max, kind = ub, "geometric upper bound"
                m, _ = point_displacement(r.curve, c)
        if d_max is None and mb is not None and tol is not None:
            # the spans the bound does not clear, measured against the whole other curve
            over = ~(mb <= tol)
            d = deviation(r.curve, c, kind="geometric", spans=np.flatnonzero(over))
            d_max = max(float(d.max_distance), float(mb[~over].max(initial=0.0)))
            kind, m = d.kind, d.max_point_displacement
        if d_max is None:
            d = deviation(r.curve, c)
            if tol is not None and not d.max_distance <= tol and "outline" in r.source \
                    and d.kind != "geometric":
                # a glyph contour's B-spline starts at its first corner node: a near-smooth
                # corner the fair made exactly smooth (a binary font's smooth node: its
                # neighbours exactly collinear) moves that seam to the next corner, and the
                # same outline is parametrised from another node (TestVGID's hah-ar.4 read
                # 386 units "away", a line's length). The outline is what the file holds.
                d = deviation(r.curve, c, kind="geometric")
            d_max, kind, m = float(d.max_distance), d.kind, d.max_point_displacement
        devs.append(d_max)
        kinds.append(kind)
        if m is not None:
            mpd = max(mpd or 0.0, float(m))
    return devs, kinds, mpd


#: The rounding allowance of :func:`_svg_point_displacement`, in units of ``eps`` times the
#: largest coordinate: the Bezier points are computed from the B-spline (power form to
#: Bernstein) and mapped through the element's transformation and back, each a few roundings.
#: A point of a Bezier chain farther than ``tol`` by no more than this is rounding, not the
#: fairing: :func:`write_checked` then scales that curve's moves down by a few allowances and
#: writes again (every node and handle within ``tol`` exactly, as read back).
_SVG_POINT_ULPS = 64


def _svg_point_displacement(ref: CurveRecord, back: CurveRecord) -> tuple[float, float] | None:
    """SVG: how far the points the file holds moved -- the nodes and handles of a Bezier chain
    (against the Bezier points of the reference curve), the vertices of a polyline -- and the
    rounding allowance of that figure; None when they cannot be paired one to one.

    The read-back deviation of a Bezier chain is a geometric (Hausdorff) distance, since its
    knots follow the control polygon's lengths; a node or handle rounded to the element's
    decimals can move farther than ``tol`` while the curve stays within it (a handle of a
    one-decimal icon moved by 0.1 + rounding 0.05 in x and y: 0.14 at tol 0.1). ``--tol``
    bounds every point, so it is measured here too."""
    if ref.kind == "bspline" and back.kind == "bspline":
        bb = back.source.get("beziers")
        if bb is None:
            return None
        b1 = np.asarray(bb, dtype=np.float64)
        b0 = np.asarray(ref.source.get("beziers", []), dtype=np.float64)
        if b0.shape != b1.shape:
            # no segments as read (a reference curve built by hand): those of its B-spline
            from ._common import bezier_pieces
            try:
                b0 = bezier_pieces(ref.curve, "write_checked", max_degree=3)
            except CurvefairError:
                return None
    elif ref.kind in POINT_KINDS and ref.points is not None and back.points is not None:
        b0, b1 = np.asarray(ref.points, dtype=np.float64), np.asarray(back.points)
    else:
        return None
    if b0.shape != b1.shape or b0.size == 0:
        return None
    diff = b1 - b0
    d = float(np.hypot(diff[..., 0], diff[..., 1]).max() if diff.shape[-1] == 2
              else np.linalg.norm(diff, axis=-1).max())
    slack = _SVG_POINT_ULPS * float(np.finfo(np.float64).eps) * float(np.abs(b0).max())
    return d, slack


def _moved_by(p0: FloatArray, p1: FloatArray, s: float) -> FloatArray:
    """``p0 + s (p1 - p0)``, with the points that did not move (corners, clamped ends,
    protected points) kept bit for bit."""
    p0 = np.asarray(p0, dtype=np.float64)
    p1 = np.asarray(p1, dtype=np.float64)
    pts = p0 + s * (p1 - p0)
    same = np.all(p1 == p0, axis=1)
    pts[same] = p0[same]
    return pts


def _scaled(rec: CurveRecord, ref: CurveRecord, s: float) -> CurveRecord:
    """``rec`` with its data points moved ``s`` times as far from ``ref``'s as faired."""
    pts = _moved_by(cast("CubicHermite", ref.curve).points,
                    cast("CubicHermite", rec.curve).points, s)
    return rec.with_curve(points_curve(pts, bool(rec.curve.closed)))


def _bspline_shrinkable(rec: CurveRecord, ref: CurveRecord) -> bool:
    a = getattr(rec.curve, "control_points", None)
    b = getattr(ref.curve, "control_points", None)
    ka = getattr(rec.curve, "knots", None)
    kb = getattr(ref.curve, "knots", None)
    return (rec.kind == "bspline" and isinstance(a, np.ndarray) and isinstance(b, np.ndarray)
            and a.shape == b.shape and isinstance(ka, np.ndarray)
            and isinstance(kb, np.ndarray) and np.array_equal(ka, kb))


def _scaled_bspline(rec: CurveRecord, ref: CurveRecord, s: float) -> CurveRecord:
    """``rec`` (a B-spline record) with its control points moved ``s`` times as far from
    ``ref``'s as faired, on its own knots (see :func:`_bspline_shrinkable`)."""
    curve = cast("BSplineCurve", rec.curve)
    pts = _moved_by(cast("BSplineCurve", ref.curve).control_points, curve.control_points, s)
    return rec.with_curve(curve.replace(control_points=pts))


def _shrinkable(rec: CurveRecord, ref: CurveRecord) -> bool:
    a = getattr(rec.curve, "points", None)
    b = getattr(ref.curve, "points", None)
    return (rec.kind in POINT_KINDS and isinstance(a, np.ndarray) and isinstance(b, np.ndarray)
            and a.shape == b.shape)


#: The largest turn, in degrees, that rounding a rewritten SVG element's numbers may open at
#: a join of a Bezier chain that is smooth in the input (handles parallel: the reader makes
#: the B-spline C1 there, and fairing keeps it so). Rounded independently, the two handles of
#: such a join point apart: a handle 2.3 units long rounded to one decimal turns by up to
#: 1.8 degrees (Font Awesome 3.svg at tol 0.3), a visible kink in a curve the user had smooth.
SMOOTH_JOIN_TURN = 0.01


def _opened_joins(ref: CurveRecord, faired: CurveRecord, back: CurveRecord) -> float:
    """SVG: the largest turn (degrees) the file read back has at a join that is smooth in
    the input and in the faired curve (turn at most :data:`SMOOTH_JOIN_TURN` / 100), 0.0
    when there is none or the segments cannot be paired one to one."""
    if not (ref.kind == "bspline" and back.kind == "bspline"):
        return 0.0
    b0 = np.asarray(ref.source.get("beziers", []), dtype=np.float64)
    b1 = np.asarray(back.source.get("beziers", []), dtype=np.float64)
    if b0.ndim != 3 or b0.shape != b1.shape or b0.shape[0] < 1:
        return 0.0
    from ._common import bezier_pieces
    try:
        bf = bezier_pieces(faired.curve, "write_checked", max_degree=3)
    except CurvefairError:
        return 0.0
    if bf.shape != b0.shape:
        return 0.0
    from .svg import join_turns
    closed = bool(np.array_equal(b0[-1, 3], b0[0, 0]))
    _, smooth = join_turns(b0, closed)
    tf, _ = join_turns(bf, closed)
    t1, _ = join_turns(b1, closed)
    keep = smooth & (np.degrees(tf) <= SMOOTH_JOIN_TURN / 100)
    return float(np.degrees(t1[keep]).max()) if keep.any() else 0.0


#: SVG write-backs round a rewritten element's numbers to its own decimals first, then to
#: :data:`curvefair.io.svg.MORE_DECIMALS` more, then write them exactly (what the notes say).
_SVG_PRECISION = {"file": "the elements' own decimals",
                  "file+": "the elements' own decimals plus 3"}
_SVG_NEXT = {"file": "written with 3 more decimals", "file+": "written with exact numbers"}


def _svg_next(precision: str) -> str:
    return "file+" if precision == "file" else "exact"


def write_checked(path: str | os.PathLike[str], records: Sequence[CurveRecord],
                  reference: Sequence[CurveRecord], *, tol: float | None,
                  reader: Callable[[str], list[CurveRecord]], template: object = None,
                  format: str | None = None, overwrite: bool = False,
                  decimals: int | None = None, precision: str = "file") -> WriteCheck:
    """Write ``records`` to ``path`` only if the file read back holds every curve within
    ``tol`` of ``reference``.

    The records are written to a temporary file beside ``path``, which is read back with
    ``reader``; every curve read back is measured against its reference curve (what the user
    had before): the parametric deviation when both have the same parameter domain (spline
    entities: same knots), else the geometric (Hausdorff) distance of
    :func:`curvefair.deviation`, or an upper bound of it where that already meets ``tol``. A
    curve read back farther than ``tol`` is handled in this order: SVG elements rounded to
    their own decimals are written again with exact numbers; point data (re-interpolated on
    reading) get their moves from the reference scaled down, ``p = p0 + s (p_faired - p0)``
    with ``s < 1``, until within ``tol``; otherwise nothing is written. Only a file that
    passes replaces ``path``. :func:`curvefair.write_curves` and ``curvefair fair`` write
    through this function.

    Parameters
    ----------
    path : path-like
        The destination; untouched unless the check passes.
    records : sequence of CurveRecord
        The faired records, one per reference record, in the same order.
    reference : sequence of CurveRecord
        The records read from the input (the curves the user had).
    tol : float or None
        None: measure and report, enforce nothing (the file must still read back).
    reader : callable
        ``reader(path) -> records``: how the file is read (the same corner handling as the
        input).
    template, format, overwrite, decimals, precision
        As for :func:`curvefair.write_curves` (which calls this function; ``overwrite`` is
        checked there); ``decimals`` given: the rounding asked for is kept, and a file it puts
        out of tolerance is not written; ``precision="exact"``: exact numbers from the start.

    Returns
    -------
    WriteCheck
        What was measured on the written file (deviations per record, how each was measured,
        the move scales applied, the curves read back).

    Raises
    ------
    WriteCheckError
        The file would not read back, or a curve read back would be farther than ``tol``
        from its input; nothing is written.
    """
    from . import _template_path, _write_plain, detect_format

    del overwrite  # the destination is checked by write_curves / the CLI; tmp is never an input
    if len(records) != len(reference):
        raise InputError(f"write_checked: {len(records)} records for {len(reference)} "
                         "reference records")
    fmt = detect_format(path, format)
    if decimals is not None:
        precision = "decimals"
    elif precision not in ("file", "exact"):
        raise InputError(f"precision must be 'file' or 'exact', got {precision!r}")
    tpath = _template_path(template)
    recs = list(records)
    scale = [1.0] * len(recs)
    notes: list[str] = []
    where = os.fspath(path)
    with atomic_path(path) as tmp:
        for _attempt in range(_MAX_SHRINK + 3):
            _write_plain(tmp, recs, fmt, tpath, decimals,
                         precision if precision in ("exact", "file+") else "file")
            try:
                back = reader(os.fspath(tmp))
            except CurvefairError as exc:
                msg = str(exc).replace(os.fspath(tmp), where)
                if precision in ("file", "file+") and fmt == "svg":
                    notes.append(f"{_SVG_PRECISION[precision]} gave a file that does not "
                                 f"read back; {_SVG_NEXT[precision]}")
                    precision = _svg_next(precision)
                    continue
                hint = f" (--decimals {decimals} rounds too much?)" if decimals is not None \
                    else ""
                raise WriteCheckError(f"{where}: not written: the file would not read back: "
                                      f"{msg}{hint}") from None
            back = _as_reference_dims(reference, _ordered(reference, back))
            lost = _lost_points(reference, back)
            if lost is not None:
                hint = f" (--decimals {decimals} rounds too much?)" if decimals is not None \
                    else ""
                raise WriteCheckError(f"{where}: not written: {lost}{hint}")
            curves = _matched(reference, back)
            if curves is None:
                if precision in ("file", "file+") and fmt == "svg":
                    # e.g. a tiny closed subpath faired nearly to a point: the element's own
                    # decimals merge its points, exact numbers keep them apart
                    notes.append(f"{_SVG_PRECISION[precision]} gave {len(back)} curves where "
                                 f"the input had {len(reference)}; {_SVG_NEXT[precision]}")
                    precision = _svg_next(precision)
                    continue
                seen = {_entity(b) for b in back}
                gone = [_label(r, i) for i, r in enumerate(reference)
                        if _entity(r) is not None and _entity(r) not in seen]
                raise WriteCheckError(
                    f"{where}: not written: it reads back as {len(back)} curves, the input "
                    f"had {len(reference)}"
                    + (f" ({', '.join(gone[:3])}{' ...' if len(gone) > 3 else ''} not read "
                       "back)" if gone else ""))
            try:
                devs, kinds, mpd = _measure(reference, curves, tol)
            except CurvefairError:
                raise
            except (ValueError, ArithmeticError, MemoryError) as exc:
                raise WriteCheckError(f"{where}: not written: the curves read back could not "
                                      f"be measured against the input ({exc})") from None
            if fmt == "svg" and tol is not None and _shapes_agree(reference, back):
                # every node, handle and vertex within tol too, not only the curve
                nudge: dict[int, float] = {}  # curve -> the scale-down of its moves
                for i, (r, b) in enumerate(zip(reference, back, strict=True)):
                    pd = _svg_point_displacement(r, b)
                    if pd is None or not pd[0] > tol:
                        continue
                    if (pd[0] <= tol + pd[1] and _attempt < _MAX_SHRINK
                            and _bspline_shrinkable(records[i], reference[i])):
                        nudge[i] = 8.0 * pd[1] / float(tol)
                    else:
                        devs[i] = max(devs[i], pd[0])
                if nudge:
                    # a node or handle over tol by rounding only (the control points are
                    # within tol, the Bezier points are convex combinations of them, computed
                    # in float): scale the curve's moves down by 8 allowances and write again
                    for i, down in nudge.items():
                        scale[i] *= 1.0 - down
                        recs[i] = _scaled_bspline(records[i], reference[i], scale[i])
                    notes.append(f"{len(nudge)} curve(s) had a node or handle over tol by "
                                 "rounding only; their moves were scaled down by at most "
                                 f"{max(nudge.values()):.1e}")
                    continue
            over = [i for i, d in enumerate(devs) if tol is not None and not d <= tol]
            undone = ([i for i, d in enumerate(devs) if d == 0.0
                       and not _same_curve(records[i].curve, reference[i].curve)]
                      if not over and precision in ("file", "file+") and fmt == "svg" else [])
            if undone:
                # every move of a faired curve smaller than half the element's last decimal:
                # rounded, the file would hold the input as it was
                notes.append(f"rounded to {_SVG_PRECISION[precision]}, the moves of "
                             f"{_label(reference[undone[0]], undone[0])}"
                             + (f" and {len(undone) - 1} more curve(s)" if len(undone) > 1
                                else "")
                             + f" were undone; {_SVG_NEXT[precision]}")
                precision = _svg_next(precision)
                continue
            if (not over and fmt == "svg" and precision in ("file", "file+", "decimals")
                    and _shapes_agree(reference, back)):
                # rounding must not kink a join the user had smooth (handles rounded apart)
                turns = [_opened_joins(r, f, b)
                         for r, f, b in zip(reference, recs, back, strict=True)]
                kinked = [i for i, t in enumerate(turns) if t > SMOOTH_JOIN_TURN]
                if kinked:
                    worst = max(kinked, key=lambda i: turns[i])
                    what = (f"{_label(reference[worst], worst)} turned {turns[worst]:.3g} "
                            "degrees at a join smooth in the input"
                            + (f" ({len(kinked)} curves)" if len(kinked) > 1 else ""))
                    if precision == "decimals":
                        notes.append(f"rounded to --decimals {decimals}, {what}")
                    else:
                        notes.append(f"rounded to {_SVG_PRECISION[precision]}, {what}; "
                                     f"{_SVG_NEXT[precision]}")
                        precision = _svg_next(precision)
                        continue
            if not over:
                return WriteCheck(max(devs, default=0.0), tuple(devs), tuple(kinds), mpd,
                                  precision, tuple(scale), tuple(notes), tuple(curves))
            if precision in ("file", "file+") and fmt == "svg":
                worst = max(over, key=lambda i: devs[i])
                notes.append(f"rounded to {_SVG_PRECISION[precision]}, "
                             f"{_label(reference[worst], worst)} "
                             f"read back {devs[worst]:.6g} from the input (> tol {tol:g}); "
                             f"{_SVG_NEXT[precision]}")
                precision = _svg_next(precision)
                continue
            fix = [i for i in over if _shrinkable(records[i], reference[i])]
            if len(fix) < len(over) or precision == "decimals":
                i = next(i for i in over if i not in fix) if len(fix) < len(over) else over[0]
                why = (f"; --decimals {decimals} rounds too much" if precision == "decimals"
                       else "")
                raise WriteCheckError(
                    f"{where}: not written: {_label(reference[i], i)} would read back "
                    f"{devs[i]:.6g} from the input, more than tol {tol:g}{why}")
            if all(sc == 1.0 for sc in scale):
                worst = max(fix, key=lambda i: devs[i])
                notes.append(f"point data: the curve re-interpolated through the written points "
                             f"of {_label(reference[worst], worst)} read back {devs[worst]:.6g} "
                             f"from the input (> tol {tol:g}); the moves of {len(fix)} curve(s) "
                             "were scaled down until within tol")
            for i in fix:
                # the deviation grows about linearly with the scale of the moves; aim at
                # 0.995 tol (the geometric measure is not certified: leave it room)
                s = scale[i] * min(0.998, 0.995 * float(tol) / devs[i])  # type: ignore[arg-type]
                scale[i] = s
                recs[i] = _scaled(records[i], reference[i], s)
        raise WriteCheckError(f"{where}: not written: the curves read back stay farther than "
                              f"tol {tol:g} from the input")
    raise AssertionError("unreachable")  # pragma: no cover


def _same_curve(a: Any, b: Any) -> bool:
    """Same type, knots / parameters and data arrays, bit for bit (a curve read back as it was
    written); False for curves curvefair cannot compare so (then they are analysed)."""
    if type(a) is not type(b) or a.closed != b.closed or a.degree != b.degree:
        return False
    found = False
    for name in ("knots", "params", "control_points", "points", "tangents", "d1", "d2"):
        x, y = getattr(a, name, None), getattr(b, name, None)
        if not isinstance(x, np.ndarray) or not isinstance(y, np.ndarray):
            continue
        found = True
        if x.shape != y.shape or not np.array_equal(x, y):
            return False
    return found


def on_disk_report(report: dict[str, Any], original: Any, faired: Any, written: Any,
                   scale: float) -> dict[str, Any]:
    """A :func:`curvefair.fair` report whose after-figures describe the written file.

    The command line and :func:`curvefair.batch.fair_file` report what is on disk:

    * moves scaled by ``scale != 1`` to hold the tolerance on disk: :func:`rescaled_report`;
    * a cubic Hermite curve read back on other parameters than the faired one -- point data
      that moved: a reader rebuilds the curve through the written points at their own chord
      lengths, not the curve ``fair()`` returned on the input's parameters --: every
      ``<figure>_after`` of :func:`curvefair.analyze` (energies, jumps, Sapidis sum,
      inflections, extrema) is recomputed for ``written``; the faired curve's figures stay
      under ``fair_after`` and ``after_figures`` says so;
    * a curve read back with the faired curve's parameters but other numbers (rounded to the
      file's precision): the same, every ``<figure>_after`` recomputed for ``written``;
    * otherwise ``report`` itself (the curve read back is the faired one, bit for bit).

    Parameters
    ----------
    report : dict
        The ``report`` of the fair; not modified.
    original, faired, written : curve
        The curve read from the input, the faired curve, and the curve read back from the
        written file (``read_back[i]`` of the :class:`WriteCheck`).
    scale : float
        ``move_scale[i]`` of that check.

    Returns
    -------
    dict
        ``report`` or an updated copy.
    """
    if scale != 1.0:
        return rescaled_report(report, original, written, scale)
    from ..curves.hermite import CubicHermite
    from ..fairing.fair import ANALYSIS_FIGURES, analysis_block

    if faired is original:
        return report
    # the parameters tell (no O(n) test of the input): a point list read back has the chord
    # lengths of the written points, the faired curve kept the input's
    rebuilt = (type(faired) is CubicHermite and type(written) is CubicHermite
               and not np.array_equal(written.params, faired.params))
    if not rebuilt:
        if _same_curve(faired, written):
            return report
        # the file's numbers are the faired ones rounded to its precision: what is on disk
        # is analysed (a rounding ripple is a curvature extremum like any other)
        return _with_after(report, analysis_block(written),
                           "counted on the curve read back from the written file, whose "
                           "numbers are the faired ones rounded to the file's precision "
                           "(fair_after: the faired curve)")
    rb = (report.get("guard") or {}).get("rebuilt")
    if (isinstance(rb, dict) and all(k in rb for k in ANALYSIS_FIGURES)
            and written.closed == faired.closed
            and np.array_equal(written.points, faired.points)):
        # fair()'s guard analysed this very curve (the chord-length cubic through the same
        # points): its figures, not a second O(n) analysis
        after = {k: rb[k] for k in ANALYSIS_FIGURES}
    else:
        after = analysis_block(written)
    return _with_after(report, after,
                       "counted on the curve read back from the written file: point data are "
                       "rebuilt through the written points at their own chord lengths, as a "
                       "reader does (fair_after: the faired curve on the input's parameters)")


def _with_after(report: dict[str, Any], after: dict[str, Any], why: str) -> dict[str, Any]:
    """A copy of ``report`` whose ``<figure>_after`` are ``after``'s, the faired curve's kept
    under ``fair_after``, ``why`` under ``after_figures``."""
    out = dict(report)
    out["fair_after"] = {k: report.get(f"{k}_after") for k in after}
    for k, v in after.items():
        out[f"{k}_after"] = v
    out["after_figures"] = why
    return out


def rescaled_report(report: dict[str, Any], original: Any, written: Any,
                    scale: float) -> dict[str, Any]:
    """A :func:`curvefair.fair` report whose after-figures describe ``written``, the curve read
    back from the file, instead of the faired curve whose moves were scaled by ``scale`` to
    hold the tolerance on disk (point data re-interpolated on reading; see
    :func:`write_checked`).

    Parameters
    ----------
    report : dict
        The ``report`` of the :class:`curvefair.FairingResult` of the fair; not modified.
    original : curve
        The curve read from the input, the one that was faired.
    written : curve
        The curve read back from the written file (``read_back[i]`` of the
        :class:`WriteCheck` that :func:`write_checked` returned).
    scale : float
        The factor its moves were scaled by (``move_scale[i]`` of that check).

    Returns
    -------
    dict
        A copy of ``report`` with the figures below recomputed for ``written``.

    Notes
    -----
    Recomputed: every ``<figure>_after`` of :func:`curvefair.analyze` (energies, jumps,
    Sapidis sum, inflections, extrema), the data point moves (``moved``, ``n_moved``,
    ``max_point_displacement``, ``max_point_index``) and the deviation from ``original``
    (``max_deviation*``, with ``kind="auto"``: geometric, since re-interpolation gives new
    chord parameters). A method's own after-figure (``measure_max_after``) cannot be
    recomputed and becomes None. ``move_scale`` and ``after_figures`` say what was done.
    """
    from ..analysis import deviation
    from ..fairing import point_report
    from ..fairing.fair import analysis_block

    out = dict(report)
    after = analysis_block(written)
    redone = []
    for k, v in after.items():
        out[f"{k}_after"] = v
        redone.append(f"{k}_after")
    for k in list(out):
        if k.endswith("_after") and k not in redone:
            out[k] = None
    moved_idx, disp, max_disp, max_idx = point_report(original, written)
    out["moved"] = {"indices": [int(i) for i in moved_idx],
                    "displacement": [float(x) for x in disp]}
    out["n_moved"] = int(moved_idx.size)
    out["max_point_displacement"] = float(max_disp)
    out["max_point_index"] = None if max_idx is None else int(max_idx)
    d = deviation(original, written)
    ub = getattr(d, "upper_bound", None)
    out["max_deviation"] = float(d.max_distance)
    out["max_deviation_upper_bound"] = None if ub is None or not np.isfinite(ub) else float(ub)
    out["max_deviation_param"] = None if d.param is None else float(d.param)
    out["max_deviation_point"] = None if d.point_a is None else \
        [float(x) for x in np.asarray(d.point_a).reshape(-1)]
    out["max_deviation_kind"] = d.kind
    out["move_scale"] = float(scale)
    out["after_figures"] = (f"recomputed for the curve read back from the written file: the "
                            f"faired moves were scaled by {scale:.12g} to hold tol on disk")
    return out
