"""Geometry its owner protected is left as it is: DXF entities on locked or frozen layers,
3dm objects that are locked or hidden or on a locked or hidden layer (CAD tools do not let a
user select or edit them). They are not read, a warning names each, and the file is written
back with them bit for bit, checked with ezdxf and rhino3dm on real files (tests/data/README.md).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from curvefair import fair, read_curves, write_curves

REAL = Path(__file__).parent / "data" / "real"


def _fair_all(src, out, tol):
    with pytest.warns(UserWarning, match="as it is") as rec:
        recs = read_curves(src, on_unsupported="skip")
    faired = [r.with_curve(fair(r.curve, tol=tol).curve) for r in recs]
    write_curves(out, faired, template=src, reference=recs, tol=tol)
    return recs, [str(w.message) for w in rec]


def test_dxf_locked_and_frozen_layers_are_left_as_they_are(tmp_path):
    ezdxf = pytest.importorskip("ezdxf")
    real = REAL / "trimesh" / "spline.DXF"  # six SPLINEs on layer 0, four of them read
    with pytest.warns(UserWarning, match="unsupported"):
        readable = [r.source["handle"] for r in read_curves(real, on_unsupported="skip")]
    doc = ezdxf.readfile(real)
    doc.layers.add("kept").lock()
    doc.layers.add("cold").freeze()
    splines = [e for e in doc.modelspace() if e.dxftype() == "SPLINE"]
    by_handle = {e.dxf.handle: e for e in splines}
    by_handle[readable[0]].dxf.layer = "kept"
    by_handle[readable[1]].dxf.layer = "cold"
    protected = set(readable[:2])
    src, out = tmp_path / "in.dxf", tmp_path / "out.dxf"
    doc.saveas(src)
    recs, msgs = _fair_all(src, out, 0.5)
    assert {r.source["handle"] for r in recs} == set(readable) - protected
    assert sum("'kept' is locked" in m for m in msgs) == 1
    assert sum("'cold' is frozen" in m for m in msgs) == 1
    before = {e.dxf.handle: np.array(e.control_points) for e in splines}
    after = {e.dxf.handle: np.array(e.control_points)
             for e in ezdxf.readfile(out).modelspace() if e.dxftype() == "SPLINE"}
    assert set(after) == set(before)
    for h in protected:
        assert np.array_equal(after[h], before[h])  # bit for bit
    moved = [h for h in after if h not in protected and not np.array_equal(after[h], before[h])]
    assert moved  # the others were faired


def test_3dm_locked_and_hidden_objects_are_left_as_they_are(tmp_path):
    r3 = pytest.importorskip("rhino3dm")
    base = r3.File3dm.Read(str(REAL / "opennurbs" / "v1_three_curves.3dm"))
    # object 1 is the NurbsCurve curvefair reads (object 0 is rational: not read)
    wiggle = base.Objects[1].Geometry
    assert isinstance(wiggle, r3.NurbsCurve)
    m = r3.File3dm()
    free = m.Layers.AddLayer("free", (0, 0, 0, 255))
    hid = m.Layers.AddLayer("hid", (0, 0, 0, 255))
    shut = m.Layers.AddLayer("shut", (0, 0, 0, 255))
    m.Layers.FindIndex(hid).Visible = False
    m.Layers.FindIndex(shut).Locked = True
    kinds = [("locked", free, r3.ObjectMode.Locked), ("hidden", free, r3.ObjectMode.Hidden),
             ("on hidden layer", hid, None), ("on locked layer", shut, None),
             ("free", free, None)]
    for _, layer, mode in kinds:
        a = r3.ObjectAttributes()
        a.LayerIndex = layer
        if mode is not None:
            a.Mode = mode
        m.Objects.Add(wiggle, a)
    src, out = tmp_path / "in.3dm", tmp_path / "out.3dm"
    m.Write(str(src), 7)
    recs, msgs = _fair_all(src, out, 0.05)
    assert len(recs) == 1 and len(msgs) == 4
    back = r3.File3dm.Read(str(out))
    cps = [np.array([[p.X, p.Y, p.Z] for p in o.Geometry.Points]) for o in back.Objects]
    orig = np.array([[p.X, p.Y, p.Z] for p in wiggle.Points])
    assert len(cps) == 5
    for k in range(4):
        assert np.array_equal(cps[k], orig), kinds[k][0]  # bit for bit
    assert not np.array_equal(cps[4], orig)  # the free one was faired


def test_cli_file_with_only_protected_curves_is_copied(tmp_path):
    """Every curve on a locked layer: nothing to fair; the command copies the file and exits
    0 (it said 'no curves in the dxf file' and exited 1)."""
    import os
    import subprocess
    import sys

    ezdxf = pytest.importorskip("ezdxf")
    doc = ezdxf.readfile(REAL / "trimesh" / "spline.DXF")
    doc.layers.get("0").lock()
    src, out = tmp_path / "in.dxf", tmp_path / "out.dxf"
    doc.saveas(src)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    run = subprocess.run([sys.executable, "-m", "curvefair", "fair", str(src), "--tol", "0.5",
                          "-o", str(out)], capture_output=True, text=True, env=env)
    assert run.returncode == 0, run.stderr
    assert "is locked; left as it is" in run.stderr
    assert out.read_bytes() == src.read_bytes()
