"""Files from other software that the second file hunt (session 19) found damaged or refused.

Each test reads a real file (tests/data/README.md: origin and licence), or a real file with
one property a user's copy may have (a byte order mark, a Latin-1 name line), writes it back
the way ``curvefair fair`` does and checks the result with independent means: the bytes of
the file, and the libraries that wrote such files (ezdxf, svgpathtools, rhino3dm).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from curvefair import read_curves, write_curves

DATA = Path(__file__).parent / "data"
REAL = DATA / "real"


def _moved(rec, k, dy):
    """The record with its curve's data point ``k`` moved by ``dy`` in y."""
    pts = np.array(rec.curve.points)
    pts[k, 1] += dy
    return rec.with_curve(rec.curve.replace(points=pts))


# ------------------------------------------------------------------------------------------
# text encodings: a byte order mark and Latin-1 text are written back as they were
# ------------------------------------------------------------------------------------------
def _line_diff(a: bytes, b: bytes) -> list[int]:
    la, lb = a.split(b"\n"), b.split(b"\n")
    assert len(la) == len(lb)
    return [i for i, (x, y) in enumerate(zip(la, lb, strict=True)) if x != y]


def test_airfoil_with_a_byte_order_mark_keeps_it(tmp_path):
    # clarky.dat (UIUC, via aerosandbox) as a Windows editor saves it: UTF-8 with a BOM
    src = tmp_path / "clarky.dat"
    src.write_bytes(b"\xef\xbb\xbf" + (DATA / "clarky.dat").read_bytes())
    recs = read_curves(src)
    assert recs[0].name == "CLARK Y AIRFOIL"
    out = tmp_path / "out.dat"
    write_curves(out, [_moved(recs[0], 5, 1e-5)] + recs[1:])
    a, b = src.read_bytes(), out.read_bytes()
    assert b.startswith(b"\xef\xbb\xbf CLARK Y AIRFOIL")   # was dropped: "CLARK Y..." only
    assert _line_diff(a, b) == [6]                           # the one moved row, nothing else


def test_points_csv_with_a_byte_order_mark_keeps_it(tmp_path):
    src = tmp_path / "p.csv"
    src.write_bytes(b"\xef\xbb\xbfx;y\r\n" + b"".join(
        b"%.4f;%.4f\r\n" % (x, np.sin(x)) for x in np.linspace(0, 3, 12)))
    (rec,) = read_curves(src)
    out = tmp_path / "o.csv"
    write_curves(out, [_moved(rec, 4, 1e-3)])
    a, b = src.read_bytes(), out.read_bytes()
    assert b.startswith(b"\xef\xbb\xbfx;y\r\n")
    assert _line_diff(a, b) == [5]


def test_airfoil_with_a_latin1_name_line_is_written_in_latin1(tmp_path):
    # the same file with a name line in Latin-1 (not UTF-8): 'é' is the byte 0xE9 and must
    # stay that byte (it was re-encoded as UTF-8, 0xC3 0xA9: a changed name line)
    raw = (DATA / "clarky.dat").read_bytes()
    src = tmp_path / "clarky.dat"
    src.write_bytes(raw.replace(b"CLARK Y AIRFOIL", b"CLARK Y \xe9paisseur 11,7 %", 1))
    recs = read_curves(src)
    assert recs[0].name == "CLARK Y \u00e9paisseur 11,7 %"
    out = tmp_path / "out.dat"
    write_curves(out, [_moved(recs[0], 5, 1e-5)] + recs[1:])
    a, b = src.read_bytes(), out.read_bytes()
    assert b.split(b"\n")[0] == a.split(b"\n")[0]
    assert _line_diff(a, b) == [6]


# ------------------------------------------------------------------------------------------
# binary DXF: written back binary (it was written as ASCII DXF, silently)
# ------------------------------------------------------------------------------------------
BIN_SENTINEL = b"AutoCAD Binary DXF\r\n\x1a\x00"


def test_binary_dxf_is_written_back_binary(tmp_path):
    import ezdxf
    # trimesh's spline.DXF (AC1015, 6 SPLINEs, 4 LINEs) saved by ezdxf as a binary DXF, as
    # netDxf's "sample binary.dxf" (263 kB, same behaviour) is
    src = tmp_path / "spline_bin.dxf"
    ezdxf.readfile(REAL / "trimesh" / "spline.DXF").saveas(src, fmt="bin")
    assert src.read_bytes().startswith(BIN_SENTINEL)
    with pytest.warns(UserWarning, match="degree-1 spline"):
        recs = read_curves(src, on_unsupported="skip")
    rec = recs[0]
    assert rec.kind == "bspline"
    cp = np.array(rec.curve.control_points)
    cp[1, 1] += 1e-3
    out = tmp_path / "out.dxf"
    write_curves(out, [rec.with_curve(rec.curve.replace(control_points=cp))] + recs[1:],
                 template=src)
    assert out.read_bytes().startswith(BIN_SENTINEL)
    a, b = ezdxf.readfile(src), ezdxf.readfile(out)
    ea = sorted((e.dxftype(), e.dxf.handle) for e in a.modelspace())
    eb = sorted((e.dxftype(), e.dxf.handle) for e in b.modelspace())
    assert ea == eb
    h = rec.source["handle"]
    got = np.array([tuple(p) for p in b.entitydb[h].control_points])[:, : cp.shape[1]]
    np.testing.assert_allclose(got, cp, rtol=0, atol=1e-12)
