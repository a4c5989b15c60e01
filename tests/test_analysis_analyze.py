"""analyze(): energies, jumps, Sapidis measure, inflection/extremum counts, quadratures.

Independent references: scipy's spline evaluation (CubicHermiteSpline/BPoly) for one-sided
derivatives, the planar closed form of the Sapidis-Farin measure, brute-force dense sampling for
the sign counts, scipy.integrate.quad for arc length and int (dkappa/ds)^2 ds, and curves of
known structure (S-curve, lines, circle, ellipse, figure eight).
"""

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad
from scipy.interpolate import BPoly, CubicHermiteSpline

import curvefair as cf
from curvefair.analysis import curvature_derivative
from curvefair.analysis._sampling import sample_curve, scan_sign_changes
from curvefair.errors import InputError


def _scipy_spline(c):
    if isinstance(c, cf.QuinticHermite):
        return BPoly.from_derivatives(c.params, np.stack([c.points, c.d1, c.d2], axis=1))
    return CubicHermiteSpline(c.params, c.points, c.tangents, axis=0)


def _one_sided(spl, a, b, nu, deg, at_end):
    """nu-th derivative of the polynomial piece on [a, b] at its start or end, from scipy
    values at interior points (exact polynomial fit of degree deg - nu)."""
    k = max(deg - nu, 0)
    x = a + (b - a) * np.linspace(0.2, 0.8, k + 1)
    v = spl(x, nu)
    fit = [np.polyfit(x - a, v[:, d], k) for d in range(v.shape[1])]
    s = (b - a) if at_end else 0.0
    return np.array([np.polyval(f, s) for f in fit])


def _ref_jumps(c, nu):
    spl = _scipy_spline(c)
    t = c.params
    m = len(t) - 1
    idx = np.arange(0 if c.closed else 1, m)
    out = []
    for j in idx:
        left = _one_sided(spl, t[j - 1 if j else m - 1], t[j if j else m], nu, c.degree, True)
        right = _one_sided(spl, t[j], t[j + 1], nu, c.degree, False)
        out.append(np.linalg.norm(right - left))
    return idx, np.array(out)


def _noisy(rng, n, dim, closed=False):
    s = np.linspace(0, 2 * np.pi, n + (1 if closed else 0))[: n if closed else None]
    base = [np.cos(s), np.sin(2 * s) * 0.7, 0.3 * np.sin(3 * s)][:dim]
    return np.c_[tuple(base)] + 0.02 * rng.normal(size=(n, dim))


CURVES = {
    "cubic-2d": lambda r: cf.interpolate_cubic(_noisy(r, 14, 2)),
    "cubic-3d": lambda r: cf.interpolate_cubic(_noisy(r, 14, 3)),
    "cubic-2d-closed": lambda r: cf.interpolate_cubic(_noisy(r, 14, 2, True), bc="periodic"),
    "cubic-3d-closed": lambda r: cf.interpolate_cubic(_noisy(r, 14, 3, True), bc="periodic"),
    "hermite-c1": lambda r: cf.CubicHermite(_noisy(r, 10, 2), r.normal(size=(10, 2)),
                                            np.cumsum(r.uniform(0.2, 1, 10))),
    "quintic-2d": lambda r: cf.interpolate_quintic(_noisy(r, 12, 2)),
    "quintic-3d-closed": lambda r: cf.interpolate_quintic(_noisy(r, 12, 3, True),
                                                          bc="periodic"),
}


@pytest.mark.parametrize("name", sorted(CURVES))
def test_energies_and_jumps_vs_scipy(name):
    c = CURVES[name](np.random.default_rng(len(name)))
    a = cf.analyze(c)
    assert a.energy2 == pytest.approx(cf.energy(c, 2), rel=1e-12)
    assert a.energy3 == pytest.approx(cf.energy(c, 3), rel=1e-12)
    idx, ref3 = _ref_jumps(c, 3)
    np.testing.assert_array_equal(a.jump_indices, idx)
    np.testing.assert_allclose(a.jump_params, c.params[idx], rtol=0, atol=0)
    scale = max(ref3.max(), 1.0)
    np.testing.assert_allclose(a.jumps, ref3, rtol=1e-7, atol=1e-9 * scale)
    _, reft = _ref_jumps(c, c.degree)
    np.testing.assert_allclose(a.top_jumps, reft, rtol=1e-7, atol=1e-9 * max(reft.max(), 1))
    assert a.max_jump == pytest.approx(ref3.max(), rel=1e-7)
    k = int(np.flatnonzero(idx == a.max_jump_index)[0])  # the argmax (ties within rounding)
    assert ref3[k] == pytest.approx(ref3.max(), rel=1e-7, abs=1e-9 * scale)
    assert a.top_order == c.degree and a.closed == c.closed and a.dim == c.dim


@pytest.mark.parametrize("closed", [False, True])
def test_sapidis_planar_closed_form(closed):
    # planar C2 cubic: z_j = |r' x jump(r''')| / |r'|^4 (lecture notes 004 / ERRATA)
    rng = np.random.default_rng(11)
    c = (cf.interpolate_cubic(_noisy(rng, 16, 2, True), bc="periodic") if closed
         else cf.interpolate_cubic(_noisy(rng, 16, 2)))
    a = cf.analyze(c)
    idx = a.jump_indices
    spl = _scipy_spline(c)
    t = c.params
    m = len(t) - 1
    z = []
    for j in idx:
        jl, jr = (j - 1, j) if j else (m - 1, m)
        d3 = (_one_sided(spl, t[j], t[j + 1], 3, 3, False)
              - _one_sided(spl, t[jl], t[jr], 3, 3, True))
        r1 = spl(t[j], 1)
        z.append(abs(r1[0] * d3[1] - r1[1] * d3[0]) / np.dot(r1, r1) ** 2)
    np.testing.assert_allclose(a.sapidis, z, rtol=1e-7, atol=1e-10)
    assert a.sapidis_sum == pytest.approx(np.sum(z), rel=1e-7)
    assert a.max_sapidis_index == idx[np.argmax(z)]


def test_sapidis_3d_vs_one_sided_dkds():
    c = CURVES["quintic-3d-closed"](np.random.default_rng(3))
    a = cf.analyze(c)
    assert not a.planar
    b = c.piecewise.breaks
    ref = np.abs(curvature_derivative(c, b[a.jump_indices], side="right")
                 - curvature_derivative(c, b[a.jump_indices], side="left"))
    np.testing.assert_allclose(a.sapidis, ref, rtol=1e-9, atol=1e-12)


# -- counts ------------------------------------------------------------------------------------
def _dense_counts(c, a, per_segment=400):
    """Brute force: curvature and dkappa/ds on a dense grid of every segment (both one-sided
    values at each knot), zero band as documented, sign changes counted (cyclic if closed)."""
    b = c.piecewise.breaks
    f = np.linspace(0, 1, per_segment)
    u = b[:-1, None] + np.diff(b)[:, None] * f[None, :]
    out = []
    for fun, tol, wanted in ((cf.curvature, a.kappa_tol, a.planar),
                             (curvature_derivative, a.dkds_tol, True)):
        if not wanted:
            out.append(0)
            continue
        v = fun(c, u[:, :-1]) if c.dim == 2 or fun is curvature_derivative else None
        if v is None:  # planar 3-D curve: signed curvature in its plane (tested elsewhere)
            out.append(None)
            continue
        v = np.concatenate([v, fun(c, u[:, -1], side="left")[:, None]], axis=1).ravel()
        sg = np.sign(np.where(np.abs(v) <= tol, 0.0, v))
        nz = sg[sg != 0]
        n = int(np.count_nonzero(nz[1:] != nz[:-1]))
        if c.closed and nz.size and nz[0] != nz[-1]:
            n += 1
        out.append(n)
    return out


@pytest.mark.parametrize("name", sorted(CURVES))
def test_counts_match_dense_sampling(name):
    c = CURVES[name](np.random.default_rng(100 + len(name)))
    a = cf.analyze(c)
    infl, ext = _dense_counts(c, a)
    if infl is not None:
        assert a.inflections == infl
    assert a.extrema == ext
    assert len(a.inflection_params) == a.inflections
    assert len(a.extremum_params) == a.extrema
    t0, t1 = c.domain
    assert np.all((a.extremum_params >= t0) & (a.extremum_params <= t1))


def test_hidden_sign_changes_are_found():
    # wild data: some sign changes of the curvature and dkappa/ds numerators fall between two
    # samples of a segment; the Bernstein certificate adds samples there. Compared with the
    # pure sign structure (no noise band) of a dense brute-force sampling.
    rng = np.random.default_rng(0)
    x = np.linspace(0, 20, 2000)
    pts = np.c_[x, np.sin(x)] + 1e-2 * rng.normal(size=(2000, 2))
    c = cf.interpolate_cubic(pts)
    pp = c.piecewise
    b = pp.breaks
    smp = sample_curve(np.asarray(pp.coeffs), pp.widths, True, False)
    assert smp.extra[0][0].size > 0 and smp.extra[1][0].size > 0  # the certificate added some
    f = np.linspace(0, 1, 300)
    u = b[:-1, None] + np.diff(b)[:, None] * f[None, :]
    no_floor = (np.full(len(b) - 1, 1e300), np.zeros(len(b) - 1))
    for which, (fun, vals, power) in enumerate(((cf.curvature, smp.kappa, 1),
                                                (curvature_derivative, smp.dkds, 2))):
        v = np.concatenate([fun(c, u[:, :-1]), fun(c, u[:, -1], side="left")[:, None]],
                           axis=1).ravel()
        nz = np.sign(v[v != 0])
        dense = int(np.count_nonzero(nz[1:] != nz[:-1]))
        n, _ = scan_sign_changes(vals, smp.x, b, smp.extra[which], 0.0, False, *no_floor,
                                 power)
        empty = (np.zeros(0, dtype=np.int64), np.zeros(0), np.zeros(0))
        n_without, _ = scan_sign_changes(vals, smp.x, b, empty, 0.0, False, *no_floor, power)
        assert n == dense and n_without < dense


def test_s_curve_one_inflection():
    x = np.linspace(-2, 2, 21)
    c = cf.interpolate_cubic(np.c_[x, np.tanh(2 * x)])
    a = cf.analyze(c)
    assert a.inflections == 1 and a.extrema == 2
    # the inflection is at the symmetry point x = 0
    assert c(a.inflection_params[0])[0] == pytest.approx(0.0, abs=1e-6)
    # extrema: curvature maximum and minimum on either side, symmetric
    xs = c(a.extremum_params)[:, 0]
    assert xs[0] == pytest.approx(-xs[1], rel=1e-6) and xs[0] < 0


@pytest.mark.parametrize("dim", [2, 3])
def test_straight_lines_have_no_inflections_or_extrema(dim):
    rng = np.random.default_rng(dim)
    for _ in range(20):
        t = np.cumsum(rng.uniform(0.1, 1, int(rng.integers(3, 30))))
        d = rng.normal(size=dim)
        scale = 10 ** rng.uniform(-3, 3)
        pts = scale * (rng.normal(size=dim) * 10 ** rng.uniform(-2, 3) + np.outer(t, d))
        for c in (cf.interpolate_cubic(pts),
                  cf.QuinticHermite(pts, np.tile(d * scale, (len(t), 1)), np.zeros_like(pts),
                                    t)):
            a = cf.analyze(c)
            assert (a.inflections, a.extrema) == (0, 0)
            assert a.max_curvature * np.ptp(pts, axis=0).max() < 1e-6


def test_circle_arc_real_tiny_oscillations_are_counted():
    a_ = np.linspace(0, np.pi, 40)
    c = cf.interpolate_cubic(np.c_[3 * np.cos(a_), 3 * np.sin(a_)])
    a = cf.analyze(c)
    assert a.inflections == 0
    infl, ext = _dense_counts(c, a)
    assert a.extrema == ext > 10  # the spline's curvature really oscillates about 1/R


@pytest.mark.parametrize("n", [24, 40, 64])
def test_closed_ellipse_four_vertices(n):
    # data symmetric about the four vertices (one of them at the seam, so one extremum is a
    # sign change of dkappa/ds across the seam): exactly the four vertices
    th = np.linspace(0, 2 * np.pi, n + 1)[:-1]
    c = cf.interpolate_cubic(np.c_[2 * np.cos(th), np.sin(th)], bc="periodic")
    a = cf.analyze(c)
    assert a.inflections == 0 and a.extrema == 4
    p = c(a.extremum_params)
    # vertices of the ellipse: (+-2, 0) and (0, +-1)
    ang = np.sort(np.mod(np.arctan2(p[:, 1], p[:, 0] / 2) + 0.1, 2 * np.pi)) - 0.1
    np.testing.assert_allclose(ang, [0, np.pi / 2, np.pi, 3 * np.pi / 2], atol=1e-6)
    # data not symmetric about the vertices: the spline really has a pair of extra extrema
    # near some vertices; the count agrees with brute force
    c2 = cf.interpolate_cubic(np.c_[2 * np.cos(th + 0.1), np.sin(th + 0.1)], bc="periodic")
    a2 = cf.analyze(c2)
    assert a2.extrema >= 4 and [a2.inflections, a2.extrema] == _dense_counts(c2, a2)


@pytest.mark.parametrize("shift", [0.0, 0.4, np.pi])
def test_figure_eight_closed_counted_cyclically(shift):
    # lemniscate of Gerono: two inflections at the crossing point; shift=0 and pi put the
    # seam at an inflection, so one of them is found across the seam
    u = np.linspace(0, 2 * np.pi, 61)[:-1] + shift
    c = cf.interpolate_cubic(np.c_[np.sin(u), np.sin(u) * np.cos(u)], bc="periodic")
    a = cf.analyze(c)
    assert a.inflections == 2
    np.testing.assert_allclose(c(a.inflection_params), 0.0, atol=1e-3)
    infl, ext = _dense_counts(c, a)
    assert (a.inflections, a.extrema) == (infl, ext)


def test_planar_3d_curve_matches_2d_and_twisted_has_no_inflections():
    x = np.linspace(-2, 2, 21)
    s2 = np.c_[x, np.tanh(2 * x)]
    q, _ = np.linalg.qr(np.random.default_rng(0).normal(size=(3, 3)))
    s3 = np.c_[s2, np.zeros(21)] @ q.T + [1, -2, 3]
    a2, a3 = cf.analyze(cf.interpolate_cubic(s2)), cf.analyze(cf.interpolate_cubic(s3))
    assert a3.planar and a3.dim == 3
    assert (a3.inflections, a3.extrema) == (a2.inflections, a2.extrema) == (1, 2)
    for f in ("energy2", "energy3", "arc_length", "dkds_energy", "sapidis_sum", "max_jump"):
        assert getattr(a3, f) == pytest.approx(getattr(a2, f), rel=1e-9)
    np.testing.assert_allclose(a3.inflection_params, a2.inflection_params, rtol=1e-9)
    s = np.linspace(0, 4 * np.pi, 40)
    h = cf.analyze(cf.interpolate_cubic(np.c_[np.cos(s), np.sin(s), 0.3 * s]))
    assert not h.planar and h.inflections == 0 and h.inflection_params.size == 0


# -- quadratures -------------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["cubic-2d", "cubic-3d", "cubic-2d-closed", "quintic-2d",
                                  "hermite-c1", "quintic-3d-closed"])
def test_arc_length_and_dkds_energy_vs_quad(name):
    # reference: scipy.integrate.quad per segment on the curve's derivative and on the
    # (separately tested) curvature_derivative
    c = CURVES[name](np.random.default_rng(7))
    b = c.piecewise.breaks
    arc = dke = 0.0
    for i in range(len(b) - 1):
        arc += quad(lambda t: np.linalg.norm(c(t, 1)), b[i], b[i + 1], epsabs=0,
                    epsrel=1e-13, limit=400)[0]
        dke += quad(lambda t: curvature_derivative(c, t) ** 2 * np.linalg.norm(c(t, 1)),
                    b[i], b[i + 1], epsabs=0, epsrel=1e-12, limit=400)[0]
    a = cf.analyze(c)
    assert a.arc_length == pytest.approx(arc, rel=1e-9)
    # (3-D: |kappa| has near-corners where the curvature nearly vanishes; the adaptive
    # re-integration bisects the pieces around them, 2-D and 3-D alike to 1e-9)
    assert a.dkds_energy == pytest.approx(dke, rel=2e-9)
    # the reported error estimates are honest (bound the true error, up to quad's own)
    assert abs(a.arc_length - arc) <= a.arc_length_error + 1e-12 * arc
    assert abs(a.dkds_energy - dke) <= a.dkds_energy_error + 1e-10 * dke
    coarse = cf.analyze(c, quad_rtol=1e-3)
    assert coarse.dkds_energy == pytest.approx(dke, rel=1e-2)
    assert (coarse.inflections, coarse.extrema) == (a.inflections, a.extrema)


@pytest.mark.parametrize("eps", [1e-2, 1e-4])
def test_dkds_energy_of_a_space_curve_whose_curvature_nearly_vanishes(eps):
    """A space curve through a planar S whose inflection is lifted out of the plane by
    ``eps``: its curvature dips to ~eps within a parameter range of ~eps, where dkappa/ds
    turns. Against scipy's quad (told where the dip is): the energy to 1e-9, the error
    estimate honest. (Refining whole segments uniformly, curvefair stopped at 10 levels,
    8,000 pieces per segment, short of 1e-9.)"""
    t = np.linspace(-1.0, 1.0, 8)            # the dip (t = 0) inside a segment
    c = cf.interpolate_cubic(np.c_[t, t**3 - t, eps * t**2], param=t)
    dke = 0.0
    b = c.piecewise.breaks
    for i in range(len(b) - 1):
        dke += quad(lambda u: curvature_derivative(c, u) ** 2 * np.linalg.norm(c(u, 1)),
                    b[i], b[i + 1], epsabs=0, epsrel=1e-12, limit=2000,
                    points=[0.0] if b[i] < 0.0 < b[i + 1] else None)[0]
    a = cf.analyze(c)
    assert a.dkds_energy == pytest.approx(dke, rel=1e-9)
    assert abs(a.dkds_energy - dke) <= a.dkds_energy_error + 1e-10 * dke
    assert a.dkds_energy_error <= 1e-9 * a.dkds_energy


# -- invariance, output, bad input --------------------------------------------------------------
@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), angle=st.floats(0, 2 * np.pi),
       scale=st.floats(0.01, 100), closed=st.booleans())
def test_rigid_motion_and_scaling(seed, angle, scale, closed):
    rng = np.random.default_rng(seed)
    pts = _noisy(rng, 12, 2, closed)
    R = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    bc = "periodic" if closed else "natural"
    c1 = cf.interpolate_cubic(pts, bc=bc)
    c2 = cf.interpolate_cubic(scale * pts @ R.T + [5.0, -3.0], param=scale * c1.params, bc=bc)
    a1, a2 = cf.analyze(c1), cf.analyze(c2)
    assert (a2.inflections, a2.extrema) == (a1.inflections, a1.extrema)
    assert a2.arc_length == pytest.approx(scale * a1.arc_length, rel=1e-9)
    assert a2.energy2 == pytest.approx(a1.energy2 / scale, rel=1e-9)
    assert a2.sapidis_sum == pytest.approx(a1.sapidis_sum / scale**2, rel=1e-7)
    assert a2.max_curvature == pytest.approx(a1.max_curvature / scale, rel=1e-9)
    np.testing.assert_allclose(a2.extremum_params, scale * a1.extremum_params, rtol=1e-8,
                               atol=1e-9 * scale)


def test_to_dict_json_and_frozen():
    c = CURVES["cubic-2d-closed"](np.random.default_rng(1))
    a = cf.analyze(c)
    d = a.to_dict()
    text = json.dumps(d, allow_nan=False)
    back = json.loads(text)
    assert back["inflections"] == a.inflections and back["jumps"] == a.jumps.tolist()
    assert all(type(v) in (int, float, bool, list, type(None)) for v in d.values())
    with pytest.raises(AttributeError):
        a.energy2 = 0.0  # type: ignore[misc]
    with pytest.raises(ValueError):
        a.jumps[0] = 1.0
    for f in ("arc_length_error", "dkds_energy_error"):
        assert 0.0 <= d[f] < 1e-6 * max(d[f.replace("_error", "")], 1.0)


def test_single_segment_and_bspline():
    one = cf.CubicHermite([[0, 0], [1, 1]], [[1, 0], [0, 1]], [0.0, 1.0])
    a = cf.analyze(one)
    assert a.jumps.size == 0 and a.max_jump == 0.0 and a.max_jump_index is None
    assert a.max_sapidis_index is None and a.sapidis_sum == 0.0
    json.dumps(a.to_dict(), allow_nan=False)
    rng = np.random.default_rng(2)
    bs = cf.interpolate_bspline(_noisy(rng, 15, 2), degree=2)
    ab = cf.analyze(bs)
    assert ab.energy3 == 0.0 and ab.degree == 2
    assert ab.energy2 == pytest.approx(cf.energy(bs, 2), rel=1e-12)
    infl, ext = _dense_counts(bs, ab)
    assert (ab.inflections, ab.extrema) == (infl, ext)


@pytest.mark.parametrize("bad", [None, "curve", np.zeros((4, 2)), [[0, 0], [1, 1]]])
def test_bad_curve(bad):
    with pytest.raises(InputError, match="curve"):
        cf.analyze(bad)


@pytest.mark.parametrize("rtol", [0, -1e-3, np.nan, "x", None])
def test_bad_quad_rtol(rtol):
    c = cf.interpolate_cubic([[0, 0], [1, 1], [2, 0]])
    with pytest.raises(InputError, match="quad_rtol"):
        cf.analyze(c, quad_rtol=rtol)


@pytest.mark.parametrize("dim", [2, 3])
def test_counts_do_not_depend_on_the_drawing_scale(dim):
    """kappa ~ 1/size and dkappa/ds ~ 1/size**2 leave float32's range at 1e24 / 1e-18 unless
    the stored samples are made dimensionless (before: every extremum lost at 1e24)."""
    from curvefair.curves.interpolate import interpolate_quintic
    rng = np.random.default_rng(1)
    t = np.linspace(0, 2 * np.pi, 8)[:-1]
    P = np.c_[np.cos(t) * (1 + 0.1 * rng.standard_normal(7)),
              np.sin(t) * (1 + 0.1 * rng.standard_normal(7))]
    if dim == 3:  # a twisted closed curve
        P = np.c_[P, 0.3 * np.sin(2 * t)]
    P = np.vstack([P, P[:1]])
    c = interpolate_quintic(P, "chord", "periodic")
    ref = cf.analyze(c)
    assert ref.extrema > 0
    for s in (1e-18, 1e-12, 1e6, 1e12, 1e20, 1e24):
        cs = c.replace(points=np.asarray(c.points) * s, d1=np.asarray(c.d1) * s,
                       d2=np.asarray(c.d2) * s)
        a = cf.analyze(cs)
        assert (a.extrema, a.inflections) == (ref.extrema, ref.inflections), s
        np.testing.assert_allclose(a.extremum_params, ref.extremum_params, rtol=0, atol=1e-6)


def _bitwise_same(a, b):
    da, db = a.to_dict(), b.to_dict()
    assert da.keys() == db.keys()
    for k in da:
        assert np.array_equal(np.asarray(da[k]), np.asarray(db[k])), k


@pytest.mark.parametrize("kind", ["open", "closed", "quintic", "twisted", "gaps",
                                  "closed_few"])
def test_sampling_pass_in_ranges_is_bitwise_the_same(monkeypatch, kind):
    """The sampling pass split into ranges on two threads (curvefair._threads) gives bitwise
    the analysis of one pass on one thread: every range boundary is a breakpoint whose jumps
    need the segment before (the range re-runs it), a closed curve's seam joins the last
    range to the first. Sixteen ranges of a few segments each, so every kind of boundary is
    crossed; also with the worker thread busy (the calling thread does every range)."""
    import threading

    from curvefair import _threads
    from curvefair.analysis import _sampling

    rng = np.random.default_rng(11)
    n = 130
    x = np.linspace(0, 9, n)
    pts = np.c_[x, np.sin(x)] + 0.01 * rng.normal(size=(n, 2))
    if kind == "open":
        c = cf.interpolate_cubic(pts)
    elif kind == "closed":
        a = np.linspace(0, 2 * np.pi, n, endpoint=False)
        c = cf.interpolate_bspline(np.c_[np.cos(a), 0.5 * np.sin(a)]
                                   + 0.002 * rng.normal(size=(n, 2)), closed=True)
    elif kind == "quintic":
        c = cf.interpolate_quintic(pts)
    elif kind == "twisted":
        c = cf.interpolate_cubic(np.c_[np.cos(x), np.sin(x), 0.2 * x]
                                 + 0.01 * rng.normal(size=(n, 3)))
    elif kind == "closed_few":  # fewer segments than ranges: some ranges are empty
        a = np.linspace(0, 2 * np.pi, 9, endpoint=False)
        c = cf.interpolate_cubic(np.vstack([np.c_[np.cos(a), 0.5 * np.sin(a) + 0.1 * a],
                                            [[1.0, 0.0]]]), "chord", "periodic")
    else:  # near-straight noisy data: many gaps to refine in the sign certificates
        c = cf.interpolate_cubic(np.c_[x, 1e-3 * rng.normal(size=n)])
    monkeypatch.setattr(_threads, "THREADS", 1)
    ref = cf.analyze(c)
    monkeypatch.setattr(_threads, "THREADS", 2)
    monkeypatch.setattr(_sampling, "PAR_MIN", 4)
    calls = []
    ranges = _threads.ranges
    monkeypatch.setattr(_threads, "ranges",
                        lambda fn, lo, hi, *a: calls.append(hi - lo) or ranges(fn, lo, hi, *a))
    got = cf.analyze(c)
    assert calls and ref.extrema > 0
    _bitwise_same(ref, got)
    gate = threading.Event()
    _threads.pool().submit(gate.wait, 30)  # the worker is busy
    try:
        _bitwise_same(ref, cf.analyze(c))
    finally:
        gate.set()


def test_analyze_from_several_threads_at_once(monkeypatch):
    """Several user threads analysing long curves at once share the one worker thread of
    curvefair._threads: each gets bitwise its single-threaded analysis, none waits forever."""
    import threading

    from curvefair import _threads
    from curvefair.analysis import _sampling

    monkeypatch.setattr(_sampling, "PAR_MIN", 64)
    rng = np.random.default_rng(21)
    curves = []
    for k in range(4):
        x = np.linspace(0, 20 + k, 3000)
        curves.append(cf.interpolate_cubic(np.c_[x, np.sin(x)] + 1e-3 * rng.normal(size=(3000, 2))))
    monkeypatch.setattr(_threads, "THREADS", 1)
    ref = [cf.analyze(c) for c in curves]
    monkeypatch.setattr(_threads, "THREADS", 2)
    got: list = [None] * len(curves)

    def work(k):
        got[k] = cf.analyze(curves[k])

    ts = [threading.Thread(target=work, args=(k,)) for k in range(len(curves))]
    for t in ts:
        t.start()
    for t in ts:
        t.join(60)
        assert not t.is_alive()
    for a, b in zip(ref, got, strict=True):
        _bitwise_same(a, b)


@pytest.mark.parametrize("name", [*CURVES, "bspline-closed", "planar-3d", "long-bspline"])
def test_fairness_figures_are_analyze_figures_bit_for_bit(name):
    """fair()'s report reads fairness_figures (no per-knot arrays); each figure is the bits
    of the full analysis' (the long curve: two threads and numpy's pairwise summation over
    many blocks of the Sapidis sum)."""
    from curvefair.analysis import fairness_figures

    rng = np.random.default_rng(5)
    if name == "bspline-closed":
        a = np.linspace(0, 2 * np.pi, 40, endpoint=False)
        c = cf.interpolate_bspline(np.c_[np.cos(a), 0.6 * np.sin(a)]
                                   + 0.01 * rng.normal(size=(40, 2)), closed=True)
    elif name == "planar-3d":  # analysed in its plane; energies from the 3-D coefficients
        R = np.linalg.qr(rng.normal(size=(3, 3)))[0]
        c = cf.interpolate_cubic(np.c_[_noisy(rng, 20, 2), np.zeros(20)] @ R.T)
    elif name == "long-bspline":
        t = np.arange(60_000, dtype=float)
        c = cf.interpolate_bspline(np.c_[t, 20 * np.sin(t / 7)]
                                   + 0.05 * rng.normal(size=(t.size, 2)))
    else:
        c = CURVES[name](rng)
    a = cf.analyze(c)
    got = fairness_figures(c)
    want = {"energy2": a.energy2, "energy3": a.energy3, "max_jump": a.max_jump,
            "max_top_jump": a.max_top_jump, "sapidis_sum": a.sapidis_sum,
            "dkds_energy": a.dkds_energy, "inflections": a.inflections, "extrema": a.extrema}
    assert set(got) == set(want)
    for k, v in want.items():
        assert type(got[k]) is type(v), k
        assert np.float64(got[k]).tobytes() == np.float64(v).tobytes(), (k, got[k], v)
    assert a.extrema > 0 and a.max_jump > 0


@pytest.mark.parametrize("kind", ["open", "closed", "quadratic", "quintic", "flat", "tiny",
                                  "huge", "hermite", "hermite-closed", "hermite-c1",
                                  "hermite-quintic", "hermite-flat"])
def test_planar_curve_from_span_forms_is_the_whole_form_bit_for_bit(monkeypatch, kind):
    """A planar B-spline whose power form is not built is analysed from its spans' forms made
    range by range (analysis._sampling.SpanForms: no whole form at ten million spans); every
    field of the Analysis is the bits of the analysis of the whole form, with the ranges on
    two threads, the re-integration of the worst segments and the sign certificates of
    near-straight data (their segments' rows made on demand), and at drawing scales where the
    two paths pick another power-of-two unit for the stored samples."""
    from curvefair import _threads
    from curvefair.analysis import _analyze as A
    from curvefair.analysis import _sampling

    rng = np.random.default_rng(len(kind))
    n = 150
    x = np.sort(rng.uniform(0, 30, n))
    pts = np.c_[x, np.sin(x)] + 0.01 * rng.normal(size=(n, 2))
    if kind == "closed":
        a = np.linspace(0, 2 * np.pi, n, endpoint=False)
        c = cf.interpolate_bspline(np.c_[np.cos(a), 0.5 * np.sin(a)]
                                   + 1e-3 * rng.normal(size=(n, 2)), closed=True)
    elif kind in ("quadratic", "quintic"):
        c = cf.interpolate_bspline(pts, degree=2 if kind == "quadratic" else 5)
    elif kind == "flat":  # near-straight: gaps to certify and segments to re-integrate
        c = cf.interpolate_bspline(np.c_[x, 1e-4 * rng.normal(size=n)])
    elif kind == "hermite":
        c = cf.interpolate_cubic(pts)
    elif kind == "hermite-closed":
        a = np.linspace(0, 2 * np.pi, n, endpoint=False)
        ring = np.c_[np.cos(a), 0.5 * np.sin(a)] + 1e-3 * rng.normal(size=(n, 2))
        c = cf.interpolate_cubic(np.vstack([ring, ring[:1]]), "chord", "periodic")
    elif kind == "hermite-c1":  # tangents of their own: curvature jumps at every point
        c = cf.CubicHermite(pts, np.c_[np.ones(n), np.cos(x)] + 0.05 * rng.normal(size=(n, 2)),
                            x + np.arange(n) * 1e-3)
    elif kind == "hermite-quintic":
        c = cf.interpolate_quintic(pts)
    elif kind == "hermite-flat":
        c = cf.interpolate_cubic(np.c_[x, 1e-4 * rng.normal(size=n)])
    else:
        scale = {"open": 1.0, "tiny": 3e-18, "huge": 2e27}[kind]
        c = cf.interpolate_bspline(pts * scale)
    monkeypatch.setattr(_threads, "THREADS", 2)
    monkeypatch.setattr(_sampling, "PAR_MIN", 4)
    used = []
    rows = _sampling.SpanForms.rows
    monkeypatch.setattr(_sampling.SpanForms, "rows",
                        lambda self, a, b: used.append(b - a) or rows(self, a, b))
    gathered = []
    gather = _sampling.SpanForms.__getitem__
    monkeypatch.setattr(_sampling.SpanForms, "__getitem__",
                        lambda self, idx: gathered.append(len(idx)) or gather(self, idx))
    got = cf.analyze(c)
    assert "piecewise" not in c.__dict__  # the whole form was never built
    assert len(used) > 1 and max(used) < c.piecewise.n_segments
    if kind in ("flat", "hermite-flat"):  # the gathers of the few segments refined
        assert gathered
    want = A._analyze(c, 1e-9, False, True)  # the whole form (built just above)
    _bitwise_same(want, got)
    assert got.extrema > 0
    if kind in ("flat", "hermite-flat"):
        assert got.extremum_params.size and (got.arc_length_error > 0)


@pytest.mark.parametrize("make", [cf.interpolate_cubic, cf.interpolate_quintic])
def test_hermite_span_coefficients_are_the_whole_forms_rows(make):
    """CubicHermite / QuinticHermite.span_coefficients(idx) is piecewise.coeffs[idx] bit for
    bit (any order, repeats), the Taylor coefficients of the curve (its derivatives at the
    segment's start over k!, by scipy's splines); out-of-range indices are refused."""
    from math import factorial

    rng = np.random.default_rng(4)
    x = np.sort(rng.uniform(0, 10, 30))
    c = make(np.c_[x, np.cos(x)])
    idx = np.array([3, 0, 3, c.piecewise.n_segments - 1, 11])
    rows = c.span_coefficients(idx)
    assert rows.tobytes() == np.asarray(c.piecewise.coeffs)[idx].tobytes()
    spl = _scipy_spline(c)
    starts = np.asarray(c.params)[idx]
    for k in range(c.degree + 1):
        # (scipy's high derivatives of a Bernstein piece lose a few digits: 2e-7 at k = 4)
        np.testing.assert_allclose(rows[:, k, :], spl(starts, k) / factorial(k),
                                   rtol=1e-6, atol=1e-6)
    with pytest.raises(InputError, match="segment indices"):
        c.span_coefficients([c.piecewise.n_segments])
    with pytest.raises(InputError, match="span indices"):
        cf.interpolate_bspline(np.c_[x, np.cos(x)]).span_coefficients([-1])


def test_span_coefficients_are_the_whole_forms_rows():
    """BSplineCurve.span_coefficients(idx) is piecewise.coeffs[idx] bit for bit (any order,
    repeats), and the Taylor coefficients of the curve: scipy's BSpline derivatives at each
    span's left knot over k!."""
    from math import factorial

    from scipy.interpolate import BSpline

    rng = np.random.default_rng(2)
    x = np.sort(rng.uniform(0, 10, 40))
    c = cf.interpolate_bspline(np.c_[x, np.cos(x)], degree=3)
    idx = np.array([5, 0, 5, c.piecewise.n_segments - 1, 17])
    rows = c.span_coefficients(idx)
    assert rows.tobytes() == np.asarray(c.piecewise.coeffs)[idx].tobytes()
    spl = BSpline(np.asarray(c.knots), np.asarray(c.control_points), 3)
    starts = np.asarray(c.piecewise.breaks)[idx]
    for k in range(4):
        np.testing.assert_allclose(rows[:, k, :], spl(starts, k) / factorial(k),
                                   rtol=1e-9, atol=1e-9)
    assert c.span_coefficients(np.zeros(0, dtype=int)).shape == (0, 4, 2)


def test_a_finished_pass_keeps_nothing_alive_while_the_worker_is_busy():
    """A pass whose chunks the calling thread did alone (the worker busy with an earlier job)
    leaves its job in the worker's queue; once finished, that job no longer holds the pass's
    function, so what the function references (a Gram band's work arrays, measured: 5.25x the
    input's coordinate bytes through the global fairing's set-up) is freed with the caller's
    last reference, not when the worker gets to the stale job."""
    import gc
    import threading
    import weakref

    from curvefair import _threads

    class Pass:  # a callable the test can watch (a weak reference to it dies with it)
        def __init__(self) -> None:
            self.rows = np.zeros(1000)

        def __call__(self, a: int, b: int) -> int:
            self.rows[a:b] += 1.0
            return b - a

    gate = threading.Event()
    busy = _threads.pool().submit(gate.wait, 30)  # the worker is busy
    try:
        fn = Pass()
        ref = weakref.ref(fn)
        out = _threads.ranges(fn, 0, 1000, 2, 0, chunks=8)
        assert sum(out) == 1000 and np.all(fn.rows == 1.0)  # every chunk once
        del fn
        gc.collect()
        assert not busy.done()  # the stale job is still queued behind the busy worker
        assert ref() is None
    finally:
        gate.set()
    busy.result(timeout=30)
