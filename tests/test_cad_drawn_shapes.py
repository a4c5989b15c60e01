"""DXF and 3dm polylines are drawn shapes: left as drawn unless ``polylines=True``.

Session 28: a hunt through every DXF of ezdxf's and dxf-parser's repositories and every 3dm of
openNURBS' and rhino3dm's (``curvefair fair F --tol T``, T = 1e-3 of the drawing's diagonal)
found polylines faired as point data: 77 polylines, 6,870 vertices moved; ezdxf's map of the
USA turned a vertex by 179 degrees, its hatch boundary by 40, dxf-parser's polylines by 16.8.
The files here are those projects' own (licences in tests/data/README.md); everything is
measured with ezdxf / rhino3dm on the written file.
"""

from __future__ import annotations

import json
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest
from _helpers import assert_copied_with_note
from click.testing import CliRunner

from curvefair import read_curves
from curvefair.cli import main
from curvefair.errors import FileFormatError
from curvefair.io import DrawnShapesLeft

ezdxf = pytest.importorskip("ezdxf")

REAL = Path(__file__).parent / "data" / "real"
POLYLINES = REAL / "dxf-parser" / "polylines.dxf"      # R12, twelve 3-D POLYLINEs, nothing else
HATCHES = REAL / "ezdxf" / "hatches_2.dxf"              # four LWPOLYLINEs and a SPLINE
TJOINT = REAL / "opennurbs" / "v3_T-Joint2.3dm"         # two 3-D PolylineCurves, PolyCurves


def _run(*args: object):
    return CliRunner().invoke(main, [str(a) for a in args], catch_exceptions=False)


def _dxf_polylines(path: Path) -> dict[str, np.ndarray]:
    """Vertices of every LWPOLYLINE (x, y, start width, end width, bulge) and POLYLINE
    (x, y, z) by handle, as ezdxf reads them."""
    out = {}
    for e in ezdxf.readfile(path).modelspace():
        if e.dxftype() == "LWPOLYLINE":
            out[e.dxf.handle] = np.array(list(e.get_points("xyseb")), dtype=float)
        elif e.dxftype() == "POLYLINE":
            out[e.dxf.handle] = np.array([tuple(v.dxf.location) for v in e.vertices])
    return out


def _spline_samples(path: Path, handle: str, n: int = 20001) -> np.ndarray:
    e = ezdxf.readfile(path).entitydb[handle]
    return np.array([tuple(p) for p in e.construction_tool().approximate(n - 1)])[:, :2]


def test_dxf_polylines_stay_as_drawn_and_the_spline_is_faired(tmp_path):
    """hatches_2.dxf: by default the four LWPOLYLINEs (one a 1,301-vertex hatch boundary whose
    vertices the old default moved, turning one by 40 degrees) keep every number, and the
    SPLINE is faired within tol (dense samples, nearest neighbours)."""
    from scipy.spatial import cKDTree

    tol = 0.14
    out = tmp_path / "out.dxf"
    res = _run("fair", HATCHES, "-o", out, "--tol", tol, "--report", tmp_path / "r.json")
    assert res.exit_code == 0, res.output
    # said, so that a user who wanted them faired is not left guessing
    assert "Note: " in res.output and "4 polylines (LWPOLYLINE, 2-D and 3-D POLYLINE) left " \
        "as drawn; read_curves(..., polylines=True) (CLI --polylines)" in res.output
    rep = json.loads((tmp_path / "r.json").read_text())
    assert [c["kind"] for c in rep["curves"]] == ["bspline"]
    before, after = _dxf_polylines(HATCHES), _dxf_polylines(out)
    assert set(before) == set(after) == {"218", "21B", "220", "24A"}
    for h in before:
        np.testing.assert_array_equal(after[h], before[h])
    a, b = _spline_samples(HATCHES, "21A"), _spline_samples(out, "21A")
    assert np.abs(a - b).max() > 1e-3 * tol           # faired
    spacing = np.linalg.norm(np.diff(a, axis=0), axis=1).max()
    assert cKDTree(a).query(b)[0].max() <= tol + spacing
    # --polylines reads them as point lists again: vertices move, each within tol exactly
    out2 = tmp_path / "pl.dxf"
    res = _run("fair", HATCHES, "-o", out2, "--tol", tol, "--polylines")
    assert res.exit_code == 0, res.output
    after = _dxf_polylines(out2)
    moved = np.linalg.norm(after["24A"][:, :2] - before["24A"][:, :2], axis=1)
    assert np.count_nonzero(moved) > 100 and moved.max() <= tol


@pytest.mark.parametrize("path, n, lib", [
    (HATCHES, 4, "ezdxf"),
    (REAL / "simple-icons" / "spdx.svg", 2, "svgpathtools"),   # a polygon, a rectangle, curves
    (TJOINT, 2, "rhino3dm"),
])
def test_reading_a_drawing_notes_the_shapes_left_as_drawn(path, n, lib):
    pytest.importorskip(lib)
    with pytest.warns(DrawnShapesLeft, match=f": {n} .* left as drawn; read_curves") as w:
        recs = read_curves(path, on_unsupported="skip")
    assert recs and [x.message.n_drawn for x in w if x.category is DrawnShapesLeft] == [n]
    with warnings.catch_warnings():
        warnings.simplefilter("error", DrawnShapesLeft)
        read_curves(path, on_unsupported="skip", polylines=True)   # nothing left: no note


def test_dxf_of_polylines_only_is_written_unchanged_and_said_so(tmp_path):
    """dxf-parser's polylines.dxf: twelve 3-D POLYLINEs (7-64 vertices) and nothing else. The
    old default moved 254 of their vertices and turned one by 16.8 degrees; now the file is
    copied (exit 0) with a note naming --polylines, which fairs them within tol."""
    with pytest.raises(FileFormatError, match=r"no curves in the dxf file: its 12 polylines "
                                              r"are \(LWPOLYLINE.*\) left as drawn") as exc:
        read_curves(POLYLINES)
    assert exc.value.n_drawn == 12
    src = tmp_path / "polylines.dxf"
    shutil.copyfile(POLYLINES, src)
    assert_copied_with_note(_run, src, tmp_path / "out.dxf", tmp_path / "r.json", 0.4, 12)
    res = _run("fair", src, "-o", tmp_path / "pl.dxf", "--tol", "0.4", "--polylines", "-q")
    assert res.exit_code == 0, res.output
    before, after = _dxf_polylines(src), _dxf_polylines(tmp_path / "pl.dxf")
    assert set(after) == set(before)                   # no polyline lost
    n_moved = 0
    for h, p in before.items():
        assert after[h].shape == p.shape
        d = np.linalg.norm(after[h] - p, axis=1)
        assert d.max() <= 0.4
        n_moved += int(np.count_nonzero(d))
    assert n_moved > 50


def test_other_commands_say_how_to_read_dxf_polylines(tmp_path):
    res = _run("analyze", POLYLINES)
    assert res.exit_code == 1 and "--polylines" in res.output
    res = _run("analyze", POLYLINES, "--polylines", "--json")
    assert res.exit_code == 0, res.output
    assert {c["kind"] for c in json.loads(res.output)["curves"]} == {"polyline"}
    res = _run("check", POLYLINES, "--format", "json")
    assert res.exit_code == 0 and json.loads(res.output)["n_curves"] == 0
    res = _run("check", POLYLINES, "--format", "json", "--polylines")
    assert json.loads(res.output)["n_curves"] >= 12


def test_batch_leaves_dxf_polylines_as_drawn_unless_asked(tmp_path):
    inp = tmp_path / "in"
    inp.mkdir()
    shutil.copyfile(POLYLINES, inp / "polylines.dxf")
    res = _run("fair", inp, "-o", tmp_path / "out", "--tol", "0.4", "--jobs", "1", "-q")
    assert res.exit_code == 0, res.output
    assert (tmp_path / "out" / "polylines.dxf").read_bytes() == POLYLINES.read_bytes()
    res = _run("fair", inp, "-o", tmp_path / "out2", "--tol", "0.4", "--jobs", "1", "-q",
               "--polylines")
    assert res.exit_code == 0, res.output
    before, after = _dxf_polylines(POLYLINES), _dxf_polylines(tmp_path / "out2" / "polylines.dxf")
    assert any(not np.array_equal(after[h], before[h]) for h in before)
    assert all(np.linalg.norm(after[h] - before[h], axis=1).max() <= 0.4 for h in before)


def _3dm_polylines(path: Path) -> dict[str, np.ndarray]:
    rh = pytest.importorskip("rhino3dm")
    m = rh.File3dm.Read(str(path))
    return {str(o.Attributes.Id): np.array([[q.X, q.Y, q.Z] for q in
                                            (o.Geometry.Point(i)
                                             for i in range(o.Geometry.PointCount))])
            for o in m.Objects if isinstance(o.Geometry, rh.PolylineCurve)}


def test_3dm_polylines_stay_as_drawn_and_a_3d_polyline_faired_flat_reads_back(tmp_path):
    """openNURBS' T-Joint2 model: two straight 3-D PolylineCurves whose z differs by rounding
    noise (1e-15). By default they keep every number. With --polylines the fair makes their z
    exactly equal, the file reads back as a 2-D curve at that z, and the write check compared
    it with the 3-D input: "curve_a is 3-D but curve_b is 2-D", exit 1, nothing written. Now
    it is the same curve in 3-D: written, every vertex within tol."""
    pytest.importorskip("rhino3dm")
    tol = 0.01
    before = _3dm_polylines(TJOINT)
    assert len(before) == 2
    res = _run("fair", TJOINT, "-o", tmp_path / "out.3dm", "--tol", tol, "-q",
               "--report", tmp_path / "r.json")
    assert res.exit_code == 0, res.output
    assert {c["kind"] for c in json.loads((tmp_path / "r.json").read_text())["curves"]} == \
        {"bspline"}
    after = _3dm_polylines(tmp_path / "out.3dm")
    for k, p in before.items():
        np.testing.assert_array_equal(after[k], p)
    res = _run("fair", TJOINT, "-o", tmp_path / "pl.3dm", "--tol", tol, "-q", "--polylines",
               "--report", tmp_path / "r2.json")
    assert res.exit_code == 0, res.output
    rep = json.loads((tmp_path / "r2.json").read_text())
    assert rep["output_written"] and [c["kind"] for c in rep["curves"]].count("polyline") == 2
    after = _3dm_polylines(tmp_path / "pl.3dm")
    for k, p in before.items():
        assert after[k].shape == p.shape
        assert np.linalg.norm(after[k] - p, axis=1).max() <= tol


def test_a_3d_spline_faired_flat_is_measured_in_3d(tmp_path):
    """The B-spline side of the lift: a 3-D SPLINE whose z differ by rounding noise, written
    flat (every z equal), reads back as a 2-D curve at that z and is measured against the 3-D
    input as the same curve (it raised "curve_a is 3-D but curve_b is 2-D")."""
    from curvefair import BSplineCurve, write_curves

    a = np.linspace(0.0, 3.0, 9)
    noisy = np.c_[np.cos(a), np.sin(a), 2.5 + np.r_[0.0, 4e-16, -4e-16, 0.0, 2e-16, 0.0, 0.0,
                                                        -2e-16, 0.0]]
    knots = np.r_[[0.0] * 4, np.arange(1.0, 6.0), [6.0] * 4]
    src = tmp_path / "in.dxf"
    write_curves(src, [BSplineCurve(noisy, knots, 3)])
    (rec,) = read_curves(src)
    assert rec.curve.dim == 3
    flat = np.array(rec.curve.control_points)
    flat[:, 2] = 2.5
    check = write_curves(tmp_path / "out.dxf", [rec.with_curve(rec.curve.replace(
        control_points=flat))], template=src, tol=1e-12)
    assert check.max_deviation <= 1e-12
    (back,) = read_curves(tmp_path / "out.dxf")
    assert back.curve.dim == 2 and back.source["z"] == 2.5
