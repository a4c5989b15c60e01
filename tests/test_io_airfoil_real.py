"""Airfoil files written by others: UIUC .dat files with leading lines and trailing notes,
every file of the UIUC database as shipped in the aerosandbox 4.2.10 wheel, and SUAVE's
Lednicer-layout files.

The expected coordinates come from an independent reading of the text (``str.split`` and
``float`` on every line, no curvefair code); the wheel is fetched from PyPI with pip at test
time only (cached under tests/.cache), and the test skips with the reason when that fails.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import warnings
import zipfile
from pathlib import Path

import numpy as np
import pytest
from _helpers import record_points

from curvefair import read_curves, write_curves
from curvefair.errors import FileFormatError
from curvefair.io.airfoil import LEADING_EDGE_CORNER_ANGLE

HERE = Path(__file__).parent
REAL = HERE / "data" / "real"
DOCS = HERE.parent / "docs" / "formats.md"
WHEEL = "aerosandbox-4.2.10-py3-none-any.whl"
DB = "aerosandbox/geometry/airfoil/airfoil_database/"


def _pairs(text: str) -> list[tuple[int, tuple[float, float] | None]]:
    """(line index, (x, y) or None) for every line: independent of curvefair's parser."""
    out: list[tuple[int, tuple[float, float] | None]] = []
    for i, line in enumerate(text.replace("\r\n", "\n").split("\n")):
        toks = line.split()
        try:
            vals = [float(t) for t in toks]
        except ValueError:
            vals = []
        out.append((i, (vals[0], vals[1]) if len(vals) == 2 else None))
    return out


def _expected_selig(text: str) -> tuple[np.ndarray, int | None]:
    """Coordinates (the first run of two-number lines, blank lines allowed inside) and the
    0-based index of the first line after them that is not blank (the notes), or None."""
    rows: list[tuple[float, float]] = []
    notes = None
    lines = text.replace("\r\n", "\n").split("\n")
    for i, xy in _pairs(text):
        if xy is not None and notes is None:
            rows.append(xy)
        elif rows and xy is None and lines[i].strip() and notes is None:
            notes = i
    pts = np.array(rows)
    keep = np.r_[True, np.any(pts[1:] != pts[:-1], axis=1)]
    return pts[keep], notes


_contour = record_points


# ------------------------------------------------------------------------------------------
# committed UIUC files with notes (from the same wheel)
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name, first_note", [
    ("mh18b.dat", "Thickness: 11.8% "),
    ("hs522.dat", "http://www.aerodesign.de/"),
])
def test_uiuc_trailing_notes_read_and_kept(tmp_path, name, first_note):
    p = REAL / "uiuc" / name
    text = p.read_text()
    recs = read_curves(p)
    want, notes_at = _expected_selig(text)
    np.testing.assert_array_equal(_contour(recs), want)
    lines = text.split("\n")
    assert lines[notes_at] == first_note
    assert recs[0].source["notes"][0] == first_note
    assert recs[0].name == lines[0].strip()
    # unchanged records: byte for byte
    write_curves(tmp_path / "same.dat", recs)
    assert (tmp_path / "same.dat").read_bytes() == p.read_bytes()
    # moved points: the notes (trailing blanks, tabs) and the name line are written verbatim
    moved = [r.with_curve(r.curve.replace(points=r.points * [1.0, 1.01])) for r in recs]
    write_curves(tmp_path / "moved.dat", moved)
    out = (tmp_path / "moved.dat").read_text().split("\n")
    assert out[0] == lines[0]
    assert out[notes_at:] == lines[notes_at:]
    back = read_curves(tmp_path / "moved.dat")
    np.testing.assert_allclose(_contour(back), want * [1.0, 1.01], rtol=0, atol=1e-12)


def test_leading_lines_and_numbers_after_notes(tmp_path):
    p = tmp_path / "lead.dat"
    body = "".join(f"{x:.4f} {y:.4f}\n" for x, y in
                   [(1, 0), (0.5, 0.06), (0, 0), (0.5, -0.04), (1, 0)])
    p.write_text("Ornithopter airfoil.\nS1020\n  -2.0 3.0 -2.6 3.4\n" + body + "Thickness 10%\n")
    (rec,) = read_curves(p, corner_angle=None)
    assert rec.name == "Ornithopter airfoil."
    assert rec.source["leading_lines"] == ("S1020", "  -2.0 3.0 -2.6 3.4")
    assert rec.source["notes"] == ("Thickness 10%",)
    assert rec.points.shape == (5, 2)
    # coordinates after the notes began are ambiguous: refused, naming the line
    bad = tmp_path / "bad.dat"
    bad.write_text("FOIL\n" + body + "upper surface ends\n0.5 0.1\n")
    with pytest.raises(FileFormatError, match="after the text at line 7") as exc:
        read_curves(bad)
    assert exc.value.line == 8


def test_duplicate_consecutive_airfoil_point_dropped(tmp_path):
    p = tmp_path / "dup.dat"
    p.write_text("FOIL\n1 0\n0.5 0.06\n0.5 0.06\n0 0\n0.5 -0.04\n1 0\n")
    with pytest.warns(UserWarning, match=r"dropped 1 exactly repeated .*line 4"):
        (rec,) = read_curves(p, corner_angle=None)
    np.testing.assert_array_equal(rec.points, [[1, 0], [0.5, 0.06], [0, 0], [0.5, -0.04],
                                               [1, 0]])
    moved = rec.with_curve(rec.curve.replace(points=rec.points * [1, 2]))
    write_curves(tmp_path / "o.dat", moved)
    assert (tmp_path / "o.dat").read_text().split("\n")[2:4] == ["0.5 0.12", "0.5 0.12"]


# ------------------------------------------------------------------------------------------
# SUAVE's Lednicer files
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name, n", [("NACA_63_412.txt", 26), ("B737d.txt", 23)])
def test_suave_lednicer(tmp_path, name, n):
    p = REAL / "suave" / name
    text = p.read_text()
    rows = [xy for _, xy in _pairs(text) if xy is not None]
    assert rows[0] == (n, n)
    upper, lower = np.array(rows[1:n + 1]), np.array(rows[n + 1:])
    assert lower.shape == (n, 2)
    shared = np.array_equal(upper[0], lower[0])
    want = np.vstack([upper[::-1], lower[1:] if shared else lower])
    recs = read_curves(p, format="airfoil")
    assert recs[0].source["airfoil_layout"] == "lednicer"
    assert recs[0].name == text.split("\n")[0].strip()
    np.testing.assert_array_equal(_contour(recs), want)
    write_curves(tmp_path / "same.dat", recs)
    assert (tmp_path / "same.dat").read_bytes() == p.read_bytes()


# ------------------------------------------------------------------------------------------
# every file of the UIUC database in the aerosandbox 4.2.10 wheel
# ------------------------------------------------------------------------------------------
@pytest.fixture(scope="session")
def aerosandbox_wheel() -> Path:
    cache = Path(os.environ.get("CURVEFAIR_TEST_CACHE", HERE / ".cache"))
    whl = cache / WHEEL
    if not whl.is_file():
        cache.mkdir(parents=True, exist_ok=True)
        try:
            res = subprocess.run([sys.executable, "-m", "pip", "download", "--no-deps",
                                  "--disable-pip-version-check", "aerosandbox==4.2.10",
                                  "-d", str(cache)], capture_output=True, text=True,
                                 timeout=300)
        except (OSError, subprocess.TimeoutExpired) as exc:
            pytest.skip(f"cannot download {WHEEL} from PyPI with pip: {exc}")
        if res.returncode != 0 or not whl.is_file():
            tail = (res.stderr or res.stdout).strip().splitlines()[-1:] or ["no output"]
            pytest.skip(f"cannot download {WHEEL} from PyPI with pip: {tail[0]}")
    return whl


def _documented_refusals() -> dict[str, str]:
    """file name -> reason, from the table in docs/formats.md."""
    text = DOCS.read_text()
    sec = text[text.index("## UIUC airfoil files that are refused"):]
    return dict(re.findall(r"^\| `([^`]+\.dat)` \| (.+?) \|$", sec, re.MULTILINE))


def test_every_uiuc_file_of_the_aerosandbox_wheel(aerosandbox_wheel, tmp_path):
    refused_doc = _documented_refusals()
    assert refused_doc, "docs/formats.md lists no refusals (section missing?)"
    with zipfile.ZipFile(aerosandbox_wheel) as z:
        names = sorted(n for n in z.namelist() if n.startswith(DB) and n.endswith(".dat"))
        assert len(names) == 2174
        read_ok, refused, notes = 0, {}, 0
        not_identical: list[str] = []
        round_le, cut_wrong = 0, []
        for n in names:
            base = n[len(DB):]
            raw = z.read(n)
            p = tmp_path / base
            p.write_bytes(raw)
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    recs = read_curves(p)
            except FileFormatError as exc:
                refused[base] = str(exc)
                continue
            read_ok += 1
            # the leading edge (farthest from the trailing edge's middle) is cut only where
            # it turns by LEADING_EDGE_CORNER_ANGLE or more; the other corners by the default
            pts = _contour(recs)
            le = int(np.argmax(np.linalg.norm(pts - 0.5 * (pts[0] + pts[-1]), axis=1)))
            if 0 < le < len(pts) - 1:
                a, b = pts[le] - pts[le - 1], pts[le + 1] - pts[le]
                turn = np.degrees(np.arccos(np.clip(
                    a @ b / (np.linalg.norm(a) * np.linalg.norm(b)), -1.0, 1.0)))
                cut = le in {int(r.source["indices"][0]) for r in recs[1:]}
                round_le += bool(60.0 <= turn < LEADING_EDGE_CORNER_ANGLE)
                if cut != (turn >= LEADING_EDGE_CORNER_ANGLE):
                    cut_wrong.append((base, float(turn), cut))
            src = recs[0].source
            notes += bool(src["notes"])
            if src["airfoil_layout"] == "selig":
                want, _ = _expected_selig(raw.decode("latin-1"))
                got = _contour(recs)
                assert got.shape == want.shape, base
                np.testing.assert_array_equal(got, want, err_msg=base)
            # nothing changed: the write-back is the file itself, byte for byte (also the
            # files with more digits than a float64 holds)
            out = tmp_path / "out.dat"
            write_curves(out, recs, template=p, overwrite=True)
            if out.read_bytes() != raw:
                not_identical.append(base)
            p.unlink()
    assert set(refused) == set(refused_doc), (
        f"refused but not documented: {sorted(set(refused) - set(refused_doc))}; "
        f"documented but read: {sorted(set(refused_doc) - set(refused))}")
    assert read_ok == 2174 - len(refused_doc)
    assert notes >= 300        # 341 files carry notes after the coordinates
    assert not_identical == [], f"{len(not_identical)} unchanged files not written back as read"
    # coarse tables turn by 60-120 degrees at a round leading edge (the default corner angle
    # alone cut 527 files there); none is cut, every sharper one is
    assert round_le >= 400
    assert cut_wrong == []
