"""Straight-line shapes in SVG collections: drawn polygons or sampled curves?

The figures behind the SVG reader's default (docs/formats.md, "Straight-line shapes are drawn
shapes"): for every subpath of straight segments only (svgpathtools' reading: polygons,
polylines and rectangles become paths too) with at least three segments, the turning angle at
each vertex. A shape "looks sampled" when it has 20 or more vertices and its median turn is
below 10 degrees; a vertex turning by 0.01-60 degrees (below the readers' default corner angle)
would be an interior point of point data, free to move, if such shapes were read as point
lists.

Usage::

    python benchmarks/survey_svg_shapes.py FOLDER [FOLDER ...]

Session 27 ran it on Simple Icons (simple-icons/simple-icons @ 34c22501, ``icons/``), GNOME's
Adwaita symbolic icons and hicolor app icons and the W3C SVG 1.1 suite (GNOME/librsvg @
3da74df8c96b, ``rsvg/tests/fixtures/reftests/adwaita``, ``benchmarks/hicolor-apps``,
``reftests/svg1.1``).
"""

from __future__ import annotations

import collections
import os
import sys
import warnings

import numpy as np


def turns(pts: np.ndarray, closed: bool) -> np.ndarray:
    """Absolute turning angle (degrees) at each vertex (interior ones of an open list)."""
    if closed:
        a, b, c = np.roll(pts, 1, 0), pts, np.roll(pts, -1, 0)
    else:
        a, b, c = pts[:-2], pts[1:-1], pts[2:]
    e1, e2 = b - a, c - b
    cross = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    return np.abs(np.degrees(np.arctan2(cross, (e1 * e2).sum(axis=1))))


def shapes(folder: str):
    """``(file, vertex count, turns)`` of every straight-line subpath of the folder's SVGs."""
    import svgpathtools as spt

    for name in sorted(os.listdir(folder)):
        if not name.endswith(".svg"):
            continue
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                paths = spt.Document(os.path.join(folder, name)).paths()
        except Exception:  # noqa: BLE001 - a file svgpathtools cannot read is not counted
            continue
        for p in paths:
            for sub in p.continuous_subpaths():
                segs = [g for g in sub if g.length() > 1e-9]
                if len(segs) < 3 or not all(isinstance(g, spt.Line) for g in segs):
                    continue
                closed = abs(segs[-1].end - segs[0].start) < 1e-9
                z = [g.start for g in segs] + ([] if closed else [segs[-1].end])
                pts = np.array([[v.real, v.imag] for v in z])
                yield name, len(pts), turns(pts, closed)


def main(folders: list[str]) -> None:
    print("| collection | files with such shapes | shapes | vertices | turning 0.01-60 deg "
          "| looks sampled |")
    print("|---|---|---|---|---|---|")
    total = collections.Counter()
    for folder in folders:
        c = collections.Counter()
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
