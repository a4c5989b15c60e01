"""Plots of curves and their fairness: curvature combs, curvature plots, before/after comparisons.

Matplotlib is optional (``pip install 'curvefair[plot]'``) and imported only inside the plotting
functions; without it they raise :class:`curvefair.MissingDependencyError`.
:func:`curvature_comb` needs only numpy and gives the comb's hairs for any plotting library.

Conventions
-----------
* **Comb** (porcupine plot, Farin & Sapidis 1989): at sampled points ``r(t)`` a hair
  ``r(t) - scale * kappa(t) * N(t)`` is drawn, where ``kappa * N = r'' _|_ r' / |r'|^2`` is the
  curvature vector (``N`` the principal normal, pointing towards the centre of curvature). Hairs
  therefore point *away* from the centre of curvature, to the convex side, as in CAD systems, and
  their length is proportional to the curvature. The hair tips are joined by the envelope.
  Every segment is sampled at both of its ends, so a curvature jump at a breakpoint shows as two
  hairs at the same point.
* **Curvature** is signed for planar curves (positive where the curve turns left) and the
  unsigned ``|r' x r''| / |r'|^3`` for space curves.
* **3-D curves** are drawn as their orthogonal projection onto the best-fit plane of the curve
  (least squares through dense samples; ``projection="plane"``, the default) or onto a coordinate
  plane (``"xy"``, ``"xz"``, ``"yz"``); the axes labels say which. The comb uses the 3-D
  principal normal and is projected with the curve.
* **Markers**: inflections (sign changes of the curvature, planar curves only), curvature extrema,
  and the worst bad points of :func:`curvefair.analysis.rank_bad_points` (the jump of the third
  derivative at the breakpoints, Wang & Cao 2006, section "Bad points identification"; the bad
  control points of Cheng & Yu on a cubic B-spline), labelled 1, 2, 3, ...

Indices are 0-based (the papers number points from 1).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Literal, NamedTuple

import numpy as np

from ._typing import FloatArray
from ._validate import as_positive, choice
from .curves.piecewise import PiecewiseCurve
from .errors import InputError, MissingDependencyError

__all__ = [
    "plot_curve",
    "plot_curvature",
    "plot_compare",
    "figure",
    "curvature_comb",
    "Comb",
]

ProjectionName = Literal["plane", "xy", "xz", "yz"]
PROJECTIONS = ("plane", "xy", "xz", "yz")

# Styles -------------------------------------------------------------------------------------
_MAIN = {"curve": "#1f4e79", "hair": "#5b9bd5", "envelope": "#2e75b6", "points": "#1f4e79"}
_REF = {"curve": "#8c8c8c", "hair": "#c9c9c9", "envelope": "#a6a6a6", "points": "#8c8c8c"}
_INFLECTION = "#e07b00"
_EXTREMUM = "#2f9e44"
_BAD = "#c92a2a"
_GID_HAIRS = "curvefair-comb-hairs"
_GID_ENVELOPE = "curvefair-comb-envelope"
_GID_CURVE = "curvefair-curve"
_GID_CURVATURE = "curvefair-curvature"
_GID_DEVIATION = "curvefair-deviation"

#: Target number of hairs for the automatic comb density.
_AUTO_HAIRS = 600
#: Target number of samples for the drawn curve and curvature plot.
_AUTO_SAMPLES = 6000


def _mpl() -> Any:
    """Import matplotlib lazily; raise MissingDependencyError naming the ``plot`` extra."""
    try:
        import matplotlib  # noqa: F401
        import matplotlib.collections
        import matplotlib.figure
        import matplotlib.lines
    except ImportError:
        raise MissingDependencyError("matplotlib", "plot", "curvefair.plot") from None
    return matplotlib


def _pyplot_axes(n: int = 1, **kw: Any) -> Any:
    _mpl()
    import matplotlib.pyplot as plt

    if n == 1:
        return plt.gca()
    fig, axes = plt.subplots(n, 1, **kw)
    return axes


# Sampling -----------------------------------------------------------------------------------
def _check_curve(curve: object, name: str) -> PiecewiseCurve:
    from .interop import as_curve

    curve = as_curve(curve, name)
    if not isinstance(curve, PiecewiseCurve):
        raise InputError(f"{name} must be a curvefair curve (PiecewiseCurve), "
                         f"got {type(curve).__name__}")
    return curve


def _density(value: object, n_segments: int, name: str, target: int, cap: int) -> int:
    """Samples (intervals) per segment: given, or chosen so the total is about ``target``."""
    if value is None:
        return int(min(cap, max(1, math.ceil(target / n_segments))))
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise InputError(f"{name} must be an integer >= 1 (intervals per curve segment), "
                         f"got {value!r}")
    return int(value)


@dataclass
class _Samples:
    """A curve sampled at ``fracs`` of every segment (both segment ends included)."""

    u: FloatArray  # (m, k) parameters
    seg: np.ndarray  # (m, k) segment index
    r: FloatArray  # (m, k, dim)
    kvec: FloatArray  # (m, k, dim) curvature vector kappa * N
    kappa: FloatArray  # (m, k) signed (2-D) or unsigned (3-D) curvature
    s: FloatArray  # (m, k) arc length from the start of the curve

    def flat(self, name: str) -> FloatArray:
        a = getattr(self, name)
        return a.reshape((-1,) + a.shape[2:])


_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(8)
_GAUSS_X = 0.5 * (_GAUSS_X + 1.0)
_GAUSS_W = 0.5 * _GAUSS_W


def _arclength_table(curve: PiecewiseCurve, fracs: FloatArray) -> FloatArray:
    """Arc length at ``breaks[i] + fracs * width_i`` for every segment ``i``: ``(m, k)``.

    Composite 8-point Gauss-Legendre quadrature of the speed on every sub-interval between
    consecutive ``fracs`` (``fracs`` must start at 0 and be increasing).
    """
    pp = curve.piecewise
    df = np.diff(fracs)
    nodes = (fracs[:-1, None] + df[:, None] * _GAUSS_X[None, :]).reshape(-1)
    speed = np.linalg.norm(pp.segment_values(nodes, 1), axis=2)  # (m, (k-1)*8)
    speed = speed.reshape(pp.n_segments, df.size, _GAUSS_X.size)
    sub = (speed @ _GAUSS_W) * df[None, :] * pp.widths[:, None]  # (m, k-1)
    local = np.concatenate([np.zeros((pp.n_segments, 1)), np.cumsum(sub, axis=1)], axis=1)
    if fracs[-1] < 1.0:  # segment lengths need the whole segment
        seg_len = _arclength_table(curve, np.array([0.0, 1.0]))[:, -1]
    else:
        seg_len = local[:, -1]
    offset = np.concatenate([[0.0], np.cumsum(seg_len)[:-1]])
    return local + offset[:, None]


def _curvature_vectors(curve: PiecewiseCurve, u: FloatArray, d1: FloatArray, d2: FloatArray,
                       side: str) -> tuple[FloatArray, FloatArray]:
    """Curvature (:func:`curvefair.curvature`) and curvature vector ``kappa N`` at ``u``.

    ``d1``, ``d2`` are ``r'``, ``r''`` at ``u`` (shape ``(k, dim)``). ``N`` is the unit normal
    towards the centre of curvature: in 2-D the left normal (the curvature is signed), in 3-D the
    principal normal (the unit part of ``r''`` orthogonal to ``r'``). Zero-speed points have
    curvature 0 (as :func:`curvefair.curvature` defines it) and a zero vector.
    """
    from .analysis import curvature

    kappa = np.asarray(curvature(curve, u, side=side), dtype=float).reshape(-1)
    sp = np.sqrt(np.sum(d1 * d1, axis=-1))
    with np.errstate(divide="ignore", invalid="ignore"):
        if curve.dim == 2:
            n = np.column_stack([-d1[:, 1], d1[:, 0]]) / sp[:, None]
        else:
            t = d1 / sp[:, None]
            perp = d2 - np.sum(d2 * t, axis=1)[:, None] * t
            n = perp / np.linalg.norm(perp, axis=1)[:, None]
    kvec = kappa[:, None] * n
    kvec[~np.all(np.isfinite(kvec), axis=1) | (kappa == 0.0)] = 0.0
    return kvec, kappa


def _sample(curve: PiecewiseCurve, per_segment: int) -> _Samples:
    pp = curve.piecewise
    m = pp.n_segments
    fracs = np.linspace(0.0, 1.0, per_segment + 1)
    r = pp.segment_values(fracs, 0)
    d1 = pp.segment_values(fracs, 1)
    d2 = pp.segment_values(fracs, 2) if pp.degree >= 2 else np.zeros_like(d1)
    u = pp.breaks[:-1, None] + pp.widths[:, None] * fracs[None, :]
    u[:, -1] = pp.breaks[1:]
    dim = r.shape[2]
    kvec = np.empty_like(r)
    kappa = np.empty(u.shape)
    # the segment's own (one-sided) values: right limits at its start, left limits at its end
    kv, ka = _curvature_vectors(curve, u[:, :-1].reshape(-1), d1[:, :-1].reshape(-1, dim),
                                d2[:, :-1].reshape(-1, dim), "right")
    kvec[:, :-1], kappa[:, :-1] = kv.reshape(m, -1, dim), ka.reshape(m, -1)
    kv, ka = _curvature_vectors(curve, u[:, -1], d1[:, -1], d2[:, -1], "left")
    kvec[:, -1], kappa[:, -1] = kv, ka
    seg = np.broadcast_to(np.arange(m)[:, None], u.shape)
    return _Samples(u=u, seg=seg, r=r, kvec=kvec, kappa=kappa, s=_arclength_table(curve, fracs))


# Comb ---------------------------------------------------------------------------------------
class Comb(NamedTuple):
    """Hairs of a curvature comb (see :func:`curvature_comb`)."""

    #: Hair roots on the curve, shape ``(N, dim)``.
    base: FloatArray
    #: Hair tips ``base - scale * kappa * N``, shape ``(N, dim)``; joined they give the envelope.
    tip: FloatArray
    #: Curvature at the roots, shape ``(N,)`` (signed for planar curves).
    kappa: FloatArray
    #: Parameters of the roots, shape ``(N,)``.
    u: FloatArray
    #: The scale used: hair length = ``scale * |kappa|``.
    scale: float


def _auto_scale(max_kappa: float, extent: float) -> float:
    """Scale making the longest hair a fifth of the curve's extent."""
    if not np.isfinite(max_kappa) or max_kappa <= 0.0 or extent <= 0.0:
        return 1.0 if extent <= 0.0 else extent
    return 0.2 * extent / max_kappa


def _weighted_quantile(values: FloatArray, weights: FloatArray, q: float) -> float:
    """The ``q`` quantile of ``values`` weighted by ``weights`` (lower value at ties)."""
    ok = np.isfinite(values) & np.isfinite(weights) & (weights >= 0)
    v, w = values[ok], weights[ok]
    if v.size == 0 or not np.any(w > 0):
        return float(np.quantile(v, q)) if v.size else 0.0
    order = np.argsort(v, kind="stable")
    cw = np.cumsum(w[order])
    i = int(np.searchsorted(cw, q * cw[-1], side="left"))
    return float(v[order][min(i, v.size - 1)])


def _length_weights(s: FloatArray) -> FloatArray:
    """Arc length each sample stands for (half the gaps to its neighbours)."""
    s = np.asarray(s, dtype=float).reshape(-1)
    if s.size < 2:
        return np.ones_like(s)
    g = np.abs(np.diff(s))
    return np.concatenate([[0.5 * g[0]], 0.5 * (g[:-1] + g[1:]), [0.5 * g[-1]]])


def typical_curvature(kappas: Sequence[FloatArray], arclengths: Sequence[FloatArray],
                      q: float = 0.9) -> tuple[float, float]:
    """``(typical, max)`` of ``|kappa|``: its ``q`` quantile by arc length, and its maximum.

    Weighted by arc length, not by sample, so densely sampled regions (an airfoil's leading
    edge, where the points cluster) count by their length only.
    """
    k = np.concatenate([np.abs(np.asarray(a, dtype=float).reshape(-1)) for a in kappas])
    w = np.concatenate([_length_weights(s) for s in arclengths])
    fin = np.isfinite(k)
    if not np.any(fin):
        return 0.0, 0.0
    return _weighted_quantile(k, w, q), float(np.max(k[fin]))


#: A curvature peak more than this many times the typical (90 % by arc length) curvature makes
#: the comb scale robust (clipped hairs) and the curvature axis symmetric-logarithmic.
PEAK_RATIO = 20.0


def robust_comb_scale(kappas: Sequence[FloatArray], arclengths: Sequence[FloatArray],
                      extent: float) -> tuple[float, float | None]:
    """Comb scale and hair clip length, robust to a curvature peak.

    Without a dominant peak (``max |kappa| <= PEAK_RATIO`` times the typical curvature, the 90 %
    quantile by arc length) the longest hair is a fifth of ``extent`` and nothing is clipped.
    With one, hairs at 3 times the typical curvature are a fifth of ``extent`` and longer hairs
    are drawn at the clip length ``extent / 5`` (so the leading edge of an airfoil does not
    shrink the comb of the rest to nothing). Returns ``(scale, clip or None)``.
    """
    typical, kmax = typical_curvature(kappas, arclengths)
    if kmax <= 0.0 or extent <= 0.0 or typical <= 0.0 or kmax <= PEAK_RATIO * typical:
        return _auto_scale(kmax, extent), None
    ref = 3.0 * typical
    return 0.2 * extent / ref, 0.2 * extent


def curvature_axis_mode(kappas: Sequence[FloatArray], arclengths: Sequence[FloatArray]) -> str:
    """``"symlog"`` when the curvature (samples of one or more curves and their arc lengths)
    has a dominant peak (see :data:`PEAK_RATIO`), else ``"linear"``."""
    typical, kmax = typical_curvature(kappas, arclengths)
    return "symlog" if typical > 0.0 and kmax > PEAK_RATIO * typical else "linear"


def _extent(points: FloatArray) -> float:
    pts = points[np.all(np.isfinite(points), axis=1)]
    if pts.size == 0:
        return 0.0
    return float(np.max(pts.max(axis=0) - pts.min(axis=0)))


def curvature_comb(curve: PiecewiseCurve, scale: float | None = None,
                   density: int | None = None) -> Comb:
    """The hairs of the curvature comb of ``curve``, without plotting.

    Parameters
    ----------
    curve : PiecewiseCurve
        Any curvefair curve, dim 2 or 3.
    scale : float, optional
        Hair length per unit curvature (length units squared). Default: the longest hair is a
        fifth of the largest side of the curve's bounding box.
    density : int, optional
        Hair intervals per curve segment; every segment gets ``density + 1`` hairs, including
        both of its ends (so a curvature jump at a breakpoint shows as two different hairs at one
        point). Default: about 600 hairs in all, at most 40 intervals per segment.

    Returns
    -------
    Comb
        ``base``, ``tip`` (``(N, dim)``), ``kappa``, ``u`` (``(N,)``) and the ``scale`` used.

    Notes
    -----
    ``tip = base - scale * kappa * N`` with the curvature vector
    ``kappa N = (r'' |r'|^2 - r' (r'.r'')) / |r'|^4`` (Farin & Sapidis 1989, porcupine plot):
    hairs point away from the centre of curvature.

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import interpolate_cubic
    >>> from curvefair.plot import curvature_comb
    >>> t = np.linspace(0, np.pi, 9)
    >>> c = curvature_comb(interpolate_cubic(np.c_[np.cos(t), np.sin(t)]), scale=0.5, density=4)
    >>> c.base.shape, round(float(np.median(c.kappa)), 2)
    ((40, 2), 1.0)
    """
    curve = _check_curve(curve, "curve")
    per = _density(density, curve.piecewise.n_segments, "density", _AUTO_HAIRS, 40)
    smp = _sample(curve, per)
    if scale is None:
        scale = _auto_scale(float(np.nanmax(np.abs(smp.kappa))), _extent(smp.flat("r")))
    else:
        scale = float(as_positive(scale, "scale", window=True))
    base = smp.flat("r")
    tip = base - scale * smp.flat("kvec")
    return Comb(base=base, tip=tip, kappa=smp.flat("kappa"), u=smp.flat("u"), scale=scale)


# Features: inflections, curvature extrema, bad points ----------------------------------------
@dataclass
class _Features:
    inflections: FloatArray = field(default_factory=lambda: np.empty(0))  # parameters
    extrema: FloatArray = field(default_factory=lambda: np.empty(0))  # parameters
    bad: list[tuple[int, float, float]] = field(default_factory=list)  # (index, u, measure)
    bad_label: str = "max |Δr'''|"  # what ranks the bad points (legend)


def _features(curve: PiecewiseCurve, n_bad: int) -> _Features:
    """Inflections, curvature extrema and the ``n_bad`` worst bad points, from :func:`analyze`.

    Bad points are those of :func:`curvefair.analysis.rank_bad_points` (the ranking
    ``curvefair analyze`` lists): breakpoints ranked by the jump of the third derivative (Wang
    & Cao 2006) or, without one, of the highest derivative; on a cubic B-spline the bad control
    points of Cheng & Yu, marked at the joint their criterion looks at.
    """
    from .analysis import analyze, rank_bad_points

    a = analyze(curve)
    feats = _Features(inflections=np.asarray(a.inflection_params, dtype=float),
                      extrema=np.asarray(a.extremum_params, dtype=float))
    if n_bad > 0:
        ranked = rank_bad_points(curve, a)[:n_bad]
        feats.bad = [(b.index, b.param, b.measure) for b in ranked]
        if ranked:
            d = ranked[0].derivative
            feats.bad_label = (f"max |Δr{_prime(d)}|" if d is not None
                               else "max Cheng-Yu z = D²")
    return feats


def _s_at(curve: PiecewiseCurve, smp: _Samples, u: FloatArray) -> FloatArray:
    """Arc length at parameters ``u`` (interpolated in the sample table)."""
    return np.interp(u, smp.flat("u"), smp.flat("s"))


# Projection ---------------------------------------------------------------------------------
#: Curves whose best-fit planes are this flat (smallest / largest singular value) and whose
#: normals agree to within this angle are drawn in their common plane.
_PLANAR = 1e-3
_PARALLEL_DEG = 10.0


def _common_normal(dense_points: list[FloatArray]) -> FloatArray | None:
    """The mean normal of several planar 3-D curves lying in parallel planes, else None.

    Each curve's plane is its least-squares plane (SVD of its centred samples); it is planar
    when its smallest singular value is at most ``_PLANAR`` times its largest. With two or more
    curves, all planar and all normals within ``_PARALLEL_DEG`` degrees, their mean normal is
    the viewing direction (hull stations, each in its own plane x = const, are seen face-on,
    rather than edge-on as the best-fit plane of all of them together would show them).
    """
    if len(dense_points) < 2:
        return None
    normals = []
    for p in dense_points:
        p = p[np.all(np.isfinite(p), axis=1)]
        if p.shape[0] < 3:
            return None
        _, sv, vt = np.linalg.svd(p - p.mean(axis=0), full_matrices=False)
        if sv.size < 3 or not sv[0] > 0 or sv[2] > _PLANAR * sv[0] or sv[1] <= _PLANAR * sv[0]:
            return None
        normals.append(vt[2])
    n0 = normals[0]
    aligned = np.array([n if n @ n0 >= 0 else -n for n in normals])
    if np.min(aligned @ n0) < math.cos(math.radians(_PARALLEL_DEG)):
        return None
    m = aligned.mean(axis=0)
    return m / np.linalg.norm(m)


class _Projector:
    """Maps 2-D or 3-D points to plot coordinates."""

    def __init__(self, dense_points: list[FloatArray], projection: str) -> None:
        choice(projection, PROJECTIONS, "projection")
        dims = {p.shape[1] for p in dense_points}
        if len(dims) > 1:
            raise InputError("curves drawn together must all be 2-D or all 3-D")
        self.dim = dims.pop()
        self.labels = ("x", "y")
        self.note = ""
        if self.dim == 2:
            self.basis = np.eye(2)
            self.origin = np.zeros(2)
            return
        if projection != "plane":
            ax = {"x": 0, "y": 1, "z": 2}
            self.basis = np.eye(3)[:, [ax[projection[0]], ax[projection[1]]]]
            self.origin = np.zeros(3)
            self.labels = (projection[0], projection[1])
            self.note = f"3-D curve, projected onto the {projection} plane"
            return
        pts = np.vstack(dense_points)
        pts = pts[np.all(np.isfinite(pts), axis=1)]
        self.origin = pts.mean(axis=0)
        normal = _common_normal(dense_points)
        if normal is not None:  # parallel planar curves (hull stations): seen face-on
            flat = (pts - self.origin) - np.outer((pts - self.origin) @ normal, normal)
            _, _, vt = np.linalg.svd(flat, full_matrices=False)
            vt = np.vstack([vt[0], np.cross(normal, vt[0])])
        else:
            _, _, vt = np.linalg.svd(pts - self.origin, full_matrices=False)
        e1, e2 = vt[0], vt[1]
        # deterministic orientation: largest component of e1 positive, normal towards +z (or +x)
        e1 = e1 * np.sign(e1[np.argmax(np.abs(e1))])
        nrm = np.cross(e1, e2)
        if nrm[np.argmax(np.abs(nrm))] < 0:
            e2 = -e2
        self.basis = np.column_stack([e1, e2])
        self.labels = ("u (best-fit plane)", "v (best-fit plane)")
        self.note = ("3-D curves, seen along their planes' common normal "
                     f"({', '.join(f'{v:.3g}' for v in np.cross(e1, e2))})"
                     if normal is not None else "3-D curve, projected onto its best-fit plane")

    def __call__(self, pts: FloatArray) -> FloatArray:
        if self.dim == 2:
            return pts
        return (pts - self.origin) @ self.basis

    def vec(self, v: FloatArray) -> FloatArray:
        return v if self.dim == 2 else v @ self.basis


# Prepared curves ----------------------------------------------------------------------------
@dataclass
class _Prepared:
    curve: PiecewiseCurve
    fine: _Samples  # for the drawn curve and curvature plot
    comb: _Samples  # hair roots
    feats: _Features
    label: str | None

    @property
    def length(self) -> float:
        return float(self.fine.s[-1, -1])


def _prepare(curves: Sequence[PiecewiseCurve], names: Sequence[str], comb_density: Any,
             markers: bool, n_bad: int) -> list[_Prepared]:
    out = []
    for c, name in zip(curves, names, strict=True):
        c = _check_curve(c, name)
        m = c.piecewise.n_segments
        fine = _sample(c, _density(None, m, "samples", _AUTO_SAMPLES, 64))
        comb = _sample(c, _density(comb_density, m, "comb_density", _AUTO_HAIRS, 40))
        feats = _features(c, n_bad) if markers else _Features()
        out.append(_Prepared(c, fine, comb, feats, None))
    return out


def _joint_scale(prepared: list[_Prepared], comb_scale: object) -> float:
    return _joint_scale_clip(prepared, comb_scale)[0]


def _joint_scale_clip(prepared: list[_Prepared], comb_scale: object) -> tuple[float, float | None]:
    """``(scale, clip)``: the given scale (no clip), or :func:`robust_comb_scale`."""
    if comb_scale is not None:
        return float(as_positive(comb_scale, "comb_scale", window=True)), None
    extent = _extent(np.vstack([p.fine.flat("r") for p in prepared]))
    return robust_comb_scale([p.comb.flat("kappa") for p in prepared],
                             [p.comb.flat("s") for p in prepared], extent)


def _projector(prepared: list[_Prepared], projection: str) -> _Projector:
    return _Projector([p.fine.flat("r") for p in prepared], projection)


# Drawing ------------------------------------------------------------------------------------
def _draw_curve(ax: Any, p: _Prepared, proj: _Projector, *, comb: bool, scale: float,
                markers: bool, style: dict[str, str], label: str | None, points: bool,
                ref: bool = False, bad_labels: bool = True, clip: float | None = None) -> None:
    mpl = _mpl()
    LineCollection = mpl.collections.LineCollection
    xy = proj(p.fine.flat("r"))
    ax.plot(xy[:, 0], xy[:, 1], color=style["curve"], lw=1.3 if ref else 1.8,
            ls="--" if ref else "-", label=label, zorder=3 if ref else 4, gid=_GID_CURVE)
    if comb:
        base = proj(p.comb.r)  # (m, k, 2)
        hair = -scale * proj.vec(p.comb.kvec)
        if clip is not None:  # longer hairs drawn at the clip length
            ln = np.linalg.norm(hair, axis=-1)
            over = ln > clip
            hair[over] *= (clip / ln[over])[..., None]
        tip = base + hair
        fin = np.all(np.isfinite(tip), axis=-1)
        segs = np.stack([base[fin], tip[fin]], axis=1)
        ax.add_collection(LineCollection(segs, colors=style["hair"], linewidths=0.6,
                                         alpha=0.9, zorder=2, gid=_GID_HAIRS))
        env = tip.reshape(-1, 2).copy()
        ax.plot(env[:, 0], env[:, 1], color=style["envelope"], lw=0.9, zorder=2,
                gid=_GID_ENVELOPE)
    if points:
        data = getattr(p.curve, "points", None)
        ctrl = getattr(p.curve, "control_points", None)
        if data is not None:
            d = proj(np.asarray(data))
            ax.plot(d[:, 0], d[:, 1], ls="none", marker="o", ms=3.5 if ref else 4.0,
                    mfc="white" if ref else style["points"], mec=style["points"], mew=0.9,
                    zorder=5)
        elif ctrl is not None:
            d = proj(np.asarray(ctrl))
            ax.plot(d[:, 0], d[:, 1], ls=":", lw=0.8, marker="s", ms=3.0, color=style["points"],
                    mfc="white", zorder=3)
    if markers and not ref:
        _draw_curve_markers(ax, p, proj, ref=ref, bad_labels=bad_labels)


def _draw_curve_markers(ax: Any, p: _Prepared, proj: _Projector, *, ref: bool,
                        bad_labels: bool) -> None:
    f = p.feats
    alpha = 0.55 if ref else 1.0
    if f.inflections.size:
        q = proj(p.curve(f.inflections))
        ax.plot(q[:, 0], q[:, 1], ls="none", marker="D", ms=6, mfc=_INFLECTION, mec="white",
                mew=0.6, alpha=alpha, zorder=6, gid="curvefair-inflections")
    if f.extrema.size:
        q = proj(p.curve(f.extrema))
        ax.plot(q[:, 0], q[:, 1], ls="none", marker="^", ms=6, mfc=_EXTREMUM, mec="white",
                mew=0.6, alpha=alpha, zorder=6, gid="curvefair-extrema")
    if f.bad:
        ub = np.array([b[1] for b in f.bad])
        q = proj(p.curve(ub))
        ax.plot(q[:, 0], q[:, 1], ls="none", marker="o", ms=11, mfc="none", mec=_BAD,
                mew=1.4, alpha=alpha, zorder=6, gid="curvefair-bad-points")
        if bad_labels:
            for rank, xy in enumerate(q, start=1):
                ax.annotate(f"{rank}", xy, xytext=(6, 6), textcoords="offset points",
                            color=_BAD, fontsize=8, fontweight="bold", alpha=alpha, zorder=7)


def _legend_handles(has: dict[str, Any]) -> list[Any]:
    mpl = _mpl()
    Line2D = mpl.lines.Line2D
    out = []
    if has.get("inflection"):
        out.append(Line2D([], [], ls="none", marker="D", ms=6, mfc=_INFLECTION, mec="white",
                          label="inflection"))
    if has.get("extremum"):
        out.append(Line2D([], [], ls="none", marker="^", ms=6, mfc=_EXTREMUM, mec="white",
                          label="curvature extremum"))
    if has.get("bad"):
        out.append(Line2D([], [], ls="none", marker="o", ms=9, mfc="none", mec=_BAD, mew=1.4,
                          label=("worst bad points" if has["bad_label"] is None else
                                 f"worst bad points ({has['bad_label']})")))
    return out


def _common_label(prepared: list[_Prepared]) -> str | None:
    labels = {p.feats.bad_label for p in prepared if p.feats.bad}
    return labels.pop() if len(labels) == 1 else (_Features.bad_label if not labels else None)


def _prime(order: int) -> str:
    sup = str.maketrans("0123456789", "⁰¹²³⁴⁵⁶⁷⁸⁹")
    return "'" * order if order <= 3 else "⁽" + str(order).translate(sup) + "⁾"


def _finish_curve_axes(ax: Any, prepared: list[_Prepared], proj: _Projector, scale: float,
                       comb: bool, markers: bool, extra_handles: list[Any] | None = None,
                       clip: float | None = None, y_down: bool = False,
                       legend: bool = True) -> None:
    ax.set_aspect("equal", adjustable="datalim")
    ax.autoscale_view()
    if y_down and proj.dim == 2 and not ax.yaxis_inverted():
        ax.invert_yaxis()
    ax.set_xlabel(proj.labels[0])
    ax.set_ylabel(proj.labels[1])
    ax.grid(True, lw=0.4, alpha=0.4)
    handles, _ = ax.get_legend_handles_labels()
    handles = list(handles) + (extra_handles or [])
    if markers:
        handles += _legend_handles({
            "inflection": any(p.feats.inflections.size for p in prepared),
            "extremum": any(p.feats.extrema.size for p in prepared),
            "bad": any(p.feats.bad for p in prepared),
            "bad_label": _common_label(prepared),
        })
    if handles and legend:
        ax.legend(handles=handles, loc="best", fontsize=8, framealpha=0.85)
    notes = []
    if comb:
        notes.append(f"comb: hair = {scale:.3g} × κ"
                     + (f", clipped at {clip:.3g}" if clip is not None else ""))
    if y_down and proj.dim == 2:
        notes.append("y axis down (as in the file)")
    if proj.note:
        notes.append(proj.note)
    if notes:
        ax.text(0.01, 0.01, "; ".join(notes), transform=ax.transAxes, fontsize=7.5,
                color="0.35", ha="left", va="bottom")


def _draw_curvature(ax: Any, p: _Prepared, *, style: dict[str, str], label: str | None,
                    markers: bool, ref: bool = False, offset: float = 0.0) -> None:
    s = p.fine.flat("s") + offset
    k = p.fine.flat("kappa")
    ax.plot(s, k, color=style["curve"], lw=1.2 if ref else 1.6, ls="--" if ref else "-",
            label=label, gid=_GID_CURVATURE, zorder=3 if ref else 4)
    if not markers or ref:
        return
    f = p.feats
    alpha = 0.55 if ref else 1.0
    if f.inflections.size:
        ax.plot(_s_at(p.curve, p.fine, f.inflections) + offset, np.zeros(f.inflections.size),
                ls="none", marker="D", ms=5.5, mfc=_INFLECTION, mec="white", mew=0.6,
                alpha=alpha, zorder=6)
    if f.extrema.size:
        ke = _kappa_at(p.curve, f.extrema)
        ax.plot(_s_at(p.curve, p.fine, f.extrema) + offset, ke, ls="none", marker="^", ms=5.5,
                mfc=_EXTREMUM, mec="white", mew=0.6, alpha=alpha, zorder=6)
    for rank, (_, ub, _) in enumerate(f.bad, start=1):
        sb = float(_s_at(p.curve, p.fine, np.array([ub]))[0]) + offset
        ax.axvline(sb, color=_BAD, lw=0.9, ls=":", alpha=alpha, zorder=1)
        if not ref:
            ax.annotate(f"{rank}", (sb, 1.0), xycoords=("data", "axes fraction"),
                        xytext=(3, -10), textcoords="offset points", color=_BAD, fontsize=8,
                        fontweight="bold")


def _kappa_at(curve: PiecewiseCurve, u: FloatArray) -> FloatArray:
    from .analysis import curvature

    return np.asarray(curvature(curve, u), dtype=float).reshape(-1)


KappaScale = Literal["auto", "linear", "symlog", "clip"]
KAPPA_SCALES = ("auto", "linear", "symlog", "clip")


def _set_kappa_scale(ax: Any, prepared: Sequence[_Prepared], mode: str) -> str:
    """Apply the curvature axis scale; returns the mode used.

    ``"auto"``: :func:`curvature_axis_mode`. ``"symlog"``: matplotlib's symmetric log scale,
    linear within the median ``|kappa|`` (by arc length). ``"clip"``: the axis limited to
    1.5 times the 95 % quantile of ``|kappa|`` by arc length (the peak runs off the axis; the
    label gives its value).
    """
    choice(mode, KAPPA_SCALES, "kappa_scale")
    ks = [p.fine.flat("kappa") for p in prepared]
    ss = [p.fine.flat("s") for p in prepared]
    if mode == "auto":
        mode = curvature_axis_mode(ks, ss)
    if mode == "symlog":
        med, kmax = typical_curvature(ks, ss, 0.5)
        lin = med if med > 0 else (kmax / 1e3 if kmax > 0 else 1.0)
        ax.set_yscale("symlog", linthresh=lin)
    elif mode == "clip":
        q95, kmax = typical_curvature(ks, ss, 0.95)
        lim = 1.5 * q95
        if lim > 0 and kmax > lim:
            signed = bool(np.nanmin(np.concatenate(ks)) < 0)
            ax.set_ylim(-lim if signed else -0.05 * lim, lim)
            ax.text(0.99, 0.98, f"clipped at ±{lim:.3g} (max |κ| {kmax:.4g})",
                    transform=ax.transAxes, ha="right", va="top", fontsize=7.5, color="0.35")
    return mode


def _finish_curvature_axes(ax: Any, dim: int, prepared: Sequence[_Prepared] = (),
                           kappa_scale: str = "linear") -> None:
    ax.axhline(0.0, color="0.6", lw=0.7, zorder=1)
    ax.set_xlabel("arc length s")
    mode = _set_kappa_scale(ax, prepared, kappa_scale) if prepared else "linear"
    ylab = "curvature κ (signed)" if dim == 2 else "curvature κ"
    ax.set_ylabel(ylab + (", symlog" if mode == "symlog" else ""))
    ax.grid(True, lw=0.4, alpha=0.4)
    ax.margins(x=0.01)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc="best", fontsize=8, framealpha=0.85)


def _same_domain(a: PiecewiseCurve, b: PiecewiseCurve) -> bool:
    (a0, a1), (b0, b1) = a.domain, b.domain
    tol_t = 1e-12 * max(a1 - a0, b1 - b0, abs(a0), abs(a1))
    return abs(a0 - b0) <= tol_t and abs(a1 - b1) <= tol_t


def _nearest_distance(q: FloatArray, other: PiecewiseCurve) -> FloatArray:
    """Distance from each point of ``q`` to ``other``, replaced by a fine polyline.

    About 20 000 vertices; nearest vertex from a k-d tree, then the two adjacent chords.
    """
    from scipy.spatial import cKDTree

    m = other.piecewise.n_segments
    poly = _sample(other, _density(None, m, "samples", 20000, 256)).flat("r")
    _, j = cKDTree(poly).query(q)
    best = np.linalg.norm(q - poly[j], axis=1)
    for a_off in (-1, 0):
        a = np.clip(j + a_off, 0, poly.shape[0] - 2)
        p0, p1 = poly[a], poly[a + 1]
        d = p1 - p0
        dd = np.sum(d * d, axis=1)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.clip(np.sum((q - p0) * d, axis=1) / dd, 0.0, 1.0)
        t = np.where(dd > 0, t, 0.0)
        best = np.minimum(best, np.linalg.norm(q - (p0 + t[:, None] * d), axis=1))
    return best


def exact_text(value: float, ref: float | None = None, digits: int = 5) -> str:
    """``value`` with ``digits`` significant digits, or more until the text compares with
    ``ref`` (a tolerance) as the value does and differs from it when the value does
    (1.0013e-4 is never printed as 0.0001, a value just above the tolerance never as the
    tolerance); at most the 17 digits of float64's round trip."""
    v = float(value)
    if not math.isfinite(v):
        return repr(v)
    for d in range(digits, 18):
        text = f"{v:.{d}g}"
        shown = float(text)
        if ref is None:
            return text
        r = float(ref)
        if (shown <= r) == (v <= r) and (shown == r) == (v == r):
            return text
    return repr(v)


def _draw_deviation(ax: Any, before: _Prepared, after: _Prepared, *, offset: float = 0.0,
                    annotate: bool = True, tol: float | None = None) -> tuple[float, bool]:
    """Plot the deviation of ``after`` from ``before`` against the arc length of ``after``.

    Curves on the same parameter domain (a curve and its faired version): ``|after(t) -
    before(t)|``, the quantity the fairing tolerance bounds, with its certified maximum from
    :func:`curvefair.deviation`. Otherwise: the distance to the nearest point of ``before``.
    Returns (largest value, parametric?).
    """
    from .analysis import deviation

    s = after.fine.flat("s") + offset
    parametric = _same_domain(before.curve, after.curve)
    if parametric:
        u = after.fine.flat("u")
        dev = np.linalg.norm(after.fine.flat("r") - before.curve(u), axis=1)
        d = deviation(before.curve, after.curve)
        dmax = float(d.max_distance)
        smax = float(_s_at(after.curve, after.fine, np.array([d.param]))[0]) + offset
    else:
        dev = _nearest_distance(after.fine.flat("r"), before.curve)
        i = int(np.argmax(dev))
        dmax, smax = float(dev[i]), float(s[i])
    ax.fill_between(s, 0.0, dev, color=_MAIN["hair"], alpha=0.35, lw=0, zorder=2)
    ax.plot(s, dev, color=_MAIN["curve"], lw=1.3, gid=_GID_DEVIATION, zorder=3)
    if annotate:
        ax.plot([smax], [dmax], marker="v", color=_BAD, ms=6, zorder=5, ls="none")
        ax.annotate(f"max {exact_text(dmax, tol)} at s = {smax:.4g}", (smax, dmax),
                    xytext=(6, -2),
                    textcoords="offset points", fontsize=8, color=_BAD, va="top")
    return dmax, parametric


def _finish_deviation_axes(ax: Any, tol: float | None, dmax: float, parametric: bool,
                           labels: tuple[str, str]) -> None:
    if tol is not None:
        ax.axhline(tol, color=_BAD, lw=1.0, ls="--", label=f"tolerance {float(tol)!r}",
                   zorder=4)
        ax.legend(loc="upper right", fontsize=8, framealpha=0.85)
    top = max(dmax, tol or 0.0)
    ax.set_ylim(0.0, 1.2 * top if top > 0 else 1.0)
    ax.set_xlabel("arc length s")
    ax.set_ylabel("deviation")
    if dmax > 0:
        ax.text(0.01, 0.97, f"max deviation {exact_text(dmax, tol)}", transform=ax.transAxes,
                ha="left", va="top", fontsize=8, color=_BAD, gid="curvefair-max-deviation")
    what = (f"deviation |{labels[1]}(t) - {labels[0]}(t)|" if parametric else
            f"distance of {labels[1]} to the nearest point of {labels[0]}")
    ax.set_title(what, fontsize=9, loc="left")
    ax.grid(True, lw=0.4, alpha=0.4)
    ax.margins(x=0.01)


# Public plotting functions ------------------------------------------------------------------
def plot_curve(curve: PiecewiseCurve, ax: Any = None, comb: bool = True,
               comb_scale: float | None = None, comb_density: int | None = None,
               markers: bool = True, *, points: bool = True, label: str | None = None,
               projection: ProjectionName = "plane", n_bad: int = 3,
               y_down: bool = False) -> Any:
    """Draw ``curve`` with its curvature comb and markers.

    Parameters
    ----------
    curve : PiecewiseCurve
        Any curvefair curve (2-D, or 3-D drawn as a projection, see ``projection``).
    ax : matplotlib Axes, optional
        Where to draw; default the current pyplot axes.
    comb : bool
        Draw the curvature comb (hairs and their envelope).
    comb_scale : float, optional
        Hair length per unit curvature. Default: the longest hair is a fifth of the curve's extent.
    comb_density : int, optional
        Hair intervals per curve segment (``density + 1`` hairs per segment, both ends included).
        Default: about 600 hairs in all.
    markers : bool
        Mark inflections (◆), curvature extrema (▲) and the ``n_bad`` worst bad points (○, those of
        :func:`curvefair.analysis.rank_bad_points`).
    points : bool
        Draw the data points (Hermite curves) or the control polygon (B-splines).
    label : str, optional
        Legend label of the curve.
    projection : {"plane", "xy", "xz", "yz"}
        For 3-D curves: the best-fit plane (default) or a coordinate plane. Ignored in 2-D.
    n_bad : int
        How many bad points to mark.
    y_down : bool
        The data's y axis points down (SVG coordinates): the axes are drawn that way up.

    Returns
    -------
    matplotlib Axes

    Notes
    -----
    The default comb scale is robust (:func:`robust_comb_scale`): with a dominant curvature
    peak (an airfoil's leading edge) hairs longer than a fifth of the drawing are drawn at that
    length, and the note on the axes says so.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import numpy as np
    >>> from curvefair import interpolate_cubic
    >>> from curvefair.plot import plot_curve
    >>> pts = np.column_stack([np.arange(1.0, 8.0), np.ones(7)]); pts[3] = (4.3, 1.6)
    >>> ax = plot_curve(interpolate_cubic(pts))
    """
    _mpl()
    if ax is None:
        ax = _pyplot_axes()
    prepared = _prepare([curve], ["curve"], comb_density, markers, n_bad)
    proj = _projector(prepared, projection)
    scale, clip = _joint_scale_clip(prepared, comb_scale)
    _draw_curve(ax, prepared[0], proj, comb=comb, scale=scale, markers=markers, style=_MAIN,
                label=label, points=points, clip=clip)
    _finish_curve_axes(ax, prepared, proj, scale, comb, markers, clip=clip, y_down=y_down)
    return ax


def plot_curvature(curve: PiecewiseCurve, ax: Any = None, *, markers: bool = True,
                   label: str | None = None, n_bad: int = 3,
                   kappa_scale: KappaScale = "auto") -> Any:
    """Plot the curvature of ``curve`` against its arc length.

    Parameters
    ----------
    curve : PiecewiseCurve
    ax : matplotlib Axes, optional
        Default: the current pyplot axes.
    markers : bool
        Mark inflections (zeros, planar curves), curvature extrema and bad points (dotted
        vertical lines with their rank).
    label : str, optional
    n_bad : int
    kappa_scale : {"auto", "linear", "symlog", "clip"}
        Curvature axis: ``"auto"`` is symmetric-logarithmic when the curvature has a dominant
        peak (:func:`curvature_axis_mode`), else linear; ``"clip"`` limits the axis to 1.5
        times the 95 % quantile of ``|kappa|`` by arc length.

    Returns
    -------
    matplotlib Axes

    Notes
    -----
    Planar curves: signed ``kappa = (x'y'' - y'x'') / |r'|^3``; space curves
    ``|r' x r''| / |r'|^3``. Arc length by composite Gauss-Legendre quadrature of ``|r'|``.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import numpy as np
    >>> from curvefair import interpolate_cubic
    >>> from curvefair.plot import plot_curvature
    >>> ax = plot_curvature(interpolate_cubic(np.c_[np.arange(6.0), np.arange(6.0) ** 2]))
    """
    _mpl()
    if ax is None:
        ax = _pyplot_axes()
    p = _prepare([curve], ["curve"], None, markers, n_bad)[0]
    _draw_curvature(ax, p, style=_MAIN, label=label, markers=markers)
    _finish_curvature_axes(ax, p.curve.dim, [p], kappa_scale)
    return ax


def plot_compare(before: PiecewiseCurve, after: PiecewiseCurve, axes: Any = None, *,
                 tol: float | None = None, labels: tuple[str, str] = ("before", "after"),
                 comb: bool = True, comb_scale: float | None = None,
                 comb_density: int | None = None, markers: bool = True,
                 projection: ProjectionName = "plane", n_bad: int = 3) -> Any:
    """Overlay ``before`` and ``after`` with their combs, and plot the deviation of ``after``.

    Parameters
    ----------
    before, after : PiecewiseCurve
        E.g. a curve and its faired version.
    axes : pair of matplotlib Axes, optional
        ``(curve_axes, deviation_axes)``; default a new pyplot figure with two rows.
    tol : float, optional
        Tolerance drawn as a line on the deviation plot.
    labels : (str, str)
        Legend labels.
    comb, comb_scale, comb_density, markers, projection, n_bad
        As for :func:`plot_curve`. Both combs use the same scale, so they compare.

    Returns
    -------
    (Axes, Axes)
        The curve axes and the deviation axes.

    Notes
    -----
    The deviation at a point of ``after`` is its distance to the nearest point of ``before``
    (``before`` replaced by a polyline of about 20 000 vertices), plotted against the arc length
    of ``after``.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import numpy as np
    >>> from curvefair import interpolate_cubic
    >>> from curvefair.plot import plot_compare
    >>> pts = np.column_stack([np.arange(1.0, 8.0), np.ones(7)]); pts[3] = (4.3, 1.6)
    >>> flat = pts.copy(); flat[3] = (4.2, 1.02)
    >>> ax_curve, ax_dev = plot_compare(interpolate_cubic(pts), interpolate_cubic(flat), tol=0.7)
    """
    _mpl()
    if axes is None:
        axes = _pyplot_axes(2, figsize=(8, 6), height_ratios=(2, 1), layout="constrained")
    ax_c, ax_d = axes
    prepared = (_prepare([before], ["before"], comb_density, False, n_bad)
                + _prepare([after], ["after"], comb_density, markers, n_bad))
    proj = _projector(prepared, projection)
    scale, clip = _joint_scale_clip(prepared, comb_scale)
    tol = None if tol is None else as_positive(tol, "tol", window=True)
    _draw_curve(ax_c, prepared[0], proj, comb=comb, scale=scale, markers=markers, style=_REF,
                label=labels[0], points=True, ref=True, bad_labels=False, clip=clip)
    _draw_curve(ax_c, prepared[1], proj, comb=comb, scale=scale, markers=markers, style=_MAIN,
                label=labels[1], points=True, clip=clip)
    _finish_curve_axes(ax_c, prepared, proj, scale, comb, markers, clip=clip)
    dmax, parametric = _draw_deviation(ax_d, prepared[0], prepared[1], tol=tol)
    _finish_deviation_axes(ax_d, tol, dmax, parametric, labels)
    return ax_c, ax_d


def _as_curve_list(x: Any, name: str) -> list[PiecewiseCurve]:
    """One curve-like object (:func:`curvefair.as_curve`) or a list / tuple of them."""
    from .view import _as_curves

    return _as_curves(x, name)


#: ``figure(panels="auto")`` draws one panel per curve for 2 .. this many curves.
MAX_PANELS = 64


def figure(curve: PiecewiseCurve | Sequence[PiecewiseCurve],
           compare: PiecewiseCurve | Sequence[PiecewiseCurve] | None = None, *,
           labels: tuple[str, str] | None = None, tol: float | None = None,
           comb: bool = True, comb_scale: float | None = None, comb_density: int | None = None,
           markers: bool = True, projection: ProjectionName = "plane", n_bad: int = 3,
           title: str | None = None, figsize: tuple[float, float] | None = None,
           panels: Literal["auto", "overlay", "grid"] = "auto",
           names: Sequence[str | None] | None = None, kappa_scale: KappaScale = "auto",
           y_down: bool = False) -> Any:
    """The standard curvefair figure: curve and comb above, curvature against arc length below.

    With ``compare`` the second curve (e.g. the faired one) is drawn over ``curve`` with its own
    comb at the same scale, both curvature plots share the lower panel, and a third panel shows
    the deviation of ``compare`` from ``curve``, its maximum printed with enough digits to tell
    it from the tolerance (:func:`exact_text`).

    Parameters
    ----------
    curve : PiecewiseCurve or sequence of them
        Anything :func:`curvefair.as_curve` accepts, or a list of them.
    compare : PiecewiseCurve or sequence, optional
        As many curves as ``curve``, paired in order.
    labels : (str, str), optional
        Legend labels of ``curve`` and ``compare``; default ``("curve", "compare")``, or
        ``("before", "after")`` is a good choice for fairing.
    tol : float, optional
        Tolerance line on the deviation panel.
    comb, comb_scale, comb_density, markers, projection, n_bad
        As for :func:`plot_curve`. The default comb scale is robust
        (:func:`robust_comb_scale`).
    title : str, optional
    figsize : (float, float), optional
        Inches; default 9 wide, the height following the curve's aspect ratio (grid: about
        4.2 inches per column).
    panels : {"auto", "overlay", "grid"}
        ``"grid"``: one cell per curve (its curve panel above its curvature panel, and its
        deviation panel with ``compare``), each with its own comb scale, curvature axis and
        (3-D) best-fit plane, so each curve is readable. ``"overlay"``: all curves in one
        panel, their curvature plots following one another along a common arc-length axis,
        separated by grey lines. ``"auto"``: grid for 2 to :data:`MAX_PANELS` curves.
    names : sequence of str, optional
        Grid cell titles (default ``curve 0``, ``curve 1``, ...).
    kappa_scale : {"auto", "linear", "symlog", "clip"}
        Curvature axis, as for :func:`plot_curvature`.
    y_down : bool
        The data's y axis points down (SVG coordinates): 2-D curve panels are drawn that way.

    Returns
    -------
    matplotlib.figure.Figure
        A figure not managed by pyplot: save it with ``fig.savefig(path)`` (works headless).

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import interpolate_cubic
    >>> from curvefair.plot import figure
    >>> pts = np.column_stack([np.arange(1.0, 8.0), np.ones(7)]); pts[3] = (4.3, 1.6)
    >>> fig = figure(interpolate_cubic(pts), title="Wang & Cao 2006, Example 1")
    >>> len(fig.axes)
    2
    """
    mpl = _mpl()
    curves = _as_curve_list(curve, "curve")
    others = None if compare is None else _as_curve_list(compare, "compare")
    if others is not None and len(others) != len(curves):
        raise InputError(f"compare has {len(others)} curves but curve has {len(curves)}; "
                         "they are paired in order")
    choice(panels, ("auto", "overlay", "grid"), "panels")
    choice(kappa_scale, KAPPA_SCALES, "kappa_scale")
    if names is not None:
        names = list(names)
        if len(names) != len(curves):
            raise InputError(f"names has {len(names)} entries for {len(curves)} curves")
    if labels is None:
        labels = ("curve", "compare")
    tol = None if tol is None else as_positive(tol, "tol", window=True)
    if panels == "grid" or (panels == "auto" and 2 <= len(curves) <= MAX_PANELS):
        return _grid_figure(mpl, curves, others, labels=labels, tol=tol, comb=comb,
                            comb_scale=comb_scale, comb_density=comb_density, markers=markers,
                            projection=projection, n_bad=n_bad, title=title, figsize=figsize,
                            names=names, kappa_scale=kappa_scale, y_down=y_down)
    prep = _prepare(curves, [f"curve[{i}]" for i in range(len(curves))], comb_density,
                    markers and others is None, n_bad)
    prep_o = ([] if others is None else
              _prepare(others, [f"compare[{i}]" for i in range(len(others))], comb_density,
                       markers, n_bad))
    everything = prep + prep_o
    proj = _projector(everything, projection)
    scale, clip = _joint_scale_clip(everything, comb_scale)

    # layout: curve panel height from the data's aspect ratio
    xys = [proj(p.fine.flat("r")) for p in everything]
    if comb:
        xys += [proj(p.comb.flat("r")) - scale * proj.vec(p.comb.flat("kvec")) for p in everything]
    xy = np.vstack(xys)
    xy = xy[np.all(np.isfinite(xy), axis=1)]
    span = np.ptp(xy, axis=0) if xy.size else np.ones(2)
    aspect = float(span[1] / span[0]) if span[0] > 0 else 1.0
    width = 9.0
    # axes about 8 inches wide; 10 % margins; 0.8 inch for labels
    top_h = float(np.clip(8.0 * aspect * 1.1 + 0.8, 2.4, 8.0))
    heights = [top_h, 2.4] + ([1.8] if others else [])
    if figsize is None:
        figsize = (width, sum(heights) + (0.4 if title else 0.0))
    fig = mpl.figure.Figure(figsize=figsize, layout="constrained")
    axs = fig.subplots(len(heights), 1, height_ratios=heights)
    ax_c, ax_k = axs[0], axs[1]

    multi = len(curves) > 1
    for i, p in enumerate(prep):
        lab = labels[0] if i == 0 else None
        if others is None:
            _draw_curve(ax_c, p, proj, comb=comb, scale=scale, markers=markers, style=_MAIN,
                        label=lab if multi else None, points=True, clip=clip)
        else:
            _draw_curve(ax_c, p, proj, comb=comb, scale=scale, markers=markers, style=_REF,
                        label=lab, points=True, ref=True, bad_labels=False, clip=clip)
            _draw_curve(ax_c, prep_o[i], proj, comb=comb, scale=scale, markers=markers,
                        style=_MAIN, label=labels[1] if i == 0 else None, points=True,
                        clip=clip)
    _finish_curve_axes(ax_c, everything, proj, scale, comb, markers, clip=clip, y_down=y_down)

    offset = 0.0
    dmax = 0.0
    parametric = True
    for i, p in enumerate(prep):
        if others is None:
            _draw_curvature(ax_k, p, style=_MAIN, label=(labels[0] if multi and i == 0 else None),
                            markers=markers, offset=offset)
            length = p.length
        else:
            q = prep_o[i]
            _draw_curvature(ax_k, p, style=_REF, label=labels[0] if i == 0 else None,
                            markers=markers, ref=True, offset=offset)
            _draw_curvature(ax_k, q, style=_MAIN, label=labels[1] if i == 0 else None,
                            markers=markers, offset=offset)
            dm, parametric = _draw_deviation(axs[2], p, q, offset=offset, annotate=not multi,
                                             tol=tol)
            dmax = max(dmax, dm)
            length = max(p.length, q.length)
        offset += length
        if multi and i < len(prep) - 1:
            for ax in axs[1:]:
                ax.axvline(offset, color="0.5", lw=1.0, ls="-", alpha=0.6)
    _finish_curvature_axes(ax_k, proj.dim, everything, kappa_scale)
    if others is not None:
        _finish_deviation_axes(axs[2], tol, dmax, parametric, labels)
    if multi:
        ax_k.set_xlabel("arc length s (curves one after another)")
    if title:
        fig.suptitle(title, fontsize=11)
    return fig


def _grid_figure(mpl: Any, curves: list[PiecewiseCurve], others: list[PiecewiseCurve] | None,
                 *, labels: tuple[str, str], tol: float | None, comb: bool,
                 comb_scale: float | None, comb_density: int | None, markers: bool,
                 projection: str, n_bad: int, title: str | None,
                 figsize: tuple[float, float] | None, names: list[str | None] | None,
                 kappa_scale: str, y_down: bool) -> Any:
    """One cell per curve: curve panel, curvature panel (and deviation panel)."""
    n = len(curves)
    ncols = min(4, math.ceil(math.sqrt(n)))
    nrows = math.ceil(n / ncols)
    rows = [2.6, 1.5] + ([1.2] if others is not None else [])
    if figsize is None:
        figsize = (4.2 * ncols, nrows * sum(rows) + (0.4 if title else 0.0))
    fig = mpl.figure.Figure(figsize=figsize, layout="constrained")
    outer = fig.add_gridspec(nrows, ncols)
    for i, c in enumerate(curves):
        cell = outer[i // ncols, i % ncols].subgridspec(len(rows), 1, height_ratios=rows)
        axs = [fig.add_subplot(cell[j]) for j in range(len(rows))]
        p = _prepare([c], [f"curve[{i}]"], comb_density, markers and others is None, n_bad)
        q = ([] if others is None else
             _prepare([others[i]], [f"compare[{i}]"], comb_density, markers, n_bad))
        both = p + q
        proj = _projector(both, projection)
        scale, clip = _joint_scale_clip(both, comb_scale)
        if others is None:
            _draw_curve(axs[0], p[0], proj, comb=comb, scale=scale, markers=markers,
                        style=_MAIN, label=None, points=True, clip=clip)
            _draw_curvature(axs[1], p[0], style=_MAIN, label=None, markers=markers)
        else:
            _draw_curve(axs[0], p[0], proj, comb=comb, scale=scale, markers=markers,
                        style=_REF, label=labels[0], points=True, ref=True,
                        bad_labels=False, clip=clip)
            _draw_curve(axs[0], q[0], proj, comb=comb, scale=scale, markers=markers,
                        style=_MAIN, label=labels[1], points=True, clip=clip)
            _draw_curvature(axs[1], p[0], style=_REF, label=None, markers=markers, ref=True)
            _draw_curvature(axs[1], q[0], style=_MAIN, label=None, markers=markers)
            dmax, parametric = _draw_deviation(axs[2], p[0], q[0], tol=tol)
            _finish_deviation_axes(axs[2], tol, dmax, parametric, labels)
            axs[2].set_title("")
        _finish_curve_axes(axs[0], both, proj, scale, comb, markers, clip=clip,
                           y_down=y_down, legend=(i == 0))
        _finish_curvature_axes(axs[1], proj.dim, both, kappa_scale)
        name = names[i] if names is not None and names[i] else f"curve {i}"
        axs[0].set_title(name, fontsize=9, loc="left")
        for ax in axs:
            ax.tick_params(labelsize=7)
            ax.xaxis.label.set_size(8)
            ax.yaxis.label.set_size(8)
    if title:
        fig.suptitle(title, fontsize=11)
    return fig
