"""Rhino PolyCurves (joined curves): read, faired and written back into their segments.

Rhino 2 saved every curve as a PolyCurve, and Rhino's Join makes one of any chain of curves;
curvefair skipped them all ("unsupported PolyCurve"). Files: openNURBS' example models
(tests/data/README.md, "Rhino PolyCurves"). Everything is measured on the file written, read
back with rhino3dm (openNURBS' own evaluation: ``TangentAtStart``, ``CurvatureAt``), never
with curvefair's reader.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

rh = pytest.importorskip("rhino3dm")

DATA = Path(__file__).parent / "data" / "real" / "opennurbs"
LOGO = DATA / "v7_rhino_logo_annotations.3dm"   # Rhino 7: PolyCurves of cubic segments
STEARMAN = DATA / "v2_Stearman.3dm"             # Rhino 2: quadratic poly-Beziers and lines
TERRAIN = DATA / "v2_Terrain.3dm"               # Rhino 2: one periodic cubic per PolyCurve


def _fair(tmp_path: Path, src: Path, tol: float, *extra: str) -> Path:
    from click.testing import CliRunner

    from curvefair.cli import main

    inp = tmp_path / src.name
    inp.write_bytes(src.read_bytes())
    out = tmp_path / ("out_" + src.name)
    res = CliRunner().invoke(main, ["fair", str(inp), "-o", str(out), "--tol", repr(tol), "-q",
                                    *extra])
    assert res.exit_code == 0, res.output
    assert inp.read_bytes() == src.read_bytes()
    return out


def _v(p) -> np.ndarray:
    return np.array([p.X, p.Y, p.Z], dtype=float)


def _cps(c) -> np.ndarray:
    return np.array([(c.Points[i].X, c.Points[i].Y, c.Points[i].Z, c.Points[i].W)
                     for i in range(len(c.Points))])


def _turn(a, b) -> float:
    """Degrees between two unit tangents."""
    return math.degrees(math.acos(float(np.clip(np.dot(_v(a), _v(b)), -1.0, 1.0))))


def _joins(g) -> list[float]:
    """Turn at every join of a PolyCurve: between segments (openNURBS' end tangents) and at
    the C0 knots inside a NurbsCurve segment (positions on either side, 1e-7 of its domain)."""
    n = g.SegmentCount
    segs = [g.SegmentCurve(i) for i in range(n)]
    out = [_turn(segs[i].TangentAtEnd, segs[(i + 1) % n].TangentAtStart)
           for i in range(n if g.IsClosed else n - 1)]
    for s in segs:
        if not isinstance(s, rh.NurbsCurve):
            continue
        k = np.array(list(s.Knots))
        u, m = np.unique(k, return_counts=True)
        h = 1e-7 * (k[-1] - k[0])
        for t in u[(m >= s.Degree) & (u > k[0]) & (u < k[-1])]:
            a = _v(s.PointAt(t)) - _v(s.PointAt(t - h))
            b = _v(s.PointAt(t + h)) - _v(s.PointAt(t))
            c = np.dot(a, b) / (np.linalg.norm(a) * np.linalg.norm(b))
            out.append(math.degrees(math.acos(float(np.clip(c, -1.0, 1.0)))))
    return out


def _diag(model) -> float:
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    for o in model.Objects:
        if isinstance(o.Geometry, rh.Curve):
            b = o.Geometry.GetBoundingBox()
            lo, hi = np.minimum(lo, _v(b.Min)), np.maximum(hi, _v(b.Max))
    return float(np.linalg.norm(hi - lo))


def _compare(src: Path, out: Path, tol: float) -> tuple[int, float, list[tuple[float, float]]]:
    """PolyCurves moved, the largest control-point move, and (before, after) of every join;
    asserts that the structure of every object is kept."""
    m0, m1 = rh.File3dm.Read(str(src)), rh.File3dm.Read(str(out))
    assert len(m0.Objects) == len(m1.Objects)
    after = {str(o.Attributes.Id): o for o in m1.Objects}
    moved, worst, joins = 0, 0.0, []
    for o0 in m0.Objects:
        o1 = after[str(o0.Attributes.Id)]
        assert (o0.Attributes.Name, o0.Attributes.LayerIndex) == \
            (o1.Attributes.Name, o1.Attributes.LayerIndex)
        g0, g1 = o0.Geometry, o1.Geometry
        assert type(g0) is type(g1)
        if not isinstance(g0, rh.PolyCurve):
            continue
        assert g0.SegmentCount == g1.SegmentCount
        d = 0.0
        for i in range(g0.SegmentCount):
            s0, s1 = g0.SegmentCurve(i), g1.SegmentCurve(i)
            assert type(s0) is type(s1)
            assert (g0.SegmentDomain(i).T0, g0.SegmentDomain(i).T1) == \
                (g1.SegmentDomain(i).T0, g1.SegmentDomain(i).T1)
            if isinstance(s0, rh.NurbsCurve):
                assert s0.Degree == s1.Degree and list(s0.Knots) == list(s1.Knots)
                a, b = _cps(s0), _cps(s1)
                assert np.array_equal(a[:, 3], b[:, 3])
                d = max(d, float(np.linalg.norm(a[:, :3] - b[:, :3], axis=1).max()))
            else:
                assert _v(s0.PointAtStart).tolist() == _v(s1.PointAtStart).tolist()
                assert _v(s0.PointAtEnd).tolist() == _v(s1.PointAtEnd).tolist()
        moved += d > 0
        worst = max(worst, d)
        joins += list(zip(_joins(g0), _joins(g1), strict=True))
    assert worst <= tol
    return moved, worst, joins


@pytest.mark.parametrize("src, n_moved", [(LOGO, 2), (STEARMAN, 90), (TERRAIN, 7)],
                         ids=["v7-logo", "v2-stearman", "v2-terrain"])
def test_real_polycurves_are_faired_in_their_segments(tmp_path, src, n_moved):
    """Every PolyCurve keeps its segments (types, degrees, knots, weights, the PolyCurve's
    parametrisation), every control point stays within tol, smooth joins stay smooth and
    corners keep their angle. Before, no PolyCurve was read: nothing moved."""
    tol = 1e-3 * _diag(rh.File3dm.Read(str(src)))
    out = _fair(tmp_path, src, tol)
    moved, worst, joins = _compare(src, out, tol)
    assert moved >= n_moved and worst > 0
    smooth = [(a, b) for a, b in joins if a <= 0.01]
    corners = [(a, b) for a, b in joins if a > 0.5]
    assert all(b <= 0.01 for _, b in smooth), max(b for _, b in smooth)
    assert all(abs(b - a) <= 1.0 + 1e-6 for a, b in corners), \
        max(abs(b - a) for a, b in corners)
    # joins nearly smooth (0.01 to 0.5 degrees) may be made smooth, never sharper
    assert all(b <= a + 1e-6 for a, b in joins if 0.01 < a <= 0.5)


def _nurbs(points, degree: int = 3):
    return rh.NurbsCurve.Create(False, degree, [rh.Point3d(*map(float, p)) for p in points])


def test_joins_to_kept_segments_keep_position_tangent_and_curvature(tmp_path):
    """A PolyCurve made here: wiggly cubic A, cubic B joined G1 to it, a line joined G2 to B
    (B ends straight), a cubic D at a 40-degree corner after the line. A and B are one run
    (their G1 join faired through), D another; the line is kept; at the line's ends the
    runs hold their end point, tangent and (G2) curvature."""
    x = np.linspace(0.0, 4.0, 9)
    A = np.c_[x, 0.6 * np.sin(x) + 0.04 * (-1) ** np.arange(9), np.zeros(9)]
    d = A[-1] - A[-2]
    B = [A[-1], A[-1] + 0.4 * d / np.linalg.norm(d)]        # G1 with A
    B += [B[-1] + (0.5, 0.3 + 0.05 * (k % 2), 0.0) for k in range(4)]
    e = np.array((1.0, 0.2, 0.0)) / math.hypot(1.0, 0.2)
    B += [B[-1] + 0.4 * e, B[-1] + 0.8 * e]                 # B ends straight: zero curvature
    B = np.array(B)
    L0, L1 = B[-1], B[-1] + 2.0 * e
    rot = math.radians(40.0)
    f = np.array((e[0] * math.cos(rot) - e[1] * math.sin(rot),
                  e[0] * math.sin(rot) + e[1] * math.cos(rot), 0.0))
    D = np.array([L1 + k * 0.5 * f + np.array((0.0, 0.06 * (k % 2), 0.0)) * (k > 1)
                  for k in range(7)])
    pc = rh.PolyCurve()
    for c in (_nurbs(A), _nurbs(B), rh.LineCurve(rh.Point3d(*L0), rh.Point3d(*L1)), _nurbs(D)):
        assert pc.Append(c)
    m = rh.File3dm()
    a = rh.ObjectAttributes()
    a.Name = "joined"
    m.Objects.Add(pc, a)
    src = tmp_path / "made.3dm"
    assert m.Write(str(src), 7)
    g0 = rh.File3dm.Read(str(src)).Objects[0].Geometry
    tol = 0.05
    out = _fair(tmp_path, src, tol)
    moved, worst, joins = _compare(src, out, tol)
    assert moved == 1 and worst > 0
    g1 = rh.File3dm.Read(str(out)).Objects[0].Geometry
    segs0 = [g0.SegmentCurve(i) for i in range(4)]
    segs1 = [g1.SegmentCurve(i) for i in range(4)]
    # the premise: G1 between A and B, G2 between B and the line, a 40-degree corner
    assert _turn(segs0[0].TangentAtEnd, segs0[1].TangentAtStart) < 1e-9
    assert _v(segs0[1].CurvatureAt(segs0[1].Domain.T1)).tolist() == pytest.approx([0, 0, 0],
                                                                                abs=1e-12)
    assert _turn(segs0[2].TangentAtEnd, segs0[3].TangentAtStart) == pytest.approx(40.0)
    # A and B both moved, and stay G1
    for k in (0, 1):
        assert not np.array_equal(_cps(segs0[k]), _cps(segs1[k]))
    assert _turn(segs1[0].TangentAtEnd, segs1[1].TangentAtStart) <= 0.01
    # at the line: B's end point, tangent and curvature exactly as they were
    end0, end1 = segs0[1].Domain.T1, segs1[1].Domain.T1
    assert _v(segs1[1].PointAtEnd).tolist() == _v(segs0[1].PointAtEnd).tolist()
    assert _v(segs1[1].TangentAtEnd).tolist() == _v(segs0[1].TangentAtEnd).tolist()
    assert np.linalg.norm(_v(segs1[1].CurvatureAt(end1))) <= 1e-12
    assert end0 == end1
    # D leaves the corner as it did: the corner keeps its 40 degrees
    assert _v(segs1[3].TangentAtStart).tolist() == _v(segs0[3].TangentAtStart).tolist()
    assert not np.array_equal(_cps(segs0[3]), _cps(segs1[3]))


def test_closed_polycurve_of_one_run_keeps_its_seam_smooth(tmp_path):
    """Two cubic halves of a noisy closed loop, G1 at both joins: one run ending on its start,
    whose seam the fairing plans like an open chain's (seam clamp)."""
    t = np.linspace(0.0, math.pi, 8)
    r = 1.0 + 0.05 * (-1) ** np.arange(8)
    top = np.c_[np.cos(t) * r, np.sin(t) * r, np.zeros(8)]
    top[0], top[-1] = (1.0, 0.0, 0.0), (-1.0, 0.0, 0.0)
    top[1], top[-2] = (1.0, 0.4, 0.0), (-1.0, 0.4, 0.0)     # vertical tangents at both joins
    bottom = top * (1.0, -1.0, 1.0)
    bottom = bottom[::-1]
    bottom[0], bottom[-1] = top[-1], top[0]
    pc = rh.PolyCurve()
    assert pc.Append(_nurbs(top)) and pc.Append(_nurbs(bottom))
    assert pc.IsClosed
    m = rh.File3dm()
    m.Objects.AddCurve(pc)
    src = tmp_path / "loop.3dm"
    assert m.Write(str(src), 7)
    out = _fair(tmp_path, src, 0.03)
    moved, worst, joins = _compare(src, out, 0.03)
    assert moved == 1 and worst > 0
    assert len(joins) == 2 and all(a < 1e-9 and b <= 0.01 for a, b in joins), joins
