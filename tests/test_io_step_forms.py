"""STEP write-back of the other Part 42 forms of a B-spline curve (issue 11), on OCCT files.

Three files of the OCCT test data hold their one free curve in a form other than a simple
``B_SPLINE_CURVE_WITH_KNOTS``: a complex instance with ``RATIONAL_B_SPLINE_CURVE`` of unit
weights (Alias), a ``QUASI_UNIFORM_CURVE`` (knots implied; Theorem CADDS), and a
``TRIMMED_CURVE`` of a closed periodic B-spline with parameter and cartesian-point trims
(CoCreate). Each curve is changed (one control point moved), written back into its file, and
the written file is read again by Open CASCADE directly (``BRepAdaptor_Curve``, not
curvefair) and by a test-side split of the DATA section: the curve on disk is the changed
one (1e-9 of the model's size, on the edge's own parameter range), and every instance other
than the curve's moved control points (and the trim point, which must lie on the new curve)
has exactly the text it had. A rational curve with weights other than 1 is not read
(a warning, ``--strict`` refuses) and stays byte for byte.
"""

from __future__ import annotations

import os
import re

import numpy as np
import pytest

from curvefair import FileFormatError, read_curves, write_curves

pytest.importorskip("OCP")

from OCP.BRepAdaptor import BRepAdaptor_Curve  # noqa: E402
from OCP.STEPControl import STEPControl_Reader  # noqa: E402
from OCP.TopAbs import TopAbs_ShapeEnum  # noqa: E402
from OCP.TopExp import TopExp_Explorer  # noqa: E402
from OCP.TopoDS import TopoDS  # noqa: E402

_EDGE = getattr(TopoDS, "Edge_s", None) or TopoDS.Edge  # 7.x / 8.x spelling

DATA = os.path.join(os.path.dirname(__file__), "data", "real", "occt")


def _instances(path):
    """{id: text} of every ``#id = ...;`` of the DATA section (test-side: split at ';' ending
    a line; these files hold no ';' inside strings)."""
    text = open(path, encoding="latin-1").read()
    data = text[text.index("DATA;") + 5:text.index("ENDSEC;", text.index("DATA;"))]
    out = {}
    for m in re.finditer(r"#(\d+)\s*=(.*?);\s*(?=#\d+\s*=|$)", data, re.S):
        out[int(m[1])] = re.sub(r"\s+", "", m[2])
    return out


def _occ_edge(path):
    """(u, xyz) of the file's one free edge (bounding no face) by OCC, 401 parameters."""
    from curvefair.io.occ import _free_edges, _quiet, _read_shape

    with _quiet():
        (edge,) = _free_edges(_read_shape(path, "step", "test"))
    ad = BRepAdaptor_Curve(edge)
    u = np.linspace(ad.FirstParameter(), ad.LastParameter(), 401)
    return u, np.array([[ad.Value(t).X(), ad.Value(t).Y(), ad.Value(t).Z()] for t in u])


def _domain_end(body, end):
    """The first (``end=0``) or last (``-1``) knot of a B-spline's domain from its text."""
    groups = re.findall(r"\(([-+\d.,E]+)\)", body)
    mults = [int(v) for v in groups[-2].split(",")]
    knots = np.repeat([float(v) for v in groups[-1].split(",")], mults)
    p = int(body.split(",")[1])
    return float(knots[p] if end == 0 else knots[-p - 1])


def _basis_point(inst, cid, u):
    """The point at parameter ``u`` of the B_SPLINE_CURVE_WITH_KNOTS instance ``cid`` of the
    file (test-side: its poles, multiplicities and knots evaluated by scipy)."""
    from scipy.interpolate import BSpline

    body = inst[cid]
    pids = [int(v) for v in re.findall(r"#(\d+)", body)]
    pts = np.array([[float(x) for x in inst[q].split(",(")[1].rstrip(")").split(",")]
                    for q in pids])
    groups = re.findall(r"\(([-+\d.,E]+)\)", body)
    mults, knots = ([int(v) for v in groups[-2].split(",")],
                    [float(v) for v in groups[-1].split(",")])
    return BSpline(np.repeat(knots, mults), pts, int(body.split(",")[1]))(u)


@pytest.mark.parametrize("name, form, pole", [
    ("trj7_c2-al-214.stp", "RATIONAL_B_SPLINE_CURVE", 2),
    ("trj7_c2-tc-203.stp", "QUASI_UNIFORM_CURVE", 2),
    ("trj7_c2-sd-214.stp", "TRIMMED_CURVE", 2),     # parameter + point trims, periodic basis
    ("trj8_c2-db-214.stp", "TRIMMED_CURVE", 0),     # point trims only; its start moves
])
def test_other_forms_written_back_in_place(tmp_path, name, form, pole):
    src = os.path.join(DATA, name)
    assert form in open(src, encoding="latin-1").read()
    (rec,) = read_curves(src)
    c = rec.curve
    q = np.array(c.control_points)
    size = float(np.ptp(q, axis=0).max())
    q[pole] += 1e-3 * size                    # the one moved control point
    moved = c.replace(control_points=q)
    out = tmp_path / name
    write_curves(out, [rec.with_curve(moved)], template=src)
    # OCC's own reading: the edge is the moved curve, on the same parameter range
    u0, xyz0 = _occ_edge(src)
    u1, xyz1 = _occ_edge(out)
    np.testing.assert_array_equal(u0, u1)
    exp = moved(u1)
    exp = np.c_[exp, np.full(len(exp), rec.source["z"])] if exp.shape[1] == 2 else exp
    # (the edge's location: compare through the unmoved curve, which OCC gives as xyz0)
    shift = xyz0 - (lambda e: np.c_[e, np.full(len(e), rec.source["z"])]
                    if e.shape[1] == 2 else e)(c(u0))
    assert np.abs(shift).max() <= 1e-9 * size
    assert np.abs(xyz1 - exp).max() <= 1e-9 * size
    assert np.abs(xyz1 - xyz0).max() > 1e-5 * size          # it did move
    # every other instance unchanged: only control points of the curve (and its trim point)
    a, b = _instances(src), _instances(out)
    assert a.keys() == b.keys()
    changed = {i for i in a if a[i] != b[i]}
    assert changed
    for i in changed:
        assert b[i].startswith("CARTESIAN_POINT("), (i, b[i])
        assert a[i].split(",(")[0] == b[i].split(",(")[0]     # its name kept
    form_re = r"\(?.*(B_SPLINE_CURVE(_WITH_KNOTS)?|QUASI_UNIFORM_CURVE)\("
    curve_ids = [i for i in a if re.match(form_re, a[i]) and "SURFACE" not in a[i]]
    poles = {int(p) for i in curve_ids for p in re.findall(r"#(\d+)", a[i])}
    trim_pts = set()
    if form == "TRIMMED_CURVE":
        (t,) = [v for v in b.values() if v.startswith("TRIMMED_CURVE(")]
        assert t in a.values()                                  # the trim itself unchanged
        m = re.match(r"TRIMMED_CURVE\('[^']*',#(\d+),\((.*?)\),\((.*?)\),\.T\.", t)
        basis = int(m[1])
        kn = [float(v) for v in re.findall(r"\(([-+\d.,E]+)\)", a[basis])[-1].split(",")]
        p = int(a[basis].split(",")[1])
        for sel, end in ((m[2], 0), (m[3], -1)):
            us = [float(v) for v in re.findall(r"PARAMETER_VALUE\(([-+\d.E]+)\)", sel)]
            # a point-only trim is at the end of the basis's domain (OCC reads it whole)
            u = us[0] if us else _domain_end(a[basis], end)
            for pid in map(int, re.findall(r"#(\d+)", sel)):
                trim_pts.add(pid)
                xyz = np.array([float(v) for v in b[pid].split(",(")[1].rstrip(")").split(",")])
                old = np.array([float(v) for v in a[pid].split(",(")[1].rstrip(")").split(",")])
                # before: on the old curve; after: on the written curve, at the trim's
                # parameter, and moved exactly when the curve moved there
                assert np.abs(old - _basis_point(a, basis, u)).max() <= 1e-9 * size
                assert np.abs(xyz - _basis_point(b, basis, u)).max() <= 1e-9 * size
                moved_there = np.abs(_basis_point(a, basis, u)
                                     - _basis_point(b, basis, u)).max() > 1e-9 * size
                assert (pid in changed) == moved_there
        assert kn and p and trim_pts & changed
    assert changed <= poles | trim_pts


def _two_curve_file(tmp_path):
    """The Alias file with a second free curve: a copy of its curve instance #19 as #900
    with weight 2 at its second pole (a rational curve on the same poles), added to the
    geometric set."""
    text = open(os.path.join(DATA, "trj7_c2-al-214.stp"), encoding="latin-1").read()
    m = re.search(r"#19=\((.*?)\);", text, re.S)
    rational = m[1].replace("RATIONAL_B_SPLINE_CURVE((1.,1.,", "RATIONAL_B_SPLINE_CURVE((1.,2.,")
    rational = rational.replace("'curve#2'", "'curve#3'")
    assert rational != m[1]
    new = text.replace("#20=GEOMETRIC_SET('Alias Surface Model',(#19,#18));",
                       f"#900=({rational});\n"
                       "#20=GEOMETRIC_SET('Alias Surface Model',(#19,#18,#900));")
    assert new.count("#900") == 2
    src = tmp_path / "two.stp"
    src.write_text(new, encoding="latin-1")
    return src


def test_rational_curve_is_skipped_and_kept_byte_for_byte(tmp_path):
    """A rational curve (weights other than 1) is not a curve curvefair fairs: reading warns
    and skips it (``on_unsupported="raise"``, like the CLI's ``--strict``, refuses the file);
    the CLI fairs the other curve, exits 0 with a warning naming the rational curve, and the
    written file keeps the rational curve's instance and its geometry (read by OCC) exactly."""
    from click.testing import CliRunner

    from curvefair.cli import main

    src = _two_curve_file(tmp_path)
    with pytest.raises(FileFormatError, match="rational"):
        read_curves(src)
    with pytest.warns(UserWarning, match="rational"):
        (rec,) = read_curves(src, on_unsupported="skip")
    q = np.array(rec.curve.control_points)
    q[3] += 0.5
    out = tmp_path / "out.stp"
    write_curves(out, [rec.with_curve(rec.curve.replace(control_points=q))], template=src)
    a, b = _instances(src), _instances(out)
    assert b[900] == a[900] and b[20] == a[20]
    # the faired curve's poles are shared with the rational one: the moved pole is a new
    # point, and only the faired curve's own instance names it
    assert {i for i in a if a[i] != b[i]} == {19} and len(b) == len(a) + 1
    # OCC reads the rational curve where it was
    def edges(path):
        r = STEPControl_Reader()
        r.ReadFile(str(path))
        r.TransferRoots()
        ex = TopExp_Explorer(r.OneShape(), TopAbs_ShapeEnum.TopAbs_EDGE)
        got = []
        while ex.More():
            ad = BRepAdaptor_Curve(_EDGE(ex.Current()))
            if ad.GetType().name == "GeomAbs_BSplineCurve" and ad.BSpline().IsRational():
                u = np.linspace(ad.FirstParameter(), ad.LastParameter(), 101)
                got.append(np.array([[ad.Value(t).X(), ad.Value(t).Y(), ad.Value(t).Z()]
                                     for t in u]))
            ex.Next()
        return got
    (r0,), (r1,) = edges(src), edges(out)
    np.testing.assert_array_equal(r0, r1)
    # the CLI: default skips with a warning and exits 0, --strict refuses (exit 1, no file)
    res = CliRunner().invoke(main, ["fair", str(src), "-o", str(tmp_path / "c.stp"),
                                    "--tol", "0.5"])
    assert res.exit_code == 0, res.output
    assert "rational" in res.stderr
    assert _instances(tmp_path / "c.stp")[900] == a[900]
    res = CliRunner().invoke(main, ["fair", str(src), "-o", str(tmp_path / "s.stp"),
                                    "--tol", "0.5", "--strict"])
    assert res.exit_code != 0 and "rational" in res.stderr
    assert "Traceback" not in res.output and not (tmp_path / "s.stp").exists()
