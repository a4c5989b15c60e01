"""Glyphs sources written back losslessly: the faired nodes' coordinates are patched into the
source's own text, so the data glyphsLib does not round-trip survives (format 3: fontType,
kernTop, background imagePaths, an instance's visible; format 2: an ``Axes`` custom parameter,
numbers such as ``146.0`` or ``329.123456789``).

Checked independently of curvefair's tokenizer: openstep_plist's parse of the output equals
that of the input once the coordinates of the faired paths are masked, the output's lines are
the input's except for the two numbers of node lines, glyphsLib reads every node back within
tol of the input node, and no warning about glyphsLib's round trip is given. Real files from
glyphsLib's tests (tests/data/README.md).
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np
import pytest

glyphsLib = pytest.importorskip("glyphsLib")
openstep_plist = pytest.importorskip("openstep_plist")

from curvefair import fair, read_curves, write_curves  # noqa: E402

DATA = Path(__file__).parent / "data" / "real" / "glyphsLib"
# (file, format, tol): each loses data in glyphsLib's own load and save
CASES = [("GlyphsFileFormatv3", 3, 5.0), ("CornerComponents", 3, 5.0),
         ("BracketTestFont", 2, 5.0), ("IntegerFloat", 2, 1.0)]
ROUND_TRIP = "glyphsLib does not write this source back"


def _glyphslib_loses(src: Path, tmp: Path) -> bool:
    rt = tmp / "roundtrip.glyphs"
    glyphsLib.GSFont(str(src)).save(str(rt))
    return rt.read_bytes() != src.read_bytes()


def _paths(tree, fmt):
    """{(glyph, layerId, path index): nodes list} of a parsed source (paths only)."""
    out = {}
    for g in tree["glyphs"]:
        for layer in g.get("layers", []):
            shapes = layer.get("shapes", []) if fmt == 3 else layer.get("paths", [])
            paths = [s for s in shapes if "ref" not in s] if fmt == 3 else shapes
            for i, p in enumerate(paths):
                out[(str(g["glyphname"]), layer["layerId"], i)] = p["nodes"]
    return out


def _xy(node, fmt):
    if fmt == 3:
        return float(node[0]), float(node[1])
    x, y = node.split(" ")[:2]
    return float(x), float(y)


def _mask(tree, fmt, keys):
    """The tree with the coordinates of the nodes of the paths ``keys`` replaced by None."""
    for g in tree["glyphs"]:
        for layer in g.get("layers", []):
            shapes = layer.get("shapes", []) if fmt == 3 else layer.get("paths", [])
            paths = [s for s in shapes if "ref" not in s] if fmt == 3 else shapes
            for i, p in enumerate(paths):
                if (str(g["glyphname"]), layer["layerId"], i) not in keys:
                    continue
                if fmt == 3:
                    p["nodes"] = [[None, None, *n[2:]] for n in p["nodes"]]
                else:
                    p["nodes"] = ["X Y " + n.split(" ", 2)[2] for n in p["nodes"]]
    return tree


def _fair_and_write(src: Path, out: Path, tol: float):
    recs = read_curves(src)
    faired = [r.with_curve(fair(r.curve, tol=tol, protect=r.corners).curve) for r in recs]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        write_curves(out, faired, template=src)
    return recs, [str(w.message) for w in caught if issubclass(w.category, UserWarning)]


@pytest.mark.parametrize("name,fmt,tol", CASES)
def test_glyphs_faired_output_is_the_source_but_the_faired_coordinates(tmp_path, name, fmt,
                                                                       tol):
    src = DATA / f"{name}.glyphs"
    assert _glyphslib_loses(src, tmp_path)  # the case: glyphsLib's save alone loses data
    out = tmp_path / f"{name}.out.glyphs"
    recs, warned = _fair_and_write(src, out, tol)
    # (c) no warning about glyphsLib's round trip: nothing is lost
    assert not [w for w in warned if ROUND_TRIP in w], warned
    a = openstep_plist.loads(src.read_text("utf-8"), use_numbers=True)
    b = openstep_plist.loads(out.read_text("utf-8"), use_numbers=True)
    assert a.get(".formatVersion", 2) == fmt
    pa, pb = _paths(a, fmt), _paths(b, fmt)
    assert pa.keys() == pb.keys()
    moved = {k for k in pa if [_xy(n, fmt) for n in pa[k]] != [_xy(n, fmt) for n in pb[k]]}
    assert moved  # some curves changed
    # (a) everything else parses equal: masking only the moved paths' coordinates
    assert _mask(a, fmt, moved) == _mask(b, fmt, moved)
    # (b) glyphsLib reads the faired nodes back within tol of the input's nodes
    fa, fb = glyphsLib.GSFont(str(src)), glyphsLib.GSFont(str(out))
    worst = 0.0
    for g, layer_id, i in moved:
        na = list(fa.glyphs[g].layers[layer_id].paths)[i].nodes
        nb = list(fb.glyphs[g].layers[layer_id].paths)[i].nodes
        assert [(n.type, n.smooth) for n in na] == [(n.type, n.smooth) for n in nb]
        pa_ = np.array([(n.position.x, n.position.y) for n in na], float)
        pb_ = np.array([(n.position.x, n.position.y) for n in nb], float)
        d = float(np.linalg.norm(pb_ - pa_, axis=1).max())
        assert d <= tol, (g, layer_id, i, d)
        worst = max(worst, d)
    assert worst > 0
    # the moved paths are those of records whose curve was faired
    assert len(moved) <= len(recs)


def _node_line(fmt):
    return (re.compile(rb"^\((-?[\d.e]+),(-?[\d.e]+)(,.*)$") if fmt == 3
            else re.compile(rb'^"(-?[\d.e]+) (-?[\d.e]+)( .*)$'))


@pytest.mark.parametrize("name,fmt,tol", CASES)
def test_glyphs_faired_output_bytes_outside_node_numbers_are_the_source(tmp_path, name, fmt,
                                                                        tol):
    src = DATA / f"{name}.glyphs"
    out = tmp_path / f"{name}.out.glyphs"
    _fair_and_write(src, out, tol)
    a, b = src.read_bytes().split(b"\n"), out.read_bytes().split(b"\n")
    assert len(a) == len(b)
    pat = _node_line(fmt)
    changed = 0
    for la, lb in zip(a, b, strict=True):
        if la == lb:
            continue
        ma, mb = pat.match(la), pat.match(lb)
        assert ma and mb, (la, lb)  # only node lines differ
        assert ma.group(3) == mb.group(3), (la, lb)  # type, smooth, userData, comma kept
        changed += 1
    assert changed
    if name == "IntegerFloat":
        # glyphsLib would write "146" and "329.12346 253.98765": unmoved numbers keep their text
        text = out.read_text("utf-8")
        assert '"146.0 178 LINE"' in text and '"332.1 180 LINE"' in text


def test_glyphs_source_with_crlf_line_ends_keeps_them(tmp_path):
    # the text is patched as bytes decoded, not re-read with universal newlines
    src = tmp_path / "IntegerFloat.glyphs"
    src.write_bytes((DATA / "IntegerFloat.glyphs").read_bytes().replace(b"\n", b"\r\n"))
    out = tmp_path / "out.glyphs"
    _, warned = _fair_and_write(src, out, 1.0)
    assert not [w for w in warned if ROUND_TRIP in w], warned
    a, b = src.read_bytes().split(b"\r\n"), out.read_bytes().split(b"\r\n")
    assert len(a) == len(b) and b"\n" not in b"".join(b)
    assert sum(x != y for x, y in zip(a, b, strict=True)) == 2  # the two off-curve nodes


def test_glyphs_cli_writes_the_source_with_the_faired_nodes_only(tmp_path):
    from click.testing import CliRunner

    from curvefair.cli import main

    src = DATA / "GlyphsFileFormatv3.glyphs"
    out = tmp_path / "out.glyphs"
    res = CliRunner().invoke(main, ["fair", str(src), "-o", str(out), "--tol", "5"])
    assert res.exit_code == 0, res.output
    assert ROUND_TRIP not in res.output
    text = out.read_text("utf-8")
    # what glyphsLib's save drops is still there
    for kept in ("kernTop = A;", "imagePath = files/Smily.png;", "visible = 1;",
                 "sortNameKeep = YSmily;", "fontType = variable;"):
        assert kept in src.read_text("utf-8") and kept in text, kept
    assert out.read_bytes() != src.read_bytes()


def test_glyphs_text_patch_tokenizer_with_comments_and_escaped_strings():
    """Comments and strings holding quotes, parentheses and 'nodes = (' before the nodes: the
    patch moves exactly the asked-for numbers."""
    from curvefair.io._glyphs_text import patch_nodes

    text = (DATA / "GlyphsFileFormatv3.glyphs").read_text("utf-8")
    tree = openstep_plist.loads(text, use_numbers=True)
    g = next(g for g in tree["glyphs"] if g["glyphname"] == "A")
    layer = g["layers"][0]
    k = text.index("glyphname = A;")
    tricky = ('/* a comment: nodes = ((1,2,l)); "not a string */\n'
              'testNote = "a \\"quoted\\" note ( nodes = ((1,2,l), \\\\";\n// nodes = (\n')
    text2 = text[:k] + tricky + text[k:]
    tree2 = openstep_plist.loads(text2, use_numbers=True)
    assert tree2 != tree and g.get("testNote") is None  # the note is read
    paths = [s for s in layer["shapes"] if "ref" not in s]
    old = [(float(n[0]), float(n[1])) for n in paths[0]["nodes"]]
    new = [(x + 1.5, y - 0.25) for x, y in old]
    out = patch_nodes(text2, 3, [("A", layer["layerId"], 0, old, new)])
    back = openstep_plist.loads(out, use_numbers=True)
    g2 = next(g for g in back["glyphs"] if g["glyphname"] == "A")
    got = [(float(n[0]), float(n[1])) for n in
           [s for s in g2["layers"][0]["shapes"] if "ref" not in s][0]["nodes"]]
    assert got == new
    assert out.startswith(text2[:k + len(tricky)])


def test_glyphs_text_patch_refuses_what_it_cannot_locate():
    from curvefair.io._glyphs_text import NotPatchable, patch_nodes

    text = (DATA / "BracketTestFont.glyphs").read_text("utf-8")
    tree = openstep_plist.loads(text, use_numbers=True)
    g = tree["glyphs"][0]
    layer = g["layers"][0]
    old = [tuple(map(float, n.split(" ")[:2])) for n in layer["paths"][0]["nodes"]]
    new = [(x + 1, y) for x, y in old]
    with pytest.raises(NotPatchable, match="found 0 times"):
        patch_nodes(text, 2, [("nosuchglyph", layer["layerId"], 0, old, new)])
    with pytest.raises(NotPatchable, match="not the node glyphsLib read"):
        patch_nodes(text, 2, [(str(g["glyphname"]), layer["layerId"], 0, new, new)])
    # the same glyph twice: not located once
    one = ("{glyphname = a; layers = ({layerId = m; shapes = ({closed = 1; nodes = ("
           "(1,2,l),(3,4,o),(5,6,o),(7,8,c));});});}")
    dup = "{\n.formatVersion = 3;\nglyphs = (\n" + one + ",\n" + one + "\n);\n}\n"
    pts = [(1, 2), (3, 4), (5, 6), (7, 8)]
    with pytest.raises(NotPatchable, match="found 2 times"):
        patch_nodes(dup, 3, [("a", "m", 0, pts, pts)])
    single = "{\n.formatVersion = 3;\nglyphs = (\n" + one + "\n);\n}\n"
    assert patch_nodes(single, 3, [("a", "m", 0, pts, [(1, 2), (3.5, 4), (5, 6), (7, 8)])]) \
        == single.replace("(3,4,o)", "(3.5,4,o)")


def test_glyphs_source_not_patchable_falls_back_to_glyphslib_with_a_warning(tmp_path,
                                                                          monkeypatch):
    # a source whose text cannot be patched is written by glyphsLib, and what its round trip
    # changes is named (first line)
    from click.testing import CliRunner

    from curvefair.cli import main
    from curvefair.io import _glyphs_text

    def refuse(*a, **k):
        raise _glyphs_text.NotPatchable("refused for the test")

    monkeypatch.setattr(_glyphs_text, "patch_nodes", refuse)
    src = DATA / "GlyphsFileFormatv3.glyphs"
    out = tmp_path / "out.glyphs"
    res = CliRunner().invoke(main, ["fair", str(src), "-o", str(out), "--tol", "5"])
    assert res.exit_code == 0, res.output
    assert ROUND_TRIP in res.output and "refused for the test" in res.output
    assert "line 45" in res.output and out.read_bytes() != src.read_bytes()
