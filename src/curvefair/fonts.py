"""Fairing where fonts are made: outlines, a fontTools point pen, a ufo2ft filter.

``pip install 'curvefair[fonts]'``.

- :func:`fair_contours` fairs a glyph's contours (UFO-style points) and gives their new
  points with the outline's structure kept (:mod:`curvefair.io._outline`: same points in the
  same order, quadratic stays quadratic, smooth nodes exactly smooth, extrema keep their
  horizontal/vertical tangent, corners and straight segments unmoved), every point within
  ``tol`` font units of its input, so the outline is within ``tol`` everywhere.
- :class:`FairPointPen`: a fontTools point pen that fairs each contour drawn into it and
  passes it on (components and everything else unchanged), e.g.
  ``glyph.drawPoints(FairPointPen(other.getPointPen(), tol=2))``.
- :class:`FairFilter`: a ufo2ft filter (``ufo2ft.filters.BaseFilter``), so that
  ``fontmake -u Font.ufo --filter "curvefair.fonts::FairFilter(tol=2)"`` fairs at build time
  (or ``ufo2ft.compileOTF(ufo, filters=[FairFilter(tol=2)])``).
- :func:`font_to_ufo` writes a binary font's outlines as a UFO (smooth flags from the exact
  collinearity of each node's neighbours), to fair a font that has no source.
- :func:`check_outlines` lists kinks at smooth nodes, G2 breaks and inflections by glyph name
  and contour point index.
- :func:`fair_designspace` fairs every master of a designspace document with the same
  options and checks that they still interpolate (fontTools' ``varLib.interpolatable``); the
  CLI's ``curvefair fair X.designspace --tol T -o OUTDIR`` calls it.

Fairing uses :func:`curvefair.fair` on the contour's B-spline (``method=None``: the B-spline
default), with ``protect`` = the corner nodes and the points of straight segments.
"""

from __future__ import annotations

import dataclasses
import os
import warnings
from collections.abc import Sequence
from types import SimpleNamespace
from typing import Any

import numpy as np

from ._typing import FloatArray
from .errors import CurvefairError, InputError, MissingDependencyError
from .io import CurveRecord
from .io.fonts import Contour, glyph_contours, record_points, ufo_contour

__all__ = ["fair_contours", "FairPointPen", "FairFilter", "font_to_ufo",  # noqa: F822
           "fair_designspace", "interpolation_problems", "check_outlines"]


def _check_tol(tol: object) -> float:
    if isinstance(tol, bool) or not isinstance(tol, (int, float)) or not np.isfinite(tol) \
            or tol <= 0:
        raise InputError(f"tol must be a positive number of font units, got {tol!r}")
    return float(tol)


def fair_contours(contours: Sequence[Contour], tol: float, *, method: str | None = None,
                  harmonize: bool = False, glyph: str = "glyph", **options: Any
                  ) -> list[FloatArray | None]:
    """New points of each contour (None: unchanged: no curve, or nothing to gain).

    Parameters
    ----------
    contours : sequence of Contour
        See :func:`curvefair.io.fonts.ufo_contour`.
    tol : float
        Largest move of any point, in font units.
    method, options
        As for :func:`curvefair.fair`.
    harmonize : bool
        Also make smooth nodes G2 by moving their handles along the tangent
        (:func:`curvefair.io._outline.harmonize`), within ``tol``.
    """
    from .fairing.fair import fair

    tol = _check_tol(tol)
    recs = glyph_contours(glyph, list(contours), {"format": None, "path": None},
                          skip=lambda msg: None)
    out: list[FloatArray | None] = [None] * len(contours)
    for r in recs:
        try:
            res = fair(r.curve, method, tol=tol, protect=r.corners, **options)
        except CurvefairError:
            continue
        pts = record_points(r.with_curve(res.curve), tol, harmonize=harmonize)
        c: Contour = r.source["outline"]
        if not np.array_equal(pts, c.points):
            out[int(r.source["contour"])] = pts
    return out


class FairPointPen:
    """A fontTools point pen that fairs every contour drawn into it, then draws it into
    ``out_pen`` (components, identifiers, names and smooth flags passed on unchanged).

    Parameters
    ----------
    out_pen : AbstractPointPen
    tol : float
        Largest move of any point, in font units.
    grid : bool
        Round to integers (a glyph bound for a binary font).
    method, harmonize, options
        As for :func:`fair_contours`.
    """

    def __init__(self, out_pen: Any, tol: float, *, grid: bool = False,
                 method: str | None = None, harmonize: bool = False, **options: Any) -> None:
        self.out_pen = out_pen
        self.tol = _check_tol(tol)
        self.grid = bool(grid)
        self.method, self.harmonize, self.options = method, harmonize, options
        self._points: list[tuple[Any, ...]] | None = None
        self._path_kwargs: dict[str, Any] = {}

    def beginPath(self, identifier: str | None = None, **kwargs: Any) -> None:  # noqa: N802
        self._points = []
        self._path_kwargs = dict(kwargs, identifier=identifier)

    def addPoint(self, pt: tuple[float, float], segmentType: str | None = None,  # noqa: N802,N803
                 smooth: bool = False, name: str | None = None, identifier: str | None = None,
                 **kwargs: Any) -> None:
        if self._points is None:
            raise InputError("FairPointPen: addPoint outside beginPath/endPath")
        self._points.append((pt, segmentType, smooth, name, identifier, kwargs))

    def endPath(self) -> None:  # noqa: N802
        pts = self._points or []
        self._points = None
        new = None
        if pts:
            ns = [SimpleNamespace(x=p[0][0], y=p[0][1], segmentType=p[1], smooth=p[2])
                  for p in pts]
            try:
                c = ufo_contour(ns)
                if self.grid:
                    c = Contour(c.points, c.on, c.smooth, c.closed, c.quadratic, grid=True)
                new = fair_contours([c], self.tol, method=self.method,
                                    harmonize=self.harmonize, **self.options)[0]
            except CurvefairError:
                new = None
            except Exception as exc:  # an unsupported contour: passed on unchanged
                if type(exc).__name__ != "Unsupported":
                    raise
        kw = {k: v for k, v in self._path_kwargs.items() if k != "identifier" or v is not None}
        self.out_pen.beginPath(**kw)
        for k, (pt, seg, smooth, name, ident, kwargs) in enumerate(pts):
            xy = pt if new is None else (_num(new[k][0]), _num(new[k][1]))
            extra = dict(kwargs)
            if ident is not None:
                extra["identifier"] = ident
            self.out_pen.addPoint(xy, segmentType=seg, smooth=smooth, name=name, **extra)
        self.out_pen.endPath()

    def addComponent(self, baseGlyphName: str, transformation: Any,  # noqa: N802,N803
                     identifier: str | None = None, **kwargs: Any) -> None:
        if identifier is not None:
            kwargs["identifier"] = identifier
        self.out_pen.addComponent(baseGlyphName, transformation, **kwargs)


def _num(v: float) -> float | int:
    return int(v) if float(v).is_integer() else float(v)


def _filter_class() -> type:
    try:
        from ufo2ft.filters import BaseFilter
    except ImportError:  # pragma: no cover - the fonts extra installs it
        raise MissingDependencyError("ufo2ft", "fonts", "FairFilter") from None

    class FairFilter(BaseFilter):
        """ufo2ft filter: fair every glyph's contours within ``tol`` font units.

        Options (keyword arguments, also in ``--filter "curvefair.fonts::FairFilter(...)"``):
        ``tol`` (default 2), ``method`` (default: the B-spline default), ``harmonize``
        (default False), ``grid`` (``"auto"``, the default: contours with integer coordinates
        get integers, so that the compiled font's rounding neither moves points nor breaks
        smooth nodes; True/False: always/never), and ufo2ft's ``include``/``exclude``/``pre``.
        """

        _kwargs = {"tol": 2.0, "method": None, "harmonize": False, "grid": "auto"}

        def start(self) -> None:
            self.options.tol = _check_tol(self.options.tol)
            if self.options.grid not in ("auto", True, False):
                raise InputError(f"grid must be 'auto', True or False, got "
                                 f"{self.options.grid!r}")

        def filter(self, glyph: Any) -> bool:
            conts: list[Any] = []
            for contour in glyph:
                try:
                    c = ufo_contour(list(contour))
                except Exception:  # an unsupported contour stays as it is
                    conts.append(RuntimeError("unsupported"))
                    continue
                grid = self.options.grid
                if grid == "auto":  # integer sources stay integer: the binary keeps G1
                    grid = bool(np.array_equal(c.points, np.round(c.points)))
                conts.append(dataclasses.replace(c, grid=bool(grid)))
            if not conts:
                return False
            new = fair_contours(conts, self.options.tol, method=self.options.method,
                                harmonize=self.options.harmonize,
                                glyph=getattr(glyph, "name", "glyph") or "glyph")
            changed = False
            for contour, pts in zip(glyph, new, strict=True):
                if pts is None:
                    continue
                for p, (x, y) in zip(list(contour), pts, strict=True):
                    p.x, p.y = _num(x), _num(y)
                changed = True
            return changed

    FairFilter.__module__ = __name__
    FairFilter.__qualname__ = "FairFilter"
    return FairFilter


_FILTER: type | None = None


def __getattr__(name: str) -> Any:
    global _FILTER
    if name == "FairFilter":
        if _FILTER is None:
            _FILTER = _filter_class()
        return _FILTER
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def font_to_ufo(src: str | os.PathLike[str], dest: str | os.PathLike[str], *,
                glyphs: Sequence[str] | None = None) -> None:
    """Write the outlines, advance widths and code points of a binary font as a UFO.

    Each point is as in the font (TrueType: off-curve points and ``qcurve`` nodes, implied
    on-curve points left implied; CFF: ``curve``/``line`` nodes); ``smooth`` where the node's
    neighbours are exactly collinear with it. Components stay components.
    """
    import ufoLib2
    from fontTools.pens.pointPen import SegmentToPointPen
    from fontTools.ttLib import TTFont

    from .io.fonts import exact_smooth_flags

    font = TTFont(os.fspath(src))
    gs = font.getGlyphSet()
    cmap = font.getBestCmap() or {}
    uni: dict[str, list[int]] = {}
    for code, g in cmap.items():
        uni.setdefault(g, []).append(code)
    ufo = ufoLib2.Font()
    names = list(font.getGlyphOrder()) if glyphs is None else list(glyphs)
    for g in names:
        glyph = ufo.newGlyph(g)
        glyph.width = font["hmtx"][g][0]
        glyph.unicodes = sorted(uni.get(g, []))
        pen = glyph.getPointPen()
        if "glyf" in font:
            gs[g].drawPoints(pen)
        else:
            gs[g].draw(SegmentToPointPen(pen))
        for contour in glyph.contours:
            xy = np.array([(p.x, p.y) for p in contour.points], dtype=float)
            on = [p.type is not None for p in contour.points]
            for p, s in zip(contour.points, exact_smooth_flags(xy, on), strict=True):
                p.smooth = s
    ufo.glyphOrder = names
    ufo.info.unitsPerEm = font["head"].unitsPerEm
    ufo.info.familyName = font["name"].getDebugName(1)
    ufo.save(os.fspath(dest), overwrite=True)


def fair_designspace(path: str | os.PathLike[str], out_dir: str | os.PathLike[str], tol: float,
                     *, glyphs: Sequence[str] | None = None, method: str | None = None,
                     **options: Any) -> dict[str, Any]:
    """Fair every source (master) of a designspace document into ``out_dir``.

    ``out_dir`` gets a copy of the document (same file name) and of every source UFO (same
    relative file names) whose contours are faired within ``tol`` with the same options.
    Sparse sources are faired with the rest: a UFO with only some glyphs, and a layer source
    (``layerName``: a brace/intermediate master kept in a layer of another master's UFO),
    whose layer is rewritten in the copy. The structure of every contour is kept, so masters
    that were compatible stay compatible; that is checked with fontTools'
    ``varLib.interpolatable`` on the result (``problems`` in the returned dict: what it
    reports for the output, and ``problems_before`` for the input). Each contour's masters
    share one never-worse decision (:func:`curvefair.io.fonts.shared_points`: one scale of the
    fair's moves for all of them, measured on the masters and on instances between them), and
    every point stays within ``tol`` of its input (so the outline does, by the convex hull
    property).
    """
    from .fairing.fair import fair
    from .io import atomic_write
    from .io.fonts import designspace_records, designspace_sources, shared_points, write_ufo

    tol = _check_tol(tol)
    src = os.path.abspath(os.fspath(path))
    out = os.path.abspath(os.fspath(out_dir))
    if os.path.dirname(src) == out:
        raise InputError("out_dir must not be the folder of the designspace document")
    base = os.path.dirname(src)
    sources = designspace_sources(src)  # every source checked before anything is written
    for s in sources:
        if os.path.relpath(s["ufo"], base).startswith(os.pardir):
            raise InputError(f"designspace source {s['index']} "
                             f"({os.path.relpath(s['ufo'], base)!r}) is outside the "
                             "document's folder: out_dir cannot hold it at the same relative "
                             "path")

    def skip(msg: str) -> None:
        warnings.warn(f"{src}: skipped (left unchanged): {msg}", stacklevel=3)

    # integer masters stay integer (as FairFilter's grid="auto"): a build's rounding then
    # neither moves points nor breaks smooth nodes
    recs = [_grid_if_integer(r) for r in designspace_records(src, glyphs, skip)]
    groups: dict[tuple[str, int], list[CurveRecord]] = {}
    for r in recs:
        try:
            res = fair(r.curve, method, tol=tol, protect=r.corners, **options)
            r = r.with_curve(res.curve)
        except CurvefairError:
            pass
        groups.setdefault((r.source["glyph"], int(r.source["contour"])), []).append(r)
    changes: dict[tuple[str, str | None], dict[str, dict[int, FloatArray]]] = {}
    for group in groups.values():
        for r, pts in zip(group, shared_points(group, tol), strict=True):
            if not np.array_equal(pts, r.source["outline"].points):
                key = (r.source["ufo"], r.source["layer"])
                changes.setdefault(key, {}).setdefault(r.source["glyph"], {})[
                    int(r.source["contour"])] = pts
    os.makedirs(out, exist_ok=True)
    done: dict[str, Any] = {"sources": []}
    for ufo in dict.fromkeys(s["ufo"] for s in sources):
        rel = os.path.relpath(ufo, base)
        dest = os.path.join(out, rel)
        os.makedirs(os.path.dirname(dest), exist_ok=True)
        layers = {lay: ch for (u, lay), ch in changes.items() if u == ufo and lay is not None}
        write_ufo(dest, changes.get((ufo, None), {}), ufo, layers=layers)
    for s in sources:
        n = sum(1 for r in recs if r.source["ufo"] == s["ufo"] and r.source["layer"] == s["layer"])
        ch = changes.get((s["ufo"], s["layer"]), {})
        done["sources"].append({"ufo": os.path.relpath(s["ufo"], base), "layer": s["layer"],
                                "contours": n,
                                "changed": sum(len(v) for v in ch.values())})
    with open(src, "rb") as fh:
        atomic_write(os.path.join(out, os.path.basename(src)), fh.read())
    done["problems_before"] = interpolation_problems(src)
    done["problems"] = interpolation_problems(os.path.join(out, os.path.basename(src)))
    return done


def _grid_if_integer(r: CurveRecord) -> CurveRecord:
    c: Contour = r.source["outline"]
    if c.grid or not np.array_equal(c.points, np.round(c.points)):
        return r
    return dataclasses.replace(r, source=dict(r.source, outline=dataclasses.replace(c, grid=True)))


class _Glyphset(dict):
    """A glyph set that gives None for a glyph it does not have (interpolatable's sparse
    masters)."""

    def __missing__(self, key: str) -> None:
        return None


def interpolation_problems(designspace: str | os.PathLike[str]) -> list[dict[str, Any]]:
    """What ``fontTools.varLib.interpolatable`` reports for a designspace's sources (empty:
    compatible). A layer source is its layer; a glyph missing from a sparse source is not a
    problem (``ignore_missing``)."""
    import ufoLib2
    from fontTools.varLib.interpolatable import test as interpolatable_test

    from .io.fonts import designspace_sources

    fonts: dict[str, Any] = {}
    glyphsets, names = [], []
    for s in designspace_sources(designspace):
        if s["ufo"] not in fonts:
            fonts[s["ufo"]] = ufoLib2.Font.open(s["ufo"])
        font = fonts[s["ufo"]]
        layer = font.layers[s["layer"]] if s["layer"] else font.layers.defaultLayer
        glyphsets.append(_Glyphset({g.name: g for g in layer}))
        names.append(s["label"])
    problems = interpolatable_test(glyphsets, names=names, ignore_missing=True)
    return [dict(p, glyph=g) for g, ps in problems.items() for p in ps]


def _end_curvature(P: FloatArray) -> float:
    """Signed curvature at the end of the Bezier segment with control points ``P`` (degree
    ``n = len(P) - 1``): ``(n-1)/n * cross(P_n - P_{n-1}, P_{n-1} - P_{n-2}) / |P_n - P_{n-1}|^3``
    (e.g. Farin, *Curves and Surfaces for CAGD*, end curvature of a Bezier curve)."""
    n = len(P) - 1
    a, b = P[-1] - P[-2], P[-2] - P[-3]
    la = float(np.hypot(*a))
    return float((n - 1) / n * -(a[0] * b[1] - a[1] * b[0]) / la ** 3) if la > 0 else np.nan


def _piece(c: Contour, k: int, step: int) -> FloatArray:
    """The Bezier control polygon of the segment before (``step=-1``) or after (``+1``) node
    ``k``, ordered so that it ends at ``k`` (TrueType: the neighbouring implied on-curve point
    ends the quadratic piece)."""
    P, n = np.asarray(c.points, dtype=np.float64), len(c.on)
    pts = [P[k]]
    j = (k + step) % n
    while not c.on[j]:
        pts.append(P[j])
        j = (j + step) % n
    pts.append(P[j])
    if c.quadratic and len(pts) > 3:
        pts = [pts[0], pts[1], (pts[1] + pts[2]) / 2]
    return np.array(pts[::-1])


def check_outlines(path: str | os.PathLike[str], *, glyphs: Sequence[str] | str | None = None,
                   kink_angle: float = 2.0, g2_rel: float = 0.05) -> list[dict[str, Any]]:
    """Outline problems a type designer looks for, by glyph name and contour point index.

    - ``"kink"``: an on-curve node meant to be smooth (UFO/Glyphs ``smooth`` flag, or turning
      by at most ``kink_angle`` degrees) whose neighbours are not collinear (turn > 1e-9 rad);
      ``value`` is the turn in radians;
    - ``"g2"``: a smooth node between two curve segments whose two end curvatures differ by
      more than ``g2_rel`` of the larger; ``value`` is that relative difference;
    - ``"inflection"``: an inflection of the contour (:func:`curvefair.analyze`), ``point``
      the nearest contour point; ``value`` its parameter on the record's curve.

    Returns a list of dicts ``{"glyph", "contour", "point", "kind", "value", "name"}`` (``name``
    is the record name, ``"<glyph>#<contour>"``).
    """
    from .analysis import analyze
    from .io import read_curves
    from .io.fonts import smooth_angle

    out: list[dict[str, Any]] = []
    for r in read_curves(path, glyphs=glyphs, on_unsupported="skip"):
        c: Contour = r.source["outline"]
        n = len(c.on)
        P = np.asarray(c.points, dtype=np.float64)
        base = {"glyph": r.source["glyph"], "contour": int(r.source["contour"]), "name": r.name}
        for k in range(n):
            if not c.on[k]:
                continue
            ang = smooth_angle(c, k)
            if ang is None or (c.on[(k - 1) % n] and c.on[(k + 1) % n]):
                continue
            meant = c.smooth[k] or ang <= np.radians(kink_angle)
            if meant and ang > 1e-9:
                out.append(dict(base, point=k, kind="kink", value=ang))
                continue
            if not meant or c.on[(k - 1) % n] or c.on[(k + 1) % n]:
                continue
            k1 = _end_curvature(_piece(c, k, -1))
            k2 = -_end_curvature(_piece(c, k, 1))  # the outgoing piece, reversed, ends at k
            big = max(abs(k1), abs(k2))
            if big > 0 and abs(k1 - k2) > g2_rel * big:
                out.append(dict(base, point=k, kind="g2", value=abs(k1 - k2) / big))
        a = analyze(r.curve)
        for u in np.atleast_1d(a.inflection_params):
            xy = np.asarray(r.curve(float(u)))
            k = int(np.argmin(np.linalg.norm(P - xy, axis=1)))
            out.append(dict(base, point=k, kind="inflection", value=float(u)))
    return out
