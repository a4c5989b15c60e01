"""SVG ``<path>`` elements through svgpathtools (``pip install 'curvefair[svg]'``).

Read
----
Every ``<path>`` element, in document order, split into its continuous subpaths:

- subpaths of straight segments only -> ``kind="polyline"``: the vertices (closed if the
  subpath ends where it starts), split at corners like every point list;
- subpaths of cubic Beziers (quadratic Beziers and straight segments among them are
  degree-elevated, exactly) -> ``kind="bspline"``: a cubic :class:`~curvefair.BSplineCurve`
  equal to the chain. The parameter width of each segment follows the tangent-length ratio at
  smooth joins, and each join gets a knot of multiplicity 1 (the chain is C2 there), 2 (C1) or
  3 (C0 -- a corner or a kink), so a chain exported from a C2 spline comes back as that
  spline; the result is checked to reproduce every segment to 1e-9 of the drawing size (else
  all joins get multiplicity 3, which is exact by construction). A closed chain is periodic
  when every join including the closing one is C2, otherwise an open curve from the start
  point round to it;
- subpaths with elliptical arcs: unsupported (``on_unsupported``).

Segments of length zero (an ``L`` to the current point, as matplotlib writes at the end of
closed lines) carry no geometry and are dropped; a subpath rewritten on write-back loses them.

Coordinates are the path's own user units (``transform`` attributes are not applied; they are
kept in ``source["transform"]``). ``source`` keys: ``element`` (index among the ``<path>``
elements), ``id``, ``subpath``, ``n_subpaths``, ``svg_closed``, ``beziers`` (the original
segments of a bspline record, to tell unchanged curves) and the point-list keys.

Write
-----
With ``template=`` the source text is copied and only the ``d`` attribute of the ``<path>``
elements whose curves changed is rewritten (absolute ``M``/``L``/``C``/``Z`` commands, every
other subpath of the element as it was; everything else in the file byte for byte). A
B-spline is written as its cubic Bezier pieces (one per knot span: the same number of
segments as read when the knots are unchanged). Without a template, a new SVG holding one
``<path>`` per curve (cubic curves only: degree <= 3). Numbers of a rewritten element get the
largest number of decimals the element had (its precision; ``decimals=`` overrides,
``precision="exact"`` writes the shortest exact representation instead), numbers of a new file
the shortest exact representation.
"""

from __future__ import annotations

import html
import os
import re
import warnings
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from typing import Any

import numpy as np

from .._typing import FloatArray
from ..curves.bspline import BSplineCurve
from ..errors import FileFormatError, InputError
from ._common import (
    CurveRecord,
    Unsupported,
    atomic_write,
    bezier_pieces,
    check_points,
    data_points,
    joined_points,
    lazy_import,
    piece_values,
    point_records,
)

__all__ = ["read", "write", "bezier_chain_to_bspline"]

FORMAT = "svg"
_PATH_TAG_RE = re.compile(r"<path\b[^>]*?>", re.DOTALL)
_D_RE = re.compile(r"""(\sd\s*=\s*)(["'])(.*?)\2""", re.DOTALL)


def _svgpathtools(what: str) -> Any:
    return lazy_import("svgpathtools", "svgpathtools", "svg", what)


# ------------------------------------------------------------------------------------------
# Bezier chain -> B-spline
# ------------------------------------------------------------------------------------------
def _bezier_eval(P: FloatArray, s: FloatArray) -> FloatArray:
    """Points of every cubic segment ``P (m, 4, dim)`` at local parameters ``s (k,)``."""
    b = np.stack([(1 - s) ** 3, 3 * s * (1 - s) ** 2, 3 * s**2 * (1 - s), s**3], axis=1)
    return np.einsum("kj,mjd->mkd", b, P)


def bezier_chain_to_bspline(P: FloatArray, closed: bool) -> BSplineCurve:
    """The cubic B-spline equal to a chain of cubic Bezier segments.

    Parameters
    ----------
    P : ndarray, shape (m, 4, dim)
        Control points of ``m`` segments; segment ``i`` ends where ``i + 1`` starts.
    closed : bool
        The last segment ends where the first starts.

    Returns
    -------
    BSplineCurve
        Knot spans = segments; knot multiplicity 1, 2 or 3 at each join as the chain is C2,
        C1 or only C0 there (parameter widths chosen so that G1 joins are C1).

    Notes
    -----
    At a join with incoming handle ``a = P3 - P2`` and outgoing handle ``b = Q1 - Q0``, the
    derivatives are ``3a/h_i`` and ``3b/h_{i+1}``: parallel handles give C1 with
    ``h_{i+1} = h_i |b| / |a|``; then C2 holds when ``6 (P3 - 2 P2 + P1) / h_i^2 =
    6 (Q2 - 2 Q1 + Q0) / h_{i+1}^2``. The control points are found by least squares on 5
    samples per segment and accepted only if the B-spline reproduces the chain to 1e-9 of its
    size; otherwise every join gets multiplicity 3 (control points = Bezier points).
    """
    P = np.asarray(P, dtype=float)
    m, _, dim = P.shape
    scale = max(float(np.abs(P).max()), 1.0)
    poly = np.linalg.norm(np.diff(P, axis=1), axis=2).sum(axis=1)
    poly = np.where(poly > 0, poly, 1.0)
    h = np.empty(m)
    h[0] = poly[0]
    mult = np.full(m, 3)          # mult[i]: join between segment i and i+1 (m-1: closing)
    n_joins = m if closed else m - 1
    for i in range(n_joins):
        j = (i + 1) % m
        a = P[i, 3] - P[i, 2]
        b = P[j, 1] - P[j, 0]
        na, nb = np.linalg.norm(a), np.linalg.norm(b)
        g1 = False
        if na > 1e-12 * scale and nb > 1e-12 * scale:
            cross = np.linalg.norm(np.cross(a, b)) if dim == 3 else abs(a[0] * b[1] - a[1] * b[0])
            g1 = cross <= 1e-9 * na * nb and float(np.dot(a, b)) > 0
        if j == 0:
            # closing join: C1 only if the widths come round consistently
            if g1 and abs(h[0] - h[i] * nb / na) <= 1e-9 * h[0]:
                mult[i] = 2
            else:
                mult[i] = 3
        else:
            h[j] = h[i] * nb / na if g1 else poly[j]
            mult[i] = 2 if g1 else 3
        if mult[i] == 2:
            d2a = 6 * (P[i, 3] - 2 * P[i, 2] + P[i, 1]) / h[i] ** 2
            d2b = 6 * (P[j, 2] - 2 * P[j, 1] + P[j, 0]) / h[j] ** 2
            ref = max(float(np.abs(d2a).max()), float(np.abs(d2b).max()), 1e-300)
            if float(np.abs(d2a - d2b).max()) <= 1e-9 * ref:
                mult[i] = 1
    t = np.r_[0.0, np.cumsum(h)]
    exact = _c0_bspline(P, t)
    if np.all(mult[:n_joins] == 3):
        return exact
    periodic = closed and np.all(mult == 1)
    try:
        cand = _fit(P, t, mult, periodic)
    except (ValueError, np.linalg.LinAlgError):
        return exact
    s = np.linspace(0.0, 1.0, 9)
    ref = _bezier_eval(P, s).reshape(-1, dim)
    u = (t[:-1, None] + h[:, None] * s[None, :]).reshape(-1)
    if float(np.abs(cand(u) - ref).max()) <= 1e-9 * scale:
        return cand
    return exact


def _c0_bspline(P: FloatArray, t: FloatArray) -> BSplineCurve:
    ctrl = np.vstack([P[0, :1]] + [P[i, 1:] for i in range(P.shape[0])])
    knots = np.r_[[t[0]] * 4, np.repeat(t[1:-1], 3), [t[-1]] * 4]
    return BSplineCurve(ctrl, knots, 3)


def _fit(P: FloatArray, t: FloatArray, mult: np.ndarray, periodic: bool) -> BSplineCurve:
    from scipy.interpolate import BSpline

    m, _, dim = P.shape
    s = np.array([0.0, 0.25, 0.5, 0.75])
    x = (t[:-1, None] + np.diff(t)[:, None] * s[None, :]).reshape(-1)
    y = _bezier_eval(P, s).reshape(-1, dim)
    if periodic:
        n = m
        full = BSplineCurve(np.zeros((n, dim)), t, 3, closed=True).knots
        A = BSpline.design_matrix(x, full, 3).toarray()
        A[:, :3] += A[:, n:]
        A = A[:, :n]
        c, *_ = np.linalg.lstsq(A, y, rcond=None)
        return BSplineCurve(c, full, 3, closed=True)
    x = np.r_[x, t[-1]]
    y = np.vstack([y, P[-1, 3]])
    knots = np.r_[[t[0]] * 4, np.repeat(t[1:-1], mult[: m - 1]), [t[-1]] * 4]
    A = BSpline.design_matrix(x, knots, 3).toarray()
    c, *_ = np.linalg.lstsq(A, y, rcond=None)
    c[0], c[-1] = P[0, 0], P[-1, 3]
    return BSplineCurve(c, knots, 3)


# ------------------------------------------------------------------------------------------
# read
# ------------------------------------------------------------------------------------------
def _xy(z: complex) -> tuple[float, float]:
    return (float(z.real), float(z.imag))


def _segments_to_cubics(seg: Any, spt: Any) -> FloatArray:
    out = []
    for g in seg:
        if isinstance(g, spt.CubicBezier):
            out.append([_xy(g.start), _xy(g.control1), _xy(g.control2), _xy(g.end)])
        elif isinstance(g, spt.QuadraticBezier):
            p0, p1, p2 = (np.array(_xy(v)) for v in (g.start, g.control, g.end))
            out.append([p0, p0 + 2 / 3 * (p1 - p0), p2 + 2 / 3 * (p1 - p2), p2])
        elif isinstance(g, spt.Line):
            p0, p1 = np.array(_xy(g.start)), np.array(_xy(g.end))
            out.append([p0, p0 + (p1 - p0) / 3, p0 + 2 * (p1 - p0) / 3, p1])
        else:
            raise Unsupported(f"{type(g).__name__} segment")
    return np.array(out, dtype=float)


def _path_elements(text: str, path: object) -> list[ET.Element]:
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        line = exc.position[0] if hasattr(exc, "position") else None
        raise FileFormatError(f"not well-formed XML ({exc})", path, line) from None
    if not (root.tag == "svg" or root.tag.endswith("}svg")):
        raise FileFormatError(f"the root element is <{root.tag}>, not <svg>", path)
    return [el for el in root.iter() if el.tag == "path" or str(el.tag).endswith("}path")]


def _read_text(path: object) -> str:
    try:
        with open(os.fspath(path), "rb") as f:  # type: ignore[arg-type]
            raw = f.read()
    except OSError as exc:
        raise FileFormatError(f"cannot read the file: {exc.strerror or exc}", path) from None
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise FileFormatError(f"not UTF-8 text ({exc.reason})", path) from None


def read(path: str | os.PathLike[str], *, corner_angle: float | None = 90.0,
         on_unsupported: str = "raise", **_: Any) -> list[CurveRecord]:
    """Read the curves of the ``<path>`` elements of an SVG file; see the module docstring."""
    spt = _svgpathtools("reading SVG files")
    text = _read_text(path)
    if not text.strip():
        raise FileFormatError("empty SVG file", path)
    elements = _path_elements(text, path)
    records: list[CurveRecord] = []
    apath = os.path.abspath(path)
    for k, el in enumerate(elements):
        d = el.get("d")
        if d is None or not d.strip():
            continue
        try:
            parsed = spt.parse_path(d)
        except Exception as exc:  # svgpathtools raises ValueError/IndexError on bad data
            raise FileFormatError(f"<path> element {k} (id={el.get('id')!r}): bad path data "
                                  f"({type(exc).__name__}: {exc})", path) from None
        subs = parsed.continuous_subpaths() if len(parsed) else []
        for j, sub in enumerate(subs):
            ident = el.get("id")
            name = f"{ident or 'path' + str(k)}" + (f"/{j}" if len(subs) > 1 else "")
            base = {"format": FORMAT, "path": apath, "element": k, "id": ident, "subpath": j,
                    "n_subpaths": len(subs), "transform": el.get("transform"),
                    "svg_closed": bool(sub.isclosed())}
            try:
                records.extend(_subpath_records(sub, spt, base, name, corner_angle, path,
                                                len(records)))
            except Unsupported as exc:
                msg = f"<path> element {k} (id={ident!r}) subpath {j}: unsupported {exc}"
                if on_unsupported == "raise":
                    raise FileFormatError(msg + " (read_curves(..., on_unsupported='skip') "
                                          "skips it)", path) from None
                warnings.warn(f"{os.fspath(path)}: skipped {msg}", UserWarning, stacklevel=3)
    return records


def _degenerate(g: Any, spt: Any) -> bool:
    """A segment that does not move (``L`` to the current point: matplotlib writes these)."""
    if isinstance(g, spt.Line):
        return bool(g.start == g.end)
    if isinstance(g, spt.CubicBezier):
        return bool(g.start == g.control1 == g.control2 == g.end)
    if isinstance(g, spt.QuadraticBezier):
        return bool(g.start == g.control == g.end)
    return False


def _subpath_records(sub: Any, spt: Any, base: dict[str, Any], name: str,
                     corner_angle: float | None, path: object, index: int
                     ) -> list[CurveRecord]:
    closed = bool(sub.isclosed())
    segs = [g for g in sub if not _degenerate(g, spt)]
    if not segs:
        return []
    sub = spt.Path(*segs)
    if all(isinstance(g, spt.Line) for g in sub):
        pts = np.array([_xy(g.start) for g in sub] + [_xy(sub[-1].end)], dtype=float)
        check_points(pts, path, None, what=f"<path> element {base['element']} vertex")
        distinct = pts[:-1] if closed else pts
        if closed and distinct.shape[0] < 3:
            distinct, closed = pts, False
        src = dict(base, row_map=tuple(range(distinct.shape[0])))
        return point_records(distinct, closed=closed, corner_angle=corner_angle,
                             kind="polyline", name=name, source=src, first_index=index)
    P = _segments_to_cubics(sub, spt)
    if not np.isfinite(P).all():
        raise FileFormatError(f"<path> element {base['element']}: non-finite coordinate", path)
    curve = bezier_chain_to_bspline(P, closed)
    src = dict(base, index=index, beziers=P.tolist())
    return [CurveRecord(curve, name, "bspline", src)]


# ------------------------------------------------------------------------------------------
# write
# ------------------------------------------------------------------------------------------
def _num(v: float, decimals: int | None) -> str:
    if decimals is not None:
        s = f"{v:.{decimals}f}"
        if "." in s:
            s = s.rstrip("0").rstrip(".")
    else:
        s = repr(float(v))
        if s.endswith(".0"):
            s = s[:-2]
    return "0" if s in ("-0", "") else s


def _pt(p: Any, decimals: int | None) -> str:
    return f"{_num(p[0], decimals)},{_num(p[1], decimals)}"


def _d_cubics(B: FloatArray, closed: bool, decimals: int | None) -> str:
    parts = [f"M {_pt(B[0, 0], decimals)}"]
    parts += [f"C {_pt(b[1], decimals)} {_pt(b[2], decimals)} {_pt(b[3], decimals)}"
              for b in B]
    if closed:
        parts.append("Z")
    return " ".join(parts)


def _d_points(pts: FloatArray, closed: bool, decimals: int | None) -> str:
    s = f"M {_pt(pts[0], decimals)} " + " ".join(f"L {_pt(p, decimals)}" for p in pts[1:])
    return s + (" Z" if closed else "")


def _d_original(sub: Any, spt: Any, decimals: int | None) -> str:
    """An unchanged subpath in absolute commands (arcs kept as arcs)."""
    out = [f"M {_pt(_xy(sub[0].start), decimals)}"]
    for g in sub:
        if isinstance(g, spt.Line):
            out.append(f"L {_pt(_xy(g.end), decimals)}")
        elif isinstance(g, spt.CubicBezier):
            out.append(f"C {_pt(_xy(g.control1), decimals)} {_pt(_xy(g.control2), decimals)} "
                       f"{_pt(_xy(g.end), decimals)}")
        elif isinstance(g, spt.QuadraticBezier):
            out.append(f"Q {_pt(_xy(g.control), decimals)} {_pt(_xy(g.end), decimals)}")
        else:
            out.append(f"A {_num(g.radius.real, decimals)},{_num(g.radius.imag, decimals)} "
                       f"{_num(g.rotation, decimals)} {int(bool(g.large_arc))},"
                       f"{int(bool(g.sweep))} {_pt(_xy(g.end), decimals)}")
    if sub.isclosed():
        out.append("Z")
    return " ".join(out)


def _record_d(recs: list[CurveRecord], decimals: int | None) -> tuple[str, bool]:
    """The d of one subpath from its record(s), and whether it changed."""
    r0 = recs[0]
    if r0.kind == "bspline":
        curve = r0.curve
        B = bezier_pieces(curve, "write_curves (SVG)", max_degree=3)
        orig = np.asarray(r0.source.get("beziers", []), dtype=float)
        scale = max(float(np.abs(orig).max()) if orig.size else 1.0, 1.0)
        if orig.shape == B.shape and np.abs(orig - B).max() <= 1e-12 * scale:
            return "", False
        return _d_cubics(B, bool(r0.source.get("svg_closed", curve.closed)), decimals), True
    n = int(r0.source["n_points"])
    dim = data_points(r0.curve, "write_curves (SVG)").shape[1]
    pts = piece_values(n, dim, recs, "write_curves (SVG)")
    orig = np.full_like(pts, np.nan)
    for r in recs:
        orig[np.asarray(r.source["indices"])] = np.asarray(r.points)
    if np.array_equal(orig, pts):
        return "", False
    return _d_points(pts, bool(r0.source.get("closed")), decimals), True


def write(path: str | os.PathLike[str], records: Sequence[CurveRecord], *,
          template: str | None = None, decimals: int | None = None, precision: str = "file",
          **_: Any) -> None:
    """Write an SVG file; see the module docstring.

    ``precision="exact"`` (with ``decimals=None``) writes the numbers of rewritten elements
    in the shortest form that reads back as exactly the value, instead of the element's own
    number of decimals.
    """
    spt = _svgpathtools("writing SVG files")
    ours = [r for r in records if template is not None and r.format == FORMAT
            and r.path is not None and os.path.abspath(r.path) == os.path.abspath(template)]
    others = [r for r in records if not any(r is o for o in ours)]
    if template is None:
        atomic_write(path, _fresh_svg(others, decimals))
        return
    text = _read_text(template)
    elements = _path_elements(text, template)
    tags = list(_PATH_TAG_RE.finditer(text))
    spans: list[tuple[int, int, str]] = []
    for mt in tags:
        md = _D_RE.search(mt.group(0))
        if md is None:
            spans.append((-1, -1, ""))
            continue
        # XML attribute-value normalisation: line breaks and tabs read as blanks
        value = html.unescape(re.sub(r"\r\n|[\r\n\t]", " ", md.group(3)))
        spans.append((mt.start() + md.start(3), mt.start() + md.end(3), value))
    if len(spans) != len(elements) or any(
            (el.get("d") or "") != (sp[2] if sp[0] >= 0 else "") for el, sp in
            zip(elements, spans, strict=False)):
        raise FileFormatError("cannot locate the <path> elements in the text of the template "
                              "for a write-back (comments or CDATA holding '<path'?)", template)
    by_el: dict[int, dict[int, list[CurveRecord]]] = {}
    for r in ours:
        by_el.setdefault(int(r.source["element"]), {}).setdefault(
            int(r.source["subpath"]), []).append(r)
    edits: list[tuple[int, int, str]] = []
    for k, subs in sorted(by_el.items()):
        parsed = spt.parse_path(elements[k].get("d"))
        originals = parsed.continuous_subpaths()
        pieces = []
        changed = False
        for j, sub in enumerate(originals):
            if j in subs:
                d, ch = _record_d(subs[j], decimals)
                changed |= ch
                pieces.append(d if ch else _d_original(sub, spt, None))
            else:
                pieces.append(_d_original(sub, spt, None))
        if changed and decimals is None and precision != "exact":
            # the precision of the element as it was: its largest number of decimals
            found = re.findall(r"\.(\d+)", elements[k].get("d") or "")
            dec = max((len(f) for f in found), default=None)
            if dec is not None:
                pieces = []
                for j, sub in enumerate(originals):
                    d, ch = _record_d(subs[j], dec) if j in subs else ("", False)
                    pieces.append(d if ch else _d_original(sub, spt, None))
        if changed:
            edits.append((spans[k][0], spans[k][1], html.escape(" ".join(pieces), quote=True)))
    for a, b, new in sorted(edits, reverse=True):
        text = text[:a] + new + text[b:]
    if others:
        extra = "".join(f'<path d="{_record_path_d(r, decimals)}" fill="none" stroke="black"/>\n'
                        for r in _join_foreign(others))
        close = text.rfind("</svg>")
        if close < 0:
            raise FileFormatError("no closing </svg> tag", template)
        text = text[:close] + extra + text[close:]
    atomic_write(path, text)


def _join_foreign(records: Sequence[CurveRecord]) -> list[CurveRecord]:
    groups: dict[Any, list[CurveRecord]] = {}
    for i, r in enumerate(records):
        key = (r.path, r.format, r.source.get("handle"), r.source.get("element"),
               r.source.get("subpath")) if "indices" in r.source else ("single", i)
        groups.setdefault(key, []).append(r)
    out = []
    for recs in groups.values():
        if len(recs) > 1 or "indices" in recs[0].source:
            pts = joined_points(recs, "write_curves (SVG)")
            from ._common import points_curve
            closed = bool(recs[0].source.get("closed"))
            out.append(recs[0].with_curve(points_curve(pts, closed)))
        else:
            out.append(recs[0])
    return out


def _record_path_d(r: CurveRecord, decimals: int | None) -> str:
    c = r.curve
    if r.kind in ("points", "airfoil", "polyline", "fit_points") and hasattr(c, "points"):
        pts = np.asarray(c.points)
        if pts.shape[1] != 2:
            raise InputError("write_curves (SVG): SVG holds 2-D curves, got dimension "
                             f"{pts.shape[1]}")
        return _d_points(pts[:-1] if c.closed else pts, c.closed, decimals)
    if c.dim != 2:
        raise InputError(f"write_curves (SVG): SVG holds 2-D curves, got dimension {c.dim}")
    return _d_cubics(bezier_pieces(c, "write_curves (SVG)", max_degree=3), c.closed, decimals)


def _fresh_svg(records: Sequence[CurveRecord], decimals: int | None) -> str:
    recs = _join_foreign(records)
    ds = [_record_path_d(r, decimals) for r in recs]
    lo = np.array([np.inf, np.inf])
    hi = -lo
    for r in recs:
        u = np.linspace(*r.curve.domain, 200)
        xy = r.curve(u)
        lo, hi = np.minimum(lo, xy.min(axis=0)), np.maximum(hi, xy.max(axis=0))
    pad = 0.05 * max(float((hi - lo).max()), 1e-9)
    vb = f"{_num(lo[0] - pad, 6)} {_num(lo[1] - pad, 6)} " \
         f"{_num(hi[0] - lo[0] + 2 * pad, 6)} {_num(hi[1] - lo[1] + 2 * pad, 6)}"
    body = "".join(
        f'  <path id="{html.escape(r.name or f"curve{i}", quote=True)}" d="{d}" '
        f'fill="none" stroke="black" stroke-width="{_num(pad / 10, 6)}"/>\n'
        for i, (r, d) in enumerate(zip(recs, ds, strict=True)))
    return ('<?xml version="1.0" encoding="UTF-8"?>\n'
            f'<svg xmlns="http://www.w3.org/2000/svg" viewBox="{vb}">\n{body}</svg>\n')
