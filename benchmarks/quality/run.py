"""Fairing quality benchmark: every curvefair method and the peers at equal maximum deviation.

Usage (from the repository root)::

    make bench-quality                      # full run, regenerates docs/benchmarks.md
    python benchmarks/quality/run.py --quick  # a tiny subset (writes the same page)

Every tool gets the same input points and the same allowed deviation ``tol``:

* curvefair: ``fair(curve, method, tol=tol)`` with every registered method, once with the
  method's default ``eps`` and once with ``eps=0`` (run until the tolerance blocks every move or
  the step cap is reached), plus the ``l=3`` variants of ``VARIANTS``. The Hermite methods
  start from ``interpolate_cubic`` / ``interpolate_quintic`` (natural ends, or periodic), the
  B-spline methods from
  ``interpolate_bspline``; all with chord-length parameters, except Kjellander's method, which is
  defined for uniform parameters and gets equally spaced ones over the same range.
* ``cf:fair-points``: ``curvefair.fair_points(points, tol)`` with its defaults (the
  minimiser of E3 over quintic splines with every point within ``tol`` at its chord-length
  parameter); it starts from the points, not from an interpolant.
* peers (``peers.py``): smoothing parameter bisected so that the maximum deviation reaches
  ``tol`` from below.

Metrics (one definition for all tools): ``curvefair.analyze`` on the resulting curve (extrema,
inflections, E2, E3, integral of (dkappa/ds)^2 ds); the deviation ``max_i |C(u_i) - p_i|`` at
each tool's own parameters (and its index); on the ground-truth corpus the largest distance from
the curve to the true curve (dense polyline of 20 001 vertices) and whether the extrema and
inflection counts equal the true ones.
"""

from __future__ import annotations

import argparse
import csv
import datetime as _dt
import multiprocessing as mp
import os
import platform
import sys
import time
import traceback
from pathlib import Path
from typing import Any

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(HERE))

import corpus as C  # noqa: E402
import peers as P  # noqa: E402

import curvefair as cf  # noqa: E402
from curvefair.fairing.fair import METHODS as REGISTERED_METHODS  # noqa: E402

HERMITE_CUBIC = ("kjellander", "poliakoff", "wang-cao", "points-l1")
HERMITE_QUINTIC = ("wang-quintic",)
BSPLINE = ("eck-hadenfeld", "knot-removal", "cheng-yu", "global")
METHODS = HERMITE_CUBIC + HERMITE_QUINTIC + BSPLINE
BASELINE = "interpolant"  # natural cubic interpolating spline of the input: "before"


# option variants worth showing besides each method's defaults: ``l=3`` (the third-derivative
# energy) for the two methods that take it, and Eck-Hadenfeld's sweep schedule
VARIANTS: dict[str, list[tuple[str, dict[str, Any]]]] = {
    "eck-hadenfeld": [("l3+eps0", {"l": 3, "eps": 0.0}), ("sweep", {"schedule": "sweep"})],
    "global": [("l3", {"l": 3})],
    # points-l1 bounds the data points only (as the peers are tuned), not also the rebuilt
    # curve's distance from the input interpolant between the points
    "points-l1": [("points", {"curve_tol": False})],
}


def curvefair_tools() -> list[tuple[str, str, dict[str, Any]]]:
    """``(tool name, method, fair() keywords)``: every registered method with its defaults and
    with ``eps=0``, plus :data:`VARIANTS`."""
    from curvefair.fairing.fair import METHODS as REGISTERED

    names = [m for m in METHODS if m in REGISTERED] + [m for m in REGISTERED if m not in METHODS]
    out: list[tuple[str, str, dict[str, Any]]] = []
    for m in names:
        out.append((f"cf:{m}", m, {}))
        out.append((f"cf:{m}/eps0", m, {"eps": 0.0}))
        for suffix, kw in VARIANTS.get(m, []):
            out.append((f"cf:{m}/{suffix}", m, kw))
    out.append((POINTS_TOOL, "fair_points", {}))
    out.append((CLI_TOOL, "cli", {}))
    return out


# ``curvefair fair in.csv -o out.csv --tol T`` as a user runs it: the points written to a CSV
# file (shortest exact decimals), the command's own defaults (reader, corner split, default
# method per curve kind, read-back check), the written file read back
CLI_TOOL = "cf:cli-default"


def run_cli_default(case: C.Case) -> tuple[cf.PiecewiseCurve, np.ndarray, dict[str, Any]]:
    """``curvefair fair`` with its defaults on ``case``'s points (airfoils as a Selig ``.dat``
    file, the rest as CSV); returns the curve rebuilt from the written file (the chord-length
    natural, closed: periodic, cubic through every written point, as for every other tool's
    rebuilt columns; the command itself splits a list at its corners), the written points,
    and the method(s) used."""
    import json
    import tempfile

    from click.testing import CliRunner

    from curvefair.cli import main as cli_main

    pts = np.asarray(case.points, dtype=float)
    rows = np.vstack([pts, pts[:1]]) if case.closed else pts
    # airfoils as Selig .dat files (name line, then "x y"), everything else as CSV
    dat = case.corpus == "airfoils"
    ext, sep = (".dat", " ") if dat else (".csv", ",")
    with tempfile.TemporaryDirectory() as d:
        src, dst, rep = (os.path.join(d, n) for n in ("in" + ext, "out" + ext, "report.json"))
        with open(src, "w") as f:
            f.write(("FOIL\n" if dat else "")
                    + "".join(sep.join(repr(float(v)) for v in r) + "\n" for r in rows))
        res = CliRunner().invoke(cli_main, ["fair", src, "-o", dst, "--tol", repr(case.tol),
                                            "--report", rep, "--quiet"])
        if res.exit_code != 0 or not os.path.exists(dst):
            raise RuntimeError(f"curvefair fair exit {res.exit_code}: "
                               f"{(res.output or '')[-200:]} {res.exception!r}")
        w = np.loadtxt(dst, delimiter=None if dat else ",", skiprows=1 if dat else 0, ndmin=2)
        with open(rep) as f:
            report = json.load(f)
    if case.closed:
        w = w[:-1]
    methods = sorted({str((c.get("report") or {}).get("method", c.get("status")))
                      for c in report.get("curves", [])})
    if case.closed:
        rb = cf.interpolate_cubic(np.vstack([w, w[:1]]), "chord", "periodic")
    else:
        rb = cf.interpolate_cubic(w, "chord", "natural")
    return rb, w, {"method": "+".join(methods)}




# ``curvefair.fair_points`` works on the points themselves (no start curve to move): the
# minimiser of E3 over quintic splines with |C(u_i) - p_i| <= tol at the chord parameters
POINTS_TOOL = "cf:fair-points"


def run_fair_points(case: C.Case) -> tuple[Any, np.ndarray, dict[str, Any]]:
    """``fair_points(points, tol)`` with its defaults (degree 5, E3, chord parameters)."""
    u = P.chord_params(case.points, case.closed)
    res = cf.fair_points(case.points, case.tol, closed=case.closed, param=u)
    return res.curve, u, res.report


def run_tool(case: C.Case, tool: str) -> Any:
    """The curve ``tool`` produces on ``case`` (used to redraw figures in the main process)."""
    if tool == BASELINE:
        return initial_curve("poliakoff", case.points, case.closed)[0]
    if tool == POINTS_TOOL:
        return run_fair_points(case)[0]
    if tool == CLI_TOOL:
        return run_cli_default(case)[0]
    for name, method, kw in curvefair_tools():
        if name == tool:
            c0, _ = initial_curve(method, case.points, case.closed)
            return cf.fair(c0, method, tol=case.tol, **kw).curve
    return P.run_peer(tool.removeprefix("peer:"), case.points, case.closed, case.tol).curve


def initial_curve(method: str, points: np.ndarray, closed: bool
                  ) -> tuple[cf.PiecewiseCurve, np.ndarray]:
    """The curve ``method`` starts from, and the parameters of the input points on it."""
    u = P.chord_params(points, closed)
    if method == "kjellander":
        u = np.linspace(0.0, u[-1], u.shape[0])
    bc = "periodic" if closed else "natural"
    if method in HERMITE_QUINTIC:
        return cf.interpolate_quintic(points, u, bc), u
    if method in BSPLINE or method not in HERMITE_CUBIC:
        return cf.interpolate_bspline(points, 3, u, closed=closed), u
    return cf.interpolate_cubic(points, u, bc), u


# ---------------------------------------------------------------------------------------------
def _polyline_distance(q: np.ndarray, poly: np.ndarray, tree: Any) -> np.ndarray:
    """Distance of each point of ``q`` to the polyline ``poly`` (nearest vertex's two edges)."""
    _, j = tree.query(q)
    best = np.linalg.norm(q - poly[j], axis=1)
    for a, b in ((j - 1, j), (j, j + 1)):
        ok = (a >= 0) & (b < len(poly))
        a, b = np.clip(a, 0, len(poly) - 1), np.clip(b, 0, len(poly) - 1)
        e = poly[b] - poly[a]
        ee = np.maximum(np.sum(e * e, axis=1), 1e-300)
        t = np.clip(np.sum((q - poly[a]) * e, axis=1) / ee, 0.0, 1.0)
        d = np.linalg.norm(q - (poly[a] + t[:, None] * e), axis=1)
        best = np.where(ok, np.minimum(best, d), best)
    return best


def dense_samples(curve: cf.PiecewiseCurve, per_segment: int = 24) -> np.ndarray:
    pp = curve.piecewise
    return pp.segment_values(np.linspace(0.0, 1.0, per_segment + 1), 0).reshape(-1, pp.dim)


_TRUTH: dict[int, tuple[np.ndarray, Any]] = {}


def truth_distance(case: C.Case, curve: cf.PiecewiseCurve) -> float:
    from scipy.spatial import cKDTree

    key = id(case.truth)
    if key not in _TRUTH:
        poly = case.truth.polyline()
        _TRUTH[key] = (poly, cKDTree(poly))
    poly, tree = _TRUTH[key]
    return float(_polyline_distance(dense_samples(curve), poly, tree).max())


def metrics(case: C.Case, curve: cf.PiecewiseCurve) -> dict[str, Any]:
    a = cf.analyze(curve)
    row: dict[str, Any] = {
        "extrema": int(a.extrema), "inflections": int(a.inflections),
        "E2": float(a.energy2), "E3": float(a.energy3), "dkds": float(a.dkds_energy),
        "n_segments": int(a.n_segments),
    }
    if case.truth is not None:
        row["truth_dist"] = truth_distance(case, curve)
        row["hit_extrema"] = int(a.extrema == case.true_extrema)
        if case.true_inflections is not None:
            row["hit_inflections"] = int(a.inflections == case.true_inflections)
    return row


def written_points(curve: cf.PiecewiseCurve, u: np.ndarray, n: int) -> np.ndarray:
    """The ``n`` points a point file would hold after fairing: a Hermite curve's data points
    (its own parameters), else the curve at the input's parameters ``u``."""
    if isinstance(curve, (cf.CubicHermite, cf.QuinticHermite)):
        return np.asarray(curve.points)[:n]
    return np.asarray(curve(u[:n]))


def result_deviation(curve: cf.PiecewiseCurve, pts: np.ndarray, u: np.ndarray
                     ) -> tuple[float, int]:
    """``max_i |w_i - p_i|`` over the written points ``w`` (:func:`written_points`): at the
    input's parameters, or a Hermite result's own data points (``points-l1`` re-interpolates
    at the chord lengths of the moved points)."""
    w = written_points(curve, u, len(pts))
    d = np.linalg.norm(w - pts, axis=1)
    i = int(np.argmax(d))
    return float(d[i]), i


def rebuilt_metrics(case: C.Case, curve: cf.PiecewiseCurve, u: np.ndarray) -> dict[str, Any]:
    """:func:`metrics` (suffix ``_rb``) of the curve rebuilt from the written point file: the
    chord-length natural (closed: periodic) cubic through :func:`written_points`, as curvefair's
    point-file reader builds it."""
    w = written_points(curve, u, len(case.points))
    if case.closed:
        rb = cf.interpolate_cubic(np.vstack([w, w[:1]]), "chord", "periodic")
    else:
        rb = cf.interpolate_cubic(w, "chord", "natural")
    return {k + "_rb": v for k, v in metrics(case, rb).items()}


def _base_row(case: C.Case, tool: str) -> dict[str, Any]:
    return {"corpus": case.corpus, "family": case.family, "case": case.name, "tool": tool,
            "n_points": int(len(case.points)), "closed": int(case.closed), "tol": case.tol,
            "noise": case.noise if case.noise is not None else "",
            "true_extrema": case.true_extrema if case.true_extrema is not None else "",
            "true_inflections": (case.true_inflections
                                 if case.true_inflections is not None else "")}


def run_case(case: C.Case, tools: list[str] | None = None) -> list[dict[str, Any]]:
    rows = []
    pts = case.points

    def want(name: str) -> bool:
        return tools is None or name in tools or name == BASELINE

    # baseline: the natural (periodic) cubic interpolant, i.e. what the Hermite methods start from
    row = _base_row(case, BASELINE)
    try:
        t0 = time.perf_counter()
        c0, u = initial_curve("poliakoff", pts, case.closed)
        row.update(ok=1, time_s=time.perf_counter() - t0)
        d, i = P.data_deviation(c0, pts, u)
        row.update(dev=d, dev_index=i, dev_over_tol=d / case.tol)
        row.update(metrics(case, c0))
        row.update(rebuilt_metrics(case, c0, u))
    except Exception as exc:  # noqa: BLE001
        row.update(ok=0, error=repr(exc)[:300])
    rows.append(row)

    for tool, method, kw in curvefair_tools():
        if not want(tool):
            continue
        row = _base_row(case, tool)
        try:
            t0 = time.perf_counter()
            if tool == POINTS_TOOL:
                curve, u, rep = run_fair_points(case)
                rep = dict(rep, steps=rep["iterations"])
            elif tool == CLI_TOOL:
                curve, w, rep = run_cli_default(case)
                dt = time.perf_counter() - t0
                d = np.linalg.norm(w - pts, axis=1)
                i = int(np.argmax(d))
                row.update(ok=1, time_s=dt, dev=float(d[i]), dev_index=i,
                           dev_over_tol=float(d[i]) / case.tol,
                           violation=int(d[i] > case.tol * (1 + 1e-9)),
                           stop_reason=rep["method"])
                # the curve read back is the rebuilt one: both column sets are the file's
                m = metrics(case, curve)
                row.update(m)
                row.update({k + "_rb": v for k, v in m.items()})
                rows.append(row)
                continue
            else:
                c0, u = initial_curve(method, pts, case.closed)
                spec = REGISTERED_METHODS[method]
                if spec.accepts is not None and not spec.accepts(c0):
                    row.update(ok=0, na=1, error=f"{method} does not handle this curve")
                    rows.append(row)
                    continue
                res = cf.fair(c0, method, tol=case.tol, **kw)
                curve, rep = res.curve, res.report
            dt = time.perf_counter() - t0
            d, i = result_deviation(curve, pts, u)
            row.update(ok=1, time_s=dt, dev=d, dev_index=i, dev_over_tol=d / case.tol,
                       violation=int(d > case.tol * (1 + 1e-9)),
                       steps=rep.get("steps"), stop_reason=rep.get("stop_reason"),
                       curve_dev=rep.get("max_deviation"))
            row.update(metrics(case, curve))
            row.update(rebuilt_metrics(case, curve, u))
        except Exception as exc:  # noqa: BLE001
            row.update(ok=0, error=(repr(exc) + " " + traceback.format_exc(limit=-1))[:300])
        rows.append(row)

    for name in P.PEERS:
        tool = f"peer:{name}"
        if not want(tool):
            continue
        row = _base_row(case, tool)
        try:
            t0 = time.perf_counter()
            r = P.run_peer(name, pts, case.closed, case.tol)
            dt = time.perf_counter() - t0
            if r.curve is None:
                row.update(ok=0, error=r.note or "no result within the target deviation",
                           na=int(bool(r.note)))
            else:
                row.update(ok=1, time_s=dt, dev=r.dev, dev_index=r.dev_index,
                           dev_over_tol=r.dev / case.tol,
                           violation=int(r.dev > case.tol * (1 + 1e-9)),
                           converged=int(r.converged), param=r.param, steps=r.evaluations)
                row.update(metrics(case, r.curve))
                row.update(rebuilt_metrics(case, r.curve, P.chord_params(pts, case.closed)))
        except Exception as exc:  # noqa: BLE001
            row.update(ok=0, error=repr(exc)[:300])
        rows.append(row)
    return rows


# ---------------------------------------------------------------------------------------------
_CASES: list[C.Case] = []


_TOOLS: list[str] | None = None


def _work(i: int, tools: list[str] | None = None) -> list[dict[str, Any]]:
    import warnings

    warnings.simplefilter("ignore")
    return run_case(_CASES[i], tools if tools is not None else _TOOLS)


def _isolated(ctx: Any, i: int) -> list[dict[str, Any]]:
    """Run case ``i`` in a process of its own; if that process dies (a crash in compiled code),
    run each tool in a process of its own and record the one that crashes as failed."""
    from concurrent.futures import ProcessPoolExecutor
    from concurrent.futures.process import BrokenProcessPool

    try:
        with ProcessPoolExecutor(1, mp_context=ctx) as ex:
            return ex.submit(_work, i).result()
    except BrokenProcessPool:
        pass
    rows: list[dict[str, Any]] = []
    for tool in all_tools():
        try:
            with ProcessPoolExecutor(1, mp_context=ctx) as ex:
                got = ex.submit(_work, i, [tool]).result()
            rows += [r for r in got if r["tool"] == tool]
        except BrokenProcessPool:
            row = _base_row(_CASES[i], tool)
            row.update(ok=0, error="the process crashed (memory corruption or abort) while "
                                   "running this tool")
            rows.append(row)
            print(f"  CRASH: {tool} on {_CASES[i].name}", flush=True)
    return rows


def run_all(cases: list[C.Case], jobs: int, tools: list[str] | None = None
            ) -> list[dict[str, Any]]:
    """All tools on all cases, ``jobs`` worker processes (fork), biggest cases first. A worker
    that dies does not stop the run: the unfinished cases are re-run in isolation."""
    from concurrent.futures import ProcessPoolExecutor, as_completed
    from concurrent.futures.process import BrokenProcessPool

    global _CASES, _TOOLS
    _CASES = cases
    _TOOLS = tools
    order = sorted(range(len(cases)), key=lambda i: -len(cases[i].points))
    rows: list[dict[str, Any]] = []
    done: set[int] = set()
    t0 = time.perf_counter()

    def progress() -> None:
        if len(done) % 25 == 0:
            print(f"  {len(done)}/{len(cases)} cases, {time.perf_counter() - t0:.0f} s",
                  flush=True)

    ctx = mp.get_context("fork")
    if jobs > 1:
        try:
            with ProcessPoolExecutor(jobs, mp_context=ctx) as ex:
                futs = {ex.submit(_work, i): i for i in order}
                for f in as_completed(futs):
                    rows.extend(f.result())
                    done.add(futs[f])
                    progress()
        except BrokenProcessPool:
            print("  a worker process died; re-running the unfinished cases in isolation",
                  flush=True)
    for i in order:
        if i in done:
            continue
        rows.extend(_isolated(ctx, i) if jobs > 1 else _work(i))
        done.add(i)
        progress()
    key = {c.name: j for j, c in enumerate(cases)}
    tool_order = {t: j for j, t in enumerate(all_tools())}
    rows.sort(key=lambda r: (key[r["case"]], tool_order.get(r["tool"], 999)))
    return rows


def all_tools() -> list[str]:
    return [BASELINE] + [t for t, _, _ in curvefair_tools()] + [f"peer:{n}" for n in P.PEERS]


# ---------------------------------------------------------------------------------------------
def write_csv(rows: list[dict[str, Any]], path: Path) -> None:
    cols: list[str] = []
    for r in rows:
        for k in r:
            if k not in cols:
                cols.append(k)
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=cols)
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in r.items()})


def read_csv(path: Path) -> list[dict[str, Any]]:
    """The rows of :func:`write_csv` (values as text; the report converts them)."""
    with open(path, newline="") as f:
        return [{k: v for k, v in r.items() if v != ""} | {"case": r["case"], "tool": r["tool"]}
                for r in csv.DictReader(f)]


def merge_rows(new: list[dict[str, Any]], old: list[dict[str, Any]], cases: list[C.Case]
               ) -> tuple[list[dict[str, Any]], int]:
    """``new`` plus the rows of ``old`` for every (case, tool) ``new`` does not have, on the
    cases of ``cases`` only, in the run's order; and the number reused."""
    names = {c.name for c in cases}
    have = {(r["case"], r["tool"]) for r in new}
    keep = [r for r in old if r["case"] in names and (r["case"], r["tool"]) not in have]
    rows = new + keep
    key = {c.name: j for j, c in enumerate(cases)}
    tool_order = {t: j for j, t in enumerate(all_tools())}
    rows.sort(key=lambda r: (key[r["case"]], tool_order.get(r["tool"], 999)))
    return rows, len(keep)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="a tiny subset (about a minute)")
    ap.add_argument("--jobs", type=int, default=min(2, os.cpu_count() or 1))
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "benchmarks.md")
    ap.add_argument("--img", type=Path, default=None,
                    help="folder of the comb images (default: docs/img/bench for the default "
                         "--out, else an img/ folder beside --out, so that a partial run never "
                         "overwrites the committed page's images)")
    ap.add_argument("--csv", type=Path, default=HERE / "results.csv")
    ap.add_argument("--airfoils", type=int, default=None, help="number of UIUC airfoils")
    ap.add_argument("--glyphs", type=int, default=None, help="number of glyph runs")
    ap.add_argument("--instances", type=int, default=None,
                    help="ground-truth instances per family and noise level")
    ap.add_argument("--only", nargs="+", default=None,
                    choices=("ground-truth", "airfoils", "glyphs", "point-files"),
                    help="run these corpora only (a partial page)")
    ap.add_argument("--reuse", type=Path, default=None, metavar="RESULTS.csv",
                    help="with --tools: the rows of every other tool are taken from this "
                         "earlier full run's CSV (same corpus), so that a change to one method "
                         "reruns that method only; the page says so")
    ap.add_argument("--tools", nargs="+", default=None,
                    help="run these tools only (names as in the tables, e.g. cf:points-l1 "
                         "peer:scipy-splprep; the input interpolant always runs)")
    args = ap.parse_args(argv)

    import report

    if args.out.exists():
        # before the run, not after it: a page whose hand-written sections cannot be kept
        report.splice(args.out.read_text(), "")
    t_start = time.perf_counter()
    if args.quick:
        gt = C.ground_truth_cases(instances=args.instances or 1, levels=(1e-3,))
        af = C.airfoil_cases(args.airfoils or 6)
        gl = C.glyph_cases(args.glyphs or 6)
        pf = C.point_file_cases(instances=1, levels=(1e-3,))
    else:
        gt = C.ground_truth_cases(instances=args.instances or 4)
        af = C.airfoil_cases(args.airfoils or 240)
        gl = C.glyph_cases(args.glyphs or 80)
        pf = C.point_file_cases()
    page_cases = gt + af + gl + pf
    if args.only:
        keep = set(args.only)
        gt, af, gl, pf = [c if n in keep else [] for n, c in
                          (("ground-truth", gt), ("airfoils", af), ("glyphs", gl),
                           ("point-files", pf))]
    cases = gt + af + gl + pf
    print(f"corpus: {len(gt)} ground-truth, {len(af)} airfoils, {len(gl)} glyph runs, "
          f"{len(pf)} point files; "
          f"{len(all_tools())} tools; {args.jobs} processes", flush=True)
    rows = run_all(cases, args.jobs, args.tools)
    elapsed = time.perf_counter() - t_start
    reused = 0
    if args.reuse is not None:
        if not args.tools:
            ap.error("--reuse needs --tools (the tools to run again)")
        # the page covers every corpus; the rows this run made replace the earlier ones
        cases = page_cases
        rows, reused = merge_rows(rows, read_csv(args.reuse), cases)
    if args.img is None:
        page = ROOT / "docs" / "benchmarks.md"
        args.img = (ROOT / "docs" / "img" / "bench" if args.out.resolve() == page.resolve()
                    else args.out.parent / "img")
    args.csv.parent.mkdir(parents=True, exist_ok=True)
    write_csv(rows, args.csv)

    given = sys.argv[1:] if argv is None else list(argv)
    cmd = ("make bench-quality" if not given else
           "python benchmarks/quality/run.py " + " ".join(given))
    info = {
        "command": cmd,
        "date": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "elapsed_s": elapsed,
        "jobs": args.jobs,
        "machine": f"{platform.machine()}, {os.cpu_count()} cores, Python "
                   f"{platform.python_version()}",
        "versions": report.versions(),
        "quick": args.quick,
        "csv": os.path.relpath(args.csv, args.out.parent),
    }
    if reused:
        info["reused"] = (f"{reused} rows come from the earlier run in `{args.reuse}`; "
                          "this run made the rows of "
                          + ", ".join("`" + t + "`" for t in args.tools)
                          + (f" on {', '.join(args.only)}" if args.only else "")
                          + " (and the input interpolant's)")
    report.write_page(rows, cases, info, args.out, args.img)
    n_viol = sum(int(r.get("violation") or 0) for r in rows if r["tool"].startswith("cf:"))
    print(f"wrote {args.out} and {args.csv} in {elapsed:.0f} s; "
          f"curvefair tolerance violations: {n_viol}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
