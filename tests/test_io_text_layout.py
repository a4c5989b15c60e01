"""The numeric text layout (curvefair.io._text): what is read, and what is written back.

Random files in every style the reader accepts (blanks, tabs, commas, semicolons; padded and
right-aligned columns; fixed, exponent, ``+``-signed, bare-point numbers, ``nan``/``inf``;
comments at the end of rows; CRLF) are checked against plain computations:

- the values are Python's ``float`` of the tokens a plain split gives;
- writing the values read gives the file back byte for byte;
- writing changed values: every number written reads back as exactly the value given (no
  ``decimals``), unchanged rows keep their line, and the text equals that of a slow reference
  renderer written here, token by token with :func:`format_number` (the layout's rule for
  styles and right-aligned columns); with ``decimals`` every row is rewritten to that many
  decimals.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from curvefair.io._text import Token, format_number, parse_text

_SPLIT = re.compile(r"(\s*[,;]\s*|\s+)")


def _style(rng: np.random.Generator, v: float) -> str:
    """``v`` written in one of the styles found in real files."""
    k = int(rng.integers(7))
    if k == 0:
        d = int(rng.integers(0, 9))
        s = f"{v:.{d}f}" + ("." if d == 0 and rng.integers(2) else "")
    elif k == 1:
        s = f"{v:.{int(rng.integers(1, 8))}e}"
        if rng.integers(2):
            s = s.replace("e", "E")
    elif k == 2:
        s = repr(v)
    elif k == 3:  # bare point
        s = f"{v:.{int(rng.integers(1, 7))}f}"
        s = s.replace("0.", ".", 1) if s.startswith(("0.", "-0.")) else s
    elif k == 4:  # explicit plus
        s = f"{v:+.{int(rng.integers(1, 6))}f}"
    elif k == 5:
        s = f"{v:.{int(rng.integers(1, 5))}E}".replace("E+0", "E+").replace("E-0", "E-")
    else:
        s = f"{v:.17g}"
    return s


def _random_file(rng: np.random.Generator, nrows: int, ncols: int) -> str:
    sep = str(rng.choice([" ", "\t", ",", ", ", ";", " ; "]))
    aligned = sep.strip() == "" and bool(rng.integers(2))
    lines = ["# made by a test", "x y z"[: 2 * ncols - 1] if rng.integers(2) else "# no header"]
    for _ in range(nrows):
        vals = rng.normal(scale=10.0 ** rng.integers(-3, 4), size=ncols)
        toks = [_style(rng, float(v)) for v in vals]
        if rng.random() < 0.02:
            toks[int(rng.integers(ncols))] = str(rng.choice(["nan", "inf", "-inf", "NaN"]))
        if aligned:
            line = "".join(" " + t.rjust(15) for t in toks)
        else:
            line = " " * int(rng.integers(0, 3)) + sep.join(toks)
        if rng.random() < 0.05:
            line += "   # remark"
        lines.append(line)
        if rng.random() < 0.03:
            lines.append("" if rng.integers(2) else "# between rows")
    nl = "\r\n" if rng.integers(2) else "\n"
    return nl.join(lines) + (nl if rng.integers(2) else "")


def _reference_render(lay, values: np.ndarray, decimals: int | None) -> str:
    """Every data row rebuilt token by token from a plain split of its line: each number by
    :func:`format_number` with its own parsed :class:`Token`, the blanks before a number
    absorbing its change of length."""
    lines = list(lay.lines)
    for r, li in enumerate(lay.data_lines):
        line = lay.lines[li]
        h = line.find("#")
        body, comment = (line, "") if h < 0 else (line[:h], line[h:])
        core = body.strip()
        prefix = body[: len(body) - len(body.lstrip())]
        trail = body[len(body.rstrip()):]
        parts = _SPLIT.split(core)
        out, lead = [], prefix
        for j, text in enumerate(parts[0::2]):
            s = format_number(float(values[r, j]), Token.parse(text), lay.column_decimals[j],
                              decimals)
            delta = len(s) - len(text)
            c = lead.rstrip(" \t")
            pad = lead[len(c):]
            if delta and pad:
                lead = c + pad[0] * max(len(pad) - delta, 0 if j == 0 else 1)
            out += [lead, s]
            lead = parts[2 * j + 1] if 2 * j + 1 < len(parts) else ""
        lines[li] = "".join(out) + trail + comment
    text = lay.newline.join(lines)
    return text + lay.newline if lay.final_newline else text


@pytest.mark.parametrize("seed", range(12))
def test_read_write_back_and_changed_values_against_a_plain_reference(tmp_path, seed):
    rng = np.random.default_rng(seed)
    ncols = int(rng.choice([2, 3]))
    text = _random_file(rng, int(rng.integers(1, 400)), ncols)
    path = tmp_path / "p.csv"
    path.write_bytes(text.encode())
    lay = parse_text(path)
    # values: Python's float of the plainly split tokens
    rows = [ln for ln in text.replace("\r\n", "\n").split("\n")[2:]
            if ln.strip() and not ln.lstrip().startswith("#")]
    want = np.array([[float(t) for t in _SPLIT.split(ln.split("#")[0].strip())[0::2]]
                     for ln in rows])
    np.testing.assert_array_equal(lay.values, want)  # NaN == NaN here
    assert lay.column_decimals == tuple(
        max(Token.parse(t).decimals for ln in rows
            for t in [_SPLIT.split(ln.split("#")[0].strip())[2 * j]]) for j in range(ncols))
    # the values read write the file back byte for byte
    assert lay.render(lay.values).encode() == text.encode()
    # changed values: some rows, some columns
    new = lay.values.copy()
    pick = (rng.random(new.shape) < 0.3) & np.isfinite(new)
    new[pick] += rng.normal(scale=1e-3, size=int(pick.sum())) * np.abs(new[pick]).clip(1e-9)
    new[np.isnan(new)] = 0.0  # a nan replaced by a number
    out = lay.render(new)
    assert out == _reference_render(lay, new, None)
    back = tmp_path / "q.csv"
    back.write_bytes(out.encode())
    lay2 = parse_text(back)
    np.testing.assert_array_equal(lay2.values, new)  # every number reads back exactly
    changed = np.any(pick | np.isnan(lay.values), axis=1)  # (a nan is now 0.0)
    for r in np.flatnonzero(~changed):
        assert lay2.lines[lay2.data_lines[r]] == lay.lines[lay.data_lines[r]]
    # an explicit number of decimals rewrites every row to it
    d = int(rng.integers(1, 6))
    out_d = lay.render(new, decimals=d)
    assert out_d == _reference_render(lay, new, d)
    fin = np.isfinite(new)
    # fixed style: within half a unit of the last decimal; exponent style: of the mantissa's
    err = np.abs(parse_text_of(tmp_path, out_d)[fin] - new[fin])
    assert np.all(err <= 0.5 * 10.0 ** -d * np.maximum(1.0, np.abs(new[fin])) * (1 + 1e-9))


def parse_text_of(tmp_path, text: str) -> np.ndarray:
    p = tmp_path / "d.csv"
    p.write_bytes(text.encode())
    return parse_text(p).values


def test_keep_rows_and_the_token_view(tmp_path):
    path = tmp_path / "a.dat"
    path.write_text("name\n   1.50   2.0e+01\n  -0.25  +.5 # c\n")
    lay = parse_text(path)
    assert [t.decimals for t in lay.rows[0].tokens] == [2, 1]
    assert [(t.plus, t.bare_point) for t in lay.rows[1].tokens] == [(False, False), (True, True)]
    out = lay.render(np.array([[1.5, 30.0], [-0.125, 0.75]]), keep_rows=[1])
    assert out == "name\n   1.50   3.0e+01\n  -0.25  +.5 # c\n"
    assert math.isclose(float(out.split()[2]), 30.0)


@pytest.mark.parametrize("column", [["3.", "-4.", "12."], ["3.", "-4.50", "0.125"],
                                    ["-0.0", "0.00", "1.5"], ["7", "-8", "9"]])
def test_point_only_and_zero_decimal_columns_against_the_reference(tmp_path, column):
    """Columns whose numbers have no decimals after their point (``3.``), mixed decimals,
    signed zeros and integers: changed values written as the slow reference writes them, and
    read back exactly."""
    path = tmp_path / "c.txt"
    path.write_text("".join(f"{t} 1.0\n" for t in column))
    lay = parse_text(path, header=False)
    for new_x in ([3.25, -4.0, 12.0], [-0.0, 0.0, -1e-300], [1e22, -2.5e-7, 5.0]):
        new = lay.values.copy()
        new[:, 0] = new_x
        out = lay.render(new)
        assert out == _reference_render(lay, new, None)
        np.testing.assert_array_equal(parse_text_of(tmp_path, out)[:, 0], new_x)


def _plain_file(rng: np.random.Generator, sep: str, nrows: int, ncols: int) -> str:
    """Rows of plain fixed-point numbers joined by one separator character (the layout the
    block renderer serves), with a few rows of other styles among them."""
    lines = ["x" + sep + "y" + (sep + "z" if ncols == 3 else "")]
    for _ in range(nrows):
        vals = rng.normal(scale=10.0 ** rng.integers(-2, 3), size=ncols)
        toks = [f"{v:.{int(rng.integers(1, 9))}f}" for v in vals]
        u = rng.random()
        if u < 0.02:
            toks[0] = str(int(rng.integers(-5, 5)))          # an integer
        elif u < 0.03:
            toks[-1] = "3."                                    # a point, no decimals
        elif u < 0.04:
            toks[0] = "0.000" if rng.integers(2) else "-0.00"  # signed zeros
        lines.append(sep.join(toks))
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("sep", [",", ";", " ", "\t"])
@pytest.mark.parametrize("seed", range(3))
def test_block_renderer_writes_what_the_row_renderer_writes(tmp_path, sep, seed):
    """Many changed rows of the common layout are rendered at once
    (:func:`_render_plain_block`); the text must be the slow reference's, value for value:
    unchanged values, values exact at their token's decimals or at the column's, signed and
    tiny values that round to zero, huge values, shortest-form values."""
    from curvefair.io import _text

    rng = np.random.default_rng(100 + seed)
    ncols = 2 + seed % 2
    path = tmp_path / "p.csv"
    path.write_text(_plain_file(rng, sep, 600, ncols))
    lay = parse_text(path)
    new = lay.values.copy()
    kind = rng.integers(0, 8, size=new.shape)
    d = rng.integers(1, 9, size=new.shape)
    for (r, j), c in np.ndenumerate(kind):
        v = new[r, j]
        if c == 1:
            new[r, j] = v + rng.normal() * 1e-4                   # shortest form
        elif c == 2:
            new[r, j] = float(f"{v + 0.01:.{d[r, j]}f}")          # exact at some decimals
        elif c == 3:
            new[r, j] = float(f"{v + 0.01:.{lay.column_decimals[j]}f}")  # the column's
        elif c == 4:
            new[r, j] = -0.0 if rng.integers(2) else -1e-12 * rng.random()
        elif c == 5:
            new[r, j] = float(rng.choice([1e17, -3.5e15, 2.0 ** 50 + 0.5, 123456789.125]))
        elif c == 6:
            new[r, j] = float(f"{v:.1f}")
    out = lay.render(new)
    assert out == _reference_render(lay, new, None)
    np.testing.assert_array_equal(parse_text_of(tmp_path, out), new)
    # the block renderer served every row of its layout and left exactly the others
    lines = np.array(lay.lines, dtype=object)
    redo = np.arange(len(lay.data_lines))
    left = _text._render_plain_block(lines, np.array(lay.data_lines), redo, new, lay.values,
                                     lay.column_decimals).tolist()
    odd = [r for r in redo.tolist()
           if not all(re.fullmatch(r"-?\d+\.\d+", t)
                      for t in lay.lines[lay.data_lines[r]].split(sep))]
    assert left == odd
    assert len(left) < len(redo) // 10


def _read_both(monkeypatch, path):
    """parse_text with the block reader, then with the line-by-line reader only: both
    results (or both errors' texts)."""
    from curvefair.io import _text

    out = []
    for block_min in (_text._BLOCK_MIN_ROWS, 10 ** 12):
        monkeypatch.setattr(_text, "_BLOCK_MIN_ROWS", block_min)
        try:
            out.append(parse_text(path))
        except ValueError as exc:
            out.append(str(exc))
    return out


@pytest.mark.parametrize("sep", [",", ";", " ", "\t"])
def test_block_reader_reads_what_the_line_reader_reads(tmp_path, monkeypatch, sep):
    """Files of the common layout are read with one check of the whole block: the same
    values, decimals and row lines as the line-by-line reader, in plain, exponent and signed
    styles."""
    rng = np.random.default_rng(7)
    text = _plain_file(rng, sep, 500, 2)
    lines = text.splitlines()
    lines[300] = sep.join(["1.5e-3", "+2.25E+01"])   # exponent and signed numbers
    lines[301] = sep.join(["-.5", "7"])
    path = tmp_path / "p.csv"
    path.write_text("\n".join(lines) + "\n")
    fast, slow = _read_both(monkeypatch, path)
    np.testing.assert_array_equal(fast.values, slow.values)
    assert fast.column_decimals == slow.column_decimals
    assert fast.data_lines == slow.data_lines and fast.header == slow.header
    assert fast.values.shape == (500, 2)
    assert float(lines[300].split(sep)[1]) == fast.values[299, 1] == 22.5


@pytest.mark.parametrize("bad", ["1.0,abc", "1.0,,2.0", "1.0", "1.0,2.0,3.0", "# a comment",
                                 "", "1.0, 2.0", "1.0,2.0 # note", "1e,2.0", "-,2.0",
                                 "1.0,2.0,", "nan,1.0", "1_0.0,2.0"])
def test_block_reader_leaves_every_other_line_to_the_line_reader(tmp_path, monkeypatch, bad):
    """A line the block check does not accept sends the file to the line-by-line reader: the
    same result, or the same error naming the same line."""
    rng = np.random.default_rng(8)
    lines = _plain_file(rng, ",", 300, 2).splitlines()
    lines[200] = bad
    path = tmp_path / "p.csv"
    path.write_text("\n".join(lines) + "\n")
    fast, slow = _read_both(monkeypatch, path)
    if isinstance(slow, str):
        assert fast == slow
        assert ":201: " in slow
    else:
        np.testing.assert_array_equal(fast.values, slow.values)
        assert fast.data_lines == slow.data_lines
        assert fast.column_decimals == slow.column_decimals
