"""Airfoil coordinate files (``.dat``) in the two layouts of the UIUC airfoil database.

Selig
    A name line, then ``x y`` rows from the trailing edge over the upper surface to the
    leading edge and back along the lower surface to the trailing edge.
Lednicer
    A name line, a count line ``NU. NL.`` (number of upper and lower points), then the upper
    surface from leading to trailing edge, then the lower surface from leading to trailing edge
    (usually separated by blank lines; both usually start with the same leading-edge point).

Any lines before the coordinates are kept (the first non-blank one is the name; further
name or remark lines, or a line of more than two numbers, are leading lines), and so is any
text after them (``Thickness: 7.99%``, remarks, URLs: the trailing notes, from the first line
that is not two numbers to the end of the file); both are written back verbatim. Exactly
repeated consecutive points are dropped with a warning and written back with the value of
the point they repeat.

Records
-------
The contour in Selig order (Lednicer: upper reversed, then lower, the shared leading-edge
point once) as ``kind="airfoil"`` records; the first and last points (the trailing edge) are
corners, and so is any interior point turning by ``corner_angle`` or more (the contour is then
split there) -- but the leading edge (the contour point farthest from the middle of the
trailing edge) only from :data:`LEADING_EDGE_CORNER_ANGLE` (120 degrees) on: a round leading
edge sampled more coarsely than its radius (0, 1.25 %, 2.5 % ... of the chord, as many
tables are) turns by up to about 118 degrees at that one point, while a sharp one (biconvex,
double wedge) turns by 135 degrees or more. Split at a round leading edge, each surface
would be faired on its own with the leading edge as a free end, and the two faired pieces
would meet there at an angle. ``name`` is the name line. ``source`` keys: ``layout`` (TextLayout),
``airfoil_layout``
(``"selig"`` or ``"lednicer"``), ``counts`` (Lednicer ``(NU, NL)``), ``row_map`` (file data row ->
contour point; the count line is row 0 of a Lednicer file and maps to -1, as does a Selig
file's count line, first or last: two integers summing to the other rows, far outside the
contour, e.g. ``129 0``), ``indices``,
``n_points``, ``closed`` (always False), ``piece``, ``n_pieces``, ``leading_lines`` (lines
before the data other than the name line) and ``notes`` (the trailing lines), as text.

Writing
-------
The same layout: name line, count line and blank lines kept, each surface in its own order, the
leading-edge point written to both surfaces of a Lednicer file, numbers formatted as
:mod:`curvefair.io.points` does.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any, cast

import numpy as np

from ..errors import FileFormatError, InputError
from ._common import (
    CurveRecord,
    atomic_write,
    check_points,
    drop_duplicates,
    frozen_index,
    joined_points,
    piece_values,
    point_records,
)
from ._text import TextLayout, fresh_text, parse_text

__all__ = ["read", "write"]

FORMAT = "airfoil"


#: The corner angle at an airfoil's leading edge (degrees; ``corner_angle`` if larger): see
#: the module docstring.
LEADING_EDGE_CORNER_ANGLE = 120.0


def leading_edge(contour: np.ndarray) -> int:
    """Index of the leading edge of a contour from trailing edge to trailing edge: the point
    farthest from the middle of its first and last points."""
    mid = 0.5 * (contour[0] + contour[-1])
    return int(np.argmax(np.linalg.norm(contour - mid, axis=1)))


def _is_count_row(v: np.ndarray) -> bool:
    return bool(np.all(np.isfinite(v)) and np.all(v >= 2) and np.all(v == np.round(v)))


def _selig_count_row(vals: np.ndarray) -> int | None:
    """The data row (0 or -1) that is a count line of a Selig file, or None: two integers
    summing to the number of the other rows (``129 0`` before 129 rows; ``66 66`` after two
    surfaces of 66), far outside the contour (more than twice its largest coordinate). Read
    as a point it moved the real trailing edge (HQGA's ``rae2822.dat`` opened its sharp
    trailing edge by 1e-4 chord)."""
    n = vals.shape[0]
    if n < 4:
        return None
    for at in (0, -1):
        v = vals[at]
        rest = np.delete(vals, at % n, axis=0)
        if np.all(np.isfinite(v)) and np.all(v >= 0) and np.all(v == np.round(v)) and \
                int(v.sum()) == n - 1 and \
                float(np.abs(v).max()) > 2.0 * float(np.abs(rest).max()):
            return at
    return None


def read(path: str | os.PathLike[str], *, corner_angle: float | None = 60.0,
         **_: Any) -> list[CurveRecord]:
    """Read a Selig or Lednicer airfoil file; see the module docstring."""
    lay = parse_text(path, header=True, ncols=(2,), what="airfoil file", notes=True)
    vals = lay.values
    lines = lay.line_numbers()
    name = cast(str, lay.header_text).strip() if lay.header is not None else None
    if _is_count_row(vals[0]):
        nu, nl = (int(v) for v in vals[0])
        pts = vals[1:]
        got = pts.shape[0]
        if got != nu + nl:
            raise FileFormatError(
                f"Lednicer count line (line {lines[0]}) announces {nu} + {nl} = {nu + nl} "
                f"points, the file has {got}" + (" (truncated?)" if got < nu + nl else ""),
                path, lines[-1])
        upper, lower = pts[:nu], pts[nu:]
        shared = bool(np.array_equal(upper[0], lower[0]))
        raw = np.vstack([upper[::-1], lower[1:] if shared else lower])
        lo_map = np.arange(nl) + (nu - 1 if shared else nu)
        # upper row i (LE -> TE) is contour point nu-1-i; the count line maps to -1
        raw_map = np.r_[-1, nu - 1 - np.arange(nu), lo_map]
        kind_layout = "lednicer"
        counts: tuple[int, int] | None = (nu, nl)
        raw_lines = [lines[1 + nu - 1 - i] for i in range(nu)] + \
            [lines[1 + nu + j] for j in range(1 if shared else 0, nl)]
    elif (at := _selig_count_row(vals)) is not None:
        # a count line: kept as it is (written back verbatim), not a point
        n = vals.shape[0]
        raw = vals[1:] if at == 0 else vals[:-1]
        raw_map = np.r_[-1, np.arange(n - 1)] if at == 0 else np.r_[np.arange(n - 1), -1]
        kind_layout = "selig"
        counts = None
        raw_lines = lines[1:] if at == 0 else lines[:-1]
    else:
        raw = vals
        raw_map = np.arange(vals.shape[0])
        kind_layout = "selig"
        counts = None
        raw_lines = lines
    # exactly repeated consecutive points: dropped (written back with their twin's value)
    contour, where = drop_duplicates(raw, path, raw_lines)
    row_map = np.where(raw_map < 0, -1, where[np.maximum(raw_map, 0)])
    keep = np.r_[True, where[1:] != where[:-1]] if where.size else where.astype(bool)
    contour_lines = [ln for ln, k in zip(raw_lines, keep, strict=True) if k]
    check_points(contour, path, contour_lines)
    if contour.shape[0] < 3:
        raise FileFormatError(f"an airfoil needs at least 3 points, got {contour.shape[0]}",
                              path)
    notes = () if lay.notes_from is None else lay.lines[lay.notes_from:]
    src = {"format": FORMAT, "path": os.path.abspath(path), "layout": lay,
           "airfoil_layout": kind_layout, "counts": counts,
           "row_map": frozen_index(row_map),
           "leading_lines": tuple(lay.lines[i] for i in lay.leading),
           "notes": tuple(notes)}
    return point_records(contour, closed=False, corner_angle=corner_angle, kind="airfoil",
                         name=name, source=src, end_corners=True,
                         min_angles={leading_edge(contour): LEADING_EDGE_CORNER_ANGLE})


def write(path: str | os.PathLike[str], records: Sequence[CurveRecord], *,
          decimals: int | None = None, **_: Any) -> None:
    """Write an airfoil file; see the module docstring.

    Records read from an airfoil file are written back into its layout; one other curve is
    written as a new Selig file (name line = the record's name, or ``"curvefair airfoil"``).
    """
    lays = {id(r.source.get("layout")): r.source.get("layout") for r in records}
    lay = next(iter(lays.values()))
    if len(lays) == 1 and isinstance(lay, TextLayout) and \
            all(r.format == FORMAT for r in records):
        n_points = int(records[0].source["n_points"])
        contour = piece_values(n_points, 2, records, "write_curves")
        row_map = np.asarray(records[0].source["row_map"], dtype=int)
        rows = np.array(lay.values)
        keep = np.flatnonzero(row_map < 0)
        use = row_map >= 0
        rows[use] = contour[row_map[use]]
        atomic_write(path, lay.render(rows, decimals, keep_rows=keep), encoding=lay.encoding)
        return
    pts = joined_points(records, "write_curves")
    if pts.shape[1] != 2:
        raise InputError(f"an airfoil file holds 2-D points, got dimension {pts.shape[1]}")
    name = records[0].name or "curvefair airfoil"
    if decimals is not None:
        text = name + "\n" + "".join(f" {x:.{int(decimals)}f} {y:.{int(decimals)}f}\n"
                                     for x, y in pts)
    else:
        text = fresh_text(pts, sep=" ", header=name)
    atomic_write(path, text)
