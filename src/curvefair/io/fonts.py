"""Font sources and binaries: UFO (ufoLib2), OpenType/TrueType (fontTools), Glyphs (glyphsLib).

``pip install 'curvefair[fonts]'``.

Read
----
One record per contour of every glyph (``glyphs=`` chooses glyphs by name), in glyph order:
the default layer of a UFO (``.ufo`` folder), the ``glyf`` (quadratic) or ``CFF `` (cubic)
outlines of a ``.ttf``/``.otf``, every master, brace (intermediate) and bracket (alternate)
layer of a ``.glyphs`` source (backup layers are left as they are; records of a brace or
bracket layer are named ``"<glyph>@<layer name> <master name>#<contour>"``), every source of
a ``.designspace`` document
(read only: :func:`curvefair.fonts.fair_designspace`, or ``curvefair fair X.designspace --tol T
-o OUTDIR``, writes one, masters included; records
named ``"<glyph>@<source name>#<contour>"``). Units are font units, ``y`` up. Contours made
of straight lines only, components and empty glyphs carry no curve and are not records (they
are written back untouched); a font whose contours are all straight raises
:class:`~curvefair.io.DrawnShapesOnly` (nothing to fair: the command line writes it back
unchanged). The curve is the contour's B-spline of
:mod:`curvefair.io._outline` (cubic poly-Bezier with knots of multiplicity 3; quadratic
B-spline with TrueType's implied on-curve points exact); ``corners`` holds the corner nodes
and straight segments.

``name`` is ``"<glyph>#<contour>"``; ``source`` keys: ``glyph``, ``contour`` (0-based index in
the glyph), ``handle`` (= name), ``master`` (Glyphs sources with several masters: the name is
then ``"<glyph>@<master>#<contour>"``), ``outline`` (the
:class:`~curvefair.io._outline.Contour`: points, on-curve and smooth flags, closedness,
quadratic, integer grid) and ``point_index`` (the control point of each contour point: a
point index reported on the curve maps back to the contour's point through it).

Write
-----
Only with the source as template (a font is never made from curves alone). The faired control
points become the contour's points with the outline's rules enforced
(:func:`curvefair.io._outline.constrained_points`: same points in the same order, smooth
nodes exactly smooth, extrema keep their horizontal/vertical tangent, corners and straight
segments unmoved, integers in TrueType and in CFF contours drawn on integers -- a CFF contour
with fractional coordinates keeps them and its nearly smooth nodes smooth), each contour no
farther from its input than the record's faired control points are (so within the fairing's
``tol``), and never less fair than
its input as written (:func:`record_points`: no more curvature extrema, no more bending
energy; else the input contour is written). The layers of a multi-master ``.glyphs`` source
share that decision per contour, instances between them included (:func:`shared_points`).
A variable TrueType binary (``gvar``) is refused: its sources are faired instead.

- UFO: the template folder is copied; in the ``.glif`` file of each changed glyph only the
  ``x``/``y`` attributes of the moved points are replaced, in the file's own text
  (:func:`_patch_glif`; read back with glifLib and compared, else the file is rewritten by
  glifLib in the glyph's own GLIF format version); kerning, features, groups, lib, other
  layers, components, anchors, guidelines, notes and every other byte come back unchanged.
  A contour whose coordinates are all integers keeps to the integer grid.
- TrueType: the changed glyphs' coordinates are replaced (instructions, flags and point
  counts kept), bounds recomputed, the left side bearing follows ``xMin`` where it was equal.
- Glyphs: nothing changed, the source's bytes are copied; else the faired coordinates are
  patched into the source's own text (:mod:`curvefair.io._glyphs_text`): the output is the
  source except for the numbers of the nodes that moved, so what glyphsLib does not
  round-trip (format 3: ``fontType``, ``kernTop``, background images, an instance's
  ``visible``; format 2: e.g. an ``Axes`` custom parameter, ``146.0``) is kept. Integer
  coordinates stay integers (Glyphs' default grid); others are written with the shortest
  decimals that read back as the exact float. A source whose text cannot be patched safely
  falls back to glyphsLib's save (5 decimals), with a ``UserWarning`` naming the first line
  that save changes (:func:`write_glyphs`).
- CFF: the charstrings are desubroutinized and each changed glyph's drawing operators
  rewritten as ``rmoveto``/``rlineto``/``rrcurveto`` (hints, hint masks and width kept).

The font is saved with fontTools (head/hhea/maxp bounds recomputed) and read back by the
caller's check; a binary font in which no glyph changed is copied byte for byte instead.
"""

from __future__ import annotations

import os
import re
import shutil
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .._typing import FloatArray
from ..errors import CurvefairError, FileFormatError, InputError
from ._common import CurveRecord, DrawnShapesOnly, Unsupported, lazy_import
from ._outline import Contour, constrained_points, contour_curve, fairness, smooth_angle
from ._outline import harmonize as _harmonize

__all__ = ["read", "write", "glyph_contours", "font_contours", "Contour", "smooth_angle",
           "exact_smooth_flags"]


def _ufolib2(what: str) -> Any:
    return lazy_import("ufoLib2", "ufoLib2", "fonts", what)


def _fonttools(what: str) -> Any:
    return lazy_import("fontTools", "fonttools", "fonts", what)


# ------------------------------------------------------------------------------------------
# contours of the formats
# ------------------------------------------------------------------------------------------
def ufo_contour(points: Sequence[Any], path: object = None) -> Contour:
    """A :class:`Contour` from a UFO contour's points (``x, y, type/segmentType, smooth``)."""
    types = [getattr(p, "type", None) if hasattr(p, "type") else p.segmentType for p in points]
    closed = not (types and types[0] == "move")
    # a closed contour of off-curve points only is a quadratic (TrueType) curve (UFO 3 spec)
    quad = "qcurve" in types or (closed and all(t in (None, "offcurve") for t in types))
    if quad and "curve" in types:
        raise Unsupported("a contour mixing cubic and quadratic segments")
    xy = np.array([(float(p.x), float(p.y)) for p in points], dtype=np.float64)
    on = tuple(t is not None and t != "offcurve" for t in types)
    smooth = tuple(bool(p.smooth) for p in points)
    # a contour drawn on the integer grid (most UFO sources: the editors' default) keeps to it,
    # as a Glyphs source's does; one with fractional coordinates is not put on it
    grid = bool(xy.size) and bool(np.array_equal(xy, np.round(xy)))
    return Contour(xy, on, smooth, closed, quad, grid=grid)


def exact_smooth_flags(xy: FloatArray, on: Sequence[bool]) -> tuple[bool, ...]:
    n = len(on)
    out = []
    for k in range(n):
        a, p, b = xy[(k - 1) % n], xy[k], xy[(k + 1) % n]
        d1, d2 = p - a, b - p
        out.append(bool(on[k] and d1[0] * d2[1] - d1[1] * d2[0] == 0 and float(d1 @ d2) > 0))
    return tuple(out)


def _binary_contour(xy: FloatArray, on: Sequence[bool], quadratic: bool) -> Contour:
    return Contour(xy, tuple(bool(o) for o in on), exact_smooth_flags(xy, on), True,
                   quadratic, grid=True)


def _glyf_contours(font: Any, name: str) -> list[Contour]:
    glyf = font["glyf"]
    g = glyf[name]
    if g.isComposite() or g.numberOfContours <= 0:
        return []
    coords, ends, flags = g.getCoordinates(glyf)
    xy = np.array(coords, dtype=np.float64)
    out, start = [], 0
    for e in ends:
        out.append(_binary_contour(xy[start:e + 1], [bool(f & 1) for f in flags[start:e + 1]],
                                   True))
        start = e + 1
    return out


def _cff_commands(font: Any, name: str) -> list[tuple[str, list[Any]]]:
    from fontTools.cffLib.specializer import generalizeCommands, programToCommands

    cs = font["CFF "].cff.topDictIndex[0].CharStrings[name]
    cs.decompile()
    return generalizeCommands(programToCommands(cs.program))


def _cff_walk(cmds: list[tuple[str, list[Any]]]) -> list[tuple[list[FloatArray], list[bool],
                                                                  bool]]:
    """Contours of generalized charstring commands: (points, on flags, closing point equals
    the start)."""
    contours: list[tuple[list[FloatArray], list[bool], bool]] = []
    cur = np.zeros(2)
    pts: list[FloatArray] = []
    on: list[bool] = []

    def close() -> None:
        if pts:
            dup = len(pts) > 1 and np.array_equal(pts[-1], pts[0]) and on[-1]
            if dup:
                pts.pop()
                on.pop()
            contours.append((list(pts), list(on), bool(dup)))
            pts.clear()
            on.clear()

    for op, args in cmds:
        if op == "rmoveto":
            close()
            cur = cur + np.array(args[:2], dtype=float)
            pts.append(cur.copy())
            on.append(True)
        elif op == "rlineto":
            cur = cur + np.array(args[:2], dtype=float)
            pts.append(cur.copy())
            on.append(True)
        elif op in ("rrcurveto", "flex"):
            for s in range(0, 12 if op == "flex" else 6, 6):
                for j, o in ((0, False), (2, False), (4, True)):
                    cur = cur + np.array(args[s + j:s + j + 2], dtype=float)
                    pts.append(cur.copy())
                    on.append(o)
        elif op == "endchar":
            close()
        elif op in ("", "hstem", "vstem", "hstemhm", "vstemhm", "hintmask", "cntrmask"):
            continue
        else:
            raise Unsupported(f"charstring operator {op!r}")
    close()
    return contours


def _cff_contours(font: Any, name: str) -> list[Contour]:
    """A CFF glyph's contours. Charstrings hold 16.16 fixed-point numbers, not only
    integers: a contour whose coordinates are all integers keeps to the integer grid (its
    smooth nodes those exactly collinear with their handles); one with fractional coordinates
    (Linux Libertine: on-curve points at tenths) is not put on the grid -- rounding its
    handles but not its nodes kinked joins that were smooth to 0.26 degrees into 12 -- and
    every node whose handles are collinear within ``_outline.SMOOTH_ANGLE`` (0.5 degrees) is
    kept smooth, as in a UFO."""
    walked = _cff_walk(_cff_commands(font, name))
    out = []
    for p, o, _ in walked:
        xy = np.array(p)
        if np.array_equal(xy, np.round(xy)):
            out.append(_binary_contour(xy, o, False))
        else:
            out.append(Contour(xy, tuple(bool(v) for v in o), tuple(bool(v) for v in o), True,
                               False, grid=False))
    return out


def _open_binary(path: Any) -> Any:
    _fonttools("OpenType/TrueType fonts")
    from fontTools.ttLib import TTFont
    try:
        font = TTFont(os.fspath(path))
        font.getGlyphOrder()
    except Exception as exc:  # fontTools raises many kinds for a garbled file
        raise FileFormatError(f"not a font fontTools can read ({exc})", path) from None
    if "glyf" not in font and "CFF " not in font:
        if "CFF2" in font:
            raise FileFormatError("its outlines are in a CFF2 table (variable OpenType/CFF2), "
                                  "which curvefair does not read or write: fair the font's "
                                  "sources (a .designspace with 'curvefair fair', or its UFO "
                                  "masters) and build it again", path)
        raise FileFormatError("no glyf or CFF outlines", path)
    if "CFF " in font:
        font["CFF "].cff.desubroutinize()
    return font


def _open_ufo(path: Any) -> Any:
    ufoLib2 = _ufolib2("UFO sources")
    try:
        return ufoLib2.Font.open(os.fspath(path), lazy=True)
    except Exception as exc:
        raise FileFormatError(f"not a UFO ufoLib2 can read ({exc})", path) from None


def _open_glyphs(path: Any) -> Any:
    glyphsLib = lazy_import("glyphsLib", "glyphsLib", "fonts", "Glyphs sources")
    try:
        # what GSFont(path) does, with the file closed again (glyphsLib's own open is not)
        font = glyphsLib.GSFont()
        with open(os.fspath(path), encoding="utf-8") as f:
            glyphsLib.load(f, font)
        font.filepath = os.fsdecode(os.fspath(path))
        for master in font.masters:
            master.font = font
        return font
    except Exception as exc:
        raise FileFormatError(f"not a Glyphs source glyphsLib can read ({exc})", path) from None


def _glyphs_layers(font: Any, names: Sequence[str]
                   ) -> list[tuple[str, str, Any, dict[str, Any]]]:
    """(glyph, label, layer, location) of every layer that takes part in the design, in glyph
    order: the master layers (label: the master's name) and the brace (intermediate) and
    bracket (alternate) layers (label ``"<layer name> <master name>"``); backup and other
    layers are left out. The location is the design-space position (axis index: value; a
    bracket layer also has ``"set"``, its layer name: it interpolates with its like only)."""
    masters = {m.id: m for m in font.masters}
    out = []
    for g in names:
        for layer in font.glyphs[g].layers:
            m = masters.get(layer.associatedMasterId)
            if m is None:
                continue
            loc: dict[str, Any] = {str(i): float(v) for i, v in enumerate(m.axes or [])}
            if layer.layerId == m.id:
                out.append((g, m.name, layer, loc))
                continue
            if layer._is_brace_layer():
                coords = layer._brace_coordinates() or []
                loc = {str(i): float(v) for i, v in enumerate(coords)}
            elif layer._is_bracket_layer():
                loc["set"] = str(layer.name)
            else:
                continue
            out.append((g, f"{layer.name or layer.layerId} {m.name}", layer, loc))
    return out


def _glyphs_label(font: Any, g: str, label: str, layer: Any) -> str:
    """The record label of a .glyphs layer: the glyph name alone for the master layer of a
    single-master source, else ``"<glyph>@<label>"``."""
    if len(font.masters) > 1 or layer.layerId != layer.associatedMasterId:
        return f"{g}@{label}"
    return g


def glyphs_contour(path: Any) -> Contour:
    """A :class:`Contour` from a glyphsLib ``GSPath`` (integer grid when its coordinates are
    integers, as Glyphs writes them by default)."""
    nodes = list(path.nodes)
    types = [n.type for n in nodes]
    quad = "qcurve" in types
    if quad and "curve" in types:
        raise Unsupported("a path mixing cubic and quadratic segments")
    xy = np.array([(float(n.position.x), float(n.position.y)) for n in nodes], dtype=np.float64)
    on = tuple(t != "offcurve" for t in types)
    smooth = tuple(bool(n.smooth) for n in nodes)
    grid = bool(np.array_equal(xy, np.round(xy)))
    return Contour(xy, on, smooth, bool(path.closed), quad, grid=grid)


def designspace_sources(path: Any) -> list[dict[str, Any]]:
    """Every source of a designspace document, checked before anything is read or written:
    ``{"index", "label", "ufo" (absolute path), "layer" (layer name, None for the default
    layer)}``. A source may be sparse (a UFO with only some glyphs, or a layer of another
    source's UFO: a brace/intermediate master)."""
    _fonttools("designspace documents")
    from fontTools.designspaceLib import DesignSpaceDocument

    try:
        doc = DesignSpaceDocument.fromfile(os.fspath(path))
    except Exception as exc:
        raise FileFormatError(f"not a designspace document fontTools can read ({exc})",
                              path) from None
    base = os.path.dirname(os.path.abspath(os.fspath(path)))
    out: list[dict[str, Any]] = []
    layers: dict[str, Any] = {}
    for k, s in enumerate(doc.sources):
        ufo = s.path or (os.path.join(base, s.filename) if s.filename else None)
        if ufo is None or not os.path.isdir(ufo):
            raise FileFormatError(f"source {k} ({s.filename!r}): no such UFO ({ufo!r})", path)
        ufo = os.path.abspath(ufo)
        if s.layerName:
            if ufo not in layers:
                layers[ufo] = set(_open_ufo(ufo).layers.keys())
            if s.layerName not in layers[ufo]:
                raise FileFormatError(f"source {k} ({s.filename!r}): the UFO has no layer "
                                      f"{s.layerName!r}", path)
        label = s.name or s.styleName or f"source{k}"
        if any(o["label"] == label for o in out):
            label = f"{label} ({k})"
        out.append({"index": k, "label": label, "ufo": ufo, "layer": s.layerName or None,
                    "location": {str(a): float(v) if isinstance(v, (int, float)) else str(v)
                                 for a, v in (s.location or {}).items()}})
    return out


def _ufo_layer_contours(ufo: str, layer_name: str | None, glyphs: Sequence[str] | None
                        ) -> list[tuple[str, list[Contour]]]:
    font = _open_ufo(ufo)
    layer = font.layers[layer_name] if layer_name else font.layers.defaultLayer
    names = _glyph_order(list(layer.keys()), font.glyphOrder)
    if glyphs is not None:
        want = set(glyphs)
        names = [g for g in names if g in want]
    return [(g, _ufo_glyph_contours(layer[g])) for g in names]


def _ufo_glyph_contours(glyph: Any) -> list[Contour]:
    """A UFO glyph's contours; one that cannot be represented stands as its
    :class:`Unsupported` (skipped with a warning by the caller, kept on write)."""
    conts = []
    for c in glyph.contours:
        try:
            conts.append(ufo_contour(c.points))
        except Unsupported as exc:
            conts.append(exc)  # type: ignore[arg-type]
    return conts


def designspace_records(path: Any, glyphs: Sequence[str] | str | None, skip: Any
                        ) -> list[CurveRecord]:
    """Records of every source of a designspace (:func:`designspace_sources`), named
    ``"<glyph>@<source label>#<contour>"``, ``source`` with ``ufo`` and ``layer`` besides the
    usual keys. A sparse source gives the glyphs it has; ``glyphs`` names glyphs that at
    least one source must have."""
    where = os.path.abspath(os.fspath(path))
    if isinstance(glyphs, str):
        glyphs = [g for g in glyphs.split(",") if g]
    recs: list[CurveRecord] = []
    seen: set[str] = set()
    for src in designspace_sources(path):
        per = _ufo_layer_contours(src["ufo"], src["layer"], glyphs)
        base = {"format": "designspace", "path": where, "ufo": src["ufo"],
                "layer": src["layer"], "location": src["location"]}
        for g, conts in per:
            seen.add(g)
            recs.extend(glyph_contours(f"{g}@{src['label']}", conts, base, skip, len(recs)))
    missing = [g for g in (glyphs or []) if g not in seen]
    if missing:
        raise InputError(f"glyphs: {', '.join(map(repr, missing[:10]))} in no source of "
                         f"{where!r}")
    return recs


def _glyph_order(names: Sequence[str], order: Sequence[str] | None) -> list[str]:
    known = set(names)
    first = [g for g in (order or []) if g in known]
    seen = set(first)
    return first + sorted(g for g in names if g not in seen)


def _select(names: list[str], glyphs: Sequence[str] | None, path: Any) -> list[str]:
    if glyphs is None:
        return names
    if isinstance(glyphs, str):
        glyphs = [g for g in glyphs.split(",") if g]
    missing = [g for g in glyphs if g not in set(names)]
    if missing:
        raise InputError(f"glyphs: {', '.join(map(repr, missing[:10]))} not in "
                         f"{os.fspath(path)!r}")
    want = set(glyphs)
    return [g for g in names if g in want]


def font_contours(path: str | os.PathLike[str], glyphs: Sequence[str] | None = None
                  ) -> tuple[str, list[tuple[str, list[Contour], dict[str, Any]]]]:
    """``(format, [(glyph label, contours, extra source keys)])`` of a UFO, Glyphs source or
    binary font, in glyph order."""
    p = Path(path)
    if p.suffix.lower() == ".glyphs":
        font = _open_glyphs(path)
        names = _select([g.name for g in font.glyphs], glyphs, path)
        out = []
        for g, label, layer, loc in _glyphs_layers(font, names):
            conts = []
            for c in layer.paths:
                try:
                    conts.append(glyphs_contour(c))
                except Unsupported as exc:
                    conts.append(exc)  # type: ignore[arg-type]
            out.append((_glyphs_label(font, g, label, layer), conts, {"location": loc}))
        return "glyphs", out
    if p.suffix.lower() == ".ufo":
        font = _open_ufo(path)
        layer = font.layers.defaultLayer
        names = _select(_glyph_order(list(layer.keys()), font.glyphOrder), glyphs, path)
        return "ufo", [(g, _ufo_glyph_contours(layer[g]), {}) for g in names]
    font = _open_binary(path)
    names = _select(list(font.getGlyphOrder()), glyphs, path)
    get = _glyf_contours if "glyf" in font else _cff_contours
    out = []
    for g in names:
        try:
            out.append((g, get(font, g), {}))
        except Unsupported as exc:
            out.append((g, [exc], {}))  # type: ignore[list-item]
    return "opentype", out


# ------------------------------------------------------------------------------------------
# read
# ------------------------------------------------------------------------------------------
def glyph_contours(glyph: str, contours: Sequence[Contour | Exception], base: dict[str, Any],
                   skip: Any, start: int = 0) -> list[CurveRecord]:
    """Records of one glyph's contours (contours of lines only are not records); ``glyph``
    may be ``"<glyph>@<master>"`` (a Glyphs source with several masters)."""
    recs: list[CurveRecord] = []
    label = glyph
    glyph, _, master = label.partition("@") if "@" in label and \
        base.get("format") in ("glyphs", "designspace") else (label, "", "")
    for ci, c in enumerate(contours):
        name = f"{label}#{ci}"
        if isinstance(c, Exception):
            skip(f"glyph {glyph!r}: {c}")
            continue
        if all(c.on):
            continue
        try:
            curve, index, hold = contour_curve(c)
        except (Unsupported, CurvefairError) as exc:
            skip(f"glyph {glyph!r} contour {ci}: {exc}")
            continue
        src = dict(base, index=start + len(recs), glyph=glyph, contour=ci, handle=name,
                   outline=c, point_index=tuple(int(i) for i in index))
        if master:
            src["master"] = master
        recs.append(CurveRecord(curve, name, "bspline", src, None, tuple(hold)))
    return recs


def read(path: str | os.PathLike[str], *, corner_angle: float | None = 60.0,
         on_unsupported: str = "raise", glyphs: Sequence[str] | None = None
         ) -> list[CurveRecord]:
    """Every contour with curves of the chosen glyphs (module docstring)."""
    del corner_angle  # outlines carry their own corners (the nodes' smooth flags)
    where = os.path.abspath(os.fspath(path))

    def skip(msg: str) -> None:
        if on_unsupported == "raise":
            raise FileFormatError(f"unsupported: {msg} (on_unsupported='skip' leaves it "
                                  "unchanged)", path)
        warnings.warn(f"{where}: skipped (left unchanged): {msg}", stacklevel=4)

    if Path(path).suffix.lower() == ".designspace":
        return designspace_records(path, glyphs, skip)
    fmt, per_glyph = font_contours(path, glyphs)
    base = {"format": fmt, "path": where}
    recs: list[CurveRecord] = []
    straight = 0
    for g, conts, extra in per_glyph:
        recs.extend(glyph_contours(g, conts, dict(base, **extra), skip, len(recs)))
        straight += sum(isinstance(c, Contour) and all(c.on) for c in conts)
    if not recs and straight:
        # a font of straight contours only (a pixel or geometric design): nothing to fair, and
        # the command line writes it back unchanged, as a drawing of polygons
        raise DrawnShapesOnly(straight, path, fmt)
    return recs


# ------------------------------------------------------------------------------------------
# write
# ------------------------------------------------------------------------------------------
#: the moves tried by the never-worse guard of :func:`record_points`, as fractions of the fair's
GUARD_SCALES = (1.0, 0.5, 0.25, 0.125)


def _guard_setup(rec: CurveRecord, tol: float | None
                 ) -> tuple[Contour, FloatArray, FloatArray, float]:
    """(contour, input points, faired points at the contour's indices, tol) of a record."""
    c: Contour = rec.source["outline"]
    idx = np.asarray(rec.source["point_index"], dtype=np.intp)
    cp = np.asarray(rec.curve.control_points, dtype=np.float64)  # type: ignore[attr-defined]
    if cp.ndim != 2 or cp.shape[1] != 2 or cp.shape[0] <= int(idx.max()):
        raise InputError(f"{rec.name}: the curve has {cp.shape[0]} control points, the contour "
                         "needs its own structure back (same knots)")
    new = cp[idx]
    if tol is None:
        ref, _, _ = contour_curve(c)
        P0 = np.asarray(ref.control_points)
        if P0.shape != cp.shape:
            raise InputError(f"{rec.name}: {cp.shape[0]} control points, the contour has "
                             f"{P0.shape[0]}: its structure must be kept")
        tol = float(np.max(np.linalg.norm(cp - P0, axis=1)))
    return c, np.asarray(c.points, dtype=np.float64), new, float(tol)


def _candidate(c: Contour, P0: FloatArray, new: FloatArray, tol: float, s: float,
               harmonize: bool) -> FloatArray:
    pts, _ = constrained_points(c, P0 + s * (new - P0) if s != 1.0 else new, tol)
    return _harmonize(c, pts, tol) if harmonize else pts


def record_points(rec: CurveRecord, tol: float | None = None, *, harmonize: bool = False,
                  guard: bool = True) -> FloatArray:
    """The contour points to write for a (faired) record: its control points at the contour's
    indices with the outline's rules enforced, no farther from the input than ``tol`` (default:
    the farthest faired control point, i.e. the fairing's own tolerance).

    Never worse (``guard=True``): what is written -- after the smooth-node and extremum rules,
    the rounding to integers of binary fonts and ``harmonize`` -- is measured with
    :func:`curvefair.io._outline.fairness` on the contour's own Bezier segments, for the fair's
    moves scaled by each of :data:`GUARD_SCALES`. Of the candidates with no more curvature
    extrema and no more bending energy than the input, the one with the fewest extrema (then
    the least energy) is written; when there is none the input contour is written unchanged.
    The fair itself works on the B-spline and cannot see these rules: rounding a TrueType
    point to the grid, or putting a node back on its neighbours' line, can add an extremum
    the fair's own check did not count. The masters of an interpolated design share one
    decision: :func:`shared_points`."""
    return shared_points([rec], tol, harmonize=harmonize, guard=guard)[0]


#: the instances between two masters that :func:`shared_points` measures, as interpolation
#: weights ``w`` of ``(1 - w) A + w B``
INSTANCE_WEIGHTS = (0.25, 0.5, 0.75)


def neighbour_pairs(locations: Sequence[dict[str, Any]]) -> list[tuple[int, int]]:
    """The pairs of masters whose straight interpolation is an instance of the design: two
    locations that differ in one axis only (non-numeric entries, such as a bracket layer's
    set, equal) with no third location strictly between them on that axis (e.g. Light and
    Regular, Regular and Bold on a weight axis; not Light and Bold)."""
    def num(loc: dict[str, Any]) -> dict[str, float]:
        return {k: v for k, v in loc.items() if isinstance(v, float)}

    def rest(loc: dict[str, Any]) -> dict[str, Any]:
        return {k: v for k, v in loc.items() if not isinstance(v, float)}

    out = []
    n = len(locations)
    for i in range(n):
        for j in range(i + 1, n):
            a, b = locations[i], locations[j]
            if rest(a) != rest(b) or set(num(a)) != set(num(b)):
                continue
            diff = [k for k in num(a) if a[k] != b[k]]
            if len(diff) != 1:
                continue
            ax = diff[0]
            lo, hi = sorted((a[ax], b[ax]))
            between = any(rest(c) == rest(a) and set(num(c)) == set(num(a))
                          and all(c[k] == a[k] for k in num(a) if k != ax)
                          and lo < c[ax] < hi for c in locations)
            if not between:
                out.append((i, j))
    return out


def _compatible(cs: Sequence[Contour]) -> bool:
    c0 = cs[0]
    return all(len(c.on) == len(c0.on) and c.on == c0.on and c.closed == c0.closed
               and c.quadratic == c0.quadratic for c in cs[1:])


def shared_points(recs: Sequence[CurveRecord], tol: float | None = None, *,
                  harmonize: bool = False, guard: bool = True) -> list[FloatArray]:
    """The points to write for one contour faired in several masters of a design (the masters,
    brace/intermediate and bracket layers of a glyph), with one never-worse decision for all.

    Each master's candidate is built as in :func:`record_points`. For each scale ``s`` of
    :data:`GUARD_SCALES`, every master takes the fair's moves scaled by that same ``s``, except
    a master whose own candidate has more curvature extrema or more bending energy than its
    input (it keeps its input); then the instances ``(1 - w) A + w B`` of every pair of
    neighbouring masters (:func:`neighbour_pairs` of ``source["location"]``; every pair when
    a record has no location), ``w`` in :data:`INSTANCE_WEIGHTS`, are measured the same way
    against the same instances of the input (their contours take their corners from the
    interpolated input, smooth where both masters are). The scale is admissible when none of
    these instances is worse; of the admissible scales the one with the fewest extrema in total
    over masters and instances (then the least energy) is written, else every master's input.
    A guard per master alone could fair a contour in one master and leave its instances
    unguarded (the masters stay compatible, the instances between them need not stay fair).
    Masters with different structures (point counts, on-curve pattern) cannot interpolate and
    are guarded one by one."""
    setups = [_guard_setup(r, tol) for r in recs]
    if not guard:
        return [_candidate(c, P0, new, t, 1.0, harmonize) for c, P0, new, t in setups]
    if len(setups) > 1 and not _compatible([st[0] for st in setups]):
        return [shared_points([r], tol, harmonize=harmonize)[0] for r in recs]
    # what is measured: each master, then the instances of each pair of neighbours
    locs = [r.source.get("location") for r in recs]
    if all(isinstance(loc, dict) for loc in locs):
        pairs = neighbour_pairs(locs)  # type: ignore[arg-type]
    else:
        pairs = [(i, j) for i in range(len(recs)) for j in range(i + 1, len(recs))]
    mixes: list[tuple[int, int, float, Contour]] = []
    for i, j in pairs:
        ci, cj = setups[i][0], setups[j][0]
        sm = tuple(a and b for a, b in zip(ci.smooth, cj.smooth, strict=True))
        for w in INSTANCE_WEIGHTS:
            mixes.append((i, j, w, Contour((1 - w) * setups[i][1] + w * setups[j][1],
                                           ci.on, sm, ci.closed, ci.quadratic)))

    def measure(pts: list[FloatArray]) -> list[tuple[int, float]]:
        out = [fairness(st[0], p) for st, p in zip(setups, pts, strict=True)]
        out += [fairness(cm, (1 - w) * pts[i] + w * pts[j]) for i, j, w, cm in mixes]
        return out

    inputs = [st[1] for st in setups]
    base = measure(inputs)
    nm = len(setups)
    best: tuple[int, float, list[FloatArray]] | None = None
    for s in GUARD_SCALES:
        pts = [_candidate(c, P0, new, t, s, harmonize) for c, P0, new, t in setups]
        own = [fairness(st[0], p) for st, p in zip(setups, pts, strict=True)]
        # a master whose own candidate is worse keeps its input at this scale
        pts = [p if k <= base[i][0] and en <= base[i][1] else inputs[i]
               for i, (p, (k, en)) in enumerate(zip(pts, own, strict=True))]
        if all(np.array_equal(p, q) for p, q in zip(pts, inputs, strict=True)):
            continue
        got = measure(pts)
        if all(k <= k0 and en <= en0
               for (k, en), (k0, en0) in zip(got[nm:], base[nm:], strict=True)):
            score = (sum(k for k, _ in got), sum(en for _, en in got))
            if best is None or score < best[:2]:
                best = (*score, pts)
    return [p.copy() for p in inputs] if best is None else best[2]


def _by_glyph(records: Sequence[CurveRecord], tpath: str, tol: float | None = None
              ) -> dict[str, dict[int, FloatArray]]:
    """The changed contours' points by glyph label (``"<glyph>"`` or ``"<glyph>@<master>"``).
    The records of one contour in several masters (``source["master"]``) share one guard
    decision (:func:`shared_points`)."""
    groups: dict[tuple[Any, ...], list[CurveRecord]] = {}
    for i, r in enumerate(records):
        if "outline" not in r.source or "glyph" not in r.source:
            raise InputError(f"curves[{i}] was not read from a font: a font is written from "
                             "its own records")
        if r.path is not None and os.path.abspath(r.path) != tpath:
            raise InputError(f"curves[{i}] comes from {r.path!r}, not from the template "
                             f"{tpath!r}")
        key = (r.source["glyph"], int(r.source["contour"])) if "master" in r.source else (i,)
        groups.setdefault(key, []).append(r)
    out: dict[str, dict[int, FloatArray]] = {}
    for group in groups.values():
        for r, pts in zip(group, shared_points(group, tol), strict=True):
            c: Contour = r.source["outline"]
            if np.array_equal(pts, c.points):
                continue
            label = str(r.source["handle"]).rsplit("#", 1)[0]
            out.setdefault(label, {})[int(r.source["contour"])] = pts
    return out


def _glif_version(text: bytes) -> tuple[int, int] | None:
    m = re.search(rb'<glyph[^>]*\bformat="(\d+)"', text)
    if not m:
        return None
    m2 = re.search(rb'<glyph[^>]*\bformatMinor="(\d+)"', text)
    return int(m.group(1)), int(m2.group(1)) if m2 else 0


def write_ufo(path: str | os.PathLike[str], changes: dict[str, dict[int, FloatArray]],
              template: str, layers: dict[str, dict[str, dict[int, FloatArray]]] | None = None
              ) -> None:
    """Copy the UFO ``template`` to ``path`` and rewrite the changed glyphs' ``.glif`` files:
    ``changes`` in the default layer, ``layers`` (layer name: changes) in other layers."""
    _ufolib2("UFO sources")
    dest = os.fspath(path)
    if os.path.lexists(dest):
        if os.path.isdir(dest) and not os.path.islink(dest):
            shutil.rmtree(dest)
        else:
            os.unlink(dest)
    shutil.copytree(template, dest, symlinks=True)
    todo: dict[str | None, dict[str, dict[int, FloatArray]]] = {None: changes}
    todo.update(layers or {})
    for layer_name, layer_changes in todo.items():
        if layer_changes:
            _write_layer(dest, template, layer_name, layer_changes)


def _write_layer(dest: str, template: str, layer_name: str | None,
                 changes: dict[str, dict[int, FloatArray]]) -> None:
    ufoLib2 = _ufolib2("UFO sources")
    from fontTools.ufoLib import UFOReader
    from fontTools.ufoLib.glifLib import GlyphSet

    with UFOReader(template, validate=False) as reader:
        layer_dir = reader.getGlyphSet(layer_name).dirName
        ufo_version = reader.formatVersionTuple
    gs = GlyphSet(os.path.join(dest, layer_dir), ufoFormatVersion=ufo_version, validateRead=False,
                  validateWrite=True)
    for gname, conts in changes.items():
        glyph = ufoLib2.objects.Glyph(gname)
        gs.readGlyph(gname, glyph, glyph.getPointPen())
        for ci, pts in conts.items():
            for p, (x, y) in zip(glyph.contours[ci].points, pts, strict=True):
                p.x, p.y = _number(x), _number(y)
        raw = gs.getGLIF(gname)
        patched = _patch_glif(raw, conts)
        if patched is not None:
            # the file's own text with only the moved numbers replaced, if it reads back as
            # exactly the glyph with the new points
            gs.fs.writebytes(gs.contents[gname], patched)
            back = ufoLib2.objects.Glyph(gname)
            gs.readGlyph(gname, back, back.getPointPen())
            if back == glyph:
                continue
        gs.writeGlyph(gname, glyph, glyph.drawPoints, formatVersion=_glif_version(raw))


_POINT_TAG = re.compile(rb"""<point\b(?:\s+[\w:.-]+\s*=\s*(?:"[^"]*"|'[^']*'))*\s*/?>""")


def _patch_glif(raw: bytes, conts: dict[int, FloatArray]) -> bytes | None:
    """The ``.glif`` text ``raw`` with the ``x``/``y`` attributes of the points of the changed
    contours (``conts``: contour index -> new points, in file order) replaced, every other byte
    kept -- the file's formatting, attribute order and quoting, notes, lib, comments -- so a
    version-controlled UFO changes by exactly the moved numbers (fontTools' glifLib rewrites
    the whole file in its own layout and drops an empty ``<note>``). GLIF 1 stores anchors as
    contours of one named ``move`` point, which glifLib reads as anchors: those are not counted.
    None when the file cannot be patched so (the contours and points found differ from
    ``conts``). The caller reads the result back and compares."""
    import xml.parsers.expat

    version = _glif_version(raw)
    if version is None or version[0] not in (1, 2):
        return None
    found: list[list[tuple[int, dict[str, str]]]] = []   # per contour: each child's offset
    depth: list[str] = []
    parser = xml.parsers.expat.ParserCreate()

    def start(name: str, attrs: dict[str, str]) -> None:
        if name == "contour" and depth[-1:] == ["outline"]:
            found.append([])
        elif depth[-2:] == ["outline", "contour"]:
            found[-1].append((parser.CurrentByteIndex if name == "point" else -1, attrs))
        depth.append(name)

    def end(_name: str) -> None:
        depth.pop()

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    try:
        parser.Parse(raw, True)
    except xml.parsers.expat.ExpatError:
        return None
    if version[0] == 1:
        found = [c for c in found if not (len(c) == 1 and c[0][0] >= 0
                                          and c[0][1].get("type") == "move"
                                          and c[0][1].get("name") is not None)]
    if any(off < 0 for c in found for off, _ in c):
        return None
    starts = [[off for off, _ in c] for c in found]
    edits: list[tuple[int, int, bytes]] = []
    for ci, pts in conts.items():
        if not 0 <= ci < len(starts) or len(starts[ci]) != len(pts):
            return None
        for off, (x, y) in zip(starts[ci], pts, strict=True):
            m = _POINT_TAG.match(raw, off)
            if m is None:
                return None
            tag = m.group(0)
            for name, v in ((b"x", x), (b"y", y)):
                a = re.search(rb"(\s" + name + rb"\s*=\s*)([\"'])([^\"']*)\2", tag)
                if a is None:
                    return None
                tag = tag[:a.start(3)] + repr(_number(v)).encode() + tag[a.end(3):]
            edits.append((m.start(), m.end(), tag))
    out = bytearray(raw)
    for s, e, tag in sorted(edits, reverse=True):
        out[s:e] = tag
    return bytes(out)


def write_glyphs(path: str | os.PathLike[str], changes: dict[str, dict[int, FloatArray]],
                 template: str) -> None:
    """Save a copy of the Glyphs source ``template`` with the changed layers' nodes moved.

    Nothing changed: the template's bytes, exactly. Otherwise the faired coordinates are
    patched into the template's own text (:func:`curvefair.io._glyphs_text.patch_nodes`):
    the output equals the template except for the numbers of the nodes that moved -- node
    types, ``smooth`` flags, userData, unmoved numbers and every other byte are kept, so the
    data glyphsLib does not round-trip (format 3: ``fontType``, ``kernTop``, background
    ``imagePath`` entries, an instance's ``visible``; format 2: e.g. an ``Axes`` custom
    parameter, numbers with more than 5 decimals) is not lost. New numbers are integers when
    integral, else the shortest decimals that read back as exactly the float computed (not
    glyphsLib's 5 decimals, whose rounding could move a node past ``tol``); glyphsLib reads
    the patched file back and must find exactly those numbers at the changed nodes.

    Fallback: a source whose text cannot be patched safely (it is not UTF-8, the tokenizer's
    reading differs from ``openstep_plist``'s, a glyph or layer is not found exactly once, a
    path's nodes are not those glyphsLib read, the patched text reads back with other
    changes, or a ``.glyphspackage``) is written as before: glyphsLib loads the source, the
    nodes are moved and it saves the file; if its save of the unmodified source differs from
    the template, a ``UserWarning`` names the file and the first line glyphsLib changes
    (and why the text could not be patched). glyphsLib then writes non-integers with 5
    decimals."""
    from ._glyphs_text import NotPatchable, patch_nodes

    with open(template, "rb") as f:
        raw = f.read()
    if not any(changes.values()):
        with open(os.fspath(path), "wb") as f:
            f.write(raw)
        return
    font = _open_glyphs(template)
    names = sorted({k.split("@")[0] for k in changes})
    moves = []
    for g, label, layer, _ in _glyphs_layers(font, [n for n in names if n in font.glyphs]):
        conts = changes.get(_glyphs_label(font, g, label, layer))
        if conts:
            moves.append((g, layer, conts))
    why = ""
    try:
        text = raw.decode("utf-8")
        targets = []
        for g, layer, conts in moves:
            paths = list(layer.paths)
            for ci, pts in sorted(conts.items()):
                old = [(float(n.position.x), float(n.position.y)) for n in paths[ci].nodes]
                targets.append((g, str(layer.layerId), ci, old,
                                [(float(x), float(y)) for x, y in pts]))
        patched = patch_nodes(text, int(font.format_version or 2), targets)
        with open(os.fspath(path), "wb") as f:
            f.write(patched.encode("utf-8"))
        _check_patched(path, targets)
        return
    except UnicodeDecodeError:
        why = "the source is not UTF-8 text"
    except NotPatchable as exc:
        why = str(exc)
    _write_glyphs_through_glyphslib(path, font, moves, template, raw, why)


def _check_patched(path: str | os.PathLike[str], targets: Sequence[tuple[Any, ...]]) -> None:
    """glyphsLib reads the patched file back with the changed nodes where they were written
    (the unmoved numbers as they were, the others as written)."""
    from ._glyphs_text import NotPatchable, format_number

    try:
        back = _open_glyphs(path)
    except FileFormatError as exc:
        raise NotPatchable(f"glyphsLib does not read the patched text ({exc})") from None
    for g, layer_id, ci, old, new in targets:
        glyph = back.glyphs[g]
        layer = glyph.layers[layer_id] if glyph is not None else None
        if layer is None:
            raise NotPatchable(f"glyph {g!r}: layer {layer_id!r} not read back")
        got = [(float(n.position.x), float(n.position.y)) for n in list(layer.paths)[ci].nodes]
        want = [tuple(a if a == b else float(format_number(b)) for a, b in zip(o, n, strict=True))
                for o, n in zip(old, new, strict=True)]
        if got != want:
            raise NotPatchable(f"glyph {g!r} path {ci}: glyphsLib reads the patched nodes "
                               "back elsewhere")


def _write_glyphs_through_glyphslib(path: str | os.PathLike[str], font: Any, moves: list[Any],
                                    template: str, raw: bytes, why: str) -> None:
    """The fallback of :func:`write_glyphs`: glyphsLib moves the nodes of ``moves`` (layers
    of ``font``, the template as glyphsLib read it) and saves the file."""
    for _g, layer, conts in moves:
        paths = list(layer.paths)
        for ci, pts in conts.items():
            for node, (x, y) in zip(paths[ci].nodes, pts, strict=True):
                node.position = (_number(x), _number(y))
    font.save(os.fspath(path))
    probe = os.fspath(path) + ".roundtrip"
    try:
        _open_glyphs(template).save(probe)
        with open(probe, "rb") as f:
            same = f.read()
    finally:
        if os.path.exists(probe):
            os.remove(probe)
    if same != raw:
        a = raw.decode("utf-8", "replace").splitlines()
        b = same.decode("utf-8", "replace").splitlines()
        k = next((i for i, (x, y) in enumerate(zip(a, b, strict=False)) if x != y),
                 min(len(a), len(b)))
        was = a[k].strip() if k < len(a) else "(end of file)"
        now = b[k].strip() if k < len(b) else "(end of file)"
        warnings.warn(f"{template}: glyphsLib does not write this source back as it read it, "
                      f"so the output differs from it beyond the faired nodes (first at line "
                      f"{k + 1}: {was!r} becomes {now!r}; the faired nodes could not be "
                      f"written into the source's own text: {why}); compare before replacing "
                      "the source", UserWarning, stacklevel=3)


#: The charstrings' fixed-point scale (Type 2 charstring numbers: 16.16).
_FIXED = 65536.0


def _number(v: float) -> float | int:
    return int(v) if float(v).is_integer() else float(v)


def write_binary(path: str | os.PathLike[str], changes: dict[str, dict[int, FloatArray]],
                 template: str) -> None:
    """Replace the changed glyphs' outlines in a copy of the binary font ``template``.

    Nothing changed: the template's bytes, exactly (fontTools' save would rebuild every table,
    and a CFF font's charstrings come out desubroutinized, larger). A variable TrueType font
    (``gvar``) is refused: its instances are the default outline plus the ``gvar`` deltas, so
    a faired default outline with the deltas kept would move every instance by the default's
    moves, unchecked against ``tol`` and unfaired."""
    font = _open_binary(template)
    if "gvar" in font:
        raise FileFormatError("a variable TrueType font (gvar table): fairing its default "
                              "outline would move every instance through the unchanged gvar "
                              "deltas; fair the font's sources (a .designspace with "
                              "'curvefair fair X.designspace --tol T -o OUTDIR', or its UFO "
                              "masters) and build it again", template)
    if not any(changes.values()):
        shutil.copyfile(template, os.fspath(path))
        return
    if "glyf" in font:
        glyf, hmtx = font["glyf"], font["hmtx"]
        for gname, conts in changes.items():
            g = glyf[gname]
            coords = g.coordinates
            old_xmin = g.xMin
            start = 0
            for ci, e in enumerate(g.endPtsOfContours):
                if ci in conts:
                    for k, (x, y) in enumerate(conts[ci]):
                        coords[start + k] = (int(x), int(y))
                start = e + 1
            g.recalcBounds(glyf)
            adv, lsb = hmtx[gname]
            if lsb == old_xmin:
                hmtx[gname] = (adv, g.xMin)
    else:
        from fontTools.cffLib.specializer import commandsToProgram

        cs = font["CFF "].cff.topDictIndex[0].CharStrings
        for gname, conts in changes.items():
            cmds = _cff_commands(font, gname)
            walked = _cff_walk(cmds)
            new_abs = [conts.get(ci, np.array(p)) for ci, (p, _, _) in enumerate(walked)]
            cs[gname].program = commandsToProgram(_cff_rewrite(cmds, walked, new_abs))
    font.save(os.fspath(path))


def _cff_rewrite(cmds: list[tuple[str, list[Any]]], walked: list[Any],
                 new_abs: list[FloatArray]) -> list[tuple[str, list[Any]]]:
    """The generalized commands with every drawn point replaced by ``new_abs``.

    Charstrings hold relative moves as 16.16 fixed-point numbers. Every absolute point is put
    on that grid first, each coordinate rounded toward its value in the font (which is on the
    grid), so no point ends farther from where it was than ``new_abs`` put it; each move is
    then the exact difference of two grid values, and the moves sum to every point exactly: a
    contour drawn back to its start still closes exactly (rounding each move on its own
    drifted a Linux Libertine contour's last point off its first by 1.5e-5, so it read back
    with one point more and the write was refused)."""
    seq: list[FloatArray] = []
    for (pts, _on, dup), new in zip(walked, new_abs, strict=True):
        old = np.asarray(pts, dtype=float)
        grid = old + np.trunc((np.asarray(new, dtype=float) - old) * _FIXED) / _FIXED
        seq.extend(grid)
        if dup:
            seq.append(grid[0])
    it = iter(seq)
    cur = np.zeros(2)
    out = []

    def rel() -> list[float | int]:
        nonlocal cur
        p = next(it)
        d = p - cur
        cur = p
        return [_number(d[0]), _number(d[1])]

    for op, args in cmds:
        if op in ("rmoveto", "rlineto"):
            out.append((op, rel()))
        elif op == "rrcurveto":
            out.append((op, rel() + rel() + rel()))
        elif op == "flex":
            out.append((op, [v for _ in range(6) for v in rel()] + list(args[12:])))
        else:
            out.append((op, args))
    return out


def write(path: str | os.PathLike[str], records: Sequence[CurveRecord], *,
          template: str | None = None, decimals: int | None = None,
          precision: str = "file") -> None:
    """Write faired records into a copy of their font (module docstring)."""
    del decimals, precision  # font units: the font's own number types
    if template is None:
        paths = {r.path for r in records}
        if len(paths) != 1 or None in paths:
            raise InputError("a font is written into a copy of the font its records were read "
                             "from: pass template= (or records from one font)")
        template = paths.pop()
    tpath = os.path.abspath(os.fspath(template))  # type: ignore[arg-type]
    if Path(tpath).suffix.lower() == ".designspace":
        raise InputError("a designspace is written with its masters: use "
                         "curvefair.fonts.fair_designspace(path, out_dir, tol)")
    changes = _by_glyph(records, tpath)
    if Path(tpath).suffix.lower() == ".glyphs":
        write_glyphs(path, changes, tpath)
    elif Path(tpath).suffix.lower() == ".ufo":
        if Path(os.fspath(path)).suffix.lower() != ".ufo":
            raise InputError(f"{os.fspath(path)!r}: a UFO is written as a .ufo folder")
        write_ufo(path, changes, tpath)
    else:
        write_binary(path, changes, tpath)
