"""curvefair's own JSON format (``.json``), ``schema_version`` 1.

The JSON Schema is ``docs/curvefair-curve.schema.json``; ``docs/formats.md`` explains it.
A file is an object ``{"schema_version": 1, "generator": "...", "curves": [...]}``; each curve
has a ``type``:

``"bspline"``
    ``degree`` (>= 2), ``knots`` (the full vector: ``n + degree + 1`` clamped values for an
    open curve, ``n + 2 degree + 1`` periodic values or one period of ``n + 1`` for a closed
    one), ``control_points`` (``n`` rows; a closed curve lists its distinct ones), ``closed``.
``"cubic_hermite"``
    ``points``, ``tangents``, ``params`` (``degree`` 3 if given), ``closed`` (a closed curve
    repeats its first point, tangent last).
``"quintic_hermite"``
    ``points``, ``d1``, ``d2``, ``params`` (``degree`` 5 if given), ``closed``.
``"points"``
    ``points`` only: read as ``interpolate_cubic(points, "chord", "natural")`` (``"periodic"``
    if ``closed``), written back as the same number of points.

Every curve may have ``name`` (string or null), ``corners`` (0-based point indices to keep:
the record's ``corners``) and ``metadata`` (any object, kept as ``source["metadata"]`` and
written back). Numbers are written with ``repr`` (exact round trip); NaN and infinities are
errors both ways.

Records: ``kind`` = the curve's ``type``; ``source`` keys ``metadata``, ``repeat_first`` (a
``points`` curve whose closed list repeated its first point).
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Sequence
from typing import Any, cast

import numpy as np

from .._version import __version__
from ..curves.bspline import BSplineCurve
from ..curves.hermite import CubicHermite, HermiteSpline, QuinticHermite
from ..errors import CurvefairError, FileFormatError, InputError
from ._common import CurveRecord, atomic_write, check_points, curve_kind, points_curve

__all__ = ["read", "write", "SCHEMA_VERSION", "curve_to_json", "curve_from_json"]

FORMAT = "json"
SCHEMA_VERSION = 1
TYPES = ("bspline", "cubic_hermite", "quintic_hermite", "points")
_FIELDS = {
    "bspline": ("degree", "knots", "control_points"),
    "cubic_hermite": ("points", "tangents", "params"),
    "quintic_hermite": ("points", "d1", "d2", "params"),
    "points": ("points",),
}
_COMMON = ("type", "name", "closed", "corners", "metadata")


def _reject_constant(name: str) -> float:
    raise ValueError(f"{name} is not a number JSON allows")


def _array(obj: dict[str, Any], key: str, where: str, path: object, ndim: int) -> np.ndarray:
    if key not in obj:
        raise FileFormatError(f"{where}: missing {key!r}", path)
    val = obj[key]
    try:
        arr = np.array(val, dtype=np.float64)
    except (TypeError, ValueError):
        raise FileFormatError(f"{where}.{key}: must be "
                              + ("an array of numbers" if ndim == 1 else
                                 "an array of [x, y] or [x, y, z] rows"), path) from None
    if arr.ndim != ndim or (ndim == 2 and arr.shape[1] not in (2, 3)) or \
            any(isinstance(v, bool) for v in np.ravel(np.array(val, dtype=object))):
        raise FileFormatError(f"{where}.{key}: must be "
                              + ("an array of numbers" if ndim == 1 else
                                 "an array of [x, y] or [x, y, z] rows")
                              + f", got shape {arr.shape}", path)
    return arr


def curve_from_json(obj: Any, where: str = "curve", path: str | os.PathLike[str] | None = None,
                    index: int = 0) -> CurveRecord:
    """One curve object of the schema -> :class:`CurveRecord` (FileFormatError if invalid)."""
    if not isinstance(obj, dict):
        raise FileFormatError(f"{where}: must be an object, got {type(obj).__name__}", path)
    typ = obj.get("type")
    if typ not in TYPES:
        raise FileFormatError(f"{where}.type: must be one of {list(TYPES)}, got {typ!r}", path)
    unknown = set(obj) - set(_COMMON) - set(_FIELDS[typ]) - {"degree"}
    if unknown:
        raise FileFormatError(f"{where}: unknown keys {sorted(unknown)} for type {typ!r}", path)
    closed = obj.get("closed", False)
    if not isinstance(closed, bool):
        raise FileFormatError(f"{where}.closed: must be true or false, got {closed!r}", path)
    name = obj.get("name")
    if name is not None and not isinstance(name, str):
        raise FileFormatError(f"{where}.name: must be a string or null, got {name!r}", path)
    meta = obj.get("metadata", {})
    if not isinstance(meta, dict):
        raise FileFormatError(f"{where}.metadata: must be an object", path)
    corners = obj.get("corners", [])
    if not isinstance(corners, list) or not all(
            isinstance(c, int) and not isinstance(c, bool) and c >= 0 for c in corners):
        raise FileFormatError(f"{where}.corners: must be an array of point indices >= 0", path)
    degree = obj.get("degree")
    fixed = {"cubic_hermite": 3, "quintic_hermite": 5}
    if typ in fixed and degree is not None and degree != fixed[typ]:
        raise FileFormatError(f"{where}.degree: a {typ} has degree {fixed[typ]}, got {degree!r}",
                              path)
    if typ == "bspline" and (isinstance(degree, bool) or not isinstance(degree, int)):
        raise FileFormatError(f"{where}.degree: must be an integer >= 2, got {degree!r}", path)
    src: dict[str, Any] = {"format": FORMAT, "path": None if path is None else
                           os.path.abspath(os.fspath(path)), "index": index, "metadata": meta}
    points = None
    try:
        if typ == "bspline":
            ctrl = _array(obj, "control_points", where, path, 2)
            knots = _array(obj, "knots", where, path, 1)
            curve: Any = BSplineCurve(ctrl, knots, cast(int, degree), closed=closed)
        elif typ == "points":
            pts = _array(obj, "points", where, path, 2)
            check_points(pts, path, None, what=f"{where} point")
            repeat = closed and pts.shape[0] > 1 and bool(np.array_equal(pts[0], pts[-1]))
            src["repeat_first"] = repeat
            curve = points_curve(pts, closed)
            points = pts
        else:
            pts = _array(obj, "points", where, path, 2)
            params = _array(obj, "params", where, path, 1)
            if typ == "cubic_hermite":
                curve = CubicHermite(pts, _array(obj, "tangents", where, path, 2), params,
                                     closed=closed)
            else:
                curve = QuinticHermite(pts, _array(obj, "d1", where, path, 2),
                                       _array(obj, "d2", where, path, 2), params, closed=closed)
    except FileFormatError:
        raise
    except CurvefairError as exc:
        raise FileFormatError(f"{where}: {exc}", path) from None
    n = points.shape[0] if points is not None else getattr(curve, "n_points", None)
    if n is None and isinstance(curve, BSplineCurve):
        n = curve.n_ctrl
    bad = [c for c in corners if n is not None and c >= n]
    if bad:
        raise FileFormatError(f"{where}.corners: index {bad[0]} out of range (n = {n})", path)
    return CurveRecord(curve, name, typ, src, points, tuple(corners))


def read(path: str | os.PathLike[str], **_: Any) -> list[CurveRecord]:
    """Read a curvefair JSON file; see the module docstring."""
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except UnicodeDecodeError as exc:
        raise FileFormatError(f"not UTF-8 text ({exc.reason})", path) from None
    except OSError as exc:
        raise FileFormatError(f"cannot read the file: {exc.strerror or exc}", path) from None
    if not text.strip():
        raise FileFormatError("empty JSON file", path)
    try:
        doc = json.loads(text, parse_constant=_reject_constant)
    except json.JSONDecodeError as exc:
        raise FileFormatError(f"invalid JSON: {exc.msg} (column {exc.colno})", path,
                              exc.lineno) from None
    except ValueError as exc:
        raise FileFormatError(f"invalid JSON: {exc}", path) from None
    except RecursionError:
        raise FileFormatError("invalid JSON for curvefair: arrays or objects nested too deeply "
                              "(a curve file nests at most a few levels)", path) from None
    if not isinstance(doc, dict):
        raise FileFormatError("the top level must be an object with 'schema_version' and "
                              "'curves'", path)
    ver = doc.get("schema_version")
    if ver != SCHEMA_VERSION:
        raise FileFormatError(f"schema_version must be {SCHEMA_VERSION} (this curvefair "
                              f"reads version {SCHEMA_VERSION}), got {ver!r}", path)
    curves = doc.get("curves")
    if not isinstance(curves, list):
        raise FileFormatError("'curves' must be an array", path)
    if not curves:
        raise FileFormatError("no curves in the file", path)
    return [curve_from_json(c, f"curves[{i}]", path, i) for i, c in enumerate(curves)]


def _rows(a: Any) -> list[list[float]]:
    return [[float(v) for v in row] for row in np.asarray(a, dtype=float)]


def curve_to_json(rec: CurveRecord) -> dict[str, Any]:
    """One record -> a curve object of the schema."""
    c = rec.curve
    out: dict[str, Any] = {}
    if rec.kind == "points" and rec.format == FORMAT and isinstance(c, HermiteSpline):
        pts = np.asarray(c.points)
        if c.closed and not rec.source.get("repeat_first", False):
            pts = pts[:-1]
        out = {"type": "points", "closed": c.closed, "points": _rows(pts)}
    else:
        kind = curve_kind(c)
        out = {"type": kind, "degree": int(c.degree), "closed": bool(c.closed)}
        if isinstance(c, BSplineCurve):
            out["knots"] = [float(v) for v in c.knots]
            out["control_points"] = _rows(c.control_points)
        elif isinstance(c, QuinticHermite):
            out.update(points=_rows(c.points), d1=_rows(c.d1), d2=_rows(c.d2),
                       params=[float(v) for v in c.params])
        else:
            assert isinstance(c, CubicHermite)
            out.update(points=_rows(c.points), tangents=_rows(c.tangents),
                       params=[float(v) for v in c.params])
    out = {"name": rec.name, **out}
    if rec.corners:
        out["corners"] = list(rec.corners)
    meta = rec.source.get("metadata")
    if meta:
        out["metadata"] = meta
    return out


def _dump(obj: Any, indent: int = 0) -> str:
    """JSON with number arrays on one line and point rows one per line."""
    pad = "  " * indent
    if isinstance(obj, dict):
        if not obj:
            return "{}"
        items = [f'{pad}  {json.dumps(k)}: {_dump(v, indent + 1)}' for k, v in obj.items()]
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(obj, list):
        if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in obj):
            return json.dumps(obj, allow_nan=False)
        if all(isinstance(v, list) and all(isinstance(x, (int, float)) for x in v) for v in obj) \
                and obj:
            return "[\n" + ",\n".join(pad + "  " + json.dumps(v, allow_nan=False)
                                      for v in obj) + "\n" + pad + "]"
        if not obj:
            return "[]"
        return "[\n" + ",\n".join(pad + "  " + _dump(v, indent + 1) for v in obj) + "\n" + pad + "]"
    if isinstance(obj, float) and not math.isfinite(obj):
        raise InputError(f"cannot write the non-finite number {obj!r} to JSON")
    return json.dumps(obj, allow_nan=False)


def write(path: str | os.PathLike[str], records: Sequence[CurveRecord], **_: Any) -> None:
    """Write a curvefair JSON file (atomically); see the module docstring."""
    doc = {"schema_version": SCHEMA_VERSION, "generator": f"curvefair {__version__}",
           "curves": [curve_to_json(r) for r in records]}
    atomic_write(path, _dump(doc) + "\n")
