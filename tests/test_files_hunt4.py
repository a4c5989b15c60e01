"""The fourth file hunt (session 25): SVG files of librsvg's test suite (W3C SVG 1.1 tests,
GNOME's Adwaita and hicolor icons, fuzz files), faired by the command, read back with
svgpathtools.

Joins whose handle lies on its node.

A Bezier segment may end with its last handle on its node (``C 240,60 240,90 240,90``): its
first derivative is zero there and its tangent is that of the next handle back
(``P_3 - P_1``). Inkscape's rounded corners and the W3C path tests draw smooth joins this
way. The join planner skipped a join whose first derivative vanished (an exact zero) or
read a rounding-level one as a corner: nothing kept its tangent, the fairing moved the
handle off the node, and the file came back kinked -- by 9.9 degrees on W3C
``paths-data-01-t.svg`` at tol 0.6, by 26.6 degrees on Adwaita's
``computer-symbolic.svg`` at tol 0.02, exit 0. Such a join is now held: its point and every
control point the tangents on both sides depend on (a corner: its point and a handle on it).

Checked on the files read back with svgpathtools (tangents from the Bezier points it reads),
and on curves made here by differences of positions of the faired curve, not with
curvefair's join code.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from test_files_hunt3 import _join_pairs, _worst_node_or_handle

import curvefair as cf

REAL = Path(__file__).parent / "data" / "real"
W3C = REAL / "w3c" / "paths-data-01-t.svg"
ADWAITA = REAL / "adwaita" / "computer-symbolic.svg"


def _tangents(seg, spt):
    """Unit directions ``(leaving the start, arriving at the end)`` of one svgpathtools
    segment. A Bezier's from its points: the first control point that differs from the node
    (a handle on the node gives the next one: the exact limit direction; svgpathtools' own
    ``unit_tangent(0)`` of ``C 14,92 14,90 16,90`` from 14,92 points the wrong way)."""
    if isinstance(seg, (spt.CubicBezier, spt.QuadraticBezier)):
        pts = list(seg.bpoints())
        tiny = 1e-12 * max(abs(z) for z in pts)
        a = next(z for z in pts[1:] if abs(z - pts[0]) > tiny) - pts[0]
        b = pts[-1] - next(z for z in pts[-2::-1] if abs(z - pts[-1]) > tiny)
        return a / abs(a), b / abs(b)
    if isinstance(seg, spt.Line):
        d = seg.end - seg.start
        return d / abs(d), d / abs(d)
    return seg.unit_tangent(0.0), seg.unit_tangent(1.0)


def _joins(path):
    """``(turn in degrees, a handle on its node)`` of every join of the file
    (``test_files_hunt3._join_pairs``)."""
    spt = pytest.importorskip("svgpathtools")
    out = []
    for a, b in _join_pairs(path):
        turn = abs(math.degrees(np.angle(_tangents(b, spt)[0] / _tangents(a, spt)[1])))
        on_node = (isinstance(a, spt.CubicBezier) and a.control2 == a.end) or (
            isinstance(b, spt.CubicBezier) and b.control1 == b.start)
        out.append((turn, on_node))
    return out


@pytest.mark.parametrize("src, tol, faired", [(W3C, 0.6, True), (W3C, 3.0, True),
                                              (ADWAITA, 0.02, False)],
                         ids=["w3c-0.6", "w3c-3", "adwaita-0.02"])
def test_smooth_joins_with_a_handle_on_the_node_stay_smooth_on_disk(tmp_path, src, tol, faired):
    """``faired``: whether anything is free to move. The Adwaita icon is lines and rounded
    corners drawn with handles on their nodes: lines, corners and those joins are held, so
    its geometry comes back as it was (its handles had been moved off the nodes)."""
    from test_cli import assert_user_error, cli

    (tmp_path / "in.svg").write_bytes(src.read_bytes())
    res = cli(["fair", "in.svg", "--tol", str(tol), "-o", "out.svg", "-q"], tmp_path)
    assert_user_error(res, 0)
    before, after = _joins(tmp_path / "in.svg"), _joins(tmp_path / "out.svg")
    assert len(before) == len(after)
    smooth = [k for k, (turn, _) in enumerate(before) if turn < 1e-7]
    # the premise: smooth joins drawn with a handle on the node are there
    assert sum(before[k][1] for k in smooth) >= 1
    worst = max(after[k][0] for k in smooth)
    assert worst <= 0.01, f"a smooth join turns {worst} degrees in the file written"
    # and the file was faired, within tol
    worst = _worst_node_or_handle(tmp_path / "in.svg", tmp_path / "out.svg")
    assert (0 < worst <= tol) if faired else worst == 0
    assert (tmp_path / "in.svg").read_bytes() == src.read_bytes()


# ------------------------------------------------------------------------------------------
# the same on curves made here, every B-spline method
# ------------------------------------------------------------------------------------------
def _poly_bezier(B: np.ndarray) -> cf.BSplineCurve:
    """The cubic B-spline of Bezier segments ``B (m, 4, 2)`` joined end to start (knots of
    multiplicity 3: C0 joins)."""
    m = B.shape[0]
    P = np.vstack([B[0, :1]] + [b[1:] for b in B])
    knots = np.r_[[0.0] * 4, np.repeat(np.arange(1.0, m), 3), [float(m)] * 4]
    return cf.BSplineCurve(P, knots, 3)


def _direction(c, u: float, side: int, h: float = 1e-4) -> np.ndarray:
    """The unit direction the curve arrives at (side -1) or leaves (side +1) ``c(u)`` with,
    from differences of positions (independent of derivatives): the chord directions ``e(h)``
    to ``c(u + side h)`` and ``e(h / 2)``, extrapolated to ``h = 0`` (``2 e(h/2) - e(h)``: the
    chord's angle to the tangent is ``O(h)``, also where the first derivative vanishes)."""
    r0 = np.asarray(c(np.array([u])))[0]

    def e(step: float) -> np.ndarray:
        d = (np.asarray(c(np.array([u + side * step])))[0] - r0) * side
        return d / np.linalg.norm(d)

    d = 2.0 * e(h / 2) - e(h)
    return d / np.linalg.norm(d)


def _turn(c, u: float, u_end: float | None = None) -> float:
    """Degrees between the arriving and leaving direction at ``u`` (the seam: arriving at
    ``u_end``)."""
    a = _direction(c, u if u_end is None else u_end, -1)
    b = _direction(c, u, +1)
    return math.degrees(math.atan2(abs(a[0] * b[1] - a[1] * b[0]), float(a @ b)))


def _wiggly_segments() -> list[np.ndarray]:
    rng = np.random.default_rng(5)
    segs = []
    x = 0.0
    for _ in range(6):
        p0 = np.array([x, 0.0])
        segs.append(np.array([p0, p0 + [0.3, 0.4], p0 + [0.7, -0.4], p0 + [1.0, 0.0]])
                    + np.r_[0, 1, 1, 0][:, None] * rng.normal(0, 0.05, (4, 2)))
        x += 1.0
    return segs


#: the B-spline methods that fair a poly-Bezier (knot removal finds no simple knot to remove
#: in one, Cheng-Yu refuses its corners)
METHODS = ["eck-hadenfeld", "global"]


@pytest.mark.parametrize("method", METHODS)
def test_interior_joins_with_a_handle_on_the_node(method):
    """A chain of six wiggly cubic segments; at join 2 the left handle lies on the node and
    the tangents agree (G1), at join 4 the right handle lies on the node and the tangents
    differ by 30 degrees (a corner). The G1 join stays G1 and its handle on the node; the
    corner stays where it was, its handle on it (Evince's icon: a cusp drawn with a handle
    on its node, ``C 14,92 14,90 16,90`` after a line down to 14,92, turned from 180 to 153
    degrees when that handle moved off)."""
    segs = _wiggly_segments()
    # join 2 (between segments 1 and 2): left handle on the node, the direction arriving
    # (node - previous handle) continued by the right handle
    s1, s2 = segs[1], segs[2]
    s1[2] = s1[3]
    d = s1[3] - s1[1]
    s2[1] = s2[0] + 0.4 * d / np.linalg.norm(d)
    # join 4 (between segments 3 and 4): right handle on the node, a 30 degree corner
    s3, s4 = segs[3], segs[4]
    d = s3[3] - s3[2]
    rot = np.array([[math.cos(0.5236), -math.sin(0.5236)], [math.sin(0.5236), math.cos(0.5236)]])
    s4[1] = s4[0]
    s4[2] = s4[0] + 0.5 * rot @ (d / np.linalg.norm(d))
    c = _poly_bezier(np.array(segs))
    assert _turn(c, 2.0) < 1e-3 and abs(_turn(c, 4.0) - 30.0) < 1e-2  # the premise
    res = cf.fair(c, method, tol=0.05)
    out = res.curve
    P0, P1 = np.asarray(c.control_points), np.asarray(out.control_points)
    assert np.abs(P1 - P0).max() > 1e-3  # it faired
    assert _turn(out, 2.0) < 1e-3
    node2, node4 = 6, 12  # control-point indices of the join points
    assert np.array_equal(P1[node2], P0[node2]) and np.array_equal(P1[node2 - 1], P1[node2])
    assert np.array_equal(P1[node4], P0[node4]) and np.array_equal(P1[node4 + 1], P1[node4])
    assert abs(_turn(out, 4.0) - 30.0) < 5.0  # a corner it stays


@pytest.mark.parametrize("method", METHODS)
def test_open_chain_closing_on_itself_with_a_handle_on_the_node(method):
    """An open chain whose last node is its first (a closed outline written as an open path,
    like W3C's ``Infinity_McccCz``), its last handle on that node, the seam G1: the seam
    stays G1 (it turned 9.9 degrees)."""
    th = np.linspace(0, 2 * np.pi, 7)
    rng = np.random.default_rng(3)
    r = 1.0 + 0.05 * rng.normal(size=7)
    r[-1] = r[0]
    nodes = np.c_[r * np.cos(th), r * np.sin(th)]
    tang = np.c_[-np.sin(th), np.cos(th)] * 0.35
    B = np.array([[nodes[i], nodes[i] + tang[i], nodes[i + 1] - tang[i + 1], nodes[i + 1]]
                  for i in range(6)])
    B[-1, 2] = B[-1, 3]  # the last handle on the seam node; its tangent is P3 - P1
    d = B[-1, 3] - B[-1, 1]
    B[0, 1] = B[0, 0] + 0.35 * d / np.linalg.norm(d)  # the first handle continues it
    c = _poly_bezier(B)
    assert _turn(c, 0.0, 6.0) < 1e-3  # the premise: a smooth seam
    res = cf.fair(c, method, tol=0.05)
    out = res.curve
    assert np.abs(np.asarray(out.control_points) - np.asarray(c.control_points)).max() > 1e-3
    assert _turn(out, 0.0, 6.0) < 1e-3


# ------------------------------------------------------------------------------------------
# groups nested deeper than Python's recursion limit
# ------------------------------------------------------------------------------------------
def test_groups_nested_deeper_than_the_recursion_limit(tmp_path):
    """librsvg's fuzz file ``layer-nesting-depth.svg`` nests 2,000 ``<g>``: the reader walked
    the tree recursively and the command ended in a RecursionError traceback. A path inside
    3,000 nested groups is read, faired and written back."""
    from test_cli import assert_user_error, cli

    n = 3000
    d = "M 10,50 C 20,20 30,80 40,50 S 60,20 70,50 S 80,80 90,50"
    text = ('<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100">\n'
            + "<g>" * n + f'<path d="{d}"/>' + "</g>" * n + "\n</svg>\n")
    (tmp_path / "deep.svg").write_text(text, encoding="utf-8")
    res = cli(["fair", "deep.svg", "--tol", "1", "-o", "out.svg", "-q"], tmp_path)
    assert_user_error(res, 0)
    out = (tmp_path / "out.svg").read_text(encoding="utf-8")
    assert out.count("<g>") == n and f'd="{d}"' not in out
    assert _worst_node_or_handle(tmp_path / "deep.svg", tmp_path / "out.svg") <= 1.0
