"""Corpus of the fairing quality benchmark.

Three corpora, all built here from formulas or from files shipped inside pip packages (nothing is
downloaded at run time except the aerosandbox wheel, fetched with ``pip download``):

* ``ground-truth`` -- fair curves with known curvature structure, sampled at jittered arc-length
  spacing and perturbed by seeded Gaussian noise at several levels: circle arcs, ellipse arcs,
  clothoid (Euler spiral) segments, cubic polynomial graphs, NACA 4-digit airfoils from their
  analytic formula, a 3-D helix and a closed superellipse ``|x/a|^4 + |y/b|^4 = 1``. Each case
  carries its true curve (a vectorised callable and a dense polyline) and the true number of
  curvature extrema and inflections.
* ``airfoils`` -- UIUC airfoil coordinate files as shipped in the aerosandbox wheel (read from the
  zip; aerosandbox is never imported nor installed).
* ``glyphs`` -- smooth runs of the TrueType outlines of DejaVu Sans / DejaVu Serif as shipped in
  matplotlib, read with fontTools and split at corners.

Conventions used for the *true* counts (the same as the benchmark applies to every fitted curve):

* planar curves: extrema of the signed curvature ``kappa(s)``; 3-D curves: of ``|kappa(s)|``;
* open curves count interior extrema only (the two ends are not extrema); closed curves count all;
* inflections: sign changes of the signed curvature (planar only; ``None`` in 3-D);
* a level stretch of constant curvature (circle, helix) has no extremum.

The counts are computed by *dense exact evaluation*: the true curve is evaluated at 20 001
parameters, its derivatives by central differences (positive kernels, so a curvature jump such as
the NACA camber line's at ``x = p`` cannot create an overshoot), and extrema counted as reversals
whose excursion exceeds ``1e-7`` of the curvature range. Where a closed form exists the generator
also states the analytic count and ``tests/test_quality_corpus.py`` checks that both agree.
"""

from __future__ import annotations

import math
import re
import subprocess
import sys
import zipfile
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.special import fresnel

HERE = Path(__file__).resolve().parent
CACHE = HERE / ".cache"
AEROSANDBOX_VERSION = "4.2.10"  # pinned so the corpus does not change under us

NOISE_LEVELS = (1e-4, 1e-3, 5e-3)  # noise sigma per coordinate, relative to the bbox diagonal
TOL_FACTOR = 4.0  # tolerance = TOL_FACTOR * sigma: P(|2-D noise| > 4 sigma) = exp(-8) = 3e-4
AIRFOIL_TOL = 1e-4  # chord
GLYPH_TOL = 1e-3  # em
DENSE = 20001

FAMILIES = ("circle", "ellipse", "clothoid", "cubic", "naca", "helix", "superellipse")


# ---------------------------------------------------------------------------------------------
# counting on dense samples
# ---------------------------------------------------------------------------------------------

def turning_points(f: np.ndarray, threshold: float) -> np.ndarray:
    """Indices of the direction reversals of ``f`` whose excursion exceeds ``threshold``.

    A zig-zag filter: a running extreme is confirmed as a turning point once the sequence has
    come back from it by more than ``threshold``. The first and last samples are never returned.
    """
    f = np.asarray(f, dtype=float)
    out: list[int] = []
    if f.size < 3:
        return np.array(out, dtype=int)
    direction = 0  # +1 rising, -1 falling, 0 unknown yet
    ext, iext = f[0], 0  # running extreme of the current leg
    for i in range(1, f.size):
        v = f[i]
        if direction == 0:
            if v - f[0] > threshold:
                direction, ext, iext = 1, v, i
            elif f[0] - v > threshold:
                direction, ext, iext = -1, v, i
            continue
        if (v - ext) * direction > 0:
            ext, iext = v, i
        elif (ext - v) * direction > threshold:
            out.append(iext)
            direction, ext, iext = -direction, v, i
    return np.array(out, dtype=int)


def count_reversals(f: np.ndarray, threshold: float) -> int:
    """Number of :func:`turning_points`."""
    return int(turning_points(f, threshold).size)


def extrema_indices(f: np.ndarray, closed: bool, rel: float = 1e-7) -> np.ndarray:
    """Indices of the local extrema of a densely sampled function.

    Open: interior extrema only. Closed (``f`` sampled once around, no repeated end): all,
    cyclically. Excursions below ``rel`` times the range of ``f`` are ignored (rounding noise).
    """
    f = np.asarray(f, dtype=float)
    span = float(f.max() - f.min())
    thr = rel * max(span, float(np.abs(f).max()), 1e-300)
    if span <= thr:
        return np.array([], dtype=int)
    if not closed:
        return turning_points(f, thr)
    k = int(np.argmax(f))
    g = np.concatenate([f[k:], f[:k], f[k:k + 1]])  # start and end at the global maximum
    idx = (turning_points(g, thr) + k) % f.size
    return np.sort(np.concatenate([[k], idx]))


def count_extrema(f: np.ndarray, closed: bool, rel: float = 1e-7) -> int:
    """Number of :func:`extrema_indices`."""
    return int(extrema_indices(f, closed, rel).size)


def merge_close(pos: np.ndarray, spacing: float, period: float | None = None) -> np.ndarray:
    """Drop adjacent pairs of extrema closer than ``spacing`` (closest pair first).

    ``pos`` are sorted arc-length positions of alternating maxima and minima; removing a pair
    keeps the alternation. ``period`` (closed curves) makes the gaps cyclic.
    """
    pos = list(np.asarray(pos, dtype=float))
    while len(pos) >= 2:
        gaps = np.diff(pos)
        if period is not None:
            gaps = np.append(gaps, pos[0] + period - pos[-1])
        j = int(np.argmin(gaps))
        if gaps[j] >= spacing:
            break
        k = (j + 1) % len(pos)
        for i in sorted((j, k), reverse=True):
            del pos[i]
    return np.array(pos)


def count_sign_changes(f: np.ndarray, closed: bool, rel: float = 1e-7) -> int:
    """Sign changes of ``f``, ignoring values within ``rel * max|f|`` of zero."""
    f = np.asarray(f, dtype=float)
    thr = rel * max(float(np.abs(f).max()), 1e-300)
    s = np.sign(f[np.abs(f) > thr])
    if s.size < 2:
        return 0
    n = int(np.count_nonzero(s[1:] != s[:-1]))
    if closed and s[0] != s[-1]:
        n += 1
    return n


# ---------------------------------------------------------------------------------------------
# true curves
# ---------------------------------------------------------------------------------------------

@dataclass(frozen=True, eq=False)
class TrueCurve:
    """A fair curve ``r(t)``, ``t0 <= t <= t1``, with its dense polyline and curvature counts."""

    family: str
    fn: Callable[[np.ndarray], np.ndarray]
    t0: float
    t1: float
    closed: bool
    analytic_extrema: int | None = None  # closed form, where one exists
    analytic_inflections: int | None = None
    params: dict = field(default_factory=dict)
    sampling: str = "arclength"  # or "param": equal parameter steps (NACA: clustered at the LE)

    @property
    def dim(self) -> int:
        return int(self.fn(np.array([self.t0])).shape[1])

    def dense_t(self, n: int = DENSE) -> np.ndarray:
        return np.linspace(self.t0, self.t1, n)

    def polyline(self, n: int = DENSE) -> np.ndarray:
        """``(n, dim)`` points at equal parameter steps (the closing point repeated if closed)."""
        return self.fn(self.dense_t(n))

    def curvature(self, n: int = DENSE) -> np.ndarray:
        """Signed curvature (planar) or curvature (3-D) at ``dense_t(n)`` by central differences."""
        t = self.dense_t(n)
        h = 1e-4 * (self.t1 - self.t0)
        # open curves: the formulas extend smoothly past the ends, only the end samples use it
        rp, rm, r0 = self.fn(t + h), self.fn(t - h), self.fn(t)
        d1 = (rp - rm) / (2 * h)
        d2 = (rp - 2 * r0 + rm) / (h * h)
        speed = np.linalg.norm(d1, axis=1)
        if d1.shape[1] == 2:
            cross = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
        else:
            cross = np.linalg.norm(np.cross(d1, d2), axis=1)
        return cross / speed**3

    def _kappa_for_counting(self) -> np.ndarray:
        k = self.curvature()
        return k[:-1] if self.closed else k[1:-1]  # closed: drop the repeated end

    @property
    def extrema(self) -> int:
        """True number of curvature extrema (dense exact evaluation)."""
        return count_extrema(self._kappa_for_counting(), self.closed)

    def resolvable_extrema(self, spacing: float) -> int:
        """Extrema left after dropping adjacent pairs closer than ``spacing`` in arc length.

        Features narrower than the sample spacing cannot be recovered from the samples by any
        tool (e.g. the NACA 00xx double curvature peak 5e-5 chord from the leading edge).
        """
        k = self._kappa_for_counting()
        idx = extrema_indices(k, self.closed)
        _, s = self.arclength_table()
        s = s[:-1] if self.closed else s[1:-1]
        return int(merge_close(s[idx], spacing, s[-1] if self.closed else None).size)

    @property
    def inflections(self) -> int | None:
        """True number of inflections (planar), ``None`` for a 3-D curve."""
        if self.dim != 2:
            return None
        return count_sign_changes(self._kappa_for_counting(), self.closed)

    def arclength_table(self, n: int = DENSE) -> tuple[np.ndarray, np.ndarray]:
        t = self.dense_t(n)
        p = self.fn(t)
        s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))])
        return t, s


def circle_arc(rng: np.random.Generator) -> TrueCurve:
    r = rng.uniform(0.5, 2.0)
    a0 = rng.uniform(0, 2 * np.pi)
    span = rng.uniform(0.5 * np.pi, 1.5 * np.pi)

    def fn(t):
        return np.column_stack([r * np.cos(t), r * np.sin(t)])

    return TrueCurve("circle", fn, a0, a0 + span, False, 0, 0, {"r": r})


def ellipse_arc(rng: np.random.Generator) -> TrueCurve:
    """``(a cos t, b sin t)`` over ``[-d0, pi + d1]``: extrema at t = 0, pi/2, pi (3 interior)."""
    a, b = rng.uniform(1.5, 3.0), 1.0
    d0, d1 = rng.uniform(0.3, 0.7, size=2)

    def fn(t):
        return np.column_stack([a * np.cos(t), b * np.sin(t)])

    return TrueCurve("ellipse", fn, -d0, np.pi + d1, False, 3, 0, {"a": a, "b": b})


def clothoid(rng: np.random.Generator) -> TrueCurve:
    """Euler spiral ``(C(t), S(t))`` (Fresnel integrals), curvature ``pi t``, t in [-a, b].

    Curvature is monotone and crosses zero once: 0 extrema, 1 inflection.
    """
    a, b = rng.uniform(0.6, 1.4, size=2)

    def fn(t):
        s, c = fresnel(t)
        return np.column_stack([c, s])

    return TrueCurve("clothoid", fn, -a, b, False, 0, 1, {"a": a, "b": b})


def cubic_graph(rng: np.random.Generator) -> TrueCurve:
    """Graph of ``y = A (x^3 - k x) + c x^2`` for x in [-1, 1].

    Extrema of kappa = y'' / (1 + y'^2)^(3/2) are the real roots in (-1, 1) of the quartic
    ``y''' (1 + y'^2) - 3 y' y''^2``; inflections the root of ``y''`` in (-1, 1).
    """
    A = rng.uniform(0.5, 1.5)
    k = rng.uniform(0.0, 1.0)
    c = rng.uniform(-0.3, 0.3)
    y = np.polynomial.Polynomial([0.0, -A * k, c, A])
    y1, y2, y3 = y.deriv(1), y.deriv(2), y.deriv(3)
    num = y3 * (1 + y1 * y1) - 3 * y1 * y2 * y2
    roots = num.roots()
    real = roots[np.abs(roots.imag) < 1e-9].real
    # a double root does not change the sign of dkappa/dx: count roots of odd multiplicity
    real = np.sort(real[(real > -1) & (real < 1)])
    n_ext = 0
    for r in np.unique(np.round(real, 9)):
        mult = int(np.sum(np.abs(real - r) < 1e-6))
        n_ext += mult % 2
    infl = y2.roots().real
    n_infl = int(np.sum((infl > -1) & (infl < 1)))

    def fn(t):
        return np.column_stack([t, y(t)])

    return TrueCurve("cubic", fn, -1.0, 1.0, False, n_ext, n_infl, {"A": A, "k": k, "c": c})


# Symmetric sections only: a cambered 4-digit section joins two camber parabolas with C1 contact at
# x = p, so its surface curvature jumps there (and the thickness-normal offset adds a tiny tangent
# kink): not a curve with a well-defined extrema count. Cambered sections are in the UIUC corpus.
NACA_CODES = ("0012", "0009", "0015", "0006", "0018", "0021")


def naca4(code: str) -> TrueCurve:
    """NACA 4-digit airfoil from its analytic formula (open trailing edge, chord 1).

    Parameter ``tau`` in [-1, 1], ``x = tau**2`` (so ``sqrt(x) = |tau|`` and the parameterisation
    is regular at both ends and at the leading edge): upper surface from the trailing edge
    (tau = -1) to the leading edge (tau = 0), then the lower surface (Selig order).
    """
    m = int(code[0]) / 100.0
    p = int(code[1]) / 10.0
    th = int(code[2:]) / 100.0

    def fn(tau):
        tau = np.asarray(tau, dtype=float)
        x = tau * tau
        sq = np.abs(tau)  # sqrt(x)
        yt = 5 * th * (0.2969 * sq - 0.1260 * x - 0.3516 * x**2 + 0.2843 * x**3 - 0.1015 * x**4)
        if m == 0.0:
            yc = np.zeros_like(x)
            dyc = np.zeros_like(x)
        else:
            front = x < p
            yc = np.where(front, m / p**2 * (2 * p * x - x**2),
                          m / (1 - p) ** 2 * ((1 - 2 * p) + 2 * p * x - x**2))
            dyc = np.where(front, 2 * m / p**2 * (p - x), 2 * m / (1 - p) ** 2 * (p - x))
        theta = np.arctan(dyc)
        side = np.where(tau < 0, 1.0, -1.0)  # upper for tau < 0
        return np.column_stack([x - side * yt * np.sin(theta), yc + side * yt * np.cos(theta)])

    return TrueCurve("naca", fn, -1.0, 1.0, False, None, None, {"code": code}, "param")


def helix(rng: np.random.Generator) -> TrueCurve:
    """``(R cos t, R sin t, c t)``: constant curvature R / (R^2 + c^2), no extremum."""
    R = rng.uniform(0.5, 1.5)
    c = rng.uniform(0.1, 0.4)
    T = rng.uniform(2 * np.pi, 4 * np.pi)

    def fn(t):
        return np.column_stack([R * np.cos(t), R * np.sin(t), c * t])

    return TrueCurve("helix", fn, 0.0, T, False, 0, None, {"R": R, "c": c})


def superellipse(rng: np.random.Generator) -> TrueCurve:
    """Closed ``|x/a|^4 + |y/b|^4 = 1``, polar form ``rho(phi) = (cos^4/a^4 + sin^4/b^4)^(-1/4)``.

    Curvature vanishes (without changing sign) at the four axis points and peaks once per
    quadrant: 8 extrema, 0 inflections.
    """
    a, b = rng.uniform(1.0, 2.0), 1.0
    rot = rng.uniform(0, np.pi / 2)

    def fn(phi):
        phi = np.asarray(phi, dtype=float)
        rho = (np.cos(phi) ** 4 / a**4 + np.sin(phi) ** 4 / b**4) ** -0.25
        x, y = rho * np.cos(phi), rho * np.sin(phi)
        cr, sr = np.cos(rot), np.sin(rot)
        return np.column_stack([cr * x - sr * y, sr * x + cr * y])

    return TrueCurve("superellipse", fn, 0.0, 2 * np.pi, True, 8, 0, {"a": a, "b": b})


def make_true_curve(family: str, rng: np.random.Generator, instance: int = 0) -> TrueCurve:
    if family == "naca":
        return naca4(NACA_CODES[instance % len(NACA_CODES)])
    return {"circle": circle_arc, "ellipse": ellipse_arc, "clothoid": clothoid,
            "cubic": cubic_graph, "helix": helix, "superellipse": superellipse}[family](rng)


# ---------------------------------------------------------------------------------------------
# cases
# ---------------------------------------------------------------------------------------------

@dataclass(frozen=True, eq=False)
class Case:
    """One input curve of the benchmark.

    ``points`` are the data every tool receives; ``tol`` the maximum deviation every tool is
    allowed (absolute, in the data's units); ``truth`` is set on the ground-truth corpus only.
    """

    corpus: str
    family: str
    name: str
    points: np.ndarray
    closed: bool
    tol: float
    scale: float
    noise: float | None = None
    truth: TrueCurve | None = None
    clean: np.ndarray | None = None
    true_extrema: int | None = None  # resolvable at the sample spacing (see TrueCurve)
    true_inflections: int | None = None

    @property
    def dim(self) -> int:
        return int(self.points.shape[1])


def sample_true_curve(tc: TrueCurve, n: int, rng: np.random.Generator,
                      jitter: float = 0.25) -> np.ndarray:
    """``n`` points at jittered, roughly equal arc-length (or parameter, per ``tc.sampling``)
    spacing; no closing repeat if closed."""
    t, s = tc.arclength_table()
    if tc.sampling == "param":
        s = (t - t[0]) / (t[-1] - t[0])
    L = s[-1]
    if tc.closed:
        target = (np.arange(n) + rng.uniform(-jitter, jitter, n)) * (L / n)
        target = np.mod(target, L)
        target.sort()
    else:
        h = L / (n - 1)
        target = np.arange(n) * h
        target[1:-1] += rng.uniform(-jitter, jitter, n - 2) * h
    tt = np.interp(target, s, t)
    return tc.fn(tt)


def ground_truth_cases(instances: int = 3, levels: tuple[float, ...] = NOISE_LEVELS,
                       families: tuple[str, ...] = FAMILIES, seed: int = 20240611,
                       n_range: tuple[int, int] = (40, 100)) -> list[Case]:
    """Seeded ground-truth cases: ``families x instances`` true curves, each at every noise level.

    The same true curve and the same sampling are used at every noise level; the noise is
    ``N(0, (level * diag)^2)`` per coordinate with ``diag`` the bounding-box diagonal of the true
    curve, and the tolerance is ``TOL_FACTOR * level * diag``.
    """
    cases = []
    for fi, fam in enumerate(families):
        for inst in range(instances):
            rng = np.random.default_rng([seed, fi, inst])
            tc = make_true_curve(fam, rng, inst)
            n = int(rng.integers(n_range[0], n_range[1] + 1))
            clean = sample_true_curve(tc, n, rng)
            poly = tc.polyline()
            diag = float(np.linalg.norm(poly.max(axis=0) - poly.min(axis=0)))
            closed_pts = np.vstack([clean, clean[:1]]) if tc.closed else clean
            spacing = float(np.median(np.linalg.norm(np.diff(closed_pts, axis=0), axis=1)))
            n_ext = tc.resolvable_extrema(spacing)
            n_infl = tc.inflections
            for li, lev in enumerate(levels):
                nrng = np.random.default_rng([seed, fi, inst, li, 7])
                pts = clean + nrng.normal(0.0, lev * diag, clean.shape)
                label = tc.params.get("code", inst)
                cases.append(Case("ground-truth", fam, f"{fam}-{label}@{lev:g}", pts, tc.closed,
                                  TOL_FACTOR * lev * diag, diag, lev, tc, clean, n_ext, n_infl))
    return cases


# ---------------------------------------------------------------------------------------------
# point files: five curve families that the ground-truth corpus does not have
# ---------------------------------------------------------------------------------------------
POINT_FILE_FAMILIES = ("logspiral", "sine", "cardioid", "lemniscate", "cycloid")


def _point_file_curve(family: str, rng: np.random.Generator) -> TrueCurve:
    """Open arcs; the true extrema / inflection counts come from dense evaluation
    (:attr:`TrueCurve.extrema`), not from closed forms."""
    if family == "logspiral":  # r = e^(b theta): curvature monotone, 0 extrema
        b = rng.uniform(0.1, 0.3)
        span = rng.uniform(3.0, 5.0)

        def fn(t):
            r = np.exp(b * t)
            return np.column_stack([r * np.cos(t), r * np.sin(t)])

        return TrueCurve(family, fn, 0.0, span, False, params={"b": b})
    if family == "sine":
        a = rng.uniform(0.15, 0.35)
        x1 = rng.uniform(1.1, 1.7)

        def fn(t):
            return np.column_stack([t, a * np.sin(2 * np.pi * t)])

        return TrueCurve(family, fn, 0.0, x1, False, params={"a": a})
    if family == "cardioid":
        e = rng.uniform(2.2, 2.8)

        def fn(t):
            r = 1.0 + np.cos(t)
            return np.column_stack([r * np.cos(t), r * np.sin(t)])

        return TrueCurve(family, fn, -e, e, False, params={"e": e})
    if family == "lemniscate":  # Bernoulli, one lobe and a bit, away from the node
        e = rng.uniform(0.5, 0.7)

        def fn(t):
            d = 1.0 + np.sin(t) ** 2
            return np.column_stack([np.cos(t) / d, np.sin(t) * np.cos(t) / d])

        return TrueCurve(family, fn, -np.pi / 2 + e, np.pi / 2 - e + 0.3, False,
                         params={"e": e})
    e = rng.uniform(0.4, 0.8)  # cycloid arch, away from the cusps

    def fn(t):
        return np.column_stack([t - np.sin(t), 1.0 - np.cos(t)])

    return TrueCurve("cycloid", fn, e, 2 * np.pi - e * rng.uniform(0.8, 1.2), False,
                     params={"e": e})


def point_file_cases(instances: int = 2, levels: tuple[float, ...] = NOISE_LEVELS,
                     seed: int = 20261202, n_range: tuple[int, int] = (40, 100)) -> list[Case]:
    """``5 families x instances x levels`` noisy point lists (30 with the defaults),
    ``tol = TOL_FACTOR sigma``; sampled like :func:`ground_truth_cases`."""
    cases = []
    for fi, fam in enumerate(POINT_FILE_FAMILIES):
        for inst in range(instances):
            rng = np.random.default_rng([seed, fi, inst])
            tc = _point_file_curve(fam, rng)
            n = int(rng.integers(n_range[0], n_range[1] + 1))
            clean = sample_true_curve(tc, n, rng)
            poly = tc.polyline()
            diag = float(np.linalg.norm(poly.max(axis=0) - poly.min(axis=0)))
            spacing = float(np.median(np.linalg.norm(np.diff(clean, axis=0), axis=1)))
            n_ext = tc.resolvable_extrema(spacing)
            for li, lev in enumerate(levels):
                nrng = np.random.default_rng([seed, fi, inst, li, 7])
                pts = clean + nrng.normal(0.0, lev * diag, clean.shape)
                cases.append(Case("point-files", fam, f"{fam}-{inst}@{lev:g}", pts, False,
                                  TOL_FACTOR * lev * diag, diag, lev, tc, clean, n_ext,
                                  tc.inflections))
    return cases


# ---------------------------------------------------------------------------------------------
# airfoils from the aerosandbox wheel (UIUC database)
# ---------------------------------------------------------------------------------------------

def aerosandbox_wheel(cache: Path = CACHE, version: str = AEROSANDBOX_VERSION) -> Path:
    """Path of the aerosandbox wheel, fetched with ``pip download --no-deps`` if not cached."""
    cache.mkdir(parents=True, exist_ok=True)
    found = sorted(cache.glob(f"aerosandbox-{version}-*.whl"))
    if not found:
        subprocess.run([sys.executable, "-m", "pip", "download", f"aerosandbox=={version}",
                        "--no-deps", "--only-binary=:all:", "--quiet", "-d", str(cache)],
                       check=True)
        found = sorted(cache.glob(f"aerosandbox-{version}-*.whl"))
    if not found:
        raise FileNotFoundError(f"pip download left no aerosandbox wheel in {cache}")
    return found[0]


_NUM = re.compile(r"^[\s]*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][-+]?\d+)?)[\s,;]+"
                  r"([-+]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][-+]?\d+)?)\s*[,;]?\s*$")


def parse_airfoil_dat(text: str) -> tuple[str, np.ndarray]:
    """Parse a Selig or Lednicer airfoil file into ``(name, points)`` in Selig order.

    Selig: a name line, then x y pairs from the trailing edge over the upper surface to the
    leading edge and back along the lower surface. Lednicer: a name line, a line with the point
    counts of the two surfaces (numbers > 1), then both surfaces from the leading edge to the
    trailing edge, separated by a blank line. Raises ``ValueError`` on anything else.
    """
    lines = text.replace("\r", "\n").split("\n")
    name = lines[0].strip()
    rows: list[tuple[float, float] | None] = []
    for ln in lines[1:]:
        m = _NUM.match(ln)
        if m:
            rows.append((float(m.group(1).replace("d", "e").replace("D", "e")),
                         float(m.group(2).replace("d", "e").replace("D", "e"))))
        elif ln.strip() == "":
            rows.append(None)
        elif rows and any(r is not None for r in rows):
            raise ValueError(f"unparsable line {ln!r}")
    data = [r for r in rows if r is not None]
    if len(data) < 10:
        raise ValueError("fewer than 10 coordinate lines")
    first = data[0]
    if first[0] > 1.5 and first[1] > 1.5:  # Lednicer
        nu, nl = int(round(first[0])), int(round(first[1]))
        body = data[1:]
        if len(body) != nu + nl:
            raise ValueError(f"Lednicer counts {nu}+{nl} do not match {len(body)} lines")
        upper = np.array(body[:nu])
        lower = np.array(body[nu:])
        pts = np.vstack([upper[::-1], lower])
    else:
        pts = np.array(data)
    return name, pts


def clean_airfoil(pts: np.ndarray) -> np.ndarray:
    """Drop consecutive (near) duplicates; ``ValueError`` if the result is not a usable airfoil."""
    chord = float(pts[:, 0].max() - pts[:, 0].min())
    if not np.isfinite(pts).all() or chord <= 0:
        raise ValueError("non-finite coordinates or zero chord")
    keep = np.ones(len(pts), bool)
    d = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    keep[1:] = d > 1e-7 * chord
    pts = pts[keep]
    if len(pts) < 20:
        raise ValueError("fewer than 20 distinct points")
    d = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    if d.max() > 0.5 * chord:
        raise ValueError("a jump of more than half the chord (several blocks?)")
    # turning back by more than ~170 degrees between consecutive chords = a spike, not a surface
    v = np.diff(pts, axis=0)
    cosang = np.sum(v[1:] * v[:-1], axis=1) / (d[1:] * d[:-1])
    if np.any(cosang < -0.985):
        raise ValueError("a reversal spike in the point sequence")
    return pts


def airfoil_cases(count: int | None = 240, cache: Path = CACHE,
                  min_points: int = 30, max_points: int = 400) -> list[Case]:
    """UIUC airfoils from the aerosandbox wheel, every file that parses and passes
    :func:`clean_airfoil`, thinned evenly (sorted by file name) to ``count`` cases.

    Tolerance ``AIRFOIL_TOL`` chord. Files are read from the zip with :mod:`zipfile`.
    """
    whl = aerosandbox_wheel(cache)
    out = []
    with zipfile.ZipFile(whl) as z:
        names = sorted(n for n in z.namelist()
                       if n.endswith(".dat") and "airfoil_database" in n)
        for n in names:
            try:
                text = z.read(n).decode("latin-1")
                _, pts = parse_airfoil_dat(text)
                pts = clean_airfoil(pts)
            except ValueError:
                continue
            if not (min_points <= len(pts) <= max_points):
                continue
            chord = float(pts[:, 0].max() - pts[:, 0].min())
            stem = Path(n).stem
            out.append(Case("airfoils", "uiuc", stem, pts, False, AIRFOIL_TOL * chord, chord))
    if count is not None and count < len(out):
        idx = np.unique(np.linspace(0, len(out) - 1, count).round().astype(int))
        out = [out[i] for i in idx]
    return out


# ---------------------------------------------------------------------------------------------
# glyph outlines (DejaVu fonts shipped in matplotlib)
# ---------------------------------------------------------------------------------------------

def dejavu_path(name: str = "DejaVuSans.ttf") -> Path:
    import matplotlib

    p = Path(matplotlib.get_data_path()) / "fonts" / "ttf" / name
    if not p.exists():
        raise FileNotFoundError(p)
    return p


def _contour_segments(pts: np.ndarray, on: np.ndarray) -> list[np.ndarray]:
    """TrueType contour -> list of segments, each ``(2, 2)`` (line) or ``(3, 2)`` (quadratic)."""
    n = len(pts)
    # rotate so that the contour starts at an on-curve point
    if not on.any():
        mid = 0.5 * (pts + np.roll(pts, -1, axis=0))
        pts = np.vstack([np.column_stack([mid[i], pts[(i + 1) % n]]).T for i in range(n)])
        on = np.tile([True, False], n)
        n = len(pts)
    k = int(np.argmax(on))
    pts, on = np.roll(pts, -k, axis=0), np.roll(on, -k)
    # insert implied on-curve points between consecutive off-curve points
    seq, flags = [], []
    for i in range(n):
        j = (i + 1) % n
        seq.append(pts[i])
        flags.append(bool(on[i]))
        if not on[i] and not on[j]:
            seq.append(0.5 * (pts[i] + pts[j]))
            flags.append(True)
    seq.append(pts[0])
    flags.append(True)
    segs = []
    i = 0
    while i < len(seq) - 1:
        if flags[i + 1]:
            segs.append(np.array([seq[i], seq[i + 1]]))
            i += 1
        else:
            segs.append(np.array([seq[i], seq[i + 1], seq[i + 2]]))
            i += 2
    return [s for s in segs if np.linalg.norm(s[-1] - s[0]) > 0 or len(s) == 3]


def _seg_eval(seg: np.ndarray, u: np.ndarray) -> np.ndarray:
    u = u[:, None]
    if len(seg) == 2:
        return (1 - u) * seg[0] + u * seg[1]
    return (1 - u) ** 2 * seg[0] + 2 * u * (1 - u) * seg[1] + u**2 * seg[2]


def _seg_tangents(seg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    if len(seg) == 2:
        d = seg[1] - seg[0]
        return d, d
    a, b = seg[1] - seg[0], seg[2] - seg[1]
    if np.linalg.norm(a) == 0:
        a = b
    if np.linalg.norm(b) == 0:
        b = a
    return a, b


def glyph_runs(font_path: Path, chars: str, corner_deg: float = 8.0, spacing: float = 0.02,
               min_samples: int = 10) -> Iterator[tuple[str, np.ndarray, bool, float]]:
    """Smooth runs of glyph outlines: ``(label, samples, closed, units_per_em)``.

    Each contour is split at its corners (tangent turning by more than ``corner_deg``); each
    run containing at least one quadratic arc is sampled at roughly ``spacing`` em (at least the
    segment ends and midpoints). A contour without corners is one closed run.
    """
    from fontTools.ttLib import TTFont

    font = TTFont(str(font_path))
    upem = float(font["head"].unitsPerEm)
    glyf = font["glyf"]
    cmap = font.getBestCmap()
    step = spacing * upem
    for ch in chars:
        gname = cmap.get(ord(ch))
        if gname is None:
            continue
        g = glyf[gname]
        if g.isComposite() or g.numberOfContours <= 0:
            continue
        coords, ends, flags = g.getCoordinates(glyf)
        coords = np.asarray(coords, dtype=float)
        flags = np.asarray(flags) & 1
        start = 0
        for ci, end in enumerate(ends):
            pts, on = coords[start:end + 1], flags[start:end + 1].astype(bool)
            start = end + 1
            if len(pts) < 3:
                continue
            segs = _contour_segments(pts, on)
            m = len(segs)
            corner = np.zeros(m, bool)  # corner at the START of segment i
            for i in range(m):
                _, tin = _seg_tangents(segs[i - 1])
                tout, _ = _seg_tangents(segs[i])
                c = np.dot(tin, tout) / (np.linalg.norm(tin) * np.linalg.norm(tout))
                corner[i] = c < math.cos(math.radians(corner_deg))
            if corner.any():
                first = int(np.argmax(corner))
                order = [(first + i) % m for i in range(m)]
                runs, cur = [], []
                for i in order:
                    if corner[i] and cur:
                        runs.append(cur)
                        cur = []
                    cur.append(segs[i])
                runs.append(cur)
                closed = False
            else:
                runs, closed = [segs], True
            for ri, run in enumerate(runs):
                if not any(len(s) == 3 for s in run):
                    continue
                samples = []
                for s in run:
                    length = np.linalg.norm(np.diff(s, axis=0), axis=1).sum()
                    k = max(2, int(math.ceil(length / step)))
                    samples.append(_seg_eval(s, np.arange(k) / k))
                if not closed:
                    samples.append(run[-1][-1:])
                samples = np.vstack(samples)
                keep = np.ones(len(samples), bool)
                keep[1:] = np.linalg.norm(np.diff(samples, axis=0), axis=1) > 1e-9 * upem
                samples = samples[keep]
                if closed and np.linalg.norm(samples[-1] - samples[0]) < 1e-9 * upem:
                    samples = samples[:-1]
                if len(samples) >= min_samples:
                    yield f"{ch}.{ci}.{ri}", samples, closed, upem


GLYPH_CHARS = "abcdefgjmnopqrsuCDGJOPQRSUB023568&@?$%"


def glyph_cases(count: int | None = 80,
                fonts: tuple[str, ...] = ("DejaVuSans.ttf", "DejaVuSerif.ttf")) -> list[Case]:
    """Smooth outline runs of DejaVu glyphs, thinned evenly to ``count``; tolerance
    ``GLYPH_TOL`` em."""
    out = []
    for f in fonts:
        for label, pts, closed, upem in glyph_runs(dejavu_path(f), GLYPH_CHARS):
            fam = f.removesuffix(".ttf")
            out.append(Case("glyphs", fam, f"{fam}:{label}", pts, closed, GLYPH_TOL * upem, upem))
    if count is not None and count < len(out):
        idx = np.unique(np.linspace(0, len(out) - 1, count).round().astype(int))
        out = [out[i] for i in idx]
    return out
