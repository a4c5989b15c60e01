"""OCC131-6.igs (OCCT test data): the free edges OCC reads come from a curve on a surface
(entity 142, preference 1: the 2-D curve on the surface), not from any 126 entity, so a faired
curve is refused, and the refusal names the entities. Switching the 142 to its model-space
curve (preference 2), the way a faired 3-D curve would have to be attached, changes how OCC
reads every edge of it: checked by patching the file's text and re-reading it with OCC."""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np
import pytest

from curvefair import FileFormatError, read_curves, write_curves

SRC = Path(__file__).parent / "data/real/occt/OCC131-6.igs"


def _read(p):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return read_curves(p, on_unsupported="skip")


def test_refusal_names_the_curve_on_surface(tmp_path):
    pytest.importorskip("OCP")
    recs = _read(SRC)
    cp = np.array(recs[0].curve.control_points)
    cp[len(cp) // 2] += 0.01
    out = tmp_path / "o.igs"
    with pytest.raises(FileFormatError) as ei:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            write_curves(out, [recs[0].with_curve(recs[0].curve.replace(control_points=cp))]
                         + recs[1:], template=SRC)
    msg = str(ei.value)
    # the file's own directory entries: DE 1 is "142,0,3,5,17,1;" (surface 3, 2-D curve 5,
    # model-space curve 17, preference 1)
    p1 = next(ln for ln in SRC.read_text().splitlines() if ln[72:73] == "P"
              and int(ln[65:72]) == 1)
    assert p1.startswith("142,0,3,5,17,1;")
    assert "DE 1: the 2-D curve DE 5 on surface DE 3, preference 1" in msg
    assert "model-space curve DE 17 not used" in msg
    assert not out.exists()


def test_model_space_preference_changes_every_edge(tmp_path):
    pytest.importorskip("OCP")
    lines = SRC.read_text().split("\n")
    out = []
    for ln in lines:
        if ln[72:73] == "P" and int(ln[65:72]) == 1:
            ln = re.sub(r"^142,0,3,5,17,1;", "142,0,3,5,17,2;", ln[:64]).ljust(64) + ln[64:]
        out.append(ln)
    p = tmp_path / "pref2.igs"
    p.write_text("\n".join(out))
    a, b = _read(SRC), _read(p)
    assert len(a) == 3
    # OCC now builds the 142's edges from the model-space pieces: other curves, other count
    assert len(b) != len(a)
    assert sorted((r.curve.degree, r.curve.n_ctrl) for r in a) != \
        sorted((r.curve.degree, r.curve.n_ctrl) for r in b)
