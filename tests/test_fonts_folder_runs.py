"""UFO fonts through the command, alone and in folder runs (session 28).

- A font whose contours are all straight lines has nothing to fair: the command writes it back
  unchanged with a note, exit 0, as a drawing of polygons. It used to stop with "no curves in
  the ufo file", exit 1 -- 33 of the 145 font sources of the font-source hunt. The file is
  fontTools' own test UFO (three straight contours).
- A folder run failed on every UFO ("Is a directory": the run hashed the input as a file), and
  ``--resume`` never found a UFO output up to date.
"""

from __future__ import annotations

import filecmp
import json
import shutil
from pathlib import Path

import pytest

pytest.importorskip("ufoLib2")
from click.testing import CliRunner  # noqa: E402

from curvefair import read_curves  # noqa: E402
from curvefair.errors import FileFormatError  # noqa: E402

SRC = Path(__file__).parent / "data" / "real" / "fonttools" / "SparseMasters-Medium.ufo"


def _run(*args: object):
    from curvefair.cli import main

    return CliRunner().invoke(main, [str(a) for a in args], catch_exceptions=False)


def _same_tree(a: Path, b: Path) -> bool:
    cmp = filecmp.dircmp(a, b)
    if cmp.left_only or cmp.right_only or cmp.funny_files:
        return False
    _, mismatch, errors = filecmp.cmpfiles(a, b, cmp.common_files, shallow=False)
    return not mismatch and not errors and all(_same_tree(a / d, b / d) for d in cmp.common_dirs)


def test_a_font_of_straight_contours_is_written_back_unchanged(tmp_path):
    with pytest.raises(FileFormatError, match=r"no curves in the ufo file: its 3 contours are "
                                              r"\(straight lines only\) left as drawn; a "
                                              r"contour of straight lines has no curve") as exc:
        read_curves(SRC)
    assert exc.value.n_drawn == 3
    out = tmp_path / "out.ufo"
    res = _run("fair", SRC, "-o", out, "--tol", "2", "--report", tmp_path / "r.json")
    assert res.exit_code == 0, res.output
    assert "nothing to fair (3 contours of straight lines only)" in res.output
    assert "--polylines" not in res.output            # no option would read them
    assert out.is_dir() and _same_tree(SRC, out)
    rep = json.loads((tmp_path / "r.json").read_text())
    assert rep["n_curves"] == 0 and rep["n_drawn_shapes"] == 3 and rep["output_written"]


def test_a_folder_run_of_ufo_fonts(tmp_path):
    import ufoLib2

    mutator = SRC.parent.parent / "ufoLib2" / "MutatorSansBoldCondensed.ufo"
    inp = tmp_path / "in"
    inp.mkdir()
    shutil.copytree(SRC, inp / SRC.name)
    shutil.copytree(mutator, inp / mutator.name)
    res = _run("fair", inp, "-o", tmp_path / "out", "--tol", "2", "--jobs", "1", "-q")
    assert res.exit_code == 0, res.output
    assert _same_tree(SRC, tmp_path / "out" / SRC.name)        # nothing to fair: copied
    f0 = ufoLib2.Font.open(mutator)
    f1 = ufoLib2.Font.open(tmp_path / "out" / mutator.name)
    moved = [abs(p.x - q.x) + abs(p.y - q.y) for g in f0.keys()
             for c0, c1 in zip(f0[g].contours, f1[g].contours, strict=True)
             for p, q in zip(c0, c1, strict=True)]
    assert max(moved) > 0
    run = json.loads((tmp_path / "out" / ".curvefair" / "run.json").read_text())
    assert run["n_failed"] == 0
    # --resume: both outputs found up to date (input, options and output hashes match)
    res = _run("fair", inp, "-o", tmp_path / "out", "--tol", "2", "--jobs", "1", "--resume")
    assert res.exit_code == 0 and "2 up to date" in res.output, res.output
