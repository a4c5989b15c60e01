"""Point lists in text files: CSV or whitespace columns (``.csv``, ``.txt``, ``.xyz``, ``.pts``).

Layout read
-----------
2 or 3 columns (x y [z]) separated by blanks, commas or semicolons; ``#`` starts a comment
(whole line or after the numbers); one non-numeric line before the data is a header (kept);
blank lines are kept. A row exactly equal to the row before it is dropped with a warning (and
written back with its twin's value). A file whose last row repeats the first (4 rows or more)
is a closed loop. One point list per file.

Records
-------
One record per piece between corners (see :func:`curvefair.io.read_curves`), ``kind="points"``,
``curve = interpolate_cubic(points, "chord", "natural")`` (``"periodic"`` for a closed loop
without corners). ``source`` keys: ``layout`` (the :class:`~curvefair.io._text.TextLayout`),
``row_map`` (for each data row of the file, its index in the distinct point list),
``indices``, ``n_points``, ``closed``, ``piece``, ``n_pieces``, ``header``.

Writing
-------
The faired data points (same number, same order) go back into the same lines: comments,
header, separators, padding kept; each number keeps its token's decimals when that writes it
exactly, else the column's largest number of decimals in the file when that writes it exactly,
else the shortest exact form, unless ``decimals=`` is given (``curvefair.io._text.format_number``).
:func:`render_row` renders one row by the same rule, or rounded to the file's precision for a
writer that checks the rounding against its tolerance itself (chunked fairing).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any

import numpy as np

from .._typing import FloatArray
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
from ._text import (
    TextLayout,
    _column_decimals,
    _render_line,
    _split_numbers,
    fresh_text,
    parse_text,
)

__all__ = ["read", "write", "render_row", "column_decimals"]

FORMAT = "points"


def read(path: str | os.PathLike[str], *, corner_angle: float | None = 60.0,
         **_: Any) -> list[CurveRecord]:
    """Read a CSV / whitespace point list; see the module docstring."""
    lay = parse_text(path, header=True, ncols=(2, 3), what="points file")
    vals = lay.values
    lines = lay.line_numbers()
    # exactly repeated consecutive rows: dropped, written back with their twin's value
    vals, where = drop_duplicates(vals, path, lines)
    keep = np.r_[True, where[1:] != where[:-1]]
    check_points(vals, path, [ln for ln, k in zip(lines, keep, strict=True) if k])
    R = vals.shape[0]
    if R < 2:
        raise FileFormatError(f"a curve needs at least 2 points, the file has {R}", path)
    loop = R >= 4 and bool(np.array_equal(vals[0], vals[-1]))
    if loop:
        distinct = vals[:-1]
        row_map = np.where(where == R - 1, 0, where)
    else:
        distinct = vals
        row_map = where
    name = os.path.splitext(os.path.basename(path))[0]
    src = {"format": FORMAT, "path": os.path.abspath(path), "layout": lay,
           "row_map": frozen_index(row_map), "header": lay.header_text}
    return point_records(distinct, closed=loop, corner_angle=corner_angle, kind="points",
                         name=name, source=src)


def _layout_of(records: Sequence[CurveRecord]) -> TextLayout | None:
    lays = {id(r.source.get("layout")): r.source.get("layout") for r in records}
    if len(lays) > 1:
        raise InputError("records: a points file holds one point list; these records come from "
                         f"{len(lays)} different files (or were built without one)")
    lay = next(iter(lays.values()))
    return lay if isinstance(lay, TextLayout) else None


def assemble(records: Sequence[CurveRecord], lay: TextLayout, what: str) -> FloatArray:
    """File rows (shape ``(rows, ncols)``) from the records of one layout."""
    n_points = int(records[0].source["n_points"])
    values = piece_values(n_points, lay.ncols, records, what)
    row_map = np.asarray(records[0].source["row_map"], dtype=int)
    return values[row_map]


def write(path: str | os.PathLike[str], records: Sequence[CurveRecord], *,
          decimals: int | None = None, **_: Any) -> None:
    """Write a points file; see the module docstring.

    Records read from a points file are written back into their layout; other curves (one at
    most) are written as a fresh file of their data points (shortest exact numbers; ``,``
    separated for ``.csv``, blank separated otherwise).
    """
    lay = _layout_of(records)
    if lay is not None and all(r.format == FORMAT for r in records):
        rows = assemble(records, lay, "write_curves")
        atomic_write(path, lay.render(rows, decimals), encoding=lay.encoding)
        return
    pts = joined_points(records, "write_curves")
    sep = "," if str(path).lower().endswith(".csv") else " "
    header = None
    if sep == ",":
        header = ",".join("xyz"[: pts.shape[1]])
    if decimals is not None:
        text = (header + "\n" if header else "") + "".join(
            sep.join(f"{v:.{int(decimals)}f}" for v in row) + "\n" for row in pts)
    else:
        text = fresh_text(pts, sep=sep, header=header)
    atomic_write(path, text)


def column_decimals(texts: list[str], width: int) -> tuple[int, ...]:
    """The largest number of decimals per column (of the mantissa for exponent style) of the
    number texts of rows of ``width`` numbers, row after row: the file's precision, as the
    reader records it (:attr:`TextLayout.column_decimals`)."""
    return _column_decimals(texts, width)


def render_row(line: str, values: Sequence[float], column_decimals: Sequence[int],
               extra: int | None = None) -> tuple[str, list[float]] | None:
    """One data line of a points file with ``values`` in place, in the line's own layout
    (the rule :meth:`TextLayout.render` follows for a row: separators, padding, the number
    style and any trailing comment kept; a value equal to the one read keeps its text).

    ``extra`` None: a changed value keeps its token's or the column's decimals only where that
    writes it exactly, else the shortest exact form (what :func:`write` does). ``extra`` an
    integer: a changed value is rounded to the column's decimals (``column_decimals``, the
    file's largest per column) plus ``extra`` (:func:`curvefair.io._text.rounded_number`), for
    a writer that measures the rounded result against its tolerance itself.

    Returns the line (without line ending) and the values it reads back as, or None when
    ``line`` is not a row of ``len(values)`` numbers by this reader's rules.
    """
    texts = _split_numbers(line)
    if texts is None or len(texts) != len(values):
        return None
    out = _render_line(line, values, column_decimals, None, extra)
    back = _split_numbers(out)
    if back is None or len(back) != len(texts):  # pragma: no cover - the layout's own text
        return None
    return out, [float(t) for t in back]
