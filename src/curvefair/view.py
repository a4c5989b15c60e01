"""A self-contained interactive HTML page of curves and their fairness (``curvefair view``).

:func:`write_html` (and :func:`to_html`) write one HTML file holding its data, script and style
inline: it opens from disk in any browser, with no server, no network access and no external
script or font. The page shows

* every curve with its curvature comb (hairs ``r - S kappa N``, pointing away from the centre of
  curvature as in :func:`curvefair.plot.curvature_comb`; the scale ``S`` chosen robustly by
  :func:`curvefair.plot.robust_comb_scale`, hairs longer than the clip length drawn at that
  length), one check box per curve to show or hide it and a click to focus it;
* with a second set of curves (``compare``, e.g. the faired file) a before / after / both
  toggle, and for the focused curve the deviation along its arc length with its maximum marked:
  ``|after(t) - before(t)|`` on a common parameter domain, its maximum the certified one of
  :func:`curvefair.deviation`; else the distance to the nearest point of ``before``;
* the curvature of the focused curve against arc length, on a linear, symmetric-log
  (``sign(k) log10(1 + |k| / c)``) or clipped axis (the default chosen as in
  :func:`curvefair.plot.curvature_axis_mode`, so a leading edge does not flatten the rest);
* the tolerance and the report (a fairing report dict, e.g. the ``--report`` JSON, or a
  per-curve summary from :func:`curvefair.analyze` when none is given).

3-D curves are drawn projected onto the best-fit plane of all of them (as
:func:`curvefair.plot.figure` does). Large curves are drawn from at most ``max_samples``
samples per curve (the report's figures are computed on the curves themselves).

:func:`curve_svg` gives the small inline SVG that curves and fairing results show in a notebook
(``_repr_html_``).
"""

from __future__ import annotations

import html
import json
import math
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ._typing import FloatArray
from .curves.piecewise import PiecewiseCurve
from .errors import InputError

__all__ = ["to_html", "write_html", "page_data", "curve_svg"]

#: Samples per curve for the drawn path, the curvature and the deviation.
MAX_SAMPLES = 1500
#: Hairs per curve.
MAX_HAIRS = 400

_BEFORE = "#8c8c8c"
_AFTER = "#1f4e79"
_HAIR = "#5b9bd5"
_HAIR_BEFORE = "#c9c9c9"
_MARK = "#c92a2a"


# ------------------------------------------------------------------------------------------
# sampling
# ------------------------------------------------------------------------------------------
def _sample(curve: PiecewiseCurve, target: int) -> dict[str, FloatArray]:
    """Points, curvature, curvature vectors and arc length at about ``target`` samples.

    Curves with few segments are sampled on every segment including both its ends (so curvature
    jumps at breakpoints show, :func:`curvefair.plot._sample`, arc length by Gauss-Legendre
    quadrature); curves with more segments than ``target / 4`` at ``target`` equally spaced
    parameters (arc length from the chords: display only).
    """
    from . import plot as P

    m = curve.piecewise.n_segments
    if 4 * m <= target:
        smp = P._sample(curve, max(1, math.ceil(target / m) - 1))
        return {"u": smp.flat("u"), "r": smp.flat("r"), "kvec": smp.flat("kvec"),
                "kappa": smp.flat("kappa"), "s": smp.flat("s")}
    t0, t1 = curve.domain
    u = np.linspace(t0, t1, target)
    r = curve(u)
    d1 = curve(u, 1)
    d2 = curve(u, 2) if curve.degree >= 2 else np.zeros_like(d1)
    kvec, kappa = P._curvature_vectors(curve, u, d1, d2, "right")
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(r, axis=0), axis=1))])
    return {"u": u, "r": r, "kvec": kvec, "kappa": kappa, "s": s}


def _nums(a: Any, digits: int = 7) -> list[float]:
    """Flattened finite values rounded to ``digits`` significant digits (for a small page)."""
    a = np.asarray(a, dtype=float).reshape(-1)
    a = np.where(np.isfinite(a), a, 0.0)
    return [float(f"{v:.{digits}g}") for v in a.tolist()]


def _as_curves(x: Any, name: str) -> list[PiecewiseCurve]:
    """A list of curves from one curve-like object (:func:`curvefair.as_curve`), or from a list
    (or a tuple of curves / records); records and results give their ``.curve``."""
    from .interop import as_curve

    def _is_curve(c: Any) -> bool:
        return isinstance(getattr(c, "curve", c), PiecewiseCurve)

    if isinstance(x, list) or (isinstance(x, tuple) and x and all(_is_curve(c) for c in x)):
        if not x:
            raise InputError(f"{name} is an empty sequence of curves")
        return [as_curve(getattr(c, "curve", c), f"{name}[{i}]") for i, c in enumerate(x)]
    return [as_curve(getattr(x, "curve", x), name)]


def _summary(curve: PiecewiseCurve) -> dict[str, Any]:
    from .analysis import analyze

    a = analyze(curve)
    return {"type": type(curve).__name__, "degree": int(curve.degree),
            "segments": int(curve.piecewise.n_segments), "closed": bool(curve.closed),
            "arc_length": float(a.arc_length), "inflections": int(a.inflections),
            "extrema": int(a.extrema), "energy2": float(a.energy2),
            "max_jump": float(a.max_jump)}


def _json_safe(obj: Any) -> Any:
    """A JSON-ready copy: numpy scalars/arrays to Python, non-finite floats to None."""
    if isinstance(obj, Mapping):
        return {str(k): _json_safe(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_json_safe(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _json_safe(obj.tolist())
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        v = float(obj)
        return v if math.isfinite(v) else None
    if obj is None or isinstance(obj, (str, int, bool)):
        return obj
    return str(obj)


# ------------------------------------------------------------------------------------------
# the page's data
# ------------------------------------------------------------------------------------------
def page_data(curves: Any, compare: Any = None, *, names: Sequence[str | None] | None = None,
              tol: float | None = None, report: Mapping[str, Any] | None = None,
              title: str | None = None, y_down: bool = False,
              max_samples: int = MAX_SAMPLES) -> dict[str, Any]:
    """The data the page draws, as a JSON-ready dict (see the module docstring).

    Parameters
    ----------
    curves : curve or sequence of curves (or of :class:`~curvefair.CurveRecord`)
        Anything :func:`curvefair.as_curve` accepts.
    compare : same, optional
        As many curves, paired in order (e.g. the faired ones).
    names : sequence of str, optional
        One label per curve (default ``curve 0``, ``curve 1``, ...; a record's ``name``).
    tol : float, optional
        Tolerance drawn on the deviation plot and printed.
    report : mapping, optional
        Shown as the report (e.g. :attr:`curvefair.FairingResult.report` or a ``--report``
        file); default: a per-curve summary of :func:`curvefair.analyze` figures.
    title : str, optional
    y_down : bool
        The coordinates' y axis points down (SVG files): the page draws them that way up.
    max_samples : int
        Samples per drawn curve.
    """
    from . import plot as P
    from ._validate import as_positive

    recs = list(curves) if isinstance(curves, (list, tuple)) and curves and all(
        hasattr(c, "curve") for c in curves) else None
    before = _as_curves(curves, "curves")
    after = None if compare is None else _as_curves(compare, "compare")
    if after is not None and len(after) != len(before):
        raise InputError(f"compare has {len(after)} curves but curves has {len(before)}; "
                         "they are paired in order")
    if names is None:
        names = [getattr(r, "name", None) for r in recs] if recs else [None] * len(before)
    names = list(names)
    if len(names) != len(before):
        raise InputError(f"names has {len(names)} entries for {len(before)} curves")
    tol_v = None if tol is None else float(as_positive(tol, "tol", window=True))
    if isinstance(max_samples, bool) or not isinstance(max_samples, (int, np.integer)) \
            or max_samples < 16:
        raise InputError(f"max_samples must be an integer >= 16, got {max_samples!r}")

    everything = before + (after or [])
    dims = {c.dim for c in everything}
    if len(dims) > 1:
        raise InputError("curves shown together must all be 2-D or all 3-D")
    samples = [_sample(c, int(max_samples)) for c in everything]
    proj = P._Projector([smp["r"] for smp in samples], "plane")
    hair_samples = [_sample(c, MAX_HAIRS) for c in everything]
    scale, clip = P.robust_comb_scale(
        [h["kappa"] for h in hair_samples], [h["s"] for h in hair_samples],
        P._extent(np.vstack([smp["r"] for smp in samples])))

    def one(smp: dict[str, FloatArray], hs: dict[str, FloatArray]) -> dict[str, Any]:
        xy = proj(smp["r"])
        base = proj(hs["r"])
        hair = -scale * proj.vec(hs["kvec"])
        ln = np.linalg.norm(hair, axis=1)
        if clip is not None:
            over = ln > clip
            hair[over] *= (clip / ln[over])[:, None]
        return {"xy": _nums(xy), "cb": _nums(base), "ct": _nums(base + hair),
                "s": _nums(smp["s"]), "k": _nums(smp["kappa"], 6)}

    out_curves: list[dict[str, Any]] = []
    n = len(before)
    for i, c in enumerate(before):
        entry: dict[str, Any] = {
            "name": names[i] if names[i] else f"curve {i}",
            "before": one(samples[i], hair_samples[i]),
            "after": None, "dev": None,
            "summary": {"before": _summary(c)},
        }
        if after is not None:
            a = after[i]
            entry["after"] = one(samples[n + i], hair_samples[n + i])
            entry["summary"]["after"] = _summary(a)
            entry["dev"] = _deviation_data(c, a, samples[n + i], proj)
            entry["summary"]["max_deviation"] = entry["dev"]["max"]
        out_curves.append(entry)
    return {
        "title": title or "curvefair view",
        "tol": tol_v,
        "y_down": bool(y_down),
        "dim": int(dims.pop()),
        "note": proj.note,
        "has_after": after is not None,
        "comb_scale": float(scale),
        "comb_clip": None if clip is None else float(clip),
        "kappa_mode": P.curvature_axis_mode([s["kappa"] for s in samples],
                                              [s["s"] for s in samples]),
        "curves": out_curves,
        "report": _json_safe(report) if report is not None else None,
    }


def _deviation_data(before: PiecewiseCurve, after: PiecewiseCurve, smp: dict[str, FloatArray],
                    proj: Any) -> dict[str, Any]:
    """Deviation of ``after`` from ``before`` along ``after``'s samples, and its maximum."""
    from . import plot as P
    from .analysis import deviation

    if P._same_domain(before, after):
        dev = np.linalg.norm(smp["r"] - before(smp["u"]), axis=1)
        d = deviation(before, after, kind="parametric")
        dmax, umax = float(d.max_distance), float(d.param)
        smax = float(np.interp(umax, smp["u"], smp["s"]))
        pmax = after(np.array([umax]))[0]
        parametric = True
    else:
        dev = P._nearest_distance(smp["r"], before)
        j = int(np.argmax(dev))
        dmax, smax, pmax = float(dev[j]), float(smp["s"][j]), smp["r"][j]
        parametric = False
    return {"d": _nums(dev, 6), "max": dmax, "max_s": smax,
            "max_xy": _nums(proj(pmax[None, :])), "parametric": parametric}


# ------------------------------------------------------------------------------------------
# the page
# ------------------------------------------------------------------------------------------
def _script_json(obj: Any) -> str:
    """JSON safe inside a <script> element (no ``</``, no ``<!--``)."""
    text = json.dumps(obj, separators=(",", ":"), allow_nan=False)
    return text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")


def to_html(curves: Any, compare: Any = None, **kw: Any) -> str:
    """The page as a string; arguments as for :func:`page_data`."""
    data = page_data(curves, compare, **kw)
    title = html.escape(str(data["title"]))
    return (_TEMPLATE.replace("__TITLE__", title)
            .replace("__STYLE__", _STYLE)
            .replace("__SCRIPT__", _SCRIPT)
            .replace("__DATA__", _script_json(data)))


def write_html(path: str | os.PathLike[str], curves: Any, compare: Any = None,
               **kw: Any) -> Path:
    """Write the page to ``path`` atomically (:func:`curvefair.io.atomic_path`: a temporary
    file in the same folder, renamed; a symlink is written through and stays a link).
    Arguments as for :func:`page_data`. Returns ``Path(path)``."""
    from .io import atomic_path

    text = to_html(curves, compare, **kw)
    with atomic_path(path) as tmp:
        Path(tmp).write_text(text, encoding="utf-8")
    return Path(path)


# ------------------------------------------------------------------------------------------
# notebook display
# ------------------------------------------------------------------------------------------
def curve_svg(curve: PiecewiseCurve, compare: PiecewiseCurve | None = None, *,
              width: int = 360, samples: int = 400, caption: str | None = None) -> str:
    """A small inline SVG of ``curve`` (and ``compare`` over it) with a light comb.

    At most ``samples`` points per curve whatever its size (equally spaced parameters for
    large curves), so the markup stays a few tens of kilobytes. The y axis points up.
    """
    from . import plot as P

    cs = [curve] + ([compare] if compare is not None else [])
    smp = [_sample(c, samples) for c in cs]
    hs = [_sample(c, 120) for c in cs]
    proj = P._Projector([s["r"] for s in smp], "plane")
    scale, clip = P.robust_comb_scale([h["kappa"] for h in hs], [h["s"] for h in hs],
                                      P._extent(np.vstack([s["r"] for s in smp])))
    paths = []
    allxy = []
    for j, (s, h) in enumerate(zip(smp, hs, strict=True)):
        xy = proj(s["r"])
        base = proj(h["r"])
        hair = -scale * proj.vec(h["kvec"])
        ln = np.linalg.norm(hair, axis=1)
        if clip is not None:
            over = ln > clip
            hair[over] *= (clip / ln[over])[:, None]
        tip = base + hair
        allxy += [xy, tip]
        paths.append((xy, base, tip, j))
    pts = np.vstack(allxy)
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    span = np.maximum(hi - lo, 1e-300)
    pad = 0.05 * float(max(span))
    lo, hi = lo - pad, hi + pad
    span = hi - lo
    height = int(max(60, min(2 * width, round(width * span[1] / span[0]))))
    sx = width / span[0]
    sy = height / span[1]
    k = min(sx, sy)

    def fmt(q: FloatArray) -> str:
        x = (q[:, 0] - lo[0]) * k
        y = height - (q[:, 1] - lo[1]) * k
        return " ".join(f"{a:.1f},{b:.1f}" for a, b in zip(x.tolist(), y.tolist(), strict=True))

    parts = []
    for xy, base, tip, j in paths:
        col, hc = (_AFTER, _HAIR) if j == len(paths) - 1 else (_BEFORE, _HAIR_BEFORE)
        hairs = " ".join(f"M{a} L{b}" for a, b in zip(fmt(base).split(), fmt(tip).split(),
                                                      strict=True))
        parts.append(f'<path d="{hairs}" stroke="{hc}" stroke-width="0.6" fill="none"/>')
        parts.append(f'<polyline points="{fmt(tip)}" stroke="{hc}" stroke-width="0.8" '
                     f'fill="none"/>')
        parts.append(f'<polyline points="{fmt(xy)}" stroke="{col}" stroke-width="1.6" '
                     f'fill="none"/>')
    cap = f"<div style='font:12px sans-serif;color:#444'>{html.escape(caption)}</div>" \
        if caption else ""
    return (f'<div class="curvefair-repr">{cap}<svg xmlns="http://www.w3.org/2000/svg" '
            f'width="{width}" height="{height}" viewBox="0 0 {width} {height}">'
            + "".join(parts) + "</svg></div>")


def curve_repr_html(curve: PiecewiseCurve) -> str:
    """``_repr_html_`` of a curve: its SVG and a one-line description."""
    pts = getattr(curve, "points", None)
    n = len(pts) if pts is not None else len(getattr(curve, "control_points", []))
    what = "points" if pts is not None else "control points"
    cap = (f"{type(curve).__name__}: degree {curve.degree}, {curve.dim}-D, "
           f"{'closed, ' if curve.closed else ''}{curve.piecewise.n_segments} segments, "
           f"{n} {what}")
    return curve_svg(curve, caption=cap)


def result_repr_html(result: Any) -> str:
    """``_repr_html_`` of a :class:`~curvefair.FairingResult`: before (grey) and after (blue),
    and the main report figures. The input curve is ``result.original`` (set by
    :func:`curvefair.fair`); a result without it shows the faired curve only."""
    r = result.report
    original = getattr(result, "original", None)
    rows = []
    for key in ("method", "steps", "stop_reason", "tol", "max_deviation",
                "max_point_displacement", "energy_before", "energy_after",
                "inflections_before", "inflections_after", "extrema_before", "extrema_after"):
        if key in r:
            v = r[key]
            if isinstance(v, float):
                v = repr(v) if key in ("tol", "max_deviation", "max_point_displacement") \
                    else f"{v:.6g}"
            rows.append(f"<tr><td>{html.escape(key)}</td><td>{html.escape(str(v))}</td></tr>")
    table = ("<table style='font:12px monospace;border-collapse:collapse'>" + "".join(rows)
             + "</table>")
    svg = curve_svg(result.curve, caption="FairingResult")
    if isinstance(original, PiecewiseCurve):
        svg = curve_svg(original, result.curve, caption="FairingResult: before (grey), after")
    return f"<div style='display:flex;gap:12px;align-items:flex-start'>{svg}{table}</div>"


# ------------------------------------------------------------------------------------------
# page template (inline style and script)
# ------------------------------------------------------------------------------------------
_TEMPLATE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<meta http-equiv="Content-Security-Policy" content="default-src 'none'; \
script-src 'unsafe-inline'; style-src 'unsafe-inline'; img-src data:">
<title>__TITLE__</title>
<style>__STYLE__</style></head>
<body class="show-both">
<header><h1 id="title">__TITLE__</h1><div id="info"></div></header>
<div id="main">
<aside id="side">
  <div id="modes"></div>
  <div class="ctl"><label><input type="checkbox" id="comb" checked> curvature comb</label></div>
  <div class="ctl">curvature axis <select id="kscale">
    <option value="linear">linear</option><option value="symlog">log (symmetric)</option>
    <option value="clip">clipped</option></select></div>
  <div class="ctl"><button id="all">all</button> <button id="none">none</button></div>
  <ul id="list"></ul>
</aside>
<section id="plots">
  <svg id="view" xmlns="http://www.w3.org/2000/svg" preserveAspectRatio="xMidYMid meet"></svg>
  <div class="cap" id="viewcap"></div>
  <svg id="kplot" xmlns="http://www.w3.org/2000/svg" viewBox="0 0 800 220"></svg>
  <svg id="dplot" xmlns="http://www.w3.org/2000/svg" viewBox="0 0 800 180"></svg>
  <div class="cap" id="devcap"></div>
</section>
</div>
<section id="reportbox"><h2>Report</h2><pre id="report"></pre></section>
<script type="application/json" id="curvefair-data">__DATA__</script>
<script>__SCRIPT__</script>
</body></html>
"""

_STYLE = """
body{font:13px/1.35 system-ui,sans-serif;margin:0;color:#222;background:#fff}
header{padding:6px 12px;border-bottom:1px solid #ddd}
h1{font-size:16px;margin:0}h2{font-size:14px;margin:4px 0}
#info{color:#555;font-size:12px}
#main{display:flex;align-items:flex-start}
#side{width:210px;flex:none;padding:8px;border-right:1px solid #eee;max-height:560px;overflow:auto}
#plots{flex:1;padding:8px;min-width:0}
#view{width:100%;height:420px;display:block;background:#fff;border:1px solid #eee}
#kplot,#dplot{width:100%;height:auto;display:block;margin-top:6px}
#list{list-style:none;padding:0;margin:6px 0}
#list li{cursor:pointer;padding:1px 2px;white-space:nowrap;overflow:hidden;text-overflow:ellipsis}
#list li.focus{background:#e8f0fa;font-weight:600}
.ctl{margin:4px 0}.cap{color:#555;font-size:12px;min-height:1em}
#reportbox{padding:6px 12px;border-top:1px solid #ddd}
#report{font:11px/1.3 monospace;max-height:300px;overflow:auto;background:#fafafa;padding:6px}
.curve{fill:none;stroke-linejoin:round}
.before.curve{stroke:#8c8c8c;stroke-dasharray:none}
.after.curve{stroke:#1f4e79}
.hairs,.env{fill:none}
.before.hairs,.before.env{stroke:#c9c9c9}.after.hairs,.after.env{stroke:#5b9bd5}
body.show-before .after{display:none}body.show-after .before{display:none}
body.nocomb .hairs,body.nocomb .env{display:none}
g.hidden{display:none}
.axis{stroke:#888;stroke-width:1}.grid{stroke:#eee;stroke-width:1}
.tick{font-size:11px;fill:#555}
"""

_SCRIPT = r"""
"use strict";
(function(){
const D = JSON.parse(document.getElementById("curvefair-data").textContent);
const NS = "http://www.w3.org/2000/svg";
const C = D.curves;
let focus = 0;
function el(tag, attrs, parent){
  const e = document.createElementNS(NS, tag);
  for (const k in attrs) e.setAttribute(k, attrs[k]);
  if (parent) parent.appendChild(e);
  return e;
}
function fmt(v){ if (v === null || v === undefined) return "-";
  if (typeof v !== "number") return String(v);
  if (v === 0) return "0"; const a = Math.abs(v);
  return (a >= 1e-3 && a < 1e5) ? String(+v.toPrecision(6)) : v.toExponential(4); }
function exact(v){ return (v === null || v === undefined) ? "-" : String(v); }
const ysign = D.y_down ? 1 : -1;
function pathXY(a){
  let s = "";
  for (let i = 0; i < a.length; i += 2)
    s += (i ? "L" : "M") + a[i] + " " + (ysign * a[i + 1]);
  return s;
}
function pathHairs(b, t){
  let s = "";
  for (let i = 0; i < b.length; i += 2)
    s += "M" + b[i] + " " + (ysign * b[i + 1]) + "L" + t[i] + " " + (ysign * t[i + 1]);
  return s;
}
// ---- header
const info = document.getElementById("info");
let txt = C.length + " curve" + (C.length === 1 ? "" : "s") + " (" + D.dim + "-D)";
if (D.tol !== null) txt += " · tolerance " + exact(D.tol);
if (D.has_after) {
  let m = 0; for (const c of C) m = Math.max(m, c.dev.max);
  txt += " · max deviation " + exact(m);
  if (D.tol !== null) txt += (m <= D.tol ? " (within tolerance)" : " (EXCEEDS tolerance)");
}
txt += " · comb hair = " + fmt(D.comb_scale) + " × κ" +
       (D.comb_clip !== null ? ", clipped at " + fmt(D.comb_clip) : "");
if (D.note) txt += " · " + D.note;
if (D.y_down) txt += " · y axis down (as in the file)";
info.textContent = txt;
// ---- mode toggle
const modes = document.getElementById("modes");
if (D.has_after) {
  for (const [v, lab] of [["both", "both"], ["before", "before"], ["after", "after"]]) {
    const l = document.createElement("label"); l.style.marginRight = "6px";
    const r = document.createElement("input"); r.type = "radio"; r.name = "mode"; r.value = v;
    r.id = "mode-" + v; if (v === "both") r.checked = true;
    r.addEventListener("change", () => setMode(v));
    l.appendChild(r); l.appendChild(document.createTextNode(" " + lab)); modes.appendChild(l);
  }
} else { document.body.className = "show-before"; }
function setMode(v){
  const nc = document.body.classList.contains("nocomb");
  document.body.className = "show-" + v + (nc ? " nocomb" : "");
  drawPlots();
}
document.getElementById("comb").addEventListener("change", (e) => {
  document.body.classList.toggle("nocomb", !e.target.checked); fitView(); });
const ksel = document.getElementById("kscale");
ksel.value = D.kappa_mode;
ksel.addEventListener("change", drawPlots);
// ---- curve view
const view = document.getElementById("view");
const groups = [];
C.forEach((c, i) => {
  const g = el("g", {"class": "cgroup", "data-curve": i}, view);
  for (const st of ["before", "after"]) {
    const d = c[st]; if (!d) continue;
    el("path", {"class": st + " hairs", d: pathHairs(d.cb, d.ct), "stroke-width": 0.6,
                "vector-effect": "non-scaling-stroke"}, g);
    el("path", {"class": st + " env", d: pathXY(d.ct), "stroke-width": 0.9,
                "vector-effect": "non-scaling-stroke"}, g);
  }
  for (const st of ["before", "after"]) {
    const d = c[st]; if (!d) continue;
    const p = el("path", {"class": st + " curve", d: pathXY(d.xy), "data-curve": i,
      "stroke-width": st === "after" ? 2 : (D.has_after ? 1.6 : 2),
      "vector-effect": "non-scaling-stroke"}, g);
    p.addEventListener("click", () => setFocus(i));
  }
  if (c.dev) {
    const mk = el("circle", {"class": "devmax-mark", cx: c.dev.max_xy[0],
      cy: ysign * c.dev.max_xy[1], r: 5, fill: "none", stroke: "#c92a2a", "stroke-width": 2,
      "vector-effect": "non-scaling-stroke", "data-curve": i}, g);
    mk.style.display = "none";
  }
  groups.push(g);
});
function fitView(){
  let x0 = Infinity, x1 = -Infinity, y0 = Infinity, y1 = -Infinity;
  const comb = !document.body.classList.contains("nocomb");
  C.forEach((c, i) => {
    if (groups[i].classList.contains("hidden")) return;
    for (const st of ["before", "after"]) {
      const d = c[st]; if (!d) continue;
      for (const a of (comb ? [d.xy, d.ct] : [d.xy]))
        for (let j = 0; j < a.length; j += 2) {
          const x = a[j], y = ysign * a[j + 1];
          if (x < x0) x0 = x; if (x > x1) x1 = x; if (y < y0) y0 = y; if (y > y1) y1 = y;
        }
    }
  });
  if (!isFinite(x0)) { x0 = 0; x1 = 1; y0 = 0; y1 = 1; }
  const w = Math.max(x1 - x0, 1e-300), h = Math.max(y1 - y0, 1e-300);
  const pad = 0.05 * Math.max(w, h);
  view.setAttribute("viewBox", (x0 - pad) + " " + (y0 - pad) + " " + (w + 2 * pad) + " " +
                    (h + 2 * pad));
  const rr = 0.012 * (Math.max(w, h) + 2 * pad);
  view.querySelectorAll(".devmax-mark").forEach((m) => m.setAttribute("r", rr));
}
// ---- list
const list = document.getElementById("list");
const boxes = [];
C.forEach((c, i) => {
  const li = document.createElement("li"); li.dataset.curve = i;
  const cb = document.createElement("input"); cb.type = "checkbox"; cb.checked = true;
  cb.className = "sel"; cb.dataset.curve = i;
  cb.addEventListener("click", (e) => e.stopPropagation());
  cb.addEventListener("change", () => { groups[i].classList.toggle("hidden", !cb.checked);
                                        fitView(); });
  li.appendChild(cb);
  let lab = " " + c.name;
  if (c.dev) lab += "  (" + fmt(c.dev.max) + ")";
  li.appendChild(document.createTextNode(lab));
  li.title = c.name;
  li.addEventListener("click", () => setFocus(i));
  list.appendChild(li); boxes.push(cb);
});
function setAll(v){ boxes.forEach((b, i) => { b.checked = v;
  groups[i].classList.toggle("hidden", !v); }); fitView(); }
document.getElementById("all").addEventListener("click", () => setAll(true));
document.getElementById("none").addEventListener("click", () => setAll(false));
// ---- plots
function kmap(mode, scale){
  if (mode === "symlog") return (k) => Math.sign(k) * Math.log10(1 + Math.abs(k) / scale);
  if (mode === "clip") return (k) => Math.max(-scale, Math.min(scale, k));
  return (k) => k;
}
function quantile(a, q){ const b = a.map(Math.abs).sort((x, y) => x - y);
  return b.length ? b[Math.min(b.length - 1, Math.floor(q * b.length))] : 0; }
function axes(svg, W, H, L, B, xr, yr, ylab, xlab, yticks){
  el("line", {"class": "axis", x1: L, y1: H - B, x2: W - 8, y2: H - B}, svg);
  el("line", {"class": "axis", x1: L, y1: 8, x2: L, y2: H - B}, svg);
  const t1 = el("text", {"class": "tick", x: W - 8, y: H - 4, "text-anchor": "end"}, svg);
  t1.textContent = xlab + "  [" + fmt(xr[0]) + " … " + fmt(xr[1]) + "]";
  for (const [yv, lab] of yticks) {
    const y = 8 + (H - B - 8) * (1 - (yv - yr[0]) / (yr[1] - yr[0]));
    if (!(y >= 7 && y <= H - B + 1)) continue;
    el("line", {"class": "grid", x1: L, y1: y, x2: W - 8, y2: y}, svg);
    const t = el("text", {"class": "tick", x: L - 4, y: y + 4, "text-anchor": "end"}, svg);
    t.textContent = lab;
  }
  const ty = el("text", {"class": "tick", x: L + 4, y: 18}, svg); ty.textContent = ylab;
}
function polyline(svg, xs, ys, xr, yr, W, H, L, B, attrs){
  let s = "";
  for (let i = 0; i < xs.length; i++) {
    const x = L + (W - 8 - L) * (xs[i] - xr[0]) / ((xr[1] - xr[0]) || 1);
    const y = 8 + (H - B - 8) * (1 - (ys[i] - yr[0]) / ((yr[1] - yr[0]) || 1));
    s += (i ? "L" : "M") + x.toFixed(2) + " " + y.toFixed(2);
  }
  attrs.d = s; attrs.fill = "none";
  return el("path", attrs, svg);
}
function drawPlots(){
  const c = C[focus];
  const mode = ksel.value;
  const showB = !document.body.classList.contains("show-after") || !c.after;
  const showA = c.after && !document.body.classList.contains("show-before");
  // curvature
  const kp = document.getElementById("kplot"); kp.innerHTML = "";
  const W = 800, H = 220, L = 70, B = 22;
  const sets = [];
  if (showB) sets.push(["before", c.before]);
  if (showA) sets.push(["after", c.after]);
  let all = []; let smax = 0;
  for (const [, d] of sets) { all = all.concat(d.k); smax = Math.max(smax, d.s[d.s.length - 1]); }
  const scale = mode === "symlog" ? Math.max(quantile(all, 0.5), 1e-300)
              : mode === "clip" ? Math.max(1.5 * quantile(all, 0.95), 1e-300) : 1;
  const f = kmap(mode, scale);
  let ylo = 0, yhi = 0;
  for (const k of all) { const v = f(k); if (v < ylo) ylo = v; if (v > yhi) yhi = v; }
  if (yhi - ylo <= 0) { ylo -= 1; yhi += 1; }
  const padk = 0.05 * (yhi - ylo); ylo -= padk; yhi += padk;
  let ticks = [];
  if (mode === "symlog") {
    for (const sgn of [-1, 1]) for (let e = -12; e <= 12; e++) {
      const k = sgn * Math.pow(10, e); const v = f(k);
      if (v >= ylo && v <= yhi && Math.abs(k) >= scale)
        ticks.push([v, (sgn < 0 ? "-" : "") + "1e" + e]);
    }
    ticks.push([0, "0"]);
  } else {
    for (let j = 0; j <= 4; j++) { const v = ylo + (yhi - ylo) * j / 4; ticks.push([v, fmt(v)]); }
  }
  axes(kp, W, H, L, B, [0, smax], [ylo, yhi],
       "curvature κ" + (D.dim === 2 ? " (signed)" : "") +
       (mode === "symlog" ? ", symmetric log (linear below " + fmt(scale) + ")" :
        mode === "clip" ? ", clipped at ±" + fmt(scale) : "") + " — " + c.name,
       "arc length s", ticks);
  for (const [st, d] of sets)
    polyline(kp, d.s, d.k.map(f), [0, smax], [ylo, yhi], W, H, L, B,
             {"class": "kcurve " + st, stroke: st === "after" ? "#1f4e79" : "#8c8c8c",
              "stroke-width": st === "after" ? 1.6 : 1.3});
  // deviation
  const dp = document.getElementById("dplot"); dp.innerHTML = "";
  const cap = document.getElementById("devcap");
  document.querySelectorAll(".devmax-mark").forEach((m) => { m.style.display = "none"; });
  if (!c.dev) { dp.style.display = "none"; cap.textContent = ""; return; }
  dp.style.display = "block";
  const H2 = 180; const dv = c.dev;
  let dtop = Math.max(dv.max, D.tol || 0) * 1.15 || 1;
  const ds = c.after.s;
  const sm = ds[ds.length - 1] || 1;
  const dt = []; for (let j = 0; j <= 4; j++) dt.push([dtop * j / 4, fmt(dtop * j / 4)]);
  axes(dp, W, H2, L, B, [0, sm], [0, dtop],
       (dv.parametric ? "deviation |after(t) − before(t)|"
                      : "distance to the nearest point of before"),
       "arc length s (after)", dt);
  polyline(dp, ds, dv.d, [0, sm], [0, dtop], W, H2, L, B,
           {"class": "dcurve", stroke: "#1f4e79", "stroke-width": 1.4});
  const yof = (v) => 8 + (H2 - B - 8) * (1 - v / dtop);
  if (D.tol !== null) {
    el("line", {"class": "tolline", x1: L, x2: W - 8, y1: yof(D.tol), y2: yof(D.tol),
                stroke: "#c92a2a", "stroke-dasharray": "5 4", "stroke-width": 1}, dp);
  }
  const mx = L + (W - 8 - L) * dv.max_s / sm;
  el("circle", {id: "dev-max", cx: mx, cy: yof(dv.max), r: 4.5, fill: "#c92a2a"}, dp);
  const lab = el("text", {id: "dev-max-label", x: Math.min(mx + 8, W - 260),
                          y: Math.max(yof(dv.max) + 4, 22),
                          "class": "tick", fill: "#c92a2a"}, dp);
  lab.textContent = "max " + exact(dv.max) + " at s = " + fmt(dv.max_s);
  cap.textContent = "max deviation " + exact(dv.max) +
    (D.tol !== null ? " · tolerance " + exact(D.tol) : "");
  const mk = groups[focus].querySelector(".devmax-mark"); if (mk) mk.style.display = "";
}
function setFocus(i){
  focus = i;
  list.querySelectorAll("li").forEach(
    (li) => li.classList.toggle("focus", +li.dataset.curve === i));
  drawPlots();
}
// ---- report
const rep = document.getElementById("report");
if (D.report) rep.textContent = JSON.stringify(D.report, null, 1);
else rep.textContent = JSON.stringify(
  C.map((c) => Object.assign({name: c.name}, c.summary)), null, 1);
fitView(); setFocus(0);
document.body.dataset.ready = "1";
})();
"""
