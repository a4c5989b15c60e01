"""Fonts (issue 16): ``curvefair fair X.designspace --tol T -o OUTDIR`` and building the result.

The designspace and its three master UFOs are made by glyphsLib (``build_masters``) from the
real Glyphs source tests/data/real/glyphsLib/GlyphsUnitTestSans3.glyphs. Checked here with
fontTools/ufoLib2 only: same point structure per master, every point within tol, masters
still interpolation-compatible (fontTools' interpolatable), clear errors (no -o, a missing
master, a layer source whose layer is missing), and the faired UFO compiles with ufo2ft into an
OTF and a TTF that fontTools reads back with the faired outlines.
"""

from __future__ import annotations

import logging
import shutil
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("fontTools")
ufoLib2 = pytest.importorskip("ufoLib2")
glyphsLib = pytest.importorskip("glyphsLib")

from click.testing import CliRunner  # noqa: E402
from fontTools.designspaceLib import DesignSpaceDocument  # noqa: E402
from fontTools.pens.recordingPen import RecordingPointPen  # noqa: E402
from fontTools.ttLib import TTFont  # noqa: E402

from curvefair.cli import main  # noqa: E402

SRC = Path(__file__).parent / "data" / "real" / "glyphsLib" / "GlyphsUnitTestSans3.glyphs"
GLYPHS = ["a", "n", "h", "m", "A"]


@pytest.fixture
def masters(tmp_path):
    """(full designspace with its brace-layer source, designspace of the three masters)."""
    d = tmp_path / "src"
    logging.getLogger("glyphsLib").setLevel(logging.ERROR)
    logging.getLogger("fontTools").setLevel(logging.ERROR)
    glyphsLib.build_masters(str(SRC), str(d), designspace_path=str(d / "Full.designspace"),
                            minimal=True)
    doc = DesignSpaceDocument.fromfile(d / "Full.designspace")
    assert any(s.layerName for s in doc.sources)  # the brace layer {155}
    doc.sources = [s for s in doc.sources if not s.layerName]
    doc.write(d / "Test.designspace")
    return d / "Full.designspace", d / "Test.designspace"


def _points(font, g):
    pen = RecordingPointPen()
    font[g].drawPoints(pen)
    return ([a[0] for op, a, _ in pen.value if op == "addPoint"],
            [a[1] for op, a, _ in pen.value if op == "addPoint"])


def test_cli_fairs_designspace_masters(masters, tmp_path):
    full, ds = masters
    out = tmp_path / "out"
    res = CliRunner().invoke(main, ["fair", str(ds), "--tol", "2", "-o", str(out),
                                    "--glyphs", ",".join(GLYPHS), "--report",
                                    str(tmp_path / "r.json")])
    assert res.exit_code == 0, res.output
    assert "interpolation problems" in res.output
    doc = DesignSpaceDocument.fromfile(ds)
    assert (out / ds.name).is_file()
    moved = 0.0
    for s in doc.sources:
        a, b = ufoLib2.Font.open(s.path), ufoLib2.Font.open(out / s.filename)
        assert sorted(a.keys()) == sorted(b.keys())
        for g in a.keys():
            pa, ta = _points(a, g)
            pb, tb = _points(b, g)
            assert ta == tb, g  # the same points, types in the same order
            if pa:
                d = np.linalg.norm(np.array(pb, float) - np.array(pa, float), axis=1)
                assert d.max() <= 2.0, (s.filename, g, d.max())
                if g not in GLYPHS:
                    assert d.max() == 0.0, g
                moved = max(moved, float(d.max()))
        assert a.kerning == b.kerning and a.features.text == b.features.text
    assert moved > 0
    # masters stay compatible: no problem kind the input did not have
    from curvefair.fonts import interpolation_problems

    before = {p["type"] for p in interpolation_problems(ds)}
    after = {p["type"] for p in interpolation_problems(out / ds.name)}
    assert after <= before, after - before


def test_cli_designspace_errors(masters, tmp_path):
    full, ds = masters
    run = CliRunner().invoke
    res = run(main, ["fair", str(ds), "--tol", "2"])
    assert res.exit_code == 2 and "-o OUTDIR" in res.output
    res = run(main, ["fair", str(ds), "-o", str(tmp_path / "o")])
    assert res.exit_code == 2 and "--tol is required" in res.output
    res = run(main, ["fair", str(ds), "--tol", "2", "-o", str(ds.parent)])
    assert res.exit_code == 2 and "folder of the designspace" in res.output
    res = run(main, ["fair", str(ds), "--tol", "2", "-o", str(tmp_path / "no" / "o")])
    assert res.exit_code == 2 and "does not exist" in res.output
    # a layer source (the brace layer) whose layer is not in its UFO: named, nothing written
    doc = DesignSpaceDocument.fromfile(full)
    next(s for s in doc.sources if s.layerName).layerName = "{999}"
    doc.write(full.parent / "Bad.designspace")
    res = run(main, ["fair", str(full.parent / "Bad.designspace"), "--tol", "2", "-o",
                     str(tmp_path / "o"), "-q"])
    assert res.exit_code == 1 and "no layer '{999}'" in res.output, res.output
    assert "Traceback" not in res.output and not (tmp_path / "o").exists()
    # a master that is not there: named, nothing written
    doc = DesignSpaceDocument.fromfile(ds)
    shutil.rmtree(doc.sources[1].path)
    res = run(main, ["fair", str(ds), "--tol", "2", "-o", str(tmp_path / "o2"), "-q"])
    assert res.exit_code == 1 and doc.sources[1].filename in res.output, res.output
    assert "no such UFO" in res.output
    assert not (tmp_path / "o2").exists()


def test_faired_ufo_compiles_with_ufo2ft(masters, tmp_path):
    ufo2ft = pytest.importorskip("ufo2ft")
    _, ds = masters
    out = tmp_path / "out"
    res = CliRunner().invoke(main, ["fair", str(ds), "--tol", "2", "-o", str(out), "-q",
                                    "--glyphs", ",".join(GLYPHS)])
    assert res.exit_code == 0, res.output
    doc = DesignSpaceDocument.fromfile(ds)
    ufo_path = out / doc.sources[1].filename  # Regular
    for compile_, ext in ((ufo2ft.compileOTF, "otf"), (ufo2ft.compileTTF, "ttf")):
        ufo = ufoLib2.Font.open(ufo_path)
        kw = {"optimizeCFF": 0} if ext == "otf" else {"reverseDirection": False}
        compile_(ufo, **kw).save(tmp_path / f"F.{ext}")
        f = TTFont(tmp_path / f"F.{ext}")
        f.ensureDecompiled()
        gs = f.getGlyphSet()
        for g in GLYPHS:
            pts, types = _points(ufoLib2.Font.open(ufo_path), g)
            pen = RecordingPointPen()
            gs[g].drawPoints(pen)
            got = [a[0] for op, a, _ in pen.value if op == "addPoint"]
            if ext == "otf":  # CFF: the faired cubic points, rounded to integers by the build
                # (the masters' integer contours are faired on the integer grid: exact there)
                P, xy = np.array(pts, float), np.array(got, float)
                assert xy.shape == P.shape, g
                assert np.abs(xy - P).max() <= 0.5, g
                if np.array_equal(P, np.round(P)):
                    assert np.array_equal(xy, P), g
            else:  # glyf: cubics converted to quadratics, within cu2qu's 1 unit
                P, xy = np.array(pts, float), np.array(got, float)
                assert xy.min(0)[0] >= P.min(0)[0] - 1.5 and xy.max(0)[0] <= P.max(0)[0] + 1.5


def test_faired_masters_build_variable_fonts_and_cff2_is_refused(masters, tmp_path):
    """The faired designspace builds as variable fonts (ufo2ft merges the masters with varLib:
    it fails on incompatible masters); a CFF2 binary is refused with a message naming the
    table."""
    ufo2ft = pytest.importorskip("ufo2ft")
    from curvefair import read_curves
    from curvefair.errors import FileFormatError

    _, ds = masters
    out = tmp_path / "out"
    res = CliRunner().invoke(main, ["fair", str(ds), "--tol", "2", "-o", str(out), "-q",
                                    "--glyphs", ",".join(GLYPHS)])
    assert res.exit_code == 0, res.output
    doc = DesignSpaceDocument.fromfile(out / ds.name)
    doc.loadSourceFonts(ufoLib2.Font.open)
    vf = ufo2ft.compileVariableTTF(doc)
    assert "gvar" in vf and "fvar" in vf
    doc = DesignSpaceDocument.fromfile(out / ds.name)
    doc.loadSourceFonts(ufoLib2.Font.open)
    cff2 = ufo2ft.compileVariableCFF2(doc, optimizeCFF=0)
    assert "CFF2" in cff2 and "CFF " not in cff2
    cff2.save(tmp_path / "V.otf")
    with pytest.raises(FileFormatError, match="CFF2"):
        read_curves(tmp_path / "V.otf")
    res = CliRunner().invoke(main, ["fair", str(tmp_path / "V.otf"), "--tol", "2", "-o",
                                    str(tmp_path / "W.otf")])
    assert res.exit_code == 1 and "CFF2" in res.output and "Traceback" not in res.output
