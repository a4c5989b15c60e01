"""Tests of the quality benchmark's peers and runner (benchmarks/quality/peers.py, run.py).

Conversions are checked against the peer library's own evaluation; the bisection against its
promise (``(1 - 2%) target <= deviation <= target``), with the deviation recomputed by brute
force from the peer's own object.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks" / "quality"))
import corpus as C  # noqa: E402
import peers as P  # noqa: E402


def _noisy_ellipse(n=60, closed=False, sigma=2e-3, seed=0):
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 2 * np.pi, n, endpoint=False) if closed else np.linspace(-0.3, 3.4, n)
    pts = np.c_[2 * np.cos(t), np.sin(t)]
    return pts + rng.normal(0, sigma, pts.shape)


def test_ppcurve_cut_matches_scipy_ppoly():
    from scipy.interpolate import CubicSpline

    rng = np.random.default_rng(1)
    x = np.sort(rng.uniform(0, 10, 12))
    y = rng.normal(size=(12, 2))
    cs = CubicSpline(x, y)
    lo, hi = x[2] + 0.3, x[9] - 0.2  # cut inside pieces
    c = P.PPCurve.from_ppoly(cs.x, cs.c, lo, hi)
    assert c.domain == (lo, hi)
    u = np.linspace(lo, hi, 301)
    assert np.allclose(c(u), cs(u), atol=1e-12)
    assert np.allclose(c(u, 2), cs(u, 2), atol=1e-10)


def test_taylor_shift_against_direct_evaluation():
    rng = np.random.default_rng(2)
    c = rng.normal(size=(4, 3))
    d = 0.37
    s = np.linspace(-1, 1, 9)
    direct = sum(c[j] * (s[:, None] + d) ** j for j in range(4))
    shifted = P._taylor_shift(c, d)
    assert np.allclose(sum(shifted[j] * s[:, None] ** j for j in range(4)), direct)


@pytest.mark.parametrize("name", ["csaps", "scipy-smoothing", "scipy-splprep"])
@pytest.mark.parametrize("closed", [False, True])
def test_bisection_reaches_the_target(name, closed):
    if name == "csaps":
        pytest.importorskip("csaps")
    pts = _noisy_ellipse(closed=closed)
    tol = 8e-3
    r = P.run_peer(name, pts, closed, tol)
    assert r.curve is not None
    u = P.chord_params(pts, closed)
    # brute-force deviation at the data parameters
    dev = np.max(np.linalg.norm(r.curve(u[: len(pts)]) - pts, axis=1))
    assert dev == pytest.approx(r.dev, rel=1e-12)
    assert dev <= tol
    if name != "scipy-splprep":  # FITPACK's knots make splprep non-monotone in s
        assert r.converged and dev >= 0.98 * tol
    else:
        assert dev >= 0.5 * tol
    assert r.curve.closed == closed
    if closed:  # the curve closes up (value and first two derivatives)
        t0, t1 = r.curve.domain
        pp = r.curve.piecewise
        last = np.array([pp.n_segments - 1])
        for nu in range(3):
            a = pp.evaluate(np.array([t0]), nu)[0]
            b = pp.evaluate(np.array([t1]), nu, segment=last)[0]
            assert np.linalg.norm(a - b) < 1e-6 * max(1.0, np.linalg.norm(a))


def test_csaps_conversion_matches_csaps_evaluation():
    csaps = pytest.importorskip("csaps")
    pts = _noisy_ellipse()
    u = P.chord_params(pts, False)
    s = csaps.CubicSmoothingSpline(u, pts.T, smooth=0.99)
    sp = s.spline
    c = P.PPCurve.from_ppoly(np.asarray(sp.x), np.asarray(sp.c), u[0], u[-1])
    uu = np.linspace(u[0], u[-1], 500)
    assert np.allclose(c(uu), s(uu).T, atol=1e-12)


def test_smoother_peers_are_smoother_than_the_interpolant():
    """At the same tolerance a smoothing spline lowers E2 below the interpolant's."""
    import curvefair as cf

    pts = _noisy_ellipse(sigma=5e-3)
    u = P.chord_params(pts, False)
    e_int = cf.analyze(cf.interpolate_bspline(pts, 3, u)).energy2
    r = P.run_peer("scipy-smoothing", pts, False, 2e-2)
    assert cf.analyze(r.curve).energy2 < 0.5 * e_int


def test_splipy_smooth_stays_within_tolerance():
    pytest.importorskip("splipy")
    pts = _noisy_ellipse(sigma=5e-3)
    r = P.run_peer("splipy-smooth", pts, False, 2e-2)
    assert r.curve is not None and r.extra["iterations"] >= 1
    assert r.dev <= 2e-2
    # one more averaging pass would break the tolerance (unless the cap was reached)
    if r.extra["iterations"] < 4096:
        from splipy import BSplineBasis, Curve
        from splipy.utils.smooth import smooth

        crv = Curve(BSplineBasis(4, np.array(r.curve.knots)), np.array(r.curve.control_points))
        smooth(crv)
        u = P.chord_params(pts, False)
        assert np.max(np.linalg.norm(crv(u) - pts, axis=1)) > 2e-2
    assert P.run_peer("splipy-smooth", pts, True, 2e-2).curve is None  # closed: n/a


def test_run_case_smoke_and_tolerance_check():
    import run as R

    case = C.ground_truth_cases(instances=1, levels=(1e-3,), families=("ellipse",))[0]
    rows = R.run_case(case, tools=["cf:poliakoff", "cf:eck-hadenfeld", "peer:scipy-smoothing"])
    tools = [r["tool"] for r in rows]
    assert tools == ["interpolant", "cf:poliakoff", "cf:eck-hadenfeld", "peer:scipy-smoothing"]
    for r in rows:
        assert r["ok"] == 1, r
        assert r["dev"] <= case.tol * (1 + 1e-9)
        assert r["extrema"] >= 0 and np.isfinite(r["E2"])
        assert r["truth_dist"] < 3 * case.tol
    # the interpolant passes through the points
    assert rows[0]["dev"] < 1e-12 * case.scale


def test_run_all_survives_a_crashing_tool(monkeypatch):
    """A tool that kills its process (as a memory error in compiled code would) is recorded as
    failed for that case; the other tools and cases are unaffected."""
    import os

    import run as R

    cases = C.ground_truth_cases(instances=1, levels=(1e-3,), families=("ellipse", "cubic"))
    victim = cases[1].name

    def fake(case, tools=None):
        names = tools if tools is not None else R.all_tools()
        if case.name == victim and "cf:poliakoff" in names:
            os._exit(3)
        return [dict(R._base_row(case, t), ok=1) for t in names]

    monkeypatch.setattr(R, "run_case", fake)
    rows = R.run_all(cases, jobs=2)
    assert len(rows) == 2 * len(R.all_tools())
    bad = [r for r in rows if not r["ok"]]
    assert [(r["case"], r["tool"]) for r in bad] == [(victim, "cf:poliakoff")]
    assert "crashed" in bad[0]["error"]


def test_page_keeps_hand_written_sections(tmp_path):
    """``make bench-quality`` rewrites only the part of docs/benchmarks.md between its markers:
    text before and after them survives a rewrite; a page without markers is refused (before
    the run, by ``run.main``, so no run is lost), and the committed page has them."""
    import report as Rp

    page = tmp_path / "b.md"
    Rp.write_generated(page, "# Generated\n\nrun 1")
    text = page.read_text()
    assert text.startswith(Rp.BEGIN) and "run 1" in text
    page.write_text(text + "\n## Hand-written\n\nkept table\n")
    Rp.write_generated(page, "# Generated\n\nrun 2")
    text = page.read_text()
    assert "run 2" in text and "run 1" not in text
    assert text.index(Rp.END) < text.index("## Hand-written") < text.index("kept table")
    page.write_text("# A page written by hand\n")
    with pytest.raises(Rp.PageError):
        Rp.write_generated(page, "# Generated")
    assert page.read_text() == "# A page written by hand\n"
    committed = (Path(__file__).resolve().parents[1] / "docs" / "benchmarks.md").read_text()
    Rp.splice(committed, "")  # raises if the committed page lost its markers
    tail = committed[committed.index(Rp.END):]
    assert "## Glyph outlines read from the font itself" in tail


def test_cli_default_tool_counts_the_written_file():
    """``cf:cli-default`` runs ``curvefair fair`` and measures the file it wrote: its points
    are within tol of the input, and its curve is the chord-length natural cubic through
    them (recomputed here from the file's numbers)."""
    import run as R

    case = C.point_file_cases(instances=1, levels=(1e-3,))[1]
    curve, w, rep = R.run_cli_default(case)
    assert rep["method"] == "points-l1"
    assert np.max(np.linalg.norm(w - case.points, axis=1)) <= case.tol
    from scipy.interpolate import CubicSpline

    u = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(w, axis=0), axis=1))]
    ref = CubicSpline(u, w, bc_type="natural")
    t = np.linspace(curve.domain[0], curve.domain[1], 777)
    s = u[0] + (t - curve.domain[0]) * (u[-1] - u[0]) / (curve.domain[1] - curve.domain[0])
    assert np.max(np.abs(np.asarray(curve(t)) - ref(s))) < 1e-9 * case.scale
