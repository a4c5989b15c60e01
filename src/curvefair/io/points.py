"""Point lists in text files: CSV or whitespace columns (``.csv``, ``.txt``, ``.xyz``, ``.pts``).

Layout read
-----------
2 or 3 coordinate columns (x y [z]) separated by blanks, commas or semicolons; ``#`` starts a
comment (whole line or after the numbers); one non-numeric line before the data is a header
(kept); blank lines are kept. Other numeric columns -- point numbers, arc lengths -- are kept
as they are (written back character for character) when it is clear which columns are the
coordinates (:func:`coordinate_columns`): ``columns=`` says so, or a header naming them
``x``, ``y`` (``z``), or a first column of consecutive integers beside 3 others. A 3-column
file without a header whose first column holds consecutive integers is refused: point numbers
and x coordinates look the same there, and guessing wrong either rewrites the point numbers or
fairs a projection. Decimal commas (``10,25;0,5``, :func:`decimal_commas`) and Fortran's
``D`` exponents (:func:`fortran_exponents`) are read and written back as they were. A row
exactly equal to the row before it is dropped with a warning (and written back with its
twin's value). A file whose last row repeats the first (4 rows or more) is a closed loop.
One point list per file.

Records
-------
One record per piece between corners (see :func:`curvefair.io.read_curves`), ``kind="points"``,
``curve = interpolate_cubic(points, "chord", "natural")`` (``"periodic"`` for a closed loop
without corners). ``source`` keys: ``layout`` (the :class:`~curvefair.io._text.TextLayout`),
``row_map`` (for each data row of the file, its index in the distinct point list),
``indices``, ``n_points``, ``closed``, ``piece``, ``n_pieces``, ``header``, ``columns`` (the
0-based file columns read as x, y [z]).

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

import operator
import os
import re
from collections.abc import Sequence
from typing import Any

import numpy as np

from .._typing import FloatArray
from ..errors import FileFormatError, InputError
from ._common import (
    ColumnsKept,
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
    decimal_commas,
    fortran_exponents,
    fresh_text,
    parse_text,
    wordy,
)

__all__ = ["read", "write", "render_row", "column_decimals", "coordinate_columns",
           "is_point_numbers", "decimal_commas", "fortran_exponents", "wordy"]

FORMAT = "points"


#: header names of coordinate columns: the name's first run of letters (``X [mm]``, ``y_m``)
_AXES = ("x", "y", "z")
_NAME_RE = re.compile(r"[A-Za-z]+")  # matched at the start of a name
_HEADER_SPLIT = re.compile(r"\s*[,;\t]\s*|\s+")


def _header_parts(header: str | None, ncols: int) -> list[str] | None:
    """The header's column names as written (quotes dropped), when it has one per column."""
    if header is None:
        return None
    text = header.strip().lstrip("\ufeff")
    if text[-1:] in (",", ";"):  # a separator after the last name, as after the last number
        text = text[:-1].rstrip()
    sep = next((c for c in ",;\t" if c in text), None)
    parts = [p.strip() for p in text.split(sep)] if sep is not None else text.split()
    return [p.strip("\"'") for p in parts] if len(parts) == ncols else None


def _header_names(header: str | None, ncols: int) -> list[str] | None:
    """The header's column names reduced to their leading run of letters, lower-case
    (``X [mm]`` -> ``x``; ``""`` for a name that does not start with a letter)."""
    parts = _header_parts(header, ncols)
    if parts is None:
        return None
    out = []
    for p in parts:
        m = _NAME_RE.match(p)
        out.append(m.group(0).lower() if m is not None else "")
    return out


def is_point_numbers(col: FloatArray) -> bool:
    """A column of at least 3 integers, each one more than the one before (point numbers)."""
    return (col.shape[0] >= 3 and bool(np.all(np.isfinite(col)))
            and bool(np.all(col == np.round(col))) and bool(np.all(np.diff(col) == 1.0)))


def coordinate_columns(ncols: int, header: str | Sequence[str] | None,
                       first_column: FloatArray, columns: Sequence[int] | None = None,
                       path: str | os.PathLike[str] | None = None,
                       line: int | None = None) -> tuple[int, ...]:
    """Which columns of a points file (``ncols`` numeric columns) are the coordinates.

    ``header``: the header line, or the lines before the data (the first one naming ``ncols``
    columns counts).

    In order of precedence:

    1. ``columns`` (0-based column indices, 2 or 3 of them, as numpy's ``usecols``): those.
    2. A header naming one column ``x`` and one ``y`` (and at most one ``z``; a name counts
       by its first run of letters, so ``X [mm]`` and ``y_m`` do): those, in file order; the
       other columns (``id``, ``s``, ...) are kept as they are.
    3. 2 or 3 columns: all of them -- except 3 columns whose first one holds consecutive
       integers (``1, 2, 3, ...``), which is refused (:class:`FileFormatError`): point numbers
       beside x, y, or x coordinates of a 3-D curve? Either guess damages the other reading
       (the point numbers rewritten as coordinates, or a 3-D curve faired as its projection).
    4. 4 columns whose first holds consecutive integers (point numbers): the other 3.

    A header naming one column ``x`` among 3 and neither ``y`` nor ``z`` (Engauge
    Digitizer's ``x,Curve1,Curve2``: two curves over the same x) is refused too.

    Anything else is refused, naming ``columns=`` and the header as the ways to say it.
    """
    if columns is not None:
        try:
            cols = tuple(operator.index(c) for c in columns)
        except TypeError:
            raise InputError(f"columns must be 2 or 3 column indices (0-based), got "
                             f"{columns!r}") from None
        if len(cols) not in (2, 3) or len(set(cols)) != len(cols):
            raise InputError(f"columns must be 2 or 3 different column indices (0-based), got "
                             f"{columns!r}")
        bad = [c for c in cols if not 0 <= c < ncols]
        if bad:
            raise FileFormatError(f"columns={list(cols)}: the rows have {ncols} columns "
                                  f"(0 .. {ncols - 1}), no column {bad[0]}", path, line)
        return cols
    heads = [header] if isinstance(header, str) or header is None else list(header)
    header = next((h for h in heads if _header_names(h, ncols) is not None), None)
    names = _header_names(header, ncols)
    if names is not None and names.count("x") == 1 and names.count("y") == 1 and \
            names.count("z") <= 1:
        return tuple(i for i, nm in enumerate(names) if nm in _AXES)
    if names is not None and ncols == 3 and names.count("x") == 1 and "y" not in names and \
            "z" not in names:
        named = _header_parts(header, ncols) or names
        raise FileFormatError(
            f"the header ({named[0]!r}, {named[1]!r}, {named[2]!r}) names a column x but no "
            "y or z: a 3-D curve, or two curves over the same x (a digitiser's "
            "'all curves on each line' export)? columns=(0, 1, 2) (--columns 0,1,2) reads "
            "x, y, z; columns=(0, 1) (--columns 0,1) fairs the first curve and keeps the "
            "other column as it is", path, line)
    index = is_point_numbers(first_column)
    say = ("say which columns are x, y (z) with columns= (--columns, 0-based) or a header "
           "line naming them (e.g. 'id,x,y')")
    if ncols in (2, 3) and not (ncols == 3 and index):
        return tuple(range(ncols))
    if ncols == 3:
        lo, hi = first_column[0], first_column[-1]
        raise FileFormatError(
            f"the first of the 3 columns holds the consecutive integers {lo:.0f} .. {hi:.0f}: "
            "point numbers beside x, y, or the x coordinates of a 3-D curve? "
            "columns=(1, 2) (--columns 1,2) keeps them as they are and fairs x, y; "
            "columns=(0, 1, 2) (--columns 0,1,2) reads x, y, z; or name the columns in a "
            "header line", path, line)
    if ncols in (4,) and index:
        return tuple(range(1, ncols))
    raise FileFormatError(f"points file rows need 2 or 3 coordinate columns, got {ncols}: "
                          f"{say}", path, line)


def read(path: str | os.PathLike[str], *, corner_angle: float | None = 60.0,
         columns: Sequence[int] | None = None, **_: Any) -> list[CurveRecord]:
    """Read a CSV / whitespace point list; see the module docstring."""
    lay = parse_text(path, header=True, ncols=None, what="points file")
    heads = [lay.lines[i] for i in sorted(((lay.header,) if lay.header is not None else ())
                                          + tuple(lay.leading))]
    cols = coordinate_columns(lay.ncols, heads, lay.values[:, 0], columns, path,
                              lay.data_lines[0] + 1)
    if cols != tuple(range(lay.ncols)):
        kept = tuple(c for c in range(lay.ncols) if c not in cols)
        names = next((p for p in (_header_parts(h, lay.ncols) for h in heads)
                      if p is not None), None)
        what = ", ".join(repr(names[c]) if names and names[c] else str(c) for c in kept)
        import warnings

        warnings.warn(ColumnsKept(
            f"{os.fspath(path)}: column{'s' if len(kept) > 1 else ''} {what} kept as "
            f"{'they are' if len(kept) > 1 else 'it is'}; columns {', '.join(map(str, cols))} "
            f"read as {', '.join(_AXES[:len(cols)])}", kept), stacklevel=3)
    vals = lay.values[:, cols] if cols != tuple(range(lay.ncols)) else lay.values
    dl = lay.data_lines  # 1-based line numbers, per row (one run of lines: no conversion)
    lines = (np.arange(dl[0] + 1, dl[-1] + 2, dtype=np.int64) if dl[-1] - dl[0] + 1 == len(dl)
             else np.asarray(dl, dtype=np.int64) + 1)
    # exactly repeated consecutive rows: dropped, written back with their twin's value
    vals, where = drop_duplicates(vals, path, lines)
    keep = np.r_[True, where[1:] != where[:-1]]
    check_points(vals, path, lines[keep])
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
           "row_map": frozen_index(row_map), "header": lay.header_text, "columns": cols}
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
    cols = tuple(records[0].source.get("columns") or range(lay.ncols))
    values = piece_values(n_points, len(cols), records, what)
    row_map = np.asarray(records[0].source["row_map"], dtype=int)
    if cols == tuple(range(lay.ncols)):
        return values[row_map]
    rows = np.array(lay.values)  # the other columns as read: written back as they were
    rows[:, cols] = values[row_map]
    return rows


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
