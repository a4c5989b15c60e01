"""Fonts (issue 16): a variable binary is not written as if it were static.

A variable TrueType font (``gvar``): its instances are the default outline plus the gvar deltas,
so writing a faired default outline with the deltas kept would move every instance by the
default's moves. Refused on write, naming the gvar table and the way out (fair the sources).
The font is a real one: the Amstelvar subset of the fontTools test data (tests/data/README.md).
Reading it (``curvefair check``) stays possible.
"""

from __future__ import annotations

from pathlib import Path

import pytest

pytest.importorskip("fontTools")

from click.testing import CliRunner  # noqa: E402
from fontTools.ttLib import TTFont  # noqa: E402

from curvefair import fair, read_curves, write_curves  # noqa: E402
from curvefair.cli import main  # noqa: E402
from curvefair.errors import FileFormatError  # noqa: E402

AMSTELVAR = Path(__file__).parent / "data" / "real" / "fonttools" / "Amstelvar-avar2.subset.ttf"


def test_variable_truetype_is_refused_naming_gvar(tmp_path):
    assert "gvar" in TTFont(AMSTELVAR)
    recs = read_curves(AMSTELVAR)  # the default outline reads (check, view)
    assert {r.source["glyph"] for r in recs} >= {"e", "s"}
    faired = [r.with_curve(fair(r.curve, tol=2.0, protect=r.corners).curve) for r in recs]
    out = tmp_path / "F.ttf"
    with pytest.raises(FileFormatError, match="gvar") as info:
        write_curves(out, faired, template=AMSTELVAR)
    assert "designspace" in str(info.value) and "Amstelvar" in str(info.value)
    assert not out.exists()
    res = CliRunner().invoke(main, ["fair", str(AMSTELVAR), "--tol", "2", "-o", str(out), "-q"])
    assert res.exit_code == 1 and "gvar" in res.output, res.output
    assert "Traceback" not in res.output and not out.exists()
