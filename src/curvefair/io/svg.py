"""SVG shape elements through svgpathtools (``pip install 'curvefair[svg]'``).

Read
----
Every ``<path>``, ``<polygon>``, ``<polyline>``, ``<line>`` and ``<rect>`` element, in document
order and with any namespace prefix (``<svg:path>``); each path is split into its continuous
subpaths:

- subpaths of straight segments only, polygons, polylines, lines and rectangles (rounded ones
  are unsupported): **drawn shapes, not read** by default -- in a drawing a polygon's vertices
  are its design, not samples of a curve (over 37,000 vertices of such shapes in four public
  icon and test-suite collections, 7 of 6,527 shapes look like samples: docs/formats.md), so
  they are left exactly as drawn. ``polylines=True`` (CLI ``--polylines``) reads them as
  point lists, ``kind="polyline"``: the vertices (a path subpath is closed if it ends where it
  starts, a polygon and a rectangle are closed), split at corners like every point list (a
  rectangle's four vertices are always corners);
- subpaths of cubic Beziers (quadratic Beziers and straight segments among them are
  degree-elevated, exactly) -> ``kind="bspline"``: a cubic :class:`~curvefair.BSplineCurve`
  equal to the chain. The parameter width of each segment follows the tangent-length ratio at
  smooth joins, and each join gets a knot of multiplicity 1 (the chain is C2 there), 2 (C1) or
  3 (C0 -- a corner or a kink), so a chain exported from a C2 spline comes back as that
  spline; the result is checked to reproduce every segment to 1e-9 of the drawing size (else
  all joins get multiplicity 3, which is exact by construction). A closed chain is periodic
  when every join including the closing one is C2, otherwise an open curve from the start
  point round to it;
- subpaths with elliptical arcs, ``<circle>`` and ``<ellipse>``: unsupported
  (``on_unsupported``; skipped ones stay untouched in a write-back): an arc is not a
  polynomial curve, and an approximation would move it without the user asking.

Segments of length zero (an ``L`` to the current point, as matplotlib writes at the end of
closed lines) carry no geometry and are dropped; a subpath rewritten on write-back loses them.
So are segments no longer than rounding noise (256 ulps of the subpath's largest coordinate:
relative commands closed by ``z`` leave closing segments ~1e-15 long); the segments kept are
joined exactly, a closed subpath ending exactly at its start. Exactly repeated consecutive
vertices are dropped with a warning (written back with their twin's value), and so, with a
warning naming the element, are vertices equal to the one before up to rounding noise.

Coordinates are those of the document: the element's current transformation matrix (the
product of its own and its ancestors' ``transform`` attributes, SVG 1.1 sec. 7.5, parsed by
svgpathtools, and of the viewport transformation of each nested ``<svg>`` it is in, sec. 7.9)
is applied on read, and its inverse on write, so the file keeps every element's
own coordinates and ``transform`` attributes. ``source`` keys: ``element`` (index among the
curve elements), ``node`` (index among all elements), ``tag``, ``id``, ``subpath``,
``n_subpaths``, ``svg_closed`` (closed by a ``z``: a subpath that merely ends at its start is
read as a loop but written back open, without ``Z``), ``transform`` (the element's own
attribute), ``ctm`` (the 2x3 matrix row by row, or None for the identity), ``beziers`` (the
original segments of a bspline record, in document coordinates, to tell unchanged curves) and
the point-list keys, and ``polylines`` (the reading's ``polylines`` choice: the write-back's
check reads the file again the same way).

Write
-----
With ``template=`` the source bytes are copied and only the ``d`` attribute of the ``<path>``
elements whose curves changed (the ``points`` of a polygon/polyline, ``x1 y1 x2 y2`` of a
line; a changed ``<rect>`` is refused) is rewritten, at the byte offsets the XML parser
(expat) reports for the element, so text inside comments or CDATA is never edited
(the changed subpath's own text replaced by absolute ``M``/``L``/``C``/``Z`` commands in the
element's own coordinates; the text of every other subpath of the element kept verbatim,
except that a relative ``m`` right after a replaced subpath whose end point is not the
float it was counted from is written as the same absolute ``M``; everything else in the
file byte for byte). A
B-spline is written as its cubic Bezier pieces (one per knot span: the same number of
segments as read when the knots are unchanged). Without a template, a new SVG holding one
``<path>`` per curve (cubic curves only: degree <= 3). Numbers of a rewritten element get the
largest number of decimals the element had (its precision; an element of whole numbers gets
three, one with exponents the shortest exact form; ``decimals=`` overrides,
``precision="exact"`` writes the shortest exact representation instead; when the element's
precision puts a curve read back beyond the tolerance, the write-back tries three more decimals,
then exact numbers), numbers of a new file the shortest exact representation.
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
from ..errors import FileFormatError, InputError, MissingDependencyError
from ._common import (
    CurveRecord,
    DrawnShapesOnly,
    Unsupported,
    atomic_write,
    bezier_pieces,
    check_points,
    data_points,
    drop_duplicates,
    joined_points,
    lazy_import,
    piece_values,
    point_records,
    warn_drawn,
)

__all__ = ["read", "write", "bezier_chain_to_bspline"]

FORMAT = "svg"


def _svgpathtools(what: str) -> Any:
    return lazy_import("svgpathtools", "svgpathtools", "svg", what)


# ------------------------------------------------------------------------------------------
# Bezier chain -> B-spline
# ------------------------------------------------------------------------------------------
def _bezier_eval(P: FloatArray, s: FloatArray) -> FloatArray:
    """Points of every cubic segment ``P (m, 4, dim)`` at local parameters ``s (k,)``."""
    b = np.stack([(1 - s) ** 3, 3 * s * (1 - s) ** 2, 3 * s**2 * (1 - s), s**3], axis=1)
    return np.einsum("kj,mjd->mkd", b, P)


def join_turns(B: FloatArray, closed: bool | None = None) -> tuple[FloatArray, np.ndarray]:
    """The turn (radians) at each join of the Bezier chain ``B`` (m, 4, dim), the closing
    join included when ``closed`` (None: when the chain ends exactly at its start), and
    whether the join is smooth: both handles longer than 1e-12 of the chain's size, parallel
    to 1e-9, same direction -- where :func:`bezier_chain_to_bspline` makes the B-spline C1,
    and what the write-back check keeps smooth in the file. A handle of zero length is
    replaced by the next point of its segment (the tangent direction there) for the turn."""
    B = np.asarray(B, dtype=np.float64)
    m = B.shape[0]
    if closed is None:
        closed = bool(np.array_equal(B[-1, 3], B[0, 0]))
    i = np.arange(m if closed else m - 1)
    j = (i + 1) % m
    scale = max(float(np.abs(B).max()), 1.0)

    def direction(pts: FloatArray) -> tuple[FloatArray, FloatArray]:
        # pts[:, k]: the node, then the handles outward; the first one off the node
        v = pts[:, 1] - pts[:, 0]
        first = np.linalg.norm(v, axis=1)
        for k in (2, 3):
            short = np.linalg.norm(v, axis=1) <= 1e-12 * scale
            v[short] = pts[short, k] - pts[short, 0]
        return v, first

    a, na0 = direction(B[i][:, ::-1])      # incoming: P3 - P2 (sign reversed below)
    a = -a
    b, nb0 = direction(B[j])              # outgoing: Q1 - Q0
    na, nb = np.linalg.norm(a, axis=1), np.linalg.norm(b, axis=1)
    if B.shape[2] == 2:
        cross = np.abs(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])
    else:
        cross = np.linalg.norm(np.cross(a, b), axis=1)
    dot = np.einsum("ij,ij->i", a, b)
    turn = np.arctan2(cross, dot)
    smooth = ((na0 > 1e-12 * scale) & (nb0 > 1e-12 * scale)
              & (cross <= 1e-9 * na * nb) & (dot > 0))
    return turn, smooth


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
    _, smooth = join_turns(P, closed)
    for i in range(n_joins):
        j = (i + 1) % m
        g1 = bool(smooth[i])
        na = np.linalg.norm(P[i, 3] - P[i, 2])
        nb = np.linalg.norm(P[j, 1] - P[j, 0])
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
    periodic = closed and bool(np.all(mult == 1))
    try:
        cand = _fit(P, t, mult, periodic)
    except (ValueError, np.linalg.LinAlgError):
        return exact
    s = np.linspace(0.0, 1.0, 9)
    ref_pts = _bezier_eval(P, s).reshape(-1, dim)
    u = (t[:-1, None] + h[:, None] * s[None, :]).reshape(-1)
    if float(np.abs(cand(u) - ref_pts).max()) <= 1e-9 * scale:
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
    out: list[list[Any]] = []
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


_SHAPES = ("path", "polygon", "polyline", "rect", "circle", "ellipse", "line")
_NUM_LIST_RE = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")


def _local(tag: object) -> str:
    """Local name of an element tag: ``{ns}path``, ``svg:path`` and ``path`` are ``path``."""
    t = str(tag)
    return t.rsplit("}", 1)[-1].rsplit(":", 1)[-1]


def _root(text: str, path: object) -> ET.Element:
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        line = exc.position[0] if hasattr(exc, "position") else None
        raise FileFormatError(f"not well-formed XML ({exc})", path, line) from None
    if _local(root.tag) != "svg":
        raise FileFormatError(f"the root element is <{root.tag}>, not <svg>", path)
    return root


# CSS absolute units in user units (px), CSS Values 3 sec. 5.2: 96 px to the inch
_UNITS = {"": 1.0, "px": 1.0, "in": 96.0, "cm": 96.0 / 2.54, "mm": 96.0 / 25.4,
          "q": 96.0 / 101.6, "pt": 96.0 / 72.0, "pc": 16.0}
_LENGTH_RE = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([a-zA-Z]*|%)\s*$")


def _viewport_length(el: ET.Element, name: str, default: str, ref: float | None) -> float:
    """The length attribute ``name`` of a nested ``<svg>`` in its parent's user units
    (percentages of ``ref``, the parent viewport's width or height); Unsupported when it
    cannot be resolved (font-relative units, a percentage of an unknown viewport)."""
    v = el.get(name)
    v = default if v is None or not v.strip() else v
    m = _LENGTH_RE.match(v)
    unit = m.group(2).lower() if m else None
    if m is None or (unit != "%" and unit not in _UNITS) or (unit == "%" and ref is None):
        raise Unsupported(f"nested <svg> with {name}={v!r}, which curvefair cannot convert to "
                          "the document's units")
    x = float(m.group(1))
    if unit == "%":
        assert ref is not None
        return x / 100.0 * ref
    return x * _UNITS[str(unit)]


def _viewbox(el: ET.Element) -> tuple[float, float, float, float] | None:
    vb = el.get("viewBox")
    if vb is None or not vb.strip():
        return None
    try:
        x, y, w, h = (float(t) for t in vb.replace(",", " ").split())
    except ValueError:
        raise Unsupported(f"<svg> with viewBox={vb!r} (not four numbers)") from None
    return x, y, w, h


def _nested_viewport(el: ET.Element, size: tuple[float, float] | None
                     ) -> tuple[np.ndarray, tuple[float, float] | None]:
    """The matrix from a nested ``<svg>``'s user units to its parent's (its ``x``, ``y``,
    ``width``, ``height``, ``viewBox`` and ``preserveAspectRatio``, SVG 1.1 sec. 7.7-7.9) and
    the size of the viewport it gives its children (for their percentages)."""
    vw, vh = (None, None) if size is None else size
    x = _viewport_length(el, "x", "0", vw)
    y = _viewport_length(el, "y", "0", vh)
    vb = _viewbox(el)
    if vb is None:
        try:
            inner = (_viewport_length(el, "width", "100%", vw),
                     _viewport_length(el, "height", "100%", vh))
        except Unsupported:
            inner = None                  # only the children's percentages need it
        return np.array([[1.0, 0.0, x], [0.0, 1.0, y], [0.0, 0.0, 1.0]]), inner
    w = _viewport_length(el, "width", "100%", vw)
    h = _viewport_length(el, "height", "100%", vh)
    bx, by, bw, bh = vb
    if not (w > 0 and h > 0 and bw > 0 and bh > 0):
        raise Unsupported(f"nested <svg> with an empty viewport or viewBox (width={w}, "
                          f"height={h}, viewBox={el.get('viewBox')!r}: not rendered)")
    par = (el.get("preserveAspectRatio") or "xMidYMid meet").split()
    if par and par[0] == "defer":
        par = par[1:]
    align = par[0] if par else "xMidYMid"
    sx, sy = w / bw, h / bh
    tx, ty = x, y
    if align != "none":
        sx = sy = max(sx, sy) if len(par) > 1 and par[1] == "slice" else min(sx, sy)
        fx = 0.5 if "xMid" in align else 1.0 if "xMax" in align else 0.0
        fy = 0.5 if "YMid" in align else 1.0 if "YMax" in align else 0.0
        tx += fx * (w - bw * sx)
        ty += fy * (h - bh * sy)
    m = np.array([[sx, 0.0, tx - bx * sx], [0.0, sy, ty - by * sy], [0.0, 0.0, 1.0]])
    return m, (bw, bh)


def _root_viewport(root: ET.Element) -> tuple[float, float] | None:
    """The size of the root's viewport in its user units (what a nested ``<svg>``'s
    percentages refer to): its viewBox's, else its plain width and height, else unknown."""
    try:
        vb = _viewbox(root)
        if vb is not None:
            return vb[2], vb[3]
        return (_viewport_length(root, "width", "", None),
                _viewport_length(root, "height", "", None))
    except Unsupported:
        return None


def _shape_elements(root: ET.Element, spt: Any, path: object
                    ) -> list[tuple[int, ET.Element, np.ndarray | None, str | None]]:
    """(index in document order among all elements, element, 2x3 affine matrix or None, why
    not) of every curve element, the matrix being the product of the ``transform`` attributes
    of the element and its ancestors (its current transformation matrix, SVG 1.1 sec. 7.5)
    and of the viewport transformations of the nested ``<svg>`` elements it is in (their
    ``x``, ``y`` and ``viewBox``, sec. 7.9), so that curves are in the root's user units;
    "why not" is the reason an element's matrix is unknown (a nested ``<svg>`` whose
    viewport curvefair cannot resolve), else None."""
    out: list[tuple[int, ET.Element, np.ndarray | None, str | None]] = []
    count = 0

    before: dict[int, np.ndarray] = {}      # id(element): its parent's matrix
    after: dict[int, np.ndarray] = {}       # id(element): its own (children's) matrix
    sizes: dict[int, tuple[float, float] | None] = {}
    below: dict[int, list[int]] = {}        # id(element): positions in out of its shapes

    def visit(el: ET.Element, ctm: np.ndarray, size: tuple[float, float] | None,
              why: str | None, chain: tuple[int, ...]
              ) -> tuple[np.ndarray, tuple[float, float] | None, str | None, tuple[int, ...]]:
        """One element; what its children inherit."""
        nonlocal count
        k = count
        count += 1
        before[id(el)] = ctm
        sizes[id(el)] = size
        chain = (*chain, id(el))
        tf = el.get("transform")
        if tf is not None and tf.strip():
            with warnings.catch_warnings():
                warnings.simplefilter("error")
                try:
                    m = np.asarray(spt.parser.parse_transform(tf), dtype=float)
                except Exception as exc:  # SVGSyntaxWarning, ValueError
                    raise FileFormatError(f"<{_local(el.tag)}> element (id={el.get('id')!r}): "
                                          f"bad transform {tf!r} ({exc})", path) from None
            ctm = ctm @ m
        if why is None and _CSS_TRANSFORM_RE.search(el.get("style") or ""):
            # CSS transform property (SVG 2; browsers apply it): not parsed here, so the
            # element's drawn size is unknown
            why = (f"<{_local(el.tag)}> (id={el.get('id')!r}) with a CSS transform in its "
                   "style attribute, which curvefair does not read")
        if why is None:
            why = _own_units(el)
        if el is not root and _local(el.tag) == "svg" and why is None:
            try:
                m, size = _nested_viewport(el, size)
                ctm = ctm @ m
            except Unsupported as exc:
                why = str(exc)
        after[id(el)] = ctm
        if _local(el.tag) in _SHAPES:
            ident = np.allclose(ctm, np.eye(3), rtol=0, atol=0)
            for a in chain:
                below.setdefault(a, []).append(len(out))
            out.append((k, el, None if ident else ctm[:2].copy(), why))
        return ctm, size, why, chain

    # depth first in document order, with a stack of its own: a file may nest its groups
    # deeper than Python's recursion limit (librsvg's fuzz file: 2,000 nested <g>)
    stack: list[tuple[ET.Element, Any]] = [(root, (np.eye(3), _root_viewport(root),
                                                   _sheet_transform(root), ()))]
    while stack:
        el, inherited = stack.pop()
        mine = visit(el, *inherited)
        stack.extend((child, mine) for child in reversed(list(el)))
    _drawn_by_use(root, out, before, after, sizes, below)
    return out


_SHEET_TRANSFORM_RE = re.compile(r"(?:^|[{;\s])transform\s*:\s*(?!none\s*(?:;|}|!|$))[^;}\s]",
                                 re.I)


def _sheet_transform(root: ET.Element) -> str | None:
    """Why no element's drawn size is known when a ``<style>`` sheet sets a CSS ``transform``
    (SVG 2: browsers apply it to whatever its selectors match; curvefair does not evaluate
    selectors), else None. Every curve element of such a document is then unsupported: left
    as it is, rather than faired in units that may not be the drawing's."""
    for el in root.iter():
        if _local(el.tag) != "style":
            continue
        text = "".join(el.itertext())
        text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)  # CSS comments
        if _SHEET_TRANSFORM_RE.search(text):
            return ("a <style> sheet that sets a CSS transform (curvefair does not evaluate "
                    "its selectors, so no element's drawn size is known)")
    return None


def _own_units(el: ET.Element) -> str | None:
    """Why the content of ``el`` is drawn in a coordinate system of its own, not the one of
    its ancestors (SVG 1.1 sec. 11.6, 14.3.5, 14.4, 13.3), else None: a ``<marker>`` (scaled
    by the stroke width and its viewBox), a ``<clipPath>``/``<mask>``/``<pattern>`` whose
    content is in ``objectBoundingBox`` units (0..1 of the box of the element using it), a
    ``<pattern>`` with a viewBox or a ``patternTransform``."""
    tag = _local(el.tag)
    ident = el.get("id")
    if tag == "marker":
        return f"<marker> (id={ident!r}), drawn scaled by the stroke it marks"
    units = {"clipPath": "clipPathUnits", "mask": "maskContentUnits",
             "pattern": "patternContentUnits"}.get(tag)
    if units is not None and (el.get(units) or "").strip() == "objectBoundingBox":
        return (f"<{tag}> (id={ident!r}) with {units}='objectBoundingBox' (drawn scaled to "
                "the box of the element using it)")
    if tag == "pattern" and (el.get("viewBox") or el.get("patternTransform")):
        return f"<pattern> (id={ident!r}) with its own viewBox or patternTransform"
    return None


_XLINK_HREF = "{http://www.w3.org/1999/xlink}href"
_CSS_TRANSFORM_RE = re.compile(r"(?:^|;)\s*transform\s*:\s*(?!none\s*(?:;|$|!))[^;\s]", re.I)


def _drawn_by_use(root: ET.Element,
                  out: list[tuple[int, ET.Element, np.ndarray | None, str | None]],
                  before: dict[int, np.ndarray], after: dict[int, np.ndarray],
                  sizes: dict[int, tuple[float, float] | None],
                  below: dict[int, list[int]]) -> None:
    """Mark (in ``out``, in place) the curve elements a ``<use>`` draws larger than curvefair
    reads them: a ``<use>`` draws its target (and everything in it) through its own matrix,
    its ``x``/``y`` and, for a ``<symbol>``, the symbol's viewport (SVG 1.1 sec. 5.6), not
    through the target's ancestors. A move of ``tol`` in the element's document coordinates
    is a move of at most ``s tol`` in that copy, ``s`` the largest singular value of the
    linear map between the two; where ``s > 1`` the tolerance would not hold in the drawing,
    and the element is unsupported (a copy drawn at the same size or smaller is fine)."""
    ids = {el.get("id"): el for el in root.iter() if el.get("id")}
    worst: dict[int, tuple[float, str]] = {}
    for use in root.iter():
        if _local(use.tag) != "use":
            continue
        href = (use.get("href") or use.get(_XLINK_HREF) or "").strip()
        target = ids.get(href[1:]) if href.startswith("#") else None
        if target is None or id(target) not in below or id(use) not in after:
            continue
        lin = after[id(use)][:2, :2]
        what = f"drawn by <use> (id={use.get('id')!r}, href={href!r})"
        try:
            if _local(target.tag) == "symbol":
                # the symbol's viewport: the <use>'s width/height (default 100%) on the
                # symbol's viewBox and preserveAspectRatio
                vp = ET.Element("svg", {k: v for k, v in (
                    ("viewBox", target.get("viewBox")),
                    ("preserveAspectRatio", target.get("preserveAspectRatio")),
                    ("width", use.get("width")), ("height", use.get("height")))
                    if v is not None})
                m, _ = _nested_viewport(vp, sizes.get(id(use)))
                lin = lin @ m[:2, :2]
            rel = lin @ np.linalg.inv(before[id(target)][:2, :2])
            scale = float(np.linalg.svd(rel, compute_uv=False)[0])
        except (Unsupported, np.linalg.LinAlgError) as exc:
            scale, what = float("inf"), f"{what}, at a size curvefair cannot tell ({exc})"
        if not scale <= 1.0 + 1e-9:
            for pos in below[id(target)]:
                if scale > worst.get(pos, (0.0, ""))[0]:
                    worst[pos] = (scale, what)
    for pos, (scale, what) in worst.items():
        k, el, ctm, why = out[pos]
        if why is None:
            size = f" {scale:.6g} times larger" if scale < float("inf") else ""
            why = (f"{what}{size} than it is read: a fairing within --tol would not be "
                   "within it there")
            out[pos] = (k, el, ctm, why)


def _path_elements(text: str, path: object) -> list[ET.Element]:
    """The ``<path>`` elements of an SVG text in document order (any namespace prefix)."""
    root = _root(text, path)
    return [el for el in root.iter() if _local(el.tag) == "path"]


def _read_text(path: str | os.PathLike[str]) -> str:
    try:
        with open(os.fspath(path), "rb") as f:
            raw = f.read()
    except OSError as exc:
        raise FileFormatError(f"cannot read the file: {exc.strerror or exc}", path) from None
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise FileFormatError(f"not UTF-8 text ({exc.reason})", path) from None


def _apply(m: np.ndarray | None, xy: FloatArray) -> FloatArray:
    """Points (..., 2) mapped by the affine matrix ``m`` (2x3), or unchanged when None."""
    if m is None:
        return xy
    return xy @ m[:, :2].T + m[:, 2]


def _unapply(m: np.ndarray | None, xy: FloatArray) -> FloatArray:
    """Points (..., 2) mapped back by the inverse of ``m`` (document -> element coords)."""
    if m is None:
        return xy
    return np.linalg.solve(m[:, :2], (xy - m[:, 2]).reshape(-1, 2).T).T.reshape(xy.shape)


def _points_attr(el: ET.Element, what: str, path: object) -> FloatArray:
    """The ``points`` of a ``<polygon>``/``<polyline>`` (SVG 1.1 sec. 9.7: numbers separated
    by blanks and/or one comma; an odd count drops the last, as browsers do, with an error
    here instead)."""
    raw = el.get("points") or ""
    nums = _NUM_LIST_RE.findall(raw)
    rest = _NUM_LIST_RE.sub(" ", raw).replace(",", " ").strip()
    if rest:
        raise FileFormatError(f"{what}: bad points attribute (unexpected {rest[:20]!r})", path)
    if len(nums) % 2:
        raise FileFormatError(f"{what}: odd number of coordinates in points", path)
    return np.asarray([float(v) for v in nums], dtype=float).reshape(-1, 2)


def _length(el: ET.Element, name: str, what: str, path: object) -> float:
    v = (el.get(name) or "0").strip()
    try:
        return float(v)
    except ValueError:
        raise Unsupported(f"{name}={v!r} (only plain user units are read)") from None


def read(path: str | os.PathLike[str], *, corner_angle: float | None = 60.0,
         on_unsupported: str = "raise", polylines: bool = False,
         **_: Any) -> list[CurveRecord]:
    """Read the curves of the shape elements of an SVG file; see the module docstring.

    ``polylines=False`` leaves straight-line shapes as drawn (no records); a file holding
    nothing else raises :class:`~curvefair.FileFormatError` saying how many there are and how
    to read them."""
    spt = _svgpathtools("reading SVG files")
    drawn = 0
    text = _read_text(path)
    if not text.strip():
        raise FileFormatError("empty SVG file", path)
    root = _root(text, path)
    records: list[CurveRecord] = []
    apath = os.path.abspath(path)

    def skip(msg: str) -> None:
        if on_unsupported == "raise":
            raise FileFormatError(msg + " (read_curves(..., on_unsupported='skip') skips it)",
                                  path) from None
        warnings.warn(f"{os.fspath(path)}: skipped {msg}; kept untouched", UserWarning,
                      stacklevel=4)

    k = -1
    for node, el, ctm, why in _shape_elements(root, spt, path):
        tag = _local(el.tag)
        ident = el.get("id")
        base = {"format": FORMAT, "path": apath, "id": ident, "tag": tag, "node": node,
                "polylines": bool(polylines),
                "transform": el.get("transform"),
                "ctm": None if ctm is None else tuple(float(v) for v in ctm.reshape(-1))}
        what = f"<{tag}> element (id={ident!r})"
        if tag in ("circle", "ellipse"):
            skip(f"{what}: unsupported <{tag}> (elliptical arcs are not polynomial curves)")
            continue
        k += 1
        base["element"] = k
        if why is not None:
            skip(f"{what}: unsupported: "
                 f"{why if why.startswith('drawn') else 'in a ' + why}")
            continue
        if tag in ("polygon", "polyline", "line", "rect"):
            if not polylines:
                drawn += 1
                continue
            try:
                pts, closed = _shape_points(el, tag, what, path)
            except Unsupported as exc:
                skip(f"{what}: unsupported {exc}")
                continue
            if pts.shape[0] < 2:
                continue
            pts = _apply(ctm, pts)
            name = ident or f"{tag}{k}"
            base.update(subpath=0, n_subpaths=1, svg_closed=closed)
            # a rectangle's four vertices are corners whatever their angle (skewed or drawn
            # through a shear, or a --corner-angle above 90): it is written back only
            # unchanged, so nothing of it may move
            try:
                records.extend(_polyline_records(pts, closed, base, name,
                                                 0.0 if tag == "rect" else corner_angle, path,
                                                 len(records)))
            except Unsupported as exc:
                skip(f"{what}: unsupported {exc}")
            continue
        d = el.get("d")
        if d is None or not d.strip():
            continue
        try:
            parsed = spt.parse_path(d)
        except Exception as exc:  # svgpathtools raises ValueError/IndexError on bad data
            raise FileFormatError(f"<path> element {k} (id={ident!r}): bad path data "
                                  f"({type(exc).__name__}: {exc})", path) from None
        subs, zs = _subpaths(d, parsed, spt)
        for j, sub in enumerate(subs):
            name = f"{ident or 'path' + str(k)}" + (f"/{j}" if len(subs) > 1 else "")
            sbase = dict(base, subpath=j, n_subpaths=len(subs), svg_closed=zs[j])
            if not polylines and _lines_only(sub, spt):
                drawn += 1
                continue
            try:
                records.extend(_subpath_records(sub, spt, sbase, name, corner_angle, path,
                                                len(records), ctm))
            except Unsupported as exc:
                skip(f"<path> element {k} (id={ident!r}) subpath {j}: unsupported {exc}")
            except (FileFormatError, MissingDependencyError):
                raise
            except ValueError as exc:   # e.g. a knot vector refused: name the file and element
                raise FileFormatError(f"<path> element {k} (id={ident!r}) subpath {j}: {exc}",
                                      path) from None
    if not records and drawn:
        raise DrawnShapesOnly(drawn, path, FORMAT)
    warn_drawn(path, drawn, FORMAT)
    return records


def _kept_segments(sub: Any, spt: Any) -> list[Any]:
    """The segments of a subpath without the degenerate ones (length zero, or no longer than
    rounding noise: relative commands closed by ``z`` leave closing segments ~1e-15 long)."""
    tiny = _rounding_level([c for g in sub if not isinstance(g, spt.Arc)
                            for z in (g.start, g.end) for c in (z.real, z.imag)])
    return [g for g in sub if not _degenerate(g, spt, tiny)]


def _lines_only(sub: Any, spt: Any) -> bool:
    """A subpath of straight segments only, once the degenerate ones are dropped (what
    :func:`_subpath_records` reads as a point list)."""
    segs = _kept_segments(sub, spt)
    return bool(segs) and all(isinstance(g, spt.Line) for g in segs)


def _shape_points(el: ET.Element, tag: str, what: str, path: object
                  ) -> tuple[FloatArray, bool]:
    """Vertices (in element coordinates) and closedness of a polygon, polyline, line or rect."""
    if tag in ("polygon", "polyline"):
        return _points_attr(el, what, path), tag == "polygon"
    if tag == "line":
        xy = [_length(el, n, what, path) for n in ("x1", "y1", "x2", "y2")]
        return np.asarray(xy, dtype=float).reshape(2, 2), False
    x, y, w, h = (_length(el, n, what, path) for n in ("x", "y", "width", "height"))
    if el.get("rx") not in (None, "0") or el.get("ry") not in (None, "0"):
        raise Unsupported("<rect> with rounded corners (elliptical arcs)")
    if not (w > 0 and h > 0):
        return np.zeros((0, 2)), True          # not rendered (SVG 1.1 sec. 9.2)
    return np.array([[x, y], [x + w, y], [x + w, y + h], [x, y + h]], dtype=float), True


def _polyline_records(pts: FloatArray, closed: bool, base: dict[str, Any], name: str,
                      corner_angle: float | None, path: object, index: int
                      ) -> list[CurveRecord]:
    """Records of a vertex list (polyline subpath, polygon, polyline, line, rect): exact
    repeats dropped (written back with their twin), a closed list not repeating its start."""
    what = f"<{base['tag']}> element {base['element']} vertex"
    tiny = _rounding_level(pts)
    if closed and pts.shape[0] > 1 and np.abs(pts[0] - pts[-1]).max() <= tiny:
        pts = pts[:-1]
    label = f"<{base['tag']}> element {base['element']} (id={base.get('id')!r}) vertex"
    kept, where = drop_duplicates(pts, path, None, what=label, tiny=tiny)
    if closed and kept.shape[0] > 1 and np.abs(kept[0] - kept[-1]).max() <= tiny:
        kept = kept[:-1]
        where = np.where(where == kept.shape[0], 0, where)
    check_points(kept, path, None, what=what)
    if closed and kept.shape[0] < 3:
        closed = False
    if kept.shape[0] < 2:
        return []
    src = dict(base, row_map=tuple(int(i) for i in where), n_vertices=int(pts.shape[0]))
    return point_records(kept, closed=closed, corner_angle=corner_angle, kind="polyline",
                         name=name, source=src, first_index=index)


# A segment or vertex step no longer than this many units in the last place of the
# coordinates' magnitude is rounding noise (relative commands summed in floating point leave
# a closing ``z`` segment of ~1e-15), not geometry: it is treated as length zero.
_ROUNDING_ULPS = 256


def _rounding_level(xy: Any) -> float:
    """The length below which a step between the points ``xy`` is rounding noise."""
    a = np.abs(np.asarray(xy, dtype=float))
    a = a[np.isfinite(a)]
    return _ROUNDING_ULPS * float(np.finfo(float).eps) * (float(a.max()) if a.size else 0.0)


def _degenerate(g: Any, spt: Any, tiny: float = 0.0) -> bool:
    """A segment that does not move (``L`` to the current point: matplotlib writes these),
    or moves no farther than ``tiny`` (rounding noise)."""
    pts: tuple[Any, ...]
    if isinstance(g, spt.Line):
        pts = (g.start, g.end)
    elif isinstance(g, spt.CubicBezier):
        pts = (g.start, g.control1, g.control2, g.end)
    elif isinstance(g, spt.QuadraticBezier):
        pts = (g.start, g.control, g.end)
    else:
        return False
    if all(z == g.start for z in pts):
        return True
    return bool(all(max(abs(z.real - g.start.real), abs(z.imag - g.start.imag)) <= tiny
                    for z in pts))


def _subpath_records(sub: Any, spt: Any, base: dict[str, Any], name: str,
                     corner_angle: float | None, path: object, index: int,
                     ctm: np.ndarray | None = None) -> list[CurveRecord]:
    closed = bool(sub.isclosed())
    # segments no longer than rounding noise are dropped like zero-length ones; the
    # segments kept are joined exactly (a dropped one's gap closed) and a closed subpath
    # ends exactly at its start
    segs = _kept_segments(sub, spt)
    if not segs:
        return []
    sub = spt.Path(*segs)
    if all(isinstance(g, spt.Line) for g in sub):
        pts = np.array([_xy(g.start) for g in sub] + [_xy(sub[-1].end)], dtype=float)
        if not np.isfinite(pts).all():
            raise FileFormatError(f"<path> element {base['element']}: non-finite coordinate",
                                  path)
        if closed:
            pts[-1] = pts[0]
        return _polyline_records(_apply(ctm, pts), closed, base, name, corner_angle, path,
                                 index)
    P = _segments_to_cubics(sub, spt)
    if not np.isfinite(P).all():
        raise FileFormatError(f"<path> element {base['element']}: non-finite coordinate", path)
    P[1:, 0] = P[:-1, 3]
    if closed:
        P[-1, 3] = P[0, 0]
    P = _apply(ctm, P)
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


def _straight(B: FloatArray) -> np.ndarray:
    """Which segments of the Bezier chain ``B`` (m, 4, dim) are straight lines drawn evenly:
    handles at the thirds of the chord to 1e-9 of the chain's size -- what the reader makes
    of an ``L``, ``H`` or ``V`` (degree elevation), and what a faired curve keeps of such a
    segment that it did not bend. They are written back as ``L``: exactly straight in the
    file, where two handles rounded to the element's decimals would bend the line (by a
    rounding-level amount, but with curvature of alternating sign: inflections a curvature
    plot shows)."""
    B = np.asarray(B, dtype=np.float64)
    if B.size == 0:
        return np.zeros(0, dtype=bool)
    scale = max(float(np.abs(B).max()), 1.0)
    h1 = (2.0 * B[:, 0] + B[:, 3]) / 3.0
    h2 = (B[:, 0] + 2.0 * B[:, 3]) / 3.0
    err = np.maximum(np.abs(B[:, 1] - h1).max(axis=1), np.abs(B[:, 2] - h2).max(axis=1))
    return np.asarray(err <= 1e-9 * scale)


def _d_cubics(B: FloatArray, closed: bool, decimals: int | None,
              lines: np.ndarray | None = None) -> str:
    """A subpath of cubic segments, ``lines[i]`` (:func:`_straight`) written as ``L``."""
    parts = [f"M {_pt(B[0, 0], decimals)}"]
    parts += [f"L {_pt(b[3], decimals)}" if lines is not None and lines[i] else
              f"C {_pt(b[1], decimals)} {_pt(b[2], decimals)} {_pt(b[3], decimals)}"
              for i, b in enumerate(B)]
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


_MOVETO_RE = re.compile(r"[Mm]")
_CLOSE_RE = re.compile(r"[Zz]")
_NUM_RE = re.compile(r"[-+]?[0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?")


def _split_subpaths(d: str, parsed: Any, spt: Any
                    ) -> list[tuple[int, int, complex, complex, list[Any]]] | None:
    """The subpaths of ``d`` as curvefair reads them: ``(start, end, current point before,
    current point after, segments)`` with ``d[start:end]`` a subpath's commands (trailing
    blanks excluded), or None when the text does not split so (then the callers fall back on
    svgpathtools' ``continuous_subpaths`` of ``parsed``, and the writer re-renders).

    The text is cut before every moveto (``M``/``m``: SVG 1.1 sec. 8.3.3) and after every
    closepath (``z``/``Z``) that another command follows: that command starts a new subpath at
    the closed one's initial point (sec. 8.3.3), which svgpathtools joins to the closed one as
    one continuous subpath (a loop then lost its ``Z`` and the closing line became a cubic on
    write-back). Each piece is parsed by svgpathtools from the current point the previous
    pieces leave (a relative ``m`` is relative to it); the pieces must give exactly the
    segments of the whole path. A piece whose segments join the previous piece's continuously
    (an ``m 0,0``) belongs to the same subpath, unless the previous one was closed."""
    cuts = [m.start() for m in _MOVETO_RE.finditer(d)]
    if not cuts or d[:cuts[0]].strip():
        return None
    after_z = {m.end() for m in _CLOSE_RE.finditer(d)
               if d[m.end():].lstrip(" \t\r\n,")[:1] not in ("", "M", "m")}
    cuts = sorted(set(cuts) | after_z)
    cuts.append(len(d))
    groups: list[tuple[int, int, complex, complex, list[Any]]] = []
    cp = 0j
    for a, b in zip(cuts[:-1], cuts[1:], strict=True):
        try:
            segs = list(spt.parse_path(d[a:b], current_pos=cp))
        except Exception:  # noqa: BLE001 - svgpathtools raises several kinds; re-render
            return None
        if not segs:
            return None
        end = a + len(d[a:b].rstrip())
        groups.append((a, end, cp, segs[-1].end, segs))
        cp = segs[-1].end
    flat = [g for grp in groups for g in grp[4]]
    if len(flat) != len(parsed) or any(x != y for x, y in zip(flat, parsed, strict=True)):
        return None
    out: list[tuple[int, int, complex, complex, list[Any]]] = []
    for a, b, before, after, segs in groups:
        if (out and segs[0].start == out[-1][3]       # continuous: same subpath,
                and d[out[-1][0]:out[-1][1]][-1:] not in ("z", "Z")):  # unless closed
            out[-1] = (out[-1][0], b, out[-1][2], after, out[-1][4] + segs)
        else:
            out.append((a, b, before, after, segs))
    return out


def _subpath_spans(d: str, parsed: Any, spt: Any
                   ) -> list[tuple[int, int, complex, complex]] | None:
    """``(start, end, current point before, current point after)`` of each subpath of
    :func:`_split_subpaths`, or None."""
    split = _split_subpaths(d, parsed, spt)
    return None if split is None else [g[:4] for g in split]


def _subpaths(d: str, parsed: Any, spt: Any) -> tuple[list[Any], list[bool]]:
    """The subpaths of a ``<path>`` as svgpathtools ``Path`` objects, cut as in
    :func:`_split_subpaths` (svgpathtools' continuous subpaths when the text does not split),
    and for each whether a closepath closed it: it ends where it starts and its text ends
    with ``z``/``Z``. An open subpath that merely ends at its start point is drawn with two
    caps, not a join, and is written back without ``Z``; when the text does not split, a
    subpath ending at its start counts as closed."""
    if not len(parsed):
        return [], []
    split = _split_subpaths(d, parsed, spt)
    if split is None:
        subs = list(parsed.continuous_subpaths())
        return subs, [bool(sub.isclosed()) for sub in subs]
    subs = [spt.Path(*g[4]) for g in split]
    return subs, [bool(sub.isclosed()) and d[a:b][-1:] in ("z", "Z")
                  for sub, (a, b, _, _, _) in zip(subs, split, strict=True)]


def _splice_subpaths(d: str, parsed: Any, new: dict[int, str], spt: Any) -> str | None:
    """``d`` with the text of subpath ``j`` replaced by ``new[j]`` and every other subpath's
    text kept as it was, or None when ``d`` cannot be split into its subpaths.

    A subpath that follows a replaced one and starts with a relative ``m`` is relative to
    the current point the replaced one leaves; when that point changed, its moveto is
    written absolute (``M x,y``, then ``l`` for implicit coordinate pairs after it, SVG 1.1
    sec. 8.3.2), the rest of its text unchanged. One that starts with a drawing command
    after a closepath starts at the closed subpath's initial point: when the replaced text
    moved that point, ``M x,y`` with the point as it was is written before it."""
    spans = _subpath_spans(d, parsed, spt)
    if spans is None:
        return None
    out: list[str] = []
    pos = 0
    moved = False
    for j, (a, b, before, after) in enumerate(spans):
        out.append(d[pos:a])
        if j in new:
            kept = d[a:b]
            out.append(kept[:len(kept) - len(kept.lstrip())] + new[j])  # its leading blanks
            try:
                segs = list(spt.parse_path(new[j]))
            except Exception:  # noqa: BLE001
                return None
            moved = not segs or segs[-1].end != after
        else:
            text = d[a:b]
            if moved and text[0] not in "Mm":
                # drawn from the initial point of the closed subpath before it (a command
                # after a closepath), which the replaced text moved: start it where it was
                body = text.lstrip()
                text = (text[:len(text) - len(body)] or " ") + \
                    f"M {_num(before.real, None)},{_num(before.imag, None)} {body}"
            elif moved and text[0] == "m":
                start = _subpath_start(text, before, spt)
                if start is None:
                    return None
                nums = list(_NUM_RE.finditer(text, 1))
                if len(nums) < 2:
                    return None
                rest = text[nums[1].end():]
                head = f"M {_num(start.real, None)},{_num(start.imag, None)}"
                if _NUM_RE.match(rest.lstrip(" \t\r\n,")):
                    head += " l"
                text = head + rest
            out.append(text)
            moved = False
        pos = b
    out.append(d[pos:])
    return "".join(out)


def _subpath_start(text: str, before: complex, spt: Any) -> complex | None:
    try:
        segs = list(spt.parse_path(text, current_pos=before))
    except Exception:  # noqa: BLE001
        return None
    return segs[0].start if segs else None


def _ctm(src: Any) -> np.ndarray | None:
    m = src.get("ctm")
    return None if m is None else np.asarray(m, dtype=float).reshape(2, 3)


def _toward(geo: FloatArray, orig: FloatArray, decimals: int | None) -> FloatArray | None:
    """``geo`` with every coordinate rounded to ``decimals`` TOWARD its value in ``orig`` (the
    element's numbers as read, on that grid): no coordinate moves farther from the input than
    faired, so a node, handle or vertex rounded for the file stays within the tolerance the
    fairing held it to (rounded to nearest, a point moved by nearly ``tol`` ended up to half a
    unit of the last decimal farther, e.g. 0.14 at tol 0.1 on a one-decimal icon). None when
    that rounding undoes every move: the element's own text is kept (not rewritten with lines
    as cubics whose rounded handles kink the joins), and the read-back check, finding the
    curve as it was, tries more decimals."""
    if decimals is None or orig.shape != geo.shape:
        return geo
    q = 10.0 ** decimals
    o = np.round(orig * q) / q
    step = np.trunc(np.round((geo - o) * q, 6))
    if not step.any():
        return None          # every move undone: the subpath is written back as it was
    return o + step / q


def _record_geometry(recs: list[CurveRecord], decimals: int | None = None
                     ) -> tuple[str, FloatArray | None, np.ndarray | None]:
    """``("bspline", Bezier points (m, 4, 2), straight)`` or ``("points", vertices (n, 2),
    None)`` of one subpath / shape, in the ELEMENT's own coordinates (the inverse of its
    transformation matrix applied), or ``(kind, None, None)`` when the record(s) hold the
    geometry read. With ``decimals``, rounded to them toward the input's values
    (:func:`_toward`); ``straight``: the segments that are lines before rounding
    (:func:`_straight`)."""
    r0 = recs[0]
    ctm = _ctm(r0.source)
    if r0.kind == "bspline":
        curve = r0.curve
        B = bezier_pieces(curve, "write_curves (SVG)", max_degree=3)
        orig = np.asarray(r0.source.get("beziers", []), dtype=float)
        scale = max(float(np.abs(orig).max()) if orig.size else 1.0, 1.0)
        if orig.shape == B.shape and np.abs(orig - B).max() <= 1e-12 * scale:
            return "bspline", None, None
        own = _unapply(ctm, B)
        return "bspline", _toward(own, _unapply(ctm, orig), decimals), _straight(own)
    n = int(r0.source["n_points"])
    dim = data_points(r0.curve, "write_curves (SVG)").shape[1]
    pts = piece_values(n, dim, recs, "write_curves (SVG)")
    orig = np.full_like(pts, np.nan)
    for r in recs:
        orig[np.asarray(r.source["indices"])] = np.asarray(r.points)
    if np.array_equal(orig, pts):
        return "points", None, None
    rows = np.asarray(r0.source.get("row_map", range(n)), dtype=int)
    return ("points", _toward(_unapply(ctm, pts[rows]), _unapply(ctm, orig[rows]), decimals),
            None)


def _record_d(recs: list[CurveRecord], decimals: int | None) -> tuple[str, bool]:
    """The d of one subpath from its record(s), and whether it changed."""
    kind, geo, lines = _record_geometry(recs, decimals)
    if geo is None:
        return "", False
    r0 = recs[0]
    if kind == "bspline":
        return _d_cubics(geo, bool(r0.source.get("svg_closed", r0.curve.closed)), decimals,
                         lines), True
    closed = bool(r0.source.get("closed"))
    if closed and not r0.source.get("svg_closed", True):
        # read as a loop, but the subpath had no Z (it ends at its start): it stays open
        return _d_points(np.vstack([geo, geo[:1]]), False, decimals), True
    return _d_points(geo, closed, decimals), True


def _start_tag_attrs(raw: bytes, i: int) -> dict[str, tuple[int, int]]:
    """Byte spans of the attribute values of the start tag beginning at ``raw[i] == '<'``.

    The tag was accepted by the XML parser, so it is ``< Name (S Attr = "value")* S? /? >``
    (XML 1.0 production 40): names, blanks, ``=`` and quoted values, nothing else."""
    ws = b" \t\r\n"
    j = i + 1
    while raw[j] not in ws and raw[j] not in b"/>":
        j += 1
    out: dict[str, tuple[int, int]] = {}
    while True:
        while raw[j] in ws:
            j += 1
        if raw[j] in b"/>":
            return out
        a = j
        while raw[j] not in ws and raw[j] != 0x3D:      # '='
            j += 1
        name = raw[a:j].decode("utf-8", "replace")
        while raw[j] in ws:
            j += 1
        j += 1                                          # '='
        while raw[j] in ws:
            j += 1
        quote = raw[j]
        start = j + 1
        j = raw.index(bytes([quote]), start)
        out[name] = (start, j)
        j += 1


def _locate(raw: bytes, path: object) -> tuple[list[dict[str, tuple[int, int]]], int]:
    """For every element of the document in order (the order of ``ElementTree.iter``), the
    byte spans of its attribute values, and the byte offset of the root's end tag.

    Found with expat (the XML parser under ElementTree), which reports the byte offset of
    every start tag: comments, CDATA and processing instructions that merely contain
    ``<path d=...`` text are never taken for elements, and namespace prefixes (``<svg:path>``)
    are elements like any other."""
    import xml.parsers.expat as expat

    starts: list[int] = []
    depth = 0
    root_end = -1
    parser = expat.ParserCreate()

    def start(name: str, attrs: Any) -> None:
        nonlocal depth
        starts.append(parser.CurrentByteIndex)
        depth += 1

    def end(name: str) -> None:
        nonlocal depth, root_end
        depth -= 1
        if depth == 0:
            root_end = parser.CurrentByteIndex

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    try:
        parser.Parse(raw, True)
    except expat.ExpatError as exc:
        raise FileFormatError(f"not well-formed XML ({exc})", path, exc.lineno) from None
    return [_start_tag_attrs(raw, i) for i in starts], root_end


def _attr_value(raw: bytes, span: tuple[int, int]) -> str:
    """An attribute value as the XML parser reads it (entities, blanks normalised)."""
    text = raw[span[0]:span[1]].decode("utf-8")
    return html.unescape(re.sub(r"\r\n|[\r\n\t]", " ", text))


def _decimals_of(text: str) -> int | None:
    found = re.findall(r"\.(\d+)", text)
    return max((len(f) for f in found), default=None)


#: The write-back's second precision: each rewritten element's own decimals plus this many
#: (tried when the element's own decimals put a curve read back beyond the tolerance, before
#: the shortest exact numbers).
MORE_DECIMALS = 3


def _element_decimals(text: str, precision: str) -> int | None:
    """Decimals for the numbers of a rewritten element whose text is ``text``: its own largest
    number of decimals (``"file"``), that plus :data:`MORE_DECIMALS` (``"file+"``), or None,
    the shortest exact form (``"exact"``, or an element written with exponents, whose
    decimals say nothing of its precision). An element written in whole numbers gets
    :data:`MORE_DECIMALS` decimals in both: rounded to whole numbers, moves smaller than a
    unit (what fairing makes) would be undone."""
    if precision == "exact" or re.search(r"\d[eE][-+]?\d", text):
        return None
    d = _decimals_of(text)
    if d is None:
        return MORE_DECIMALS
    return d + MORE_DECIMALS if precision == "file+" else d


def write(path: str | os.PathLike[str], records: Sequence[CurveRecord], *,
          template: str | None = None, decimals: int | None = None, precision: str = "file",
          **_: Any) -> None:
    """Write an SVG file; see the module docstring.

    ``precision="exact"`` (with ``decimals=None``) writes the numbers of rewritten elements
    in the shortest form that reads back as exactly the value, instead of the element's own
    number of decimals; ``precision="file+"`` with :data:`MORE_DECIMALS` more than the
    element's own.
    """
    spt = _svgpathtools("writing SVG files")
    ours = [r for r in records if template is not None and r.format == FORMAT
            and r.path is not None and os.path.abspath(r.path) == os.path.abspath(template)]
    mine = {id(r) for r in ours}  # (a set: a drawing's 10,000 records, not 10,000 squared)
    others = [r for r in records if id(r) not in mine]
    if template is None:
        atomic_write(path, _fresh_svg(others, decimals))
        return
    text = _read_text(template)
    with open(template, "rb") as f:
        raw = f.read()
    nodes = list(_root(text, template).iter())
    spans, root_end = _locate(raw, template)
    if len(spans) != len(nodes):
        raise FileFormatError("cannot locate the elements in the text of the template for a "
                              "write-back", template)
    by_el: dict[int, dict[int, list[CurveRecord]]] = {}
    for r in ours:
        if "node" not in r.source:
            raise InputError("write_curves (SVG): a record without source['node'] (read by an "
                             "older curvefair?); read the template again")
        by_el.setdefault(int(r.source["node"]), {}).setdefault(
            int(r.source["subpath"]), []).append(r)
    edits: list[tuple[int, int, str]] = []

    def edit(node: int, attr: str, value: str) -> None:
        el, sp = nodes[node], spans[node].get(attr)
        if sp is None or _attr_value(raw, sp) != (el.get(attr) or ""):
            raise FileFormatError(f"cannot locate the {attr} attribute of <{_local(el.tag)}> "
                                  f"element (id={el.get('id')!r}) in the template text",
                                  template)
        edits.append((sp[0], sp[1], html.escape(value, quote=True)))

    for node, subs in sorted(by_el.items()):
        el = nodes[node]
        tag = _local(el.tag)
        if tag != "path":
            dec = None if tag not in ("polygon", "polyline") else (
                decimals if decimals is not None
                else _element_decimals(el.get("points") or "", precision))
            kind, geo, _straight_segs = _record_geometry(subs[0], dec)
            if geo is None:
                continue
            if tag == "rect":
                raise InputError(f"write_curves (SVG): <rect> element (id={el.get('id')!r}) "
                                 "changed; a rectangle is written back only unchanged")
            if tag == "line":
                for name, v in zip(("x1", "y1", "x2", "y2"), geo.reshape(-1), strict=True):
                    dec = decimals if decimals is not None else _element_decimals(
                        el.get(name) or "", precision)
                    edit(node, name, _num(v, dec))
                continue
            edit(node, "points", " ".join(_pt(p, dec) for p in geo))
            continue
        parsed = spt.parse_path(el.get("d"))
        d_text = el.get("d") or ""
        changed = any(_record_d(subs[j], None)[1] for j in subs)
        if not changed:
            continue
        # the precision of the element as it was: its largest number of decimals (all digits
        # with precision="exact", when that rounding would break the tolerance on disk)
        dec = decimals if decimals is not None else _element_decimals(d_text, precision)
        new_d = {j: d for j in subs for d, ch in [_record_d(subs[j], dec)] if ch}
        sp = spans[node].get("d")
        raw_d = raw[sp[0]:sp[1]].decode("utf-8") if sp is not None else ""
        # splice into the attribute's own text (no entity references: the value is the text)
        # or, failing that, into the parsed value; either keeps every other subpath verbatim
        spliced = (_splice_subpaths(raw_d, parsed, new_d, spt)
                   if sp is not None and "&" not in raw_d
                   and _attr_value(raw, sp) == d_text else None)
        if spliced is not None and sp is not None:
            edits.append((sp[0], sp[1], spliced))
            continue
        spliced = _splice_subpaths(d_text, parsed, new_d, spt)
        if spliced is None:        # text not split into subpaths: every subpath re-rendered
            spliced = " ".join(new_d[j] if j in new_d else _d_original(sub, spt, None)
                               for j, sub in enumerate(_subpaths(d_text, parsed, spt)[0]))
        edit(node, "d", spliced)
    for a, b, new in sorted(edits, reverse=True):
        raw = raw[:a] + new.encode("utf-8") + raw[b:]
    if others:
        extra = "".join(f'<path d="{_record_path_d(r, decimals)}" fill="none" stroke="black"/>\n'
                        for r in _join_foreign(others))
        if root_end < 0:
            raise FileFormatError("no closing </svg> tag", template)
        shift = sum(len(new.encode("utf-8")) - (b - a) for a, b, new in edits if a < root_end)
        at = root_end + shift
        raw = raw[:at] + extra.encode("utf-8") + raw[at:]
    atomic_write(path, raw)


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
    B = bezier_pieces(c, "write_curves (SVG)", max_degree=3)
    return _d_cubics(B, c.closed, decimals, _straight(B))


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
