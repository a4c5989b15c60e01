"""Straight-line shapes in drawings: drawn polygons or sampled curves?

The figures behind the readers' default (docs/formats.md, "Straight-line shapes are drawn
shapes"): for every straight-line shape with at least three segments, the turning angle at
each vertex. A shape "looks sampled" when it has 20 or more vertices and its median turn is
below 10 degrees; a vertex turning by 0.01-60 degrees (below the readers' default corner angle)
would be an interior point of point data, free to move, if such shapes were read as point
lists.

- SVG: every subpath of straight segments only (svgpathtools' reading: polygons, polylines and
  rectangles become paths too);
- DXF (ezdxf): ``LWPOLYLINE`` and 2-D / 3-D ``POLYLINE`` without arc segments (bulges), in the
  model space and the paper space layouts;
- 3dm (rhino3dm): ``PolylineCurve`` objects and degree-1 ``NurbsCurve`` objects.

Usage::

    python benchmarks/survey_drawn_shapes.py FOLDER [FOLDER ...]

Session 27 ran it on Simple Icons (simple-icons/simple-icons @ 34c22501, ``icons/``), GNOME's
Adwaita symbolic icons and hicolor app icons and the W3C SVG 1.1 suite (GNOME/librsvg @
3da74df8c96b, ``rsvg/tests/fixtures/reftests/adwaita``, ``benchmarks/hicolor-apps``,
``reftests/svg1.1``); session 28 on every ``.dxf`` of mozman/ezdxf @ 5ffc69074 and
gdsestimating/dxf-parser, and every ``.3dm`` of mcneel/opennurbs and mcneel/rhino3dm.
"""

from __future__ import annotations

import collections
import os
import sys
import warnings
from collections.abc import Iterator

import numpy as np


def turns(pts: np.ndarray, closed: bool) -> np.ndarray:
    """Turning angle (degrees, 0-180) at each vertex (interior ones of an open list), in 2-D or
    3-D: the angle between the edges in and out, ``atan2(|e1 x e2|, e1 . e2)``."""
    if closed:
        a, b, c = np.roll(pts, 1, 0), pts, np.roll(pts, -1, 0)
    else:
        a, b, c = pts[:-2], pts[1:-1], pts[2:]
    e1, e2 = b - a, c - b
    if pts.shape[1] == 2:
        cross = np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    else:
        cross = np.linalg.norm(np.cross(e1, e2), axis=1)
    return np.degrees(np.arctan2(cross, (e1 * e2).sum(axis=1)))


def _shape(pts: np.ndarray, closed: bool) -> tuple[int, np.ndarray] | None:
    """``(vertex count, turns)`` of a vertex list with repeated vertices dropped, or None when
    it has fewer than three segments."""
    pts = np.asarray(pts, dtype=float)
    keep = np.r_[True, np.linalg.norm(np.diff(pts, axis=0), axis=1) > 1e-9]
    pts = pts[keep]
    if len(pts) > 2 and np.linalg.norm(pts[-1] - pts[0]) <= 1e-9:
        pts, closed = pts[:-1], True
    if len(pts) - (0 if closed else 1) < 3:
        return None
    return len(pts), turns(pts, closed)


def _svg(path: str) -> Iterator[tuple[np.ndarray, bool]]:
    import svgpathtools as spt

    for p in spt.Document(path).paths():
        for sub in p.continuous_subpaths():
            segs = [g for g in sub if g.length() > 1e-9]
            if not segs or not all(isinstance(g, spt.Line) for g in segs):
                continue
            closed = abs(segs[-1].end - segs[0].start) < 1e-9
            z = [g.start for g in segs] + ([] if closed else [segs[-1].end])
            yield np.array([[v.real, v.imag] for v in z]), closed


def _dxf(path: str) -> Iterator[tuple[np.ndarray, bool]]:
    import logging

    import ezdxf

    logging.getLogger("ezdxf").setLevel(logging.ERROR)  # its notes on odd handles, blocks
    doc = ezdxf.readfile(path)
    for layout in doc.layouts:
        for e in layout:
            t = e.dxftype()
            if t == "LWPOLYLINE":
                xyb = np.asarray(e.get_points("xyb"), dtype=float).reshape(-1, 3)
                if not np.any(xyb[:, 2] != 0):
                    yield xyb[:, :2], bool(e.closed)
            elif t == "POLYLINE" and (e.is_2d_polyline or e.is_3d_polyline) \
                    and not e.dxf.flags & 6:
                verts = list(e.vertices)
                if not any(v.dxf.get("bulge", 0.0) for v in verts):
                    yield (np.asarray([tuple(v.dxf.location) for v in verts], dtype=float)
                           .reshape(-1, 3), bool(e.is_closed))


def _3dm(path: str) -> Iterator[tuple[np.ndarray, bool]]:
    import rhino3dm as rh

    model = rh.File3dm.Read(path)
    if model is None:
        return
    for obj in model.Objects:
        g = obj.Geometry
        if isinstance(g, rh.PolylineCurve):
            xyz = np.array([[q.X, q.Y, q.Z] for q in (g.Point(i) for i in range(g.PointCount))])
        elif isinstance(g, rh.NurbsCurve) and g.Degree == 1 and not g.IsRational:
            xyz = np.array([[q.X, q.Y, q.Z] for q in g.Points])
        else:
            continue
        yield xyz, bool(g.IsClosed)


_READERS = {".svg": _svg, ".dxf": _dxf, ".3dm": _3dm}


def shapes(folder: str) -> Iterator[tuple[str, int, np.ndarray]]:
    """``(file, vertex count, turns)`` of every straight-line shape of the folder's files."""
    for name in sorted(os.listdir(folder)):
        reader = _READERS.get(os.path.splitext(name)[1].lower())
        if reader is None:
            continue
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                found = list(reader(os.path.join(folder, name)))
        except Exception:  # noqa: BLE001 - a file the library cannot read is not counted
            continue
        for pts, closed in found:
            if pts.shape[1] == 3 and np.ptp(pts[:, 2]) == 0:
                pts = pts[:, :2]
            s = _shape(pts, closed)
            if s is not None:
                yield name, s[0], s[1]


def main(folders: list[str]) -> None:
    print("| collection | files with such shapes | shapes | vertices | turning 0.01-60 deg "
          "| looks sampled |")
    print("|---|---|---|---|---|---|")
    total: collections.Counter[str] = collections.Counter()
    for folder in folders:
        c: collections.Counter[str] = collections.Counter()
        files = set()
        for name, n, t in shapes(folder):
            files.add(name)
            c["shapes"] += 1
            c["vertices"] += t.size
            c["free"] += int(((t > 0.01) & (t < 60)).sum())
            c["sampled"] += int(n >= 20 and float(np.median(t)) < 10)
        c["files"] = len(files)
        total.update(c)
        print(f"| {os.path.basename(os.path.normpath(folder))} | {c['files']} | {c['shapes']} "
              f"| {c['vertices']} | {c['free']} | {c['sampled']} |")
    print(f"| all | {total['files']} | {total['shapes']} | {total['vertices']} | "
          f"{total['free']} | {total['sampled']} |")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
