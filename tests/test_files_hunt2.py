"""Files from other software that the second file hunt (session 19) found damaged or refused.

Each test reads a real file (tests/data/README.md: origin and licence), or a real file with
one property a user's copy may have (a byte order mark, a Latin-1 name line), writes it back
the way ``curvefair fair`` does and checks the result with independent means: the bytes of
the file, and the libraries that wrote such files (ezdxf, svgpathtools, rhino3dm).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from curvefair import read_curves, write_curves

DATA = Path(__file__).parent / "data"
REAL = DATA / "real"


def _moved(rec, k, dy):
    """The record with its curve's data point ``k`` moved by ``dy`` in y."""
    pts = np.array(rec.curve.points)
    pts[k, 1] += dy
    return rec.with_curve(rec.curve.replace(points=pts))


# ------------------------------------------------------------------------------------------
# text encodings: a byte order mark and Latin-1 text are written back as they were
# ------------------------------------------------------------------------------------------
def _line_diff(a: bytes, b: bytes) -> list[int]:
    la, lb = a.split(b"\n"), b.split(b"\n")
    assert len(la) == len(lb)
    return [i for i, (x, y) in enumerate(zip(la, lb, strict=True)) if x != y]


def test_airfoil_with_a_byte_order_mark_keeps_it(tmp_path):
    # clarky.dat (UIUC, via aerosandbox) as a Windows editor saves it: UTF-8 with a BOM
    src = tmp_path / "clarky.dat"
    src.write_bytes(b"\xef\xbb\xbf" + (DATA / "clarky.dat").read_bytes())
    recs = read_curves(src)
    assert recs[0].name == "CLARK Y AIRFOIL"
    out = tmp_path / "out.dat"
    write_curves(out, [_moved(recs[0], 5, 1e-5)] + recs[1:])
    a, b = src.read_bytes(), out.read_bytes()
    assert b.startswith(b"\xef\xbb\xbf CLARK Y AIRFOIL")   # was dropped: "CLARK Y..." only
    assert _line_diff(a, b) == [6]                           # the one moved row, nothing else


def test_points_csv_with_a_byte_order_mark_keeps_it(tmp_path):
    src = tmp_path / "p.csv"
    src.write_bytes(b"\xef\xbb\xbfx;y\r\n" + b"".join(
        b"%.4f;%.4f\r\n" % (x, np.sin(x)) for x in np.linspace(0, 3, 12)))
    (rec,) = read_curves(src)
    out = tmp_path / "o.csv"
    write_curves(out, [_moved(rec, 4, 1e-3)])
    a, b = src.read_bytes(), out.read_bytes()
    assert b.startswith(b"\xef\xbb\xbfx;y\r\n")
    assert _line_diff(a, b) == [5]


def test_airfoil_with_a_latin1_name_line_is_written_in_latin1(tmp_path):
    # the same file with a name line in Latin-1 (not UTF-8): 'é' is the byte 0xE9 and must
    # stay that byte (it was re-encoded as UTF-8, 0xC3 0xA9: a changed name line)
    raw = (DATA / "clarky.dat").read_bytes()
    src = tmp_path / "clarky.dat"
    src.write_bytes(raw.replace(b"CLARK Y AIRFOIL", b"CLARK Y \xe9paisseur 11,7 %", 1))
    recs = read_curves(src)
    assert recs[0].name == "CLARK Y \u00e9paisseur 11,7 %"
    out = tmp_path / "out.dat"
    write_curves(out, [_moved(recs[0], 5, 1e-5)] + recs[1:])
    a, b = src.read_bytes(), out.read_bytes()
    assert b.split(b"\n")[0] == a.split(b"\n")[0]
    assert _line_diff(a, b) == [6]


# ------------------------------------------------------------------------------------------
# binary DXF: written back binary (it was written as ASCII DXF, silently)
# ------------------------------------------------------------------------------------------
BIN_SENTINEL = b"AutoCAD Binary DXF\r\n\x1a\x00"


def test_binary_dxf_is_written_back_binary(tmp_path):
    import ezdxf
    # trimesh's spline.DXF (AC1015, 6 SPLINEs, 4 LINEs) saved by ezdxf as a binary DXF, as
    # netDxf's "sample binary.dxf" (263 kB, same behaviour) is
    src = tmp_path / "spline_bin.dxf"
    ezdxf.readfile(REAL / "trimesh" / "spline.DXF").saveas(src, fmt="bin")
    assert src.read_bytes().startswith(BIN_SENTINEL)
    with pytest.warns(UserWarning, match="degree-1 spline"):
        recs = read_curves(src, on_unsupported="skip")
    rec = recs[0]
    assert rec.kind == "bspline"
    cp = np.array(rec.curve.control_points)
    cp[1, 1] += 1e-3
    out = tmp_path / "out.dxf"
    write_curves(out, [rec.with_curve(rec.curve.replace(control_points=cp))] + recs[1:],
                 template=src)
    assert out.read_bytes().startswith(BIN_SENTINEL)
    a, b = ezdxf.readfile(src), ezdxf.readfile(out)
    ea = sorted((e.dxftype(), e.dxf.handle) for e in a.modelspace())
    eb = sorted((e.dxftype(), e.dxf.handle) for e in b.modelspace())
    assert ea == eb
    h = rec.source["handle"]
    got = np.array([tuple(p) for p in b.entitydb[h].control_points])[:, : cp.shape[1]]
    np.testing.assert_allclose(got, cp, rtol=0, atol=1e-12)


# ------------------------------------------------------------------------------------------
# SVG: a nested <svg> maps its viewBox onto its viewport (curves in document units)
# ------------------------------------------------------------------------------------------
def _icon_d() -> str:
    import re
    text = (REAL / "fontawesome" / "3.svg").read_text(encoding="utf-8")
    return re.search(r' d="([^"]+)"', text).group(1)


def _nested_doc(d: str, extra: str = "") -> str:
    # the layout icon tools write (an app icon master: a 512-unit glyph placed on a
    # 1024 canvas, <svg x y width height viewBox>), and the same icon placed by the
    # transform a browser applies for that viewport (preserveAspectRatio xMidYMid meet)
    s = 824 / 512
    tx = 100 + (824 - 320 * s) / 2
    return ('<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 1024 1024">\n'
            f'<svg x="100" y="100" width="824" height="824" viewBox="0 0 320 512">'
            f'<path id="nested" d="{d}"/></svg>\n'
            f'<g transform="matrix({s!r},0,0,{s!r},{tx!r},100)"><path id="placed" d="{d}"/></g>\n'
            f'{extra}</svg>\n')


def test_nested_svg_viewport_is_applied_both_ways(tmp_path):
    import svgpathtools as spt
    d = _icon_d()
    src = tmp_path / "icon.svg"
    src.write_text(_nested_doc(d), encoding="utf-8")
    recs = read_curves(src, corner_angle=None)
    nested = [r for r in recs if r.source["id"] == "nested"]
    placed = [r for r in recs if r.source["id"] == "placed"]
    assert len(nested) == len(placed) > 0
    size = 1024.0
    for a, b in zip(nested, placed, strict=True):
        # was: the nested icon in its own viewBox units, 1.61 times smaller, so a --tol in
        # document units allowed moves 1.61 times larger than asked there
        np.testing.assert_allclose(np.asarray(a.curve.control_points),
                                   np.asarray(b.curve.control_points), rtol=0, atol=1e-9 * size)
    # write: a move of 1 document unit comes back as 1 document unit (1/1.61 in the icon's)
    rec = next(r for r in nested if r.kind == "bspline")
    cp = np.array(rec.curve.control_points)
    cp[2] += (0.0, 1.0)
    moved = rec.curve.replace(control_points=cp)
    out = tmp_path / "out.svg"
    write_curves(out, [rec.with_curve(moved) if r is rec else r for r in recs], template=src)
    text = out.read_text(encoding="utf-8")
    assert text.count("<path") == 2 and 'id="placed" d="' + d + '"' in text
    import xml.etree.ElementTree as ET
    el = next(e for e in ET.fromstring(text).iter() if e.get("id") == "nested")
    path = spt.parse_path(el.get("d"))
    s = 824 / 512
    tx = 100 + (824 - 320 * s) / 2
    sub = path.continuous_subpaths()[rec.source["subpath"]]
    t = np.linspace(0, 1, 2001)
    got = np.array([sub.point(v) for v in t])
    got = np.c_[got.real * s + tx, got.imag * s + 100]
    want = moved(np.linspace(moved.knots[3], moved.knots[-4], 400001))
    from scipy.spatial import cKDTree
    dist = cKDTree(want).query(got)[0].max()
    assert dist < 0.05                                # the sampling's own resolution


def test_nested_svg_with_a_viewport_it_cannot_resolve_is_skipped(tmp_path):
    d = _icon_d()
    src = tmp_path / "icon.svg"
    src.write_text(_nested_doc(d).replace('width="824"', 'width="calc(50% - 16px)"'),
                   encoding="utf-8")
    with pytest.raises(Exception, match="calc"):
        read_curves(src)
    with pytest.warns(UserWarning, match=r"id='nested'.*in a nested <svg> with width="):
        recs = read_curves(src, on_unsupported="skip")
    assert recs and all(r.source["id"] == "placed" for r in recs)


# ------------------------------------------------------------------------------------------
# the command: -o OUT without an extension writes IN's format (as --help says)
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name, fmt, tol", [
    ("clarky.dat", "airfoil", 1e-4),                       # UIUC, via aerosandbox
    ("real/occt/trj7_c2-ac-214.stp", "step", 0.01),         # AutoCAD 2000i STEP (OCCT data)
])
def test_output_without_extension_is_written_in_the_input_format(tmp_path, name, fmt, tol):
    import shutil

    from test_cli import assert_user_error, cli
    src = tmp_path / Path(name).name
    shutil.copyfile(DATA / name, src)
    res = cli(["fair", src.name, "--tol", str(tol), "-o", "faired", "-q"], tmp_path)
    # was: exit 1, "Error: '/.../.faired.x1y2z3': cannot tell the format from the extension
    # '.x1y2z3'" -- the read-back check guessed the format of its temporary file
    assert_user_error(res, 0)
    assert ".faired." not in res.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([src.name, "faired"])
    back = read_curves(tmp_path / "faired", format=fmt)
    orig = read_curves(src, format=fmt, on_unsupported="skip")
    assert len(back) == len(orig)
    if fmt == "airfoil":
        d = np.abs(np.vstack([b.points for b in back]) - np.vstack([o.points for o in orig]))
        assert 0 < d.max() <= tol
    else:
        assert (tmp_path / "faired").read_bytes()[:20] == src.read_bytes()[:20]


# ------------------------------------------------------------------------------------------
# 3dm: the geometry of instance definitions (blocks) is not read, as documented
# ------------------------------------------------------------------------------------------
def test_3dm_instance_definition_geometry_is_not_read(tmp_path):
    rh = pytest.importorskip("rhino3dm")
    # openNURBS' own example model (archive version 3, curves and layers) with a block
    # definition added by openNURBS: a copy of one of its curves, wiggled
    m = rh.File3dm.Read(str(REAL / "opennurbs" / "v3_my_curves.3dm"))
    ids = [str(m.Objects[k].Attributes.Id) for k in range(len(m.Objects))]
    t = np.linspace(0.0, 3.0, 20)
    g = rh.Curve.CreateControlPointCurve(
        [rh.Point3d(float(a) * 10, float(np.sin(a) * 10 + 0.05 * np.sin(37 * a)), 0.0)
         for a in t], 3)
    m.InstanceDefinitions.Add("wiggle", "", "", "", rh.Point3d(0, 0, 0), (g,),
                              (rh.ObjectAttributes(),))
    src = tmp_path / "blocks.3dm"
    assert m.Write(str(src), 7)
    back = rh.File3dm.Read(str(src))
    modes = [back.Objects[k].Attributes.Mode for k in range(len(back.Objects))]
    assert modes.count(rh.ObjectMode.InstanceDefinitionObject) == 1
    recs = read_curves(src, on_unsupported="skip")
    # was: the block's curve was a record too (faired in block coordinates, then drawn by
    # every instance through its transform, scaled ones beyond --tol)
    assert recs and {r.source["id"] for r in recs} <= set(ids)
    plain = read_curves(REAL / "opennurbs" / "v3_my_curves.3dm", on_unsupported="skip")
    assert len(recs) == len(plain)


# ------------------------------------------------------------------------------------------
# SVG: a curve drawn by <use> larger than it is read is not faired
# ------------------------------------------------------------------------------------------
def _use_doc(d: str) -> str:
    # the icon defined once and drawn by <use>: at its own size (an icon sprite), twice as
    # large, and as a <symbol> whose viewBox a <use> maps onto a larger viewport
    return ('<svg xmlns="http://www.w3.org/2000/svg" '
            'xmlns:xlink="http://www.w3.org/1999/xlink" viewBox="0 0 2048 1024">\n'
            f'<defs><path id="same" d="{d}"/><path id="big" d="{d}"/></defs>\n'
            f'<symbol id="sym" viewBox="0 0 320 512"><path id="insym" d="{d}"/></symbol>\n'
            '<use xlink:href="#same" x="10" y="10" transform="rotate(30)"/>\n'
            '<use xlink:href="#big" transform="translate(400,0) scale(2)"/>\n'
            '<use href="#sym" x="1000" y="0" width="640" height="1024"/>\n'
            '</svg>\n')


def test_curves_drawn_larger_by_use_are_skipped_and_kept(tmp_path):
    import re
    d = _icon_d()
    src = tmp_path / "sprite.svg"
    src.write_text(_use_doc(d), encoding="utf-8")
    with pytest.warns(UserWarning) as got:
        recs = read_curves(src, on_unsupported="skip")
    msgs = [str(w.message) for w in got]
    # was: all three read and faired in the icon's own units; the copies drawn twice as
    # large then moved up to twice --tol in the drawing
    assert {r.source["id"] for r in recs} == {"same"}
    assert any(re.search(r"id='big'.*drawn by <use>.*2 times larger", m) for m in msgs)
    assert any(re.search(r"id='insym'.*drawn by <use>.*2 times larger", m) for m in msgs)
    with pytest.raises(Exception, match="drawn by <use>"):
        read_curves(src)
    # written back: the skipped elements keep their bytes
    rec = next(r for r in recs if r.kind == "bspline")
    cp = np.array(rec.curve.control_points)
    cp[2] += (0.0, 1.0)
    out = tmp_path / "out.svg"
    write_curves(out, [rec.with_curve(rec.curve.replace(control_points=cp)) if r is rec
                       else r for r in recs], template=src)
    text = out.read_text(encoding="utf-8")
    assert f'<path id="big" d="{d}"/>' in text and f'<path id="insym" d="{d}"/>' in text
    assert f'<path id="same" d="{d}"/>' not in text


# ------------------------------------------------------------------------------------------
# SVG: a CSS transform in a style attribute (browsers draw it) makes the element unsupported
# ------------------------------------------------------------------------------------------
def test_css_transform_in_style_is_not_ignored(tmp_path):
    d = _icon_d()
    src = tmp_path / "css.svg"
    src.write_text('<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 1024 1024">\n'
                   f'<g style="fill:red; transform: scale(2)"><path id="css" d="{d}"/></g>\n'
                   f'<path id="plain" style="text-transform: none; transform: none" d="{d}"/>\n'
                   '</svg>\n', encoding="utf-8")
    # was: read in the path's own units and faired there, drawn twice as large by a browser
    with pytest.warns(UserWarning, match=r"id='css'.*CSS transform"):
        recs = read_curves(src, on_unsupported="skip")
    assert {r.source["id"] for r in recs} == {"plain"}


# ------------------------------------------------------------------------------------------
# SVG: content drawn in a coordinate system of its own (markers, bounding-box units)
# ------------------------------------------------------------------------------------------
def test_marker_and_bounding_box_content_are_unsupported(tmp_path):
    d = _icon_d()
    src = tmp_path / "units.svg"
    src.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 1024 1024">\n<defs>'
        # the icon scaled into the unit box, as a clip path in bounding-box units
        f'<clipPath id="c" clipPathUnits="objectBoundingBox" transform="scale(0.001953125)">'
        f'<path id="inbox" d="{d}"/></clipPath>\n'
        f'<clipPath id="u"><path id="inuser" d="{d}"/></clipPath>\n'
        f'<marker id="m" viewBox="0 0 320 512" markerWidth="3" markerHeight="3">'
        f'<path id="inmarker" d="{d}"/></marker></defs>\n'
        '<rect width="1024" height="1024" clip-path="url(#c)"/>\n'
        '<path id="line" d="M 0 0 L 500 500" marker-end="url(#m)"/>\n'
        '</svg>\n', encoding="utf-8")
    with pytest.warns(UserWarning) as got:
        recs = read_curves(src, on_unsupported="skip", polylines=True)
    msgs = " ".join(str(w.message) for w in got)
    # was: the clip path read in units of 1/512 of the box using it (a --tol of 0.05 became
    # 0.05 box widths), the marker in units the stroke width scales
    assert "id='inbox'" in msgs and "objectBoundingBox" in msgs
    assert "id='inmarker'" in msgs and "<marker>" in msgs
    assert {r.source["id"] for r in recs} == {"inuser", "line", None}   # None: the <rect>


def test_css_transform_in_a_style_sheet_makes_every_curve_unsupported(tmp_path):
    """A ``<style>`` sheet rule with a CSS transform: curvefair does not evaluate selectors, so
    no element's drawn size is known; every curve is left as it is (was: faired in units a
    browser draws 40 times larger). Comments, ``transform: none``, ``transform-origin`` and
    ``text-transform`` do not count."""
    import os
    import subprocess
    import sys

    d = _icon_d()
    head = '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 1024 1024">\n'
    body = (f'<path id="a" class="big" d="{d}"/>\n<path id="b" d="{d}"/>\n</svg>\n')
    harmless = tmp_path / "harmless.svg"
    harmless.write_text(head + "<style>/* .big{transform:scale(40)} */ .big{fill:red;"
                        "transform:none; transform-origin:center; text-transform:uppercase}"
                        "</style>\n" + body, encoding="utf-8")
    assert {r.source["id"] for r in read_curves(harmless)} == {"a", "b"}
    src = tmp_path / "sheet.svg"
    src.write_text(head + "<style>.big { fill: red; transform: scale(40) }</style>\n" + body,
                   encoding="utf-8")
    with pytest.warns(UserWarning, match=r"<style> sheet that sets a CSS transform"):
        with pytest.raises(Exception, match="no curves"):
            read_curves(src, on_unsupported="skip")
    out = tmp_path / "out.svg"
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    run = subprocess.run([sys.executable, "-m", "curvefair", "fair", str(src), "--tol", "0.5",
                          "-o", str(out)], capture_output=True, text=True, env=env)
    assert run.returncode == 0, run.stderr
    assert out.read_bytes() == src.read_bytes()  # nothing faired, the file as it was
