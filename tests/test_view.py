"""curvefair.view without a browser: the page's data, the ``curvefair view`` command, notebook
display (``_repr_html_``). The page itself is exercised in Chromium by test_view_browser.py."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from click.testing import CliRunner

from curvefair import fair, interpolate_cubic
from curvefair.cli import main
from curvefair.view import page_data, to_html, write_html


def _page_json(text):
    m = re.search(r'<script type="application/json" id="curvefair-data">(.*?)</script>', text,
                  re.S)
    return json.loads(m.group(1))


def _noisy(n=25, seed=0, shift=0.0):
    rng = np.random.default_rng(seed)
    x = np.linspace(0, 4, n)
    return np.c_[x + shift, np.sin(x) + 0.03 * rng.normal(size=n)]


def test_page_is_self_contained_and_holds_the_data():
    a = interpolate_cubic(_noisy())
    r = fair(a, tol=0.01)
    text = to_html(a, r.curve, tol=0.01, report=r.report, title="t </script> <b>")
    # no external resource of any kind; the title is escaped; the data survive the escaping
    assert not re.search(r'\b(src|href)\s*=', text)
    assert "https://" not in text and "http://" not in text.replace(
        "http://www.w3.org/2000/svg", "")
    assert "<b>" not in text
    d = _page_json(text)
    assert d["title"] == "t </script> <b>"
    assert d["tol"] == 0.01 and d["has_after"] and len(d["curves"]) == 1
    assert d["report"]["method"] == r.report["method"]
    # the maximum is the certified one, stored with all its digits
    assert d["curves"][0]["dev"]["max"] == pytest.approx(r.report["max_deviation"], rel=1e-9)
    assert d["curves"][0]["dev"]["max"] <= 0.01


def test_large_curve_page_stays_small():
    rng = np.random.default_rng(1)
    t = np.linspace(0, 50, 100001)
    big = interpolate_cubic(np.c_[t, np.sin(t) + 1e-3 * rng.normal(size=t.size)])
    d = page_data(big)
    xy = np.array(d["curves"][0]["before"]["xy"]).reshape(-1, 2)
    assert xy.shape[0] <= 2000
    # a curve this long is drawn from equally spaced parameters (view._sample): the drawn
    # points are the curve's there, to the page's 7 significant digits
    u = np.linspace(*big.domain, xy.shape[0])
    assert np.abs(big(u) - xy).max() <= 1e-6 * 50
    assert len(to_html(big)) < 400_000


def test_airfoil_like_comb_is_clipped_and_axis_log():
    beta = np.linspace(0.0, np.pi, 61)
    x = 0.5 * (1 - np.cos(beta))
    y = 0.6 * (0.2969 * np.sqrt(x) - 0.126 * x - 0.3516 * x**2 + 0.2843 * x**3
               - 0.1036 * x**4)
    c = interpolate_cubic(np.vstack([np.c_[x[::-1], y[::-1]], np.c_[x[1:], -y[1:]]]))
    d = page_data(c)
    assert d["kappa_mode"] == "symlog"
    assert d["comb_clip"] is not None
    cur = d["curves"][0]["before"]
    base = np.array(cur["cb"]).reshape(-1, 2)
    tip = np.array(cur["ct"]).reshape(-1, 2)
    assert np.linalg.norm(tip - base, axis=1).max() <= d["comb_clip"] * (1 + 1e-5)


def test_cli_view_with_compare_and_report(tmp_path):
    pts = _noisy()
    src = tmp_path / "in.csv"
    np.savetxt(src, pts, delimiter=",")
    runner = CliRunner()
    out = tmp_path / "faired.csv"
    rep = tmp_path / "r.json"
    res = runner.invoke(main, ["fair", str(src), "-o", str(out), "--tol", "0.01",
                               "--report", str(rep), "-q"])
    assert res.exit_code == 0, res.output
    page = tmp_path / "page.html"
    res = runner.invoke(main, ["view", str(src), "--compare", str(out), "--report", str(rep),
                               "-o", str(page)])
    assert res.exit_code == 0, res.output
    d = _page_json(page.read_text())
    assert d["tol"] == 0.01  # from the report
    assert len(d["curves"]) == 1 and d["has_after"]
    assert d["report"] == json.loads(rep.read_text())
    # usage errors
    res = runner.invoke(main, ["view", str(src), "-o", str(tmp_path / "page.png")])
    assert res.exit_code == 2 and ".html" in res.output
    res = runner.invoke(main, ["view", str(src), "-o", str(src)])
    assert res.exit_code == 2
    res = runner.invoke(main, ["view", str(src), "--compare", str(src), "-o",
                               str(tmp_path / "p2.html"), "--tol", "0.5"])
    assert res.exit_code == 0, res.output


def test_write_html_is_atomic_and_keeps_symlinks(tmp_path):
    c = interpolate_cubic(_noisy())
    target = tmp_path / "real.html"
    target.write_text("old")
    link = tmp_path / "link.html"
    link.symlink_to(target)
    write_html(link, c)
    assert link.is_symlink() and "curvefair-data" in target.read_text()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link.html", "real.html"]


def test_repr_html_small_for_large_curves():
    c = interpolate_cubic(_noisy())
    h = c._repr_html_()
    assert h.count("<svg") == 1 and "CubicHermite" in h
    t = np.linspace(0, 50, 100001)
    big = interpolate_cubic(np.c_[t, np.sin(t)])
    hb = big._repr_html_()
    assert len(hb) < 60_000
    pts = re.search(r'polyline points="([^"]*)" stroke="#1f4e79"', hb).group(1).split()
    assert 100 <= len(pts) <= 400
    r = fair(c, tol=0.01)
    hr = r._repr_html_()
    assert repr(r.report["max_deviation"]) in hr and "<svg" in hr


DATA = __import__("pathlib").Path(__file__).parent / "data" / "real"


def _circumcurvature(p):
    """Curvature of the circle through each three consecutive points (independent of any
    spline): 4 * area / (a b c)."""
    a = np.linalg.norm(p[1:-1] - p[:-2], axis=1)
    b = np.linalg.norm(p[2:] - p[1:-1], axis=1)
    c = np.linalg.norm(p[2:] - p[:-2], axis=1)
    u, v = p[1:-1] - p[:-2], p[2:] - p[:-2]
    area2 = np.abs(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0])
    return 2 * area2 / (a * b * c), 0.5 * (a + b)


def test_real_airfoil_leading_edge_gets_log_axis_and_clipped_comb():
    from curvefair import read_curves
    from curvefair.plot import typical_curvature

    recs = read_curves(DATA / "uiuc" / "e387.dat")
    k, w = _circumcurvature(np.asarray(recs[0].points))
    # independent: the nose curvature is far above the typical (length-weighted) curvature
    order = np.argsort(k)
    cw = np.cumsum(w[order])
    k90 = k[order][np.searchsorted(cw, 0.9 * cw[-1])]
    assert k.max() > 20 * k90
    assert typical_curvature([k], [np.cumsum(w)])[1] == k.max()
    d = page_data(recs)
    assert d["kappa_mode"] == "symlog"
    assert d["comb_clip"] is not None


@pytest.mark.filterwarnings("ignore:.*unsupported Arc segment")
def test_cli_view_real_svg_is_y_down(tmp_path):
    from curvefair import read_curves

    src = DATA / "svgpathtools" / "test.svg"
    n = len(read_curves(src, on_unsupported="skip"))
    page = tmp_path / "svg.html"
    res = CliRunner().invoke(main, ["view", str(src), "-o", str(page), "-q"])
    assert res.exit_code == 0, res.output
    d = _page_json(page.read_text())
    assert d["y_down"] is True and len(d["curves"]) == n


def test_result_repr_shows_the_input_before_the_faired_curve():
    """A FairingResult displays the curve that was faired (grey) under the faired one (blue):
    the grey polyline is the input's own drawing (the same mapping: both curves' samples
    agree to the tolerance in pixels) and differs from the faired one; a result built without
    its input shows the faired curve alone."""
    from curvefair import FairingResult

    c = interpolate_cubic(_noisy())
    r = fair(c, tol=0.01)
    assert r.original is c
    h = r._repr_html_()
    assert "before (grey)" in h

    def poly(html, colour):
        m = re.findall(rf'polyline points="([^"]*)" stroke="{colour}" stroke-width="1.6"', html)
        return [np.array([[float(v) for v in p.split(",")] for p in s.split()]) for s in m]

    before, after = poly(h, "#8c8c8c"), poly(h, "#1f4e79")
    assert len(before) == 1 and len(after) == 1 and before[0].shape == after[0].shape
    # pixel scale from the drawing's width (the SVG's viewBox) over the data's x extent
    width = float(re.search(r'viewBox="0 0 ([0-9.]+) ', h).group(1))
    diff = np.linalg.norm(before[0] - after[0], axis=1).max()
    span = np.ptp(np.asarray(c.points)[:, 0])
    assert 0 < diff <= (0.01 * width / span) * 1.2 + 0.15  # within tol, in pixels
    alone = FairingResult(r.curve, r.report, r.history)._repr_html_()
    assert not poly(alone, "#8c8c8c") and len(poly(alone, "#1f4e79")) == 1
