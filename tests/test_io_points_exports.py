"""Points files as spreadsheets and older tools export them.

Each of these was refused before, with a message that named the wrong cause:

- UTF-16 text with a byte order mark (Excel's "Unicode Text"): "binary data (NUL byte)";
- lines ended by a carriage return alone (classic Mac OS; some spreadsheets still write it):
  "no data rows";
- a separator after the last column (``1.5,2.5,``): "not a row of numbers".

They are now read, and written back in their own encoding, line endings and separators. The
written files are checked with Python's codecs and ``str.split``, not curvefair's reader.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import curvefair as cf
from curvefair import read_curves, write_curves

TOL = 0.01


def _arc(n: int = 40) -> np.ndarray:
    rng = np.random.default_rng(3)
    t = np.linspace(0.0, 3.0, n)
    return np.c_[10 * np.cos(t), 10 * np.sin(t) + 0.01 * rng.normal(size=n)]


def _fair_file(src: Path, out: Path) -> None:
    (rec,) = read_curves(src)
    write_curves(out, [rec.with_curve(cf.fair(rec.curve, tol=TOL).curve)], tol=TOL)


def _check(text_in: str, text_out: str, newline: str, sep: str, trailing: str,
           header: str | None) -> None:
    a, b = text_in.split(newline), text_out.split(newline)
    assert a[-1] == b[-1] == ""  # both end with the line ending
    a, b = a[:-1], b[:-1]
    assert len(a) == len(b)
    if header is not None:
        assert a[0] == b[0] == header
        a, b = a[1:], b[1:]
    assert all(ln.endswith(trailing) for ln in b) and all("\r" not in ln and "\n" not in ln
                                                           for ln in b)
    def nums(lines: list[str]) -> np.ndarray:
        return np.array([[float(v) for v in ln[:len(ln) - len(trailing)].split(sep)]
                         for ln in lines])

    pa, pb = nums(a), nums(b)
    moves = np.linalg.norm(pb - pa, axis=1)
    assert moves.max() <= TOL and np.count_nonzero(moves) > 20
    assert all(x == y for x, y, m in zip(a, b, moves, strict=True) if m == 0)


@pytest.mark.parametrize("bom", [b"\xff\xfe", b"\xfe\xff"])
def test_utf16_with_a_byte_order_mark(tmp_path, bom):
    P = _arc()
    text = "x\ty\r\n" + "".join(f"{x:.4f}\t{y:.4f}\r\n" for x, y in P)
    codec = "utf-16-le" if bom == b"\xff\xfe" else "utf-16-be"
    src = tmp_path / "in.txt"
    src.write_bytes(bom + text.encode(codec))
    (rec,) = read_curves(src)
    np.testing.assert_array_equal(rec.points, np.round(P, 4))
    out = tmp_path / "out.txt"
    _fair_file(src, out)
    raw = out.read_bytes()
    assert raw[:2] in (b"\xff\xfe", b"\xfe\xff")  # UTF-16 with its mark (machine's order)
    _check(text, raw.decode("utf-16"), "\r\n", "\t", "", "x\ty")


def test_lines_ended_by_a_carriage_return_alone(tmp_path):
    P = _arc()
    text = "x y\r" + "".join(f"{x:.4f} {y:.4f}\r" for x, y in P)
    src = tmp_path / "in.txt"
    src.write_bytes(text.encode())
    (rec,) = read_curves(src)
    assert rec.points.shape == (40, 2)
    out = tmp_path / "out.txt"
    _fair_file(src, out)
    got = out.read_bytes().decode()
    assert "\n" not in got
    _check(text, got, "\r", " ", "", "x y")


@pytest.mark.parametrize("sep", [",", ";"])
def test_a_separator_after_the_last_column(tmp_path, sep):
    P = _arc()
    text = f"x{sep}y{sep}\n" + "".join(f"{x:.4f}{sep}{y:.4f}{sep}\n" for x, y in P)
    src = tmp_path / "in.csv"
    src.write_text(text, encoding="utf-8", newline="")
    (rec,) = read_curves(src)
    assert rec.points.shape == (40, 2)
    out = tmp_path / "out.csv"
    _fair_file(src, out)
    _check(text, out.read_text(encoding="utf-8"), "\n", sep, sep, f"x{sep}y{sep}")


def test_a_trailing_separator_beside_point_numbers(tmp_path):
    """The header's own trailing separator does not hide its column names."""
    P = _arc()
    text = "id,x,y,\n" + "".join(f"{i + 1},{x:.4f},{y:.4f},\n" for i, (x, y) in enumerate(P))
    src = tmp_path / "in.csv"
    src.write_text(text, encoding="utf-8", newline="")
    with pytest.warns(cf.io.ColumnsKept):
        (rec,) = read_curves(src)
    assert rec.source["columns"] == (1, 2)


def test_a_units_row_and_a_title_before_the_data_are_kept(tmp_path):
    """Lines before the data in which no field is a number are kept as they are (they were
    refused: "not a row of numbers (and not a header)"); the one naming the columns counts."""
    P = _arc()
    pre = "Curve export, tool v2\nid,x,y\n-,mm,mm\n"
    text = pre + "".join(f"{i + 1},{x:.4f},{y:.4f}\n" for i, (x, y) in enumerate(P))
    src = tmp_path / "in.csv"
    src.write_text(text, encoding="utf-8", newline="")
    with pytest.warns(cf.io.ColumnsKept):
        (rec,) = read_curves(src)
    assert rec.source["columns"] == (1, 2)
    np.testing.assert_array_equal(rec.points, np.round(P, 4))
    out = tmp_path / "out.csv"
    with pytest.warns(cf.io.ColumnsKept):
        _fair_file(src, out)
    got = out.read_text(encoding="utf-8")
    assert got.startswith(pre)
    rows = [ln.split(",") for ln in got.splitlines()[3:]]
    assert [r[0] for r in rows] == [str(i + 1) for i in range(40)]
    moved = np.array([[float(r[1]), float(r[2])] for r in rows])
    assert np.linalg.norm(moved - np.round(P, 4), axis=1).max() <= TOL


def test_a_line_with_a_number_before_the_data_is_still_refused(tmp_path):
    src = tmp_path / "in.csv"
    src.write_text("x,y\n1.0,2.0O\n0,0\n1,1\n2,2\n", encoding="utf-8")
    with pytest.raises(cf.FileFormatError, match="not a header"):
        read_curves(src)


@pytest.mark.parametrize("name", ["f.csv", "f.dat"])
def test_fortran_d_exponents_are_read_and_written_back_with_d(tmp_path, name):
    """Fortran's double-precision exponent (``0.9970429D+01``) was refused ("no data rows",
    "not a row of numbers"); a row of such numbers before the data is not a units row."""
    P = _arc()
    sep = "," if name.endswith(".csv") else "  "
    rows = [f"{x:.6E}{sep}{y:.6E}".replace("E", "D") for x, y in P]
    text = ("x,y\n" if sep == "," else "NAME\n") + "\n".join(rows) + "\n"
    src = tmp_path / name
    src.write_text(text, encoding="utf-8", newline="")
    (rec,) = read_curves(src)
    want = np.array([[float(v.replace("D", "E")) for v in r.split(sep)] for r in rows])
    np.testing.assert_array_equal(rec.points, want)
    out = tmp_path / ("o" + name)
    _fair_file(src, out)
    b = out.read_text(encoding="utf-8").splitlines()
    assert b[0] == text.splitlines()[0] and len(b) == len(rows) + 1
    assert not any("E" in ln or "e" in ln for ln in b[1:])
    got = np.array([[float(v.replace("D", "E")) for v in
                     (ln.split(sep) if sep == "," else ln.split())] for ln in b[1:]])
    moves = np.linalg.norm(got - want, axis=1)
    assert moves.max() <= TOL and np.count_nonzero(moves) > 20
    assert all(x == y for x, y, m in zip(rows, b[1:], moves, strict=True) if m == 0)


def test_e_exponents_in_a_file_of_d_exponents_are_refused(tmp_path):
    src = tmp_path / "f.csv"
    src.write_text("1.0D+00,2.0D+00\n3.0E+00,4.0\n4,5\n5,7\n", encoding="utf-8")
    with pytest.raises(cf.FileFormatError, match="E exponents in a file of Fortran D") as exc:
        read_curves(src)
    assert exc.value.line == 2


@pytest.mark.parametrize("quote_all", [False, True])
def test_quoted_numbers_are_read_and_keep_their_quotes(tmp_path, quote_all):
    """R's ``write.csv`` quotes the header and its row names (``"1",0.5,0.25``); some tools
    quote every field. Both were refused ("not a row of numbers")."""
    P = _arc()
    if quote_all:
        text = '"x","y"\n' + "".join(f'"{x:.6f}","{y:.6f}"\n' for x, y in P)
    else:
        text = '"","x","y"\n' + "".join(f'"{i + 1}",{x:.6f},{y:.6f}\n'
                                          for i, (x, y) in enumerate(P))
    src = tmp_path / "in.csv"
    src.write_text(text, encoding="utf-8", newline="")
    if quote_all:
        (rec,) = read_curves(src)
    else:
        with pytest.warns(cf.io.ColumnsKept):
            (rec,) = read_curves(src)
    np.testing.assert_array_equal(rec.points, np.round(P, 6))
    out = tmp_path / "out.csv"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", cf.io.ColumnsKept)
        _fair_file(src, out)
    a = [ln.split(",") for ln in text.splitlines()]
    b = [ln.split(",") for ln in out.read_text(encoding="utf-8").splitlines()]
    assert a[0] == b[0] and len(a) == len(b)
    if not quote_all:
        assert [r[0] for r in a] == [r[0] for r in b]  # the row names as they were
    assert all(all(f.startswith('"') and f.endswith('"') for f in r) for r in b) == quote_all
    k = 1 if not quote_all else 0
    pa = np.array([[float(f.strip('"')) for f in r[k:]] for r in a[1:]])
    pb = np.array([[float(f.strip('"')) for f in r[k:]] for r in b[1:]])
    moves = np.linalg.norm(pb - pa, axis=1)
    assert moves.max() <= TOL and np.count_nonzero(moves) > 20
