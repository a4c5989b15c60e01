"""The ``curvefair view`` page in a real headless browser (Chromium driven by Playwright).

The page is loaded from disk with every network request refused; the checks compare what the
browser drew with the curves themselves, evaluated independently of the page's code:

* no console error or warning, no uncaught exception, no request other than the file itself;
* one drawn path per curve and state; each path's vertices lie on the curve (distance to a
  dense evaluation of the curvefair curve);
* the before / after toggle and the per-curve check boxes hide exactly what they should;
* the maximum deviation printed is the maximum of ``|after(t) - before(t)|`` found by dense
  brute-force evaluation;
* layout of the screenshot: the SVG viewBox holds the curves' bounding box (computed here), and
  mapping dense curve samples through the SVG's ``xMidYMid meet`` rule predicts where the ink
  is: almost every predicted position has ink of the right colour nearby and almost all ink is
  near a predicted position (no bitmap is committed, so fonts and anti-aliasing do not matter).

Chromium comes from Debian (``apt-get install chromium``, .ci/run installs it); without it the
test is skipped, except under ``CI=true``, where it fails.
"""

from __future__ import annotations

import io
import os
import re
import shutil

import numpy as np
import pytest

from curvefair import fair, interpolate_cubic

CHROMIUM = os.environ.get("CURVEFAIR_CHROMIUM", "/usr/bin/chromium")
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
        "--disable-component-update", "--disable-sync", "--no-first-run"]
TOL = 0.02


def _need_browser():
    missing = None
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        missing = "playwright is not installed (pip install playwright; it is in the test extra)"
    if missing is None and not (os.path.exists(CHROMIUM) or shutil.which(CHROMIUM)):
        missing = f"{CHROMIUM} is missing (apt-get install -y chromium)"
    if missing:
        if os.environ.get("CI") == "true":
            pytest.fail(f"CI needs the browser test: {missing}")
        pytest.skip(missing)


def _curves():
    rng = np.random.default_rng(7)
    x = np.linspace(0.0, 6.0, 31)
    a = np.c_[x, np.sin(x) + 0.03 * rng.normal(size=x.size)]
    t = np.linspace(0.2, 2.8, 25)
    b = np.c_[8.0 + 1.5 * np.cos(t), 0.5 + 1.5 * np.sin(t) + 0.02 * rng.normal(size=t.size)]
    before = [interpolate_cubic(a), interpolate_cubic(b)]
    after = [fair(c, tol=TOL).curve for c in before]
    return before, after


@pytest.fixture(scope="module")
def page_setup(tmp_path_factory):
    _need_browser()
    from playwright.sync_api import sync_playwright

    from curvefair.view import write_html

    before, after = _curves()
    path = tmp_path_factory.mktemp("view") / "page.html"
    write_html(path, before, after, names=["sine", "arc"], tol=TOL, title="browser test")
    messages, requests = [], []
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        try:
            page = browser.new_page(viewport={"width": 1100, "height": 900},
                                    device_scale_factor=1)
            page.on("console", lambda m: messages.append((m.type, m.text)))
            page.on("pageerror", lambda e: messages.append(("pageerror", str(e))))

            def route(r):
                requests.append(r.request.url)
                if r.request.url.startswith("file://"):
                    r.continue_()
                else:
                    r.abort()

            page.route("**/*", route)
            page.goto(path.as_uri())
            page.wait_for_selector("body[data-ready='1']", timeout=10000)
            yield page, before, after, messages, requests, path
        finally:
            browser.close()


def _visible(page, selector):
    return page.evaluate(
        "(s) => [...document.querySelectorAll(s)].filter("
        "e => e.getBoundingClientRect().width > 0 && getComputedStyle(e).display !== 'none'"
        ").length", selector)


def _dense(curve, n=20000):
    t0, t1 = curve.domain
    return curve(np.linspace(t0, t1, n))


def _path_vertices(d):
    nums = np.array([float(v) for v in re.findall(r"-?[\d.]+(?:e[-+]?\d+)?", d)])
    return nums.reshape(-1, 2)


def test_loads_without_errors_or_network(page_setup):
    page, _, _, messages, requests, path = page_setup
    bad = [m for m in messages if m[0] in ("error", "warning", "pageerror")]
    assert bad == []
    assert requests == [path.as_uri()]
    html = path.read_text()
    assert "http://" not in html.replace("http://www.w3.org/2000/svg", "")
    assert "https://" not in html


def test_every_curve_is_drawn_on_the_curve(page_setup):
    from scipy.spatial import cKDTree

    page, before, after, *_ = page_setup
    assert page.locator("#list li").count() == len(before)
    for state, curves in (("before", before), ("after", after)):
        ds = page.eval_on_selector_all(f"#view path.curve.{state}",
                                       "els => els.map(e => [e.dataset.curve, "
                                       "e.getAttribute('d')])")
        assert [int(i) for i, _ in ds] == list(range(len(curves)))
        for (i, d), c in zip(ds, curves, strict=True):
            v = _path_vertices(d) * [1.0, -1.0]  # the page draws y up as -y
            dense = _dense(c)
            dist, _ = cKDTree(dense).query(v)
            size = np.ptp(dense, axis=0).max()
            assert dist.max() < 1e-3 * size, (state, i)
            # the path covers the curve from end to end
            assert np.linalg.norm(v[0] - c(c.domain[0])) < 1e-5 * size
            assert np.linalg.norm(v[-1] - c(c.domain[1])) < 1e-5 * size


def test_toggle_and_selection(page_setup):
    page, before, *_ = page_setup
    n = len(before)
    assert _visible(page, "#view path.curve.before") == n
    assert _visible(page, "#view path.curve.after") == n
    page.click("#mode-before")
    assert _visible(page, "#view path.curve.before") == n
    assert _visible(page, "#view path.curve.after") == 0
    assert _visible(page, "#kplot path.kcurve.after") == 0
    page.click("#mode-after")
    assert _visible(page, "#view path.curve.before") == 0
    assert _visible(page, "#view path.curve.after") == n
    page.click("#mode-both")
    assert _visible(page, "#kplot path.kcurve") == 2
    vb_all = page.get_attribute("#view", "viewBox")
    page.uncheck("#list li[data-curve='1'] input.sel")
    assert _visible(page, "#view path.curve.before") == n - 1
    assert page.get_attribute("#view", "viewBox") != vb_all
    page.check("#list li[data-curve='1'] input.sel")
    assert _visible(page, "#view path.curve.before") == n
    assert page.get_attribute("#view", "viewBox") == vb_all


def test_maximum_deviation_marked_and_exact(page_setup):
    page, before, after, *_ = page_setup
    for i in range(len(before)):
        page.click(f"#list li[data-curve='{i}']")
        text = page.text_content("#dev-max-label")
        shown = float(re.search(r"max (\S+)", text).group(1))
        t0, t1 = before[i].domain
        u = np.linspace(t0, t1, 200001)
        brute = np.linalg.norm(after[i](u) - before[i](u), axis=1).max()
        assert brute <= shown * (1 + 1e-9)
        assert shown <= brute * (1 + 1e-6)
        assert shown <= TOL
        assert page.locator("#dev-max").count() == 1
        assert _visible(page, f"#view g[data-curve='{i}'] .devmax-mark") == 1
        assert "tolerance " + repr(TOL) in page.text_content("#devcap")


def _ink_check(png, before_or_after, vb, box, colour, exclude=None):
    from PIL import Image

    img = np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=float)
    h, w, _ = img.shape
    x0, y0, vw, vh = vb
    k = min(box[0] / vw, box[1] / vh)  # xMidYMid meet
    ox = box[2] + (box[0] - k * vw) / 2  # the element's border, then the centred content
    oy = box[3] + (box[1] - k * vh) / 2
    pts = np.vstack([_dense(c, 4000) for c in before_or_after]) * [1.0, -1.0]
    px = np.c_[ox + k * (pts[:, 0] - x0), oy + k * (pts[:, 1] - y0)]
    ink = np.abs(img - 255.0).max(axis=2) > 60  # not background (the frame is light grey)
    ink[:2, :] = ink[-2:, :] = False
    ink[:, :2] = ink[:, -2:] = False
    if exclude is not None:  # the ring marking the maximum deviation
        ex = np.array([ox + k * (exclude[0] - x0), oy + k * (-exclude[1] - y0)])
        yy, xx = np.mgrid[0:h, 0:w]
        r_ex = 0.012 * max(vw, vh) * k * 1.5 + 4
        ink &= np.hypot(xx - ex[0], yy - ex[1]) > r_ex
        px = px[np.hypot(px[:, 0] - ex[0], px[:, 1] - ex[1]) > r_ex + 3]
    iy, ix = np.nonzero(ink)
    from scipy.spatial import cKDTree

    # every predicted position has ink within 2 px ...
    d_pred, _ = cKDTree(np.c_[ix, iy]).query(px)
    assert np.mean(d_pred <= 2.0) > 0.97
    # ... and the ink is the curves' (within 3 px of a predicted position)
    d_ink, _ = cKDTree(px).query(np.c_[ix, iy])
    assert np.mean(d_ink <= 3.0) > 0.98
    # colour of the ink on the curve
    on = img[iy[d_ink <= 1.0], ix[d_ink <= 1.0]]
    mean = on.mean(axis=0)
    target = np.array([int(colour[i:i + 2], 16) for i in (1, 3, 5)], dtype=float)
    assert np.linalg.norm(mean - target) < 60, (mean, target)


def test_screenshot_layout(page_setup):
    page, before, after, *_ = page_setup
    page.uncheck("#comb")
    page.click("#list li[data-curve='0']")
    t0, t1 = before[0].domain
    u = np.linspace(t0, t1, 200001)
    umax = u[np.argmax(np.linalg.norm(after[0](u) - before[0](u), axis=1))]
    ring = after[0](umax)
    try:
        vb = [float(v) for v in page.get_attribute("#view", "viewBox").split()]
        box = page.evaluate("() => { const r = document.getElementById('view');"
                            " return [r.clientWidth, r.clientHeight, r.clientLeft, r.clientTop]; }")
        # the viewBox holds every curve, with a margin of at most 10 %
        pts = np.vstack([_dense(c) for c in before + after]) * [1.0, -1.0]
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        assert vb[0] <= lo[0] and vb[1] <= lo[1]
        assert vb[0] + vb[2] >= hi[0] and vb[1] + vb[3] >= hi[1]
        assert max(vb[2], vb[3]) <= 1.1 * 1.01 * max(hi - lo)
        view = page.locator("#view")
        page.click("#mode-before")
        if os.environ.get("VIEW_DEBUG"):
            with open("/tmp/shot_view.png", "wb") as f:
                f.write(view.screenshot())
        _ink_check(view.screenshot(), before, vb, box, "#8c8c8c", exclude=ring)
        page.click("#mode-after")
        _ink_check(view.screenshot(), after, vb, box, "#1f4e79", exclude=ring)
        # the plots sit below the curve view, in page order
        rects = page.evaluate("() => ['view', 'kplot', 'dplot'].map(i => "
                              "document.getElementById(i).getBoundingClientRect().top)")
        assert rects[0] < rects[1] < rects[2]
    finally:
        page.check("#comb")
        page.click("#mode-both")


def test_clipped_curvature_axis(page_setup, tmp_path):
    """The curvature plot's clipped mode, on a curve whose curvature spans four decades (a
    flat ellipse: 125 at the ends of its long axis, 0.008 at the middle). The curvature is
    computed here from a dense evaluation of the curve (finite differences of the samples,
    not the page's data); the page must print a clip level of 1.5 x the 95 % quantile of |k|,
    draw every sample at its curvature clamped to that level (mapped through the plot's axes),
    and the linear mode must draw the peak the clipped one cuts."""
    from curvefair.view import write_html

    t = np.linspace(-1.2, 1.2, 41)
    c = interpolate_cubic(np.c_[5.0 * np.cos(t), 0.2 * np.sin(t)])
    path = tmp_path / "clip.html"
    write_html(path, [c], names=["ellipse"], title="clip test")
    # curvature along arc length, independently: dense samples, central differences
    u = np.linspace(*c.domain, 400001)
    p = c(u)
    d1, d2 = np.gradient(p, u, axis=0), np.gradient(np.gradient(p, u, axis=0), u, axis=0)
    kap = (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / np.linalg.norm(d1, axis=1) ** 3
    s_ref = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))]
    messages = []
    # a second page in the module's browser (one Playwright session per module)
    page = page_setup[0].context.browser.new_page(viewport={"width": 1100, "height": 900})
    try:
        page.on("console", lambda m: messages.append((m.type, m.text)))
        page.on("pageerror", lambda e: messages.append(("pageerror", str(e))))
        page.goto(path.as_uri())
        page.wait_for_selector("body[data-ready='1']", timeout=10000)
        drawn = {}
        for mode in ("linear", "clip"):
            page.select_option("#kscale", mode)
            drawn[mode] = (page.get_attribute("#kplot path.kcurve.before", "d"),
                           page.text_content("#kplot"))
    finally:
        page.close()
    assert [m for m in messages if m[0] in ("error", "warning", "pageerror")] == []
    W, H, L, B = 800.0, 220.0, 70.0, 22.0  # the plot's frame (viewBox 0 0 800 220)

    def values(d, ylo, yhi):
        v = _path_vertices(d)
        s = (v[:, 0] - L) / (W - 8 - L) * s_ref[-1]
        k = ylo + (1 - (v[:, 1] - 8) / (H - B - 8)) * (yhi - ylo)
        return s, k

    def frame(vals):
        lo, hi = min(0.0, vals.min()), max(0.0, vals.max())
        return lo - 0.05 * (hi - lo), hi + 0.05 * (hi - lo)

    # the page's samples sit at its own arc lengths: the reference curvature there
    d_lin, _ = drawn["linear"]
    v = _path_vertices(d_lin)
    s_pg = (v[:, 0] - L) / (W - 8 - L) * s_ref[-1]
    k_ref = np.interp(s_pg, s_ref, kap)
    ylo, yhi = frame(k_ref)
    _, k_lin = values(d_lin, ylo, yhi)
    assert np.allclose(k_lin, k_ref, rtol=0.02, atol=0.01 * kap.max())
    assert k_lin.max() > 0.9 * kap.max()
    # clipped: the level printed and every sample clamped to it
    d_clip, text = drawn["clip"]
    level = float(re.search(r"clipped at ±(\S+)", text).group(1))
    srt = np.sort(np.abs(k_ref))
    expected = 1.5 * srt[min(len(srt) - 1, int(np.floor(0.95 * len(srt))))]
    assert abs(level - expected) <= 0.03 * expected + 0.001, (level, expected)
    assert level < 0.5 * kap.max()  # the peak is cut
    clamped = np.clip(k_ref, -level, level)
    ylo, yhi = frame(clamped)
    _, k_clip = values(d_clip, ylo, yhi)
    assert np.allclose(k_clip, clamped, rtol=0.02, atol=0.005 * level)
    assert np.sum(np.isclose(k_clip, level, rtol=1e-3)) >= 2  # drawn flat at the level
