"""`curvefair check`: findings measured against independent computations (the tangent legs
and end curvature of Bezier control polygons, a dense sampling of the signed curvature),
the exit code, the SARIF 2.1.0 structure and the pre-commit hook definition."""

from __future__ import annotations

import json
import math
import os
import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from curvefair import BSplineCurve, interpolate_cubic, write_curves
from curvefair.cli import main

ROOT = Path(__file__).resolve().parents[1]


def _run(args: list[str], cwd: Path):
    old = os.getcwd()
    os.chdir(cwd)
    try:
        return CliRunner().invoke(main, args, catch_exceptions=False)
    finally:
        os.chdir(old)


def _two_beziers(left: np.ndarray, right: np.ndarray) -> BSplineCurve:
    """Two cubic Bezier pieces joined at left[3] == right[0] (a C0 knot of multiplicity 3)."""
    assert np.array_equal(left[3], right[0])
    P = np.vstack([left, right[1:]])
    knots = [0, 0, 0, 0, 1, 1, 1, 2, 2, 2, 2]
    return BSplineCurve(P, knots, 3)


def _leg_angle(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> float:
    u, v = b - a, c - b
    return math.degrees(math.atan2(abs(u[0] * v[1] - u[1] * v[0]), float(u @ v)))


def _end_curvature(p0: np.ndarray, p1: np.ndarray, p2: np.ndarray) -> float:
    """Curvature of a cubic Bezier at its end p0 (p1, p2 the next control points):
    kappa = (n-1)/n |(p1-p0) x (p2-p1)| / |p1-p0|^3 with n = 3."""
    d1, d2 = p1 - p0, p2 - p1
    return 2.0 / 3.0 * abs(d1[0] * d2[1] - d1[1] * d2[0]) / np.linalg.norm(d1) ** 3


def test_kink_value_is_the_control_polygon_angle(tmp_path: Path):
    t = math.radians(3.0)
    J = np.array([3.0, 0.0])
    left = np.array([[0.0, 0.0], [1.0, 0.3], [2.0, 0.0], J])
    right = np.array([J, J + [math.cos(t), math.sin(t)], J + [2.0, 1.0], J + [3.0, 0.5]])
    write_curves(tmp_path / "kink.json", [_two_beziers(left, right)])
    r = _run(["check", "kink.json", "--format", "json"], tmp_path)
    assert r.exit_code == 1, r.output
    found = json.loads(r.output)["findings"]
    kinks = [f for f in found if f["rule"] == "kink"]
    assert len(kinks) == 1
    want = _leg_angle(left[2], J, right[1])
    assert abs(want - 3.0) < 1e-12
    assert abs(kinks[0]["value"] - want) < 1e-9
    np.testing.assert_allclose(kinks[0]["point"], J, atol=1e-12)
    # above the corner angle it is a corner drawn on purpose; with the kink threshold off: none
    r = _run(["check", "kink.json", "--corner-angle", "2", "--format", "json"], tmp_path)
    assert not [f for f in json.loads(r.output)["findings"] if f["rule"] == "kink"]


def test_g2_break_value_is_the_bezier_end_curvature_jump(tmp_path: Path):
    J = np.array([3.0, 0.0])
    left = np.array([[0.0, 0.0], [1.0, 0.5], [2.0, 0.0], J])
    right = np.array([J, [4.0, 0.0], [5.0, 1.0], [6.0, 1.0]])
    write_curves(tmp_path / "g2.json", [_two_beziers(left, right)])
    r = _run(["check", "g2.json", "--format", "json", "--max-bad", "off", "--wiggle", "off"],
             tmp_path)
    assert r.exit_code == 1, r.output
    (f,) = json.loads(r.output)["findings"]
    assert f["rule"] == "g2-break"
    kl = _end_curvature(J, left[2], left[1])   # 1/3, bending the same way as the right side
    kr = _end_curvature(J, right[1], right[2])  # 2/3
    assert abs(f["value"] - abs(kr - kl) / max(kl, kr)) < 1e-9
    # the threshold above the jump: no finding, exit 0
    r = _run(["check", "g2.json", "--g2-rel", "0.6", "--max-bad", "off"], tmp_path)
    assert r.exit_code == 0 and "0 finding(s)" in r.output


def _signed_curvature(c, n: int = 20001) -> tuple[np.ndarray, np.ndarray]:
    pp = c.piecewise
    u = np.linspace(pp.breaks[0], pp.breaks[-1], n)
    d1, d2, r = pp.evaluate(u, 1), pp.evaluate(u, 2), pp.evaluate(u)
    k = (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / np.linalg.norm(d1, axis=1) ** 3
    s = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(r, axis=0), axis=1))])
    return s, k


def test_clean_curve_passes_and_an_s_wiggle_is_found(tmp_path: Path):
    t = np.linspace(0.0, 0.5 * np.pi, 40)
    arc = interpolate_cubic(np.c_[np.cos(t), np.sin(t)], "chord", "natural")
    write_curves(tmp_path / "arc.json", [arc])
    r = _run(["check", "arc.json"], tmp_path)
    assert r.exit_code == 0, r.output
    assert "1 curve(s) checked: 0 finding(s)" in r.output
    x = np.linspace(0.0, 10.0, 41)
    y = 0.1 * x**2 / 10
    y[20] += 0.01  # a small bump on a convex curve: an S-wiggle
    bumpy = interpolate_cubic(np.c_[x, y], "chord", "natural")
    write_curves(tmp_path / "bump.json", [bumpy])
    s, k = _signed_curvature(bumpy)
    big = np.abs(k) > 1e-9 * np.abs(k).max()
    sk, kk = s[big], np.sign(k[big])
    flips = sk[1:][np.diff(kk) != 0]
    gaps = np.diff(flips) / s[-1]
    assert gaps.size and gaps.min() < 0.05  # independently: two inflections close together
    r = _run(["check", "bump.json", "--format", "json", "--wiggle", "0.05"], tmp_path)
    assert r.exit_code == 1
    wig = [f for f in json.loads(r.output)["findings"] if f["rule"] == "extra-inflection"]
    assert wig and all(4.0 < f["point"][0] < 6.0 for f in wig)
    assert abs(min(f["value"] for f in wig) - gaps.min()) < 1e-3


def test_unreadable_file_is_a_finding_and_folders_are_walked(tmp_path: Path):
    (tmp_path / "d").mkdir()
    t = np.linspace(0.0, 0.5 * np.pi, 40)
    write_curves(tmp_path / "d/arc.json", [interpolate_cubic(np.c_[np.cos(t), np.sin(t)],
                                                             "chord", "natural")])
    (tmp_path / "d/bad.csv").write_text("x,y\n1,2\nno,number\n")
    r = _run(["check", "d"], tmp_path)
    assert r.exit_code == 1 and "Traceback" not in r.output
    assert "bad.csv: file: unreadable" in r.output and "bad.csv:3" in r.output
    r = _run(["check", "d/nothing*.json"], tmp_path)
    assert r.exit_code == 2


# SARIF 2.1.0: the parts of the OASIS schema (sarif-schema-2.1.0.json) a log of ours uses, with
# their required properties, types and enums. Set CURVEFAIR_SARIF_SCHEMA to the full schema's
# path to validate against it as well.
_MESSAGE = {"type": "object", "required": ["text"], "properties": {"text": {"type": "string"}}}
_SARIF_SUBSET = {
    "type": "object", "required": ["version", "runs"],
    "properties": {
        "$schema": {"type": "string", "format": "uri"},
        "version": {"enum": ["2.1.0"]},
        "runs": {"type": "array", "items": {
            "type": "object", "required": ["tool"],
            "properties": {
                "tool": {"type": "object", "required": ["driver"], "properties": {
                    "driver": {"type": "object", "required": ["name"], "properties": {
                        "name": {"type": "string"}, "version": {"type": "string"},
                        "rules": {"type": "array", "uniqueItems": True, "items": {
                            "type": "object", "required": ["id"], "properties": {
                                "id": {"type": "string"}, "shortDescription": _MESSAGE,
                                "defaultConfiguration": {"type": "object", "properties": {
                                    "level": {"enum": ["none", "note", "warning",
                                                       "error"]}}}}}}}}}},
                "results": {"type": "array", "items": {
                    "type": "object", "required": ["message"],
                    "properties": {
                        "ruleId": {"type": "string"},
                        "ruleIndex": {"type": "integer", "minimum": -1},
                        "level": {"enum": ["none", "note", "warning", "error"]},
                        "message": _MESSAGE,
                        "locations": {"type": "array", "items": {
                            "type": "object", "properties": {
                                "physicalLocation": {"type": "object", "properties": {
                                    "artifactLocation": {"type": "object", "properties": {
                                        "uri": {"type": "string", "format": "uri-reference"}}}}},
                                "logicalLocations": {"type": "array", "items": {
                                    "type": "object", "properties": {
                                        "name": {"type": "string"},
                                        "fullyQualifiedName": {"type": "string"},
                                        "kind": {"type": "string"}}}}}}},
                        "properties": {"type": "object"}}}}}}},
    },
}


def test_sarif_log_structure(tmp_path: Path):
    jsonschema = pytest.importorskip("jsonschema")
    J = np.array([3.0, 0.0])
    left = np.array([[0.0, 0.0], [1.0, 0.5], [2.0, 0.0], J])
    right = np.array([J, [4.0, 0.0], [5.0, 1.0], [6.0, 1.0]])
    (tmp_path / "sub").mkdir()
    write_curves(tmp_path / "sub/g2.json", [_two_beziers(left, right)])
    (tmp_path / "sub/bad.csv").write_text("x,y\n1,2\nno,number\n")
    r = _run(["check", "sub", "--format", "sarif", "-o", "out.sarif"], tmp_path)
    assert r.exit_code == 1
    log = json.loads((tmp_path / "out.sarif").read_text())
    jsonschema.validate(log, _SARIF_SUBSET)
    full = os.environ.get("CURVEFAIR_SARIF_SCHEMA")
    if full:
        jsonschema.validate(log, json.loads(Path(full).read_text()))
    (run,) = log["runs"]
    rules = run["tool"]["driver"]["rules"]
    for res in run["results"]:
        assert rules[res["ruleIndex"]]["id"] == res["ruleId"]
        uri = res["locations"][0]["physicalLocation"]["artifactLocation"]["uri"]
        assert (tmp_path / uri).is_file() and not uri.startswith("/")
    got = {(res["ruleId"], res["locations"][0]["physicalLocation"]["artifactLocation"]["uri"])
           for res in run["results"]}
    assert ("g2-break", "sub/g2.json") in got and ("unreadable", "sub/bad.csv") in got


def test_pre_commit_hook_definition():
    yaml = pytest.importorskip("yaml")
    # the formats read_curves had when the hook was written (a new reader's extensions are
    # added to the hook's pattern with it)
    formats = {"points": (".csv", ".txt", ".xyz", ".pts"), "airfoil": (".dat",),
               "json": (".json",), "dxf": (".dxf",), "3dm": (".3dm",), "svg": (".svg",),
               "iges": (".igs", ".iges"), "step": (".stp", ".step")}
    hooks = yaml.safe_load((ROOT / ".pre-commit-hooks.yaml").read_text())
    (hook,) = [h for h in hooks if h["id"] == "curvefair-check"]
    for key in ("id", "name", "entry", "language"):  # pre-commit's required manifest keys
        assert isinstance(hook[key], str) and hook[key]
    assert hook["language"] == "python"
    prog, sub = hook["entry"].split()
    assert prog == "curvefair" and sub in main.commands
    pat = re.compile(hook["files"])
    for exts in formats.values():
        for e in exts:
            assert pat.search("drawings/part" + e) and pat.search("PART" + e.upper())
    assert not pat.search("README.md") and not pat.search("a.csv.bak")


def test_g2_breaks_of_a_real_svg_match_svgpathtools(tmp_path: Path):
    """trimesh's MIL.svg (Inkscape, cubic chains that are G1 but not G2): every
    tangent-continuous join of two curved segments whose curvature vector jumps by more than
    5 % (computed here from svgpathtools' own parse and derivatives) is a g2-break finding
    with the same value; joins with a straight side (a Line, or a Bezier whose control points
    lie on its chord) are not G2-tested."""
    svgpathtools = pytest.importorskip("svgpathtools")
    from curvefair import read_curves
    from curvefair._check import check_records

    path = Path(__file__).parent / "data/real/trimesh/MIL.svg"

    def kvec(d1: complex, d2: complex) -> np.ndarray:
        a, b = np.array([d1.real, d1.imag]), np.array([d2.real, d2.imag])
        t = a / np.linalg.norm(a)
        return (b - (b @ t) * t) / (a @ a)

    def straight(seg) -> bool:
        q = [complex(z) for z in seg.bpoints()]
        d = q[-1] - q[0]
        if d == 0:
            return False
        tol = 1e-9 * max(abs(d), abs(q[0]))
        return all(abs(((z - q[0]) * d.conjugate()).imag) / abs(d) <= tol for z in q)

    want, skipped = [], 0
    paths, _ = svgpathtools.svg2paths(str(path))
    for p in paths:
        for sub in p.continuous_subpaths():
            segs, L = list(sub), sub.length()
            pairs = list(zip(segs[:-1], segs[1:], strict=True))
            if sub.isclosed():
                pairs.append((segs[-1], segs[0]))
            for a, b in pairs:
                da, db = a.derivative(1), b.derivative(0)
                z = da.conjugate() * db
                if math.degrees(abs(math.atan2(z.imag, z.real))) > 0.05:
                    continue  # a kink or a corner, not a G1 join
                if straight(a) or straight(b):
                    skipped += 1
                    continue
                kl, kr = kvec(da, a.derivative(1, 2)), kvec(db, b.derivative(0, 2))
                rel = np.linalg.norm(kr - kl) / max(np.linalg.norm(kl), np.linalg.norm(kr),
                                                    1.0 / L)
                if rel > 0.05:
                    want.append(rel)
    found = check_records(read_curves(path), str(path),
                          {"max_bad": None, "wiggle": None}, top=10**6)
    got = sorted(f.value for f in found if f.rule == "g2-break")
    assert len(want) > 10 and skipped > 50
    np.testing.assert_allclose(got, sorted(want), rtol=1e-6)


@pytest.mark.parametrize("clean", ["trimesh/spline.DXF", "occt/trj7_c2-ac-214.stp",
                                   "opennurbs/v3_my_curves.3dm"])
def test_calibrated_thresholds_leave_clean_real_files_alone(tmp_path: Path, clean: str):
    """Real CAD files with fair curves (tests/data/real) give no finding at the default
    thresholds (calibrated on that corpus: docs/benchmarks.md)."""
    r = _run(["check", str(ROOT / "tests" / "data" / "real" / clean), "--format", "json"],
             tmp_path)
    rep = json.loads(r.output)
    assert r.exit_code == 0 and rep["n_curves"] > 0 and rep["findings"] == [], rep


def test_a_deliberately_kinked_glyph_is_found_by_name_and_point(tmp_path: Path):
    """A smooth node of a real glyph (Lobster "zero", made a UFO with font_to_ufo) is kinked by
    turning its outgoing handle 1 degree about the node: ``curvefair check`` then reports a
    kink of that angle (computed here from the edited points) at that glyph, contour and
    point index, which it did not report before. The node is the seam of the contour's chain
    (the reader starts a closed contour at its first corner): the seam is a join too."""
    ufoLib2 = pytest.importorskip("ufoLib2")
    from curvefair.fonts import font_to_ufo

    lob = ROOT / "tests" / "data" / "real" / "fonttools" / "Lobster.subset.otf"
    font_to_ufo(lob, tmp_path / "Z.ufo", glyphs=[".notdef", "zero"])
    before = json.loads(_run(["check", "Z.ufo", "--format", "json"], tmp_path).stdout)
    f = ufoLib2.Font.open(tmp_path / "Z.ufo")
    pts = f["zero"].contours[0].points
    n = len(pts)
    k = next(i for i, p in enumerate(pts) if p.smooth and pts[i - 1].type is None
             and pts[(i + 1) % n].type is None)
    node, h = np.array([pts[k].x, pts[k].y]), np.array([pts[(k + 1) % n].x, pts[(k + 1) % n].y])
    th = math.radians(1.0)
    v = h - node
    new = node + [v[0] * math.cos(th) - v[1] * math.sin(th),
                  v[0] * math.sin(th) + v[1] * math.cos(th)]
    pts[(k + 1) % n].x, pts[(k + 1) % n].y = float(new[0]), float(new[1])
    pts[k].smooth = False  # what an editor does when the handle is pulled off the line
    f.save(tmp_path / "K.ufo")
    expect = _leg_angle(np.array([pts[k - 1].x, pts[k - 1].y]), node, new)
    after = json.loads(_run(["check", "K.ufo", "--format", "json"], tmp_path).stdout)

    def kinks(rep):
        return [x for x in rep["findings"] if x["rule"] == "kink" and x["label"] == "zero#0"]

    assert not [x for x in kinks(before) if x.get("point_index") == k]
    hit = [x for x in kinks(after) if x.get("point_index") == k]
    assert len(hit) == 1, kinks(after)
    assert hit[0]["glyph"] == "zero" and hit[0]["label"] == "zero#0"
    assert f"point {k}" in hit[0]["message"]
    assert abs(hit[0]["value"] - expect) < 1e-6 * expect


def test_a_ufo_folder_given_by_name_is_one_input(tmp_path: Path):
    """``curvefair check Font.ufo``: the UFO folder named on the command line is one font,
    not a folder to walk (its .glif files are no inputs)."""
    pytest.importorskip("ufoLib2")
    from curvefair.fonts import font_to_ufo

    lob = ROOT / "tests" / "data" / "real" / "fonttools" / "Lobster.subset.otf"
    font_to_ufo(lob, tmp_path / "Z.ufo", glyphs=[".notdef", "zero"])
    for arg in ("Z.ufo", "Z.ufo/", str(tmp_path / "Z.ufo")):
        rep = json.loads(_run(["check", arg, "--format", "json"], tmp_path).stdout)
        assert rep["n_files"] == 1 and rep["n_curves"] == 2, (arg, rep)


def _bezier_chain(pieces: list[np.ndarray]) -> BSplineCurve:
    """Cubic Bezier pieces end to end (each piece's first point the last one's end), as one
    B-spline with interior knots of multiplicity 3."""
    P = [pieces[0][0]]
    for b in pieces:
        assert np.array_equal(b[0], P[-1])
        P += list(b[1:])
    m = len(pieces)
    knots = [0.0] * 4 + [float(k) for k in range(1, m) for _ in range(3)] + [float(m)] * 4
    return BSplineCurve(np.array(P), knots, 3)


def _signed_end_curvature(p0: np.ndarray, p1: np.ndarray, p2: np.ndarray) -> float:
    """Signed curvature of a cubic Bezier at p0 travelling towards p1 (p2 the next control
    point): 2/3 (p1-p0) x (p2-p1) / |p1-p0|^3."""
    d1, d2 = p1 - p0, p2 - p1
    return 2.0 / 3.0 * float(d1[0] * d2[1] - d1[1] * d2[0]) / float(np.linalg.norm(d1)) ** 3


def test_line_to_curve_joins_are_not_g2_breaks_but_kinks_and_curve_joins_are(tmp_path: Path):
    """One curve: a line drawn as a degenerate cubic (control points on its chord, unevenly
    spaced), a tangent curve, and a second curve tangent to it with another end curvature.
    The line-curve join (curvature 0 -> 2/3) is G1 by design and not reported; the
    curve-curve join is a G2 break of the value computed from the control polygons. A second
    curve whose line meets the curve 2 degrees off the line is a kink there."""
    J1, J2 = np.array([3.0, 0.0]), np.array([6.0, 1.0])
    line = np.array([[0.0, 0.0], [0.5, 0.0], [2.0, 0.0], J1])
    curve1 = np.array([J1, [4.0, 0.0], [5.0, 1.0], J2])
    curve2 = np.array([J2, [7.0, 1.0], [8.0, 3.0], [9.0, 3.0]])
    smooth = _bezier_chain([line, curve1, curve2])
    t = math.radians(2.0)
    kinked = _bezier_chain([line, np.array([J1, J1 + [math.cos(t), math.sin(t)],
                                            [5.0, 1.0], J2])])
    write_curves(tmp_path / "lc.json", [smooth, kinked])
    r = _run(["check", "lc.json", "--format", "json", "--max-bad", "off", "--wiggle", "off"],
             tmp_path)
    assert r.exit_code == 1, r.output
    found = json.loads(r.output)["findings"]
    # independently: the line side has no curvature, the curve's end curvature is not 0, so
    # the relative jump at J1 would be 1 -- the join is skipped, not below the threshold
    assert _end_curvature(J1, curve1[1], curve1[2]) > 0.5
    g2 = [f for f in found if f["rule"] == "g2-break"]
    assert len(g2) == 1 and g2[0]["curve"] == 0, found
    np.testing.assert_allclose(g2[0]["point"], J2, atol=1e-12)
    kl = -_signed_end_curvature(J2, curve1[2], curve1[1])  # the left side, run backwards
    kr = _signed_end_curvature(J2, curve2[1], curve2[2])
    assert abs(g2[0]["value"] - abs(kr - kl) / max(abs(kl), abs(kr))) < 1e-9
    kinks = [f for f in found if f["rule"] == "kink"]
    assert len(kinks) == 1 and kinks[0]["curve"] == 1, found
    np.testing.assert_allclose(kinks[0]["point"], J1, atol=1e-12)
    assert abs(kinks[0]["value"] - _leg_angle(line[2], J1, kinked.control_points[4])) < 1e-9
    assert {f["rule"] for f in found} == {"g2-break", "kink"}


def test_g2_breaks_of_a_real_font_skip_its_line_to_curve_nodes():
    """Lobster (CFF subset): every g2-break finding is at a smooth node between two curved
    segments, and the set of them is the one computed here from the contours' own control
    points (signed Bezier end curvatures, joins within kink_angle, relative jump above
    g2_rel). The font's smooth line-to-curve nodes, whose curved side bends (so the old
    rule's jump would have been 1 > g2_rel), are not reported; kinks still are."""
    from curvefair import analyze, read_curves
    from curvefair._check import THRESHOLDS, check_records

    path = ROOT / "tests" / "data" / "real" / "fonttools" / "Lobster.subset.otf"
    recs = read_curves(path)
    found = check_records(recs, str(path), {"max_bad": None, "wiggle": None}, top=10**6)
    got = {(f.label, f.extra["point_index"]) for f in found if f.rule == "g2-break"}
    want, line_curve, near = set(), 0, set()
    for rec in recs:
        c = rec.source["outline"]
        P, on, n = np.asarray(c.points, dtype=float), c.on, len(c.on)
        assert c.closed and not c.quadratic
        L_lower = sum(float(np.linalg.norm(P[k] - P[k - 1])) for k in range(n) if on[k])
        for k in range(n):
            if not on[k]:
                continue
            prv, nxt = P[k - 1], P[(k + 1) % n]
            if np.array_equal(prv, P[k]) or np.array_equal(nxt, P[k]):
                continue  # zero-speed side: skipped by check
            if _leg_angle(prv, P[k], nxt) > THRESHOLDS["kink_angle"]:
                continue
            line_left, line_right = on[k - 1], on[(k + 1) % n]
            if line_left and line_right:
                continue
            if line_left or line_right:
                p1, p2 = (P[(k + 1) % n], P[(k + 2) % n]) if line_left else (P[k - 1], P[k - 2])
                if abs(_end_curvature(P[k], p1, p2)) > THRESHOLDS["g2_rel"] / L_lower:
                    line_curve += 1  # the old rule: |k - 0| / max(|k|, 1/L) > g2_rel
                continue
            kl = -_signed_end_curvature(P[k], P[k - 1], P[k - 2])
            kr = _signed_end_curvature(P[k], P[(k + 1) % n], P[(k + 2) % n])
            L = float(analyze(rec.curve).arc_length)
            rel = abs(kr - kl) / max(abs(kl), abs(kr), 1.0 / L)
            if abs(rel - THRESHOLDS["g2_rel"]) < 1e-6:
                near.add((rec.name, k))
            elif rel > THRESHOLDS["g2_rel"]:
                want.add((rec.name, k))
    assert line_curve >= 3 and len(want) > 20
    assert not near and got == want
    assert any(f.rule == "kink" for f in found)


def test_a_kinked_line_to_curve_node_marked_smooth_is_still_a_kink(tmp_path: Path):
    """A smooth line-to-curve node of a real glyph (Lobster, made a UFO with font_to_ufo):
    its handle turned 1 degree about the node off the line, the node still marked smooth.
    Before the edit ``check`` reports nothing at that node (the G2 step from the line is by
    design); after it, a kink of the angle computed here from the edited points."""
    ufoLib2 = pytest.importorskip("ufoLib2")
    from curvefair.fonts import font_to_ufo

    lob = ROOT / "tests" / "data" / "real" / "fonttools" / "Lobster.subset.otf"
    font_to_ufo(lob, tmp_path / "Z.ufo")
    f = ufoLib2.Font.open(tmp_path / "Z.ufo")
    hit = None
    for g in f:
        for ci, con in enumerate(g.contours):
            pts, n = con.points, len(con.points)
            for k, p in enumerate(pts):
                if (p.smooth and p.type is not None and pts[k - 1].type is not None
                        and pts[(k + 1) % n].type is None):
                    hit = (g.name, ci, k)
                    break
            if hit:
                break
        if hit:
            break
    assert hit is not None
    name, ci, k = hit
    before = json.loads(_run(["check", "Z.ufo", "--format", "json"], tmp_path).stdout)
    label = f"{name}#{ci}"
    assert not [x for x in before["findings"]
                if x["label"] == label and x.get("point_index") == k], before
    pts = f[name].contours[ci].points
    n = len(pts)
    node = np.array([pts[k].x, pts[k].y])
    h = np.array([pts[(k + 1) % n].x, pts[(k + 1) % n].y])
    th = math.radians(1.0)
    v = h - node
    new = node + [v[0] * math.cos(th) - v[1] * math.sin(th),
                  v[0] * math.sin(th) + v[1] * math.cos(th)]
    pts[(k + 1) % n].x, pts[(k + 1) % n].y = float(new[0]), float(new[1])
    assert pts[k].smooth
    f.save(tmp_path / "K.ufo")
    expect = _leg_angle(np.array([pts[k - 1].x, pts[k - 1].y]), node, new)
    r = _run(["check", "K.ufo", "--format", "json"], tmp_path)
    assert r.exit_code == 1
    got = [x for x in json.loads(r.stdout)["findings"]
           if x["label"] == label and x.get("point_index") == k]
    assert [x["rule"] for x in got] == ["kink"], got
    assert abs(got[0]["value"] - expect) < 1e-6 * expect
