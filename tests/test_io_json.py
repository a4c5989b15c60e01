"""curvefair's JSON format: exact round trips of every curve type, the schema, bad files.

References: curves are compared by evaluating both on a dense parameter grid and by their
defining arrays; written files are validated against docs/curvefair-curve.schema.json with the
independent ``jsonschema`` package.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from curvefair import (
    BSplineCurve,
    CubicHermite,
    FileFormatError,
    QuinticHermite,
    interpolate_cubic,
    interpolate_quintic,
    read_curves,
    write_curves,
)
from curvefair.io import CurveRecord

SCHEMA = Path(__file__).parents[1] / "docs" / "curvefair-curve.schema.json"


def _curves():
    rng = np.random.default_rng(7)
    a = np.linspace(0, 2 * np.pi, 9)[:-1]
    ring = np.c_[np.cos(a), np.sin(a)] * (1 + 0.1 * rng.random(8))[:, None]
    open_b = BSplineCurve(rng.random((7, 3)), [0, 0, 0, 0, 0.2, 0.5, 0.5, 1, 1, 1, 1], 3)
    closed_b = BSplineCurve(ring, np.arange(9.0) * 0.7, 3, closed=True)
    quartic = BSplineCurve(rng.random((6, 2)), [0, 0, 0, 0, 0, 1 / 3, 1, 1, 1, 1, 1], 4)
    cub = interpolate_cubic(np.c_[np.arange(6.0), np.sin(np.arange(6.0))])
    cub_closed = interpolate_cubic(ring, bc="periodic")
    quin = interpolate_quintic(np.c_[np.arange(7.0), np.cos(np.arange(7.0)), np.arange(7.0) ** .5])
    return [open_b, closed_b, quartic, cub, cub_closed, quin]


def _same(a, b):
    assert type(a) is type(b) and a.closed == b.closed and a.degree == b.degree
    if isinstance(a, BSplineCurve):
        np.testing.assert_array_equal(a.knots, b.knots)
        np.testing.assert_array_equal(a.control_points, b.control_points)
    else:
        np.testing.assert_array_equal(a.points, b.points)
        np.testing.assert_array_equal(a.params, b.params)
        np.testing.assert_array_equal(a.tangents, b.tangents)
        if isinstance(a, QuinticHermite):
            np.testing.assert_array_equal(a.d2, b.d2)
    u = np.linspace(*a.domain, 257)
    np.testing.assert_array_equal(a(u), b(u))


def test_round_trip_every_type_is_exact(tmp_path):
    curves = _curves()
    p = tmp_path / "c.json"
    write_curves(p, curves)
    recs = read_curves(p)
    assert [r.kind for r in recs] == ["bspline", "bspline", "bspline", "cubic_hermite",
                                      "cubic_hermite", "quintic_hermite"]
    for c, r in zip(curves, recs, strict=True):
        _same(c, r.curve)
    # read -> write -> read: identical file
    write_curves(tmp_path / "d.json", recs)
    assert (tmp_path / "d.json").read_text() == p.read_text()


def test_written_file_validates_against_the_schema(tmp_path):
    jsonschema = pytest.importorskip("jsonschema")
    schema = json.loads(SCHEMA.read_text())
    jsonschema.Draft202012Validator.check_schema(schema)
    p = tmp_path / "c.json"
    recs = [CurveRecord(c, f"c{i}", "bspline" if isinstance(c, BSplineCurve) else
                        ("quintic_hermite" if isinstance(c, QuinticHermite) else "cubic_hermite"),
                        {"metadata": {"layer": "A", "n": i}}, corners=(0,))
            for i, c in enumerate(_curves())]
    write_curves(p, recs)
    doc = json.loads(p.read_text())
    jsonschema.validate(doc, schema)
    assert doc["schema_version"] == 1
    back = read_curves(p)
    assert [r.name for r in back] == [f"c{i}" for i in range(6)]
    assert back[3].source["metadata"] == {"layer": "A", "n": 3}
    assert back[3].corners == (0,)
    # the schema rejects what the reader rejects
    bad = dict(doc, curves=[dict(doc["curves"][0], degree=1)])
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(bad, schema)


def test_points_type_round_trip(tmp_path):
    pts = [[0, 0], [1, 0.5], [2, 0.25], [3, 1.0], [4, 0.5]]
    p = tmp_path / "p.json"
    p.write_text(json.dumps({"schema_version": 1, "curves": [
        {"type": "points", "name": "probe", "points": pts, "corners": [2]},
        {"type": "points", "closed": True, "points": [[0, 0], [1, 0], [1, 1], [0, 1], [0, 0]]},
    ]}))
    r0, r1 = read_curves(p)
    assert r0.kind == "points" and r0.corners == (2,) and r0.name == "probe"
    np.testing.assert_array_equal(r0.points, pts)
    _same(r0.curve, interpolate_cubic(pts))
    assert r1.curve.closed
    write_curves(tmp_path / "o.json", [r0, r1])
    doc = json.loads((tmp_path / "o.json").read_text())
    assert doc["curves"][0]["points"] == pts and doc["curves"][0]["type"] == "points"
    assert doc["curves"][1]["points"][-1] == [0, 0] and len(doc["curves"][1]["points"]) == 5


@pytest.mark.parametrize("text, match, line", [
    ("", "empty", None),
    ('{"schema_version": 1, "curves": [{"type": "bspline", "degree": 3,\n "knots": [0, 0',
     "invalid JSON", 2),
    ('{"schema_version": 1, "curves": [{"type": "points", "points": [[0, NaN], [1, 1]]}]}',
     "invalid JSON", None),
    ('{"schema_version": 2, "curves": []}', "schema_version must be 1", None),
    ('{"schema_version": 1, "curves": []}', "no curves", None),
    ('[1, 2]', "top level", None),
    ('{"schema_version": 1, "curves": [{"type": "nurbs"}]}', r"curves\[0\].type", None),
    ('{"schema_version": 1, "curves": [{"type": "bspline", "degree": 3, "knots": [0, 1],'
     ' "control_points": [[0, 0], [1, 1], [2, 0], [3, 1]]}]}', r"curves\[0\]: knots must", None),
    ('{"schema_version": 1, "curves": [{"type": "bspline", "degree": 3,'
     ' "control_points": [[0, 0], [1, 1], [2, 0], [3, 1]]}]}', "missing 'knots'", None),
    ('{"schema_version": 1, "curves": [{"type": "points", "points": [[0, 0], [0, 0], [1, 1]]}]}',
     "duplicate consecutive", None),
    ('{"schema_version": 1, "curves": [{"type": "points", "points": [[0,0,0,0], [1,1,1,1]]}]}',
     r"\[x, y\] or \[x, y, z\]", None),
    ('{"schema_version": 1, "curves": [{"type": "points", "points": [[0, 0], [1, 1]], "w": 1}]}',
     "unknown keys", None),
    ('{"schema_version": 1, "curves": [{"type": "points", "points": [[0, 0], [1, 1]],'
     ' "corners": [5]}]}', "out of range", None),
    ('{"schema_version": 1, "curves": [{"type": "cubic_hermite", "degree": 5, "points": [[0,0]],'
     ' "tangents": [[0,0]], "params": [0]}]}', "degree 3", None),
])
def test_malformed_json(tmp_path, text, match, line):
    p = tmp_path / "bad.json"
    p.write_text(text)
    with pytest.raises(FileFormatError, match=match) as exc:
        read_curves(p)
    assert exc.value.path == str(p) and exc.value.line == line


def test_json_round_trip_of_hermite_curves_is_exact_under_random_data(tmp_path):
    rng = np.random.default_rng(3)
    for k in range(5):
        n = int(rng.integers(2, 12))
        pts = np.cumsum(rng.uniform(0.1, 1, (n, 2)), axis=0)
        c = CubicHermite(pts, rng.normal(size=(n, 2)), np.cumsum(rng.uniform(0.1, 2, n)))
        write_curves(tmp_path / f"h{k}.json", c)
        _same(c, read_curves(tmp_path / f"h{k}.json")[0].curve)
