"""write_curves reads back what it wrote (issue 11): the measured on-disk deviation, nothing
written when tol is broken, verify=False to skip; one case per format, checked against an
independent measurement (dense sampling of the input and of the file read back with scipy's
cKDTree, or at equal parameters)."""

from __future__ import annotations

import os
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import cKDTree

from curvefair import BSplineCurve, interpolate_cubic, read_curves, write_curves
from curvefair.io import WriteCheck, WriteCheckError

DATA = Path(__file__).parent / "data"


def _to_polyline(q, poly):
    """Distance of each point of q to the polyline ``poly`` (its two segments next to the
    nearest vertex)."""
    j = cKDTree(poly).query(q)[1]
    best = np.full(q.shape[0], np.inf)
    for a, b in ((j - 1, j), (j, j + 1)):
        a = np.clip(a, 0, len(poly) - 1)
        b = np.clip(b, 0, len(poly) - 1)
        pa, pb = poly[a], poly[b]
        d = pb - pa
        L2 = np.maximum(np.einsum("ij,ij->i", d, d), 1e-300)
        s = np.clip(np.einsum("ij,ij->i", q - pa, d) / L2, 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(q - (pa + s[:, None] * d), axis=1))
    return best


def _dense_distance(a, b, n=100000) -> float:
    """Independent distance of curve b from curve a: at equal parameters when the domains
    agree (B-spline entities keep their knots), else the two-way sampled Hausdorff distance
    (samples of one curve to the dense polyline of the other)."""
    ta, tb = np.linspace(*a.domain, n), np.linspace(*b.domain, n)
    if np.allclose(a.domain, b.domain, rtol=0, atol=1e-12):
        return float(np.linalg.norm(a(ta) - b(tb), axis=1).max())
    # the breakpoints too: a polyline that cuts a corner is off by half a sample step there
    ta = np.union1d(ta, a.piecewise.breaks)
    tb = np.union1d(tb, b.piecewise.breaks)
    pa, pb = a(ta), b(tb)
    return float(max(_to_polyline(pa, pb).max(), _to_polyline(pb, pa).max()))


def _moved_bspline(rec, delta, seed=0):
    """rec's B-spline with every control point moved by a vector of length exactly ``delta``
    (convex hull: the curve moves at most ``delta``)."""
    c = rec.curve
    rng = np.random.default_rng(seed)
    v = rng.normal(size=c.control_points.shape)
    v *= delta / np.linalg.norm(v, axis=1, keepdims=True)
    return rec.with_curve(c.replace(control_points=np.asarray(c.control_points) + v))


def _moved_points(rec, delta, seed=0):
    from curvefair.io._common import points_curve

    pts = np.array(rec.curve.points)
    rng = np.random.default_rng(seed)
    v = rng.normal(size=pts.shape)
    v *= delta / np.linalg.norm(v, axis=1, keepdims=True)
    v[[0, -1]] = 0.0
    return rec.with_curve(points_curve(pts + v, bool(rec.curve.closed)))


def _check_result(check, recs, out, tol):
    assert isinstance(check, WriteCheck)
    assert check.max_deviation <= tol
    back = read_curves(out, corner_angle=60.0, on_unsupported="skip")
    assert len(back) == len(recs)
    indep = [_dense_distance(r.curve, b.curve) for r, b in zip(recs, back, strict=True)]
    # the independent sampled distance never exceeds tol, and the reported figure is the
    # real one (the sampled distance is a lower bound of it, close to it)
    assert max(indep) <= tol * (1 + 1e-9)
    for d_ref, d, kind in zip(indep, check.deviations, check.kinds, strict=True):
        assert d_ref <= d * (1 + 1e-4) + 1e-15
        if kind != "geometric upper bound":  # else a bound, used because it meets tol
            assert d <= max(d_ref * 1.05, d_ref + 1e-3 * tol)


CASES = {
    "dxf": (DATA / "real/dxf-parser/splines.dxf", _moved_bspline, 1.0),
    "3dm": (DATA / "real/rhino-developer-samples/nurbscurve.3dm", _moved_bspline, 0.01),
    "dat": (DATA / "clarky.dat", _moved_points, 1e-4),
    "svg": (DATA / "real/fontawesome/3.svg", None, 1.0),
}


@pytest.mark.parametrize("fmt", sorted(CASES))
def test_write_within_tol_reports_the_measured_deviation(fmt, tmp_path):
    src, move, tol = CASES[fmt]
    if fmt == "3dm":
        pytest.importorskip("rhino3dm")
    if fmt in ("dxf",):
        pytest.importorskip("ezdxf")
    if fmt == "svg":
        pytest.importorskip("svgpathtools")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        recs = read_curves(src, on_unsupported="skip")
    if move is None:  # SVG: move the B-spline records
        moved = [_moved_bspline(r, 0.5 * tol, i) if isinstance(r.curve, BSplineCurve) else r
                 for i, r in enumerate(recs)]
    else:
        moved = [move(r, 0.5 * tol, i) for i, r in enumerate(recs)]
    out = tmp_path / ("out" + src.suffix.lower())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        check = write_curves(out, moved, template=src, tol=tol)
    _check_result(check, recs, out, tol)


@pytest.mark.parametrize("ext", ["csv", "json", "dxf", "3dm", "svg", "igs", "step"])
def test_bare_curve_each_format(ext, tmp_path):
    lib = {"dxf": "ezdxf", "3dm": "rhino3dm", "svg": "svgpathtools", "igs": "OCP",
           "step": "OCP"}.get(ext)
    if lib:
        pytest.importorskip(lib)
    rng = np.random.default_rng(3)
    n, p = 9, 3
    t = np.r_[[0.0] * (p + 1), np.linspace(0, 1, n - p + 1)[1:-1], [1.0] * (p + 1)]
    pts = np.c_[np.linspace(0.0, 8.0, n), rng.normal(size=n)]
    if ext == "csv":
        from curvefair import interpolate_cubic

        c = interpolate_cubic(pts, "chord", "natural")
    else:
        c = BSplineCurve(pts, t, p)
    out = tmp_path / f"c.{ext}"
    # IGES stores reals with fewer digits than float64 (about 5e-10 relative, measured)
    tol = 1e-7 if ext == "igs" else 1e-9
    check = write_curves(out, [c], tol=tol)
    assert check.max_deviation <= tol
    back = read_curves(out, corner_angle=None)
    assert _dense_distance(c, back[0].curve, 4000) <= tol
    # verify=False: written, nothing measured
    out2 = tmp_path / f"d.{ext}"
    assert write_curves(out2, [c], verify=False) is None
    assert out2.exists()


def test_tol_broken_nothing_written(tmp_path):
    pytest.importorskip("ezdxf")
    src = DATA / "real/dxf-parser/splines.dxf"
    recs = read_curves(src)
    moved = [_moved_bspline(r, 3.0, i) for i, r in enumerate(recs)]
    out = tmp_path / "out.dxf"
    out.write_bytes(b"keep me")
    before = sorted(os.listdir(tmp_path))
    with pytest.raises(WriteCheckError, match=r"not written: curve \d.*more than tol 1"):
        write_curves(out, moved, template=src, tol=1.0)
    assert out.read_bytes() == b"keep me"           # untouched
    assert sorted(os.listdir(tmp_path)) == before     # no temporary file left
    # the independent measure agrees that tol is broken
    assert max(_dense_distance(r.curve, m.curve) for r, m in zip(recs, moved, strict=True)) > 1.0
    # without tol the same write goes through and reports the move (reference: the curves
    # given, so the figure is what the file does to them: nothing)
    check = write_curves(out, moved, template=src)
    assert check.max_deviation <= 1e-12
    # reference= measures from the input explicitly
    check = write_curves(out, moved, template=src, reference=recs, overwrite=False)
    indep = max(_dense_distance(r.curve, m.curve) for r, m in zip(recs, moved, strict=True))
    assert indep <= check.max_deviation * (1 + 1e-6)


def test_decimals_rounding_refused(tmp_path):
    recs = read_curves(DATA / "clarky.dat")
    out = tmp_path / "c.dat"
    with pytest.raises(WriteCheckError, match="not written: .*(more than tol|points)"):
        write_curves(out, recs, decimals=2, tol=1e-4)
    assert not out.exists()
    # the same rounding without tol: written, the figure reported is the rounding's effect,
    # checked against the independent distance
    check = write_curves(out, recs, decimals=3)
    indep = _dense_distance(recs[0].curve, read_curves(out)[0].curve)
    assert indep > 1e-4 and indep <= check.max_deviation * (1 + 1e-6)


def test_point_moves_scaled_with_a_warning(tmp_path):
    recs = read_curves(DATA / "clarky.dat")
    tol = 1e-4
    moved = [_moved_points(recs[0], 0.98 * tol, 7)]
    out = tmp_path / "c.dat"
    with pytest.warns(UserWarning, match="scaled down"):
        check = write_curves(out, moved, tol=tol)
    assert check.move_scale[0] < 1.0
    _check_result(check, recs, out, tol)


def test_bad_arguments():
    from curvefair import InputError

    c = BSplineCurve([[0, 0], [1, 1], [2, 0]], [0, 0, 0, 1, 1, 1], 2)
    with pytest.raises(InputError, match="tol"):
        write_curves("x.json", [c], tol=-1.0)
    with pytest.raises(InputError, match="verify"):
        write_curves("x.json", [c], verify="no")
    with pytest.raises(InputError, match="reference has 2 curves"):
        write_curves("x.json", [c], reference=[c, c])
    assert not Path("x.json").exists()


def test_report_after_figures_describe_the_written_file(tmp_path):
    """When the moves were scaled for the on-disk tolerance, rescaled_report's after-figures
    are those of the curve read back from the file: checked against analyze() of the file
    re-read independently, numpy point moves, and scipy's natural cubic spline through the
    written points (chord parameters) for the inflection count."""
    from scipy.interpolate import CubicSpline

    from curvefair import analyze, fair
    from curvefair.io import rescaled_report

    recs = read_curves(DATA / "clarky.dat")
    tol = 1e-4
    res = fair(recs[0].curve, "poliakoff", tol=tol, max_steps=5)  # reports measure_max_after
    moved = [_moved_points(recs[0], 0.98 * tol, 7)]
    out = tmp_path / "c.dat"
    with pytest.warns(UserWarning, match="scaled down"):
        check = write_curves(out, moved, tol=tol)
    s = check.move_scale[0]
    assert s < 1.0
    rep = rescaled_report(res.report, recs[0].curve, check.read_back[0], s)
    back = read_curves(out)[0]
    a = analyze(back.curve)
    assert rep["energy_after"] == a.energy2 and rep["extrema_after"] == a.extrema
    assert rep["energy_before"] == res.report["energy_before"]
    p0, p1 = np.asarray(recs[0].points), np.asarray(back.points)
    assert rep["max_point_displacement"] == pytest.approx(
        np.linalg.norm(p1 - p0, axis=1).max(), rel=1e-12)
    assert rep["max_point_displacement"] <= 0.98 * tol * s * (1 + 1e-9)
    assert rep["n_moved"] == int(np.count_nonzero(np.any(p1 != p0, axis=1)))
    assert rep["max_deviation"] <= tol and rep["move_scale"] == s
    assert rep["measure_max_after"] is None
    # inflections of the written curve, independently
    t = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(p1, axis=0), axis=1))]
    cs = CubicSpline(t, p1, bc_type="natural")
    u = np.linspace(t[0], t[-1], 200001)
    d1, d2 = cs(u, 1), cs(u, 2)
    k = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    sg = np.sign(k[np.abs(k) > 1e-9 * np.abs(k).max()])
    assert rep["inflections_after"] == int(np.count_nonzero(sg[1:] != sg[:-1]))


def test_subset_and_new_curve_into_a_template(tmp_path):
    """Writing one of a file's curves plus a new curve into the file as template: the
    template's other curves read back too; the check pairs the written ones by handle and the
    new one as the appended entity."""
    pytest.importorskip("ezdxf")
    src = DATA / "libdxfrw_closed_splines.dxf"  # AC1021
    recs = read_curves(src)
    assert len(recs) == 2
    new = BSplineCurve([[0, 0], [1, 2], [3, 2], [4, 0]], [0, 0, 0, 0, 1, 1, 1, 1], 3)
    moved = _moved_bspline(recs[1], 0.25)
    out = tmp_path / "o.dxf"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        check = write_curves(out, [moved, new], template=src, tol=1.0)
    assert len(check.deviations) == 2 and check.max_deviation <= 1.0
    back = read_curves(out)
    assert len(back) == 3
    got = {b.source["handle"]: b for b in back}
    d_moved = _dense_distance(recs[1].curve, got[recs[1].source["handle"]].curve)
    assert d_moved <= check.deviations[0] * (1 + 1e-4) + 1e-15
    d_new = _dense_distance(new, back[-1].curve)
    assert d_new <= 1e-9 and check.deviations[1] <= 1e-9


def test_new_curve_into_an_r12_template(tmp_path):
    """A new SPLINE written into a drawing ezdxf loads as R12 (no $ACADVER): ezdxf refused it
    (DXFVersionError); the drawing is written as R2000 with a warning, every entity kept."""
    ezdxf = pytest.importorskip("ezdxf")
    src = DATA / "real/dxf-parser/splines.dxf"
    recs = read_curves(src)
    new = BSplineCurve([[0, 0], [1, 2], [3, 2], [4, 0]], [0, 0, 0, 0, 1, 1, 1, 1], 3)
    out = tmp_path / "o.dxf"
    with pytest.warns(UserWarning, match="R2000"):
        check = write_curves(out, recs + [new], template=src, tol=1e-9)
    assert check.max_deviation <= 1e-9
    doc = ezdxf.readfile(str(out))
    assert doc.dxfversion >= "AC1015"
    assert sum(e.dxftype() == "SPLINE" for e in doc.modelspace()) == 3
    assert _dense_distance(new, read_curves(out)[-1].curve, 4000) <= 1e-9


def test_cli_report_after_figures_are_those_of_the_file_read_back(tmp_path, monkeypatch):
    """The CLI's wiring of rescaled_report: ``curvefair fair clarky.dat`` with the fairing
    replaced by moves of 0.98 tol in random directions (every data point within tol, but the
    curve re-interpolated through them strays beyond tol, so the CLI scales the moves). The
    JSON report's after-figures, point moves and deviation are those of the written file read
    back: analyze() of it, numpy on its points, and a cKDTree distance between dense samples
    (independent of the report's own deviation search)."""
    import dataclasses
    import json

    from click.testing import CliRunner

    import curvefair
    from curvefair import analyze
    from curvefair.cli import main

    src = DATA / "clarky.dat"
    rec = read_curves(src)[0]
    tol = 1e-4
    real_fair = curvefair.fair

    def fake_fair(curve, *a, **k):
        res = real_fair(curve, "poliakoff", tol=tol, max_steps=5)
        return dataclasses.replace(res, curve=_moved_points(rec, 0.98 * tol, 7).curve)

    monkeypatch.setattr(curvefair, "fair", fake_fair)
    out, rep_path = tmp_path / "c.dat", tmp_path / "r.json"
    res = CliRunner().invoke(main, ["fair", str(src), "-o", str(out), "--tol", str(tol),
                                    "--report", str(rep_path)])
    assert res.exit_code == 0, res.output
    assert "scaled down" in res.stderr
    report = json.loads(rep_path.read_text())
    (s,) = report["output_check"]["move_scale"]
    assert 0.5 < s < 1.0
    row = report["curves"][0]["report"]
    back = read_curves(out)[0]
    a = analyze(back.curve)
    assert row["move_scale"] == s and "recomputed" in row["after_figures"]
    assert row["energy_after"] == a.energy2 and row["extrema_after"] == a.extrema
    assert row["inflections_after"] == a.inflections
    p0, p1 = np.asarray(rec.points), np.asarray(back.points)
    assert row["max_point_displacement"] == pytest.approx(
        np.linalg.norm(p1 - p0, axis=1).max(), rel=1e-12)
    assert row["n_moved"] == int(np.count_nonzero(np.any(p1 != p0, axis=1)))
    # the deviation: the report's figure, the on-disk figure and an independent one agree
    indep = _dense_distance(rec.curve, back.curve)
    assert row["max_deviation"] <= tol and row["on_disk_deviation"] <= tol
    assert row["max_deviation"] == pytest.approx(indep, rel=1e-3)
    assert row["on_disk_deviation"] == pytest.approx(indep, rel=1e-3)
    # (and the fake fair's own moves, unscaled, would have read back beyond tol)
    assert row["max_point_displacement"] < 0.98 * tol


def test_point_file_spans_over_the_bound_are_refined(tmp_path):
    """A faired point list read back: where the O(n) per-span bound exceeds tol (here one
    span of a poliakoff fair that uses the whole tolerance) only those spans get the refined
    geometric distance; the figure is within tol, bounds the whole-curve refined distance, and
    the file holds the faired points exactly."""
    import curvefair as cf
    from curvefair.analysis import matched_hermite_bound

    rng = np.random.default_rng(0)
    n = 3000
    s = np.linspace(0.0, 24.0 * np.pi, n)
    P = np.c_[s, 3.0 * np.sin(s)] + 0.003 * rng.standard_normal((n, 2))
    src = tmp_path / "p.csv"
    np.savetxt(src, P, delimiter=",", header="x,y", comments="")
    recs = read_curves(src, corner_angle=None)
    tol = 0.01
    r = cf.fair(recs[0].curve, "poliakoff", tol=tol)
    mb = matched_hermite_bound(recs[0].curve, r.curve)
    assert np.count_nonzero(mb > tol) >= 1  # the case this test is about
    chk = write_curves(tmp_path / "o.csv", [recs[0].with_curve(r.curve)], template=src,
                       reference=recs, tol=tol, corner_angle=None)
    assert chk.kinds == ("geometric",)
    back = read_curves(tmp_path / "o.csv", corner_angle=None)[0].curve
    whole = cf.deviation(recs[0].curve, back, kind="geometric").max_distance
    assert whole * (1 - 1e-9) <= chk.deviations[0] <= tol
    np.testing.assert_array_equal(np.loadtxt(tmp_path / "o.csv", delimiter=",", skiprows=1),
                                  r.curve.points)


def test_reports_count_point_data_on_the_curve_rebuilt_from_the_written_file(tmp_path):
    """Point data whose moves need no scaling: the command's and the batch runner's report
    after-figures are those of the file read back (the curve rebuilt through the written
    points at their own chord lengths, counted by analyze() on a fresh read), not those of
    the faired curve on the input's parameters, which stay under ``fair_after``."""
    import json

    from click.testing import CliRunner

    from curvefair import analyze, fair
    from curvefair.batch import fair_file
    from curvefair.cli import main

    rng = np.random.default_rng(5)
    t = np.linspace(0.0, 6.0, 400)
    h = t[1] - t[0]
    pts = np.c_[t, np.sin(t)] + rng.normal(scale=0.3 * h, size=(t.size, 2))
    src = tmp_path / "in.csv"
    np.savetxt(src, pts, delimiter=",", header="x,y", comments="", fmt="%.10f")
    rec = read_curves(src)[0]
    opts = ["--tol", str(h), "--method", "poliakoff", "--eps", "0"]
    out, rep_path = tmp_path / "out.csv", tmp_path / "r.json"
    res = CliRunner().invoke(main, ["fair", str(src), "-o", str(out), "--report",
                                    str(rep_path), *opts])
    assert res.exit_code == 0, res.output
    report = json.loads(rep_path.read_text())
    assert report["output_check"]["move_scale"] == [1.0]
    row = report["curves"][0]["report"]
    a = analyze(read_curves(out)[0].curve)
    assert row["extrema_after"] == a.extrema and row["inflections_after"] == a.inflections
    assert row["energy_after"] == a.energy2 and "read back" in row["after_figures"]
    # fair()'s guard analysed the same rebuilt curve: its figures are the written file's
    assert row["guard"]["rebuilt"]["energy"] == a.energy2
    assert row["guard"]["rebuilt"]["sapidis_sum"] == row["sapidis_sum_after"] == a.sapidis_sum
    own = fair(rec.curve, "poliakoff", tol=h, eps=0.0).report
    assert row["fair_after"]["extrema"] == own["extrema_after"]
    assert row["fair_after"]["inflections"] == own["inflections_after"]
    assert (own["extrema_after"], own["inflections_after"]) != (a.extrema, a.inflections)
    # the batch runner's report says the same
    out2 = tmp_path / "out2.csv"
    rep2 = fair_file(str(src), str(out2), {"tol": h, "method": "poliakoff", "eps": 0.0})
    assert rep2["status"] == "ok"
    r2 = rep2["curves"][0]["report"]
    a2 = analyze(read_curves(out2)[0].curve)
    assert r2["extrema_after"] == a2.extrema and r2["inflections_after"] == a2.inflections
    assert r2["fair_after"]["extrema"] == own["extrema_after"]


def test_svg_element_merged_by_its_own_decimals_is_written_exactly(tmp_path):
    """A small closed subpath (an octagon inside a scaled group) whose moved points lie closer
    together than the element's own decimals (4), and even three more (7), resolve: written
    with them, its points merge and the file reads back with one curve fewer. The writer then
    uses exact numbers, as it does for a deviation beyond tol, instead of refusing the file
    with a count (the hunt of session 18 met this on an OCCT drawing: a tiny octagon faired at
    a tolerance of its own size). Since session 21 the rounding goes toward the input's values
    (no point farther from the input than faired), which keeps the eight points apart on the
    element's own grid: written with its own decimals, one unit of the last one from the
    faired points, nothing merged."""
    spt = pytest.importorskip("svgpathtools")
    a = np.arange(8) * (np.pi / 4)
    octagon = np.c_[525.0 + 1.8 * np.cos(a), 1178.25 + 1.45 * np.sin(a)]
    d = "M " + " L ".join(f"{x:.4f},{y:.4f}" for x, y in octagon) + " Z"
    src = tmp_path / "in.svg"
    src.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 640 690">\n'
        '<g transform="matrix(0.45772011,0,0,0.45774785,-4.5349213,-19.50284)">\n'
        f'<path style="fill:none;stroke:#00f" d="{d}" id="oct"/>\n'
        '<path style="fill:none;stroke:#000" d="M 0,0 L 100,0 L 100,100" id="other"/>\n'
        '</g>\n</svg>\n')
    recs = read_curves(src, polylines=True)
    assert [r.source["id"] for r in recs] == ["oct", "other", "other"]  # split at its corner
    p = np.asarray(recs[0].curve.points)[:-1]  # document coordinates, closing point dropped
    c = p.mean(axis=0)
    q = c + 2e-9 * (p - c)  # 3e-9 across: below the element's 4 + 3 decimals
    new = interpolate_cubic(np.vstack([q, q[:1]]), "chord", "periodic")
    out = tmp_path / "out.svg"
    check = write_curves(out, [recs[0].with_curve(new), *recs[1:]], template=src, tol=1.0)
    assert check.precision == "file" and check.max_deviation <= 1.0
    paths_in, attr_in = spt.svg2paths(str(src))
    paths_out, attr_out = spt.svg2paths(str(out))
    assert [x["id"] for x in attr_out] == ["oct", "other"]
    assert attr_out[1]["d"] == attr_in[1]["d"]  # the other element as it was
    # 4 decimals of the element (scaled by 0.4577 into the document): within one unit of them
    whole = read_curves(out, corner_angle=None, polylines=True)[0]
    assert whole.source["id"] == "oct" and len(whole.points) == 9    # the first repeated
    np.testing.assert_allclose(np.asarray(whole.points)[:-1], q, rtol=0, atol=1e-4)


def test_count_mismatch_names_the_curves_not_read_back(tmp_path):
    """A file that reads back with fewer curves than were written (here a reader that loses
    the second DXF spline) is not written, and the error names the curve that is missing."""
    ezdxf = pytest.importorskip("ezdxf")
    from curvefair.io import write_checked

    doc = ezdxf.new("R2010")
    msp = doc.modelspace()
    for k in range(2):
        msp.add_open_spline([(0, k), (1, k + 1), (2, k), (3, k + 1), (4, k)], degree=3)
    src = tmp_path / "in.dxf"
    doc.saveas(src)
    recs = read_curves(src)
    lost = recs[1].source["handle"]
    out = tmp_path / "out.dxf"
    with pytest.raises(WriteCheckError, match=rf"reads back as 1 curves, the input had 2 "
                                              rf"\(curve 1 \([^)]*{lost}[^)]*\) not read back\)"):
        write_checked(out, recs, recs, tol=0.1, reader=lambda p: read_curves(p)[:1],
                      template=str(src), format="dxf", overwrite=False)
    assert not out.exists()
