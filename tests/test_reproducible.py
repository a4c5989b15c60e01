"""Same answer on any machine: bitwise run to run, across instruction sets to a stated tolerance.

A recorded set of cases (every method, planar and 3-D, open and closed, with a tolerance) is run
in fresh interpreters. Run to run on one machine the results are bitwise equal.

Across instruction sets (CI runs the compiled-loop tests again with ``NUMBA_CPU_NAME=generic``
and numpy's wide SIMD paths disabled, see ``.ci/run``): that run compares its results with those
of a fresh interpreter without those settings. The stated tolerance:
the same step counts and stop reasons, and every coordinate within ``ISA_RTOL`` of the curve's
coordinate scale. (Compiled kernels are scalar code in a fixed operation order, without
fast-math, so they round alike on any x86-64; what may differ is numpy's and LAPACK's SIMD
kernels inside the interpolation and set-up solves, at the level of a few ulps.)
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

#: coordinates agree across instruction sets to this fraction of the coordinate scale
ISA_RTOL = 1e-9

CASES = r'''
import json, sys
import numpy as np
import curvefair as cf

def noisy(n, dim, closed, seed):
    rng = np.random.default_rng(seed)
    th = np.linspace(0, 2 * np.pi, n, endpoint=not closed)
    p = np.c_[np.cos(th), 0.6 * np.sin(th)] if closed else np.c_[th, np.sin(th)]
    if dim == 3:
        p = np.c_[p, 0.3 * np.sin(2 * th)]
    return p + 0.01 * rng.normal(size=p.shape)

out = {}
for dim in (2, 3):
    for closed in (False, True):
        pts = noisy(60, dim, closed, 10 * dim + closed)
        cub = cf.interpolate_cubic(pts, bc="periodic" if closed else "natural")
        qui = cf.interpolate_quintic(pts, bc="periodic" if closed else "natural")
        bsp = cf.interpolate_bspline(pts, closed=closed)
        uni = cf.interpolate_cubic(pts, param="uniform", bc="periodic" if closed else "natural")
        runs = [("kjellander", uni, {}), ("poliakoff", cub, {}), ("wang-cao", cub, {}),
                ("wang-quintic", qui, {}), ("eck-hadenfeld", bsp, {"schedule": "ranking"}),
                ("eck-hadenfeld", bsp, {"schedule": "sweep"}), ("knot-removal", bsp, {}),
                ("cheng-yu", bsp, {}), ("global", bsp, {})]
        for method, curve, kw in runs:
            res = cf.fair(curve, method, tol=0.02, **kw)
            c = res.curve
            pts_out = c.control_points if hasattr(c, "control_points") else c.points
            key = f"{method}{kw.get('schedule', '')}-{dim}d-{'closed' if closed else 'open'}"
            out[key] = {"steps": int(res.report["steps"]),
                        "stop": str(res.report["stop_reason"]),
                        "points": np.asarray(pts_out).tolist(),
                        "hex": [float(x).hex() for x in np.asarray(pts_out).ravel()]}
json.dump(out, sys.stdout)
'''


def _run_cases(env_extra: dict[str, str] | None = None) -> dict:
    env = dict(os.environ)
    env.update(env_extra or {})
    proc = subprocess.run([sys.executable, "-c", CASES], capture_output=True, text=True,
                          env=env, timeout=1200)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout)


@pytest.fixture(scope="module")
def first_run() -> dict:
    return _run_cases()


def test_bitwise_run_to_run(first_run):
    second = _run_cases()
    assert first_run.keys() == second.keys()
    assert len(first_run) == 36
    for key, a in first_run.items():
        b = second[key]
        assert (a["steps"], a["stop"]) == (b["steps"], b["stop"]), key
        assert a["hex"] == b["hex"], key  # bitwise


def test_cases_do_work(first_run):
    # the recorded cases are not trivial: most methods take steps
    moved = [k for k, v in first_run.items() if v["steps"] > 0]
    assert len(moved) >= 30, sorted(set(first_run) - set(moved))


#: the settings that select another instruction set (and bounds checks) for numba and numpy
ISA_VARIABLES = ("NUMBA_CPU_NAME", "NUMBA_CPU_FEATURES", "NPY_DISABLE_CPU_FEATURES",
                 "NUMBA_BOUNDSCHECK")


def test_agrees_across_instruction_sets(first_run):
    if not any(os.environ.get(v) for v in ISA_VARIABLES):
        pytest.skip("runs under another instruction set only (CI: NUMBA_CPU_NAME=generic, "
                    "NPY_DISABLE_CPU_FEATURES; see .ci/run)")
    native_env = {k: v for k, v in os.environ.items() if k not in ISA_VARIABLES}
    env = dict(native_env)
    proc = subprocess.run([sys.executable, "-c", CASES], capture_output=True, text=True,
                          env=env, timeout=1200)
    assert proc.returncode == 0, proc.stderr
    native = json.loads(proc.stdout)
    assert native.keys() == first_run.keys()
    worst = 0.0
    for key, a in first_run.items():
        b = native[key]
        assert (a["steps"], a["stop"]) == (b["steps"], b["stop"]), key
        pa, pb = np.asarray(a["points"]), np.asarray(b["points"])
        scale = max(float(np.abs(pb).max()), 1.0)
        err = float(np.abs(pa - pb).max()) / scale
        worst = max(worst, err)
        assert err <= ISA_RTOL, (key, err)
    print(f"largest difference across instruction sets: {worst:.3g} of the coordinate scale")
