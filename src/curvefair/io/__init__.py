"""Reading and writing curves: point lists, airfoils, JSON, DXF, Rhino 3dm, SVG, IGES, STEP.

:func:`read_curves` returns a list of :class:`CurveRecord` -- the curve to fair plus what is
needed to write it back faithfully; :func:`write_curves` writes faired records back, into a
copy of the source file when ``template=`` names it (every other entity untouched).

Formats (chosen by extension, or ``format=``):

================  ===========================  ==========================================
format            extensions                   needs
================  ===========================  ==========================================
``points``        .csv .txt .xyz .pts          --
``airfoil``       .dat (Selig or Lednicer)     --
``json``          .json (curvefair schema 1)   --
``dxf``           .dxf                         ``pip install 'curvefair[dxf]'`` (ezdxf)
``3dm``           .3dm                         ``pip install 'curvefair[rhino]'`` (rhino3dm)
``svg``           .svg                         ``pip install 'curvefair[svg]'`` (svgpathtools)
``iges``          .igs .iges                   ``pip install 'curvefair[occ]'`` (cadquery-ocp)
``step``          .stp .step                   ``pip install 'curvefair[occ]'`` (cadquery-ocp)
``ufo``           .ufo (a folder)              ``pip install 'curvefair[fonts]'`` (ufoLib2)
``opentype``      .ttf .otf                    ``pip install 'curvefair[fonts]'`` (fontTools)
``glyphs``        .glyphs                      ``pip install 'curvefair[fonts]'`` (glyphsLib)
``designspace``   .designspace (read only)     ``pip install 'curvefair[fonts]'`` (fontTools)
================  ===========================  ==========================================

The record
----------
``CurveRecord(curve, name, kind, source, points, corners)``:

- ``curve``: the curve to fair. Point data (points files, airfoils, polylines, DXF fit
  points) become ``interpolate_cubic(points, "chord", "natural")`` (``"periodic"`` for a
  closed loop); spline entities become :class:`~curvefair.BSplineCurve` with the file's
  degree, knots and control points.
- ``kind``: what the file held: ``"points"``, ``"airfoil"``, ``"polyline"``,
  ``"fit_points"``, ``"bspline"``, ``"cubic_hermite"``, ``"quintic_hermite"``.
- ``source``: format-specific facts for the write-back (file path, entity handle, layer,
  object id, original text layout, name line, ...); always ``format``, ``path``, ``index``.
- ``points``: the raw data points of point kinds.
- ``corners``: indices of points to keep fixed (sharp corners, an airfoil's trailing edge):
  give them to the fairing as ``protect``.

Corners: a point list turning by ``corner_angle`` degrees (default 60: a regular pentagon's
72 degree corners are corners, an airfoil's leading edge sampled at 60 points turns by less
than 30) or more at a point is split into several records there, so that each record is
smooth between its ends and the corner stays a corner; writing the records back joins the
pieces again. On a noisy list the turn is measured between chords longer than the noise, so a
turn between two noisy samples is not a corner. Open airfoils also mark their first and last
points (the trailing edge).

Writing is always atomic (a temporary file in the destination folder, then ``os.replace``) and
never replaces a file the curves were read from unless ``overwrite=True``. By default the
temporary file is read back and every curve measured against the input before it replaces the
destination (``tol=``: nothing is written when a curve reads back farther; ``verify=False``
skips the check).

Examples
--------
>>> import os, tempfile
>>> import numpy as np
>>> from curvefair import read_curves, write_curves
>>> d = tempfile.mkdtemp()
>>> src = os.path.join(d, "wave.csv")
>>> x = np.linspace(0, 3, 12)
>>> np.savetxt(src, np.c_[x, np.sin(x)], delimiter=",", header="x,y", comments="")
>>> recs = read_curves(src)
>>> recs[0].kind, recs[0].curve.points.shape
('points', (12, 2))
>>> check = write_curves(os.path.join(d, "wave_faired.csv"), recs, tol=1e-9)
>>> check.max_deviation <= 1e-9         # read back and measured before replacing the file
True
>>> np.allclose(read_curves(os.path.join(d, "wave_faired.csv"))[0].points, recs[0].points)
True
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path
from types import ModuleType
from typing import Any, Literal, cast

import numpy as np

from .._validate import as_positive, choice
from ..curves.piecewise import PiecewiseCurve
from ..errors import FileFormatError, InputError
from ._common import (
    KINDS,
    ColumnsKept,
    CurveRecord,
    DrawnShapesLeft,
    DrawnShapesOnly,
    ReadNote,
    atomic_path,
    atomic_write,
    copy_input,
    curve_kind,
    same_path,
)
from ._verify import WriteCheck, WriteCheckError, on_disk_report, rescaled_report, write_checked

__all__ = ["read_curves", "write_curves", "WriteCheck", "WriteCheckError", "CurveRecord", "KINDS",
           "FORMATS", "detect_format", "DRAWN_SHAPE_FORMATS", "DrawnShapesLeft", "DrawnShapesOnly",
           "ReadNote", "ColumnsKept", "atomic_write", "atomic_path", "copy_input",
           "write_checked", "rescaled_report", "on_disk_report"]

FormatName = Literal["points", "airfoil", "json", "dxf", "3dm", "svg", "iges", "step", "ufo",
                     "opentype", "glyphs", "designspace"]

#: format name -> file extensions
FORMATS: dict[str, tuple[str, ...]] = {
    "points": (".csv", ".txt", ".xyz", ".pts"),
    "airfoil": (".dat",),
    "json": (".json",),
    "dxf": (".dxf",),
    "3dm": (".3dm",),
    "svg": (".svg",),
    "iges": (".igs", ".iges"),
    "step": (".stp", ".step"),
    "ufo": (".ufo",),
    "opentype": (".ttf", ".otf"),
    "glyphs": (".glyphs",),
    "designspace": (".designspace",),
}

#: formats stored as a folder, and the formats that take ``glyphs=``
FOLDER_FORMATS = ("ufo",)
FONT_FORMATS = ("ufo", "opentype", "glyphs", "designspace")
#: Drawings whose straight-line shapes (polygons, polylines) are drawn shapes, left as drawn
#: unless read with ``polylines=True`` (docs/formats.md, "Straight-line shapes are drawn
#: shapes").
DRAWN_SHAPE_FORMATS = ("svg", "dxf", "3dm")


def detect_format(path: str | os.PathLike[str], format: str | None = None) -> FormatName:
    """The format name for ``path`` (by extension) or the validated ``format``."""
    if format is not None:
        return cast(FormatName, choice(format, FORMATS, "format"))
    ext = Path(path).suffix.lower()
    for name, exts in FORMATS.items():
        if ext in exts:
            return cast(FormatName, name)
    known = ", ".join(e for exts in FORMATS.values() for e in exts)
    raise InputError(f"cannot tell the format of {os.fspath(path)!r} from its extension "
                     f"{ext!r}; known: {known}; or pass format=")


def _module(fmt: str) -> Any:
    # the modules themselves import their optional libraries lazily
    m: ModuleType
    if fmt == "points":
        from . import points as m
    elif fmt == "airfoil":
        from . import airfoil as m
    elif fmt == "json":
        from . import jsonfmt as m
    elif fmt == "dxf":
        from . import dxf as m
    elif fmt == "3dm":
        from . import rhino as m
    elif fmt == "svg":
        from . import svg as m
    elif fmt in FONT_FORMATS:
        from . import fonts as m
    else:
        from . import occ as m
    return m


def read_curves(path: str | os.PathLike[str], *, format: FormatName | None = None,
                corner_angle: float | None = 60.0,
                on_unsupported: Literal["raise", "skip"] = "raise",
                glyphs: Sequence[str] | str | None = None,
                polylines: bool | None = None,
                columns: Sequence[int] | None = None) -> list[CurveRecord]:
    """Read every curve of a file.

    Parameters
    ----------
    path : path-like
    format : str, optional
        One of :data:`FORMATS`; default: from the extension.
    corner_angle : float or None
        Point lists are split at points turning by this many degrees or more (default 60;
        None: never). On a noisy list the turn is measured between chords longer than the noise
        (:func:`curvefair.io._common.corner_turning`), so noise is not taken for corners.
    on_unsupported : {"raise", "skip"}
        What to do with a curve entity curvefair cannot represent exactly (a rational or
        unclamped DXF spline, a polyline with arcs, an SVG arc...): raise
        :class:`~curvefair.FileFormatError` naming it, or skip it with a warning.
    glyphs : sequence of str or str, optional
        Fonts (``ufo``, ``opentype``, ``glyphs``): only these glyphs (names, or one comma-separated
        string); one record per contour with curves, named ``"<glyph>#<contour>"``.
    polylines : bool, optional
        Drawings (``svg``, ``dxf``, ``3dm``: :data:`DRAWN_SHAPE_FORMATS`): read straight-line
        shapes -- SVG polygons, polylines, lines, rectangles and subpaths of lines only; DXF
        ``LWPOLYLINE`` and 2-D / 3-D ``POLYLINE``; 3dm ``PolylineCurve`` and degree-1
        ``NurbsCurve`` -- as point lists (True), or leave them as drawn (the default: in a
        drawing a polygon's vertices are its design, not samples of a curve; see
        docs/formats.md). A file of point data (``points``, ``airfoil``) is point lists
        always.
    columns : sequence of int, optional
        Point lists (``points``): the 0-based columns holding x, y (z), as numpy's
        ``usecols``; the other columns (point numbers, arc lengths) are kept as they are and
        written back character for character. Default: a header naming the columns ``x``,
        ``y`` (``z``), else every column of a 2- or 3-column file (a 3-column file whose first
        column holds consecutive integers is refused as ambiguous), or the columns after a
        first column of point numbers (:func:`curvefair.io.points.coordinate_columns`).

    Returns
    -------
    list of CurveRecord
        In file order (see the module docstring for the record).

    Raises
    ------
    FileFormatError
        Missing, empty, truncated or garbled file, NaN coordinates, duplicate consecutive
        points, no curves; the message names the file and, for text formats, the line.
    MissingDependencyError
        The format's optional library is not installed (the message names the extra).

    Examples
    --------
    >>> import os, tempfile
    >>> import numpy as np
    >>> from curvefair import read_curves
    >>> p = os.path.join(tempfile.mkdtemp(), "foil.dat")
    >>> th = np.linspace(0, 2 * np.pi, 81)          # a thin ellipse as a Selig airfoil
    >>> rows = "".join(f"{(1 + np.cos(t)) / 2:.6f} {0.06 * np.sin(t):.6f}\\n" for t in th)
    >>> _ = open(p, "w").write("TOY\\n" + rows)
    >>> r = read_curves(p)
    >>> len(r), r[0].kind, r[0].name, r[0].corners        # the trailing edge is kept sharp
    (1, 'airfoil', 'TOY', (0, 80))
    """
    fmt = detect_format(path, format)
    choice(on_unsupported, ("raise", "skip"), "on_unsupported")
    if corner_angle is not None:
        corner_angle = float(corner_angle)
        if not 0.0 < corner_angle <= 180.0:
            raise InputError(f"corner_angle must be in (0, 180] degrees or None, got "
                             f"{corner_angle!r}")
    p = Path(path)
    if not p.exists():
        raise FileFormatError("no such file", path)
    if p.is_dir() and fmt not in FOLDER_FORMATS:
        raise FileFormatError("is a folder, not a file", path)
    if glyphs is not None and fmt not in FONT_FORMATS:
        raise InputError(f"glyphs= is for fonts (ufo, opentype, glyphs), not {fmt} files")
    extra: dict[str, Any] = {} if glyphs is None else {"glyphs": glyphs}
    if polylines is not None:
        if not isinstance(polylines, (bool, np.bool_)):
            raise InputError(f"polylines must be True, False or None, got {polylines!r}")
        if fmt not in DRAWN_SHAPE_FORMATS:
            raise InputError(f"polylines= is for drawings ({', '.join(DRAWN_SHAPE_FORMATS)}), "
                             f"not {fmt} files")
        extra["polylines"] = bool(polylines)
    if columns is not None:
        if fmt != "points":
            raise InputError(f"columns= is for point lists (points files), not {fmt} files")
        extra["columns"] = columns
    if fmt in ("iges", "step"):
        extra["format"] = fmt       # one module reads both; the path may have no extension
    records = _module(fmt).read(path, corner_angle=corner_angle, on_unsupported=on_unsupported,
                                **extra)
    if not records:
        raise FileFormatError(f"no curves in the {fmt} file", path)
    return records


def _as_records(curves: object) -> list[CurveRecord]:
    if isinstance(curves, (CurveRecord, PiecewiseCurve)):
        curves = [curves]
    if not isinstance(curves, Sequence) or isinstance(curves, (str, bytes)):
        raise InputError(f"curves must be a CurveRecord, a curve, or a sequence of them, got "
                         f"{type(curves).__name__}")
    out = []
    for i, c in enumerate(curves):
        if isinstance(c, CurveRecord):
            out.append(c)
        elif isinstance(c, PiecewiseCurve):
            out.append(CurveRecord(c, None, curve_kind(c), {"format": None, "path": None,
                                                            "index": i}))
        else:
            raise InputError(f"curves[{i}] must be a CurveRecord or a curve, got "
                             f"{type(c).__name__}")
    if not out:
        raise InputError("curves is empty: nothing to write")
    return out


def _template_path(template: object) -> str | None:
    if template is None:
        return None
    if isinstance(template, CurveRecord):
        template = [template]
    if isinstance(template, (str, os.PathLike)):
        t = os.path.abspath(os.fspath(template))
        if not (os.path.isfile(t) or (os.path.isdir(t) and
                                      Path(t).suffix.lower() in FORMATS["ufo"])):
            raise InputError(f"template: no such file {t!r}")
        return t
    if isinstance(template, Sequence) and template and \
            all(isinstance(r, CurveRecord) for r in template):
        paths = {r.path for r in template}
        if len(paths) != 1 or None in paths:
            raise InputError("template: the records must all come from one file")
        return _template_path(paths.pop())
    raise InputError(f"template must be a path, a CurveRecord or a list of records from one "
                     f"file, got {type(template).__name__}")


def write_curves(path: str | os.PathLike[str], curves: CurveRecord | PiecewiseCurve |
                 Sequence[CurveRecord | PiecewiseCurve], *, template: object = None,
                 format: FormatName | None = None, overwrite: bool = False,
                 decimals: int | None = None,
                 precision: Literal["file", "exact"] = "file", verify: bool = True,
                 tol: float | None = None,
                 reference: CurveRecord | PiecewiseCurve |
                 Sequence[CurveRecord | PiecewiseCurve] | None = None,
                 corner_angle: float | None = 60.0) -> WriteCheck | None:
    """Write curves (usually faired records from :func:`read_curves`) to a file, atomically,
    and check the file by reading it back.

    Parameters
    ----------
    path : path-like
        Destination; the format comes from its extension unless ``format`` is given.
    curves : CurveRecord, curve, or sequence of them
        Records keep what the source file needs (layout, handles, ids). Bare curves are written
        as new curves (new entities in DXF/3dm/SVG, a new file for point formats).
    template : path, CurveRecord or list of records, optional
        The source file. DXF, 3dm and SVG: the output is a copy of it in which the entities the
        records came from are replaced (same handle / id / element, same degree, knot vector
        and closedness) and everything else is untouched. Point formats: bare curves are
        written into the template's layout, in order. Without a template DXF/3dm/SVG/IGES/STEP
        files hold just the given curves; point formats use the layout stored in the records.
    format : str, optional
    overwrite : bool
        Allow ``path`` to be a file the curves were read from (or the template).
    decimals : int, optional
        Text point formats: number of decimals for every number (default: as in the source).
    precision : {"file", "exact"}
        With ``decimals=None``: ``"file"`` writes a rewritten SVG element with the element's
        own number of decimals (text point formats keep a token's decimals only where that
        writes the value exactly); ``"exact"`` writes every changed number in the shortest
        form that reads back as exactly the value. Binary and full-precision formats ignore it.
    verify : bool
        Default True: write to a temporary file next to ``path``, read it back with
        :func:`read_curves` and measure every curve read back against its reference curve
        (:mod:`curvefair.io._verify`: parametric deviation where the parameter domains agree,
        else the geometric distance -- point files are re-interpolated on reading); only a
        file within ``tol`` replaces ``path``. False: write without reading back (faster;
        returns None).
    tol : float, optional
        The tolerance the file must hold: every curve read back at most ``tol`` from its
        reference. When an SVG element's own decimals break it, the element is written with
        exact numbers instead; when re-interpolated point data breaks it, the moves of the
        points from the reference are scaled down until it holds (a ``UserWarning`` says so;
        :attr:`WriteCheck.move_scale`). None: measure and report only.
    reference : CurveRecord, curve or sequence of them, optional
        The curves ``tol`` is measured from, one per written curve. Default with ``tol``:
        records read from a file are compared with that file's curves as it is now (read again
        before writing, with ``corner_angle``), bare curves with themselves (what the file's
        rounding does to them). Default without ``tol``: the curves given.
    corner_angle : float or None
        The corner angle used to read the written file (and the default reference) back: use
        the one the records were read with.

    Returns
    -------
    WriteCheck or None
        What the read-back measured (``max_deviation``, per-curve ``deviations``, ``notes``);
        None with ``verify=False``.

    Raises
    ------
    InputError
        Nothing to write, a point count that differs from the source's, ``path`` is an input
        file and ``overwrite`` is False, a curve the format cannot hold.
    WriteCheckError
        (an InputError) The file would not read back, or reads back farther than ``tol`` from
        the reference; nothing was written and ``path`` is untouched.
    MissingDependencyError
        The format's optional library is not installed.
    """
    fmt = detect_format(path, format)
    records = _as_records(curves)
    tpath = _template_path(template)
    inputs = list(dict.fromkeys([tpath] + [r.path for r in records]))  # each path once
    if not overwrite and any(p is not None and same_path(path, p) for p in inputs):
        raise InputError(f"path {os.fspath(path)!r} is one of the input files; pass "
                         "overwrite=True to replace it")
    if decimals is not None and (isinstance(decimals, bool) or not isinstance(decimals, int)
                                 or decimals < 0):
        raise InputError(f"decimals must be an integer >= 0, got {decimals!r}")
    choice(precision, ("file", "exact"), "precision")
    if not isinstance(verify, (bool, np.bool_)):
        raise InputError(f"verify must be True or False, got {verify!r}")
    tol_f = as_positive(tol, "tol", allow_none=True)
    if corner_angle is not None:
        corner_angle = float(corner_angle)
        if not 0.0 < corner_angle <= 180.0:
            raise InputError(f"corner_angle must be in (0, 180] degrees or None, got "
                             f"{corner_angle!r}")
    mod = _module(fmt)
    if fmt in ("points", "airfoil") and tpath is not None and \
            all(r.format != fmt for r in records):
        records = _fill_template(records, mod.read(tpath, corner_angle=None), tpath)
    if not verify:
        _write_plain(path, records, fmt, tpath, decimals, precision)
        return None
    from ._verify import write_checked

    ref = _reference(records, reference, tol_f, corner_angle)

    poly = reads_polylines(records, fmt)
    cols = read_columns(records, fmt)

    def reader(p: str) -> list[CurveRecord]:
        with warnings.catch_warnings():  # the input's skip warnings, again
            warnings.simplefilter("ignore")
            return read_curves(p, format=fmt, corner_angle=corner_angle,
                               on_unsupported="skip", polylines=poly, columns=cols)

    check = write_checked(path, records, ref, tol=tol_f, reader=reader, template=tpath,
                          format=fmt, overwrite=True, decimals=decimals, precision=precision)
    for note in check.notes:
        warnings.warn(f"{os.fspath(path)}: {note}", UserWarning, stacklevel=2)
    return check


def reads_polylines(records: Sequence[CurveRecord], fmt: str | None) -> bool | None:
    """Whether a ``fmt`` file written from ``records`` is read back with ``polylines=True``, so
    that its curves pair up with them: records read from a drawing that way
    (``source["polylines"]``), or point data, which the writers write as polylines (in an SVG
    every point kind is a path of lines; in DXF and 3dm fit points are a fit-point spline).
    None (the reader's default) for other records, and for formats without the choice."""
    from ._verify import POINT_KINDS

    if fmt not in DRAWN_SHAPE_FORMATS:
        return None
    kinds = POINT_KINDS if fmt == "svg" else ("points", "airfoil", "polyline")
    for r in records:
        if r.kind in kinds or (r.format in DRAWN_SHAPE_FORMATS and r.source.get("polylines")):
            return True
    return None


def read_columns(records: Sequence[CurveRecord], fmt: str | None) -> tuple[int, ...] | None:
    """``read_curves``' ``columns`` for a ``fmt`` file written from ``records``: the columns
    they were read from (``source["columns"]``) when they come from a points file and it is
    written as one (the written file keeps its layout, so the same columns hold the points);
    None otherwise."""
    if fmt != "points":
        return None
    got = {tuple(r.source["columns"]) for r in records
           if r.format == "points" and r.source.get("columns") is not None}
    return got.pop() if len(got) == 1 else None


def columns_for(fmt: str | None, columns: Sequence[int] | None) -> tuple[int, ...] | None:
    """``read_curves``' ``columns`` for a caller's choice (the CLI's ``--columns``, a batch
    option) applied to a file of format ``fmt``: the columns for a points file, None (the
    reader's default) for other formats, which have no columns."""
    return tuple(columns) if columns is not None and fmt == "points" else None


def polylines_for(fmt: str | None, polylines: bool) -> bool | None:
    """``read_curves``' ``polylines`` for a caller's choice (the CLI's ``--polylines``, a batch
    option) applied to a file of format ``fmt``: True where the format has the choice
    (:data:`DRAWN_SHAPE_FORMATS`), None (the reader's default) otherwise -- point data are
    point lists always."""
    return True if polylines and fmt in DRAWN_SHAPE_FORMATS else None


def _write_plain(path: str | os.PathLike[str], records: Sequence[CurveRecord], fmt: str,
                 tpath: str | None, decimals: int | None, precision: str) -> None:
    """The format's writer, without the read-back (records already filled from a point
    template)."""
    writer: Callable[..., None] = _module(fmt).write
    extra = {"format": fmt} if fmt in ("iges", "step") else {}
    writer(path, list(records), template=tpath, decimals=decimals, precision=precision,
           **extra)


def _reference(records: list[CurveRecord], reference: object, tol: float | None,
               corner_angle: float | None) -> list[CurveRecord]:
    """The records the written file is measured against (see :func:`write_curves`)."""
    if reference is not None:
        ref = _as_records(reference)
        if len(ref) != len(records):
            raise InputError(f"reference has {len(ref)} curves for {len(records)} written")
        return ref
    if tol is None:
        return records
    out: list[CurveRecord] = []
    cache: dict[str, list[CurveRecord]] = {}
    for i, r in enumerate(records):
        src = r.path
        if src is None or r.format is None or not os.path.isfile(src):
            out.append(r)  # a bare curve: the file's rounding of it
            continue
        if src not in cache:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                mine = [x for x in records if x.path == src]
                cache[src] = read_curves(src, format=r.format,  # type: ignore[arg-type]
                                         corner_angle=corner_angle, on_unsupported="skip",
                                         polylines=reads_polylines(mine, r.format),
                                         columns=read_columns(mine, r.format))
        j = r.source.get("index")
        got = cache[src]
        o = got[j] if isinstance(j, int) and 0 <= j < len(got) else None
        if o is None or o.kind != r.kind or o.name != r.name or \
                (o.points is not None and r.points is not None
                 and np.shape(o.points) != np.shape(r.points)):
            raise InputError(
                f"write_curves: curves[{i}] ({r.name or r.kind}) does not match curve {j} of "
                f"its source file {src!r} read again; pass reference= (the records as read) "
                "or the corner_angle they were read with")
        out.append(o)
    return out


def _fill_template(records: list[CurveRecord], tmpl: list[CurveRecord],
                   tpath: str) -> list[CurveRecord]:
    if len(tmpl) != len(records):
        raise InputError(f"template {tpath!r} holds {len(tmpl)} point list(s), got "
                         f"{len(records)} curves")
    return [t.with_curve(r.curve) for t, r in zip(tmpl, records, strict=False)]
