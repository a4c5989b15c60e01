"""A UFO written by other software (MutatorSans Bold Condensed: a UFO 3 written by norad,
the Rust UFO library, made in RoboFont; from ufoLib2's test data, tests/data/README.md),
faired by the command and checked with ufoLib2, not curvefair's reader: every file but the
faired glyphs' .glif byte for byte, the glyph sets of both layers, metrics, components,
anchors, guidelines and every point's type, smooth flag and name as they were, every point
within --tol, every smooth node no less smooth."""

from __future__ import annotations

import filecmp
import json
import math
import plistlib
import shutil
from pathlib import Path

import pytest

UFO = Path(__file__).parent / "data" / "real" / "ufoLib2" / "MutatorSansBoldCondensed.ufo"


def _turn(node, before, after) -> float:
    """The turn (degrees) of the outline at a node between its two neighbours: 0 when they
    are opposite (a smooth node), 180 minus the angle between them."""
    ux, uy = before.x - node.x, before.y - node.y
    vx, vy = after.x - node.x, after.y - node.y
    if (ux, uy) == (0, 0) or (vx, vy) == (0, 0):
        return 0.0
    return abs(math.degrees(math.atan2(ux * vy - uy * vx, -(ux * vx + uy * vy))))


def _files(root: Path) -> list[str]:
    return sorted(str(p.relative_to(root)) for p in root.rglob("*") if p.is_file())


def test_real_ufo_faired_and_read_back_with_ufolib2(tmp_path):
    ufoLib2 = pytest.importorskip("ufoLib2")
    from click.testing import CliRunner

    from curvefair.cli import main

    tol = 2.0
    src, out = tmp_path / "M.ufo", tmp_path / "out.ufo"
    shutil.copytree(UFO, src)
    res = CliRunner().invoke(main, ["fair", str(src), "-o", str(out), "--tol", str(tol),
                                    "--report", str(tmp_path / "r.json")])
    assert res.exit_code == 0, res.output
    assert _files(src) == _files(out) == _files(UFO)        # nothing lost, nothing added
    a, b = ufoLib2.Font.open(src), ufoLib2.Font.open(out)
    assert [la.name for la in a.layers] == [lb.name for lb in b.layers] == \
        ["foreground", "background"]
    worst, changed_glifs, smooth_nodes = 0.0, set(), 0
    for la in a.layers:
        lb = b.layers[la.name]
        assert sorted(la.keys()) == sorted(lb.keys())
        for name in la.keys():
            ga, gb = la[name], lb[name]
            assert (ga.width, ga.height, ga.unicodes) == (gb.width, gb.height, gb.unicodes)
            assert [(c.baseGlyph, tuple(c.transformation)) for c in ga.components] == \
                [(c.baseGlyph, tuple(c.transformation)) for c in gb.components]
            assert [(x.name, x.x, x.y) for x in ga.anchors] == \
                [(x.name, x.x, x.y) for x in gb.anchors]
            assert [(x.name, x.x, x.y, x.angle) for x in ga.guidelines] == \
                [(x.name, x.x, x.y, x.angle) for x in gb.guidelines]
            assert len(ga.contours) == len(gb.contours)
            moved = False
            for ca, cb in zip(ga.contours, gb.contours, strict=True):
                assert [(p.type, p.smooth, p.name) for p in ca] == \
                    [(p.type, p.smooth, p.name) for p in cb]
                n = len(ca)
                for i, (p, q) in enumerate(zip(ca, cb, strict=True)):
                    d = math.hypot(q.x - p.x, q.y - p.y)
                    worst, moved = max(worst, d), moved or d > 0
                    if p.smooth and p.type is not None and n > 2:
                        smooth_nodes += 1
                        ta = _turn(p, ca[i - 1], ca[(i + 1) % n])
                        tb = _turn(q, cb[i - 1], cb[(i + 1) % n])
                        assert tb <= ta + 1e-9, (la.name, name, i, ta, tb)
            if moved:
                changed_glifs.add((la.name, name))
    assert 0.5 * tol < worst <= tol
    assert smooth_nodes > 100
    # the .glif files that differ are exactly those of glyphs with a moved point; every other
    # file of the UFO (fontinfo, features, kerning, groups, lib, layer plists) byte for byte
    differ = [f for f in _files(src) if not filecmp.cmp(src / f, out / f, shallow=False)]
    layer_dirs = dict(plistlib.loads((src / "layercontents.plist").read_bytes()))
    moved_files = sorted(
        f"{layer_dirs[layer]}/"
        + plistlib.loads((src / layer_dirs[layer] / "contents.plist").read_bytes())[name]
        for layer, name in changed_glifs)
    assert len(moved_files) >= 8
    assert differ == moved_files
    rep = json.loads((tmp_path / "r.json").read_text())
    assert rep["output_check"]["max_deviation"] <= tol
    assert rep["n_failed"] == 0
    # contours the write-side never-worse guard kept as they were (integer grid, smooth nodes:
    # the S) show a deviation of 0 in the summary, not the fair's
    kept = [r for r in rep["curves"] if r["report"].get("written") == "input"]
    assert kept and res.output.count("0 (written unchanged)") == len(kept)
