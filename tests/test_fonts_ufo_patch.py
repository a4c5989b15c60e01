"""UFO write-back changes a ``.glif`` file by the moved numbers only (session 28).

fontTools' glifLib rewrote each changed glyph's file in its own layout: quoting, indentation,
element and lib key order, ``1`` as ``1.0``, and an empty ``<note>`` dropped (ufoLib2 read
``''`` before and ``None`` after) -- 4,437 files in a hunt through glyphsLib's, ufoLib2's and
fontTools' UFOs. A type designer's UFO under version control then shows whole files changed
for a few moved points. Now the file's own text is kept and only the ``x``/``y`` attributes of
the moved points are replaced (read back with glifLib and compared; else the old way).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

ufoLib2 = pytest.importorskip("ufoLib2")
from click.testing import CliRunner  # noqa: E402

from curvefair.cli import main  # noqa: E402

REAL = Path(__file__).parent / "data" / "real"


def _coordinates_removed(line: bytes) -> bytes:
    return re.sub(rb"""\s[xy]\s*=\s*(["'])[^"']*\1""", b"", line)


@pytest.mark.parametrize("src", [
    REAL / "glyphsLib" / "spectral-regular.subset.ufo",  # GLIF 1: anchors as contours, a note
    REAL / "ufoLib2" / "MutatorSansBoldCondensed.ufo",   # GLIF 2
], ids=["spectral-glif1", "mutatorsans-glif2"])
def test_changed_glif_files_differ_by_the_moved_coordinates_only(tmp_path, src):
    out = tmp_path / src.name
    res = CliRunner().invoke(main, ["fair", str(src), "-o", str(out), "--tol", "2", "-q"],
                             catch_exceptions=False)
    assert res.exit_code == 0, res.output
    changed = 0
    for a in sorted((src / "glyphs").glob("*.glif")):
        b = out / "glyphs" / a.name
        la, lb = a.read_bytes().splitlines(), b.read_bytes().splitlines()
        if la == lb:
            continue
        changed += 1
        assert len(la) == len(lb), a.name
        for x, y in zip(la, lb, strict=True):
            if x != y:
                assert x.lstrip().startswith(b"<point") and \
                    _coordinates_removed(x) == _coordinates_removed(y), (a.name, x, y)
    assert changed >= 1
    # what ufoLib2 reads: the same glyphs, anchors, notes, every point within tol
    f0, f1 = ufoLib2.Font.open(src), ufoLib2.Font.open(out)
    assert sorted(f0.keys()) == sorted(f1.keys())
    for name in f0.keys():
        g0, g1 = f0[name], f1[name]
        assert g0.anchors == g1.anchors and g0.note == g1.note and g0.width == g1.width
        for c0, c1 in zip(g0.contours, g1.contours, strict=True):
            d = np.hypot([p.x - q.x for p, q in zip(c0, c1, strict=True)],
                         [p.y - q.y for p, q in zip(c0, c1, strict=True)])
            assert d.max() <= 2.0
            assert [(p.type, p.smooth) for p in c0] == [(p.type, p.smooth) for p in c1]
