"""OCC131-6.igs (OCCT test data): the free edges OCC reads come from a curve on a surface
(entity 142, preference 1: the 2-D curve on the surface), not from any 126 entity, so they are
unsupported entities: skipped with a warning naming the entities and why (kept untouched),
refused with ``on_unsupported="raise"`` / ``--strict``. Switching the 142 to its model-space
curve (preference 2), the way a faired 3-D curve would have to be attached, changes how OCC
reads every edge of it: checked by patching the file's text and re-reading it with OCC."""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import pytest

from curvefair import FileFormatError, read_curves

SRC = Path(__file__).parent / "data/real/occt/OCC131-6.igs"


def _read(p):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return read_curves(p, on_unsupported="skip")


def test_curves_bound_to_a_surface_are_skipped_naming_why(tmp_path):
    pytest.importorskip("OCP")
    from click.testing import CliRunner

    from curvefair.cli import main

    # the file's own directory entries: DE 1 is "142,0,3,5,17,1;" (surface 3, 2-D curve 5,
    # model-space curve 17, preference 1)
    p1 = next(ln for ln in SRC.read_text().splitlines() if ln[72:73] == "P"
              and int(ln[65:72]) == 1)
    assert p1.startswith("142,0,3,5,17,1;")
    with pytest.raises(FileFormatError) as ei:
        read_curves(SRC)
    msg = str(ei.value)
    assert "curve bound to a surface" in msg and "would leave its surface" in msg
    assert "DE 1: the 2-D curve DE 5 on surface DE 3, preference 1" in msg
    assert "model-space curve DE 17 not used" in msg
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        with pytest.raises(FileFormatError, match="no curves"):
            read_curves(SRC, on_unsupported="skip")
    skipped = [str(x.message) for x in w if "bound to a surface" in str(x.message)]
    assert len(skipped) == 3 and all("DE 1: the 2-D curve DE 5" in m and "kept untouched" in m
                                     for m in skipped)
    # the CLI: nothing it can fair in this file; it says so and why, the run does not fail,
    # and the file is written back unchanged; --strict refuses it
    out = tmp_path / "o.igs"
    res = CliRunner().invoke(main, ["fair", str(SRC), "-o", str(out), "--tol", "0.01"])
    assert res.exit_code == 0, res.output
    assert "nothing to fair" in res.stderr and "unsupported entities skipped" in res.stderr
    assert "curve bound to a surface" in res.stderr and "Traceback" not in res.output
    assert out.read_bytes() == SRC.read_bytes()
    res = CliRunner().invoke(main, ["fair", str(SRC), "-o", str(tmp_path / "s.igs"),
                                    "--tol", "0.01", "--strict"])
    assert res.exit_code == 1 and "curve bound to a surface" in res.stderr
    assert "Traceback" not in res.output and not (tmp_path / "s.igs").exists()


def _read_as_occ(p, monkeypatch):
    """Every free B-spline edge as OCC reads it (the surface-bound check switched off)."""
    import curvefair.io.occ as occ

    with monkeypatch.context() as m:
        m.setattr(occ, "_iges_surface_bound", lambda *a, **k: "")
        return _read(p)


def test_model_space_preference_changes_every_edge(tmp_path, monkeypatch):
    pytest.importorskip("OCP")
    lines = SRC.read_text().split("\n")
    out = []
    for ln in lines:
        if ln[72:73] == "P" and int(ln[65:72]) == 1:
            ln = re.sub(r"^142,0,3,5,17,1;", "142,0,3,5,17,2;", ln[:64]).ljust(64) + ln[64:]
        out.append(ln)
    p = tmp_path / "pref2.igs"
    p.write_text("\n".join(out))
    a, b = _read_as_occ(SRC, monkeypatch), _read_as_occ(p, monkeypatch)
    assert len(a) == 3
    # OCC now builds the 142's edges from the model-space pieces: other curves, other count
    assert len(b) != len(a)
    assert sorted((r.curve.degree, r.curve.n_ctrl) for r in a) != \
        sorted((r.curve.degree, r.curve.n_ctrl) for r in b)
