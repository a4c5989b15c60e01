"""Curves read from one format and written to another keep their points / geometry.

Reference: the points or the curve read from the source file; pieces split at corners must
come back joined.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from curvefair import FileFormatError, read_curves, write_curves

DATA = Path(__file__).parent / "data"


def _square_csv(tmp_path):
    s = np.linspace(0, 1, 6)[:-1]
    sq = np.vstack([np.c_[s, 0 * s], np.c_[1 + 0 * s, s], np.c_[1 - s, 1 + 0 * s],
                    np.c_[0 * s, 1 - s]])
    p = tmp_path / "sq.csv"
    np.savetxt(p, np.vstack([sq, sq[:1]]), fmt="%.3f", delimiter=",")
    return p, sq


@pytest.mark.parametrize("ext, lib", [("dxf", "ezdxf"), ("3dm", "rhino3dm"),
                                      ("svg", "svgpathtools"), ("json", None), ("csv", None)])
def test_split_loop_goes_across_formats_as_one_polyline(tmp_path, ext, lib):
    if lib:
        pytest.importorskip(lib)
    p, sq = _square_csv(tmp_path)
    recs = read_curves(p)
    assert len(recs) == 4
    out = tmp_path / f"o.{ext}"
    write_curves(out, recs)
    # a drawing holds the list as a polyline (an SVG path of lines): a drawn shape unless
    # polylines=True
    back = read_curves(out, corner_angle=None,
                       polylines=True if ext in ("dxf", "3dm", "svg") else None)
    if ext == "json":
        # JSON keeps each piece as its own curve
        assert len(back) == 4
        got = np.vstack([b.curve.points[:-1] for b in back])
        np.testing.assert_allclose(got, sq, atol=1e-15)
        return
    assert len(back) == 1
    got = np.asarray(back[0].points if back[0].points is not None else back[0].curve.points)
    got = got[:-1] if len(got) == len(sq) + 1 else got
    np.testing.assert_allclose(got, sq, atol=1e-12)


@pytest.mark.parametrize("ext, lib", [("dxf", "ezdxf"), ("3dm", "rhino3dm"),
                                      ("svg", "svgpathtools")])
def test_airfoil_to_cad_and_back(tmp_path, ext, lib):
    pytest.importorskip(lib)
    (rec,) = read_curves(DATA / "e423.dat")
    write_curves(tmp_path / f"e.{ext}", [rec])
    # a polyline (an SVG path of lines): by default a drawn shape, and the error says so
    noun = "straight-line shape" if ext == "svg" else "polyline"
    with pytest.raises(FileFormatError, match=f"1 {noun} is .* polylines=True"):
        read_curves(tmp_path / f"e.{ext}")
    (back,) = read_curves(tmp_path / f"e.{ext}", corner_angle=None, polylines=True)
    assert back.kind == "polyline"
    np.testing.assert_allclose(back.points, rec.points, atol=1e-12)
    write_curves(tmp_path / "e2.dat", [back])
    np.testing.assert_allclose(read_curves(tmp_path / "e2.dat")[0].points, rec.points,
                               atol=1e-12)
