"""Tests of the quality-benchmark corpus (benchmarks/quality/corpus.py).

The generators' true curvature counts come from dense evaluation with finite-difference
derivatives; they are checked here against the closed forms (circle, ellipse, clothoid, helix,
superellipse by symmetry, the cubic's quartic), and the curvature itself against the textbook
formulas. Glyph samples are checked against fontTools' own pen decomposition of the outline.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks" / "quality"))
import corpus as C  # noqa: E402


# -- counting ------------------------------------------------------------------------------------
def test_count_extrema_open_and_closed():
    t = np.linspace(0, 4 * np.pi, 4001)
    # sin on [0, 4 pi]: interior extrema at pi/2, 3pi/2, 5pi/2, 7pi/2
    assert C.count_extrema(np.sin(t), closed=False) == 4
    # one period of cos, cyclic: max at 0 and min at pi
    tp = np.linspace(0, 2 * np.pi, 2000, endpoint=False)
    assert C.count_extrema(np.cos(tp), closed=True) == 2
    assert C.count_extrema(np.cos(3 * tp), closed=True) == 6
    # a ripple below the threshold is ignored, above it is counted
    f = t + 1e-9 * np.sin(50 * t)
    assert C.count_extrema(f, closed=False) == 0
    assert C.count_extrema(t + 0.1 * np.sin(50 * t), closed=False) > 50
    assert C.count_extrema(np.full(100, 2.0), closed=True) == 0


def test_sign_changes_and_merge():
    t = np.linspace(-1, 1, 1001)
    assert C.count_sign_changes(t, closed=False) == 1
    assert C.count_sign_changes(t * t, closed=False) == 0  # touches zero only
    tp = np.linspace(0, 2 * np.pi, 1000, endpoint=False)
    assert C.count_sign_changes(np.sin(tp), closed=True) == 2
    # merging: a max-min-max triple 0.01 apart collapses to one extremum
    assert C.merge_close(np.array([0.0, 1.0, 1.01, 1.02, 3.0]), 0.05).size == 3
    assert C.merge_close(np.array([0.0, 1.0, 2.0]), 0.5).size == 3


# -- true curves ---------------------------------------------------------------------------------
@pytest.mark.parametrize("family", [f for f in C.FAMILIES if f != "naca"])
@pytest.mark.parametrize("seed", range(4))
def test_dense_counts_match_closed_forms(family, seed):
    tc = C.make_true_curve(family, np.random.default_rng([99, seed]), seed)
    assert tc.analytic_extrema is not None
    assert tc.extrema == tc.analytic_extrema
    assert tc.inflections == tc.analytic_inflections


def test_closed_form_counts_are_what_the_docs_say():
    rng = np.random.default_rng(5)
    assert C.ellipse_arc(rng).analytic_extrema == 3
    assert C.clothoid(rng).analytic_inflections == 1
    assert C.superellipse(rng).analytic_extrema == 8
    # y = x^3 - k x: dkappa/dx = 0 at two symmetric points inside (-1, 1) for these k
    for seed in range(10):
        tc = C.cubic_graph(np.random.default_rng(seed))
        assert tc.analytic_inflections == 1
        assert tc.analytic_extrema in (2, 4)


def test_curvature_against_textbook_formulas():
    rng = np.random.default_rng(1)
    ell = C.ellipse_arc(rng)
    a, b = ell.params["a"], ell.params["b"]
    t = ell.dense_t()
    exact = a * b / (a**2 * np.sin(t) ** 2 + b**2 * np.cos(t) ** 2) ** 1.5
    assert np.allclose(ell.curvature(), exact, rtol=1e-6)
    clo = C.clothoid(rng)
    assert np.allclose(clo.curvature(), np.pi * clo.dense_t(), atol=1e-6)
    hx = C.helix(rng)
    R, c = hx.params["R"], hx.params["c"]
    assert np.allclose(hx.curvature(), R / (R * R + c * c), rtol=1e-6)
    circ = C.circle_arc(rng)
    assert np.allclose(circ.curvature(), 1 / circ.params["r"], rtol=1e-6)


def test_superellipse_lies_on_its_implicit_curve():
    tc = C.superellipse(np.random.default_rng(3))
    p = tc.polyline(2001)
    a, b = tc.params["a"], tc.params["b"]
    # undo the rotation by matching |x/a|^4 + |y/b|^4 = 1 over a scan of angles
    best = min(
        np.abs(np.abs((np.cos(r) * p[:, 0] + np.sin(r) * p[:, 1]) / a) ** 4
               + np.abs((-np.sin(r) * p[:, 0] + np.cos(r) * p[:, 1]) / b) ** 4 - 1).max()
        for r in np.linspace(0, np.pi / 2, 9001))
    assert best < 1e-3
    assert np.allclose(p[0], p[-1])


def test_naca_formula_values():
    tc = C.naca4("0012")
    tau = np.linspace(0, 1, 20001)  # lower surface, LE -> TE
    p = tc.fn(tau)
    # NACA 0012: 12 % thickness at about 30 % chord, TE half-thickness 0.00126, LE at origin
    assert abs(-p[:, 1].min() * 2 - 0.12) < 0.0005
    assert abs(p[np.argmin(p[:, 1]), 0] - 0.30) < 0.01
    assert abs(p[-1, 1] + 0.00126) < 1e-6 and abs(p[-1, 0] - 1) < 1e-12
    assert np.allclose(p[0], 0)
    # symmetric: upper(-tau) mirrors lower(tau)
    assert np.allclose(tc.fn(-tau) * [1, -1], p)


def test_ground_truth_cases_noise_tol_and_determinism():
    cs = C.ground_truth_cases(instances=2)
    cs2 = C.ground_truth_cases(instances=2)
    assert len(cs) == len(C.FAMILIES) * 2 * len(C.NOISE_LEVELS)
    for a, b in zip(cs, cs2, strict=True):
        assert np.array_equal(a.points, b.points)
    for lev in C.NOISE_LEVELS:
        sel = [c for c in cs if c.noise == lev]
        z = np.concatenate([((c.points - c.clean) / c.scale).ravel() for c in sel])
        assert 0.85 * lev < z.std() < 1.15 * lev
        for c in sel:
            assert c.tol == pytest.approx(C.TOL_FACTOR * lev * c.scale)
            assert c.true_extrema is not None
            # the clean samples lie on the true curve
            assert np.min(np.linalg.norm(c.truth.polyline()[None, :, :] - c.clean[:3, None, :],
                                         axis=2), axis=1).max() < 1e-3 * c.scale


def test_naca_resolvable_count_drops_the_le_double_peak():
    tc = C.naca4("0012")
    assert tc.extrema == 5  # LE min between two maxima 5e-5 chord behind it, plus 2 minima aft
    assert tc.resolvable_extrema(0.01) == 3
    assert tc.resolvable_extrema(1e-5) == 5


# -- airfoil files -------------------------------------------------------------------------------
def _airfoil_points(n=25):
    """Upper (TE -> LE) and lower (LE -> TE) surfaces of a NACA 0012, ``n`` points each."""
    x = 0.5 * (1 - np.cos(np.linspace(0, np.pi, n)))
    yt = 0.6 * (0.2969 * np.sqrt(x) - 0.1260 * x - 0.3516 * x**2 + 0.2843 * x**3 - 0.1015 * x**4)
    return np.c_[x, yt], np.c_[x, -yt]


def test_parse_selig_and_lednicer_give_the_same_loop():
    up, lo = _airfoil_points()
    loop = np.vstack([up[::-1], lo[1:]])  # Selig order, LE once
    selig = "NACA 0012 test\n" + "\n".join(f"  {x:.6f}  {y:.6f}" for x, y in loop) + "\n"
    led = ("NACA 0012 TEST\n       25.       25.\n\n"
           + "\n".join(f" {x:.6f} {y:.6f}" for x, y in up) + "\n\n"
           + "\n".join(f" {x:.6f} {y:.6f}" for x, y in lo) + "\n")
    name, ps = C.parse_airfoil_dat(selig)
    assert name == "NACA 0012 test"
    assert np.allclose(ps, loop, atol=1e-6)
    _, pl = C.parse_airfoil_dat(led)
    assert pl.shape == (50, 2)  # the LE appears twice in Lednicer order ...
    assert np.allclose(C.clean_airfoil(pl), C.clean_airfoil(ps), atol=1e-6)  # ... once after
    bad = led.replace("25.       25.", "25.       24.")
    with pytest.raises(ValueError, match="counts"):
        C.parse_airfoil_dat(bad)
    with pytest.raises(ValueError):
        C.parse_airfoil_dat("name\n1 0\n0 0\nnot a number here\n")


def test_clean_airfoil_rejects_spikes_and_jumps():
    up, lo = _airfoil_points()
    loop = np.vstack([up[::-1], lo[1:]])
    spike = np.vstack([loop[:30], loop[27:28], loop[30:]])  # goes back and forth
    with pytest.raises(ValueError, match="spike"):
        C.clean_airfoil(spike)
    with pytest.raises(ValueError, match="jump"):
        C.clean_airfoil(np.vstack([loop, loop[::-1] + [0, 0.9]]))
    with pytest.raises(ValueError, match="fewer"):
        C.clean_airfoil(loop[:10])


def test_uiuc_airfoils_from_cached_wheel():
    if not sorted(C.CACHE.glob("aerosandbox-*.whl")):
        pytest.skip("aerosandbox wheel not cached (fetched by `make bench-quality`)")
    cases = C.airfoil_cases(None)
    assert len(cases) >= 200
    for c in cases[:: max(1, len(cases) // 50)]:
        assert c.points.shape[1] == 2 and not c.closed
        chord = c.points[:, 0].max() - c.points[:, 0].min()
        assert c.tol == pytest.approx(C.AIRFOIL_TOL * chord)
        assert np.all(np.linalg.norm(np.diff(c.points, axis=0), axis=1) > 0)


# -- glyphs --------------------------------------------------------------------------------------
def _pen_polyline(font_path, char):
    """The outline of ``char`` flattened through fontTools' own pen protocol (independent of
    corpus._contour_segments)."""
    from fontTools.pens.basePen import BasePen
    from fontTools.ttLib import TTFont

    font = TTFont(str(font_path))
    gs = font.getGlyphSet()
    pts = []

    class Flat(BasePen):
        def _moveTo(self, p):
            self.cur = self.start = np.array(p, float)

        def _closePath(self):  # the implied closing line
            self._lineTo(self.start)

        def _lineTo(self, p):
            p = np.array(p, float)
            s = np.linspace(0, 1, 2000)[:, None]
            pts.append((1 - s) * self.cur + s * p)
            self.cur = p

        def _qCurveToOne(self, p1, p2):
            p1, p2 = np.array(p1, float), np.array(p2, float)
            s = np.linspace(0, 1, 2000)[:, None]
            pts.append((1 - s) ** 2 * self.cur + 2 * s * (1 - s) * p1 + s * s * p2)
            self.cur = p2

        def _curveToOne(self, p1, p2, p3):  # pragma: no cover - TrueType has none
            raise AssertionError

    gs[font.getBestCmap()[ord(char)]].draw(Flat(gs))
    return np.vstack(pts)


@pytest.mark.parametrize("char", ["o", "S", "a"])
def test_glyph_samples_lie_on_the_outline(char):
    path = C.dejavu_path("DejaVuSans.ttf")
    runs = list(C.glyph_runs(path, char))
    assert runs
    ref = _pen_polyline(path, char)
    for _, pts, _, upem in runs:
        d = np.min(np.linalg.norm(pts[:, None, :] - ref[None, :, :], axis=2), axis=1)
        assert d.max() < 2e-4 * upem  # on the outline (up to the reference's flattening)
    if char == "o":
        assert [r[2] for r in runs] == [True, True]  # two smooth closed contours


def test_glyph_cases_count():
    cs = C.glyph_cases(10)
    assert len(cs) == 10
    assert all(c.tol == pytest.approx(C.GLYPH_TOL * c.scale) for c in cs)
