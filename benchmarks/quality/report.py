"""Aggregation of the benchmark rows into docs/benchmarks.md and the figures under docs/img/bench/.

Everything on the page is computed from the rows of one run of ``run.py``; the figures are drawn
in the same run (the tool is re-run on the chosen case in the main process, deterministically).
"""

from __future__ import annotations

import importlib.metadata as md
import math
import os
from collections import defaultdict
from pathlib import Path
from typing import Any

import corpus as C
import numpy as np

CORPORA = ("ground-truth", "airfoils", "glyphs", "point-files")
BASELINE = "interpolant"
#: the command-line defaults, counted on the written file (run.CLI_TOOL)
DEFAULT_TOOL = "cf:cli-default"


def versions() -> str:
    out = []
    for pkg in ("curvefair", "numpy", "scipy", "csaps", "splipy", "fonttools", "matplotlib"):
        try:
            out.append(f"{pkg} {md.version(pkg)}")
        except md.PackageNotFoundError:
            out.append(f"{pkg} (not installed)")
    return ", ".join(out)


# ---------------------------------------------------------------------------------------------
def _f(x: Any) -> float:
    try:
        v = float(x)
    except (TypeError, ValueError):
        return math.nan
    return v


def _q(vals: list[float], q: float) -> float:
    v = np.array([x for x in vals if math.isfinite(x)])
    return float(np.quantile(v, q)) if v.size else math.nan


def _fmt(x: float, digits: int = 3) -> str:
    if not math.isfinite(x):
        return "-"
    if x == 0:
        return "0"
    if abs(x) >= 1000 or abs(x) < 1e-3:
        return f"{x:.2e}"
    if float(x).is_integer():
        return f"{int(x)}"
    return f"{x:.{digits}g}"


def _pct(k: int, n: int) -> str:
    return f"{100.0 * k / n:.0f}% ({k}/{n})" if n else "-"


def _tool_label(t: str | None) -> str:
    if t is None:  # a partial run (--tools) without any peer
        return "(no peer run)"
    return t.removeprefix("cf:").removeprefix("peer:") if t != BASELINE else "interpolant (input)"


class Table:
    """Rows of one corpus indexed by (case, tool), with per-case baseline values."""

    def __init__(self, rows: list[dict[str, Any]], corpus: str) -> None:
        self.rows = [r for r in rows if r["corpus"] == corpus]
        self.cases = list(dict.fromkeys(r["case"] for r in self.rows))
        self.tools = list(dict.fromkeys(r["tool"] for r in self.rows))
        self.by = {(r["case"], r["tool"]): r for r in self.rows}

    def tool_rows(self, tool: str) -> list[dict[str, Any]]:
        return [self.by[(c, tool)] for c in self.cases if (c, tool) in self.by]

    def ok_rows(self, tool: str) -> list[dict[str, Any]]:
        return [r for r in self.tool_rows(tool) if int(r.get("ok") or 0)]

    def ratio(self, tool: str, key: str) -> list[float]:
        out = []
        for r in self.ok_rows(tool):
            b = self.by.get((r["case"], BASELINE))
            if b is None or not int(b.get("ok") or 0):
                continue
            den = _f(b.get(key))
            num = _f(r.get(key))
            if den > 0 and math.isfinite(num):
                out.append(num / den)
        return out

    def values(self, tool: str, key: str) -> list[float]:
        return [_f(r.get(key)) for r in self.ok_rows(tool)]

    def hits(self, tool: str, key: str = "hit_extrema") -> tuple[int, int]:
        rows = self.tool_rows(tool)
        n = len(self.cases)
        return sum(int(_f(r.get(key)) == 1) for r in rows if int(r.get("ok") or 0)), n

    def failures(self, tool: str) -> tuple[int, int]:
        rows = self.tool_rows(tool)
        na = sum(1 for r in rows if not int(r.get("ok") or 0) and int(r.get("na") or 0))
        fail = sum(1 for r in rows if not int(r.get("ok") or 0) and not int(r.get("na") or 0))
        return fail, na

    def violations(self, tool: str) -> list[dict[str, Any]]:
        return [r for r in self.ok_rows(tool) if int(r.get("violation") or 0)]


def _worst_at(t: "Table", tool: str) -> str:
    """``case #point (n points)`` of the largest deviation / tol of ``tool``."""
    rows = [x for x in t.ok_rows(tool) if math.isfinite(_f(x.get("dev_over_tol")))]
    if not rows or tool == BASELINE:
        return "-"
    w = max(rows, key=lambda x: _f(x["dev_over_tol"]))
    return f"{w['case']} #{w.get('dev_index')}/{w['n_points']}"


def _mq(vals: list[float]) -> str:
    return f"{_fmt(_q(vals, 0.5))} / {_fmt(_q(vals, 0.9))}"


# ---------------------------------------------------------------------------------------------
def table_ground_truth(t: Table) -> list[str]:
    head = ("| tool | true extrema count reached | true inflection count reached | extrema - true "
            "(median / p90) | E2 / E2(input) | E3 / E3(input) | int kappa_s^2 ds / input | "
            "max dev / tol (median / p90 / max) | largest at (curve #point/points) | "
            "distance to true curve / tol | pieces (median) | time ms | failed |")
    out = [head, "|" + "---|" * 13]
    for tool in t.tools:
        rows = t.ok_rows(tool)
        h, n = t.hits(tool)
        hi, _ = t.hits(tool, "hit_inflections")
        n_inf = sum(1 for c in t.cases if t.by.get((c, BASELINE), {}).get("true_inflections")
                    not in ("", None))
        excess = [_f(r["extrema"]) - _f(r["true_extrema"]) for r in rows]
        dev = t.values(tool, "dev_over_tol")
        dist = [_f(r.get("truth_dist")) / _f(r["tol"]) for r in rows]
        tms = [1000 * _f(r.get("time_s")) for r in rows]
        fail, na = t.failures(tool)
        viol = len(t.violations(tool))
        devs = (f"{_fmt(_q(dev, 0.5))} / {_fmt(_q(dev, 0.9))} / "
                f"{_fmt(max(dev) if dev else math.nan)}") + (
                    f" **{viol} VIOLATIONS**" if viol else "")
        out.append(f"| {_tool_label(tool)} | {_pct(h, n)} | {_pct(hi, n_inf)} | {_mq(excess)} | "
                   f"{_mq(t.ratio(tool, 'E2'))} | {_mq(t.ratio(tool, 'E3'))} | "
                   f"{_mq(t.ratio(tool, 'dkds'))} | {devs} | {_worst_at(t, tool)} | "
                   f"{_mq(dist)} | {_fmt(_q(t.values(tool, 'n_segments'), 0.5))} | "
                   f"{_fmt(_q(tms, 0.5))} | {fail}{f' (+{na} n/a)' if na else ''} |")
    return out


def table_share_by(t: Table, key: str) -> list[str]:
    groups = list(dict.fromkeys(str(r[key]) for r in t.rows))
    heads = []
    for g in groups:
        trues = sorted({int(_f(r["true_extrema"])) for r in t.rows if str(r[key]) == g})
        heads.append(f"{g} (true: {', '.join(map(str, trues))})" if key == "family" else g)
    out = ["| tool | " + " | ".join(heads) + " | all |", "|" + "---|" * (len(groups) + 2)]
    for tool in t.tools:
        cells = []
        for g in groups:
            rows = [r for r in t.tool_rows(tool) if str(r[key]) == g]
            k = sum(1 for r in rows if int(r.get("ok") or 0) and _f(r.get("hit_extrema")) == 1)
            cells.append(f"{k}/{len(rows)}")
        h, n = t.hits(tool)
        out.append(f"| {_tool_label(tool)} | " + " | ".join(cells) + f" | **{h}/{n}** |")
    return out


def table_real(t: Table) -> list[str]:
    head = ("| tool | extrema (median / p90) | extrema / input (median / p90) | fewer extrema "
            "than input | inflections (median / p90) | E2 / E2(input) | E3 / E3(input) | "
            "int kappa_s^2 ds / input | max dev / tol (median / p90 / max) | largest at "
            "(curve #point/points) | pieces (median) | time ms | failed |")
    out = [head, "|" + "---|" * 13]
    for tool in t.tools:
        rows = t.ok_rows(tool)
        fewer = 0
        for r in rows:
            b = t.by.get((r["case"], BASELINE))
            if b is not None and int(b.get("ok") or 0) and _f(r["extrema"]) < _f(b["extrema"]):
                fewer += 1
        dev = t.values(tool, "dev_over_tol")
        tms = [1000 * _f(r.get("time_s")) for r in rows]
        fail, na = t.failures(tool)
        viol = len(t.violations(tool))
        devs = (f"{_fmt(_q(dev, 0.5))} / {_fmt(_q(dev, 0.9))} / "
                f"{_fmt(max(dev) if dev else math.nan)}") + (
                    f" **{viol} VIOLATIONS**" if viol else "")
        out.append(f"| {_tool_label(tool)} | {_mq(t.values(tool, 'extrema'))} | "
                   f"{_mq(t.ratio(tool, 'extrema'))} | "
                   f"{_pct(fewer, len(t.cases)) if tool != BASELINE else '-'} | "
                   f"{_mq(t.values(tool, 'inflections'))} | {_mq(t.ratio(tool, 'E2'))} | "
                   f"{_mq(t.ratio(tool, 'E3'))} | {_mq(t.ratio(tool, 'dkds'))} | {devs} | "
                   f"{_worst_at(t, tool)} | {_fmt(_q(t.values(tool, 'n_segments'), 0.5))} | "
                   f"{_fmt(_q(tms, 0.5))} | {fail}"
                   f"{f' (+{na} n/a)' if na else ''} |")
    return out


# ---------------------------------------------------------------------------------------------
_RB_KEYS = ("extrema", "inflections", "E2", "E3", "dkds", "n_segments", "truth_dist",
            "hit_extrema", "hit_inflections")


def rebuilt_rows(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The rows with every curve metric taken from the curve rebuilt from the written points
    (the ``*_rb`` columns of ``run.py``)."""
    out = []
    for r in rows:
        x = dict(r)
        for k in _RB_KEYS:
            x.pop(k, None)
            if k + "_rb" in r:
                x[k] = r[k + "_rb"]
        out.append(x)
    return out


def goal_lines(tabs_rb: dict[str, "Table"], tool: str = "cf:points-l1") -> list[str]:
    """Issue 13's goals, measured on the rebuilt curves, for ``tool`` and the best peer."""
    L: list[str] = []
    gt, af, gl, pf = (tabs_rb[k] for k in CORPORA)
    if tool not in set(gt.tools) | set(af.tools) | set(gl.tools) | set(pf.tools):
        return L
    if gt.cases and tool in gt.tools:
        h, n = gt.hits(tool)
        hi, _ = gt.hits(tool, "hit_inflections")
        n_inf = sum(1 for c in gt.cases if gt.by.get((c, BASELINE), {}).get("true_inflections")
                    not in ("", None))
        bp = best_tool(gt, "peer:")
        hp = gt.hits(bp)[0] if bp else 0
        d = _q([_f(r["truth_dist"]) / _f(r["tol"]) for r in gt.ok_rows(tool)], 0.5)
        dp = _q([_f(r["truth_dist"]) / _f(r["tol"]) for r in gt.ok_rows(bp)], 0.5) if bp else \
            math.nan
        L += [f"- Ground truth, rebuilt curves: `{_tool_label(tool)}` reaches the true extrema "
              f"count on {h}/{n} (goal >= 55; best peer `{_tool_label(bp)}` {hp}/{n}), the "
              f"true inflection count on {hi}/{n_inf} (goal >= 66); median distance to the "
              f"true curve {_fmt(d)} tol (best peer {_fmt(dp)}).", ""]
    for name, t, goal in (("Airfoils", af, "median <= 0.35, p90 <= 0.7"),
                          ("Glyph runs", gl, "median <= 0.2")):
        if t.cases and tool in t.tools:
            r = t.ratio(tool, "extrema")
            bp = best_real_tool(t, "peer:")
            rp = t.ratio(bp, "extrema") if bp else []
            L += [f"- {name}, rebuilt curves: extrema ratio to the input median / p90 "
                  f"{_fmt(_q(r, 0.5))} / {_fmt(_q(r, 0.9))} over {len(r)} curves (goal "
                  f"{goal}); best peer `{_tool_label(bp)}` {_fmt(_q(rp, 0.5))} / "
                  f"{_fmt(_q(rp, 0.9))}.", ""]
    if pf.cases and tool in pf.tools:
        ex = [_f(r["extrema"]) - _f(r["true_extrema"]) for r in pf.ok_rows(tool)]
        bp = min((x for x in pf.tools if x.startswith("peer:")),
                 key=lambda x: _q([_f(r["extrema"]) - _f(r["true_extrema"])
                                   for r in pf.ok_rows(x)] or [math.inf], 0.5), default=None)
        exp = [_f(r["extrema"]) - _f(r["true_extrema"]) for r in pf.ok_rows(bp)] if bp else []
        L += [f"- Point files of five families ({len(pf.cases)} curves), rebuilt curves: median "
              f"excess of extrema over the true curve {_fmt(_q(ex, 0.5))} for "
              f"`{_tool_label(tool)}` (goal <= 2); best peer `{_tool_label(bp)}` "
              f"{_fmt(_q(exp, 0.5))}.", ""]
    return L


# ---------------------------------------------------------------------------------------------
def best_tool(t: Table, prefix: str) -> str | None:
    """The tool with ``prefix`` reaching the true extrema count most often (ties: smaller
    median excess)."""
    cands = [x for x in t.tools if x.startswith(prefix)]
    if not cands:
        return None

    def key(tool: str) -> tuple[float, float]:
        h, _ = t.hits(tool)
        ex = [abs(_f(r["extrema"]) - _f(r["true_extrema"])) for r in t.ok_rows(tool)]
        return (-h, _q(ex, 0.5) if ex else math.inf)

    return min(cands, key=key)


def best_real_tool(t: Table, prefix: str) -> str | None:
    """Fewest extrema relative to the input (median ratio), among tools with no violation."""
    cands = [x for x in t.tools if x.startswith(prefix) and not t.violations(x)]
    if not cands:
        return None
    return min(cands, key=lambda x: (_q(t.ratio(x, "extrema"), 0.5), -len(t.ok_rows(x))))


def _comb_scale(curve: Any, extent: float) -> float | None:
    """The 95th-percentile hair 6 % of the extent, the longest at most 35 % (so that one spike,
    e.g. at a sharp trailing edge, does not flatten the comb everywhere else)."""
    import curvefair as cf

    t0, t1 = curve.domain
    k = np.abs(cf.curvature(curve, np.linspace(t0, t1, 4001)))
    k95, kmax = float(np.quantile(k, 0.95)), float(k.max())
    return min(0.06 * extent / k95, 0.35 * extent / kmax) if k95 > 0 else None


def draw(case: C.Case, tool: str, paths: tuple[Path, Path], title: str) -> str | None:
    """Two figures (input interpolant, result of ``tool``), each with its curvature comb and its
    curvature plot, each at its own comb scale; returns an error text on failure."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import run as R

        from curvefair.plot import figure

        ext = float(np.ptp(case.points, axis=0).max())
        for curve_tool, path, label in ((BASELINE, paths[0], "input interpolant"),
                                        (tool, paths[1], _tool_label(tool))):
            curve = R.run_tool(case, curve_tool)
            if curve is None:
                return "no curve"
            fig = figure(curve, title=f"{label}: {title}", comb_scale=_comb_scale(curve, ext),
                         figsize=(6.4, 7.2))
            if case.truth is not None and case.dim == 2:
                poly = case.truth.polyline(4001)
                fig.axes[0].plot(poly[:, 0], poly[:, 1], ":", color="0.3", lw=0.8)
            fig.savefig(path, dpi=72)
        return None
    except Exception as exc:  # noqa: BLE001
        return repr(exc)[:200]


# ---------------------------------------------------------------------------------------------
def write_page(rows: list[dict[str, Any]], cases: list[C.Case], info: dict[str, Any],
               out: Path, img: Path) -> None:
    out.parent.mkdir(parents=True, exist_ok=True)
    img.mkdir(parents=True, exist_ok=True)
    for old in img.glob("*.png"):
        old.unlink()
    by_name = {c.name: c for c in cases}
    tabs = {k: Table(rows, k) for k in CORPORA}
    gt, af, gl = tabs["ground-truth"], tabs["airfoils"], tabs["glyphs"]
    rrows = rebuilt_rows(rows)
    tabs_rb = {k: Table(rrows, k) for k in CORPORA}
    rel_img = os.path.relpath(img, out.parent)

    L: list[str] = []
    L += ["# Fairing quality benchmark", "",
          "*Generated by `" + info["command"] + "` on " + info["date"] + " ("
          + f"{info['elapsed_s'] / 60:.1f} min on {info['jobs']} processes; {info['machine']}). "
          + "Do not edit by hand between the markers: every number and figure there comes "
          "from that run; the sections after the end marker are written by hand and kept by "
          "the benchmark.*", "",
          f"Versions: {info['versions']}.", ""]
    if info.get("reused"):
        L += [f"> Partly reused: {info['reused']}.", ""]
    if info.get("quick"):
        L += ["> **Quick run** (`--quick`): a tiny subset, for checking the pipeline only. "
              "Run `make bench-quality` for the real figures.", ""]

    L += ["The question: *at the deviation I can accept, which tool gives me the fairest curve?* "
          "Every tool below receives the same points and the same allowed maximum deviation "
          "`tol`; curvefair's methods are called as `fair(curve, method, tol=tol)` (and with "
          "`eps=0`, i.e. run until the tolerance blocks every move or the step cap is hit), the "
          "peers' smoothing parameter is bisected until their maximum deviation reaches `tol`. "
          "`fair-points` is `curvefair.fair_points(points, tol)` with its defaults: it starts "
          "from the points, not from a curve (the minimiser of E3 over quintic splines with a "
          "knot at every chord-length parameter, subject to |C(u_i) - p_i| <= tol at every "
          "point).", ""]

    # verdict ---------------------------------------------------------------------------------
    L += ["## Verdict", ""]
    viol_all = [(tl, r) for k, t in tabs.items() for tl in t.tools if tl.startswith("cf:")
                for r in t.violations(tl)]
    if viol_all:
        L += [f"> **TOLERANCE VIOLATIONS: {len(viol_all)} curvefair results deviate from the "
              "input by more than `tol`.** Listed under *Tolerance violations* below.", ""]
    else:
        L += ["- No curvefair result broke its tolerance (max deviation <= tol on every curve "
              "of every corpus, every method).", ""]
    if gt.cases:
        bc = best_tool(gt, "cf:")
        bp = best_tool(gt, "peer:")
        hc, n = gt.hits(bc) if bc else (0, len(gt.cases))
        hp, _ = gt.hits(bp) if bp else (0, len(gt.cases))
        hb, _ = gt.hits(BASELINE)
        verdict = ("**met**" if hc > hp else "**not met**")
        L += [f"- Ground truth ({n} curves): curvefair's best method, `{_tool_label(bc)}`, "
              f"reaches the true curvature-extrema count on {_pct(hc, n)} of the curves; the "
              f"best peer, `{_tool_label(bp)}`, on {_pct(hp, n)}; the unfaired interpolant on "
              f"{_pct(hb, n)}. Goal (more than any peer, at equal maximum deviation): "
              f"{verdict}.", ""]
        if bc and bp:
            def med(tool: str, key: str, den: str | None = None) -> float:
                rows = gt.ok_rows(tool)
                return _q([_f(r[key]) / (_f(r[den]) if den else 1.0) for r in rows], 0.5)

            L += [f"- On the same curves, the median distance to the *true* curve is "
                  f"{_fmt(med(bc, 'truth_dist', 'tol'))} tol for `{_tool_label(bc)}` and "
                  f"{_fmt(med(bp, 'truth_dist', 'tol'))} tol for `{_tool_label(bp)}`; the median "
                  f"number of polynomial pieces is {_fmt(med(bc, 'n_segments'))} and "
                  f"{_fmt(med(bp, 'n_segments'))} (the interpolant has one per input interval"
                  + ("; `make_splprep` chooses its own, fewer, knots)." if bp ==
                     "peer:scipy-splprep" else ")."), ""]
    if af.cases:
        ba = best_real_tool(af, "cf:")
        if ba:
            r_af = af.ratio(ba, "extrema")
            fewer = sum(1 for r in af.ok_rows(ba) if _f(r["extrema"]) < _f(
                af.by[(r["case"], BASELINE)].get("extrema")))
            b_ext = af.values(BASELINE, "extrema")
            a_ext = af.values(ba, "extrema")
            bpa = best_real_tool(af, "peer:")
            L += [f"- Airfoils ({len(af.cases)} UIUC files, tol = {C.AIRFOIL_TOL:g} chord): "
                  f"`{_tool_label(ba)}` lowers the curvature-extrema count on "
                  f"{_pct(fewer, len(af.cases))} of them (median {_fmt(_q(b_ext, 0.5))} -> "
                  f"{_fmt(_q(a_ext, 0.5))}; median ratio {_fmt(_q(r_af, 0.5))}), with "
                  f"{len(af.violations(ba))} tolerance violations."
                  + (f" Best peer by the same measure: `{_tool_label(bpa)}`, median ratio "
                     f"{_fmt(_q(af.ratio(bpa, 'extrema'), 0.5))}." if bpa else ""), ""]

    L += goal_lines(tabs_rb)
    L += goal_lines(tabs_rb, "cf:cli-default")

    # corpus ---------------------------------------------------------------------------------
    L += ["## Corpus", "",
          "Built by `benchmarks/quality/corpus.py` (nothing but the aerosandbox wheel is "
          "fetched, by `pip download`, and only its `.dat` files are read; aerosandbox is never "
          "imported):", ""]
    fams = defaultdict(int)
    for c in cases:
        if c.corpus == "ground-truth":
            fams[c.family] += 1
    if gt.cases:
        lv = sorted({c.noise for c in cases if c.corpus == "ground-truth"})
        L += [f"- **ground truth**: {len(gt.cases)} curves = "
              + ", ".join(f"{k} {v}" for k, v in fams.items())
              + f"; each true curve sampled at jittered arc-length spacing (NACA: parameter "
              f"spacing, clustered at the leading edge) and perturbed by Gaussian noise of "
              f"sigma = {', '.join(f'{x:g}' for x in lv)} of the bounding-box diagonal; "
              f"`tol = {C.TOL_FACTOR:g} sigma`. True extrema/inflection counts by dense exact "
              "evaluation (checked against the closed forms in the tests); extrema narrower "
              "than the sample spacing are not counted (this only concerns the NACA 00xx "
              "double curvature peak 5e-5 chord behind the leading edge).", ""]
    if af.cases:
        L += [f"- **airfoils**: {len(af.cases)} UIUC coordinate files (of those in the "
              f"aerosandbox {C.AEROSANDBOX_VERSION} wheel that parse as Selig or Lednicer, have "
              f"30-400 distinct points and no spike), evenly spread over the sorted file names; "
              f"open curves from trailing edge to trailing edge; `tol = {C.AIRFOIL_TOL:g} "
              "chord`.", ""]
    if gl.cases:
        L += [f"- **glyphs**: {len(gl.cases)} smooth runs of DejaVu Sans / Serif outlines "
              "(the TrueType files inside matplotlib, read with fontTools), split at corners "
              "(tangent turn > 8 degrees), sampled about every 0.02 em along the quadratic "
              f"arcs; closed when a contour has no corner; `tol = {C.GLYPH_TOL:g} em`.", ""]

    # method ---------------------------------------------------------------------------------
    L += ["## How the numbers are made comparable", "",
          "- **One parameter.** Every tool fits the input points at their chord-length "
          "parameters, and every result is a curvefair curve on that same parameter domain "
          "(scipy and splipy results via `BSplineCurve.from_scipy`/`BSplineCurve`, csaps via "
          "its piecewise-polynomial form). E2 = int |r''|^2 du and E3 = int |r'''|^2 du are "
          "parametric, hence shown relative to the input interpolant's on the same curve "
          "(Kjellander's method uses equally spaced parameters over the same range, so its "
          "E2/E3 ratios are not strictly comparable).",
          "- **One analysis.** Extrema, inflections, E2, E3 and int (dkappa/ds)^2 ds all come "
          "from `curvefair.analyze` (exact sign counts: sign changes of dkappa/ds, across knots "
          "included, with a 1e-9 relative noise band). Open curves count interior extrema, "
          "closed ones all.",
          "- **One deviation.** `max_i |C(u_i) - p_i|` over the input points at each tool's "
          "parameters: what the smoothing splines fit and what curvefair's `tol` bounds (a data "
          "point or control point of the interpolant never moves farther than tol). It is "
          "checked for every curvefair result.",
          "- **Peers at equal deviation.** csaps (`smooth`), scipy `make_smoothing_spline` "
          "(`lam`) and `make_splprep` (`s`) are bisected on a log scale for the smoothest result "
          "with max deviation <= tol (converged when within 2 % of tol; FITPACK's knot "
          "placement makes `make_splprep` non-monotone, so it may stop lower). splipy has no "
          "smoothing fit: its `utils.smooth.smooth` (control-point averaging) is applied to the "
          "interpolating B-spline as many times as the tolerance allows (open curves only). "
          "csaps and `make_smoothing_spline` have no periodic mode; closed inputs are wrapped "
          "(three periods, middle one kept).",
          "- **Distance to the true curve**: largest distance from the result (24 samples per "
          "segment) to a 20 001-vertex polyline of the true curve.", ""]

    L += ["## Reading notes", "",
          "- *Reached* means the exact count from `curvefair.analyze` equals the true one: every "
          "ripple of the curvature counts, however small. Circle arcs and helices have constant "
          "curvature (true count 0); a spline fitted to noisy points practically never has a "
          "curvature without any interior extremum, so no tool is expected to reach 0 there; "
          "the 'extrema - true' column says how far each tool stays.",
          "- A result with fewer polynomial pieces has fewer places where its curvature can "
          "turn. curvefair's methods keep every input point (Hermite methods) or every control "
          "point of the interpolant (B-spline methods) and move each within its own `tol` "
          "ball; a point held on its ball typically leaves a small third-derivative jump, i.e. "
          "a possible curvature extremum. The 'pieces' column shows the difference.",
          "- `fair-points` has no per-point balls around an interpolant's control points: one "
          "convex problem over the whole curve, and the quintic minimiser of E3 is C4, so an "
          "active point leaves a jump only in the fifth derivative and dkappa/ds stays "
          "continuous. Being an energy minimiser it uses the whole tolerance: every active point "
          "sits exactly at `tol` (max dev / tol = 1), which is why its distance to the true "
          "curve is larger than that of the smoothing splines, whose least-squares term keeps "
          "most points well inside. It cannot reach 0 extrema on circles and helices (no tool "
          "does). On open curves its optimality conditions impose natural ends (the third and "
          "fourth derivatives vanish at both ends), which flattens the curvature there: on "
          "every clothoid (monotone curvature, true count 0) it leaves exactly one extremum "
          "near each end (3-17 % of the parameter range from it). A fix would be end "
          "conditions that do not force r''' to 0 (e.g. end derivatives estimated from the "
          "data, or the energy integrated over a shortened domain).",
          "- `eps0` = `eps=0`; `l3` = the third-derivative energy E3 instead of E2 "
          "(`fair(..., l=3)`). Methods that do not use eps give the same result in both rows.",
          ""]

    # tables ---------------------------------------------------------------------------------
    if gt.cases:
        L += ["## Ground truth", "",
              "Medians and 90th percentiles over the curves. 'failed' counts errors; "
              "'n/a' a tool that does not handle the curve (splipy on closed curves).", ""]
        L += table_ground_truth(gt) + [""]
        L += ["### True extrema count reached, by family", ""] + table_share_by(gt, "family") + [""]
        L += ["### True extrema count reached, by noise level (sigma / diagonal)", ""]
        L += table_share_by(gt, "noise") + [""]
    if af.cases:
        L += ["## Airfoils (UIUC)", "", "No true curve: 'fewer extrema than input' compares with "
              "the natural cubic interpolant of the file's points.", ""]
        L += table_real(af) + [""]
    if gl.cases:
        L += ["## Glyph outlines (DejaVu)", ""] + table_real(gl) + [""]
    if any(t.cases for t in tabs_rb.values()):
        L += ["## Counted on the curve rebuilt from the written points", "",
              "A point file stores only points: the curve a reader rebuilds is the chord-length "
              "natural (closed: periodic) cubic through the written points (each tool's curve "
              "at the input's parameters; a Hermite result's own data points). Every curve "
              "metric below is that of the rebuilt curve; deviations are those of the written "
              "points. 'point files' are five curve families not in the ground truth "
              "(log spiral, sine, cardioid, lemniscate, cycloid arcs; noise and tol as there).",
              ""]
        for key, title, fn in (("ground-truth", "Ground truth, rebuilt", table_ground_truth),
                               ("point-files", "Point files (five families), rebuilt",
                                table_ground_truth),
                               ("airfoils", "Airfoils, rebuilt", table_real),
                               ("glyphs", "Glyph runs, rebuilt", table_real)):
            if tabs_rb[key].cases:
                L += [f"### {title}", ""] + fn(tabs_rb[key]) + [""]
                if key in ("ground-truth", "point-files"):
                    L += table_share_by(tabs_rb[key], "family") + [""]

    # violations -----------------------------------------------------------------------------
    if viol_all:
        L += ["## Tolerance violations", "", "| tool | case | max dev / tol | at point |",
              "|---|---|---|---|"]
        for tl, r in viol_all[:200]:
            L.append(f"| {_tool_label(tl)} | {r['case']} | {_fmt(_f(r['dev_over_tol']), 6)} | "
                     f"{r.get('dev_index')} |")
        L.append("")

    # figures --------------------------------------------------------------------------------
    figs: list[tuple[str, str, str, str]] = []  # (file stem, caption, case, tool)
    if gt.cases:
        bc = best_tool(gt, "cf:")
        bp = best_tool(gt, "peer:")
        base = {r["case"]: r for r in gt.ok_rows(BASELINE)}
        rows = [r for r in gt.ok_rows(bc) if r["case"] in base] if bc else []
        hit = [r for r in rows if _f(r.get("hit_extrema")) == 1]
        if hit:
            b = max(hit, key=lambda r: _f(base[r["case"]]["extrema"]) - _f(r["extrema"]))
            figs.append(("gt-best", f"Ground truth, best case for `{_tool_label(bc)}`: "
                         f"{b['case']} (true extrema {b['true_extrema']}, input interpolant "
                         f"{base[b['case']]['extrema']}, result {b['extrema']})", b["case"], bc))
        if rows:
            w = max(rows, key=lambda r: abs(_f(r["extrema"]) - _f(r["true_extrema"])))
            figs.append(("gt-worst", f"Ground truth, worst case for `{_tool_label(bc)}`: "
                         f"{w['case']} (true extrema {w['true_extrema']}, result "
                         f"{w['extrema']})", w["case"], bc))
            if bp:
                pr = gt.by.get((w["case"], bp), {})
                figs.append(("gt-worst-peer", f"The same case with the best peer "
                             f"`{_tool_label(bp)}` (result {pr.get('extrema', '-')} extrema)",
                             w["case"], bp))
    for key, label in (("airfoils", "Airfoil"), ("glyphs", "Glyph run")):
        t = tabs[key]
        bt = best_real_tool(t, "cf:") if t.cases else None
        if not bt:
            continue
        base = {r["case"]: r for r in t.ok_rows(BASELINE)}
        rows = [r for r in t.ok_rows(bt) if r["case"] in base]
        if not rows:
            continue

        def gain(r: dict[str, Any], base: dict[str, Any] = base) -> float:
            return _f(base[r["case"]]["extrema"]) - _f(r["extrema"])

        b, w = max(rows, key=gain), min(rows, key=gain)
        figs.append((f"{key}-best", f"{label} with the largest extrema reduction by "
                     f"`{_tool_label(bt)}`: {b['case']} ({base[b['case']]['extrema']} -> "
                     f"{b['extrema']})", b["case"], bt))
        if key == "airfoils":
            figs.append((f"{key}-worst", f"{label} with the smallest reduction: {w['case']} "
                         f"({base[w['case']]['extrema']} -> {w['extrema']})", w["case"], bt))
    # the new default as a user gets it: the curve read back from the written file
    for key, label in (("airfoils", "Airfoil"), ("ground-truth", "Ground-truth curve"),
                       ("point-files", "Point file")):
        t = tabs_rb[key]
        if not t.cases or DEFAULT_TOOL not in t.tools:
            continue
        base = {r["case"]: r for r in t.ok_rows(BASELINE)}
        rows = [r for r in t.ok_rows(DEFAULT_TOOL) if r["case"] in base]
        if not rows:
            continue
        if key == "airfoils":
            w = max(rows, key=lambda r: (_f(r["extrema"]) / max(_f(base[r["case"]]["extrema"]),
                                                                 1.0), r["case"]))
            what = (f"{base[w['case']]['extrema']} -> {w['extrema']} extrema, the largest "
                    "ratio to the input")
        else:
            w = max(rows, key=lambda r: (abs(_f(r["extrema"]) - _f(r["true_extrema"])),
                                         r["case"]))
            what = (f"true extrema {w['true_extrema']}, input {base[w['case']]['extrema']}, "
                    f"written file {w['extrema']}")
        figs.append((f"default-{key}-worst", f"{label}, worst case for the default "
                     f"(`curvefair fair IN -o OUT --tol T`, the curve read back from OUT; "
                     f"method {w.get('stop_reason') or '-'}): {w['case']} ({what})",
                     w["case"], DEFAULT_TOOL))
    if figs:
        L += ["## Curvature combs (before / after)", "",
              "Left: the input interpolant (natural cubic spline through the points); right: "
              "the result. Each panel: curve with its curvature comb (hairs on the convex side, "
              "length proportional to curvature; each figure at its own scale, stated in its "
              "corner), data points or control polygon, true curve dotted where known, "
              "inflections and curvature extrema marked; below, curvature against arc length.",
              ""]
        for slug, caption, case_name, tool in figs:
            names = (f"{slug}-before.png", f"{slug}-after.png")
            err = draw(by_name[case_name], tool, (img / names[0], img / names[1]),
                       case_name)
            if err:
                L += [f"*{caption}: figure failed ({err})*", ""]
            else:
                L += [f"**{caption}**", "", "| before | after |", "|---|---|",
                      f"| ![{slug} before]({rel_img}/{names[0]}) | "
                      f"![{slug} after]({rel_img}/{names[1]}) |", ""]

    L += ["## Reproduce", "", "```", "make bench-quality        # full run (writes this page)",
          "python benchmarks/quality/run.py --quick   # pipeline check on a tiny subset", "```",
          "", f"Per-curve results (one row per curve and tool, including the index of the point "
          f"where each maximum deviation sits) are written to `{info['csv']}` by each run "
          "(not committed).", ""]
    write_generated(out, "\n".join(L))


#: the generated part of the page lies between these two lines; whatever is before the first
#: and after the second is written by hand (e.g. other benchmarks' tables) and kept
BEGIN = ("<!-- bench-quality: generated, begin (make bench-quality rewrites up to the end "
         "marker) -->")
END = "<!-- bench-quality: generated, end (hand-written sections may follow) -->"


class PageError(RuntimeError):
    """The page exists but has no (or broken) generated-part markers: rewriting it whole would
    destroy hand-written text."""


def splice(old: str | None, generated: str) -> str:
    """``old`` with the text between :data:`BEGIN` and :data:`END` replaced by ``generated``
    (a page without ``old``: the generated part alone, between the markers)."""
    body = f"{BEGIN}\n{generated.rstrip()}\n{END}\n"
    if old is None or not old.strip():
        return body
    i, j = old.find(BEGIN), old.find(END)
    if i < 0 or j < 0 or j < i or old.count(BEGIN) != 1 or old.count(END) != 1:
        raise PageError("the page has no single pair of generated-part markers (add "
                        f"{BEGIN!r} and {END!r} around the generated part, or write the "
                        "run elsewhere with --out)")
    tail = old[j + len(END):].lstrip("\n")
    return old[:i] + body + ("\n" + tail if tail else "")


def write_generated(out: Path, generated: str) -> None:
    """Write ``generated`` into ``out`` between the markers, keeping the rest (atomic)."""
    old = out.read_text() if out.exists() else None
    text = splice(old, generated)
    tmp = out.with_name(out.name + ".tmp")
    tmp.write_text(text)
    os.replace(tmp, out)
