"""Point CSV files written by other software (tests/data/real/hexed, see tests/data/README.md):
read as numpy reads them, faired, written back into their own layout, and checked as a user
would check them: the written file re-read with numpy, every row within the tolerance of the
row it replaces (``|moved - original| <= tol`` per point, in float64), no row lost, the number
style of the file kept."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import curvefair as cf

DATA = Path(__file__).parent / "data" / "real" / "hexed"
# (file, number pattern of a data row's texts, separator numpy reads)
FILES = [
    # numpy.savetxt output, 18-digit mantissas and exponents, ", " between columns
    ("naca0012_geom.csv", r"-?\d\.\d{18}e[+-]\d\d", ","),
    # five decimals, explicit "+" on positive y, a "-0.00000"
    ("rae2822_raw.csv", r"[+-]?\d+\.\d+(?:e-?\d+)?", ","),
]


@pytest.mark.parametrize("name, pattern, sep", FILES)
def test_real_csv_read_fair_write_reread(tmp_path, name, pattern, sep):
    src = DATA / name
    original = np.loadtxt(src, delimiter=sep)
    records = cf.read_curves(src)
    # what curvefair read is what numpy reads, bit for bit
    lay = records[0].source["layout"]
    assert lay.values.tobytes() == original.tobytes()
    tol = 1e-4
    faired = [r.with_curve(cf.fair(r.curve, "poliakoff", tol=tol,
                                   protect=sorted(r.corners)).curve) for r in records]
    out = tmp_path / name
    cf.write_curves(out, faired, template=src, reference=records, tol=tol)
    back = np.loadtxt(out, delimiter=sep)
    assert back.shape == original.shape                      # no row lost or added
    moved = np.linalg.norm(back - original, axis=1)
    assert moved.max() <= tol                                # in the file as numpy reads it
    assert moved.max() > 0.1 * tol                           # and the fairing did move rows
    lines_in = src.read_text().splitlines()
    lines_out = out.read_text().splitlines()
    same = np.all(back == original, axis=1)
    for i in np.flatnonzero(same):                           # an unmoved row keeps its text
        assert lines_out[i] == lines_in[i]
    row = re.compile(rf"{pattern}{re.escape(sep)}\s*{pattern}")
    assert all(row.fullmatch(ln) for ln in lines_out)        # the file's number style
