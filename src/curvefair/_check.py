"""``curvefair check``: fairness findings for every curve :func:`curvefair.read_curves` returns.

Nothing is written. Every record of every file (any format a reader exists for, fonts
included once their reader is registered) is measured on its piecewise-polynomial form
(``curve.piecewise``: ``coeffs[i, j]`` multiplies ``(t - breaks[i])**j``) and four findings
are reported, each against a threshold:

``kink``
    A join meant to be smooth that is not: the angle between the left and right tangents
    (:func:`curvefair.fairing.joins.join_angles`) is above ``kink_angle`` (degrees) but below
    ``corner_angle`` (a larger turn is a corner drawn on purpose).
``g2-break``
    A tangent-continuous join (angle at most ``kink_angle``) whose curvature vector jumps:
    ``|k+ - k-| / max(|k+|, |k-|, 1/L) > g2_rel`` with ``k = (r'' - (r''.T) T) / |r'|^2`` the
    curvature vector on either side and ``L`` the arc length.
    A join where one side is a straight segment (a line, or a degenerate Bezier segment
    whose control points lie on its chord: :func:`_straight_segments`) is not tested for a
    G2 break: the curvature there steps from 0 to the curve's by design (the smooth
    line-to-curve node of type design, where the handle is collinear with the line), the
    join is G1 on purpose and ``rel`` would be 1 at every such join. It is still tested for
    a kink, and a join of two curved segments is tested as above. The rule reads the
    segments' shape, not the file format, so it serves every format with line segments.
``extra-inflection``
    Two consecutive inflections (sign changes of the curvature, :func:`curvefair.analyze`)
    closer than ``wiggle`` times the arc length: an S-wiggle a fair curve does not have. Also
    reported when the count of inflections exceeds ``max_inflections`` (if given).
``bad-point``
    The worst breakpoints by the Sapidis-Farin measure ``z_j = |dk/ds(t_j+) - dk/ds(t_j-)|``
    (:attr:`curvefair.analysis.Analysis.sapidis`), made scale-free as
    ``z_j / (k_j^2 + 1/L^2)`` (a leading edge's large curvature is not a bad point by itself);
    reported when above ``max_bad``. Reference figures: a clean cubic interpolant of 200
    points on an ellipse gives 0.2, of 60 points on a sine 22; the same with 1e-4 (ellipse) or
    1e-3 (sine) noise 6400 and 590; NACA 2412 from its .dat 1800. The default thresholds are
    measured on the real files of tests/data/real and on fonts (``benchmarks/calibrate_check.py``;
    the figures are in docs/benchmarks.md).

Font contours (records with a ``source["outline"]``) also name the glyph and the nearest
contour point (``point_index``, 0-based, as a font editor numbers the contour's points).

Joins where one side has zero speed (a degenerate control polygon) have no tangent and are
skipped.

A threshold of None switches its finding off. Each curve reports at most ``top`` findings per
kind (the worst), each saying how many the curve had.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ._version import __version__
from .errors import CurvefairError, FileFormatError

__all__ = ["THRESHOLDS", "RULES", "check_records", "check_file", "to_sarif", "Finding"]

#: Default thresholds (see the module docstring).
THRESHOLDS: dict[str, float | None] = {"kink_angle": 0.05, "corner_angle": 10.0,
                                       "g2_rel": 0.05, "wiggle": 0.02,
                                       "max_inflections": None, "max_bad": 5000.0}

RULES: dict[str, str] = {
    "kink": "a join meant to be smooth has a tangent break (kink)",
    "g2-break": "the curvature jumps at a tangent-continuous join of two curved segments "
                "(G2 break)",
    "extra-inflection": "extra inflections: an S-wiggle (two inflections close together) or "
                        "more inflections than allowed",
    "bad-point": "a bad point: a large jump of dk/ds at a breakpoint (Sapidis-Farin measure "
                 "over curvature squared + 1/L^2)",
    "unreadable": "the file could not be read",
}


@dataclass
class Finding:
    file: str
    curve: int
    label: str
    rule: str
    message: str
    value: float
    threshold: float | None
    param: float | None = None
    point: list[float] | None = None
    extra: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {"file": self.file, "curve": self.curve, "label": self.label, "rule": self.rule,
                "message": self.message, "value": _num(self.value),
                "threshold": _num(self.threshold), "param": _num(self.param),
                "point": self.point, **self.extra}


def _num(v: Any) -> Any:
    if v is None:
        return None
    v = float(v)
    return v if math.isfinite(v) else repr(v)


def _side_derivatives(pp: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """First and second derivatives at the left end (``d1r``, ``d2r``) and right end
    (``d1l``, ``d2l``) of every segment, from the local power-basis coefficients."""
    c = np.asarray(pp.coeffs, dtype=float)
    w = np.asarray(pp.widths, dtype=float)
    p = c.shape[1] - 1
    zero = np.zeros_like(c[:, 0, :])
    d1r = c[:, 1, :] if p >= 1 else zero
    d2r = 2.0 * c[:, 2, :] if p >= 2 else zero
    d1l = sum((j * c[:, j, :] * w[:, None] ** (j - 1) for j in range(1, p + 1)), zero)
    d2l = sum((j * (j - 1) * c[:, j, :] * w[:, None] ** (j - 2) for j in range(2, p + 1)), zero)
    return d1r, d2r, d1l, d2l


def _kvec(d1: np.ndarray, d2: np.ndarray) -> np.ndarray:
    s2 = float(d1 @ d1)
    if s2 == 0.0:
        return np.zeros_like(d1)
    t = d1 / math.sqrt(s2)
    return (d2 - (d2 @ t) * t) / s2


def _straight_segments(pp: Any) -> np.ndarray:
    """Which segments are straight: every power-basis term ``c[i, j] w_i^j`` (``j >= 1``) is
    parallel to the chord ``d_i = r(breaks[i+1]) - r(breaks[i]) = sum_j c[i, j] w_i^j`` to
    ``1e-9`` of ``max(|d_i|, |c[i, 0]|)`` (rounding of the basis change), so that every point
    ``r(t) = c[i, 0] + sum_j c[i, j] (t - breaks[i])^j`` lies on the chord's line. For a
    Bezier segment this is its control points being collinear with the chord (a line drawn as
    a degenerate cubic or quadratic, as font outlines store lines). A zero chord is not
    straight (a loop or a point)."""
    c = np.asarray(pp.coeffs, dtype=float)
    w = np.asarray(pp.widths, dtype=float)
    p = c.shape[1] - 1
    terms = np.stack([c[:, j, :] * w[:, None] ** j for j in range(1, p + 1)], axis=1)
    d = terms.sum(axis=1)
    dn = np.linalg.norm(d, axis=1)
    tol = 1e-9 * np.maximum(dn, np.linalg.norm(c[:, 0, :], axis=1))
    safe = np.where(dn > 0, dn, 1.0)
    t = d / safe[:, None]
    perp = terms - np.einsum("ijk,ik->ij", terms, t)[:, :, None] * t[:, None, :]
    dev = np.linalg.norm(perp, axis=2).max(axis=1)
    return np.asarray((dn > 0) & (dev <= tol), dtype=bool)


def _regular(a: np.ndarray, b: np.ndarray, width: float, L: float) -> bool:
    """Both one-sided speeds at a join are above ``1e-6`` of the mean speed ``L / width``."""
    ref = 1e-6 * L / width if width > 0 else 0.0
    return bool(np.linalg.norm(a) > ref and np.linalg.norm(b) > ref)


def _angle(a: np.ndarray, b: np.ndarray) -> float:
    na, nb = float(np.linalg.norm(a)), float(np.linalg.norm(b))
    if na == 0.0 or nb == 0.0:
        return 0.0
    cross = np.linalg.norm(np.cross(a, b)) if a.size == 3 else abs(a[0] * b[1] - a[1] * b[0])
    return math.degrees(math.atan2(float(cross), float(a @ b)))


def _arc(pp: Any, u: np.ndarray, per_segment: int = 32) -> tuple[np.ndarray, np.ndarray]:
    """Arc length at dense parameters (chords of ``per_segment`` samples per segment)."""
    br = np.asarray(pp.breaks, dtype=float)
    f = np.linspace(0.0, 1.0, per_segment, endpoint=False)
    uu = np.append((br[:-1, None] + np.diff(br)[:, None] * f[None, :]).ravel(), br[-1])
    r = pp.evaluate(uu)
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(r, axis=0), axis=1))])
    return uu, s


def check_records(records: Sequence[Any], file: str = "",
                  thresholds: Mapping[str, float | None] | None = None,
                  top: int = 3) -> list[Finding]:
    """The findings for ``records`` (see the module docstring), in curve order."""
    from . import analyze

    th = dict(THRESHOLDS)
    th.update(thresholds or {})
    found: list[Finding] = []
    for i, rec in enumerate(records):
        out: list[Finding] = []
        curve = rec.curve
        label = rec.name if rec.name else f"curve {i}"
        pp = curve.piecewise
        br = np.asarray(pp.breaks, dtype=float)
        m = len(br) - 1
        a = analyze(curve)
        L = float(a.arc_length)
        d1r, d2r, d1l, d2l = _side_derivatives(pp)
        straight = _straight_segments(pp)
        joins = [(k, k - 1, k) for k in range(1, m)]
        outline = (getattr(rec, "source", None) or {}).get("outline")
        if curve.closed or (outline is not None and outline.closed and m > 1):
            # a closed glyph contour is a chain from its seam node round to it: the seam is a
            # join too (the reader puts the seam at the first corner, so a kink is often there)
            joins.append((0, m - 1, 0))

        def at(u: float, pp: Any = pp) -> list[float]:
            return [float(v) for v in pp.evaluate(np.array([u]))[0]]

        width = float(br[-1] - br[0])
        for bk, left, right in joins:
            if not _regular(d1l[left], d1r[right], width, L):
                continue  # a zero-speed point: no tangent, no curvature to compare
            ang = _angle(d1l[left], d1r[right])
            u = float(br[bk])
            if th["kink_angle"] is not None and th["kink_angle"] < ang < (
                    th["corner_angle"] if th["corner_angle"] is not None else 180.0):
                out.append(Finding(file, i, label, "kink",
                                   f"kink of {ang:.4g} deg at a join (break {bk})", ang,
                                   th["kink_angle"], u, at(u)))
            elif th["g2_rel"] is not None and (th["kink_angle"] is None
                                                or ang <= th["kink_angle"]) and not (
                    straight[left] or straight[right]):  # line beside curve: G1 by design
                kl, kr = _kvec(d1l[left], d2l[left]), _kvec(d1r[right], d2r[right])
                scale = max(float(np.linalg.norm(kl)), float(np.linalg.norm(kr)),
                            1.0 / L if L > 0 else 0.0)
                rel = float(np.linalg.norm(kr - kl)) / scale if scale > 0 else 0.0
                if rel > th["g2_rel"]:
                    out.append(Finding(file, i, label, "g2-break",
                                       f"curvature jumps by {rel:.3g} (relative) at a "
                                       f"tangent-continuous join (break {bk})", rel,
                                       th["g2_rel"], u, at(u),
                                       {"curvature_left": float(np.linalg.norm(kl)),
                                        "curvature_right": float(np.linalg.norm(kr))}))
        ip = np.sort(np.asarray(a.inflection_params, dtype=float))
        if th["wiggle"] is not None and ip.size >= 2 and L > 0:
            uu, s = _arc(pp, ip)
            si = np.interp(ip, uu, s)
            gaps = np.diff(si) / L
            for g, u0, u1 in zip(gaps, ip[:-1], ip[1:], strict=True):
                if g < th["wiggle"]:
                    um = 0.5 * (u0 + u1)
                    out.append(Finding(file, i, label, "extra-inflection",
                                       f"two inflections {g:.3g} of the arc length apart "
                                       "(an S-wiggle)", float(g), th["wiggle"], um, at(um)))
        if th["max_inflections"] is not None and a.inflections > th["max_inflections"]:
            out.append(Finding(file, i, label, "extra-inflection",
                               f"{a.inflections} inflections (at most "
                               f"{th['max_inflections']:g} allowed)", float(a.inflections),
                               th["max_inflections"]))
        if th["max_bad"] is not None and len(a.sapidis):
            ju = np.asarray(a.jump_params, dtype=float)
            d1, d2 = pp.evaluate(ju, 1), pp.evaluate(ju, 2)
            kap = np.array([float(np.linalg.norm(_kvec(x, y))) for x, y in zip(d1, d2,
                                                                                 strict=True)])
            z = np.asarray(a.sapidis, dtype=float) / (kap**2 + (1.0 / L**2 if L > 0 else 0.0))
            regular = np.array([_regular(d1l[(j - 1) % m], d1r[j % m], width, L)
                                for j in np.asarray(a.jump_indices, dtype=int)], dtype=bool)
            z = np.where(regular & np.isfinite(z), z, 0.0)
            order = np.argsort(-z, kind="stable")
            for j in order:
                if z[j] > th["max_bad"]:
                    u = float(ju[j])
                    out.append(Finding(file, i, label, "bad-point",
                                       f"bad point: |Δ dκ/ds| / (κ² + 1/L²) = {z[j]:.4g} at "
                                       f"break {int(a.jump_indices[j])}", float(z[j]),
                                       th["max_bad"], u, at(u)))
        _name_points(rec, out)
        found += _worst(out, top)
    return found


def _name_points(rec: Any, findings: list[Finding]) -> None:
    """Font contours: each finding also names the glyph and the contour point nearest to it
    (``extra["glyph"]``, ``extra["point_index"]``, 0-based in the contour's point list), the
    way a type designer finds it in a font editor."""
    src = getattr(rec, "source", None) or {}
    outline = src.get("outline")
    if outline is None or "glyph" not in src:
        return
    P = np.asarray(outline.points, dtype=float)
    on = np.asarray(outline.on, dtype=bool)
    for f in findings:
        if f.point is None:
            continue
        d = np.linalg.norm(P - np.asarray(f.point[:2], dtype=float), axis=1)
        # an on-curve point when one is as near as the nearest point (joins are nodes)
        k = int(np.argmin(np.where(on, d, np.inf))) if on.any() else int(np.argmin(d))
        if d[k] > float(d.min()) + 1e-9 * max(1.0, float(np.abs(P).max())):
            k = int(np.argmin(d))
        f.extra["glyph"] = src["glyph"]
        f.extra["point_index"] = k
        f.message += f" (glyph {src['glyph']!r}, contour {src.get('contour')}, point {k})"


#: Which way is worse, per rule (a smaller gap between inflections is a worse wiggle).
_WORSE_LOW = {"extra-inflection"}


def _worst(findings: list[Finding], top: int) -> list[Finding]:
    """At most ``top`` findings per rule of one curve, the worst first; the kept ones say how
    many the curve had (``n_on_curve``) so a noisy curve is one short entry, not hundreds."""
    by_rule: dict[str, list[Finding]] = {}
    for f in findings:
        by_rule.setdefault(f.rule, []).append(f)
    out: list[Finding] = []
    for rule, group in by_rule.items():
        group.sort(key=lambda f: f.value if rule in _WORSE_LOW else -f.value)
        for f in group[:top]:
            f.extra["n_on_curve"] = len(group)
            if len(group) > top:
                f.message += f" (worst {top} of {len(group)} on this curve)"
            out.append(f)
    return out


def check_file(path: str, thresholds: Mapping[str, float | None] | None = None, *,
               corner_angle: float | None = 60.0, strict: bool = False,
               select: Mapping[str, Any] | None = None,
               polylines: bool = False,
               columns: tuple[int, ...] | None = None) -> tuple[list[Finding], int]:
    """``(findings, number of curves checked)`` for one file; an unreadable file is one
    ``unreadable`` finding. ``polylines``: a drawing's straight-line shapes (SVG, DXF, 3dm) are
    read as point lists and checked too (point data always are). ``columns``: a points
    file's coordinate columns (other formats ignore it)."""
    import warnings

    from . import read_curves
    from .batch import selected
    from .io import columns_for, detect_format, polylines_for

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            kind = detect_format(path)
            recs = read_curves(path, corner_angle=corner_angle,
                               on_unsupported="raise" if strict else "skip",
                               polylines=polylines_for(kind, polylines),
                               columns=columns_for(kind, columns))
    except (CurvefairError, OSError) as exc:
        if isinstance(exc, FileFormatError) and "no curves in the" in str(exc):
            return [], 0  # a drawing without curves has nothing unfair in it
        msg = str(exc) if isinstance(exc, CurvefairError) else f"{exc.strerror or exc}"
        return [Finding(path, -1, "", "unreadable", msg, float("nan"), None)], 0
    sel = [r for r in recs if select is None or selected(r, select)]
    idx = [k for k, r in enumerate(recs) if select is None or selected(r, select)]
    found = check_records(sel, path, thresholds)
    for f in found:
        f.curve = idx[f.curve]
    return found, len(sel)


def to_sarif(findings: Sequence[Finding], root: str | None = None) -> dict[str, Any]:
    """The findings as a SARIF 2.1.0 log (one run, one rule per finding kind)."""
    rule_ids = list(RULES)
    results = []
    for f in findings:
        uri = f.file
        if root is not None:
            try:
                uri = os.path.relpath(os.path.abspath(f.file), root)
            except ValueError:
                uri = os.path.abspath(f.file)
        uri = uri.replace(os.sep, "/")
        res: dict[str, Any] = {
            "ruleId": f.rule, "ruleIndex": rule_ids.index(f.rule),
            "level": "error" if f.rule == "unreadable" else "warning",
            "message": {"text": (f"{f.label}: " if f.label else "") + f.message},
            "locations": [{"physicalLocation": {"artifactLocation": {"uri": uri}}}],
            "properties": {"curve": f.curve, "value": _num(f.value),
                           "threshold": _num(f.threshold), "parameter": _num(f.param),
                           "point": f.point},
        }
        if f.curve >= 0:
            res["locations"][0]["logicalLocations"] = [
                {"name": f.label, "fullyQualifiedName": f"{uri}#{f.curve}", "kind": "object"}]
        results.append(res)
    return {
        "$schema": "https://json.schemastore.org/sarif-2.1.0.json",
        "version": "2.1.0",
        "runs": [{
            "tool": {"driver": {
                "name": "curvefair", "version": __version__,
                "rules": [{"id": r, "name": r.replace("-", " ").title().replace(" ", ""),
                           "shortDescription": {"text": d},
                           "defaultConfiguration": {
                               "level": "error" if r == "unreadable" else "warning"}}
                          for r, d in RULES.items()]}},
            "results": results,
        }],
    }


def to_json(findings: Sequence[Finding], n_files: int, n_curves: int) -> str:
    return json.dumps({"curvefair": __version__, "n_files": n_files, "n_curves": n_curves,
                       "n_findings": len(findings),
                       "findings": [f.to_dict() for f in findings]}, indent=2,
                      allow_nan=False)
