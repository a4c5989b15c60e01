"""Point-list text files (CSV / whitespace) and airfoil .dat files: read, write back, errors.

References: the interpolating curve is checked against scipy's CubicSpline built here (natural
/ periodic, chord-length parameters computed by hand); corners against hand geometry (a
square turns 90 degrees at its corners); the real airfoil files in tests/data (UIUC database
copies shipped by aerosandbox, see tests/data/README.md) must come back byte for byte.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.interpolate import CubicSpline

from curvefair import CubicHermite, FileFormatError, InputError, read_curves, write_curves
from curvefair.io import CurveRecord, atomic_write

DATA = Path(__file__).parent / "data"


def _chord(p):
    return np.r_[0.0, np.cumsum(np.hypot(*np.diff(p, axis=0).T[:2]) if p.shape[1] == 2 else
                                np.linalg.norm(np.diff(p, axis=0), axis=1))]


def _write(path, text):
    Path(path).write_text(text, encoding="utf-8", newline="")
    return path


# ------------------------------------------------------------------------------------------
# CSV / whitespace
# ------------------------------------------------------------------------------------------
CSV = """# measured section, mm
x,y,z
0.000,0.000,1.5
1.000,0.250,1.5   # a note
2.000,0.750,1.5

3.000,0.600,1.5
4.000,0.700,1.5
5.000,1.250,1.5
"""


def test_csv_read_curve_is_natural_chord_spline(tmp_path):
    p = _write(tmp_path / "s.csv", CSV)
    (rec,) = read_curves(p)
    assert isinstance(rec, CurveRecord) and rec.kind == "points" and rec.format == "points"
    pts = np.array([[0, 0, 1.5], [1, .25, 1.5], [2, .75, 1.5], [3, .6, 1.5], [4, .7, 1.5],
                    [5, 1.25, 1.5]])
    np.testing.assert_array_equal(rec.points, pts)
    assert isinstance(rec.curve, CubicHermite) and not rec.curve.closed
    t = _chord(pts)
    np.testing.assert_allclose(rec.curve.params, t, rtol=0, atol=1e-14)
    ref = CubicSpline(t, pts, bc_type="natural", axis=0)
    u = np.linspace(0, t[-1], 301)
    np.testing.assert_allclose(rec.curve(u), ref(u), rtol=0, atol=1e-12)
    assert rec.corners == ()
    assert rec.source["header"] == "x,y,z"


def test_csv_round_trip_is_byte_identical_and_keeps_layout(tmp_path):
    p = _write(tmp_path / "s.csv", CSV)
    recs = read_curves(p)
    out = tmp_path / "out.csv"
    write_curves(out, recs)
    assert out.read_bytes() == p.read_bytes()


def test_csv_faired_points_go_back_into_the_same_lines(tmp_path):
    p = _write(tmp_path / "s.csv", CSV)
    (rec,) = read_curves(p)
    new = np.array(rec.curve.points)
    new[2, 1] = 0.7123
    new[3, 1] = 0.65
    write_curves(tmp_path / "o.csv", rec.with_curve(rec.curve.replace(points=new)))
    lines = (tmp_path / "o.csv").read_text().splitlines()
    orig = CSV.splitlines()
    assert len(lines) == len(orig)
    assert lines[0] == orig[0] and lines[1] == orig[1] and lines[5] == ""
    assert lines[3] == orig[3]                       # untouched row, comment kept
    # never rounded to the column's 3 decimals (that could break a fairing tolerance):
    # a value the column's precision holds exactly uses it, any other is written exactly
    assert lines[4] == "2.000,0.7123,1.5"
    assert lines[6] == "3.000,0.650,1.5"
    back = read_curves(tmp_path / "o.csv")[0].points
    np.testing.assert_array_equal(back, new)


def test_decimals_override_and_integer_columns(tmp_path):
    p = _write(tmp_path / "i.txt", "0 0\n1 1\n2 0\n3 1\n")
    (rec,) = read_curves(p, corner_angle=None)
    new = np.array(rec.curve.points)
    new[1, 1] = 0.987654321
    write_curves(tmp_path / "o.txt", rec.with_curve(rec.curve.replace(points=new)))
    # integer column: the shortest exact representation, untouched values stay "0"
    assert (tmp_path / "o.txt").read_text().splitlines()[1] == "1 0.987654321"
    write_curves(tmp_path / "o2.txt", rec.with_curve(rec.curve.replace(points=new)), decimals=2)
    assert (tmp_path / "o2.txt").read_text().splitlines()[1] == "1.00 0.99"


def test_whitespace_columns_stay_aligned(tmp_path):
    text = "  1.00000     0.00000\n  0.50000     0.10000\n  0.00000     0.00000\n"
    p = _write(tmp_path / "a.xyz", text)
    (rec,) = read_curves(p)
    new = np.array(rec.curve.points)
    new[1, 1] = -0.1
    write_curves(tmp_path / "o.xyz", rec.with_curve(rec.curve.replace(points=new)))
    lines = (tmp_path / "o.xyz").read_text().splitlines()
    assert lines[1] == "  0.50000    -0.10000"
    assert len({len(s) for s in lines}) == 1


def _square(n_side):
    s = np.linspace(0, 1, n_side + 1)[:-1]
    return np.vstack([np.c_[s, 0 * s], np.c_[1 + 0 * s, s], np.c_[1 - s, 1 + 0 * s],
                      np.c_[0 * s, 1 - s]])


def test_closed_square_is_split_at_its_four_corners_and_rejoined(tmp_path):
    sq = _square(5)                          # 20 distinct points, corners at 0, 5, 10, 15
    loop = np.vstack([sq, sq[:1]])
    p = tmp_path / "sq.csv"
    np.savetxt(p, loop, fmt="%.4f", delimiter=",")
    recs = read_curves(p)
    assert len(recs) == 4
    starts = sorted(r.source["indices"][0] for r in recs)
    assert starts == [0, 5, 10, 15]
    for r in recs:
        assert r.corners == (0, len(r.points) - 1)
        # each side is straight: the natural spline through collinear points is that line
        u = np.linspace(*r.curve.domain, 50)
        xy = r.curve(u)
        d = r.points[-1] - r.points[0]
        cross = (xy[:, 0] - r.points[0, 0]) * d[1] - (xy[:, 1] - r.points[0, 1]) * d[0]
        assert np.abs(cross).max() < 1e-12
    out = tmp_path / "o.csv"
    write_curves(out, recs)
    assert out.read_bytes() == p.read_bytes()


def test_open_polyline_corner_split_and_threshold(tmp_path):
    # an L: 90 degree turn at index 4; a gentle 20 degree bend at index 7
    pts = np.array([[0, 0], [1, 0], [2, 0], [3, 0], [4, 0], [4, 1], [4, 2], [4, 3],
                    [4 - np.sin(np.radians(20)), 3 + np.cos(np.radians(20))]])
    p = tmp_path / "l.txt"
    np.savetxt(p, pts, fmt="%.6f")
    recs = read_curves(p)
    assert [r.source["indices"].tolist() for r in recs] == [list(range(0, 5)), list(range(4, 9))]
    assert recs[0].corners == (4,) and recs[1].corners == (0,)
    assert len(read_curves(p, corner_angle=None)) == 1
    assert len(read_curves(p, corner_angle=15.0)) == 3
    with pytest.raises(InputError, match="corner_angle"):
        read_curves(p, corner_angle=0)


def test_closed_smooth_loop_is_periodic(tmp_path):
    a = np.linspace(0, 2 * np.pi, 17)
    loop = np.c_[np.cos(a), np.sin(a)]
    loop[-1] = loop[0]
    p = tmp_path / "c.csv"
    np.savetxt(p, loop, fmt="%.10f", delimiter=",")
    (rec,) = read_curves(p)
    assert rec.curve.closed and rec.corners == ()
    assert rec.curve.points.shape == (17, 2)
    t = _chord(np.loadtxt(p, delimiter=","))
    ref = CubicSpline(t, np.loadtxt(p, delimiter=","), bc_type="periodic", axis=0)
    u = np.linspace(0, t[-1], 100)
    np.testing.assert_allclose(rec.curve(u), ref(u), atol=1e-12)
    write_curves(tmp_path / "o.csv", [rec])
    assert (tmp_path / "o.csv").read_bytes() == p.read_bytes()


def test_fresh_points_file_from_a_bare_curve(tmp_path):
    from curvefair import interpolate_cubic
    pts = np.c_[np.linspace(0, 1, 7), np.linspace(0, 1, 7) ** 2 / 3.0]
    c = interpolate_cubic(pts)
    write_curves(tmp_path / "n.csv", c)
    text = (tmp_path / "n.csv").read_text()
    assert text.splitlines()[0] == "x,y"
    np.testing.assert_array_equal(read_curves(tmp_path / "n.csv")[0].points, pts)


def test_template_gives_layout_to_bare_curves(tmp_path):
    p = _write(tmp_path / "s.csv", CSV)
    (rec,) = read_curves(p)
    bare = rec.curve.replace(points=np.array(rec.curve.points) + [0, 0.001, 0])
    write_curves(tmp_path / "o.csv", [bare], template=p)
    lines = (tmp_path / "o.csv").read_text().splitlines()
    assert lines[:2] == CSV.splitlines()[:2] and lines[2] == "0.000,0.001,1.5"
    with pytest.raises(InputError, match="1 point list"):
        write_curves(tmp_path / "o2.csv", [bare, bare], template=p)


def test_wrong_number_of_points_is_refused(tmp_path):
    p = _write(tmp_path / "s.csv", CSV)
    (rec,) = read_curves(p)
    from curvefair import interpolate_cubic
    with pytest.raises(InputError, match="6 data points"):
        write_curves(tmp_path / "o.csv", rec.with_curve(interpolate_cubic(rec.points[:5])))


@settings(max_examples=30, deadline=None)
@given(st.integers(3, 30), st.integers(0, 2**31 - 1), st.sampled_from([",", " ", "\t", "; "]),
       st.integers(2, 3), st.integers(0, 9))
def test_property_round_trip(tmp_path_factory, n, seed, sep, dim, dec):
    rng = np.random.default_rng(seed)
    pts = np.cumsum(rng.uniform(1.5, 3.0, (n, dim)) * rng.choice([-1, 1], (n, dim)), axis=0)
    pts = np.round(pts, dec)
    d = tmp_path_factory.mktemp("prop")
    p = d / "p.txt"
    p.write_text("".join(sep.join(f"{v:.{dec}f}" for v in row) + "\n" for row in pts))
    recs = read_curves(p, corner_angle=None)
    write_curves(d / "o.txt", recs)
    assert (d / "o.txt").read_bytes() == p.read_bytes()
    np.testing.assert_array_equal(read_curves(d / "o.txt", corner_angle=None)[0].points, pts)


# ------------------------------------------------------------------------------------------
# malformed files
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("text, line, match", [
    ("", None, "empty"),
    ("\n\n# only a comment\n", None, "no data"),
    ("x,y\n", None, "no data"),
    ("0,0\n1,1\nhello world\n2,2\n", 3, "not a row of numbers"),
    ("x,y\n1.0,2.0O\n0,0\n", 2, "not a header"),  # a mistyped first row is no preamble
    ("0,0\n1,1\n2\n", 3, "1 columns but the first data row \\(line 1\\) has 2"),
    ("0 0 0 0\n1 1 1 1\n", 1, "2 or 3 coordinate columns, got 4"),
    ("0 0 0 0 0\n1 1 1 1 1\n", 1, "2 or 3 coordinate columns, got 5"),
    ("0\n1\n", 1, "at least 2 columns, got 1"),
    ("0,0\n1,nan\n2,2\n", 2, "non-finite"),
    ("0,0\n1,inf\n2,2\n", 2, "non-finite"),
    ("0,0\n1,1\n1.0000000000000002,1\n2,2\n", 3, "duplicate consecutive"),
    ("0,0\n", None, "at least 2 points"),
    # a separator after the last column is allowed: "3," is one number
    ("0,0\n1,1\n2,2\n3,\n", 4, "1 columns but the first data row \\(line 1\\) has 2"),
    ("0,0\n1,1\n2,2\n3,,\n", 4, "not a row of numbers"),
    # columns that cannot be told apart (tests/test_io_points_columns.py has the others)
    ("5 0 0 0\n9 1 1 1\n", 1, "2 or 3 coordinate columns, got 4"),
    ("x;y\n10,0000;0,0035\n9.9704;0,7767\n", 3, "decimal points in a file of decimal commas"),
    ("1.234,5;2,25\n3,5;4,25\n5,5;6\n", 1, "decimal points in a file of decimal commas"),
    ("1.234,5;2\n1.235,5;4\n1.236,5;6\n", 1, "decimal points in a file of decimal commas"),
    ("1,5;2,5\n2.5;3.5\n3,5;4\n", 2, "decimal points in a file of decimal commas"),
    # Engauge Digitizer's "all curves on each line" export: two curves over one x
    ("x,Curve1,Curve2\n0.1,1,2\n0.2,1.5,2.5\n0.3,1.7,2.6\n", 2, "names a column x but no y"),
])
def test_malformed_points_files(tmp_path, text, line, match):
    p = _write(tmp_path / "bad.csv", text)
    with pytest.raises(FileFormatError, match=match) as exc:
        read_curves(p)
    assert exc.value.path == str(p)
    assert exc.value.line == line
    assert str(p) in str(exc.value)


def test_binary_garbage_and_missing_file(tmp_path):
    p = tmp_path / "bin.csv"
    p.write_bytes(b"0,0\n1,1\n\x00\x01\x02garbage")
    with pytest.raises(FileFormatError, match="binary") as exc:
        read_curves(p)
    assert exc.value.line == 3
    with pytest.raises(FileFormatError, match="no such file"):
        read_curves(tmp_path / "missing.csv")
    with pytest.raises(InputError, match="extension"):
        read_curves(tmp_path / "x.unknown")


# ------------------------------------------------------------------------------------------
# atomic writes, never the input
# ------------------------------------------------------------------------------------------
def test_never_overwrites_the_input_unless_asked(tmp_path):
    p = _write(tmp_path / "s.csv", CSV)
    recs = read_curves(p)
    before = p.read_bytes()
    with pytest.raises(InputError, match="overwrite=True"):
        write_curves(p, recs)
    with pytest.raises(InputError, match="overwrite=True"):
        write_curves(tmp_path / "." / "s.csv", recs)
    assert p.read_bytes() == before
    write_curves(p, recs, overwrite=True)
    assert p.read_bytes() == before


def test_atomic_write_keeps_mode_and_leaves_no_temp_on_error(tmp_path):
    p = tmp_path / "f.txt"
    p.write_text("old")
    os.chmod(p, 0o640)
    atomic_write(p, "new")
    assert p.read_text() == "new" and stat.S_IMODE(p.stat().st_mode) == 0o640

    def boom(f):
        f.write("partial")
        raise RuntimeError("disk full")

    with pytest.raises(RuntimeError):
        atomic_write(p, boom)
    assert p.read_text() == "new"
    assert sorted(os.listdir(tmp_path)) == ["f.txt"]
    with pytest.raises(InputError, match="does not exist"):
        atomic_write(tmp_path / "nope" / "f.txt", "x")


# ------------------------------------------------------------------------------------------
# airfoils
# ------------------------------------------------------------------------------------------
REAL_FOILS = ["clarky.dat", "e423.dat", "naca2412.dat"]


@pytest.mark.parametrize("name", REAL_FOILS)
def test_real_airfoils_round_trip_byte_identical(tmp_path, name):
    recs = read_curves(DATA / name)
    assert len(recs) == 1
    (rec,) = recs
    assert rec.kind == "airfoil" and rec.source["airfoil_layout"] == "selig"
    n = rec.points.shape[0]
    assert rec.corners == (0, n - 1)                   # the trailing edge
    assert rec.points[0, 0] == pytest.approx(1.0) and rec.points[-1, 0] == pytest.approx(1.0)
    le = np.argmin(rec.points[:, 0])
    assert rec.points[le, 0] == pytest.approx(0.0, abs=1e-4)
    write_curves(tmp_path / name, recs)
    assert (tmp_path / name).read_bytes() == (DATA / name).read_bytes()


def test_real_airfoil_names():
    assert read_curves(DATA / "clarky.dat")[0].name == "CLARK Y AIRFOIL"
    assert read_curves(DATA / "e423.dat")[0].name == "E423"


def _to_lednicer(selig: np.ndarray, name: str) -> str:
    le = int(np.argmin(selig[:, 0]))
    upper = selig[: le + 1][::-1]
    lower = selig[le:]
    rows = lambda a: "".join(f"  {x:.7f}  {y: .7f}\n" for x, y in a)  # noqa: E731
    return (f"{name}\n      {len(upper)}.       {len(lower)}.\n\n" + rows(upper) + "\n"
            + rows(lower))


def test_lednicer_layout_matches_selig_contour(tmp_path):
    selig = read_curves(DATA / "naca2412.dat")[0]
    text = _to_lednicer(np.asarray(selig.points), "NACA 2412 LEDNICER")
    p = _write(tmp_path / "led.dat", text)
    (rec,) = read_curves(p)
    assert rec.source["airfoil_layout"] == "lednicer"
    assert rec.name == "NACA 2412 LEDNICER"
    np.testing.assert_allclose(rec.points, selig.points, atol=5e-8)   # 7 decimals in the file
    assert rec.corners == (0, rec.points.shape[0] - 1)
    write_curves(tmp_path / "o.dat", [rec])
    assert (tmp_path / "o.dat").read_bytes() == p.read_bytes()
    # a faired leading edge goes to both surfaces; counts and blank lines stay
    le = int(np.argmin(rec.points[:, 0]))
    new = np.array(rec.curve.points)
    new[le] = [0.0, 0.0001]
    write_curves(tmp_path / "f.dat", rec.with_curve(rec.curve.replace(points=new)))
    lines = (tmp_path / "f.dat").read_text().splitlines()
    orig = text.splitlines()
    assert lines[:3] == orig[:3] and lines[3] == "  0.0000000   0.0001000"
    nu = int(float(orig[1].split()[0]))
    assert lines[3 + nu] == "" and lines[4 + nu] == "  0.0000000   0.0001000"
    np.testing.assert_allclose(read_curves(tmp_path / "f.dat")[0].points, new, atol=5e-8)


def test_lednicer_truncated(tmp_path):
    text = "FOIL\n 4. 4.\n\n0 0\n0.3 0.05\n0.7 0.04\n1 0\n\n0 0\n0.3 -0.03\n0.7 -0.02\n"
    p = _write(tmp_path / "t.dat", text)
    with pytest.raises(FileFormatError, match="truncated") as exc:
        read_curves(p)
    assert exc.value.line == 11


def test_airfoil_garbage_after_data(tmp_path):
    # text after the coordinates is a note (kept); coordinates after it are refused
    p = _write(tmp_path / "g.dat", "FOIL\n1 0\n0.5 0.1\n0 0\n0.5 -0.1\n1 0\nmodified 2013\n")
    assert read_curves(p)[0].source["notes"] == ("modified 2013",)
    p = _write(tmp_path / "g.dat", "FOIL\n1 0\n0.5 0.1\nmodified 2013\n0 0\n0.5 -0.1\n1 0\n")
    with pytest.raises(FileFormatError, match="after the text at line 4") as exc:
        read_curves(p)
    assert exc.value.line == 5


def test_points_exact_duplicate_row_dropped(tmp_path):
    p = _write(tmp_path / "d.csv", "0,0\n1,1\n1,1\n2,0\n3,1\n")
    with pytest.warns(UserWarning, match="dropped 1 exactly repeated consecutive point.*line 3"):
        (rec,) = read_curves(p, corner_angle=None)
    np.testing.assert_array_equal(rec.points, [[0, 0], [1, 1], [2, 0], [3, 1]])
    write_curves(tmp_path / "o.csv", rec.with_curve(rec.curve.replace(points=rec.points + 1)))
    assert (tmp_path / "o.csv").read_text() == "1,1\n2,2\n2,2\n3,1\n4,2\n"


def test_airfoil_to_csv_and_back(tmp_path):
    (rec,) = read_curves(DATA / "e423.dat")
    write_curves(tmp_path / "e.csv", [rec])
    np.testing.assert_array_equal(read_curves(tmp_path / "e.csv", corner_angle=None)[0].points,
                                  rec.points)
    write_curves(tmp_path / "e.dat", read_curves(tmp_path / "e.csv", corner_angle=None))
    back = read_curves(tmp_path / "e.dat")[0]
    np.testing.assert_array_equal(back.points, rec.points)
