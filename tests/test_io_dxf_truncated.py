"""Truncated and odd DXF files (issue 12): only curvefair errors, saying that the file is cut
short, for ASCII (R12 .. R2013) and binary DXF files written by other software; a closed
polyline of 2 distinct vertices is an unsupported entity, not a whole-file error."""

from __future__ import annotations

import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("ezdxf")
import ezdxf  # noqa: E402

from curvefair import FileFormatError  # noqa: E402
from curvefair.errors import CurvefairError  # noqa: E402
from curvefair.io import read_curves  # noqa: E402

DATA = Path(__file__).parent / "data"
FILES = [
    DATA / "real/dxf-parser/splines.dxf",           # no $ACADVER (R12 to ezdxf), SPLINEs
    DATA / "real/trimesh/spline.DXF",               # AutoCAD, closed SPLINE
    DATA / "real/p3dtest/profileHullFront_v2.dxf",
    DATA / "real/ezdxf/ASCII_R12.dxf",              # R12 (AC1009)
    DATA / "real/ezdxf/POLI-ALL210_12.DXF",         # R12 POLYLINEs (2D, 3D, closed, bulges)
    DATA / "real/ezdxf/bin_dxf_r2000.dxf",          # binary DXF, AC1015
]


def _cuts(data: bytes, k: int = 12) -> list[int]:
    """Cut points: evenly spread, at line ends near the end, and the last bytes."""
    n = len(data)
    nl = [i for i, b in enumerate(data) if b == 10]
    cuts = set(np.linspace(1, n - 1, k).astype(int).tolist())
    cuts.update(nl[-6:])
    cuts.update(i + 1 for i in nl[-6:-1])
    cuts.update(range(max(1, n - 6), n))
    return sorted(c for c in cuts if 0 < c < n)


def _ezdxf_reads(path: Path) -> bool:
    try:
        ezdxf.readfile(str(path))
    except Exception:  # noqa: BLE001 - the reference: does the original library read it?
        return False
    return True


@pytest.mark.parametrize("src", FILES, ids=lambda p: p.name)
def test_truncated_file_gives_only_curvefair_errors(src, tmp_path):
    data = src.read_bytes()
    path = tmp_path / ("cut" + src.suffix)
    n_trunc = 0
    for c in _cuts(data):
        path.write_bytes(data[:c])
        for mode in ("raise", "skip"):
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    read_curves(path, on_unsupported=mode)
            except CurvefairError as exc:
                msg = str(exc)
                assert str(path) in msg
                msg = msg.replace(str(path), "FILE")
                assert "StopIteration: )" not in msg and "()" not in msg
                if "truncated" in msg:
                    n_trunc += 1
                    assert not _ezdxf_reads(path), (c, msg)  # only files ezdxf cannot read either
    # the cuts in the middle of the file are reported as truncations
    assert n_trunc >= 8


def test_truncation_message_names_line_and_binary(tmp_path):
    src = (DATA / "real/dxf-parser/splines.dxf").read_bytes()
    p = tmp_path / "a.dxf"
    p.write_bytes(src[:1341])
    with pytest.raises(FileFormatError) as ei:
        read_curves(p)
    n_lines = src[:1341].count(b"\n") + (not src[:1341].endswith(b"\n"))
    assert f"ends at line {n_lines} without the closing '0 / EOF' group" in str(ei.value)
    b = (DATA / "real/ezdxf/bin_dxf_r2000.dxf").read_bytes()
    assert b.startswith(b"AutoCAD Binary DXF")
    p.write_bytes(b[:3000])
    with pytest.raises(FileFormatError, match="binary DXF file ends at byte 3000"):
        read_curves(p)
    # the case: cut after the first group, ezdxf raises a bare StopIteration
    p.write_bytes(src[:11])
    with pytest.raises(FileFormatError, match="looks truncated"):
        read_curves(p)
    p.write_bytes(b"")
    with pytest.raises(FileFormatError, match="the file is empty"):
        read_curves(p)


def test_whole_binary_and_r12_files_read(tmp_path):
    # the untruncated files: no truncation claim (ezdxf reads them)
    for f in ("bin_dxf_r2000.dxf", "ASCII_R12.dxf"):
        with pytest.raises(FileFormatError, match="no curves") as ei:
            read_curves(DATA / "real/ezdxf" / f)
        assert "truncated" not in str(ei.value)


def test_closed_two_vertex_polyline_is_skipped():
    path = DATA / "real/ezdxf/POLI-ALL210_12.DXF"
    doc = ezdxf.readfile(str(path))
    two = [e.dxf.handle for e in doc.modelspace() if e.dxftype() == "POLYLINE"
           and e.is_closed and len(e.vertices) == 2
           and not any(v.dxf.get("bulge", 0.0) for v in e.vertices)]
    assert two  # the file has such polylines (e.g. handle 39)
    # by default every polyline (bulges or not, two vertices or more) is a drawn shape, left as
    # drawn: the file has nothing else, and the error counts them
    n_poly = sum(e.dxftype() == "POLYLINE" and (e.is_2d_polyline or e.is_3d_polyline)
                 and not e.dxf.flags & 6 for e in doc.modelspace())
    with pytest.raises(FileFormatError, match=f"its {n_poly} polylines are") as exc:
        read_curves(path, on_unsupported="skip")
    assert exc.value.n_drawn == n_poly >= 30
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        recs = read_curves(path, on_unsupported="skip", polylines=True)
    text = " ".join(str(x.message) for x in w)
    for h in two:
        assert f"POLYLINE {h} " in text and "2 distinct vertices" in text
    read_handles = {r.source["handle"] for r in recs}
    assert not read_handles & set(two)
    # every polyline with >= 3 distinct vertices and no bulges is read
    expect = set()
    for e in doc.modelspace():
        if e.dxftype() != "POLYLINE" or any(v.dxf.get("bulge", 0.0) for v in e.vertices):
            continue
        pts = {tuple(v.dxf.location) for v in e.vertices}
        if len(pts) >= 3 or (len(pts) == 2 and not e.is_closed):
            expect.add(e.dxf.handle)
    assert read_handles == expect


def test_cli_truncated_dxf_no_traceback(tmp_path):
    src = (DATA / "real/trimesh/spline.DXF").read_bytes()
    p = tmp_path / "cut.dxf"
    p.write_bytes(src[: len(src) // 2])
    out = tmp_path / "out.dxf"
    res = subprocess.run([sys.executable, "-m", "curvefair", "fair", str(p), "--tol", "0.1",
                          "-o", str(out)], capture_output=True, text=True, timeout=300)
    assert res.returncode == 1, res.stderr
    assert "Traceback" not in res.stderr
    assert "looks truncated" in res.stderr and str(p) in res.stderr
    assert not out.exists()
