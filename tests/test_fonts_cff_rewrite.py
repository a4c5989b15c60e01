"""OpenType/CFF fonts from the font hunt of session 27, faired through the command and read
back with fontTools.

- Linux Libertine RBI's ``Agrave``: a contour with on-curve points at tenths of a unit that
  is drawn back to its start. Each rewritten relative move was rounded to the charstrings'
  16.16 fixed point on its own, so the moves no longer summed to the start: the contour read
  back with one point more, and the command refused the font ("curve 2 (Agrave#2) would read
  back 597.501 from the input").
- Its ``uni1FFB``: a corner node whose handle is 3 units long; rounded to the integer grid the
  handle turned the corner's tangent by 4.4 degrees, where the fairing allows 1.
- fontTools' TestVGID ``hah-ar.4``: a near-smooth corner at the contour's first node (0.77
  degrees) that the fair made exactly smooth; the contour read back starts at the next corner
  and was measured 386 units (a line's length) from the input, so the font was refused.

On the code before (session 26) both files are refused (exit 1, nothing written).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("fontTools")
from click.testing import CliRunner  # noqa: E402
from fontTools.pens.recordingPen import RecordingPointPen  # noqa: E402
from fontTools.ttLib import TTFont  # noqa: E402

from curvefair.cli import main  # noqa: E402

FT = Path(__file__).parent / "data" / "real" / "fonttools"


def _contours(path: Path) -> dict[str, list[list[tuple[tuple[float, float], str | None]]]]:
    font = TTFont(str(path))
    gs = font.getGlyphSet()
    out = {}
    for name in font.getGlyphOrder():
        pen = RecordingPointPen()
        gs[name].drawPoints(pen)
        cs: list[list] = []
        for op, args, _kw in pen.value:
            if op == "beginPath":
                cs.append([])
            elif op == "addPoint":
                cs[-1].append((tuple(args[0]), args[1]))
        out[name] = cs
    return out


def _tangent(c, i: int, step: int) -> np.ndarray | None:
    """Direction from on-curve point ``i`` of the closed contour ``c`` to the first point on
    side ``step`` that is not on it."""
    p = np.array(c[i][0], dtype=float)
    for k in range(1, len(c)):
        q = np.array(c[(i + step * k) % len(c)][0], dtype=float)
        if np.hypot(*(q - p)) > 0:
            return q - p
    return None


def _angle(a: np.ndarray, b: np.ndarray) -> float:
    return math.degrees(math.atan2(abs(a[0] * b[1] - a[1] * b[0]), float(a @ b)))


@pytest.mark.parametrize("name, tol", [("LinLibertine_RBI.subset2.otf", 2.0),
                                       ("TestVGID-Regular.subset.otf", 1.5)])
def test_cff_font_faired_written_and_read_back(tmp_path, name, tol):
    src, out = FT / name, tmp_path / name
    res = CliRunner().invoke(main, ["fair", str(src), "-o", str(out), "--tol", str(tol)],
                             catch_exceptions=False)
    assert res.exit_code == 0, res.output
    a, b = _contours(src), _contours(out)
    assert list(a) == list(b)
    moved = 0.0
    corners = 0
    for g in a:
        assert [len(c) for c in a[g]] == [len(c) for c in b[g]], g   # nothing lost, no point added
        for c0, c1 in zip(a[g], b[g], strict=True):
            assert [t for _, t in c0] == [t for _, t in c1]
            d = max(math.hypot(p1[0] - p0[0], p1[1] - p0[1])
                    for (p0, _), (p1, _) in zip(c0, c1, strict=True))
            assert d <= tol                            # float64, exactly
            moved = max(moved, d)
            if not any(t == "curve" for _, t in c0):
                continue
            for i, (_, t) in enumerate(c0):
                if t is None:
                    continue
                t0 = [_tangent(c0, i, s) for s in (-1, 1)]
                if any(v is None for v in t0) or _angle(-t0[0], t0[1]) <= 0.5:
                    continue                           # smooth in the input
                corners += 1
                for s, v0 in zip((-1, 1), t0, strict=True):
                    v1 = _tangent(c1, i, s)
                    assert v1 is not None and _angle(v0, v1) <= 1.0 + 1e-9, (g, i, s)
    assert moved > 0.5 and corners >= 5


def test_rewritten_moves_sum_back_to_every_point():
    """The charstring of a contour with fractional coordinates drawn back to its start,
    rewritten with points off the 16.16 grid: every point reads back on the grid, each
    coordinate rounded toward the font's value (never farther than asked), and the contour
    still closes exactly."""
    from fontTools.cffLib.specializer import commandsToProgram

    from curvefair.io import fonts as F

    font = F._open_binary(FT / "LinLibertine_RBI.subset2.otf")
    cmds = F._cff_commands(font, "Agrave")
    walked = F._cff_walk(cmds)
    assert walked[0][2] and not np.array_equal(np.round(walked[0][0]), walked[0][0])
    rng = np.random.default_rng(5)
    new = [np.asarray(p) + rng.uniform(-0.7, 0.7, size=np.shape(p)) for p, _, _ in walked]
    cs = font["CFF "].cff.topDictIndex[0].CharStrings["Agrave"]
    cs.program = commandsToProgram(F._cff_rewrite(cmds, walked, new))
    cs.compile()
    cs.decompile()
    back = F._cff_walk(F._cff_commands(font, "Agrave"))
    assert [(len(p), dup) for p, _, dup in back] == [(len(p), dup) for p, _, dup in walked]
    for (p0, _, _), want, (p1, _, _) in zip(walked, new, back, strict=True):
        p0, p1 = np.asarray(p0), np.asarray(p1)
        assert np.array_equal(p1 * 65536, np.round(p1 * 65536))       # on the 16.16 grid
        assert np.all(np.abs(p1 - p0) <= np.abs(want - p0))           # toward the input
        assert np.abs(p1 - want).max() < 1 / 65536


@pytest.mark.parametrize("name", ["Lobster.subset.otf", "LinLibertine_RBI.subset2.otf"])
def test_a_font_with_no_glyph_changed_is_written_as_its_own_bytes(tmp_path, name):
    """Nothing to write back (the records as read): the font's bytes. fontTools' save rebuilt
    every table with the CFF charstrings desubroutinized (session 27 noticed it): the Lobster
    subset came back 3,800 bytes for 3,756, Libertine's 3,008 for 3,024."""
    from curvefair import read_curves, write_curves

    src = FT / name
    out = tmp_path / name
    write_curves(out, read_curves(src), template=src)
    assert out.read_bytes() == src.read_bytes()
