"""Tests of curvefair.plot, headless (Agg).

References are independent of the plotting code: curvature of a circle (1/R) and of a helix
(a / (a^2 + b^2)), curvature and tangents by central finite differences of curve positions,
third derivatives by finite differences inside each cubic segment, arc length of a dense polyline,
deviation by brute-force dense evaluation.
"""

from __future__ import annotations

import io
import sys

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from curvefair import (  # noqa: E402
    InputError,
    MissingDependencyError,
    interpolate_bspline,
    interpolate_cubic,
    interpolate_quintic,
)
from curvefair import plot as cfplot  # noqa: E402


# ---------------------------------------------------------------------------------------------
def example1() -> np.ndarray:
    """Wang & Cao 2006 (seed 001), Example 1: (i, 1), i = 1..7, P4 moved to (4.3, 1.6)."""
    pts = np.column_stack([np.arange(1.0, 8.0), np.ones(7)])
    pts[3] = (4.3, 1.6)
    return pts


def fd_kappa_vector(curve, u: np.ndarray, h: float = 1e-4) -> np.ndarray:
    """Curvature vector kappa*N from central differences of positions (not derivatives)."""
    rp = curve(u + h)
    rm = curve(u - h)
    r0 = curve(u)
    d1 = (rp - rm) / (2 * h)
    d2 = (rp - 2 * r0 + rm) / h**2
    t = d1 / np.linalg.norm(d1, axis=1)[:, None]
    perp = d2 - np.sum(d2 * t, axis=1)[:, None] * t
    return perp / np.sum(d1 * d1, axis=1)[:, None]


def collections_with_gid(ax, gid):
    return [c for c in ax.collections if c.get_gid() == gid]


def lines_with_gid(ax, gid):
    return [ln for ln in ax.lines if ln.get_gid() == gid]


def new_ax():
    fig = Figure()
    return fig, fig.add_subplot()


def ink(fig: Figure) -> int:
    """Number of non-white pixels of the rendered figure."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    img = np.asarray(canvas.buffer_rgba())[..., :3]
    return int(np.count_nonzero(np.any(img < 250, axis=-1)))


# --- curvature_comb (no matplotlib) ------------------------------------------------------------
def test_comb_on_circle_points_outward_with_length_scale_over_radius():
    R = 2.0
    a = np.linspace(0.0, np.pi, 41)
    c = interpolate_cubic(np.c_[R * np.cos(a), R * np.sin(a)], bc="natural")
    comb = cfplot.curvature_comb(c, scale=0.5, density=4)
    assert comb.base.shape == (40 * 5, 2)
    # away from the natural ends the interpolant is a circle to ~1e-4
    inner = (comb.u > c.params[5]) & (comb.u < c.params[-6])
    rb = np.linalg.norm(comb.base[inner], axis=1)
    rt = np.linalg.norm(comb.tip[inner], axis=1)
    np.testing.assert_allclose(rb, R, atol=1e-4)
    np.testing.assert_allclose(rt - rb, 0.5 / R, rtol=1e-3)  # outward, length scale * 1/R
    np.testing.assert_allclose(comb.kappa[inner], 1.0 / R, rtol=1e-3)


@pytest.mark.parametrize("kind", ["cubic", "quintic", "bspline"])
def test_comb_hairs_equal_scale_times_fd_curvature_vector(kind):
    rng = np.random.default_rng(7)
    x = np.linspace(0, 6, 12)
    pts = np.c_[x, np.sin(x) + 0.05 * rng.standard_normal(12)]
    c = {"cubic": interpolate_cubic, "quintic": interpolate_quintic,
         "bspline": interpolate_bspline}[kind](pts)
    comb = cfplot.curvature_comb(c, scale=0.3, density=6)
    t0, t1 = c.domain
    ok = (comb.u > t0 + 1e-3) & (comb.u < t1 - 1e-3)
    # one-sided values at breakpoints can differ from the central difference; use interiors
    br = c.piecewise.breaks
    ok &= np.min(np.abs(comb.u[:, None] - br[None, :]), axis=1) > 1e-3
    ref = fd_kappa_vector(c, comb.u[ok])
    np.testing.assert_allclose(comb.base[ok] - comb.tip[ok], 0.3 * ref, atol=2e-5 * 0.3 *
                               np.abs(ref).max() + 1e-7)


def test_comb_helix_uses_principal_normal():
    a, b = 1.0, 0.3
    t = np.linspace(0, 4 * np.pi, 161)
    c = interpolate_cubic(np.c_[a * np.cos(t), a * np.sin(t), b * t])
    comb = cfplot.curvature_comb(c, scale=1.0, density=3)
    inner = (comb.u > c.params[10]) & (comb.u < c.params[-11])
    hair = comb.tip[inner] - comb.base[inner]
    # helix: kappa = a / (a^2 + b^2); principal normal points to the axis, hairs away from it
    np.testing.assert_allclose(np.linalg.norm(hair, axis=1), a / (a * a + b * b), rtol=2e-3)
    radial = comb.base[inner, :2] / np.linalg.norm(comb.base[inner, :2], axis=1)[:, None]
    np.testing.assert_allclose(hair[:, :2] / np.linalg.norm(hair, axis=1)[:, None], radial,
                               atol=5e-3)
    np.testing.assert_allclose(hair[:, 2], 0.0, atol=5e-3)


def test_comb_auto_scale_longest_hair_is_fifth_of_extent():
    c = interpolate_cubic(example1())
    comb = cfplot.curvature_comb(c)
    longest = np.max(np.linalg.norm(comb.tip - comb.base, axis=1))
    extent = np.max(np.ptp(comb.base, axis=0))
    assert longest == pytest.approx(0.2 * extent, rel=1e-9)


@pytest.mark.parametrize("bad", [0, -1, 2.5, True])
def test_comb_density_validated(bad):
    with pytest.raises(InputError, match="density"):
        cfplot.curvature_comb(interpolate_cubic(example1()), density=bad)


def test_comb_scale_validated():
    with pytest.raises(InputError, match="scale"):
        cfplot.curvature_comb(interpolate_cubic(example1()), scale=-1.0)
    with pytest.raises(InputError, match="curve"):
        cfplot.curvature_comb(np.zeros((3, 2)))


# --- plot_curve --------------------------------------------------------------------------------
def test_plot_curve_draws_one_hair_per_sample_and_joined_envelope():
    c = interpolate_cubic(example1())
    fig, ax = new_ax()
    out = cfplot.plot_curve(c, ax, comb_density=5)
    assert out is ax
    (hairs,) = collections_with_gid(ax, "curvefair-comb-hairs")
    assert isinstance(hairs, LineCollection)
    segs = hairs.get_segments()
    assert len(segs) == c.piecewise.n_segments * 6
    (env,) = lines_with_gid(ax, "curvefair-comb-envelope")
    tips = np.array([s[1] for s in segs])
    np.testing.assert_allclose(env.get_xydata(), tips)
    # roots lie on the curve: compare with direct evaluation at the hair parameters
    comb = cfplot.curvature_comb(c, density=5)
    np.testing.assert_allclose(np.array([s[0] for s in segs]), comb.base, atol=1e-12)


def test_comb_off_draws_no_hairs_and_less_ink():
    c = interpolate_cubic(example1())
    f1, a1 = new_ax()
    cfplot.plot_curve(c, a1, comb=True, markers=False)
    f2, a2 = new_ax()
    cfplot.plot_curve(c, a2, comb=False, markers=False)
    assert collections_with_gid(a2, "curvefair-comb-hairs") == []
    assert ink(f1) > 1.3 * ink(f2)


def test_inflection_marker_where_fd_curvature_changes_sign():
    x = np.linspace(-2, 2, 21)
    c = interpolate_cubic(np.c_[x, np.tanh(2 * x)])
    fig, ax = new_ax()
    cfplot.plot_curve(c, ax)
    (infl,) = lines_with_gid(ax, "curvefair-inflections")
    xy = infl.get_xydata()
    assert xy.shape == (1, 2)
    # independent: the sign of the signed curvature, by finite differences, around the marker
    u = np.linspace(*c.domain, 4001)[1:-1]
    d1 = (c(u + 1e-5) - c(u - 1e-5)) / 2e-5
    d2 = (c(u + 1e-5) - 2 * c(u) + c(u - 1e-5)) / 1e-10
    k = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    i = np.flatnonzero(np.sign(k[:-1]) != np.sign(k[1:]))
    assert i.size == 1
    np.testing.assert_allclose(xy[0], c(u[i[0]]), atol=5e-3)


def test_bad_point_ranking_matches_fd_third_derivative_jumps():
    c = interpolate_cubic(example1())
    fig, ax = new_ax()
    cfplot.plot_curve(c, ax, n_bad=3)
    (bad,) = lines_with_gid(ax, "curvefair-bad-points")
    # independent: r''' of a cubic segment is constant; third difference of positions
    br = c.piecewise.breaks
    h = np.diff(br) / 4
    d3 = np.array([(c(b + 3 * hh) - 3 * c(b + 2 * hh) + 3 * c(b + hh) - c(b)) / hh**3
                   for b, hh in zip(br[:-1], h, strict=True)])
    jumps = np.linalg.norm(np.diff(d3, axis=0), axis=1)  # at breakpoints 1 .. m-1
    order = np.argsort(-jumps)[:3] + 1
    np.testing.assert_allclose(bad.get_xydata(), c.points[order], atol=1e-12)
    assert order[0] == 3  # P4 of the paper (0-based index 3) is the worst


def test_plot_curve_bspline_and_closed_and_default_axes():
    import matplotlib.pyplot as plt

    a = np.linspace(0, 2 * np.pi, 13)[:-1]
    pts = np.c_[2 * np.cos(a), np.sin(a)]
    closed = interpolate_cubic(pts, bc="periodic")
    bs = interpolate_bspline(np.c_[np.linspace(0, 5, 9), np.cos(np.linspace(0, 5, 9))])
    try:
        ax = cfplot.plot_curve(closed)  # current pyplot axes
        assert ax is plt.gca()
        # a closed curve's comb has no gap at the seam: first and last tips coincide
        (env,) = lines_with_gid(ax, "curvefair-comb-envelope")
        np.testing.assert_allclose(env.get_xydata()[0], env.get_xydata()[-1], atol=1e-9)
        fig, ax2 = new_ax()
        cfplot.plot_curve(bs, ax2)
        assert collections_with_gid(ax2, "curvefair-comb-hairs")
    finally:
        plt.close("all")


def test_3d_planar_curve_projection_is_congruent():
    t = np.linspace(0, 3, 15)
    p2 = np.c_[t, np.sin(2 * t)]
    c2 = interpolate_cubic(p2)
    rot = np.linalg.qr(np.random.default_rng(3).standard_normal((3, 3)))[0]
    c3 = interpolate_cubic(np.c_[p2, np.zeros(15)] @ rot.T + [1.0, -2.0, 0.5])
    f2, a2 = new_ax()
    cfplot.plot_curve(c2, a2, comb=False, markers=False)
    f3, a3 = new_ax()
    cfplot.plot_curve(c3, a3, comb=False, markers=False)
    (l2,) = lines_with_gid(a2, "curvefair-curve")
    (l3,) = lines_with_gid(a3, "curvefair-curve")
    q2, q3 = l2.get_xydata(), l3.get_xydata()

    def pd(q):
        return np.linalg.norm(q[:, None] - q[None, :], axis=2)

    np.testing.assert_allclose(pd(q3[::7]), pd(q2[::7]), atol=1e-9)
    assert "best-fit plane" in a3.get_xlabel()
    f4, a4 = new_ax()
    cfplot.plot_curve(c3, a4, projection="xz", comb=False, markers=False)
    (l4,) = lines_with_gid(a4, "curvefair-curve")
    np.testing.assert_allclose(l4.get_xydata()[[0, -1]], c3(np.array(c3.domain))[:, [0, 2]],
                               atol=1e-12)
    assert a4.get_xlabel() == "x" and a4.get_ylabel() == "z"
    with pytest.raises(InputError, match="projection"):
        cfplot.plot_curve(c3, new_ax()[1], projection="zx")


# --- plot_curvature ----------------------------------------------------------------------------
def test_plot_curvature_against_polyline_arc_length():
    c = interpolate_cubic(example1())
    fig, ax = new_ax()
    cfplot.plot_curvature(c, ax)
    (ln,) = lines_with_gid(ax, "curvefair-curvature")
    s, k = ln.get_xydata().T
    dense = c(np.linspace(*c.domain, 200001))
    length = np.sum(np.linalg.norm(np.diff(dense, axis=0), axis=1))
    assert s[0] == 0.0
    assert s[-1] == pytest.approx(length, rel=1e-8)
    assert np.all(np.diff(s) >= 0)
    # curvature at the largest |k| sample against finite differences at the same arc length
    i = int(np.argmax(np.abs(k)))
    cum = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(dense, axis=0), axis=1))])
    u = np.interp(s[i], cum, np.linspace(*c.domain, 200001))
    kv = fd_kappa_vector(c, np.array([u]))[0]
    assert abs(k[i]) == pytest.approx(np.linalg.norm(kv), rel=1e-3)
    assert k[i] < 0  # the bump at P4 turns right


# --- plot_compare / figure ---------------------------------------------------------------------
def test_plot_compare_deviation_equals_bruteforce_parametric_distance():
    a = interpolate_cubic(example1())
    q = example1()
    q[3] = (4.25, 1.1)
    b = interpolate_cubic(q, param=a.params)
    fig = Figure()
    axes = fig.subplots(2, 1)
    ax_c, ax_d = cfplot.plot_compare(a, b, axes, tol=0.6)
    (dev,) = lines_with_gid(ax_d, "curvefair-deviation")
    u = np.linspace(*a.domain, 100001)
    brute = np.max(np.linalg.norm(a(u) - b(u), axis=1))
    assert dev.get_xydata()[:, 1].max() == pytest.approx(brute, rel=1e-3)
    assert dev.get_xydata()[:, 1].max() <= brute * (1 + 1e-12)
    assert any("tolerance" in t.get_text() for t in ax_d.get_legend().get_texts())
    assert len(collections_with_gid(ax_c, "curvefair-comb-hairs")) == 2
    assert "(t)" in ax_d.get_title(loc="left")


def test_figure_layouts_and_file_formats():
    a = interpolate_cubic(example1())
    fig = cfplot.figure(a, title="t")
    assert isinstance(fig, Figure) and len(fig.axes) == 2
    q = example1()
    q[3] = (4.2, 1.05)
    fig2 = cfplot.figure(a, compare=interpolate_cubic(q, param=a.params), tol=0.6,
                         labels=("before", "after"))
    assert len(fig2.axes) == 3
    for fmt, magic in (("png", b"\x89PNG"), ("svg", b"<?xml"), ("pdf", b"%PDF")):
        buf = io.BytesIO()
        fig2.savefig(buf, format=fmt)
        assert buf.getvalue().startswith(magic)
    assert ink(fig2) > 20000


def test_figure_several_curves_share_axes():
    x = np.linspace(0, 3, 10)
    c1 = interpolate_cubic(np.c_[x, np.sin(x)])
    c2 = interpolate_cubic(np.c_[x + 4, np.cos(x)])
    fig = cfplot.figure([c1, c2], panels="overlay")
    ax_c, ax_k = fig.axes
    assert len(collections_with_gid(ax_c, "curvefair-comb-hairs")) == 2
    lines = lines_with_gid(ax_k, "curvefair-curvature")
    assert len(lines) == 2
    # second curvature plot starts where the first ends (arc lengths one after another)
    assert lines[1].get_xydata()[0, 0] == pytest.approx(lines[0].get_xydata()[-1, 0])
    with pytest.raises(InputError, match="paired"):
        cfplot.figure([c1, c2], compare=[c1])
    with pytest.raises(InputError):
        cfplot.figure([])


def test_missing_matplotlib_raises_missing_dependency(monkeypatch):
    for name in list(sys.modules):
        if name == "matplotlib" or name.startswith("matplotlib."):
            monkeypatch.setitem(sys.modules, name, None)
    c = interpolate_cubic(example1())
    with pytest.raises(MissingDependencyError, match=r"curvefair\[plot\]"):
        cfplot.figure(c)
    with pytest.raises(MissingDependencyError):
        cfplot.plot_curve(c)
    # the comb itself needs no matplotlib
    assert cfplot.curvature_comb(c).base.shape[1] == 2


# issue 17: panels per curve, robust comb, curvature axis, orientation, exact labels ----------
def _airfoil_like(n=61):
    """A NACA 0012-like closed section with points clustered at the leading edge: its
    curvature there (about 1 / (1.1 t^2) for the rounded nose) is ~100x that of the rest."""
    beta = np.linspace(0.0, np.pi, n)
    x = 0.5 * (1 - np.cos(beta))
    t = 0.12
    y = 5 * t * (0.2969 * np.sqrt(x) - 0.126 * x - 0.3516 * x**2 + 0.2843 * x**3
                 - 0.1036 * x**4)
    upper = np.c_[x[::-1], y[::-1]]
    lower = np.c_[x[1:], -y[1:]]
    return np.vstack([upper, lower])


def test_grid_one_cell_per_curve_with_titles():
    x = np.linspace(0, 3, 10)
    cs = [interpolate_cubic(np.c_[x + 4 * i, np.sin(x + i)]) for i in range(5)]
    fig = cfplot.figure(cs, names=[f"station {i}" for i in range(5)])
    assert len(fig.axes) == 2 * 5
    curve_axes = [a for a in fig.axes if lines_with_gid(a, "curvefair-curve")]
    assert len(curve_axes) == 5
    assert [a.get_title(loc="left") for a in curve_axes] == [f"station {i}" for i in range(5)]
    # each panel shows its own curve: x limits hold that curve's x range only
    for i, a in enumerate(curve_axes):
        lo, hi = a.get_xlim()
        assert lo <= 4 * i + 0.0 and hi >= 4 * i + 3.0
        assert hi - lo < 6.0
    fig2 = cfplot.figure(cs, compare=cs, tol=0.1)
    assert len(fig2.axes) == 3 * 5
    assert len(cfplot.figure(cs, panels="overlay").axes) == 2


def test_leading_edge_curvature_axis_symlog_and_robust_comb():
    c = interpolate_cubic(_airfoil_like())
    _, ax = new_ax()
    cfplot.plot_curvature(c, ax)
    assert ax.get_yscale() == "symlog"
    # the peak (independent estimate: finite differences on the data, ~ 1 / nose radius)
    # is more than PEAK_RATIO times the curvature over most of the length
    t0, t1 = c.domain
    u = np.linspace(t0, t1, 20001)
    k_fd = np.linalg.norm(fd_kappa_vector(c, u[1:-1], h=1e-6 * (t1 - t0)), axis=1)
    assert k_fd.max() > cfplot.PEAK_RATIO * np.quantile(k_fd, 0.5)
    lin = ax.yaxis.get_transform().linthresh
    assert 0 < lin < k_fd.max() / 10
    # a circle: linear axis
    tt = np.linspace(0, np.pi, 20)
    _, ax2 = new_ax()
    cfplot.plot_curvature(interpolate_cubic(np.c_[np.cos(tt), np.sin(tt)]), ax2)
    assert ax2.get_yscale() == "linear"
    _, ax3 = new_ax()
    cfplot.plot_curvature(c, ax3, kappa_scale="clip")
    assert ax3.get_ylim()[1] < k_fd.max() / 5
    # robust comb: hairs clipped at a fifth of the extent, most hairs still visible
    _, ax4 = new_ax()
    cfplot.plot_curve(c, ax4, markers=False)
    segs = collections_with_gid(ax4, "curvefair-comb-hairs")[0].get_segments()
    length = np.array([np.linalg.norm(s[1] - s[0]) for s in segs])
    extent = np.ptp(c.sample(4000), axis=0).max()
    assert length.max() <= 0.2 * extent * (1 + 1e-4)
    # scaled by the maximum curvature, the typical hair would be 0.2 extent median(k) / max(k)
    assert np.median(length) > 3 * 0.2 * extent * np.median(k_fd) / k_fd.max()
    assert any("clipped at" in t.get_text() for t in ax4.texts)


def test_exact_text_never_hides_digits():
    assert cfplot.exact_text(1.0013e-4) == "0.00010013"
    assert cfplot.exact_text(1.0000001e-4, 1e-4) != "0.0001"
    assert float(cfplot.exact_text(1.0000001e-4, 1e-4)) > 1e-4
    assert float(cfplot.exact_text(0.99999999e-4, 1e-4)) < 1e-4
    assert cfplot.exact_text(1e-4, 1e-4) == "0.0001"


def test_deviation_label_is_exact():
    pts = example1()
    moved = pts.copy()
    moved[3] += (0.0, 1.0013e-4)
    a = interpolate_cubic(pts)
    b = interpolate_cubic(moved, param=a.params)  # same parameters: parametric deviation
    fig = cfplot.figure(a, compare=b, tol=1e-4)
    ax_d = fig.axes[2]
    t0, t1 = a.domain
    u = np.linspace(t0, t1, 200001)
    brute = np.linalg.norm(b(u) - a(u), axis=1).max()
    texts = [t.get_text() for t in ax_d.texts] + [t.get_text() for t in ax_d.get_children()
                                                   if hasattr(t, "get_text")]
    label = next(t for t in texts if t.startswith("max deviation"))
    shown = float(label.split()[-1])
    assert shown == pytest.approx(brute, rel=1e-4)
    assert shown > 1e-4  # above the tolerance, and the text says so
    assert ax_d.get_legend().get_texts()[0].get_text() == "tolerance 0.0001"


def test_svg_y_down_and_3d_stations_face_on():
    x = np.linspace(0, 3, 10)
    c = interpolate_cubic(np.c_[x, np.sin(x)])
    _, ax = new_ax()
    cfplot.plot_curve(c, ax, y_down=True)
    assert ax.yaxis_inverted()
    _, ax = new_ax()
    cfplot.plot_curve(c, ax)
    assert not ax.yaxis_inverted()
    # hull stations: planar sections x = const, spread along x; seen along x (face-on)
    th = np.linspace(-1.4, 1.4, 15)
    stations = [interpolate_cubic(np.c_[np.full(th.size, xs), (1 + 0.1 * xs) * np.sin(th),
                                        -np.cos(th) * (1 + 0.05 * xs)])
                for xs in np.linspace(0.0, 30.0, 6)]
    fig = cfplot.figure(stations, panels="overlay", markers=False, comb=False)
    ax_c = fig.axes[0]
    drawn = lines_with_gid(ax_c, "curvefair-curve")
    # face-on: each drawn station is congruent with its y-z section (same area-like extents);
    # edge-on it would collapse to a line
    for ln, st in zip(drawn, stations, strict=True):
        xy = ln.get_xydata()
        yz = st.sample(xy.shape[0])[:, 1:]
        assert np.ptp(xy, axis=0).min() > 0.5 * np.ptp(yz, axis=0).min()
        d_drawn = np.linalg.norm(xy[0] - xy[-1])
        d_true = np.linalg.norm(yz[0] - yz[-1])
        assert d_drawn == pytest.approx(d_true, rel=1e-9)
