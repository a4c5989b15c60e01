"""Line layout of numeric text files (CSV, whitespace columns, airfoil ``.dat``).

A :class:`TextLayout` remembers every line of the file: comments, blank lines, the header or
name line and, for each data row, the exact separators, padding and number style of its
tokens, so that new values can be written back in the same layout (same columns, same
number of decimals where that keeps the value, right-aligned columns stay aligned).
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from itertools import repeat
from typing import Any, NamedTuple

import numpy as np

from .. import _threads
from .._typing import FloatArray
from ..errors import FileFormatError

__all__ = ["TextLayout", "Token", "parse_text", "format_number", "rounded_number",
           "decimal_commas", "fortran_exponents", "wordy"]

_NUM = r"[+-]?(?:(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|nan|inf(?:inity)?)"
_NUM_RE = re.compile(_NUM, re.IGNORECASE)
_NUM_FULL = _NUM_RE.fullmatch
# whole rows in the two commonest layouts, matched at once: ``1.5,2.5`` and ``1.5  2.5`` (ASCII
# blanks and tabs), whose numbers ``str.split`` then cuts out exactly as ``_SEP_RE`` would
_COMMA_ROW = re.compile(rf"{_NUM}(?:,{_NUM})*", re.IGNORECASE).fullmatch
_BLANK_ROW = re.compile(rf"{_NUM}(?:[ \t]+{_NUM})*", re.IGNORECASE).fullmatch
_SEP_RE = re.compile(r"(\s*[,;]\s*|\s+)")
_TOKEN_RE = re.compile(r"([+-]?)([^eE]*)(?:([eE])([+-]?)(\d+))?$")
# a number written with a decimal comma (``10,25``, ``-0,5e-3``), as spreadsheets in many
# locales write them, with ``;``, tabs or blanks between the columns
# (thousands grouped by points, ``1.234,5``, count as such a number: the file is then refused,
# not read at its commas as two or three numbers)
_COMMA_NUMBER = re.compile(r"[+-]?(?:\d{1,3}(?:\.\d{3})+|\d*),\d+(?:[eE][+-]?\d+)?").fullmatch
_FIELD_SEP = re.compile(r"\s*;\s*|\s+")


def _in_body(line: str, change: Callable[[str], str]) -> str:
    """``line`` with ``change`` applied to the part before its ``#`` comment."""
    at = line.find("#")
    return change(line) if at < 0 else change(line[:at]) + line[at:]


def _comma_to_point(line: str) -> str:
    """A decimal-comma data line with decimal points."""
    return _in_body(line, lambda b: b.replace(",", "."))


def _point_to_comma(line: str) -> str:
    """The inverse of :func:`_comma_to_point` for a line written with decimal points."""
    return _in_body(line, lambda b: b.replace(".", ","))


_D_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)[dD][+-]?\d+").fullmatch
_D_EXP = re.compile(r"(?<=[\d.])([dD])(?=[+-]?\d)")
_E_EXP = re.compile(r"(?<=[\d.])([eE])(?=[+-]?\d)")


def _d_to_e(line: str) -> str:
    """A data line with ``D`` exponents written with ``E`` (``d`` with ``e``)."""
    return _in_body(line, lambda b: _D_EXP.sub(lambda m: "E" if m.group(1) == "D" else "e", b))


def _e_to_d(line: str) -> str:
    """The inverse of :func:`_d_to_e` for a line written with ``E`` exponents."""
    return _in_body(line, lambda b: _E_EXP.sub(lambda m: "D" if m.group(1) == "E" else "d", b))


def _written_in(line: str, marks: str, trailing: str, fields: Callable[[str], list[str]],
                styled: Callable[[str], Any]) -> bool:
    """Whether a data line's fields (``fields`` of the part before its comment, one
    ``trailing`` separator after the last column dropped) are numbers, at least one of them
    ``styled`` (a number style that has one of ``marks``)."""
    at = line.find("#")
    s = (line if at < 0 else line[:at]).strip()
    if not any(m in s for m in marks):
        return False
    if s[-1:] in tuple(trailing):
        s = s[:-1].rstrip()
    got = fields(s)
    return len(got) >= 2 and any(styled(f) for f in got) and \
        all(styled(f) or _NUM_FULL(f) for f in got)


def fortran_exponents(line: str) -> bool:
    """Whether a data line writes its numbers with Fortran's double-precision exponent
    (``0.1234D+01``): its fields are numbers, at least one of them with a ``D``."""
    return _written_in(line, "Dd", ",;", lambda t: _SEP_RE.split(t)[0::2], _D_NUMBER)


def decimal_commas(line: str) -> bool:
    """Whether a data line writes its numbers with decimal commas (``10,5;2,25`` or
    ``10,5<TAB>2,25``): its fields between ``;``, tabs and blanks are numbers, at least one
    of them with a comma. Such a line also splits into twice as many numbers at its commas,
    which would read the integer and fractional parts as separate columns."""
    return _written_in(line, ",", ";", _FIELD_SEP.split, _COMMA_NUMBER)


class Token(NamedTuple):
    """Style of one number as it stood in the file."""

    text: str
    decimals: int      # digits after the point (of the mantissa for exponent style)
    has_point: bool
    exponent: str      # "" (fixed), "e" or "E"
    exp_digits: int
    exp_plus: bool     # an explicit '+' in the exponent
    plus: bool         # an explicit leading '+'
    bare_point: bool   # ".5" rather than "0.5"

    @classmethod
    def parse(cls, text: str) -> Token:
        m = _TOKEN_RE.match(text)
        assert m is not None
        sign, mant, exp, exp_sign, exp_digits = m.groups()
        point = mant.find(".")
        dec = len(mant) - point - 1 if point >= 0 else 0
        return cls(text, dec, point >= 0, exp or "", len(exp_digits or ""), exp_sign == "+",
                   sign == "+", point == 0)


def _render(v: float, tok: Token, decimals: int) -> str:
    if tok.exponent:
        mant, ex = f"{v:.{decimals}e}".split("e")
        digits = (ex[1:].lstrip("0") or "0").rjust(tok.exp_digits, "0")
        sign = "-" if ex[0] == "-" else ("+" if tok.exp_plus else "")
        s = f"{mant}{tok.exponent}{sign}{digits}"
    else:
        s = f"{v:.{decimals}f}"
        if decimals == 0 and tok.has_point:
            s += "."
    if tok.bare_point and not tok.exponent and decimals > 0:  # ".5"; never "." or "-."
        if s.startswith("0."):
            s = s[1:]
        elif s.startswith("-0."):
            s = "-" + s[2:]
    if tok.plus and not s.startswith("-"):
        s = "+" + s
    if float(s) == 0.0 and s.startswith("-") and not tok.text.startswith("-"):
        s = s[1:]
    return s


def _shortest(v: float) -> str:
    s = repr(float(v))
    if s.endswith(".0"):
        s = s[:-2]
    return "0" if s == "-0" else s


def format_number(v: float, tok: Token, column_decimals: int,
                  decimals: int | None = None) -> str:
    """Text for ``v`` in the style of the token it replaces.

    1. ``decimals`` given: that many decimals, the token's style (fixed or exponent).
    2. ``v`` is the token's own value (NaN for a NaN): the token's text, character for
       character (also where the file has more digits than a float64 holds, e.g. 18
       decimals).
       Else the token's own number of decimals if that writes ``v`` exactly.
    3. Otherwise the column's largest number of decimals in the file if that writes ``v``
       exactly, else the shortest representation that reads back as exactly ``v``. A faired
       value is never rounded to the file's precision behind the user's back: rounding could
       move a point past the fairing tolerance (pass ``decimals`` to round on purpose).
    """
    if decimals is not None:
        return _render(v, tok, int(decimals))
    t = float(tok.text)
    if t == v or (t != t and v != v):  # NaN for NaN: the file's spelling ("NaN", "nan")
        return tok.text
    s = _render(v, tok, tok.decimals)
    if float(s) == v:
        return s
    if column_decimals > 0 or tok.exponent:
        s = _render(v, tok, max(column_decimals, 1))
        if float(s) == v:
            return s
    return _shortest(v)


@dataclass(frozen=True)
class Row:
    """One data line split into pieces: ``prefix text0 sep0 text1 ... suffix``.

    Only the texts are kept; a :class:`Token` (the number's style) is built when a changed
    value has to be written in that style (:meth:`render`), so reading a file of a million
    rows makes no per-number objects."""

    prefix: str
    texts: tuple[str, ...]
    seps: tuple[str, ...]
    suffix: str

    @property
    def tokens(self) -> tuple[Token, ...]:
        """The style of each number (built on demand)."""
        return tuple(Token.parse(t) for t in self.texts)

    def render(self, values: Sequence[float], column_decimals: Sequence[int],
               decimals: int | None) -> str:
        """The row with ``values`` in place of its numbers (:func:`format_number` for each)."""
        return _render_pieces(self.prefix, self.texts, self.seps, self.suffix, values,
                              column_decimals, decimals)


def _render_pieces(prefix: str, texts: Sequence[str], seps: Sequence[str], suffix: str,
                   values: Sequence[float], column_decimals: Sequence[int],
                   decimals: int | None, extra: int | None = None) -> str:
    out = []
    lead = prefix
    nsep = len(seps)
    for j, text in enumerate(texts):
        v = float(values[j])
        t = float(text)
        if decimals is None and (t == v or (t != t and v != v)):
            s = text  # format_number's rule 2, without parsing the style
        elif decimals is None and extra is not None:
            s = rounded_number(v, text, column_decimals[j], extra)
        elif decimals is None and _is_plain(text):
            s = _plain_number(v, text, column_decimals[j])
        else:
            s = format_number(v, Token.parse(text), column_decimals[j], decimals)
        # keep right-aligned columns aligned: the blanks before the token absorb the change
        # of length (at least one blank stays between whitespace-separated tokens)
        delta = len(s) - len(text)
        if delta:
            core = lead.rstrip(" \t")
            pad = lead[len(core):]
            if pad:
                lead = core + pad[0] * max(len(pad) - delta, 0 if j == 0 else 1)
        out.append(lead)
        out.append(s)
        lead = seps[j] if j < nsep else ""
    out.append(suffix)
    return "".join(out)


def rounded_number(v: float, text: str, column_decimals: int, extra: int = 0) -> str:
    """Text for ``v``, replacing the number ``text``, rounded to the file's precision: the
    token's own decimals if they write ``v`` exactly, else ``v`` rounded to the column's
    largest number of decimals plus ``extra`` (at least one), in the token's style (fixed or
    exponent, ``+``, bare point); where that rounds onto the value read, the text read. An
    integer column (no decimals, no exponent) is not rounded: the shortest exact form, as
    :func:`format_number` writes it.

    Unlike :func:`format_number`, this rounds: a caller uses it only where the rounded file is
    measured against the tolerance afterwards (and ``extra`` raised, or :func:`format_number`
    used, where it is not met)."""
    tok = Token.parse(text)
    s = _render(v, tok, tok.decimals)
    if float(s) == v:
        return s
    if column_decimals <= 0 and not tok.exponent:
        return format_number(v, tok, column_decimals)
    s = _render(v, tok, max(column_decimals, 1) + int(extra))
    return text if float(s) == float(text) else s  # rounded onto the value read: as read


def _is_plain(text: str) -> bool:
    """A fixed-point number with digits before its point and no explicit ``+`` (``-12.50``,
    ``3.``): the common style, rendered by :func:`_plain_number` without a :class:`Token`."""
    point = text.find(".")
    return (point > 0 and text[point - 1].isdigit() and text[0] != "+"
            and "e" not in text and "E" not in text)


def _plain_number(v: float, text: str, column_decimals: int) -> str:
    """:func:`format_number` (no ``decimals``, ``v`` not the token's value) for a token of
    :func:`_is_plain` style: its own decimals if they write ``v`` exactly, else the column's,
    else the shortest exact form; a negative zero only where the token had a minus."""
    d = len(text) - text.find(".") - 1
    s = f"{v:.{d}f}" if d else f"{v:.0f}."
    if s[0] == "-" and text[0] != "-" and float(s) == 0.0:
        s = s[1:]
    if float(s) == v:
        return s
    d2 = max(column_decimals, 1)
    if column_decimals > 0 and d2 != d:
        s = f"{v:.{d2}f}"
        if s[0] == "-" and text[0] != "-" and float(s) == 0.0:
            s = s[1:]
        if float(s) == v:
            return s
    return _shortest(v)


def _pieces(line: str) -> tuple[str, list[str], list[str], str]:
    """``(prefix, texts, seps, suffix)`` of a data line as read (all numbers: not checked
    again): the blanks before the first number, the numbers and what separates them, and the
    rest of the line (trailing blanks and a ``#`` comment)."""
    hash_at = line.find("#")
    body, comment = (line, "") if hash_at < 0 else (line[:hash_at], line[hash_at:])
    stripped = _numbers_part(body)
    lead = body.find(stripped[0])
    if '"' in stripped:
        q = _quoted(stripped)
        assert q is not None  # a data row: _split_numbers read it
        pre, texts, seps, closing = q
        return (body[:lead] + pre, texts, seps,
                closing + body[lead + len(stripped):] + comment)
    if _COMMA_ROW(stripped):
        texts = stripped.split(",")
        seps = [","] * (len(texts) - 1)
    else:
        parts = _SEP_RE.split(stripped)
        texts, seps = parts[0::2], parts[1::2]
    return body[:lead], texts, seps, body[lead + len(stripped):] + comment


def _render_line(line: str, values: Sequence[float], column_decimals: Sequence[int],
                 decimals: int | None, extra: int | None = None) -> str:
    """A data line as read with ``values`` in place (``extra``: changed values by
    :func:`rounded_number`)."""
    prefix, texts, seps, suffix = _pieces(line)
    return _render_pieces(prefix, texts, seps, suffix, values, column_decimals, decimals, extra)


@dataclass(frozen=True, eq=False)
class TextLayout:
    """Every line of a numeric text file, to write new values in the same layout.

    Attributes
    ----------
    lines : tuple of str
        The lines without their line ending.
    newline : str
        ``"\\n"`` or ``"\\r\\n"``.
    final_newline : bool
    header : int or None
        0-based line index of the header / name line.
    data_lines : tuple of int
        0-based line index of each data row, in file order.
    ncols : int
    column_decimals : tuple of int
        Largest number of decimals per column in the file.
    encoding : str
        ``"utf-8"``, ``"utf-8-sig"`` (UTF-8 with a byte order mark) or ``"latin-1"`` (not
        UTF-8): the file is written back in it.
    values : ndarray, shape (rows, ncols)
    leading : tuple of int
        0-based indices of the non-numeric lines before the data other than the header
        (``notes=True``: further name or remark lines, a line of a different number of
        numbers); written back verbatim.
    notes_from : int or None
        0-based index of the first line of the trailing notes (``notes=True``): every line
        from there on is text after the coordinates, written back verbatim.
    decimal_comma : bool
        The file writes its numbers with decimal commas (``10,25;0,5``): :attr:`lines` hold
        its data rows with decimal points (as read), and :meth:`render` writes them back with
        commas.
    fortran_d : bool
        The file writes its exponents with Fortran's ``D`` (``0.1234D+01``): :attr:`lines`
        hold its data rows with ``E``, and :meth:`render` writes them back with ``D``.
    """

    lines: tuple[str, ...]
    newline: str
    final_newline: bool
    header: int | None
    data_lines: tuple[int, ...]
    ncols: int
    column_decimals: tuple[int, ...]
    encoding: str
    values: FloatArray
    leading: tuple[int, ...] = ()
    notes_from: int | None = None
    decimal_comma: bool = False
    fortran_d: bool = False

    @property
    def header_text(self) -> str | None:
        return None if self.header is None else self.lines[self.header]

    @property
    def rows(self) -> tuple[Row, ...]:
        """Each data row split into its pieces (built on demand from :attr:`lines`)."""
        rows = [_split_row(self.lines[i]) for i in self.data_lines]
        return tuple(r for r in rows if r is not None)  # every data line splits

    def line_numbers(self) -> list[int]:
        """1-based line number of each data row."""
        return [i + 1 for i in self.data_lines]

    def render(self, values: FloatArray, decimals: int | None = None,
               keep_rows: Iterable[int] = ()) -> str:
        """The file text with the data rows replaced by ``values`` (shape ``(rows, ncols)``).

        Rows listed in ``keep_rows`` are written exactly as they were (e.g. a Lednicer count
        line).
        """
        nrows = len(self.data_lines)
        if values.shape != (nrows, self.ncols):
            raise ValueError(f"values must have shape {(nrows, self.ncols)}, "
                             f"got {values.shape}")
        keep = set(int(k) for k in keep_rows)
        if decimals is None and not keep and not self.decimal_comma and not self.fortran_d:
            text = self._render_whole_block(values)
            if text is not None:
                return text
        if decimals is None:
            # a row whose every value is the one read is its line as read (format_number's
            # rule 2 for each number, and nothing to re-align): only the others are rendered
            same = (values == self.values) | (np.isnan(values) & np.isnan(self.values))
            redo = np.flatnonzero(~np.all(same, axis=1))
        else:
            redo = np.arange(nrows)
        if keep:
            redo = redo[~np.isin(redo, np.fromiter(keep, np.intp, count=len(keep)))]
        data_lines, cols = self.data_lines, self.column_decimals
        lines: Any = list(self.lines)
        if decimals is None and len(redo) >= _BLOCK_MIN_ROWS:
            # the common layout (one separator character, plain fixed-point numbers) rendered
            # for all rows at once; rows of any other style go through the row renderer
            lines = np.array(lines, dtype=object)
            redo = _render_plain_block(lines, np.asarray(data_lines, dtype=np.intp), redo,
                                       values, self.values, cols)
        for r in redo.tolist():
            li = data_lines[r]
            lines[li] = _render_line(lines[li], values[r].tolist(), cols, decimals)
        if not isinstance(lines, list):
            lines = lines.tolist()
        if self.decimal_comma or self.fortran_d:  # every data row as the file writes it
            for li in data_lines:
                if self.decimal_comma:
                    lines[li] = _point_to_comma(lines[li])
                if self.fortran_d:
                    lines[li] = _e_to_d(lines[li])
        text = self.newline.join(lines)
        if self.final_newline:
            text += self.newline
        return text


    def _render_whole_block(self, values: FloatArray) -> str | None:
        """:meth:`render` (no ``decimals``, no kept rows, decimal points) for a file whose data
        rows are one run of lines of the common layout (:func:`_render_plain_block`), every
        row rendered at once, unchanged ones included (the compiled writer copies their text):
        the header and the trailing lines joined around the written block, without splitting
        it into lines. None when the rows are not such a run (then :meth:`render` does the
        rows line by line): the same text either way."""
        nrows = len(self.data_lines)
        if nrows < _BLOCK_MIN_ROWS:
            return None
        a, b = self.data_lines[0], self.data_lines[-1]
        if b - a + 1 != nrows:
            return None
        lines = self.lines
        sep = next((c for c in _PLAIN_SEPS if c in lines[a]), None)
        if sep is None:
            return None
        got = _plain_block_bytes("\n".join(lines[a:b + 1]), sep, values, self.values,
                                 self.column_decimals)
        if got is None or not got[1].all():
            return None
        nl = self.newline
        body = got[0] if nl == "\n" else got[0].replace("\n", nl)
        head = nl.join(lines[:a]) + nl if a > 0 else ""
        tail = nl + nl.join(lines[b + 1:]) if b + 1 < len(lines) else ""
        return head + body + tail + (nl if self.final_newline else "")


# below this many rows to rewrite the row renderer is as fast as the block set-up
_BLOCK_MIN_ROWS = 64
_PLAIN_SEPS = (",", ";", " ", "\t")


def _render_plain_block(lines: np.ndarray, data_lines: np.ndarray, redo: np.ndarray,
                        values: FloatArray, old: FloatArray,
                        column_decimals: Sequence[int]) -> np.ndarray:
    """Render the rows ``redo`` of the common layout at once, in place in ``lines`` (an
    object array of the file's lines; ``data_lines`` the line of each row); return the rows
    left for the row renderer.

    The layout served: every line is its numbers joined by one separator character (``,``
    ``;``, a blank or a tab; nothing before, after or between them), every number plain
    fixed point (:func:`_is_plain`) with at least one decimal. For such a line
    :func:`_render_line` reduces to the separator joining :func:`_plain_number` of each
    changed value, a blank separator growing by what a shorter number gave up (a comma or
    semicolon has no padding to give or take): an unchanged value keeps its text; a changed
    one is written with its token's decimals, else the column's, where that reads back as
    exactly the value, else in the shortest exact form. The rows' bytes are planned and
    written by compiled passes (:func:`curvefair._kernels.text.plain_block_plan`, which
    decides the decimals exactly where ``|v| 10**d < 2**49`` and the shortest form, as
    ``repr`` writes it, for ``1e-4 <= |v| < 1e15``
    (:func:`~curvefair._kernels.text.shortest_decimal`), and
    :func:`~curvefair._kernels.text.plain_block_write`); Python writes the other shortest
    forms (the ``repr`` of their list, cut in the kernel) and the few values outside the
    decimals' range (:func:`_plain_number`). The same text as
    the row renderer, character for character (tests/test_io_text_layout.py compares both).
    """
    at = data_lines[redo]
    first = lines[at[0]]
    sep = next((c for c in _PLAIN_SEPS if c in first), None)
    if sep is None:
        return redo
    got = _plain_block_bytes("\n".join(lines[at].tolist()), sep, values[redo], old[redo],
                             column_decimals)
    if got is None:
        return redo
    out, row_ok = got
    rows_text = out.split("\n")
    lines[at[row_ok]] = np.array(rows_text, dtype=object)[row_ok]
    return redo[~row_ok]


def _plain_block_bytes(block: str, sep: str, values: FloatArray, old: FloatArray,
                       column_decimals: Sequence[int]) -> tuple[str, np.ndarray] | None:
    """The rows of ``block`` (lines joined by ``\\n``, ``m`` of them) rewritten with
    ``values`` (shape ``(m, k)``; ``old`` the values read) by the compiled plan and write
    passes, and which rows were of the plain layout (the others come back as they were), or
    None when the block is not ``m`` rows of ``k`` pieces of digits, points and minus signs
    joined by ``sep``."""
    from .._kernels.text import PYTHON, SHORTEST, plain_block_plan, plain_block_write

    m, k = values.shape
    try:
        buf = np.frombuffer(block.encode("ascii"), dtype=np.uint8)
    except UnicodeEncodeError:
        return None
    new = np.ascontiguousarray(values, dtype=np.float64).ravel()
    was = np.ascontiguousarray(old, dtype=np.float64).ravel()
    cols = np.asarray(column_decimals, dtype=np.int64)
    status = np.empty(m * k, dtype=np.int8)
    dec = np.empty(m * k, dtype=np.int64)
    start = np.empty(m * k, dtype=np.int64)
    length = np.empty(m * k, dtype=np.int64)
    new_len = np.empty(m * k, dtype=np.int64)
    row_ok = np.empty(m, dtype=bool)
    digits = np.empty(m * k, dtype=np.int64)
    sepb = ord(sep)
    halves = _row_halves(buf, m)
    if halves is None:
        npy = plain_block_plan(buf, sepb, k, m, new, was, cols, status, dec, start, length,
                               new_len, row_ok, digits)
    else:  # two blocks of rows on two threads (each a block of its own: the same plan)
        r1, off = halves
        t1 = r1 * k

        def plan(lo: int, hi: int, b: np.ndarray) -> int:
            return int(plain_block_plan(b, sepb, k, hi - lo, new[lo * k:hi * k],
                                        was[lo * k:hi * k], cols, status[lo * k:hi * k],
                                        dec[lo * k:hi * k], start[lo * k:hi * k],
                                        length[lo * k:hi * k], new_len[lo * k:hi * k],
                                        row_ok[lo:hi], digits[lo * k:hi * k]))

        a, b = _on_two_threads(lambda: plan(0, r1, buf[:off - 1]),
                               lambda: plan(r1, m, buf[off:]))
        npy = -1 if a < 0 or b < 0 else a + b
        start[t1:] += off  # (the second block's token starts, from the whole block's start)
    if npy < 0 or not row_ok.any():
        return None
    # the shortest exact forms (:func:`_shortest`) the kernel did not decide from the repr
    # of their list, cut and trimmed in the kernel; the few values outside the kernel's
    # exact range by the rule the row renderer follows (:func:`_plain_number`). Written per
    # block of rows (two blocks on two threads for a long block: its rows' texts joined by
    # the newline between them, the same bytes)
    raw = buf.tobytes() if npy else b""

    def inputs(lo: int, hi: int) -> tuple[Any, ...]:
        tl, th = lo * k, hi * k
        st = status[tl:th]
        short = st == SHORTEST
        nshort = int(np.count_nonzero(short)) if npy else 0
        short_buf = np.frombuffer(repr(new[tl:th][short].tolist())[1:-1].encode("ascii")
                                  if nshort else b"", dtype=np.uint8)
        strs: list[str] = []
        if npy:
            for t in (np.flatnonzero(st == PYTHON) + tl).tolist():
                a = int(start[t])
                strs.append(_plain_number(float(new[t]),
                                          raw[a:a + int(length[t])].decode("ascii"),
                                          int(cols[t % k])))
        py_start = np.zeros(len(strs) + 1, dtype=np.int64)
        py_start[1:] = np.cumsum(np.fromiter(map(len, strs), np.int64, count=len(strs)))
        py_buf = np.frombuffer("".join(strs).encode("ascii"), dtype=np.uint8)
        return (buf, sepb, k, hi - lo, new[tl:th], st, dec[tl:th], start[tl:th],
                length[tl:th], new_len[tl:th], short_buf, nshort, py_buf, py_start,
                digits[tl:th])

    if halves is None:
        out = plain_block_write(*inputs(0, m)).tobytes()
    else:
        a1, a2 = inputs(0, r1), inputs(r1, m)
        o1, o2 = _on_two_threads(lambda: plain_block_write(*a1), lambda: plain_block_write(*a2))
        out = b"\n".join((o1.tobytes(), o2.tobytes()))
    return out.decode("ascii"), row_ok


def _split_row(line: str) -> Row | None:
    """Parse a data line, or None when it is not all numbers."""
    if _split_numbers(line) is None:
        return None
    prefix, texts, seps, suffix = _pieces(line)
    return Row(prefix, tuple(texts), tuple(seps), suffix)


def _numbers_part(body: str) -> str:
    """A data line's text without its blanks around and one trailing ``,`` or ``;`` (what
    some exporters write after the last column), where the numbers are."""
    stripped = body.strip()
    if stripped[-1:] in (",", ";"):
        stripped = stripped[:-1].rstrip()
    return stripped


def _why_not(line: str) -> str:
    """Why a line of numbers is not read as one, for the message: Fortran's ``D`` exponents
    (``; ...``), or nothing."""
    body = line.split("#", 1)[0]
    if _D_EXP.search(body):
        return ("; numbers with a D exponent (Fortran's 1.5D+00) are not read: write them "
                "with E")
    return ""


_NUMBERISH = re.compile(r"[\"']?[+-]?\.?\d").match


def wordy(line: str) -> bool:
    """A line none of whose fields (between blanks, commas and semicolons) starts like a
    number (a digit, after a quote, a sign or a point: ``1.5``, ``"2"``, ``1.5D+00``,
    ``2024-01-05``): a units row or a title before the data, which the readers keep as it
    is (a line with a number in it may be a mistyped first row, and is refused)."""
    hash_at = line.find("#")
    body = (line if hash_at < 0 else line[:hash_at]).strip()
    return not any(_NUMBERISH(f) or _NUM_FULL(f) for f in _SEP_RE.split(body)[0::2])


_QFIELD = re.compile(rf'"({_NUM})"|({_NUM})', re.IGNORECASE)
_SEP_AT = re.compile(r"\s*[,;]\s*|\s+")


def _quoted(stripped: str) -> tuple[str, list[str], list[str], str] | None:
    """``(prefix, texts, seps, suffix)`` of a row whose numbers may stand in double quotes
    (``"1",0.5,0.25``: R's ``write.csv`` quotes its row names; some tools quote every
    field), the quotes being part of the prefix, separators and suffix, so that the numbers
    are read and rewritten as any other; None when it is not such a row."""
    texts: list[str] = []
    seps: list[str] = []
    pre = ""
    pos, n = 0, len(stripped)
    while True:
        m = _QFIELD.match(stripped, pos)
        if m is None:
            return None
        g = 1 if m.group(1) is not None else 2
        if texts:
            seps[-1] += stripped[pos:m.start(g)]  # the opening quote
        else:
            pre = stripped[pos:m.start(g)]
        texts.append(m.group(g))
        closing = stripped[m.end(g):m.end()]
        if m.end() == n:
            return pre, texts, seps, closing
        sm = _SEP_AT.match(stripped, m.end())
        if sm is None:
            return None
        seps.append(closing + sm.group(0))
        pos = sm.end()


def _split_numbers(line: str) -> list[str] | None:
    """The number texts of a data line (as :func:`_split_row`), or None when it is not all
    numbers: what reading needs, without the pieces that only a rewrite of the row uses."""
    hash_at = line.find("#")
    stripped = _numbers_part(line if hash_at < 0 else line[:hash_at])
    if not stripped:
        return None
    if '"' in stripped:
        q = _quoted(stripped)
        return None if q is None else q[1]
    if _COMMA_ROW(stripped):
        return stripped.split(",")
    if _BLANK_ROW(stripped):
        return stripped.split()
    toks = _SEP_RE.split(stripped)[0::2]
    return toks if all(map(_NUM_FULL, toks)) else None


def read_lines(path: str | os.PathLike[str]) -> tuple[list[str], str, bool, str]:
    """Lines, newline, final-newline flag and encoding of a text file."""
    lines, newline, final, encoding, _ = _read_text(path)
    return lines, newline, final, encoding


def _read_text(path: str | os.PathLike[str]) -> tuple[list[str], str, bool, str, str | None]:
    """:func:`read_lines` and the decoded text when its lines are joined by ``\\n`` (LF and
    CR LF files; None for CR files): what a block of lines is a slice of."""
    try:
        with open(path, "rb") as f:
            raw = f.read()
    except OSError as exc:
        raise FileFormatError(f"cannot read the file: {exc.strerror or exc}", path) from None
    if raw.startswith((b"\xff\xfe", b"\xfe\xff")):
        # UTF-16 with a byte order mark (a spreadsheet's "Unicode text"): written back as
        # UTF-16 with a mark, in the machine's byte order (Python's ``utf-16`` codec)
        try:
            text = raw.decode("utf-16")
        except UnicodeDecodeError as exc:
            raise FileFormatError(f"not UTF-16 text after its byte order mark ({exc.reason})",
                                  path) from None
        encoding = "utf-16"
    else:
        if b"\x00" in raw:
            line = raw[: raw.index(b"\x00")].count(b"\n") + 1
            raise FileFormatError("binary data (NUL byte) in a text file", path, line)
        # the BOM, if any, is part of the encoding's name so that a writer given ``encoding``
        # writes it back (``utf-8-sig``); a file that is not UTF-8 is written back as Latin-1,
        # byte for byte where its text is unchanged
        encoding = "utf-8-sig" if raw.startswith(b"\xef\xbb\xbf") else "utf-8"
        try:
            text = raw.decode("utf-8-sig")
        except UnicodeDecodeError:
            encoding = "latin-1"
            text = raw.decode("latin-1")
    # line endings: CR LF (Windows), LF, or CR alone (classic Mac OS, still written by some
    # spreadsheets), kept as found
    if "\r\n" in text:
        newline = "\r\n"
    elif "\r" in text and "\n" not in text:
        newline = "\r"
    else:
        newline = "\n"
    final = text.endswith(newline)
    body = text.replace("\r\n", "\n") if newline == "\r\n" else text
    lines = body.split("\n" if newline == "\r\n" else newline)
    if final:
        lines.pop()
    return lines, newline, final, encoding, body if newline != "\r" else None


def parse_text(path: str | os.PathLike[str], *, header: bool = True,
               ncols: Sequence[int] | None = (2, 3), what: str = "points file",
               notes: bool = False) -> TextLayout:
    """Parse a numeric text file into a :class:`TextLayout`.

    Comments start with ``#`` (whole lines or after the numbers), blank lines are kept, one
    non-numeric line before the first data row is the header (or the name line of an airfoil)
    when ``header`` is True; further lines before the data in which no field is a number (a
    units row ``mm,mm``, a title) are kept as :attr:`TextLayout.leading` lines.

    Separators: blanks, commas or semicolons (one after the last column allowed); a file
    whose first data row writes decimal commas (:func:`decimal_commas`: ``10,25;0,5``) is read
    with them, its data rows kept with decimal points in :attr:`TextLayout.lines` and written
    back with commas (a row that then has a decimal point too is refused). ``ncols``: the
    numbers of columns a row may have (None: any from 2 on, every row as many as the first).

    ``notes=True`` (airfoil files, where remarks, URLs and ``Thickness: 7.99%`` lines are
    common): every line before the first row of ``ncols`` numbers is a leading line (the
    first non-blank one the header), and the first non-numeric line after the data starts
    the trailing notes, which run to the end of the file. Both are kept verbatim
    (:attr:`TextLayout.leading`, :attr:`TextLayout.notes_from`).

    Raises
    ------
    FileFormatError
        Empty file, no data, a non-numeric line among the data, a different number of columns
        than the first data row, a column count not in ``ncols``; with ``notes=True``, a row of
        ``ncols`` numbers after the notes began (notes between coordinates are ambiguous).
    """
    lines, newline, final, encoding, body = _read_text(path)
    head: int | None = None
    leading: list[int] = []
    notes_from: int | None = None
    data_lines: list[int] = []
    texts: list[str] = []  # every number's text, row after row
    bulk: tuple[FloatArray, tuple[int, ...]] | None = None  # the rows read at once, if any
    width: int | None = None
    comma = False  # decimal commas (``10,25;0,5``): data rows read with decimal points
    fortran = False  # D exponents (``0.1234D+01``): data rows read with E
    for i, line in enumerate(lines):
        s = line.strip()
        if not s or s.startswith("#"):
            continue
        if not comma and not data_lines and decimal_commas(line):
            comma = True
        if not fortran and not data_lines and fortran_exponents(line):
            fortran = True
        if fortran:
            if _E_EXP.search(line.split("#", 1)[0]):
                raise FileFormatError(
                    f"E exponents in a file of Fortran D exponents ({s[:40]!r}): two number "
                    "styles; curvefair does not guess which to write", path, i + 1)
            lined = _d_to_e(line)
            if lined != line and _split_numbers(lined) is not None:
                lines[i] = line = lined
        if comma:
            if "." in line.split("#", 1)[0] and (decimal_commas(line)
                                                  or _split_numbers(line) is not None):
                raise FileFormatError(
                    f"decimal points in a file of decimal commas ({s[:40]!r}): thousands "
                    "separators, or two number styles; curvefair does not guess which",
                    path, i + 1)
            pointed = _comma_to_point(line)
            row = _split_numbers(pointed)
            if row is not None and pointed != line:
                lines[i] = line = pointed
        else:
            row = _split_numbers(line)
        if notes and notes_from is not None:
            if row is not None and len(row) == width:
                raise FileFormatError(
                    f"a row of {width} numbers after the text at line {notes_from + 1} that "
                    "ends the coordinates (notes between coordinates are not read)", path, i + 1)
            continue
        if notes and not data_lines and (row is None or (ncols is not None
                                                         and len(row) not in ncols)):
            if head is None and header:
                head = i
            else:
                leading.append(i)
            continue
        if row is None:
            if notes:
                notes_from = i
                continue
            if not data_lines and head is None and header:
                head = i
                continue
            if not data_lines and header and wordy(line):
                # a further line before the data without a number in it (a units row, a
                # title): kept as it is; one with a number may be a mistyped first row
                leading.append(i)
                continue
            short = s if len(s) <= 60 else s[:57] + "..."
            if data_lines:
                raise FileFormatError(f"not a row of numbers: {short!r}{_why_not(s)}", path,
                                      i + 1)
            raise FileFormatError(f"not a row of numbers (and not a header): {short!r}"
                                  f"{_why_not(s)}", path, i + 1)
        k = len(row)
        if width is None:
            if (k not in ncols) if ncols is not None else k < 2:
                need = " or ".join(map(str, ncols)) if ncols is not None else "at least 2"
                raise FileFormatError(f"{what} rows need {need} columns, got {k}", path, i + 1)
            width = k
        elif k != width:
            raise FileFormatError(
                f"row has {k} columns but the first data row (line {data_lines[0] + 1}) has "
                f"{width}", path, i + 1)
        data_lines.append(i)
        texts.extend(row)
        if len(data_lines) == 1 and not notes and not comma and not fortran and \
                len(lines) - i > _BLOCK_MIN_ROWS:
            bulk = _plain_rows(lines, i + 1, k, body, final)
            if bulk is not None:  # every line after the first row is a row like it
                data_lines.extend(range(i + 1, len(lines)))
                break
    if not data_lines:
        if not any(line.strip() for line in lines):
            raise FileFormatError(f"empty {what}", path)
        hint = next((h for h in map(_why_not, lines) if h), "")
        if not hint and ncols is not None:  # rows of numbers, but not of the width wanted
            for j, ln in enumerate(lines):
                got = _split_numbers(ln) if ln.strip() and not ln.lstrip().startswith("#") \
                    else None
                if got is not None:
                    need = " or ".join(map(str, ncols))
                    raise FileFormatError(
                        f"no data rows in the {what}: its rows have {len(got)} "
                        f"number{'s' if len(got) != 1 else ''}, {what} rows have {need}",
                        path, j + 1)
        raise FileFormatError(f"no data rows in the {what}{hint}", path)
    assert width is not None
    values = np.array(list(map(float, texts)), dtype=np.float64)
    col_dec = _column_decimals(texts, width)
    if bulk is not None:
        values = np.concatenate([values, bulk[0]])
        col_dec = tuple(map(max, col_dec, bulk[1]))
    values = values.reshape(-1, width)
    return TextLayout(tuple(lines), newline, final, head, tuple(data_lines), width,
                      col_dec, encoding, values, tuple(leading), notes_from, comma, fortran)


_HALVES_MIN_ROWS = 100_000  # rows from which a plain block is scanned / planned in two halves


def _row_halves(buf: np.ndarray, nrows: int) -> tuple[int, int] | None:
    """Where to cut a block of ``nrows`` rows (``buf``: their bytes joined by ``\\n``) in two
    for two threads: ``(r1, off)``, the first ``r1 = nrows // 2`` rows in ``buf[:off - 1]`` and
    the others in ``buf[off:]``, each again rows joined by ``\\n`` without a final one; None
    for one thread, a short block, or a block without that many rows (then the kernel on the
    whole block says what it is)."""
    from .._kernels.text import row_start

    if _threads.THREADS < 2 or nrows < _HALVES_MIN_ROWS:
        return None
    r1 = nrows // 2
    off = int(row_start(buf, r1))
    return (r1, off) if off > 0 else None


def _on_two_threads(first: Callable[[], Any], second: Callable[[], Any]) -> tuple[Any, Any]:
    """``(first(), second())`` as two ranges of :func:`curvefair._threads.ranges` (both
    ``nogil`` compiled work on disjoint outputs): one on the worker thread when it is free,
    else both on the calling thread."""
    a, b = _threads.ranges(lambda lo, hi: first() if lo == 0 else second(), 0, 2, 2, 2, 2)
    return a, b


def _scan_rows(buf: np.ndarray, sep: int, width: int, nrows: int, values: FloatArray,
               col_dec: np.ndarray, slow_start: np.ndarray, slow_end: np.ndarray) -> int:
    """:func:`curvefair._kernels.text.scan_plain_rows` over the whole block, a long block in
    two halves on two threads (:func:`_row_halves`): each half is a block of rows of its
    own, so the values are the same; the column decimals are the larger of the halves', the
    numbers left to Python the first half's then the second's (byte ranges in ``buf``)."""
    from .._kernels.text import scan_plain_rows

    halves = _row_halves(buf, nrows)
    if halves is None:
        return int(scan_plain_rows(buf, sep, width, nrows, values, col_dec, slow_start,
                                   slow_end))
    r1, off = halves
    t1 = r1 * width
    cd2 = np.zeros(width, dtype=np.int64)
    ss2 = np.empty(values.shape[0] - t1, dtype=np.int64)
    se2 = np.empty(values.shape[0] - t1, dtype=np.int64)
    a, b = _on_two_threads(
        lambda: int(scan_plain_rows(buf[:off - 1], sep, width, r1, values[:t1], col_dec,
                                    slow_start, slow_end)),
        lambda: int(scan_plain_rows(buf[off:], sep, width, nrows - r1, values[t1:], cd2,
                                    ss2, se2)))
    if a < 0 or b < 0:
        return -1
    np.maximum(col_dec, cd2, out=col_dec)
    slow_start[a:a + b] = ss2[:b] + off
    slow_end[a:a + b] = se2[:b] + off
    return a + b


def _plain_rows(lines: list[str], start: int, width: int, body: str | None = None,
                final: bool = False) -> tuple[FloatArray, tuple[int, ...]] | None:
    """The values (row after row) and the largest decimals per column of ``lines[start:]``
    when every one of them is a row of ``width`` numbers joined by one separator character
    (``,``, ``;``, a blank or a tab) and nothing else, or None (the line-by-line reader then
    goes on, with its own messages).

    One compiled pass over the block's bytes (:func:`curvefair._kernels.text.scan_plain_rows`)
    instead of one check per line: every piece between the separators is a number of
    ``_NUM``'s grammar without ``nan`` / ``inf`` (exactly what Python's ``float`` reads over
    digits, ``.``, ``e``/``E`` and signs), every line has ``width`` of them. The values are
    those ``float`` gives (the kernel's fast path is exact; the rest is read by ``float``).

    ``body`` (the file's text, its lines joined by ``\\n``, ``final``: it ends with one), when
    given, is sliced from the block's first line instead of joining the lines again (the
    lines before it are as read: a reader that rewrites lines does not read in bulk); the
    kernel checks the row count either way."""
    nrows = len(lines) - start
    first = lines[start]
    sep = next((c for c in _PLAIN_SEPS if c in first), None)
    if sep is None or width < 2:
        return None
    block = None
    if body is not None:
        off = sum(len(ln) + 1 for ln in lines[:start])
        block = body[off:len(body) - 1] if final else body[off:]
        if not block.startswith(first):
            block = None
    if block is None:
        block = "\n".join(lines[start:])
    buf = np.frombuffer(block.encode("utf-8"), dtype=np.uint8)
    values = np.empty(nrows * width)
    col_dec = np.zeros(width, dtype=np.int64)
    slow_start = np.empty(nrows * width, dtype=np.int64)
    slow_end = np.empty(nrows * width, dtype=np.int64)
    nslow = _scan_rows(buf, ord(sep), width, nrows, values, col_dec, slow_start, slow_end)
    if nslow < 0:
        return None
    if nslow:  # the kernel's NaN marks them, in order (no NaN is read: "nan" is not a row's)
        raw = buf.tobytes()
        values[np.isnan(values)] = [
            float(raw[a:b]) for a, b in zip(slow_start[:nslow].tolist(),
                                            slow_end[:nslow].tolist(), strict=True)]
    return values, tuple(int(d) for d in col_dec)


def _column_decimals(texts: list[str], width: int) -> tuple[int, ...]:
    """Largest number of decimals per column (the ``decimals`` of :meth:`Token.parse` for each
    text), by array operations: the digits between the point and the end of the mantissa,
    which ends at an ``e``/``E`` or at the end of the text."""
    n = len(texts)
    joined = "".join(texts)
    end = np.fromiter(map(len, texts), np.intp, count=n)
    point = np.fromiter(map(str.find, texts, repeat(".")), np.intp, count=n)
    for e in "eE":
        if e in joined:
            at = np.fromiter(map(str.find, texts, repeat(e)), np.intp, count=n)
            end = np.where(at >= 0, at, end)
    dec = np.where(point >= 0, end - point - 1, 0).reshape(-1, width)
    return tuple(int(d) for d in dec.max(axis=0))


def fresh_text(values: FloatArray, *, sep: str, header: str | None = None,
               comments: Sequence[str] = ()) -> str:
    """Text of a new points file: shortest exact numbers, ``sep`` between columns."""
    out = [f"# {c}" for c in comments]
    if header is not None:
        out.append(header)
    out.extend(sep.join(_shortest(float(v)) for v in row) for row in values)
    return "\n".join(out) + "\n"


def all_integral(vals: Sequence[Any]) -> bool:
    return all(math.isfinite(v) and float(v).is_integer() for v in vals)
