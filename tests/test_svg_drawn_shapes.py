"""SVG straight-line shapes are drawn shapes: left as drawn unless ``polylines=True``.

Session 27: the icon hunts (hicolor app icons, Simple Icons) found polygons faired as point
data -- gedit's pencil and Mines' flag lost their corners (27.4 -> 7.75 degrees), Simple Icons'
logos (BoardGameGeek, SPDX) had their vertices moved off the designer's coordinates. The
files here are Simple Icons (CC0, tests/data/README.md); everything is measured with
svgpathtools on the written file.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from _helpers import assert_copied_with_note
from click.testing import CliRunner

from curvefair import read_curves
from curvefair.cli import main
from curvefair.errors import FileFormatError, InputError

spt = pytest.importorskip("svgpathtools")

SI = Path(__file__).parent / "data" / "real" / "simple-icons"


def _run(*args: object):
    return CliRunner().invoke(main, [str(a) for a in args], catch_exceptions=False)


def _subpaths(path: Path) -> list:
    (p,) = spt.Document(str(path)).paths()
    return list(p.continuous_subpaths())


def _vertices(sub) -> np.ndarray:
    """The vertices, without the closing segment relative commands leave ~1e-15 long."""
    return np.array([[g.start.real, g.start.imag] for g in sub if g.length() > 1e-9])


def _lines_only(sub) -> bool:
    return all(isinstance(g, spt.Line) for g in sub if g.length() > 1e-9)


def test_polygon_logo_is_written_unchanged_and_said_so(tmp_path):
    """BoardGameGeek's logo is one closed polygon of 10 vertices; three turn by 47-53 degrees
    (below the 60-degree corner angle): read as point data, the fair moved them. Now nothing
    is read, the command writes the input's bytes (exit 0) and says why; ``--polylines``
    still fairs it as a point list, within tol."""
    src = tmp_path / "bgg.svg"
    shutil.copyfile(SI / "boardgamegeek.svg", src)
    with pytest.raises(FileFormatError, match=r"1 straight-line shape is .* left as drawn; "
                                              r"read_curves\(\.\.\., polylines=True\)"):
        read_curves(src)
    assert_copied_with_note(_run, src, tmp_path / "out.svg", tmp_path / "r.json", 0.05, 1)
    # the opt-in: read as a point list and faired, every vertex within tol
    res = _run("fair", src, "-o", tmp_path / "pl.svg", "--tol", "0.05", "--polylines")
    assert res.exit_code == 0, res.output
    a, b = _vertices(_subpaths(src)[0]), _vertices(_subpaths(tmp_path / "pl.svg")[0])
    assert a.shape == b.shape
    move = np.hypot(*(a - b).T)
    assert move.max() > 1e-3 and move.max() <= 0.05 + 1e-12   # the vertices moved


def test_curves_faired_polygons_beside_them_kept_exactly(tmp_path):
    """SPDX's logo is one path of three subpaths: a polygon (turns of 41-45 degrees), a
    subpath of Beziers and lines, and a rectangle. By default only the middle one is faired;
    the two polygons keep every vertex (as svgpathtools reads them, to rounding of the
    relative commands they are written with) and their text."""
    src = tmp_path / "spdx.svg"
    shutil.copyfile(SI / "spdx.svg", src)
    recs = read_curves(src)
    assert [(r.kind, r.source["subpath"]) for r in recs] == [("bspline", 1)]
    assert recs[0].source["polylines"] is False
    every = read_curves(src, polylines=True)
    assert sorted({r.source["subpath"] for r in every}) == [0, 1, 2]
    tol = 0.05
    res = _run("fair", src, "-o", tmp_path / "out.svg", "--tol", tol)
    assert res.exit_code == 0, res.output
    a, b = _subpaths(src), _subpaths(tmp_path / "out.svg")
    assert len(a) == len(b) == 3
    assert [_lines_only(s) for s in a] == [True, False, True]
    for k in (0, 2):
        np.testing.assert_allclose(_vertices(b[k]), _vertices(a[k]), rtol=0, atol=1e-12)
    # the Bezier subpath did change, within tol at its nodes and handles
    pa = np.array([z for g in a[1] for z in g.bpoints()])
    pb = np.array([z for g in b[1] for z in g.bpoints()])
    assert pa.shape == pb.shape and 0 < np.abs(pa - pb).max() <= tol + 1e-9
    # the first polygon's text is the input's
    d_in = spt.svg2paths(str(src))[1][0]["d"]
    d_out = spt.svg2paths(str(tmp_path / "out.svg"))[1][0]["d"]
    first = d_in[:d_in.lower().index("z") + 1]
    assert d_out.startswith(first) and d_out != d_in
    # with --polylines the polygon is a point list again, and is faired: a vertex moves
    res = _run("fair", src, "-o", tmp_path / "pl.svg", "--tol", tol, "--polylines")
    assert res.exit_code == 0, res.output
    c = _subpaths(tmp_path / "pl.svg")
    assert np.abs(_vertices(c[0]) - _vertices(a[0])).max() > 1e-3


def test_polylines_argument_is_checked():
    with pytest.raises(InputError, match=r"polylines= is for drawings \(svg, dxf, 3dm\), "
                                         r"not airfoil"):
        read_curves(Path(__file__).parent / "data" / "e423.dat", polylines=True)
    with pytest.raises(InputError, match="polylines must be True, False or None"):
        read_curves(SI / "spdx.svg", polylines="yes")


def test_other_commands_say_how_to_read_drawn_shapes(tmp_path):
    src = SI / "boardgamegeek.svg"
    res = _run("analyze", src)
    assert res.exit_code == 1 and "--polylines" in res.output
    res = _run("analyze", src, "--polylines", "--json")
    assert res.exit_code == 0, res.output
    curves = json.loads(res.output)["curves"]   # pieces between corners of 60 degrees or more
    assert curves and all(c["kind"] == "polyline" for c in curves)
    # check: a drawing without curves has nothing unfair in it; --polylines checks the polygon
    res = _run("check", src, "--format", "json")
    assert res.exit_code == 0 and json.loads(res.output)["n_curves"] == 0
    res = _run("check", src, "--format", "json", "--polylines")
    assert json.loads(res.output)["n_curves"] == len(curves)


def test_batch_writes_a_drawing_of_polygons_unchanged(tmp_path):
    inp = tmp_path / "in"
    inp.mkdir()
    for name in ("boardgamegeek.svg", "spdx.svg"):
        shutil.copyfile(SI / name, inp / name)
    res = _run("fair", inp, "-o", tmp_path / "out", "--tol", "0.05", "--jobs", "1", "-q")
    assert res.exit_code == 0, res.output
    assert (tmp_path / "out" / "boardgamegeek.svg").read_bytes() == \
        (inp / "boardgamegeek.svg").read_bytes()
    rep = json.loads((tmp_path / "out" / ".curvefair" / "boardgamegeek.svg.json").read_text())
    assert rep["status"] == "ok" and rep["n_drawn_shapes"] == 1
    assert "left as drawn" in rep["note"]
    # the other file's polygons as drawn, its curves faired
    a, b = _subpaths(inp / "spdx.svg"), _subpaths(tmp_path / "out" / "spdx.svg")
    np.testing.assert_allclose(_vertices(b[0]), _vertices(a[0]), rtol=0, atol=1e-12)
    assert (tmp_path / "out" / "spdx.svg").read_bytes() != (inp / "spdx.svg").read_bytes()
