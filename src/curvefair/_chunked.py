"""Fairing one point list too large for memory, in overlapping chunks.

Used by :func:`curvefair.batch.fair_chunked` (and ``curvefair fair BIG --chunk N``). The curve
is the one a points file means (:func:`curvefair.io.read_curves`): the C2 cubic through the
data points with chord-length parameters and natural ends. It is never built whole; the points
are streamed in blocks (a ``.npy`` file through a memory map, text line by line) and only a
few windows are in memory at a time.

Chunks
------
Point ``i`` belongs to the core of chunk ``k = i // chunk`` (the last core takes the rest,
up to ``1.5 chunk`` points). Chunk ``k`` is faired on its *window*, the core extended by
``overlap`` points on both sides: an ordinary :func:`curvefair.fair` of
``interpolate_cubic(window, "chord", "natural")`` under ``tol``, with its own deviation
certificate (``report["max_deviation"]``). At every join ``j`` (the first point of a core)
the points ``j - hold .. j + hold`` are protected in *both* neighbouring fairs, so they are
the input's points in both; each chunk's result is kept on its own core only. Every written
point is therefore a point of one fair: ``|moved - original| <= tol`` holds per point exactly
in float64, as it does for a single fair.

Why this joins smoothly: the written file is read back as one C2 spline through all points,
so position, tangent and curvature are continuous at every join by construction. What the
held band buys is that the curve there is the one *both* fairs produced: the spline's
tangents solve a tridiagonal system whose rows are diagonally dominant (diagonal
``2 (h_{i-1} + h_i)``, off-diagonals ``h_i`` and ``h_{i-1}``, with ``h`` the chord lengths;
de Boor, A Practical Guide to Splines, ch. IV), so a change of data ``m`` points away reaches
a tangent damped by at least ``2^-m`` (``(2 - sqrt 3)^m`` for even spacing). Behind
``hold`` unmoved points, what the neighbour did beyond the band is invisible at the join up
to that factor. The report gives, per join, the angle between the two fairs' unit tangents
and the relative difference of their curvatures at the join point, and the same between each
fair and the curve read back (``joins``); :data:`G2_TOL` is the stated tolerance for both.

On disk
-------
The output is written in blocks to a temporary file next to the destination, then read back
in blocks and measured as a single-file run of point data is (:mod:`curvefair.io._verify`):
per core, the geometric (Hausdorff) distance between the curve rebuilt from the written
points and the input's curve -- its O(n) per-span upper bound where that meets ``tol``, else
the refined distance on the spans it does not clear (:func:`measure_chunk`) -- both on their
windows (``overlap`` points either side; by the bound above the window's curve on the core is
the whole curve's to ``2^-overlap`` relative, far below rounding for the default). A core
read back farther than ``tol`` gets its moves scaled down, ``p = p0 + s (p_faired - p0)``
aiming at ``0.995 tol``, and the file is written and measured again; only a file within
``tol`` everywhere is moved onto the destination (nothing is written otherwise).

Text from text is written in the input's layout (:class:`_LayoutWriter`): the input's lines
are streamed again, in step with the faired rows (kept exactly in a float64 scratch file,
since the file's precision -- each column's largest number of decimals -- is known only after
the whole input has been read); header, comment and blank lines and unmoved rows are copied
byte for byte, each line with its own ending, and moved rows are rendered in their line's
layout with their moved numbers rounded to the input's decimals. The rounding is part of the
certificate: per row, the written point (as it reads back, in float64) is within ``tol`` of
the input's point, within :func:`rounding_budget` of its faired point and not on a neighbour,
else that row gets one more decimal at a time, then its exact value; the measure above is of
the rounded file, and a core read back over ``tol`` whose rounding changed something has its
rounding undone (its moved numbers written exactly, as the single-file writer writes them)
before its moves are scaled.

Parallel work
-------------
Fairing a chunk and measuring one depend only on the points of its window, so they run in
this process, in a pool of processes or on Dask distributed workers (the window's points are
sent with the task: the workers need not see the files) and give the same bytes everywhere.
At most ``4 x workers`` tasks are in flight and the results are written in order, so memory
stays bounded by a few windows whatever the curve's length. A Dask worker that dies has its
task rerun by the scheduler; a process-pool worker that dies has its chunk redone here.
"""

from __future__ import annotations

import contextlib
import math
import os
import re
import tempfile
import time
from collections import deque
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .errors import FileFormatError, InputError
from .io.points import (
    column_decimals,
    decimal_commas,
    fortran_exponents,
    render_row,
    wordy,
)

DEFAULT_CHUNK = 5000
DEFAULT_OVERLAP = 64
DEFAULT_HOLD = 16
#: Stated G2 tolerance at the joins: tangent angle (radians) and relative curvature
#: difference ``|k_a - k_b| / max(|k_a|, |k_b|, 1 / window length)``.
G2_TOL = 1e-6
TEXT_EXTS = (".csv", ".txt", ".xyz", ".pts", ".dat")
NPY_EXTS = (".npy",)
_MAX_SHRINK = 12
_SPLIT = re.compile(r"[,;\s]+")


# ------------------------------------------------------------------------------------------
# reading in blocks
# ------------------------------------------------------------------------------------------
class PointStream:
    """The rows of a point file in blocks: ``.npy`` (2-D float array, 2 or 3 columns,
    memory-mapped) or text columns (``# comments``, blank lines, one header line before the
    data; separators blanks, commas or semicolons).

    Attributes after a full pass: ``n_rows``; ``header`` (text), ``preamble`` (the lines before
    the first row: the header, comments and blank lines) and ``sep`` (the separator of the
    first row) are known after the first block; ``n_comments_dropped`` counts the comments
    after the first row (lines an output without the input's layout does not copy).
    ``column_decimals`` (text, ``decimals=True``): the largest number of decimals per column
    over the file, the file's precision (:func:`curvefair.io.points.column_decimals`).
    """

    def __init__(self, path: str | os.PathLike[str], *, decimals: bool = False) -> None:
        self.path = os.fspath(path)
        ext = Path(self.path).suffix.lower()
        if ext in NPY_EXTS:
            self.kind = "npy"
        elif ext in TEXT_EXTS:
            self.kind = "text"
        else:
            raise InputError(f"{self.path!r}: chunked fairing reads point files "
                             f"({', '.join(TEXT_EXTS + NPY_EXTS)}), not {ext!r}")
        if not os.path.isfile(self.path):
            raise InputError(f"{self.path!r} does not exist")
        self.header: str | None = None
        self.preamble: list[str] = []
        self.n_comments_dropped = 0
        self.sep = ","
        self.dim: int | None = None
        self.n_rows: int | None = None
        self.track_decimals = bool(decimals)
        self.column_decimals: list[int] = []
        self.lead = ""  # text_rows: the raw text before the first row (with a BOM if any)
        self.tail = ""  # text_rows, after a full pass: the raw text after the last row
        if self.kind == "npy":
            try:
                mm = np.load(self.path, mmap_mode="r", allow_pickle=False)
            except (OSError, ValueError) as exc:
                raise FileFormatError(f"not a .npy array: {exc}", self.path) from None
            if mm.ndim != 2 or mm.shape[1] not in (2, 3) or mm.dtype.kind not in "fiu":
                raise FileFormatError(f"a .npy point list is a numeric (n, 2) or (n, 3) "
                                      f"array, this one is {mm.dtype} {mm.shape}", self.path)
            self.dim = int(mm.shape[1])
            self.n_rows = int(mm.shape[0])

    def estimate_rows(self) -> int:
        """The number of rows (``.npy``) or of lines (text: an upper bound, counted in
        16 MiB blocks)."""
        if self.n_rows is not None:
            return self.n_rows
        n = 0
        last = b"\n"
        with open(self.path, "rb") as f:
            for block in iter(lambda: f.read(1 << 24), b""):
                n += block.count(b"\n")
                last = block[-1:]
        return n + (last != b"\n")

    def blocks(self, size: int) -> Iterator[np.ndarray]:
        """Successive float64 arrays of up to ``size`` rows each (the last may be shorter)."""
        if self.kind == "npy":
            mm = np.load(self.path, mmap_mode="r", allow_pickle=False)
            for a in range(0, mm.shape[0], size):
                yield np.array(mm[a:a + size], dtype=np.float64)
            return
        for blk, _before, _lines in self._text_parse(size, keep=False):
            yield blk

    def text_rows(self, size: int) -> Iterator[tuple[np.ndarray, list[str], list[str]]]:
        """Text files: :meth:`blocks` with the lines as read, ``(rows, before, lines)``:
        ``lines[i]`` is row ``i``'s line with its own line ending, ``before[i]`` the raw text
        of the comment and blank lines between the row before it and row ``i`` (``""`` for
        none). :attr:`lead` (the lines before the first row, known after the first block) and
        :attr:`tail` (the lines after the last row, after the last block) complete the file:
        their concatenation in order is the file's text. Only one block of lines is held."""
        if self.kind != "text":
            raise InputError(f"{self.path!r}: text_rows reads text point files")
        yield from self._text_parse(size, keep=True)

    def _all_coordinates(self, ncols: int, ln: int) -> None:
        """Refuse a header naming columns other than x, y, z beside them (``id,x,y``): the
        chunked reader fairs every column (:func:`curvefair.io.points.coordinate_columns`)."""
        from .io.points import coordinate_columns

        if self.header is None:
            return
        heads = [h for h in self.preamble if h.strip() and not h.lstrip().startswith("#")]
        cols = coordinate_columns(ncols, heads, np.zeros(0), path=self.path)
        if cols != tuple(range(ncols)):
            raise FileFormatError(
                f"the header names columns {', '.join(map(str, cols))} as x, y (z) and keeps "
                "the others; chunked fairing reads files of coordinate columns only: fair it "
                "without --chunk", self.path, ln)

    def _no_point_numbers(self, rows: list[list[float]]) -> None:
        """Refuse 3 columns without a header whose first one holds consecutive integers
        over the first block: point numbers or x coordinates? (The reader without chunks
        refuses it too, :func:`curvefair.io.points.coordinate_columns`.)"""
        if self.dim != 3 or self.header is not None:
            return
        from .io.points import is_point_numbers

        first = np.array([r[0] for r in rows], dtype=np.float64)
        if is_point_numbers(first):
            raise FileFormatError(
                f"the first of the 3 columns holds the consecutive integers {first[0]:.0f} .. "
                f"{first[-1]:.0f} (first {len(rows)} rows): point numbers beside x, y, or the "
                "x coordinates of a 3-D curve? Chunked fairing reads x, y, z only; without "
                "--chunk, --columns says which columns are the coordinates", self.path)

    def _decimals_of(self, texts: list[str]) -> None:
        """Fold a block's number texts into :attr:`column_decimals`."""
        assert self.dim is not None
        got = column_decimals(texts, self.dim)
        self.column_decimals = [max(a, b) for a, b in
                                zip(self.column_decimals or [0] * self.dim, got, strict=True)]

    def _text_parse(self, size: int, keep: bool
                    ) -> Iterator[tuple[np.ndarray, list[str], list[str]]]:
        rows: list[list[float]] = []
        before: list[str] = []
        lines: list[str] = []
        between: list[str] = []  # keep: raw lines since the last row
        n = 0
        self.header, self.preamble, self.n_comments_dropped = None, [], 0
        self.lead, self.tail = "", ""
        self.column_decimals = []
        track = self.track_decimals
        texts: list[str] = []  # track: the number texts of the block, row after row
        if keep:
            with open(self.path, "rb") as fb:
                if fb.read(3) == b"\xef\xbb\xbf":
                    between.append("\ufeff")
        # newline="": the lines keep their own endings (split where the default mode would)
        with open(self.path, encoding="utf-8-sig", errors="strict", newline="") as f:
            try:
                for ln, line in enumerate(f, start=1):
                    s = line.split("#", 1)[0].strip()
                    if n == 0 and not s:  # n: rows so far
                        self.preamble.append(line.rstrip("\r\n"))
                        if keep:
                            between.append(line)
                        continue
                    if "#" in line and n > 0:
                        self.n_comments_dropped += 1
                    if not s:
                        if keep:
                            between.append(line)
                        continue
                    toks = _SPLIT.split(s)
                    try:
                        vals = [float(t) for t in toks]
                    except ValueError:
                        if n == 0 and not rows and (self.header is None or wordy(line)):
                            # the header, then lines without a number (a units row)
                            if self.header is None:
                                self.header = line.rstrip("\r\n")
                            self.preamble.append(line.rstrip("\r\n"))
                            if keep:
                                between.append(line)
                            continue
                        why = ("; chunked fairing reads E exponents, not Fortran's D: fair "
                               "the file without --chunk" if fortran_exponents(s) else "")
                        raise FileFormatError(f"not a row of numbers: {s[:60]!r}{why}",
                                              self.path, ln) from None
                    if self.dim is None:
                        if decimal_commas(s):
                            raise FileFormatError(
                                f"numbers with decimal commas ({s[:40]!r}): chunked fairing "
                                "reads numbers with a decimal point; fair the file without "
                                "--chunk, or save it with decimal points", self.path, ln)
                        if len(vals) not in (2, 3):
                            raise FileFormatError(f"{len(vals)} columns; a point "
                                                  "list has 2 or 3 (chunked fairing reads "
                                                  "files of coordinate columns only)",
                                                  self.path, ln)
                        self._all_coordinates(len(vals), ln)
                        self.dim = len(vals)
                        self.sep = "," if "," in s else (";" if ";" in s else " ")
                    elif len(vals) != self.dim:
                        raise FileFormatError(f"{len(vals)} columns, the rows before have "
                                              f"{self.dim}", self.path, ln)
                    if not all(math.isfinite(v) for v in vals):
                        raise FileFormatError("not a finite number", self.path, ln)
                    if track:
                        texts.extend(toks)
                    if keep:
                        if n == 0:
                            self.lead = "".join(between)
                            before.append("")
                        else:
                            before.append("".join(between))
                        between = []
                        lines.append(line)
                    rows.append(vals)
                    n += 1
                    if len(rows) == size:
                        if n == len(rows):  # the first block
                            self._no_point_numbers(rows)
                        if track:
                            self._decimals_of(texts)
                            texts = []
                        yield np.array(rows, dtype=np.float64), before, lines
                        rows, before, lines = [], [], []
            except UnicodeDecodeError as exc:
                raise FileFormatError(f"not a text file ({exc.reason})", self.path) from None
        if rows:
            if n == len(rows):  # the first block
                self._no_point_numbers(rows)
            if track:
                self._decimals_of(texts)
            yield np.array(rows, dtype=np.float64), before, lines
        if keep:
            if n == 0:
                self.lead = "".join(between)
            else:
                self.tail = "".join(between)
        self.n_rows = n


def _check_rows(pts: np.ndarray, start: int, path: str) -> None:
    """Consecutive equal rows (a zero chord) and non-finite values, named by row index."""
    if not np.isfinite(pts).all():
        bad = int(np.flatnonzero(~np.isfinite(pts).all(axis=1))[0])
        raise FileFormatError(f"row {start + bad}: not a finite number", path)
    same = np.flatnonzero(np.all(pts[1:] == pts[:-1], axis=1))
    if same.size:
        i = start + int(same[0]) + 1
        raise FileFormatError(f"rows {i - 1} and {i} (0-based) are the same point; chunked "
                              "fairing needs distinct consecutive points (fair the file "
                              "without --chunk to have them merged)", path)


@dataclass(frozen=True)
class Chunk:
    """Chunk ``index``: core ``[start, stop)``, window ``[w0, w1)`` (global row indices)."""

    index: int
    start: int
    stop: int
    w0: int
    w1: int
    n: int  # total rows


def windows(stream_blocks: Iterator[np.ndarray], chunk: int, overlap: int, path: str,
            corner_angle: float | None = None) -> Iterator[tuple[Chunk, np.ndarray]]:
    """``(Chunk, window points)`` in order, reading ``stream_blocks`` lazily (a rolling
    buffer of about ``2 chunk + 2 overlap`` rows)."""
    buf = np.empty((0, 0))
    buf0 = 0  # global index of buf[0]
    n_read = 0
    eof = False
    it = iter(stream_blocks)
    k = 0
    prev_last: np.ndarray | None = None
    first_row = np.empty(0)
    while True:
        start = k * chunk
        need = start + chunk + chunk // 2 + overlap + 1
        while not eof and n_read < need:
            try:
                blk = next(it)
            except StopIteration:
                eof = True
                break
            _check_rows(blk if prev_last is None else np.vstack([prev_last, blk]),
                        n_read - (0 if prev_last is None else 1), path)
            if corner_angle is not None:
                ctx = blk if buf.size == 0 else np.vstack([buf[-2:], blk])
                _check_corners(ctx, n_read - (ctx.shape[0] - blk.shape[0]), corner_angle, path)
            prev_last = blk[-1:]
            buf = blk if buf.size == 0 else np.vstack([buf, blk])
            n_read += blk.shape[0]
        if k == 0:
            if n_read < 2:
                raise FileFormatError(f"a curve needs at least 2 points, the file has {n_read}",
                                      path)
            first_row = buf[0].copy()
        if eof and k > 0 and start >= n_read:
            return
        last = eof and n_read <= start + chunk + chunk // 2
        stop = n_read if last else start + chunk
        w0, w1 = max(0, start - overlap), min(n_read, stop + overlap + 1)
        if last and n_read >= 4 and np.array_equal(buf[n_read - 1 - buf0], first_row):
            raise InputError(f"{path!r}: a closed loop (its last row repeats the first); "
                             "chunked fairing takes open point lists")
        yield (Chunk(k, start, stop, w0, w1, n_read if last else -1),
               buf[w0 - buf0:w1 - buf0].copy())
        if last:
            return
        k += 1
        drop = max(0, (k * chunk - overlap) - buf0)
        buf = buf[drop:]
        buf0 += drop


def _check_corners(pts: np.ndarray, start: int, corner_angle: float, path: str) -> None:
    """A turn of ``corner_angle`` degrees or more at a point: the single-file reader splits
    the list there; chunked fairing refuses it (named by row)."""
    if pts.shape[0] < 3:
        return
    d0, d1 = pts[1:-1] - pts[:-2], pts[2:] - pts[1:-1]
    c = np.einsum("ij,ij->i", d0, d1) / (np.linalg.norm(d0, axis=1) * np.linalg.norm(d1, axis=1))
    bad = np.flatnonzero(c <= math.cos(math.radians(corner_angle)))
    if bad.size:
        raise InputError(f"{path!r}: row {start + int(bad[0]) + 1} is a corner (a turn of "
                         f"{corner_angle:g} degrees or more, where the file would be split "
                         "into pieces on reading); chunked fairing takes one smooth piece "
                         "(corner_angle=None / --no-corners to read through corners)")


# ------------------------------------------------------------------------------------------
# the per-chunk work (top level: picklable for process pools and Dask)
# ------------------------------------------------------------------------------------------
def _frame(points: np.ndarray, tangents: np.ndarray, params: np.ndarray, i: int
           ) -> tuple[np.ndarray, float]:
    """Unit tangent and curvature of a C2 cubic Hermite spline at its data point ``i``, from
    the segment polynomial (the one starting at ``i``, or ending there at the last point)."""
    n = points.shape[0]
    seg = i if i < n - 1 else i - 1
    D = params[seg + 1] - params[seg]
    r0, r1, d0, d1 = points[seg], points[seg + 1], tangents[seg], tangents[seg + 1]
    a2 = 3.0 * (r1 - r0) / D**2 - (2.0 * d0 + d1) / D
    a3 = 2.0 * (r0 - r1) / D**3 + (d0 + d1) / D**2
    x = 0.0 if seg == i else D
    d1v = d0 + 2.0 * a2 * x + 3.0 * a3 * x * x
    d2v = 2.0 * a2 + 6.0 * a3 * x
    sp = float(np.linalg.norm(d1v))
    cr = (d1v[0] * d2v[1] - d1v[1] * d2v[0]) if d1v.shape[0] == 2 else \
        float(np.linalg.norm(np.cross(d1v, d2v)))
    return d1v / sp, float(cr) / sp**3


def _held(ch: Chunk, hold: int) -> list[int]:
    """Window-local indices held at the joins: ``j - hold .. j + hold`` for each inner join."""
    out: set[int] = set()
    n = ch.n if ch.n > 0 else None
    for j in (ch.start, ch.stop):
        if j == 0 or (n is not None and j >= n):
            continue
        out.update(range(max(ch.w0, j - hold), min(ch.w1 - 1, j + hold) + 1))
    return sorted(i - ch.w0 for i in out)


def _one_blas_thread() -> Any:
    """BLAS limited to one thread for the duration (threadpoolctl, when installed).

    A multithreaded BLAS splits long dot products (OpenBLAS: above 10,000 elements, e.g. the
    energy of a 5,000-point window in points-l1) by its thread count, so the rounding -- and
    the bytes written -- would depend on the worker's cores and environment (Dask workers set
    ``OPENBLAS_NUM_THREADS=1``); a chunk is small, and the parallelism is across chunks."""
    try:
        from threadpoolctl import threadpool_limits  # type: ignore[import-untyped]
    except ImportError:  # pragma: no cover - threadpoolctl comes with the dask extra
        return contextlib.nullcontext()
    return threadpool_limits(limits=1, user_api="blas")


def fair_chunk(ch: Chunk, pts: np.ndarray, tol: float, method: str | None, hold: int,
               clamp: tuple[str, str], options: Mapping[str, Any],
               protect: tuple[int, ...] = ()) -> dict[str, Any]:
    """Fair one window; return its core's points, its report and the tangent / curvature of
    its faired curve at its joins. ``protect``: global row indices that never move."""
    from . import fair, interpolate_cubic
    from .batch import _test_delay

    _test_delay()
    curve = interpolate_cubic(pts, "chord", "natural")
    left = clamp[0] if ch.w0 == 0 else "g0"
    right = clamp[1] if ch.n > 0 and ch.w1 >= ch.n else "g0"
    mine = [i - ch.w0 for i in protect if ch.w0 <= i < ch.w1]
    with _one_blas_thread():
        res = fair(curve, method, tol=tol, clamp=(left, right),
                   protect=sorted(set(_held(ch, hold)) | set(mine)), **dict(options))
    c = res.curve
    P, T, U = (np.asarray(c.points), np.asarray(c.tangents),  # type: ignore[attr-defined]
               np.asarray(c.params))  # type: ignore[attr-defined]
    a, b = ch.start - ch.w0, ch.stop - ch.w0
    core = P[a:b].copy()
    moved = np.linalg.norm(core - pts[a:b], axis=1)
    frames = {}
    for j in (ch.start, ch.stop):
        if 0 < j and (ch.n <= 0 or j < ch.n):
            t, k = _frame(P, T, U, j - ch.w0)
            frames[j] = (t.tolist(), k, float(U[-1] - U[0]))
    r = res.report
    return {"points": core, "frames": frames,
            "report": {"chunk": ch.index, "rows": [ch.start, ch.stop],
                       "window": [ch.w0, ch.w1], "method": r["method"], "steps": r["steps"],
                       "stop_reason": r["stop_reason"],
                       "max_deviation": r["max_deviation"],
                       "n_moved": int(np.count_nonzero(moved)),
                       "max_point_displacement": float(moved.max()) if moved.size else 0.0,
                       "energy_before": r["energy_before"], "energy_after": r["energy_after"],
                       "inflections_before": r["inflections_before"],
                       "inflections_after": r["inflections_after"],
                       "extrema_before": r["extrema_before"],
                       "extrema_after": r["extrema_after"]}}


def measure_chunk(ch: Chunk, orig: np.ndarray, new: np.ndarray,
                  tol: float | None = None) -> dict[str, Any]:
    """The core of ``ch`` read back: Hausdorff distance between the curves through ``new``
    and ``orig`` on the window, restricted to the core (segments ``start .. stop``), the
    largest point move, and the read-back curve's tangent / curvature at the joins.

    As :mod:`curvefair.io._verify` measures a point file read back: the per-span upper bound
    of the Hausdorff distance (:func:`curvefair.analysis.matched_hermite_bound`, one O(n)
    compiled pass) where it meets ``tol`` (``kind`` ``"matched bound"``), else, on the spans
    whose bound exceeds ``tol``, the refined geometric distance (:func:`curvefair.deviation`,
    ``kind="geometric"``, ``spans=``: Newton projections of their points onto the whole other
    core), which then decides; ``tol`` None: the refined distance of the whole core."""

    with _one_blas_thread():
        return _measure(ch, orig, new, tol)


def _measure(ch: Chunk, orig: np.ndarray, new: np.ndarray,
             tol: float | None = None) -> dict[str, Any]:
    from . import CubicHermite, deviation, interpolate_cubic
    from .analysis import matched_hermite_bound

    a = interpolate_cubic(orig, "chord", "natural")
    b = interpolate_cubic(new, "chord", "natural")
    lo, hi = ch.start - ch.w0, min(ch.stop, ch.w1 - 1) - ch.w0
    cores = []
    for c in (a, b):
        P, T, U = c.points, c.tangents, c.params
        cores.append(CubicHermite(P[lo:hi + 1], T[lo:hi + 1], U[lo:hi + 1]))
    bound = matched_hermite_bound(cores[0], cores[1])
    dist = float(bound.max()) if bound.size else 0.0
    kind = "matched bound"
    if tol is None:
        dist = float(deviation(cores[0], cores[1], kind="geometric").max_distance)
        kind = "geometric"
    elif not dist <= tol:
        # the spans the bound does not clear, measured against the whole other core
        over = ~(bound <= tol)
        refined = deviation(cores[0], cores[1], kind="geometric", spans=np.flatnonzero(over))
        dist = max(float(refined.max_distance), float(bound[~over].max(initial=0.0)))
        kind = "geometric"
    moved = np.linalg.norm(new[lo:ch.stop - ch.w0] - orig[lo:ch.stop - ch.w0], axis=1)
    frames = {}
    Pb, Tb, Ub = np.asarray(b.points), np.asarray(b.tangents), np.asarray(b.params)
    for j in (ch.start, ch.stop):
        if 0 < j and (ch.n <= 0 or j < ch.n):
            t, k = _frame(Pb, Tb, Ub, j - ch.w0)
            frames[j] = (t.tolist(), k, float(Ub[-1] - Ub[0]))
    return {"deviation": dist, "kind": kind, "frames": frames,
            "max_point_displacement": float(moved.max()) if moved.size else 0.0}


# ------------------------------------------------------------------------------------------
# running tasks in order, bounded
# ------------------------------------------------------------------------------------------
class _Runner:
    """Submit tasks to this process, a process pool or a Dask client; results in order."""

    def __init__(self, client: Any = None, jobs: int | None = None) -> None:
        self.client = client
        self.pool: Any = None
        if client is not None:
            try:
                n = len(client.scheduler_info().get("workers", {})) or 1
            except Exception:  # noqa: BLE001 - a client without scheduler info: assume one
                n = 1
        else:
            n = jobs if jobs is not None else (os.cpu_count() or 1)
            if n > 1:
                import concurrent.futures as cf
                import multiprocessing as mp

                self.pool = cf.ProcessPoolExecutor(max_workers=n,
                                                   mp_context=mp.get_context("spawn"))
        self.inflight = max(2, 4 * n)

    def close(self) -> None:
        if self.pool is not None:
            self.pool.shutdown(wait=True, cancel_futures=True)

    def map(self, fn: Callable[..., Any], tasks: Iterator[tuple[Any, ...]]
            ) -> Iterator[tuple[tuple[Any, ...], Any]]:
        """``(args, fn(*args))`` for each task, in order, at most ``inflight`` pending."""
        q: deque[tuple[tuple[Any, ...], Any]] = deque()

        def submit(args: tuple[Any, ...]) -> Any:
            if self.client is not None:
                return self.client.submit(fn, *args, pure=False)
            if self.pool is not None:
                import concurrent.futures as cf

                try:
                    return self.pool.submit(fn, *args)
                except cf.process.BrokenProcessPool:  # a worker died: the rest run here
                    return None
            return None

        def result(args: tuple[Any, ...], fut: Any) -> Any:
            if fut is None:
                return fn(*args)
            if self.pool is not None:
                import concurrent.futures as cf

                try:
                    return fut.result()
                except cf.process.BrokenProcessPool:  # a worker died: redo the task here
                    return fn(*args)
            return fut.result()

        for args in tasks:
            q.append((args, submit(args)))
            while len(q) >= self.inflight:
                a, f = q.popleft()
                yield a, result(a, f)
        while q:
            a, f = q.popleft()
            yield a, result(a, f)


# ------------------------------------------------------------------------------------------
# writing in blocks
# ------------------------------------------------------------------------------------------
class _Writer:
    """Rows appended in blocks to a temporary file (text, from a ``.npy`` input: ``sep``
    between numbers in the shortest form that reads back exactly; ``.npy``: float64, also the
    scratch file of the faired rows for :class:`_LayoutWriter`)."""

    def __init__(self, dest: str, kind: str, dim: int, sep: str) -> None:
        d = Path(dest)
        fd, self.path = tempfile.mkstemp(prefix="." + d.name + ".",
                                         suffix=".npy" if kind == "npy" else d.suffix,
                                         dir=str(d.parent) or ".")
        self.f = os.fdopen(fd, "wb")
        self.kind, self.dim, self.sep, self.n = kind, dim, sep, 0
        if kind == "npy":
            self._npy_header(10**12)
            self.hlen = self.f.tell()

    def _npy_header(self, n: int) -> None:
        np.lib.format.write_array_header_1_0(
            self.f, {"descr": "<f8", "fortran_order": False, "shape": (n, self.dim)})

    def write(self, rows: np.ndarray) -> None:
        self.n += rows.shape[0]
        if self.kind == "npy":
            self.f.write(np.ascontiguousarray(rows, dtype="<f8").tobytes())
        else:
            sep = self.sep
            self.f.write("".join(sep.join(map(repr, r)) + "\n"
                                 for r in rows.tolist()).encode())

    def close(self) -> None:
        if self.kind == "npy":
            self.f.seek(0)
            self._npy_header(self.n)
            if self.f.tell() != self.hlen:  # pragma: no cover - fixed for 2-D float64
                raise AssertionError("npy header length changed")
        self.f.close()


#: Extra decimals tried, one at a time, for a row whose rounding to the input's decimals
#: would move it past tol (or onto a neighbour) before it is written exactly.
_MAX_EXTRA = 8
#: The most rounding may move a point from where the fair put it, as a share of ``tol``: the
#: fair survives in the file (at decimals coarse against ``tol`` rounding would put the moved
#: points back onto the input's grid, i.e. undo the fair, while staying within ``tol``).
ROUND_SHARE = 0.1
#: ... and as a share of the room the chunk's fair left below ``tol`` (``tol`` minus its
#: certified deviation): the curve through rounded points moves by about the rounding (a
#: natural cubic spline's interpolation has a small max-norm operator norm), so this leaves
#: the read-back measure its margin and a rounded chunk is seldom written again.
ROOM_SHARE = 0.25


def rounding_budget(tol: float, fair_deviation: float | None) -> float:
    """How far rounding may move a point of a chunk from where its fair put it."""
    room = tol - fair_deviation if fair_deviation is not None and \
        math.isfinite(fair_deviation) else tol
    return min(ROUND_SHARE * tol, max(0.0, ROOM_SHARE * room))


class _LayoutWriter:
    """Rows written into the input's own lines (text input to text output).

    The lines before the first row, between rows (comments, blank lines) and after the last
    are copied as read, every line keeps its own ending, and a row whose values did not move
    is its line as read, byte for byte. A moved row is rendered in its line's layout
    (:func:`curvefair.io.points.render_row`: separators, padding, number style, a trailing
    comment) with its moved numbers rounded to the input's precision (the column's largest
    number of decimals over the file). Rounding is part of what the tolerance certifies, so
    it is checked here per row, in float64: a row that would end farther than ``tol`` from its
    input point, farther than the chunk's budget (:func:`rounding_budget`) from its faired
    point, or on a neighbour's point (a zero chord does not read back), is rendered with one
    more decimal at a time, then exactly (the shortest form that reads back as the value, as
    the single-file writer writes it). The curve read back is measured afterwards by the
    caller; a chunk written with budget None (its rounding undone) has every moved number
    exact.

    A row is written once its next row is known (a rounded row must not land on it), so one
    row is held back between blocks.
    """

    def __init__(self, dest: str, lead: str, column_decimals: list[int], sep: str,
                 tol: float) -> None:
        d = Path(dest)
        fd, self.path = tempfile.mkstemp(prefix="." + d.name + ".", suffix=d.suffix,
                                         dir=str(d.parent) or ".")
        self.f = os.fdopen(fd, "w", encoding="utf-8", newline="")
        self.f.write(lead)
        self.cols, self.sep, self.tol = list(column_decimals), sep, tol
        self.prev: list[float] | None = None  # the values of the last row written
        self.pending: tuple[Any, ...] | None = None
        #: per chunk: rows whose written values differ from the values given (rounded), rows
        #: written with more decimals than the input's, rows not in a layout this writer
        #: renders (written in the shortest exact form, the input's separator)
        self.rounded: dict[int, int] = {}
        self.more_decimals: dict[int, int] = {}
        self.fresh: dict[int, int] = {}

    def write(self, index: int, orig: np.ndarray, new: np.ndarray, before: list[str],
              lines: list[str], budget: float | None) -> None:
        """Chunk ``index``'s rows: ``orig`` as read (with their ``lines`` and the text
        ``before`` each), ``new`` the values to write."""
        for k in (self.rounded, self.more_decimals, self.fresh):
            k.setdefault(index, 0)
        same = np.all(new == orig, axis=1)
        f = self.f
        for i in range(orig.shape[0]):
            if same[i]:
                o = orig[i].tolist()
                if self.pending is not None:
                    self._settle(o)
                f.write(before[i])
                f.write(lines[i])
                self.prev = o
            else:
                if self.pending is not None:
                    self._settle(None)
                self.pending = (index, orig[i].tolist(), new[i].tolist(), before[i],
                                lines[i], budget)

    def _settle(self, nxt: list[float] | None) -> None:
        """Write the held row: rounded, unless that puts it past tol or onto the row before
        (``prev``) or after (``nxt``, None when that row moves too: it checks itself)."""
        assert self.pending is not None
        index, o, v, before, line, budget = self.pending
        exact = budget is None
        self.pending = None
        body = line.rstrip("\r\n")
        end = line[len(body):]
        tol = self.tol
        text, w = body, v
        level: int | None = 0
        r: tuple[str, list[float]] | None = None
        for level in ([None] if exact else [*range(_MAX_EXTRA + 1), None]):
            r = render_row(body, v, self.cols, level)
            if r is None:  # not a row of this layout (e.g. "1,,2"): fresh, exact
                self.fresh[index] += 1
                hash_at = body.find("#")
                text, w = self.sep.join(map(repr, v)), v
                if hash_at >= 0:
                    text += " " + body[hash_at:]
                break
            text, w = r
            if level is None:
                break
            d2 = e2 = 0.0
            for a, b, c in zip(w, o, v, strict=True):
                d2 += (a - b) * (a - b)
                e2 += (a - c) * (a - c)
            if math.sqrt(d2) <= tol and math.sqrt(e2) <= budget and \
                    w != self.prev and w != nxt:
                break
        if w != v:
            self.rounded[index] += 1
        if r is not None and (level is None and not exact or level is not None and level > 0):
            self.more_decimals[index] += 1
        f = self.f
        f.write(before)
        f.write(text)
        f.write(end)
        self.prev = w

    def close(self, tail: str) -> None:
        if self.pending is not None:
            self._settle(None)
        self.f.write(tail)
        self.f.close()


def _remove(path: str | None) -> None:
    if path is not None:
        with contextlib.suppress(OSError):
            os.unlink(path)


# ------------------------------------------------------------------------------------------
# the driver
# ------------------------------------------------------------------------------------------
def _angle(a: list[float], b: list[float]) -> float:
    c = float(np.clip(np.dot(a, b), -1.0, 1.0))
    s = float(np.linalg.norm(np.cross(np.r_[a, 0.0][:3], np.r_[b, 0.0][:3])))
    return math.atan2(s, c)


def _krel(ka: float, kb: float, length: float) -> float:
    return abs(ka - kb) / max(abs(ka), abs(kb), 1.0 / length)


def _blocks_of(path: str, rows: int) -> Iterator[np.ndarray]:
    s = PointStream(path)
    yield from s.blocks(rows)


def fair_chunked(source: str | os.PathLike[str], out: str | os.PathLike[str], *, tol: float,
                 chunk: int = DEFAULT_CHUNK, overlap: int = DEFAULT_OVERLAP,
                 hold: int = DEFAULT_HOLD, client: Any = None, jobs: int | None = None,
                 method: str | None = None, clamp: Any = "g0",
                 corner_angle: float | None = 60.0, protect: Any = (),
                 progress: Callable[[int, int], None] | None = None,
                 **options: Any) -> dict[str, Any]:
    """See :func:`curvefair.batch.fair_chunked`."""
    from . import fair  # noqa: F401 - import errors before any work
    from ._fileid import file_key
    from ._validate import as_positive, parse_clamp
    from .io import atomic_path

    t0 = time.perf_counter()
    src, dest = os.fspath(source), os.fspath(out)
    tol_v = as_positive(tol, "tol")
    for name, v, lo in (("chunk", chunk, 10), ("overlap", overlap, 1), ("hold", hold, 0)):
        if not isinstance(v, (int, np.integer)) or isinstance(v, bool) or v < lo:
            raise InputError(f"{name} must be an integer >= {lo}, got {v!r}")
    chunk, overlap, hold = int(chunk), int(overlap), int(hold)
    if hold + 2 > overlap:
        raise InputError(f"hold ({hold}) must be at least 2 less than overlap ({overlap})")
    if 2 * overlap + 2 > chunk:
        raise InputError(f"chunk ({chunk}) must be at least 2 (overlap + 1) = "
                         f"{2 * overlap + 2}")
    try:
        prot = tuple(sorted({int(i) for i in protect}))
    except (TypeError, ValueError):
        raise InputError(f"protect must be row indices, got {protect!r}") from None
    if prot and prot[0] < 0:
        raise InputError(f"protect: row {prot[0]} is negative (rows are 0-based)")
    clamp_pair = parse_clamp(clamp)
    if "none" in clamp_pair:
        raise InputError("clamp 'none' is not available for point data: the ends stay")
    out_kind = "npy" if Path(dest).suffix.lower() in NPY_EXTS else "text"
    # text to text: the output is the input's lines with the moved rows rendered in place
    layout = out_kind == "text" and Path(src).suffix.lower() in TEXT_EXTS
    stream = PointStream(src, decimals=layout)
    if Path(dest).suffix.lower() not in TEXT_EXTS + NPY_EXTS:
        raise InputError(f"{dest!r}: the output of chunked fairing is a point file "
                         f"({', '.join(TEXT_EXTS + NPY_EXTS)})")
    if os.path.exists(dest) and file_key(dest) == file_key(src):
        raise InputError(f"the output {dest!r} is the input file")
    if not Path(dest).resolve().parent.is_dir():
        raise InputError(f"{dest!r}: the folder does not exist")
    est = max(1, stream.estimate_rows() // chunk)
    done = 0

    def tick() -> None:
        # one step per chunk faired and per chunk measured (twice the estimated chunks)
        nonlocal done
        done += 1
        if progress is not None:
            progress(done, max(done, 2 * est))

    runner = _Runner(client, jobs)
    temps: list[str] = []
    chunk_reports: list[dict[str, Any]] = []
    fair_frames: dict[int, list[Any]] = {}
    n_total = 0
    try:
        # 1. fair every chunk, write the cores in order
        blk = max(1024, chunk)
        gen = windows(stream.blocks(blk), chunk, overlap, src, corner_angle)
        first = next(gen)
        dim = int(first[1].shape[1])
        # text to text: the faired rows first go to a float64 scratch file (the layout
        # needs the file's precision, known after the whole input has been read)
        writer = _Writer(dest, "npy" if layout else out_kind, dim,
                         stream.sep if stream.kind == "text" else ",")
        temps.append(writer.path)

        def tasks() -> Iterator[tuple[Any, ...]]:
            yield (first[0], first[1], tol_v, method, hold, clamp_pair, options, prot)
            for ch, pts in gen:
                yield (ch, pts, tol_v, method, hold, clamp_pair, options, prot)

        chunks: list[Chunk] = []
        for args, res in runner.map(fair_chunk, tasks()):
            ch = args[0]
            chunks.append(ch)
            writer.write(res["points"])
            chunk_reports.append(res["report"])
            for j, fr in res["frames"].items():
                fair_frames.setdefault(int(j), []).append(fr)
            n_total = max(n_total, ch.stop)
            tick()
        writer.close()
        est = len(chunks)
        if prot and prot[-1] >= n_total:
            raise InputError(f"protect: row {prot[-1]} is out of range (the file has "
                             f"{n_total} rows)")
        fair_file = writer.path
        # 2. read back, measure, scale where needed, until every core is within tol
        scales = [1.0] * len(chunks)
        exact = [False] * len(chunks)  # layout: chunks whose rounding was undone
        lw: _LayoutWriter | None = None
        current = fair_file
        notes: list[str] = []
        measured: list[dict[str, Any]] = []
        last = _MAX_SHRINK + (1 if layout else 0)
        for attempt in range(last + 1):
            if layout:
                lw = _write_layout(dest, src, fair_file, chunks, scales,
                                   [None if exact[k] else
                                    rounding_budget(tol_v, chunk_reports[k]["max_deviation"])
                                    for k in range(len(chunks))],
                                   stream.column_decimals, stream.sep, tol_v)
                if current != fair_file:
                    _remove(current)
                current = lw.path
                temps.append(current)
            measured = _measure_file(runner, src, current, chunks, chunk, overlap, tol_v,
                                     tick)
            over = [k for k, m in enumerate(measured) if not m["deviation"] <= tol_v]
            if not over:
                break
            if attempt == last:
                k = over[0]
                raise InputError(f"{dest!r}: not written: rows {chunks[k].start}.."
                                 f"{chunks[k].stop - 1} read back "
                                 f"{measured[k]['deviation']:.6g} from the input, more than "
                                 f"tol {tol_v:g}")
            undo = [k for k in over if lw is not None and lw.rounded[k] and not exact[k]]
            shrink = [k for k in over if k not in undo]
            for k in undo:
                exact[k] = True
            for k in shrink:
                scales[k] *= min(0.998, 0.995 * tol_v / measured[k]["deviation"])
            if undo and not any("rounding undone" in n for n in notes):
                notes.append(f"{len(undo)} chunk(s) rounded to the input's decimals read back "
                             f"farther than tol {tol_v:g}; their moved numbers were written "
                             "exactly (rounding undone)")
            if shrink and not any("scaled" in n for n in notes):
                notes.append(f"point data: {len(shrink)} chunk(s) read back farther than tol "
                             f"{tol_v:g} (the curve re-interpolated through the written "
                             "points has new chord parameters); their moves were scaled "
                             "down until within tol")
            if layout:
                continue
            w = _Writer(dest, out_kind, dim, writer.sep)
            temps.append(w.path)
            for ch, orig, faired in _lockstep(src, fair_file, chunks):
                s = scales[ch.index]
                rows = faired if s == 1.0 else _scaled(orig, faired, s)
                w.write(rows)
            w.close()
            if current != fair_file:
                _remove(current)
            current = w.path
        with atomic_path(dest) as tmp:
            os.replace(current, tmp)
    finally:
        runner.close()
        for t in temps:
            _remove(t)
    joins = []
    for k, ch in enumerate(chunks[1:], start=1):
        j = ch.start
        fa, fb = fair_frames.get(j, [None, None])[:2]
        back = measured[k]["frames"].get(j) or measured[k]["frames"].get(str(j))
        row: dict[str, Any] = {"row": j}
        if fa is not None and fb is not None and back is not None:
            row["tangent_angle"] = _angle(fa[0], fb[0])
            row["curvature_rel"] = _krel(fa[1], fb[1], min(fa[2], fb[2]))
            row["tangent_angle_read_back"] = max(_angle(fa[0], back[0]), _angle(fb[0], back[0]))
            row["curvature_rel_read_back"] = max(_krel(fa[1], back[1], fa[2]),
                                                 _krel(fb[1], back[1], fb[2]))
        joins.append(row)
    for k, (rep, m, s) in enumerate(zip(chunk_reports, measured, scales, strict=True)):
        rep["on_disk_deviation"] = m["deviation"]
        rep["on_disk_deviation_kind"] = m["kind"]
        rep["move_scale"] = s
        rep["on_disk_max_point_displacement"] = m["max_point_displacement"]
        if lw is not None:
            rep["on_disk_numbers"] = "exact" if exact[k] else "rounded"
            rep["rows_rounded"] = lw.rounded[k]
            rep["rows_more_decimals"] = lw.more_decimals[k]
            rep["rows_not_in_layout"] = lw.fresh[k]
    dropped = 0 if layout else stream.n_comments_dropped
    n_fresh = 0 if lw is None else int(np.sum(list(lw.fresh.values())))
    if n_fresh:
        notes.append(f"{n_fresh} moved row(s) the layout could not be kept for "
                     "(odd separators) were written with the input's separator and exact "
                     "numbers")
    g2 = max((max(r.get("tangent_angle", 0.0), r.get("curvature_rel", 0.0),
                  r.get("tangent_angle_read_back", 0.0), r.get("curvature_rel_read_back", 0.0))
              for r in joins), default=0.0)
    return {"input": src, "output": dest, "status": "ok", "n_points": n_total,
            "dim": dim, "n_chunks": len(chunks), "chunk": chunk, "overlap": overlap,
            "hold": hold, "tol": tol_v,
            "max_deviation": max(m["deviation"] for m in measured),
            "max_point_displacement": max(m["max_point_displacement"] for m in measured),
            "joins_g2_max": g2, "g2_tol": G2_TOL, "joins_within_g2_tol": g2 <= G2_TOL,
            "n_comments_dropped": dropped,
            "layout_kept": layout,
            "notes": notes + ([f"{dropped} comment(s) after the first row of the input were "
                               "not copied"] if dropped else []),
            "chunks": chunk_reports, "joins": joins,
            "time_s": time.perf_counter() - t0}


def _scaled(orig: np.ndarray, faired: np.ndarray, s: float) -> np.ndarray:
    out = orig + s * (faired - orig)
    same = np.all(faired == orig, axis=1)
    out[same] = orig[same]
    return out


def _write_layout(dest: str, src: str, fair_file: str, chunks: list[Chunk],
                  scales: list[float], budgets: list[float | None],
                  column_decimals: list[int],
                  sep: str, tol: float) -> _LayoutWriter:
    """The output file in the input's layout (:class:`_LayoutWriter`), from the input's lines
    and the faired rows (``fair_file``), each chunk's moves scaled by ``scales``."""
    src_rows = _text_rows(src)
    faired = _rows(fair_file)
    w = _LayoutWriter(dest, "", column_decimals, sep, tol)
    try:
        for ch in chunks:
            n = ch.stop - ch.start
            orig, before, lines = src_rows.take(n)
            if ch.index == 0:
                w.f.write(src_rows.stream.lead)
            new = faired.take(n)
            s = scales[ch.index]
            w.write(ch.index, orig, new if s == 1.0 else _scaled(orig, new, s), before,
                    lines, budgets[ch.index])
        src_rows.finish()
        w.close(src_rows.stream.tail)
    except BaseException:
        w.f.close()
        _remove(w.path)
        raise
    return w


class _text_rows:
    """Read a text point file forwards ``take(n)`` rows at a time, with their lines
    (:meth:`PointStream.text_rows`)."""

    def __init__(self, path: str) -> None:
        self.stream = PointStream(path)
        self.it = self.stream.text_rows(1 << 14)
        self.buf: tuple[np.ndarray, list[str], list[str]] | None = None

    def take(self, n: int) -> tuple[np.ndarray, list[str], list[str]]:
        parts = [self.buf] if self.buf is not None else []
        have = self.buf[0].shape[0] if self.buf is not None else 0
        while have < n:
            blk = next(self.it)
            parts.append(blk)
            have += blk[0].shape[0]
        rows = np.vstack([p[0] for p in parts]) if len(parts) > 1 else parts[0][0]
        before = [x for p in parts for x in p[1]]
        lines = [x for p in parts for x in p[2]]
        self.buf = (rows[n:], before[n:], lines[n:]) if have > n else None
        return rows[:n], before[:n], lines[:n]

    def finish(self) -> None:
        """Read to the end (the lines after the last row: :attr:`PointStream.tail`)."""
        for _ in self.it:
            raise InputError(f"{self.stream.path!r}: more rows than the chunks cover")


def _lockstep(src: str, written: str, chunks: list[Chunk]
              ) -> Iterator[tuple[Chunk, np.ndarray, np.ndarray]]:
    """``(chunk, input core rows, written core rows)`` from the two files read together."""
    a = _rows(src)
    b = _rows(written)
    for ch in chunks:
        n = ch.stop - ch.start
        yield ch, a.take(n), b.take(n)


class _rows:
    """Read a point file forwards ``take(n)`` rows at a time."""

    def __init__(self, path: str) -> None:
        self.it = PointStream(path).blocks(1 << 14)
        self.buf = np.empty((0, 0))

    def take(self, n: int) -> np.ndarray:
        parts = [self.buf] if self.buf.size else []
        have = self.buf.shape[0] if self.buf.size else 0
        while have < n:
            blk = next(self.it)
            parts.append(blk)
            have += blk.shape[0]
        allr = np.vstack(parts) if len(parts) > 1 else parts[0]
        self.buf = allr[n:]
        return allr[:n]


def _measure_file(runner: _Runner, src: str, written: str, chunks: list[Chunk], chunk: int,
                  overlap: int, tol: float, tick: Callable[[], None]
                  ) -> list[dict[str, Any]]:
    """:func:`measure_chunk` for every chunk of the written file against the input."""
    ga = windows(PointStream(src).blocks(max(1024, chunk)), chunk, overlap, src, None)
    gb = windows(PointStream(written).blocks(max(1024, chunk)), chunk, overlap, written, None)

    def tasks() -> Iterator[tuple[Any, ...]]:
        for (ca, pa), (cb, pb) in zip(ga, gb, strict=True):
            if (ca.start, ca.stop, ca.w0, ca.w1) != (cb.start, cb.stop, cb.w0, cb.w1):
                raise InputError(f"{written!r}: reads back with other rows than written")
            yield (ca, pa, pb, tol)

    out = []
    for _args, m in runner.map(measure_chunk, tasks()):
        out.append(m)
        tick()
    if len(out) != len(chunks):
        raise InputError(f"{written!r}: reads back as {len(out)} chunks, {len(chunks)} "
                         "were written")
    return out
