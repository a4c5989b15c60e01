"""Selig airfoil files with a count line (a hunt of public airfoil files found both layouts).

``129 0`` before 129 rows (HQGA_Airfoil's ``rae2822.dat``) was read as the point (129, 0): the
contour then started 128 chords away, that point was the held end, and the real trailing edge
(1, 0) moved by 1e-4 chord, opening a sharp trailing edge, exit 0. ``66 66`` after two surfaces
of 66 rows was a fourth piece from the leading edge to (66, 66). A count line -- two integers
summing to the other rows, far outside the contour -- is now kept as it is and is not a point.
Checked with ``str.split``, not curvefair's reader.
"""

from __future__ import annotations

import numpy as np
import pytest
from click.testing import CliRunner

from curvefair import read_curves
from curvefair.cli import main
from curvefair.errors import FileFormatError

TOL = 1e-4


def _foil(n: int = 129) -> np.ndarray:
    rng = np.random.default_rng(5)
    th = np.linspace(0.0, 2 * np.pi, n)
    x = 0.5 * (1 + np.cos(th))
    y = 0.06 * np.sin(th) + 2e-5 * rng.normal(size=n)
    y[0] = y[-1] = 0.0
    return np.c_[x, y]


@pytest.mark.parametrize("where", ["first", "last"])
def test_a_count_line_is_kept_and_is_not_a_point(tmp_path, where):
    P = _foil()
    rows = [f"  {x:.6f}  {y:.6f}" for x, y in P]
    count = f"{len(P)} 0" if where == "first" else f"{len(P) // 2} {len(P) - len(P) // 2}"
    lines = ([count] + rows) if where == "first" else (["RAE-LIKE"] + rows + [count])
    src = tmp_path / "foil.dat"
    src.write_text("\n".join(lines) + "\n", encoding="utf-8")
    recs = read_curves(src)
    pts = np.vstack([r.points for r in recs])
    assert np.abs(pts).max() <= 1.0  # no point at (129, 0) or (64, 65)
    out = tmp_path / "out.dat"
    res = CliRunner().invoke(main, ["fair", str(src), "-o", str(out), "--tol", str(TOL), "-q"])
    assert res.exit_code == 0, res.output
    got = out.read_text(encoding="utf-8").splitlines()
    assert len(got) == len(lines)
    k = 0 if where == "first" else -1
    assert got[k] == lines[k]  # the count line as it was
    body = got[1:] if where == "first" else got[1:-1]
    Q = np.array([[float(v) for v in ln.split()] for ln in body])
    moves = np.linalg.norm(Q - np.round(P, 6), axis=1)
    assert moves.max() <= TOL and np.count_nonzero(moves) > 50
    assert moves[0] == 0 and moves[-1] == 0  # the trailing edge stays


@pytest.mark.parametrize("text, line, match", [
    ("mesh\n1 2 3\n4 5 6\n7 8 9\n", 2, "its rows have 3 numbers, airfoil file rows have 2"),
    ("0.1\n0.2\n0.3\n", 1, "its rows have 1 number, airfoil file rows have 2"),
])
def test_rows_of_another_width_are_named(tmp_path, text, line, match):
    """A mesh or a column of numbers saved as ``.dat`` said only "no data rows"."""
    from curvefair import FileFormatError

    src = tmp_path / "f.dat"
    src.write_text(text, encoding="utf-8")
    with pytest.raises(FileFormatError, match=match) as exc:
        read_curves(src)
    assert exc.value.line == line


@pytest.mark.parametrize("text", [
    "inf inf\n1.0 0.0\n0.5 0.05\n0.0 0.0\n0.5 -0.05\n1.0 0.0\n",          # a Lednicer-like count
    "name\n1.0 0.0\n0.5 0.05\n0.0 0.0\n0.5 -0.05\n1.0 0.0\n1e999 0\n",     # a Selig-like count
])
def test_infinite_count_like_row_is_a_clear_error(tmp_path, text):
    """A row of infinite numbers where a count line could stand is refused with the file's
    error (a non-finite coordinate), not taken for a count (``int(inf)`` raised
    OverflowError; found by the mutation fuzz test)."""
    p = tmp_path / "f.dat"
    p.write_text(text)
    with pytest.raises(FileFormatError, match="non-finite"):
        read_curves(p)
