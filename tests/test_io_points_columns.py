"""Points files with columns that are not coordinates (point numbers, arc lengths).

Before: an ``id,x,y`` file was read as a 3-D curve whose x was the point number; the faired
file came back with point numbers like ``2.0032625432389963`` and the command said "wrote",
exit 0. Now the coordinate columns are chosen (``columns=`` / ``--columns``, a header naming
``x``, ``y``, ``z``, or a first column of point numbers beside 3 others), the other columns are
written back character for character, and the ambiguous case -- 3 columns without a header,
the first holding consecutive integers -- is refused. Decimal-comma files (``1,5;2,25``), whose
every number was split in two at its comma, are read and written back with their commas.

Every written file is checked with Python's ``csv`` module and numpy, not curvefair's reader:
the kept column's texts are compared as strings, the coordinates' moves measured in float64.
"""

from __future__ import annotations

import csv
import warnings
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import curvefair as cf
from curvefair import FileFormatError, InputError, read_curves, write_curves
from curvefair.cli import main
from curvefair.io import ColumnsKept, ReadNote

TOL = 0.01


def _noisy_arc(n: int = 40, seed: int = 1) -> np.ndarray:
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 3.0, n)
    return np.c_[10 * np.cos(t), 10 * np.sin(t) + 0.01 * rng.normal(size=n)]


def _write_rows(path: Path, rows: list[str], header: str | None = None) -> Path:
    path.write_text(("" if header is None else header + "\n") + "\n".join(rows) + "\n",
                    encoding="utf-8", newline="")
    return path


def _table(path: Path) -> list[list[str]]:
    """The file's fields as text, by the csv module (commas) or by blanks."""
    text = path.read_text(encoding="utf-8")
    if "," in text:
        return [r for r in csv.reader(text.splitlines()) if r]
    return [ln.split() for ln in text.splitlines() if ln.strip()]


def _numbers(rows: list[list[str]], cols: tuple[int, ...]) -> np.ndarray:
    return np.array([[float(r[c]) for c in cols] for r in rows], dtype=np.float64)


def _fair_and_write(src: Path, out: Path, **read_kw: object) -> tuple[list, object]:
    recs = read_curves(src, **read_kw)
    faired = [r.with_curve(cf.fair(r.curve, tol=TOL).curve) for r in recs]
    check = write_curves(out, faired, tol=TOL)
    return recs, check


def _assert_kept_and_within_tol(src: Path, out: Path, kept: tuple[int, ...],
                                coords: tuple[int, ...], header: bool) -> None:
    a, b = _table(src), _table(out)
    if header:
        assert a[0] == b[0]
        a, b = a[1:], b[1:]
    assert len(a) == len(b)
    for c in kept:  # character for character
        assert [r[c] for r in a] == [r[c] for r in b]
    pa, pb = _numbers(a, coords), _numbers(b, coords)
    moves = np.linalg.norm(pb - pa, axis=1)
    assert moves.max() <= TOL
    assert np.count_nonzero(moves) > len(moves) // 2  # the coordinates were faired


# ------------------------------------------------------------------------------------------
# a header naming the coordinates
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("header, kept, coords", [
    ("id,x,y", (0,), (1, 2)),
    ("Point,X,Y", (0,), (1, 2)),
    ("s,x [mm],y [mm]", (0,), (1, 2)),         # an arc-length column, units in the names
    ("x,y,id", (2,), (0, 1)),
    (",x,y", (0,), (1, 2)),                     # pandas' to_csv: the index, unnamed, first
])
def test_header_names_the_coordinates_and_the_other_column_is_kept(tmp_path, header, kept,
                                                                     coords):
    P = _noisy_arc()
    rows = []
    for i, p in enumerate(P):
        other = f"{i + 1}" if header != "s,x [mm],y [mm]" else f"{0.075 * i:.3f}"
        vals = [f"{p[0]:.4f}", f"{p[1]:.4f}"]
        fields = [other] + vals if kept == (0,) else vals + [other]
        rows.append(",".join(fields))
    src = _write_rows(tmp_path / "in.csv", rows, header)
    with pytest.warns(ColumnsKept) as rec:
        recs = read_curves(src)
    assert isinstance(rec[0].message, ReadNote) and rec[0].message.kept == kept
    assert recs[0].source["columns"] == coords
    np.testing.assert_array_equal(recs[0].points, _numbers(_table(src)[1:], coords))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ColumnsKept)
        _fair_and_write(src, tmp_path / "out.csv")
    _assert_kept_and_within_tol(src, tmp_path / "out.csv", kept, coords, header=True)


def test_a_header_of_only_coordinates_changes_nothing(tmp_path):
    P = _noisy_arc()
    src = _write_rows(tmp_path / "in.csv", [f"{x:.4f},{y:.4f},0.5" for x, y in P], "x,y,z")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no note: every column is a coordinate
        (rec,) = read_curves(src)
    assert rec.source["columns"] == (0, 1, 2) and rec.points.shape == (40, 3)


# ------------------------------------------------------------------------------------------
# no header
# ------------------------------------------------------------------------------------------
def test_three_columns_whose_first_counts_up_are_refused_as_ambiguous(tmp_path):
    P = _noisy_arc()
    src = _write_rows(tmp_path / "in.csv",
                      [f"{i + 1},{x:.4f},{y:.4f}" for i, (x, y) in enumerate(P)])
    with pytest.raises(FileFormatError, match="consecutive integers 1 .. 40") as exc:
        read_curves(src)
    assert exc.value.line == 1 and "--columns 1,2" in str(exc.value)
    # said explicitly: the point numbers kept ...
    with pytest.warns(ColumnsKept):
        _fair_and_write(src, tmp_path / "out.csv", columns=(1, 2))
    _assert_kept_and_within_tol(src, tmp_path / "out.csv", (0,), (1, 2), header=False)
    # ... or all three coordinates of a 3-D curve
    (rec,) = read_curves(src, columns=(0, 1, 2))
    assert rec.points.shape == (40, 3)


def test_three_columns_whose_first_is_not_point_numbers_are_a_3d_curve(tmp_path):
    P = _noisy_arc()
    src = _write_rows(tmp_path / "in.csv",
                      [f"{2 * i + 1},{x:.4f},{y:.4f}" for i, (x, y) in enumerate(P)])
    (rec,) = read_curves(src)
    assert rec.points.shape == (40, 3) and rec.source["columns"] == (0, 1, 2)


def test_point_numbers_beside_three_coordinates_are_kept(tmp_path):
    P = _noisy_arc()
    src = _write_rows(tmp_path / "in.txt",
                      [f"{i}  {x:.4f}  {y:.4f}  {0.25 * x:.4f}" for i, (x, y) in enumerate(P)])
    with pytest.warns(ColumnsKept, match="column 0 kept as it is; columns 1, 2, 3 read as x, "
                                         "y, z"):
        _fair_and_write(src, tmp_path / "out.txt")
    _assert_kept_and_within_tol(src, tmp_path / "out.txt", (0,), (1, 2, 3), header=False)


# ------------------------------------------------------------------------------------------
# the argument
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("columns, error, match", [
    ((1,), InputError, "2 or 3 different"),
    ((1, 1), InputError, "2 or 3 different"),
    ((0, 1, 2, 3), InputError, "2 or 3 different"),
    (("a", "b"), InputError, "column indices"),
    ((1, 7), FileFormatError, "no column 7"),
])
def test_bad_columns_are_refused(tmp_path, columns, error, match):
    src = _write_rows(tmp_path / "in.csv", ["1,0,0", "2,1,0.5", "3,2,0.7", "4,3,0.6"])
    with pytest.raises(error, match=match):
        read_curves(src, columns=columns)


def test_columns_is_for_points_files_only(tmp_path):
    p = tmp_path / "f.dat"
    p.write_text("NAME\n1 0\n0.5 0.05\n0 0\n0.5 -0.05\n1 0\n", encoding="utf-8")
    with pytest.raises(InputError, match="columns= is for point lists"):
        read_curves(p, columns=(0, 1))


# ------------------------------------------------------------------------------------------
# the command line
# ------------------------------------------------------------------------------------------
def test_cli_refuses_the_ambiguous_file_and_fairs_it_with_columns(tmp_path):
    P = _noisy_arc()
    src = _write_rows(tmp_path / "in.csv",
                      [f"{i + 1},{x:.4f},{y:.4f}" for i, (x, y) in enumerate(P)])
    out = tmp_path / "out.csv"
    runner = CliRunner()
    res = runner.invoke(main, ["fair", str(src), "-o", str(out), "--tol", str(TOL)])
    assert res.exit_code == 1 and "consecutive integers" in res.output and not out.exists()
    assert "Traceback" not in res.output
    res = runner.invoke(main, ["fair", str(src), "-o", str(out), "--tol", str(TOL),
                               "--columns", "1,2"])
    assert res.exit_code == 0, res.output
    assert "Note: " in res.output and "column 0 kept as it is" in res.output
    _assert_kept_and_within_tol(src, out, (0,), (1, 2), header=False)
    # the other commands read the same way
    res = runner.invoke(main, ["analyze", str(src), "--columns", "1,2", "--json", "-q"])
    assert res.exit_code == 0 and '"kind": "points"' in res.stdout


@pytest.mark.parametrize("value", ["1", "1,1", "a,b", "-1,2", "0,1,2,3"])
def test_cli_bad_columns_values_are_usage_errors(tmp_path, value):
    src = _write_rows(tmp_path / "in.csv", ["0,0", "1,0.5", "2,0.7", "3,0.6"])
    res = CliRunner().invoke(main, ["fair", str(src), "-o", str(tmp_path / "o.csv"),
                                    "--tol", "0.1", "--columns", value])
    assert res.exit_code == 2 and "--columns" in res.output


def test_cli_columns_on_a_drawing_is_a_usage_error(tmp_path):
    src = tmp_path / "a.svg"
    src.write_text('<svg xmlns="http://www.w3.org/2000/svg"><path d="M0 0 C 1 2 3 2 4 0"/>'
                   "</svg>", encoding="utf-8")
    res = CliRunner().invoke(main, ["fair", str(src), "-o", str(tmp_path / "o.svg"),
                                    "--tol", "0.1", "--columns", "1,2"])
    assert res.exit_code == 2 and "--columns is for point lists" in res.output


def test_folder_run_passes_columns_to_point_files(tmp_path):
    P = _noisy_arc()
    folder = tmp_path / "in"
    folder.mkdir()
    src = _write_rows(folder / "a.csv", [f"{i + 1},{x:.4f},{y:.4f}" for i, (x, y) in enumerate(P)])
    res = CliRunner().invoke(main, ["fair", str(folder), "-o", str(tmp_path / "out"),
                                    "--tol", str(TOL), "--columns", "1,2", "--jobs", "1"])
    assert res.exit_code == 0, res.output
    _assert_kept_and_within_tol(src, tmp_path / "out" / "a.csv", (0,), (1, 2), header=False)


# ------------------------------------------------------------------------------------------
# decimal commas
# ------------------------------------------------------------------------------------------
def _comma_table(path: Path) -> list[list[str]]:
    """Rows of a decimal-comma file, split at semicolons or blanks (not curvefair's reader)."""
    import re

    lines = path.read_text(encoding="utf-8").splitlines()
    return [re.split(r"\s*;\s*|\s+", ln.strip()) for ln in lines if ln.strip()]


@pytest.mark.parametrize("sep", [";", "\t", "  "])
def test_decimal_commas_are_read_and_written_back_as_commas(tmp_path, sep):
    P = _noisy_arc()
    rows = [f"{x:.4f}{sep}{y:.4f}".replace(".", ",") for x, y in P]
    src = _write_rows(tmp_path / "in.csv", rows, "x;y" if sep == ";" else None)
    (rec,) = read_curves(src)
    body = _comma_table(src)[1 if sep == ";" else 0:]
    want = np.array([[float(t.replace(",", ".")) for t in r] for r in body])
    np.testing.assert_array_equal(rec.points, want)
    out = tmp_path / "out.csv"
    write_curves(out, [rec.with_curve(cf.fair(rec.curve, tol=TOL).curve)], tol=TOL)
    a = src.read_text(encoding="utf-8").splitlines()
    b = out.read_text(encoding="utf-8").splitlines()
    assert len(a) == len(b)
    if sep == ";":
        assert a[0] == b[0]
        a, b = a[1:], b[1:]
    assert not any("." in ln for ln in b)  # every number with its comma
    got = np.array([[float(t.replace(",", ".")) for t in r] for r in
                    _comma_table(out)[1 if sep == ";" else 0:]])
    moves = np.linalg.norm(got - want, axis=1)
    assert moves.max() <= TOL and np.count_nonzero(moves) > 20
    same = moves == 0  # an unmoved row is its line as read
    assert all(x == y for x, y, k in zip(a, b, same, strict=True) if k)
    assert all(len(r) == 2 for r in _comma_table(out)[1 if sep == ";" else 0:])


def test_an_integer_column_beside_decimal_commas_is_not_a_third_coordinate(tmp_path):
    """``9,787;2`` was read at its comma as the 3-D point (9, 787, 2) and written back as
    ``8.999991256080556,787.009373253457;1.9999560823056892``, exit 0."""
    t = np.linspace(0.0, 3.0, 30)
    rows = [f"{10 * np.cos(a):.3f};{round(10 * np.sin(a))}".replace(".", ",") for a in t]
    src = _write_rows(tmp_path / "in.csv", rows)
    (rec,) = read_curves(src)
    assert rec.points.shape == (30, 2)
    np.testing.assert_array_equal(rec.points[:, 1], [round(10 * np.sin(a)) for a in t])
    out = tmp_path / "out.csv"
    write_curves(out, [rec.with_curve(cf.fair(rec.curve, tol=TOL).curve)], tol=TOL)
    got = np.array([[float(v.replace(",", ".")) for v in r] for r in _comma_table(out)])
    assert got.shape == (30, 2)
    assert np.linalg.norm(got - rec.points, axis=1).max() <= TOL
