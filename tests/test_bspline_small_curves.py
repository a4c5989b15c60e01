"""Every B-spline method on the smallest curves (a single span, band wider than the curve).

Regression: the compiled Eck-Hadenfeld loop once wrote past its arrays when 2p+1 > n.
Each curve runs in a subprocess (every method on it, one after the other) so that memory
corruption fails the test instead of the run.
"""

import subprocess
import sys

import pytest

CASES = {
    "closed-minimal": "cf.BSplineCurve([[0,0],[1,0],[1,1],[0,1]], [0,1,2,3,4], 3, closed=True)",
    "single-span": "cf.BSplineCurve([[0,0],[1,1],[2,1],[3,0]], [0,0,0,0,1,1,1,1], 3)",
    "two-span": "cf.BSplineCurve([[0,0],[1,1],[2,1],[3,0],[4,1]], [0,0,0,0,.5,1,1,1,1], 3)",
    "quartic-3d": "cf.BSplineCurve(np.c_[np.arange(5.), np.sin(np.arange(5.)),"
                  " np.cos(np.arange(5.))], [0,0,0,0,0,1,1,1,1,1], 4)",
}


METHODS = ["eck-hadenfeld", "eck-hadenfeld/sweep", "knot-removal", "cheng-yu", "global"]

#: one interpreter per curve runs every method on it (an interpreter and its kernel loads cost
#: ~2.5 s, a method on these curves milliseconds); each method's outcome is one line
_SCRIPT = """
import sys, traceback
import numpy as np, curvefair as cf
c = {curve}
for method in {methods!r}:
    name, _, sched = method.partition("/")
    opts = {{"schedule": sched}} if sched else {{}}
    try:
        try:
            r = cf.fair(c, name, tol=0.1, **opts)
        except cf.CurvefairError as exc:   # a documented refusal is fine, a crash is not
            print(method, "refused:", exc)
            continue
        u = np.linspace(*c.domain, 4001)
        dev = np.linalg.norm(r.curve(u) - c(u), axis=1).max()
        assert dev <= 0.1 * (1 + 1e-12), dev
        assert np.isfinite(r.curve.control_points).all()
        print(method, "ok", r.report["steps"], r.report["stop_reason"])
    except Exception:
        print(method, "FAILED:", traceback.format_exc().replace("\\n", " | "))
    sys.stdout.flush()
"""


@pytest.mark.parametrize("case", sorted(CASES))
def test_small_bspline_all_methods(case):
    code = _SCRIPT.format(curve=CASES[case], methods=METHODS)
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    lines = proc.stdout.splitlines()
    assert [ln.split(" ", 1)[0] for ln in lines] == METHODS, proc.stdout  # each ran, in order
    for ln in lines:
        assert ln.split(" ", 2)[1] in ("ok", "refused:"), ln
