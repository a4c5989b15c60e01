"""Airfoil files from mdolab/pygeo (Apache-2.0, tests/data/README.md) through the command.

``naca0012.dat``: XFOIL's number layout, no name line, right-aligned columns mixing fixed
numbers and exponent style (``0.1260000E-02``). ``rae2822.dat``: a Tecplot ``ZONE="..."``
line for a name, tabs, CR LF line endings. Each is faired at 1e-4 chord by the ``fair``
command and the written file is compared with the input by plain ``str.split``: the same
lines, every text line as it was, every point within the tolerance, an unmoved row's text as
it was, and the points moved (the test is not vacuous).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from curvefair.cli import main

DATA = Path(__file__).parent / "data" / "real" / "pygeo"
TOL = 1e-4


def _is_row(line: str) -> bool:
    parts = line.split()
    try:
        return len(parts) == 2 and all(np.isfinite(float(p)) for p in parts)
    except ValueError:
        return False


@pytest.mark.parametrize("name, newline", [("naca0012.dat", "\n"), ("rae2822.dat", "\r\n")])
def test_pygeo_airfoil_written_back_in_its_own_layout(tmp_path, name, newline):
    src = tmp_path / name
    shutil.copyfile(DATA / name, src)
    out = tmp_path / ("out_" + name)
    res = CliRunner().invoke(main, ["fair", str(src), "-o", str(out), "--tol", str(TOL), "-q"])
    assert res.exit_code == 0, res.output
    a = src.read_bytes().decode().split(newline)
    b = out.read_bytes().decode().split(newline)
    assert len(a) == len(b)
    moved = 0
    for la, lb in zip(a, b, strict=True):
        if not _is_row(la):
            assert la == lb
            continue
        pa = np.array(la.split(), dtype=float)
        pb = np.array(lb.split(), dtype=float)
        d = float(np.hypot(*(pb - pa)))
        assert d <= TOL
        if d == 0:
            assert la == lb
        moved += d > 0
        assert ("\t" in la) == ("\t" in lb)
    assert moved > 100
