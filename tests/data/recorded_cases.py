"""The recorded fair() cases of tests/test_recorded_cases.py, and the script that records them.

Every registered method on small curves of every kind (cubic and quintic Hermite, B-splines of
degree 3, 4 and 5; open and closed; 2-D and 3-D) under a rotating choice of the shared options
(tol, eps, max_steps, clamp, protect, mode). A case stores what fair() returns: the curve's
defining arrays, steps, stop_reason, the history and every figure of the report (the timings
excepted); a refused case stores the error's class.

Regenerate (only for a documented change of meaning, named in CHANGELOG.md)::

    PYTHONPATH=src python tests/data/recorded_cases.py            # every case
    PYTHONPATH=src python tests/data/recorded_cases.py CASE ...   # only these (others kept)

It writes tests/data/recorded_cases.npz (float64 kept bit for bit).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

import numpy as np

FIXTURE = Path(__file__).with_name("recorded_cases.npz")

# option sets; each (method, curve) pair runs the first one and three of the others in turn
OPTIONS: list[dict[str, Any]] = [
    {},
    {"tol": 1e-2},
    {"tol": 1e-6},
    {"eps": 1e-2},
    {"max_steps": 3},
    {"clamp": "g1", "tol": 0.05},
    {"clamp": "g2"},
    {"clamp": ("g0", "g2"), "max_steps": 20},
    {"clamp": "none", "tol": 0.05},
    {"protect": [3, 5], "tol": 0.05},
    {"eps": 0.3, "tol": 0.1},
    {"mode": "hermite", "tol": 0.05},
]


def curves() -> dict[str, Any]:
    """The curves by name (deterministic: seeded noise on simple shapes)."""
    from curvefair import BSplineCurve, interpolate_cubic, interpolate_quintic

    rng = np.random.default_rng(20261202)
    x = np.linspace(0.0, 3.0, 12)
    opn = np.c_[x, np.sin(x) + 0.04 * rng.standard_normal(12)]
    s = np.linspace(0.0, 4.0, 11)
    helix = np.c_[np.cos(s), np.sin(s), 0.3 * s] + 0.03 * rng.standard_normal((11, 3))
    a = np.linspace(0.0, 2 * np.pi, 13)[:-1]
    ring = np.c_[np.cos(a), 0.7 * np.sin(a)] * (1 + 0.05 * rng.standard_normal(12))[:, None]
    ring3 = np.c_[ring, 0.1 * np.sin(2 * a) + 0.02 * rng.standard_normal(12)]
    ring_c = np.r_[ring, ring[:1]]

    def knots(n: int, p: int) -> np.ndarray:
        return np.r_[[0.0] * p, np.linspace(0.0, 1.0, n - p + 1), [1.0] * p]

    return {
        "h3_open_2d": interpolate_cubic(opn),
        "h3_uniform_2d": interpolate_cubic(opn, param="uniform"),  # kjellander's kind
        "h3_closed_2d": interpolate_cubic(ring_c, bc="periodic"),
        "h3_open_3d": interpolate_cubic(helix),
        "h5_open_2d": interpolate_quintic(opn),
        "h5_closed_2d": interpolate_quintic(ring_c, bc="periodic"),
        "h5_open_3d": interpolate_quintic(helix),
        "bs3_open_2d": BSplineCurve(opn, knots(12, 3), 3),
        "bs3_closed_2d": BSplineCurve(ring, np.arange(13.0), 3, closed=True),
        "bs3_open_3d": BSplineCurve(helix, knots(11, 3), 3),
        "bs4_open_2d": BSplineCurve(opn, knots(12, 4), 4),
        "bs4_closed_3d": BSplineCurve(ring3, np.arange(13.0), 4, closed=True),
        "bs5_open_3d": BSplineCurve(helix, knots(11, 5), 5),
        "bs5_closed_2d": BSplineCurve(ring, np.arange(13.0), 5, closed=True),
    }


def cases() -> list[tuple[str, str, str, dict[str, Any]]]:
    """``(case_id, curve_name, method, options)`` for every recorded case."""
    from curvefair.fairing import available_methods

    pairs = [(cname, m) for cname, c in curves().items() for m in available_methods(c)]
    # the (curve, method) pairs already in the fixture keep their order, hence their option
    # picks; a pair that a later registration adds (a method accepting a new curve kind) comes
    # after them and is recorded on its own, without moving any recorded case
    known: list[tuple[str, str]] = []
    if FIXTURE.exists():
        with np.load(FIXTURE, allow_pickle=False) as z:
            order = json.loads(z["meta"].tobytes().decode("utf-8"))["order"]
        for cid in order:
            cname, m, _ = cid.split("|")
            if (cname, m) not in known:
                known.append((cname, m))
    pairs = [pq for pq in known if pq in pairs] + [pq for pq in pairs if pq not in known]
    out = []
    for j, (cname, m) in enumerate(pairs):
        picks = [0] + [1 + (j + 4 * i) % (len(OPTIONS) - 1) for i in range(3)]
        for k in picks:
            out.append((f"{cname}|{m}|{k}", cname, m, OPTIONS[k]))
    return out


def _flatten(obj: Any, prefix: str, floats: dict[str, float], other: dict[str, Any]) -> None:
    if isinstance(obj, dict):
        for k, v in obj.items():
            _flatten(v, f"{prefix}.{k}" if prefix else str(k), floats, other)
    elif isinstance(obj, list) and obj and all(isinstance(v, float) or v is None for v in obj):
        for i, v in enumerate(obj):
            _flatten(v, f"{prefix}[{i}]", floats, other)
    elif isinstance(obj, float):
        floats[prefix] = obj
    else:
        other[prefix] = obj


def curve_arrays(c: Any) -> dict[str, np.ndarray]:
    """The arrays that define a curve (B-spline: control points and knots; Hermite: points,
    derivatives and parameters)."""
    if hasattr(c, "control_points"):
        return {"control_points": np.asarray(c.control_points), "knots": np.asarray(c.knots)}
    out = {"points": np.asarray(c.points), "params": np.asarray(c.params)}
    for name, d in zip(c._deriv_names, c._derivs, strict=True):
        out[name] = np.asarray(d)
    return out


def run_case(cname: str, method: str, options: dict[str, Any],
             crv: dict[str, Any] | None = None) -> dict[str, Any]:
    """Run one case; the record as plain data (``arrays``: name -> float64/int64 array)."""
    from curvefair import fair
    from curvefair.errors import CurvefairError

    c = (crv or curves())[cname]
    try:
        r = fair(c, method, **options)
    except CurvefairError as exc:
        return {"meta": {"error": type(exc).__name__}, "arrays": {}}
    floats: dict[str, float] = {}
    other: dict[str, Any] = {}
    rep = r.report.to_dict()
    rep.pop("moved", None)  # the same figures as the curve arrays below
    _flatten(rep, "", floats, other)
    for d in (floats, other):  # timings (time_s, driver_time_s ...) are not results
        for k in [k for k in d if k.endswith("time_s")]:
            del d[k]
    arrays = {f"curve.{k}": np.array(v, dtype=np.float64) for k, v in curve_arrays(r.curve).items()}
    h = r.history
    arrays["history.index"] = np.asarray(h.index, dtype=np.int64)
    arrays["history.measure"] = np.asarray(h.measure, dtype=np.float64)
    arrays["history.displacement"] = np.asarray(h.displacement, dtype=np.float64)
    names = sorted(floats)
    arrays["report.floats"] = np.array([floats[k] for k in names], dtype=np.float64)
    return {"meta": {"report": other, "float_names": names}, "arrays": arrays}


def load() -> dict[str, dict[str, Any]]:
    """The recorded cases, by case id."""
    out: dict[str, dict[str, Any]] = {}
    with np.load(FIXTURE, allow_pickle=False) as z:
        doc = json.loads(z["meta"].tobytes().decode("utf-8"))
        data = {k: z[k] for k in z.files if k != "meta"}
    for cid in doc["order"]:
        meta = doc["meta"][cid]
        arrays = {}
        for field, (dtype, start, shape) in doc["layout"][cid].items():
            size = int(np.prod(shape, dtype=np.int64))
            arrays[field] = data[dtype][start:start + size].reshape(shape)
        out[cid] = {"meta": meta, "arrays": arrays}
    return out


def write(records: dict[str, dict[str, Any]]) -> None:
    """Write the fixture atomically: the metadata as one JSON text, the arrays concatenated
    by dtype (one float64 and one int64 array; the layout says where each one lies)."""
    chunks: dict[str, list[np.ndarray]] = {"float64": [], "int64": []}
    fill = {"float64": 0, "int64": 0}
    layout: dict[str, dict[str, Any]] = {}
    for cid, rec in records.items():
        lay = layout[cid] = {}
        for k, v in rec["arrays"].items():
            dt = "int64" if v.dtype.kind in "iu" else "float64"
            a = np.ascontiguousarray(v, dtype=dt)
            lay[k] = [dt, fill[dt], list(a.shape)]
            chunks[dt].append(a.reshape(-1))
            fill[dt] += a.size
    doc = {"order": list(records), "layout": layout,
           "meta": {cid: rec["meta"] for cid, rec in records.items()}}
    blob = json.dumps(doc, sort_keys=True, separators=(",", ":")).encode("utf-8")
    flat = {"meta": np.frombuffer(blob, dtype=np.uint8)}
    for dt, parts in chunks.items():
        flat[dt] = np.concatenate(parts) if parts else np.zeros(0, dtype=dt)
    tmp = FIXTURE.with_suffix(".tmp.npz")
    np.savez_compressed(tmp, **flat)  # type: ignore[arg-type]
    tmp.replace(FIXTURE)


def main(argv: list[str]) -> int:
    only = set(argv)
    crv = curves()
    records = load() if only and FIXTURE.exists() else {}
    all_cases = cases()
    unknown = only - {c[0] for c in all_cases}
    if unknown:
        print("unknown case ids:", ", ".join(sorted(unknown)), file=sys.stderr)
        return 2
    for cid, cname, m, opts in all_cases:
        if only and cid not in only:
            continue
        records[cid] = run_case(cname, m, opts, crv)
    records = {c[0]: records[c[0]] for c in all_cases if c[0] in records}
    write(records)
    n_err = sum(1 for r in records.values() if "error" in r["meta"])
    print(f"wrote {len(records)} cases ({n_err} refused) to {FIXTURE}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
