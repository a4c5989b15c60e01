"""Fairing many files: input expansion, per-file work, reports, resuming, processes and Dask.

The unit of work is one file, :func:`fair_file`: read it with :func:`curvefair.read_curves`,
fair the selected curves with :func:`curvefair.fair`, write the result through
:func:`curvefair.io.write_checked` (temporary file, read back, measured against the
input, moved onto the output only when every curve is within ``tol``) and write a per-file
JSON report. The same function runs in this process, in a pool of processes
(:func:`fair_files` with ``jobs``) or on Dask distributed workers (``client``); its result
depends only on the input file's bytes and the options, so all three give the same bytes.

Resuming
--------
A per-file report records ``input_sha256`` (the input's bytes), ``options_sha256`` (the
canonical JSON of every option that changes the output, the output format and the curvefair
version) and ``output_sha256`` (the bytes written). With ``resume=True`` a file is skipped
when its report says ``status: "ok"``, both hashes equal today's and the output on disk still
has the recorded hash: the output is exactly what this run would write.

Selection
---------
``layer``, ``name`` and ``handle`` are lists of glob patterns (:func:`fnmatch.fnmatchcase`)
matched against a record's ``source["layer"]``, ``name`` and ``source["handle"]`` or
``source["id"]`` (DXF handles, Rhino GUIDs, SVG element ids). A record is selected when, for
every option given, one of its patterns matches; a record without the field is not selected.
Unselected curves are written back untouched (their record unchanged).

Hull networks
-------------
``hold_shared=True`` protects every point (data points of point lists, control points of
splines) that lies within ``shared_distance`` of a point of another curve of the same file
(default ``1e-9`` times the drawing's bounding-box diagonal): station / longitudinal
intersections of an offsets table stay where they are in both curves, so the network stays
connected. Where two records cross elsewhere (inside a B-spline's knot span, between two
vertices of point data), :func:`shared_crossings` finds the crossing and holds the points
that make it: the ``degree + 1`` control points of the span of a B-spline (the crossing
stays exactly), the vertices around the segment of point data (it stays to about
``2.7e-5`` of the moves beyond them).
"""

from __future__ import annotations

import contextlib
import fnmatch
import glob as _glob
import hashlib
import json
import os
import re
import signal
import sys
import tempfile
import time
import warnings
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from ._fileid import file_key
from ._version import __version__
from .errors import CurvefairError, InputError

if TYPE_CHECKING:
    from .io import FormatName

__all__ = ["fair_files", "fair_file", "fair_chunked", "plan_inputs", "Job", "file_sha256",
           "options_digest", "parse_methods", "REPORT_DIR"]

#: Folder (inside the output folder) holding the per-file reports and the run report.
REPORT_DIR = ".curvefair"
#: Options that change what is written (hashed for ``resume``).
OUTPUT_OPTIONS = ("method", "tol", "eps", "max_steps", "clamp", "protect", "mode",
                  "method_options", "decimals", "corner_angle", "strict", "layer", "name",
                  "handle", "hold_shared", "shared_distance", "format", "polylines", "columns")
_DEFAULTS: dict[str, Any] = {"method": None, "tol": None, "eps": None, "max_steps": None,
                             "clamp": "g0", "protect": (), "mode": "spline",
                             "method_options": {}, "decimals": None, "corner_angle": 60.0,
                             "strict": False, "layer": (), "name": (), "handle": (),
                             "hold_shared": False, "shared_distance": None, "history": False,
                             "format": None, "polylines": False, "columns": None}
_GLOB_CHARS = re.compile(r"[*?\[]")


# ------------------------------------------------------------------------------------------
# options
# ------------------------------------------------------------------------------------------
def parse_methods(value: str | Mapping[str, str] | None) -> dict[str, str | None]:
    """``"bspline=global,points=poliakoff"`` -> ``{"bspline": "global", "points":
    "poliakoff"}``; a plain ``"NAME"`` -> ``{"*": "NAME"}``; None -> ``{"*": None}``.

    Keys are record kinds (:data:`curvefair.io.KINDS`) or ``*`` (every other kind); values
    method names of :data:`curvefair.fairing.METHODS`.
    """
    from .fairing import METHODS
    from .io import KINDS

    if value is None:
        return {"*": None}
    if isinstance(value, Mapping):
        items = list(value.items())
    elif "=" not in value:
        items = [("*", value.strip())]
    else:
        items = []
        for tok in value.split(","):
            tok = tok.strip()
            if not tok:
                continue
            k, sep, v = tok.partition("=")
            if not sep:
                k, v = "*", tok
            items.append((k.strip(), v.strip()))
    out: dict[str, str | None] = {"*": None}
    for k, v in items:
        if k not in KINDS and k != "*":
            raise InputError(f"method: {k!r} is not a curve kind; valid: *, " + ", ".join(KINDS))
        if v not in METHODS:
            raise InputError(f"method: unknown method {v!r} for {k!r}; valid: "
                             + ", ".join(METHODS))
        out[k] = v
    return out


def _options(options: Mapping[str, Any]) -> dict[str, Any]:
    bad = sorted(set(options) - set(_DEFAULTS))
    if bad:
        raise InputError(f"fair_files: unknown option {bad[0]!r}; valid: "
                         + ", ".join(sorted(_DEFAULTS)))
    opts = dict(_DEFAULTS)
    opts.update(options)
    for key in ("protect", "layer", "name", "handle"):
        v = opts[key]
        opts[key] = (v,) if isinstance(v, (str, int)) else tuple(v or ())
    opts["methods"] = parse_methods(opts["method"])
    return opts


def _jsonable(v: Any) -> Any:
    if isinstance(v, Mapping):
        return {str(k): _jsonable(x) for k, x in sorted(v.items(), key=lambda kv: str(kv[0]))}
    if isinstance(v, (list, tuple)):
        return [_jsonable(x) for x in v]
    if isinstance(v, float) and not np.isfinite(v):
        return repr(v)
    if v is None or isinstance(v, (bool, int, float, str)):
        return v
    return repr(v)


def options_digest(options: Mapping[str, Any], out_format: str | None = None) -> str:
    """SHA-256 of the canonical JSON of the output-changing options, the output format and the
    curvefair version (what ``resume`` compares)."""
    opts = _options({k: v for k, v in options.items() if k != "methods"})
    sel = {k: opts[k] for k in OUTPUT_OPTIONS}
    sel["method"] = opts["methods"]
    blob = json.dumps({"options": _jsonable(sel), "out_format": out_format,
                       "curvefair": __version__}, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(blob.encode()).hexdigest()


def file_sha256(path: str | os.PathLike[str]) -> str:
    """SHA-256 of a file's bytes; of a folder (a UFO font), of every file in it: each relative
    path (``/``-separated, sorted) and the SHA-256 of its bytes."""
    if os.path.isdir(path):
        h = hashlib.sha256(b"folder\0")
        found = []
        for root, dirs, files in os.walk(path):
            dirs.sort()
            for name in files:
                full = os.path.join(root, name)
                found.append((os.path.relpath(full, path).replace(os.sep, "/"), full))
        for rel, full in sorted(found):
            h.update(rel.encode("utf-8") + b"\0" + file_sha256(full).encode() + b"\n")
        return h.hexdigest()
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


# ------------------------------------------------------------------------------------------
# inputs and outputs
# ------------------------------------------------------------------------------------------
@dataclass
class Job:
    """One file to fair: where it is read, where its output and report go."""

    input: str
    output: str
    report: str | None
    rel: str = ""
    display: str = ""
    meta: dict[str, Any] = field(default_factory=dict)


def _known_exts() -> tuple[str, ...]:
    from .io import FORMATS

    return tuple(e for exts in FORMATS.values() for e in exts)


_file_key = file_key


def _glob_base(pattern: str) -> str:
    parts = Path(pattern).parts
    base: list[str] = []
    for part in parts:
        if _GLOB_CHARS.search(part):
            break
        base.append(part)
    return str(Path(*base)) if base else "."


def _walk(folder: str, skip: set[tuple[Any, ...]]) -> Iterator[str]:
    """Files with a known extension under ``folder``, sorted, hidden files and folders (and
    the folders in ``skip``, e.g. the output folder) left out."""
    exts = _known_exts()
    for root, dirs, files in os.walk(folder, followlinks=False):
        dirs[:] = sorted(d for d in dirs if not d.startswith(".")
                         and _file_key(os.path.join(root, d)) not in skip)
        fonts = [d for d in dirs if d.lower().endswith(".ufo")]  # a UFO font is a folder
        dirs[:] = [d for d in dirs if d not in fonts]
        yield from (os.path.join(root, d) for d in fonts)
        for f in sorted(files):
            if not f.startswith(".") and f.lower().endswith(exts):
                yield os.path.join(root, f)


def expand_inputs(paths: Sequence[str], skip_dirs: Sequence[str] = ()) -> list[tuple[str, str]]:
    """``(file, path relative to where it was found)`` for every input: files as given,
    folders walked (known extensions), glob patterns (``**`` recursive) expanded. ``-`` is
    kept as is (stdin). The same file named twice (any spelling) is kept once.

    Raises
    ------
    InputError
        A path that does not exist and matches nothing.
    """
    skip = {_file_key(d) for d in skip_dirs if os.path.isdir(d)}
    out: list[tuple[str, str]] = []
    seen: set[tuple[Any, ...]] = set()

    def add(p: str, rel: str) -> None:
        if p == "-":
            out.append((p, rel))
            return
        k = _file_key(p)
        if k not in seen:
            seen.add(k)
            out.append((p, rel))

    for p in paths:
        if p == "-":
            add(p, "-")
        elif os.path.isdir(p) and not os.path.normpath(p).lower().endswith(".ufo"):
            for f in _walk(p, skip):
                add(f, os.path.relpath(f, p))
        elif os.path.exists(p):
            add(p, os.path.basename(p))
        elif _GLOB_CHARS.search(p):
            hits = sorted(h for h in _glob.glob(p, recursive=True) if os.path.isfile(h))
            if not hits:
                raise InputError(f"{p!r}: no file matches")
            base = _glob_base(p)
            for h in hits:
                add(h, os.path.relpath(h, base))
        else:
            raise InputError(f"{p!r} does not exist")
    return out


def plan_inputs(paths: Sequence[str], out_dir: str | None, *, in_place: bool = False,
                stdin_format: str | None = None) -> list[Job]:
    """The jobs for ``paths``: one per file, output ``out_dir/<relative path>`` (or the input
    itself with ``in_place``), per-file report ``<out folder>/.curvefair/<relative>.json``.

    Raises
    ------
    InputError
        An input that does not exist, two inputs with one output, an output that is an input
        (same inode, any spelling or link) without ``in_place``.
    """
    if out_dir is None and not in_place:
        raise InputError("an output folder is needed (or in_place=True)")
    found = expand_inputs(paths, [out_dir] if out_dir else [])
    if not found:
        raise InputError("no input files")
    jobs: list[Job] = []
    for p, rel in found:
        if p == "-":
            ext = _stdin_ext(stdin_format)
            rel = "stdin" + ext
        if in_place:
            if p == "-":
                raise InputError("'-' (stdin) cannot be faired in place")
            folder = os.path.dirname(os.path.abspath(p))
            rep = os.path.join(folder, REPORT_DIR, os.path.basename(p) + ".json")
            jobs.append(Job(p, p, rep, os.path.basename(p), p))
        else:
            assert out_dir is not None
            jobs.append(Job(p, os.path.join(out_dir, rel),
                            os.path.join(out_dir, REPORT_DIR, rel + ".json"), rel,
                            "<stdin>" if p == "-" else p))
    ins = {_file_key(j.input): j.input for j in jobs if j.input != "-"}
    seen: dict[tuple[Any, ...], str] = {}
    for j in jobs:
        for what, path in (("output", j.output), ("report", j.report)):
            if path is None:
                continue
            k = _file_key(path)
            if k in ins and not (in_place and what == "output" and ins[k] == j.input):
                raise InputError(f"the {what} {path!r} is the input file {ins[k]!r}")
            if k in seen:
                raise InputError(f"{seen[k]!r} and {j.display!r} would both be written to "
                                 f"{path!r}")
            seen[k] = j.display
    return jobs


def _stdin_ext(fmt: str | None) -> str:
    from .io import FORMATS

    if fmt is None:
        raise InputError("'-' (stdin) has no file name: give its format (format=, --format); "
                         "one of " + ", ".join(FORMATS))
    if fmt not in FORMATS:
        raise InputError(f"format {fmt!r} unknown; valid: " + ", ".join(FORMATS))
    return FORMATS[fmt][0]


# ------------------------------------------------------------------------------------------
# selection and shared points
# ------------------------------------------------------------------------------------------
def _handle_of(rec: Any) -> str | None:
    for key in ("handle", "id"):
        v = rec.source.get(key)
        if v is not None:
            return str(v)
    return None


def selected(rec: Any, opts: Mapping[str, Any]) -> bool:
    """Whether ``rec`` passes the ``layer`` / ``name`` / ``handle`` glob filters."""
    for key, value in (("layer", rec.source.get("layer")), ("name", rec.name),
                       ("handle", _handle_of(rec))):
        pats = opts.get(key) or ()
        if not pats:
            continue
        if value is None or not any(fnmatch.fnmatchcase(str(value), p) for p in pats):
            return False
    return True


def _movable_points(rec: Any) -> np.ndarray | None:
    """What ``protect`` indexes for ``rec``: data points of point kinds (``rec.points``),
    else the curve's control points (B-spline) or points (Hermite)."""
    if rec.points is not None:
        return np.asarray(rec.points)
    for attr in ("control_points", "points"):
        v = getattr(rec.curve, attr, None)
        if v is not None:
            return np.asarray(v)
    return None


def _curve_points(curve: Any) -> np.ndarray | None:
    """The points a method moves: control points of a B-spline, else the curve's points."""
    for attr in ("control_points", "points"):
        v = getattr(curve, attr, None)
        if v is not None:
            return np.asarray(v)
    return None


def shared_points(records: Sequence[Any], distance: float | None = None) -> list[list[int]]:
    """For every record, the indices of its points (see :func:`_movable_points`) within
    ``distance`` of a point of another record (default: ``1e-9`` times the bounding-box
    diagonal of all points)."""
    from scipy.spatial import cKDTree

    pts = [_movable_points(r) for r in records]
    have = [p for p in pts if p is not None and len(p)]
    if len(have) < 2:
        return [[] for _ in records]
    dims = {p.shape[1] for p in have}
    dim = max(dims)
    pad = [np.c_[p, np.zeros((len(p), dim - p.shape[1]))] if p.shape[1] < dim else p
           for p in have]
    allp = np.vstack(pad)
    owner = np.concatenate([np.full(len(p), k) for k, p in enumerate(pad)])
    if distance is None:
        span = float(np.linalg.norm(allp.max(axis=0) - allp.min(axis=0)))
        distance = 1e-9 * span
    tree = cKDTree(allp)
    out: list[list[int]] = []
    k = 0
    for p in pts:
        if p is None or not len(p):
            out.append([])
            continue
        mine = pad[k]
        hits = tree.query_ball_point(mine, r=distance)
        out.append([i for i, h in enumerate(hits) if any(owner[j] != k for j in h)])
        k += 1
    return out


def _span_support(curve: Any, u: float) -> set[int]:
    """Control-point indices of the ``degree + 1`` basis functions of the knot span holding
    ``u`` (both spans when ``u`` is within rounding of a knot): holding them keeps ``C(u)``."""
    p = curve.degree
    t = np.asarray(curve.knots)
    lo, hi = curve.domain
    u = min(max(u, lo), hi)
    out: set[int] = set()
    eps = 1e-12 * max(hi - lo, 1e-300)
    for v in {u - eps, u, u + eps}:
        v = min(max(v, lo), hi)
        k = int(np.searchsorted(t, v, side="right")) - 1
        k = min(max(k, p), t.shape[0] - p - 2)
        while k > p and t[k] == t[k + 1]:  # an empty span at the domain's end
            k -= 1
        out.update(int(i) for i in curve.control_index(np.arange(k - p, k + 1)))
    return out


def _samples(curve: Any, per_span: int = 16) -> tuple[np.ndarray, np.ndarray]:
    """``(u, C(u))`` at ``per_span`` equal steps in every knot span (ends included)."""
    br = np.asarray(curve.piecewise.breaks)
    f = np.linspace(0.0, 1.0, per_span, endpoint=False)
    u = np.append((br[:-1, None] + f[None, :] * np.diff(br)[:, None]).ravel(), br[-1])
    return u, np.asarray(curve(u))


def _held_shared(records: Sequence[Any], distance: float | None) -> list[list[int]]:
    """:func:`shared_points` and :func:`shared_crossings` together, per record."""
    pts = shared_points(records, distance)
    cross = shared_crossings(records, distance)
    return [sorted(set(a) | set(b)) for a, b in zip(pts, cross, strict=True)]


#: Point data: vertices held on each side of a crossing's segment (see :func:`shared_crossings`).
SHARED_HOLD = 8


def _is_spline(curve: Any) -> bool:
    from .curves.bspline import BSplineCurve

    return isinstance(curve, BSplineCurve)


def _is_points(curve: Any) -> bool:
    """An interpolating Hermite curve (point data): vertices ``points`` at ``params``."""
    from .curves.hermite import HermiteSpline

    return isinstance(curve, HermiteSpline)


def _hermite_support(curve: Any, u: float, m: int) -> set[int]:
    """Data-point indices of the ``m`` vertices on each side of the segment holding ``u``
    (both segments when ``u`` is within rounding of a vertex), wrapped for a closed curve."""
    t = np.asarray(curve.params)
    lo, hi = float(t[0]), float(t[-1])
    n = t.shape[0]
    n_data = n - 1 if curve.closed else n
    out: set[int] = set()
    eps = 1e-12 * max(hi - lo, 1e-300)
    for v in {u - eps, u, u + eps}:
        v = min(max(v, lo), hi)
        seg = min(max(int(np.searchsorted(t, v, side="right")) - 1, 0), n - 2)
        for i in range(seg - m + 1, seg + m + 1):
            if curve.closed:
                out.add(i % n_data)
            elif 0 <= i < n:
                out.add(i)
    return out


def shared_crossings(records: Sequence[Any], distance: float | None = None
                     ) -> list[list[int]]:
    """For every B-spline and point-data record, the points to hold so that each place where
    it meets another such record of the file -- a crossing inside a knot span or between two
    vertices, not at a shared point -- stays where it is in both curves.

    Two curves meet at ``(u, v)`` when ``|A(u) - B(v)| <= distance`` (default ``1e-9`` times
    the bounding-box diagonal of all their points). Candidates are the local minima along
    ``A``'s samples (16 per span) of the distance to ``B``'s nearest sample, refined by
    Gauss-Newton on ``A(u) - B(v)`` (scipy ``least_squares``, bounded to the domains).

    What is held, per curve:

    - B-spline: the ``degree + 1`` control points whose basis functions are non-zero at
      ``u``; ``A(u) = sum_i N_i(u) P_i`` is then exactly unchanged.
    - Point data (interpolating Hermite curves: point lists, polylines, airfoils; the curve
      is re-interpolated through the points after every step and on reading): a crossing at
      one of its vertices (within ``distance``) holds that vertex, which keeps it exactly;
      else the :data:`SHARED_HOLD` vertices on each side of the segment holding ``u``. The segment
      depends on its two end vertices and their tangents, and the C2 spline's tangents on the
      other vertices with a weight that falls by ``2 - sqrt 3`` (about 0.27) per vertex for
      even spacing (at least 1/2 for any spacing: the tangent system is diagonally
      dominant; de Boor, A Practical Guide to Splines, ch. IV), so a move of ``d`` outside
      the held vertices shifts the crossing by about ``0.27^SHARED_HOLD d``, ``2.7e-5 d``.
    """
    from scipy.optimize import least_squares
    from scipy.spatial import cKDTree

    out: list[set[int]] = [set() for _ in records]
    idx = [k for k, r in enumerate(records)
           if _is_spline(r.curve) or (_is_points(r.curve) and len(r.curve.params) >= 2)]
    if len(idx) < 2:
        return [[] for _ in records]
    dim = max(records[k].curve.dim for k in idx)

    def pad(x: np.ndarray) -> np.ndarray:
        x = np.atleast_2d(x)
        return np.c_[x, np.zeros((x.shape[0], dim - x.shape[1]))] if x.shape[1] < dim else x

    def support(curve: Any, u: float) -> set[int]:
        if _is_spline(curve):
            return _span_support(curve, u)
        # an interpolating curve passes through its vertices: a crossing at one is held by
        # holding that vertex alone (two curves sharing a vertex: what shared_points holds)
        P = np.asarray(curve.points)
        d = np.linalg.norm(pad(P) - pad(np.asarray(curve(np.array([u])))), axis=1)
        i = int(np.argmin(d))
        if d[i] <= distance:
            n_data = P.shape[0] - 1 if curve.closed else P.shape[0]
            return {i % n_data}
        return _hermite_support(curve, u, SHARED_HOLD)

    if distance is None:
        allp = np.vstack([pad(np.asarray(_curve_points(records[k].curve))) for k in idx])
        distance = 1e-9 * float(np.linalg.norm(allp.max(axis=0) - allp.min(axis=0)))
    samp = {k: _samples(records[k].curve) for k in idx}
    trees = {k: cKDTree(pad(samp[k][1])) for k in idx}
    for ia, a in enumerate(idx):
        ca = records[a].curve
        ua, xa = samp[a][0], pad(samp[a][1])
        for b in idx[ia + 1:]:
            cb = records[b].curve
            ub = samp[b][0]
            d, j = trees[b].query(xa)
            # a crossing lies within a sample step of both polylines
            step = max(float(np.linalg.norm(np.diff(xa, axis=0), axis=1).max()),
                       float(np.linalg.norm(np.diff(pad(samp[b][1]), axis=0), axis=1).max()))
            near = d <= step + distance
            if not near.any():
                continue
            dd = np.where(near, d, np.inf)
            loc = np.flatnonzero(near & (dd <= np.r_[np.inf, dd[:-1]])
                                 & (dd <= np.r_[dd[1:], np.inf]))
            (la, ha), (lb, hb) = ca.domain, cb.domain

            def res(x: np.ndarray, ca: Any = ca, cb: Any = cb) -> np.ndarray:
                return (pad(np.asarray(ca(np.array([x[0]])))) -
                        pad(np.asarray(cb(np.array([x[1]])))))[0]

            seen: list[tuple[float, float]] = []
            for i in loc[:1000]:
                x0 = np.array([ua[i], ub[j[i]]])
                sol = least_squares(res, x0, bounds=([la, lb], [ha, hb]), xtol=1e-15,
                                    ftol=1e-15, gtol=1e-15, max_nfev=100)
                u, v = float(sol.x[0]), float(sol.x[1])
                if float(np.linalg.norm(res(sol.x))) > distance:
                    continue
                if any(abs(u - s0) <= 1e-9 * (ha - la) and abs(v - s1) <= 1e-9 * (hb - lb)
                       for s0, s1 in seen):
                    continue
                seen.append((u, v))
                out[a].update(support(ca, u))
                out[b].update(support(cb, v))
    return [sorted(o) for o in out]


# ------------------------------------------------------------------------------------------
# one file
# ------------------------------------------------------------------------------------------
def _nothing_to_fair(rec: Any) -> bool:
    pts = rec.points
    if pts is None:
        return False
    return len(pts) - (1 if getattr(rec.curve, "closed", False) else 0) <= 2


def _local_protect(rec: Any, user: Sequence[int]) -> list[int]:
    idx = rec.source.get("indices")
    if idx is not None and user:
        pos = {int(fi): k for k, fi in enumerate(idx)}
        mine = [pos[i] for i in user if i in pos]
    else:
        mine = list(user)
    return sorted(set(mine) | set(rec.corners))


def _label(rec: Any, i: int) -> str:
    return rec.name if rec.name else f"curve {i}"


def _change(before: Any, after: Any) -> dict[str, Any]:
    """Points moved between two records of one curve: count and largest move."""
    a, b = _curve_points(before.curve), _curve_points(after.curve)
    if a is None or b is None or a.shape != b.shape:
        return {"points": None if a is None else int(len(a)), "moved": None,
                "max_move": None}
    d = np.linalg.norm(b - a, axis=1)
    return {"points": int(len(a)), "moved": int(np.count_nonzero(d)),
            "max_move": float(d.max()) if d.size else 0.0}


def _read(path: str, opts: Mapping[str, Any], notes: list[str] | None = None,
          fmt: str | None = None) -> list[Any]:
    from . import read_curves

    poly: bool | None = None
    cols: tuple[int, ...] | None = None
    if opts.get("polylines") or opts.get("columns") is not None:
        # drawings only: point data are point lists always; columns: points files only
        from .io import columns_for, detect_format, polylines_for

        try:
            kind: str | None = detect_format(path, cast("FormatName | None", fmt))
        except CurvefairError:
            kind = None  # read_curves says why
        poly = polylines_for(kind, bool(opts.get("polylines")))
        cols = columns_for(kind, opts.get("columns"))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            recs = read_curves(path, corner_angle=opts["corner_angle"],
                               format=cast("FormatName | None", fmt),
                               on_unsupported="raise" if opts["strict"] else "skip",
                               polylines=poly, columns=cols)
        finally:  # the skip warnings also when the file then holds no curve at all
            if notes is not None:
                notes.extend(dict.fromkeys(str(w.message) for w in caught))
    return recs


def _all_skipped(exc: BaseException, notes: list[str], opts: Mapping[str, Any]
                 ) -> tuple[int, int]:
    """``(skipped, drawn)``: the numbers of skipped unsupported entities and of SVG shapes
    left as drawn when ``exc`` says a file holds no curve only because of them (then it is
    written back unchanged, as ``curvefair fair`` does for one file); ``(0, 0)`` otherwise."""
    if not isinstance(exc, CurvefairError) or "no curves in the" not in str(exc):
        return 0, 0
    drawn = int(getattr(exc, "n_drawn", 0))
    if opts["strict"]:
        return 0, drawn
    return sum(": skipped " in n for n in notes), drawn


def _nothing_why(n_skipped: int, n_drawn: int, font: bool = False) -> str:
    """Why a file has nothing to fair, for a note (``font``: the drawn shapes are a font's
    contours of straight lines)."""
    why = []
    if n_skipped:
        why.append(f"{n_skipped} unsupported entit{'y' if n_skipped == 1 else 'ies'} skipped, "
                   "see the warnings")
    if n_drawn and font:
        why.append(f"{n_drawn} contour{'s' if n_drawn > 1 else ''} of straight lines only")
    elif n_drawn:
        why.append(f"{n_drawn} straight-line shape{'s' if n_drawn > 1 else ''} left as drawn: "
                   "--polylines fairs them as point lists")
    return "; ".join(why)


def _test_delay() -> None:
    """Test hook: ``CURVEFAIR_TEST_FILE_DELAY`` seconds of sleep before each file's write and
    each chunk's fair (the worker-killed-mid-run tests need tasks that take long enough to be
    caught running)."""
    d = os.environ.get("CURVEFAIR_TEST_FILE_DELAY")
    if d:
        time.sleep(float(d))


def fair_file(infile: str, outfile: str | None, options: Mapping[str, Any] | None = None, *,
              report: str | None = None, dry_run: bool = False,
              progress: Callable[[str, Any], None] | None = None,
              in_format: str | None = None, out_format: str | None = None) -> dict[str, Any]:
    """Fair one file; return its report (a JSON-serialisable dict); never raise for bad input.

    An unexpected error (a bug, or a library failing on a file) is a ``failed`` report naming
    the exception too, so one file never stops a run; nothing is written for it.
    """

    _options(options or {})  # unknown options: the caller's error, raised
    try:
        return _fair_file(infile, outfile, options, report=report, dry_run=dry_run,
                          progress=progress, in_format=in_format, out_format=out_format)
    except (KeyboardInterrupt, SystemExit, _Terminated):
        raise
    except Exception as exc:  # noqa: BLE001 - reported per file, see the docstring
        return {"curvefair": __version__, "input": infile, "output": outfile,
                "status": "failed", "dry_run": bool(dry_run),
                "error": f"unexpected {type(exc).__name__}: {exc}"}


def _fair_file(infile: str, outfile: str | None, options: Mapping[str, Any] | None = None, *,
               report: str | None = None, dry_run: bool = False,
               progress: Callable[[str, Any], None] | None = None,
               in_format: str | None = None, out_format: str | None = None) -> dict[str, Any]:
    """The work of :func:`fair_file`; ``fair_file``'s contract, except that it may raise.

    ``outfile`` None or ``dry_run``: nothing is written (the report says what would change).
    ``report``: also write the report there (atomically). ``progress(event, value)`` is called
    with ``("curves", n)`` once the file is read, ``("phase", (done, total))`` after each phase
    of a curve's :func:`curvefair.fair` (its ``progress``), ``("curve", 1)`` after each curve,
    and ``("write", 0)`` / ``("write", 1)`` around the checked write.
    ``status`` is ``"ok"``, ``"failed"`` (nothing written: unreadable input, every selected
    curve failed, or the written file would not read back within ``tol``), ``"partial"`` (some
    curves failed: written with those unchanged) or ``"dry-run"``.
    """
    from . import fair
    from .io import detect_format

    opts = _options(options or {})
    t0 = time.perf_counter()
    rep: dict[str, Any] = {"curvefair": __version__, "input": infile, "output": outfile,
                           "status": "failed", "dry_run": bool(dry_run)}
    read_notes: list[str] = []
    fmt_in = fmt_out = ""
    try:
        fmt_in = detect_format(infile, in_format)
        fmt_out = out_format or (fmt_in if outfile is None
                                 else _out_format(infile, outfile, in_format))
        rep.update(format=fmt_out, input_sha256=file_sha256(infile),
                   options=_jsonable({k: opts[k] for k in OUTPUT_OPTIONS}),
                   options_sha256=options_digest(options or {}, fmt_out))
        records = _read(infile, opts, read_notes, fmt_in)
        if read_notes:
            rep["read_warnings"] = read_notes
    except (CurvefairError, OSError) as exc:
        n_skipped, n_drawn = _all_skipped(exc, read_notes, opts)
        if (n_skipped or n_drawn) and fmt_in and fmt_out == fmt_in:
            # nothing curvefair can fair: the output is the input's bytes
            font = not getattr(exc, "polylines_option", True)
            rep.update(status="ok" if not dry_run else "dry-run", n_curves=0,
                       n_skipped_unsupported=n_skipped, n_drawn_shapes=n_drawn,
                       read_warnings=read_notes,
                       note=f"nothing to fair ({_nothing_why(n_skipped, n_drawn, font)}); "
                            "written unchanged")
            if outfile is not None and not dry_run:
                from .io import atomic_path, copy_input

                same = os.path.exists(outfile) and os.path.samefile(infile, outfile)
                if not same:
                    os.makedirs(os.path.dirname(os.path.abspath(outfile)), exist_ok=True)
                    with atomic_path(outfile) as tmp:
                        copy_input(infile, tmp)
                rep["output_sha256"] = file_sha256(outfile)
            rep["time_s"] = time.perf_counter() - t0
            return _finish(rep, report, dry_run)
        rep["error"] = _err(exc)
        rep["time_s"] = time.perf_counter() - t0
        return _finish(rep, report, dry_run)
    if progress is not None:
        progress("curves", len(records))
    shared = (_held_shared(records, opts["shared_distance"]) if opts["hold_shared"]
              else [[] for _ in records])
    rows: list[dict[str, Any]] = []
    faired = []
    for i, rec in enumerate(records):
        row: dict[str, Any] = {"index": i, "label": _label(rec, i), "name": rec.name,
                               "kind": rec.kind, "layer": rec.source.get("layer"),
                               "handle": _handle_of(rec)}
        method = opts["methods"].get(rec.kind, opts["methods"]["*"])
        if not selected(rec, opts):
            row["status"] = "not selected"
            faired.append(rec)
        elif _nothing_to_fair(rec):
            row["status"] = "nothing to fair"
            faired.append(rec)
        else:
            notes: list[str] = []
            prot = sorted(set(_local_protect(rec, opts["protect"])) | set(shared[i]))
            if shared[i]:
                row["shared_points_held"] = len(shared[i])
            phase = None
            if progress is not None:
                def phase(done: int, total: int, _p: Any = progress) -> None:
                    _p("phase", (done, total))
            try:
                with warnings.catch_warnings(record=True) as caught:
                    warnings.simplefilter("always")
                    res = fair(rec.curve, method, tol=opts["tol"], eps=opts["eps"],
                               max_steps=opts["max_steps"], clamp=opts["clamp"], protect=prot,
                               mode=opts["mode"], progress=phase,
                               **dict(opts["method_options"]))
                notes = list(dict.fromkeys(str(w.message) for w in caught))
            except CurvefairError as exc:
                row.update(status="failed", error=str(exc))
                faired.append(rec)
            else:
                new = rec.with_curve(res.curve)
                row.update(status="ok", report=_jsonable(res.report), change=_change(rec, new))
                if notes:
                    row["warnings"] = notes
                if opts["history"]:
                    row["history"] = _jsonable(res.history.to_dict())
                faired.append(new)
        rows.append(row)
        if progress is not None:
            progress("curve", 1)
    failed = [r for r in rows if r["status"] == "failed"]
    tried = [r for r in rows if r["status"] in ("ok", "failed")]
    rep.update(n_curves=len(rows), n_selected=len(tried), n_failed=len(failed), curves=rows)
    if dry_run or outfile is None:
        rep["status"] = "dry-run"
    elif tried and len(failed) == len(tried):
        rep["error"] = "every selected curve failed; nothing written"
    else:
        _test_delay()
        if progress is not None:
            progress("write", 0)
        try:
            check = _write(outfile, faired, records, infile, fmt_in, fmt_out, opts,
                           in_place=_file_key(outfile) == _file_key(infile))
        except (CurvefairError, OSError) as exc:
            rep["error"] = _err(exc)
        else:
            from .io import on_disk_report

            for i, (row, d, kind) in enumerate(zip(rows, check.deviations, check.kinds,
                                                   strict=True)):
                if row["status"] == "ok":
                    if check.read_back:  # the after-figures of what is on disk
                        row["report"] = _jsonable(on_disk_report(
                            row["report"], records[i].curve, faired[i].curve,
                            check.read_back[i], check.move_scale[i]))
                    row["report"]["on_disk_deviation"] = d
                    row["report"]["on_disk_deviation_kind"] = kind
            rep["output_check"] = _jsonable(check.to_dict())
            rep["output_sha256"] = file_sha256(outfile)
            rep["status"] = "partial" if failed else "ok"
        if progress is not None:
            progress("write", 1)
    rep["time_s"] = time.perf_counter() - t0
    return _finish(rep, report, dry_run)


def _err(exc: BaseException) -> str:
    if isinstance(exc, OSError) and not isinstance(exc, CurvefairError):
        where = f"{exc.filename}: " if getattr(exc, "filename", None) else ""
        return f"{where}{exc.strerror or exc}"
    return str(exc)


def _write(outfile: str, faired: list[Any], records: list[Any], infile: str, fmt_in: str,
           fmt_out: str, opts: Mapping[str, Any], in_place: bool) -> Any:
    from .io import read_columns, reads_polylines, write_checked

    folder = os.path.dirname(os.path.abspath(outfile))
    os.makedirs(folder, exist_ok=True)
    # point data written to a drawing are polylines: read back as point lists; a points
    # file keeps its layout, so its points are in the columns they were read from
    back = dict(opts, polylines=opts.get("polylines")
                or bool(reads_polylines(faired, fmt_out)),
                columns=read_columns(faired, fmt_out))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return write_checked(outfile, faired, records, tol=opts["tol"],
                             reader=lambda p: _read(p, back, None, fmt_out),
                             template=infile if fmt_out == fmt_in else None, format=fmt_out,
                             overwrite=in_place, decimals=opts["decimals"])


def _finish(rep: dict[str, Any], report: str | None, dry_run: bool) -> dict[str, Any]:
    if report is not None and not dry_run:
        from .io import atomic_write

        try:
            os.makedirs(os.path.dirname(os.path.abspath(report)), exist_ok=True)
            atomic_write(report, json.dumps(rep, indent=2, allow_nan=False) + "\n")
        except (CurvefairError, OSError, ValueError) as exc:
            rep.setdefault("error", f"report {report!r} not written: {_err(exc)}")
            if rep["status"] == "ok":
                rep["status"] = "failed"
    return rep


def up_to_date(job: Job, options: Mapping[str, Any], out_format: str | None = None,
               in_format: str | None = None) -> dict[str, Any] | None:
    """The recorded report when ``job``'s output exists and matches (see the module
    docstring), else None."""
    if job.report is None or not os.path.isfile(job.report) or not os.path.exists(job.output):
        return None
    try:
        with open(job.report, encoding="utf-8") as f:
            old = json.load(f)
        fmt = out_format or _out_format(job.input, job.output, in_format)
        if (old.get("status") == "ok"
                and old.get("input_sha256") == file_sha256(job.input)
                and old.get("options_sha256") == options_digest(options, fmt)
                and old.get("output_sha256") == file_sha256(job.output)):
            return old
    except (OSError, ValueError, CurvefairError):
        return None
    return None


def _out_format(infile: str, outfile: str, in_format: str | None = None) -> str:
    from .io import detect_format

    try:
        return detect_format(outfile)
    except CurvefairError:
        return detect_format(infile, in_format)


# ------------------------------------------------------------------------------------------
# many files
# ------------------------------------------------------------------------------------------
def _sweep_temps(paths: Iterable[str | None]) -> int:
    """Remove temporary files an atomic write left next to ``paths`` (a worker killed with
    SIGKILL cannot delete its own): ``.<name>.<8 random characters><suffix>``, the names
    :func:`tempfile.mkstemp` gives in :func:`curvefair.io.atomic_path`. Only called when no
    job of the run is still writing."""
    n = 0
    for p in paths:
        if p is None:
            continue
        dest = Path(os.path.realpath(p)) if os.path.islink(p) else Path(p)
        pat = re.compile(re.escape("." + dest.name + ".") + r"[A-Za-z0-9_]{8}"
                         + r"(\.[A-Za-z0-9]+)?$")
        with contextlib.suppress(OSError):
            for e in os.scandir(dest.parent if str(dest.parent) else "."):
                if pat.match(e.name) and e.is_file(follow_symlinks=False):
                    with contextlib.suppress(OSError):
                        os.unlink(e.path)
                        n += 1
    return n


def _run_one(job: Job, options: Mapping[str, Any], dry_run: bool, in_format: str | None,
             queue: Any = None) -> dict[str, Any]:
    """Top-level (picklable) per-file call for process pools and Dask workers."""
    prog = None
    if queue is not None:
        def prog(event: str, value: Any) -> None:
            with contextlib.suppress(Exception):
                queue.put((job.display, event, value))
    rep = fair_file(job.input, job.output, options, report=job.report, dry_run=dry_run,
                    progress=prog, in_format=in_format)
    if queue is not None:
        with contextlib.suppress(Exception):
            queue.put((job.display, "file", 1))
    return rep


def _summary(job: Job, rep: Mapping[str, Any]) -> dict[str, Any]:
    return {"input": job.display, "output": job.output, "report": job.report,
            "status": rep.get("status"), "error": rep.get("error"),
            "n_curves": rep.get("n_curves"), "n_selected": rep.get("n_selected"),
            "n_failed": rep.get("n_failed"), "time_s": rep.get("time_s")}


class _Terminated(Exception):
    pass


@contextlib.contextmanager
def _signals_raise() -> Iterator[None]:
    """SIGTERM / SIGHUP in the main thread raise :class:`_Terminated` (so ``finally`` blocks
    stop the workers and remove temporary files), instead of killing the process outright."""
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    old: dict[int, Any] = {}

    def handler(signum: int, frame: Any) -> None:
        raise _Terminated(signum)

    for name in ("SIGTERM", "SIGHUP"):
        sig = getattr(signal, name, None)
        if sig is not None:
            with contextlib.suppress(ValueError, OSError):
                old[sig] = signal.signal(sig, handler)
    try:
        yield
    finally:
        for sig, h in old.items():
            with contextlib.suppress(ValueError, OSError, TypeError):
                signal.signal(sig, h)


def default_jobs(jobs_n: int | None) -> int:
    """The number of processes ``--jobs`` asks for: ``jobs_n``, or the core count when None."""
    return jobs_n if jobs_n is not None else (os.cpu_count() or 1)


def executor(jobs_n: int | None, n_todo: int, client: Any = None) -> dict[str, Any]:
    """How :func:`run_jobs` runs ``n_todo`` files, as the run report records it: ``jobs``
    (asked for, default the core count), ``processes`` (the pool's size; 0 when the files
    run in this process: one file, or ``jobs`` 1) and ``scheduler`` (the Dask scheduler's
    address, or None)."""
    n = default_jobs(jobs_n)
    if client is not None:
        addr = getattr(getattr(client, "scheduler", None), "address", None)
        return {"jobs": n, "processes": 0, "scheduler": str(addr) if addr else "dask"}
    return {"jobs": n, "processes": 0 if n <= 1 or n_todo <= 1 else min(n, n_todo),
            "scheduler": None}


def run_jobs(jobs: Sequence[Job], options: Mapping[str, Any], *, jobs_n: int | None = None,
             client: Any = None, dry_run: bool = False, resume: bool = False,
             in_format: str | None = None,
             on_event: Callable[[str, str, Any], None] | None = None
             ) -> list[dict[str, Any]]:
    """Run ``jobs`` (in this process, a process pool of ``jobs_n`` or on a Dask ``client``);
    one report per job, in the order of ``jobs``. ``on_event(file, event, value)`` gets the
    progress events (``"curves"``, ``"curve"``, ``"file"``, ``"skipped"``)."""
    _options(options)  # refuse unknown options before any work
    reports: list[dict[str, Any] | None] = [None] * len(jobs)
    todo: list[int] = []
    for k, job in enumerate(jobs):
        old = up_to_date(job, options, in_format=in_format) if resume and not dry_run else None
        if old is not None:
            rep = dict(old)
            rep["status"] = "ok"
            rep["skipped"] = "up to date (input, options and output match the report)"
            reports[k] = rep
            if on_event:
                on_event(job.display, "skipped", 1)
        else:
            todo.append(k)
    processes = executor(jobs_n, len(todo), client)["processes"]
    try:
        with _signals_raise():
            if client is not None:
                futs = client.map(_run_one, [jobs[k] for k in todo],
                                  [options] * len(todo), [dry_run] * len(todo),
                                  [in_format] * len(todo), pure=False)
                from distributed import as_completed

                index = {f.key: k for f, k in zip(futs, todo, strict=True)}
                for fut in as_completed(futs):
                    k = index[fut.key]
                    try:
                        reports[k] = fut.result()
                    except Exception as exc:  # noqa: BLE001 - e.g. KilledWorker: one file
                        reports[k] = {"input": jobs[k].input, "output": jobs[k].output,
                                      "status": "failed",
                                      "error": f"{type(exc).__name__}: {exc}"}
                    if on_event:
                        on_event(jobs[k].display, "file", 1)
            elif processes == 0:
                for k in todo:
                    def ev(event: str, value: Any, _d: str = jobs[k].display) -> None:
                        if on_event:
                            on_event(_d, event, value)
                    reports[k] = fair_file(jobs[k].input, jobs[k].output, options,
                                           report=jobs[k].report, dry_run=dry_run,
                                           progress=ev, in_format=in_format)
                    if on_event:
                        on_event(jobs[k].display, "file", 1)
            else:
                _run_pool(jobs, todo, options, processes, dry_run, in_format,
                          reports, on_event)
    finally:
        if not dry_run:
            _sweep_temps([j.output for j in jobs] + [j.report for j in jobs])
    return [r if r is not None else {"status": "failed", "error": "not run"} for r in reports]


def _run_pool(jobs: Sequence[Job], todo: Sequence[int], options: Mapping[str, Any], n: int,
              dry_run: bool, in_format: str | None, reports: list[Any],
              on_event: Callable[[str, str, Any], None] | None) -> None:
    import concurrent.futures as cf
    import multiprocessing as mp
    import queue as _queue

    ctx = mp.get_context("spawn")
    manager = ctx.Manager() if on_event else None
    q = manager.Queue() if manager is not None else None
    pool = cf.ProcessPoolExecutor(max_workers=n, mp_context=ctx)
    try:
        futs = {pool.submit(_run_one, jobs[k], options, dry_run, in_format, q): k
                for k in todo}
        pending = set(futs)
        while pending:
            done, pending = cf.wait(pending, timeout=0.1, return_when=cf.FIRST_COMPLETED)
            if q is not None:
                while True:
                    try:
                        name, event, value = q.get_nowait()
                    except (_queue.Empty, OSError, EOFError):
                        break
                    assert on_event is not None
                    on_event(name, event, value)
            for f in done:
                k = futs[f]
                try:
                    reports[k] = f.result()
                except cf.process.BrokenProcessPool as exc:  # a worker died: redo it here
                    reports[k] = fair_file(jobs[k].input, jobs[k].output, options,
                                           report=jobs[k].report, dry_run=dry_run,
                                           in_format=in_format)
                    reports[k].setdefault("notes", []).append(f"redone after {exc!r}")
    except BaseException:
        for p in list(getattr(pool, "_processes", {}).values()):
            with contextlib.suppress(Exception):
                p.terminate()  # SIGTERM: the worker's handler deletes its temporary files
        for p in list(getattr(pool, "_processes", {}).values()):
            with contextlib.suppress(Exception):
                p.join(5)
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    else:
        pool.shutdown(wait=True)
    finally:
        if manager is not None:
            manager.shutdown()


def run_report(jobs: Sequence[Job], reports: Sequence[Mapping[str, Any]],
               options: Mapping[str, Any], t0: float, dry_run: bool, *,
               jobs_n: int | None = None, client: Any = None) -> dict[str, Any]:
    """The run's report: options, how the files ran (:func:`executor`: ``jobs``,
    ``processes``, ``scheduler``), counts and one summary per file."""
    files = [_summary(j, r) for j, r in zip(jobs, reports, strict=True)]
    for f, r in zip(files, reports, strict=True):
        if r.get("skipped"):
            f["skipped"] = r["skipped"]
    opts = _options(options)
    return {"curvefair": __version__, "dry_run": dry_run,
            "options": _jsonable({k: opts[k] for k in OUTPUT_OPTIONS}),
            **executor(jobs_n, sum(not f.get("skipped") for f in files), client),
            "n_files": len(files),
            "n_ok": sum(f["status"] == "ok" and not f.get("skipped") for f in files),
            "n_skipped": sum(bool(f.get("skipped")) for f in files),
            "n_partial": sum(f["status"] == "partial" for f in files),
            "n_failed": sum(f["status"] == "failed" for f in files),
            "n_dry_run": sum(f["status"] == "dry-run" for f in files),
            "time_s": time.perf_counter() - t0, "files": files}


def fair_files(paths: str | Sequence[str], out_dir: str | os.PathLike[str], client: Any = None,
               *, jobs: int | None = None, resume: bool = False, dry_run: bool = False,
               report: str | None = None, **options: Any) -> dict[str, Any]:
    """Fair every file of ``paths`` (files, folders, glob patterns) into ``out_dir``.

    Parameters
    ----------
    paths : str or sequence of str
    out_dir : path-like
        Outputs go to ``out_dir/<path relative to the folder or glob base>``; per-file reports
        to ``out_dir/.curvefair/<relative path>.json``; the run report to
        ``out_dir/.curvefair/run.json`` (or ``report``).
    client : distributed.Client, optional
        Run the per-file work on this Dask cluster (the workers must see the same file
        system); None: local processes (``jobs``, default the core count).
    jobs, resume, dry_run
        See the module docstring; ``dry_run`` writes nothing at all.
    **options
        ``method`` (a name or ``"kind=name,..."``), ``tol``, ``eps``, ``max_steps``, ``clamp``,
        ``protect``, ``mode``, ``method_options`` (dict), ``decimals``, ``corner_angle``,
        ``strict``, ``layer``, ``name``, ``handle``, ``hold_shared``, ``shared_distance``,
        ``history``, ``polylines`` (SVG, DXF and 3dm files: read straight-line shapes as point
        lists, as :func:`curvefair.read_curves`; other formats ignore it), ``columns``
        (points files: the 0-based coordinate columns, as :func:`curvefair.read_curves`;
        other formats ignore it).

    Returns
    -------
    dict
        The run report (``files``: one summary per file; ``n_failed`` > 0 when any failed).
    """
    t0 = time.perf_counter()
    if isinstance(paths, (str, os.PathLike)):
        paths = [os.fspath(paths)]
    out = os.fspath(out_dir)
    plan = plan_inputs([os.fspath(p) for p in paths], out)
    if any(j.input == "-" for j in plan):
        raise InputError("fair_files: '-' (stdin) is for the command line only")
    reps = run_jobs(plan, options, jobs_n=jobs, client=client, dry_run=dry_run, resume=resume)
    run = run_report(plan, reps, options, t0, dry_run, jobs_n=jobs, client=client)
    if not dry_run:
        from .io import atomic_write

        dest = report or os.path.join(out, REPORT_DIR, "run.json")
        os.makedirs(os.path.dirname(os.path.abspath(dest)), exist_ok=True)
        atomic_write(dest, json.dumps(run, indent=2, allow_nan=False) + "\n")
        run["run_report"] = dest
    return run


def fair_chunked(source: str | os.PathLike[str], out: str | os.PathLike[str], *, tol: float,
                 chunk: int = 5000, overlap: int = 64, hold: int = 16, client: Any = None,
                 jobs: int | None = None, method: str | None = None, clamp: Any = "g0",
                 corner_angle: float | None = 60.0, protect: Iterable[int] = (),
                 progress: Callable[[int, int], None] | None = None,
                 report: str | os.PathLike[str] | None = None, **options: Any
                 ) -> dict[str, Any]:
    """Fair one open point list too large for memory in overlapping chunks; write ``out``.

    ``source`` is a point file (``.csv``, ``.txt``, ``.xyz``, ``.pts``, ``.dat`` columns, or a
    ``.npy`` array of shape (n, 2) or (n, 3), memory-mapped); ``out`` a point file too. Text
    from text keeps the input's layout line for line, as the single-file writer does: header,
    comment and blank lines, every line's ending, and each unmoved row byte for byte; a moved
    row keeps its separators, padding and number style. Unlike the single-file writer (which
    writes a moved number exactly where the file's decimals cannot), its moved numbers are
    rounded to the column's decimals in the input, the rounding checked as part of the
    tolerance, or given more decimals (one at a time, then exact) where rounding would move the
    point past ``tol`` from the input, too far from its faired point or onto a neighbour; a
    chunk whose curve read back then exceeds ``tol`` has its rounding undone (see
    :mod:`curvefair._chunked`). Text from ``.npy``: numbers in the shortest form that reads back
    exactly, ``,`` separated. ``.npy`` out: float64. Chunk ``k`` (rows ``k chunk
    ..``) is faired by :func:`curvefair.fair` on its rows extended by ``overlap`` rows each
    side, holding the ``hold`` rows either side of each join in both neighbouring fairs, and
    kept on its own rows; the file written is read back in chunks and measured like a
    single-file run of point data (moves scaled down where the curve read back exceeds ``tol``);
    nothing is written unless all of it is within ``tol``. Memory stays bounded by a few
    windows. The algorithm, the G2 bound at the joins and the on-disk rule:
    :mod:`curvefair._chunked`.

    Parameters
    ----------
    tol : float > 0
        Every point moves at most ``tol`` (exactly, in float64) and the curve read back from
        ``out`` is within ``tol`` of the input's (Hausdorff distance, per chunk).
    chunk, overlap, hold : int
        Rows per chunk (>= ``2 overlap + 2``), rows of context each side, rows held each side
        of a join (<= ``overlap - 2``).
    client : distributed.Client, optional
        Run the chunks on this Dask cluster (the windows travel with the tasks); None: local
        processes (``jobs``, default the core count; 1: this process). Same bytes either way.
    method, clamp, **options
        As for :func:`curvefair.fair` (``eps``, ``max_steps``, ``mode``, method options);
        ``clamp`` applies at the curve's two ends.
    corner_angle : float or None
        A turn of this many degrees or more at a row is a corner, where the single-file reader
        splits the list: refused (InputError naming the row). None: read through corners.
    protect : iterable of int
        Rows (0-based) that never move.
    progress : callable, optional
        ``progress(done, total)`` after each chunk faired and each chunk measured.
    report : path, optional
        Also write the report there as JSON.

    Returns
    -------
    dict
        ``n_points``, ``n_chunks``, ``max_deviation`` (read back), ``max_point_displacement``,
        ``chunks`` (per chunk: rows, window, method, steps, its own certificate
        ``max_deviation``, ``on_disk_deviation``, ``move_scale``; text from text also
        ``on_disk_numbers`` -- ``"rounded"`` or ``"exact"`` --, ``rows_rounded``,
        ``rows_more_decimals``), ``layout_kept``, ``joins`` (per join: the
        tangent angle and relative curvature difference between the two fairs and against
        the curve read back), ``joins_g2_max`` and ``g2_tol``.

    Raises
    ------
    InputError
        Bad arguments, an unreadable or unsuitable file (named with its row or line), or a
        result that cannot be brought within ``tol`` (nothing written).
    """
    from ._chunked import fair_chunked as _run

    rep = _run(source, out, tol=tol, chunk=chunk, overlap=overlap, hold=hold, client=client,
               jobs=jobs, method=method, clamp=clamp, corner_angle=corner_angle,
               protect=protect, progress=progress, **options)
    rep["curvefair"] = __version__
    if report is not None:
        from .fairing.fair import jsonable
        from .io import atomic_write

        atomic_write(report, json.dumps(jsonable(rep), indent=2, allow_nan=False) + "\n")
    return rep


def spool_stdin(fmt: str | None, folder: str) -> str:
    """Copy stdin into ``folder/stdin.<ext>`` (the readers take file names)."""
    path = os.path.join(folder, "stdin" + _stdin_ext(fmt))
    data = sys.stdin.buffer.read()
    with open(path, "wb") as f:
        f.write(data)
    return path


def temp_folder() -> tempfile.TemporaryDirectory[str]:
    return tempfile.TemporaryDirectory(prefix="curvefair-")
