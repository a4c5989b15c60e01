"""Chunked text output keeps the input's layout (issue 17): the lines before, between and after
the rows, every line's ending, unmoved rows byte for byte, moved rows in their line's layout
with the input's decimals, and the tolerance held in the file as written (rounding included:
more decimals where the input's would break it).

Checked independently of the chunk code: the files are read with ``numpy.loadtxt`` and the
``csv`` module (and with :func:`curvefair.read_curves`, the reader the input was made for);
distances are measured here in float64 (per row: ``numpy.linalg.norm``; the curves: scipy
``CubicSpline`` through the rows, chord-length parameters and natural ends, sampled densely
and compared with a k-d tree); decimals and layouts are taken from the input's text with a
regular expression of this file, not with the package's number parser.
"""

from __future__ import annotations

import csv
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from scipy.interpolate import CubicSpline
from scipy.spatial import cKDTree

import curvefair._chunked as ck
from curvefair import read_curves
from curvefair.batch import fair_chunked

DATA = Path(__file__).parent / "data"
NUM = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")


def _decimals(tok: str) -> int:
    mant = re.split(r"[eE]", tok)[0]
    return len(mant) - mant.index(".") - 1 if "." in mant else 0


def _skeleton(line: str) -> str:
    """The line with every number replaced by ``N``: separators, padding, comments."""
    return NUM.sub("N", line)


def _sampled_hausdorff(P: np.ndarray, Q: np.ndarray, per: int = 40) -> float:
    """Symmetric Hausdorff distance between the natural chord-length cubics through ``P`` and
    ``Q``, sampled ``per`` times per span (a lower estimate; the package certifies the exact
    one)."""
    def samples(X: np.ndarray) -> np.ndarray:
        t = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(X, axis=0), axis=1))]
        f = np.linspace(0.0, 1.0, per, endpoint=False)
        u = np.append((t[:-1, None] + f * np.diff(t)[:, None]).ravel(), t[-1])
        return CubicSpline(t, X, bc_type="natural")(u)

    a, b = samples(P), samples(Q)
    return max(float(cKDTree(b).query(a)[0].max()), float(cKDTree(a).query(b)[0].max()))


def _is_row(line: bytes) -> bool:
    """A data line of a point file: only numbers and separators before any ``#``."""
    body = line.split(b"#", 1)[0].strip()
    return bool(body) and re.fullmatch(rb"[0-9eE+\-.,;\s]+", body) is not None


def _check_layout(src: Path, dst: Path, P: np.ndarray, Q: np.ndarray, tol: float,
                  needed_more: set[int] | None = None) -> dict[str, int]:
    """Line-by-line comparison of ``dst`` with ``src``: the same lines apart from moved rows,
    which keep their skeleton and have, number by number, the column's decimals (more only
    for the rows in ``needed_more``, None: for none). Returns counts."""
    a, b = src.read_bytes(), dst.read_bytes()
    la, lb = a.splitlines(keepends=True), b.splitlines(keepends=True)
    assert len(la) == len(lb)
    ra = [ln for ln in la if _is_row(ln)]
    cols = [max(_decimals(NUM.findall(r.decode())[j]) for r in ra) for j in range(P.shape[1])]
    row = -1
    counts = {"moved": 0, "same": 0, "more": 0}
    for x, y in zip(la, lb, strict=True):
        if not _is_row(x):
            assert y == x  # header, comments, blank lines: as they were, byte for byte
            continue
        row += 1
        # every line keeps its own ending (CRLF, LF or none at the end of the file)
        assert x[len(x.rstrip(b"\r\n")):] == y[len(y.rstrip(b"\r\n")):]
        if np.array_equal(P[row], Q[row]):
            assert y == x  # an unmoved row is its line as read
            counts["same"] += 1
            continue
        counts["moved"] += 1
        sx, sy = x.decode().rstrip("\r\n"), y.decode().rstrip("\r\n")
        assert _skeleton(sx) == _skeleton(sy)
        tx, ty = NUM.findall(sx.split("#")[0]), NUM.findall(sy.split("#")[0])
        more = False
        for j, (u, v) in enumerate(zip(tx, ty, strict=True)):
            if float(u) == float(v):
                assert u == v
                continue
            assert _decimals(v) >= cols[j]
            assert (u.startswith("-.") or u.startswith(".")) == \
                (v.startswith("-.") or v.startswith(".")) or float(v) == 0.0  # bare point kept
            more |= _decimals(v) > cols[j]
        if more:
            counts["more"] += 1
            assert needed_more is not None and row in needed_more
    assert row + 1 == P.shape[0] == Q.shape[0]
    return counts


# ------------------------------------------------------------------------------------------
# (a) files written by other software (tests/data/README.md)
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize(("name", "chunk", "tol"), [
    ("clarky.dat", 40, 2e-4),     # UIUC database: 121 rows, 7 decimals, "-.0046700" style
    ("naca2412.dat", 34, 2e-4),   # Lednicer's naca.exe: leading blanks, no final newline
])
def test_a_real_airfoil_file_keeps_its_layout_and_tol(tmp_path: Path, name: str, chunk: int,
                                                      tol: float):
    src = tmp_path / name
    shutil.copyfile(DATA / name, src)
    out = tmp_path / ("out_" + name)
    rep = fair_chunked(src, out, tol=tol, chunk=chunk, overlap=16, hold=4, jobs=1)
    assert rep["n_chunks"] >= 2 and rep["layout_kept"]
    P = np.loadtxt(src, skiprows=1)
    Q = np.loadtxt(out, skiprows=1)
    assert Q.shape == P.shape
    moved = np.linalg.norm(Q - P, axis=1)
    assert moved.max() <= tol  # every row, as written, in float64
    assert np.count_nonzero(moved) > P.shape[0] // 3  # it did fair
    assert _sampled_hausdorff(P, Q) <= tol
    assert rep["max_deviation"] <= tol
    # the reader the file was written for reads the same numbers
    (rec,) = read_curves(out)
    np.testing.assert_array_equal(np.asarray(rec.points), Q)
    # the name line byte for byte; the rest line by line; rounding at 7 decimals never
    # needs more here (the rounding error, 7e-8, is far below what the fair leaves of tol)
    assert out.read_bytes().splitlines()[0] == src.read_bytes().splitlines()[0]
    counts = _check_layout(src, out, P, Q, tol, needed_more=None)
    assert counts["moved"] > 0 and counts["same"] > 0
    assert src.read_bytes().endswith(b"\n") == out.read_bytes().endswith(b"\n")


# ------------------------------------------------------------------------------------------
# (b) decimals too coarse for the tolerance
# ------------------------------------------------------------------------------------------
def _noisy(n: int, seed: int, noise: float) -> np.ndarray:
    rng = np.random.default_rng(seed)
    s = np.linspace(0.0, 8.0 * np.pi * n / 1000.0, n)
    return np.c_[s, 3.0 * np.sin(s)] + noise * rng.standard_normal((n, 2))


def test_coarse_decimals_get_more_where_rounding_would_break_tol(tmp_path: Path):
    """2 decimals and tol 0.004: rounding alone can move a point 0.007 -- past tol, or back
    onto the input's grid (undoing the fair). The rows that need it get more decimals, one at
    a time; every row is within tol as written and within the rounding budget of its faired
    point (the same fair written exactly, as .npy)."""
    tol = 0.004
    P0 = np.round(4.0 * _noisy(700, 3, 0.0025), 2)  # spacing about 0.1, noise 0.01
    src = tmp_path / "coarse.csv"
    with open(src, "w", newline="") as f:
        f.write("x,y\n")
        f.writelines(f"{x:.2f},{y:.2f}\n" for x, y in P0.tolist())
    out = tmp_path / "o.csv"
    kw = {"tol": tol, "chunk": 200, "overlap": 16, "hold": 4, "jobs": 1}
    rep = fair_chunked(src, out, **kw)
    rep_v = fair_chunked(src, tmp_path / "v.npy", **kw)
    V = np.load(tmp_path / "v.npy")  # the faired points, exactly
    assert all(c["move_scale"] == 1.0 for c in rep["chunks"] + rep_v["chunks"])
    with open(src, newline="") as f:
        P = np.array([[float(v) for v in r] for r in list(csv.reader(f))[1:]])
    with open(out, newline="") as f:
        rows = list(csv.reader(f))
    assert rows[0] == ["x", "y"]
    Q = np.array([[float(v) for v in r] for r in rows[1:]])
    np.testing.assert_array_equal(Q, np.loadtxt(out, delimiter=",", skiprows=1))
    assert Q.shape == P.shape == V.shape
    assert np.linalg.norm(Q - P, axis=1).max() <= tol
    assert _sampled_hausdorff(P, Q) <= tol and rep["max_deviation"] <= tol
    # the fair survives the rounding: every moved row is near its faired point, not put back
    moved = np.any(V != P, axis=1)
    assert np.linalg.norm(Q - V, axis=1).max() <= ck.ROUND_SHARE * tol
    assert np.count_nonzero(np.any(Q != P, axis=1)) == np.count_nonzero(moved) > 500
    # which rows needed more than 2 decimals: at 2 decimals they would be past tol from the
    # input, past the chunk's rounding budget from the faired point, or on a neighbour's point
    R = np.array([[float(f"{x:.2f}"), float(f"{y:.2f}")] for x, y in V.tolist()])
    budget = np.empty(len(P))
    for c in rep["chunks"]:
        a, b = c["rows"]
        budget[a:b] = np.inf if c["on_disk_numbers"] == "exact" else \
            ck.rounding_budget(tol, c["max_deviation"])
    far = (np.linalg.norm(R - P, axis=1) > tol) | (np.linalg.norm(R - V, axis=1) > budget)
    prev = np.r_[False, np.all(R[1:] == Q[:-1], axis=1)]
    nxt = np.r_[np.all(R[:-1] == Q[1:], axis=1), False]
    exact = np.isinf(budget)
    needed = set(np.flatnonzero(moved & (far | prev | nxt | exact)).tolist())
    counts = _check_layout(src, out, P, Q, tol, needed_more=needed)
    assert counts["more"] > 100  # the extra-decimals path was taken
    assert sum(c["rows_more_decimals"] for c in rep["chunks"]) == counts["more"]
    # one decimal at a time (up to 2 + _MAX_EXTRA, then the exact value): no moved row has
    # more decimals than it needs to meet the rules
    top = 2 + ck._MAX_EXTRA

    def breaks(i: int, k: int) -> bool:
        r = np.array([float(f"{v:.{k}f}") for v in V[i]])
        return bool(np.linalg.norm(r - P[i]) > tol or np.linalg.norm(r - V[i]) > budget[i]
                    or (i > 0 and np.array_equal(r, Q[i - 1]))
                    or (i + 1 < len(Q) and np.array_equal(r, Q[i + 1])))

    for i in np.flatnonzero(moved & ~exact):
        k = max(_decimals(t) for t in rows[i + 1])
        if 2 < k <= top:
            assert breaks(i, k - 1), i
        elif k > top:
            assert np.array_equal(Q[i], V[i]) and breaks(i, top), i


# ------------------------------------------------------------------------------------------
# (c) unmoved rows, odd layouts, comments between rows; (d) CRLF
# ------------------------------------------------------------------------------------------
def test_unmoved_rows_are_byte_identical_and_comments_stay_in_place(tmp_path: Path):
    P0 = np.round(_noisy(600, 5, 0.003), 4)
    lines = ["# made by hand", "", "  X      Y       "]
    for i, (x, y) in enumerate(P0.tolist()):
        if i % 97 == 0:
            lines.append(f"# station {i}")
        if i % 50 == 7:
            lines.append(f" {x:9.4f}  {y:+.4e}   # note {i}")  # padding, exponent, comment
        elif i % 50 == 8:
            lines.append("")
            lines.append(f" {x:9.4f}  {y:+.4e}")
        else:
            lines.append(f" {x:9.4f}  {y:+.4e}")
    src = tmp_path / "odd.txt"
    src.write_text("\n".join(lines) + "\n")
    protect = list(range(100, 140))
    out = tmp_path / "o.txt"
    rep = fair_chunked(src, out, tol=0.01, chunk=150, overlap=16, hold=4, jobs=1,
                       protect=protect)
    assert rep["n_comments_dropped"] == 0 and not any("comment" in n for n in rep["notes"])
    P = np.loadtxt(src, skiprows=3)
    Q = np.loadtxt(out, skiprows=3)
    assert np.linalg.norm(Q - P, axis=1).max() <= 0.01
    np.testing.assert_array_equal(Q[protect], P[protect])
    counts = _check_layout(src, out, P, Q, 0.01, needed_more=None)
    assert counts["same"] >= len(protect) + 2 and counts["moved"] > 100
    # _check_layout compared the comment and blank lines in place; here: they are all there
    def whole(ls: list[str]) -> list[str]:
        return [ln for ln in ls if ln.lstrip().startswith("#") or not ln.strip()]

    text = out.read_text().splitlines()
    assert whole(text) == whole(lines) and len(whole(lines)) > 10
    notes = [ln.split("#")[1] for ln in text if "# note" in ln]
    assert notes == [ln.split("#")[1] for ln in lines if "# note" in ln] and len(notes) == 12


def test_crlf_line_endings_are_kept(tmp_path: Path):
    P0 = np.round(_noisy(500, 7, 0.003), 5)
    body = "".join(f"{x:.5f};{y:.5f}\r\n" for x, y in P0.tolist()[:250]) + "# half way\r\n" + \
        "".join(f"{x:.5f};{y:.5f}\r\n" for x, y in P0.tolist()[250:])
    src = tmp_path / "w.csv"
    src.write_bytes(("x;y\r\n" + body + "\r\n# end\r\n").encode())
    out = tmp_path / "o.csv"
    fair_chunked(src, out, tol=0.01, chunk=120, overlap=16, hold=4, jobs=1)
    raw = out.read_bytes()
    assert raw.count(b"\r\n") == raw.count(b"\n") == src.read_bytes().count(b"\n")
    assert b"\r\n# half way\r\n" in raw
    P = np.loadtxt(src, delimiter=";", skiprows=1)
    Q = np.loadtxt(out, delimiter=";", skiprows=1)
    assert np.linalg.norm(Q - P, axis=1).max() <= 0.01
    counts = _check_layout(src, out, P, Q, 0.01, needed_more=None)
    assert counts["moved"] > 100


def test_a_rounded_chunk_read_back_over_tol_is_written_exactly(tmp_path: Path, monkeypatch):
    """The certificate covers rounding: chunk 1's measure is made to say 2 tol once; its
    rounding is undone (moved numbers written exactly, moves not scaled), the other chunks'
    lines are as before, and everything is measured again."""
    P0 = np.round(_noisy(600, 9, 0.003), 4)
    src = tmp_path / "p.csv"
    src.write_text("".join(f"{x:.4f},{y:.4f}\n" for x, y in P0.tolist()))
    plain = fair_chunked(src, tmp_path / "a.csv", tol=0.01, chunk=200, overlap=16, hold=4,
                         jobs=1)
    real = ck.measure_chunk
    calls = {"n": 0}

    def inflated(ch, orig, new, tol=None):
        m = real(ch, orig, new, tol)
        if ch.index == 1 and calls["n"] == 0:
            calls["n"] += 1
            m = dict(m, deviation=0.02)
        return m

    monkeypatch.setattr(ck, "measure_chunk", inflated)
    rep = fair_chunked(src, tmp_path / "b.csv", tol=0.01, chunk=200, overlap=16, hold=4,
                       jobs=1)
    assert calls["n"] == 1 and rep["n_chunks"] == plain["n_chunks"] == 3
    assert rep["chunks"][1]["move_scale"] == 1.0 and rep["notes"]
    la = (tmp_path / "a.csv").read_text().splitlines()
    lb = (tmp_path / "b.csv").read_text().splitlines()
    assert la[:200] == lb[:200] and la[400:] == lb[400:]
    A, B = np.loadtxt(tmp_path / "a.csv", delimiter=","), np.loadtxt(tmp_path / "b.csv",
                                                                     delimiter=",")
    moved = np.flatnonzero(np.any(B[200:400] != P0[200:400], axis=1)) + 200
    assert moved.size > 50
    # the exact numbers have more digits than 4, and rounded to 4 they are what the plain run
    # wrote (its rows of 4 decimals)
    four = [i for i in moved if all(_decimals(t) == 4 for t in la[i].split(","))]
    assert all(any(_decimals(t) > 4 for t in lb[i].split(",")) for i in moved)
    assert len(four) > 50
    np.testing.assert_array_equal(np.round(B[four], 4), A[four])
    assert np.linalg.norm(B - P0, axis=1).max() <= 0.01


def test_point_stream_lines_and_decimals(tmp_path: Path):
    p = tmp_path / "a.txt"
    raw = "\ufeffname\r\n# c\r\n1.5 2.25\r\n\r\n# mid\r\n3 4.125 # t\r\n5.0 6e-3\r\n# end\r\n"
    p.write_bytes(raw.encode())
    s = ck.PointStream(p, decimals=True)
    got = list(s.text_rows(2))
    assert [b[0].tolist() for b in got] == [[[1.5, 2.25], [3.0, 4.125]], [[5.0, 0.006]]]
    assert s.lead + "".join(x + y for b in got for x, y in zip(b[1], b[2], strict=True)) + \
        s.tail == raw
    assert s.column_decimals == [1, 3] and s.n_rows == 3


def test_a_moved_row_outside_the_layout_rules_is_written_exactly(tmp_path: Path):
    # "1.5;;2.5" is a row to the streaming reader but not one the layout renders: written
    # with the file's separator and exact numbers (its comment kept), counted in the report
    w = ck._LayoutWriter(str(tmp_path / "o.csv"), "x;y\n", [1, 1], ";", 0.5)
    orig = np.array([[1.5, 2.5], [3.5, 4.5], [5.5, 6.5]])
    new = np.array([[1.5, 2.5], [3.5 + 1e-3 / 3, 4.5], [5.5, 6.5 - 1e-3 / 7]])
    w.write(0, orig, new, ["", "", "# c\n"],
            ["1.5;2.5\n", "3.5;;4.5 # odd\n", "5.5 ; 6.5\n"], 0.05)
    w.close("# end\n")
    text = Path(w.path).read_text()  # the temporary file the driver measures, then moves
    x, y = float(f"{new[2, 1]:.1f}"), float(new[1, 0])
    assert x == 6.5  # rounded back onto the value read: its text
    assert text == f"x;y\n1.5;2.5\n{y!r};4.5 # odd\n# c\n5.5 ; 6.5\n# end\n"
    assert w.fresh == {0: 1} and w.rounded == {0: 1}
