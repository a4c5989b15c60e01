"""fair() gives the recorded results on a fixed set of cases (issue 15: the redesign of the
fair() -> method contract must not change what the methods compute).

tests/data/recorded_cases.py lists the cases (every registered method on cubic and quintic
Hermite curves and B-splines of degree 3-5, open and closed, 2-D and 3-D, under a rotating
choice of tol, eps, max_steps, clamp, protect and mode) and records them into
tests/data/recorded_cases.npz: the faired curve's arrays, steps, stop_reason, the history and
every report figure but the time.

Comparison: integers, strings and flags exactly; float64 figures within ``1e-12`` relative
(to each entry and to the array's largest entry), plus ``1e-14`` absolute for the curves'
arrays and ``1e-9`` for report figures (a smooth spline's knot jumps are rounding noise of
~1e-12; the curves are of unit size), so that the test holds on a CPU whose SIMD width changes
the last bits (CI's second instruction set); the index of the largest move may differ between
points that moved equally far. ``CURVEFAIR_RECORDED_EXACT=1`` compares the floats bit for
bit: on the machine that recorded them, the results must be identical.

Regenerating the fixture (``PYTHONPATH=src python tests/data/recorded_cases.py [CASE ...]``)
is allowed only for a documented change of meaning, named with the cases it changes in
CHANGELOG.md; never to make this test pass after a refactoring.
"""

from __future__ import annotations

import importlib.util
import os
from pathlib import Path

import numpy as np
import pytest

_spec = importlib.util.spec_from_file_location(
    "recorded_cases", Path(__file__).with_name("data") / "recorded_cases.py")
assert _spec is not None and _spec.loader is not None
rc = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(rc)

EXACT = os.environ.get("CURVEFAIR_RECORDED_EXACT", "") == "1"
RTOL, ATOL = 1e-12, 1e-14
#: report figures at rounding level: e.g. the largest knot jump of a B-spline that is smooth
#: there (~2e-12 on these unit-size curves) is pure rounding and changes by a few percent with
#: the SIMD width (seen under CI's second instruction set); below this they are compared as
#: "rounding-level", not digit by digit
REPORT_ATOL = 1e-9

_RECORDED = rc.load()
_CASES = rc.cases()
_CURVES: dict[str, object] = {}


def test_fixture_covers_every_case():
    assert [c[0] for c in _CASES] == list(_RECORDED)
    methods = {c[2] for c in _CASES}
    from curvefair.fairing import available_methods
    assert methods == set(available_methods())  # every registered method is recorded
    # most cases run (a refusal records only the error class)
    assert sum("error" not in r["meta"] for r in _RECORDED.values()) > 0.8 * len(_RECORDED)


def _close(name: str, got: np.ndarray, want: np.ndarray, where: str,
           atol: float = ATOL) -> None:
    assert got.shape == want.shape, f"{where}: {name} shape {got.shape} != {want.shape}"
    if got.dtype.kind in "iu" or EXACT:
        same = (got.view(np.uint8) == want.view(np.uint8)).all() if got.dtype == want.dtype \
            else np.array_equal(got, want)
        if not same:
            bad = np.flatnonzero(got.reshape(-1) != want.reshape(-1))
            raise AssertionError(f"{where}: {name} differs at {bad[:5].tolist()}: "
                                 f"{got.reshape(-1)[bad[:3]]} != {want.reshape(-1)[bad[:3]]}")
        return
    g, w = got.reshape(-1), want.reshape(-1)
    err = np.abs(g - w)
    # relative to each entry and to the array's own scale (a small second derivative next to
    # large ones carries the rounding of the large ones: seen under CI's second instruction set)
    scale = float(np.abs(w).max()) if w.size else 0.0
    lim = RTOL * (np.abs(w) + scale) + atol
    bad = np.flatnonzero(~(err <= lim))
    assert bad.size == 0, (f"{where}: {name} differs beyond {RTOL:g} relative at "
                           f"{bad[:5].tolist()}: {g[bad[:3]]} != {w[bad[:3]]}")


@pytest.mark.parametrize("cid,cname,method,options", _CASES, ids=[c[0] for c in _CASES])
def test_recorded_case(cid, cname, method, options):
    if not _CURVES:
        _CURVES.update(rc.curves())
    want = _RECORDED[cid]
    got = rc.run_case(cname, method, options, _CURVES)
    where = f"{cid} {options}"
    if "error" in want["meta"] or "error" in got["meta"]:
        assert got["meta"].get("error") == want["meta"].get("error"), where
        return
    # integers, strings, flags, lists of them: exactly (stop_reason, steps, counts, clamp ...)
    gr, wr = got["meta"]["report"], want["meta"]["report"]
    missing = sorted(set(wr) - set(gr))
    assert not missing, f"{where}: report entries gone: {missing}"
    diff = {k: (gr[k], wr[k]) for k in wr if gr[k] != wr[k]}
    if "max_point_index" in diff:
        # the arg max of the moves: two points moved equally far (a closed curve's seam, or a
        # rounding-level tie) may swap places on another CPU; both must be a largest move
        pts = np.asarray(want["arrays"].get("curve.points",
                                             want["arrays"].get("curve.control_points")))
        c0 = rc.curve_arrays(_CURVES[cname])
        p0 = c0.get("points", c0.get("control_points"))
        d = np.linalg.norm(pts - np.asarray(p0)[:len(pts)], axis=1)
        if all(d[i] >= d.max() * (1 - 1e-9) for i in diff["max_point_index"]):
            del diff["max_point_index"]
    assert not diff, f"{where}: report entries differ (got, recorded): {diff}"
    # float figures by name (entries added since the recording are not compared)
    gnames, wnames = got["meta"]["float_names"], want["meta"]["float_names"]
    gone = sorted(set(wnames) - set(gnames))
    assert not gone, f"{where}: report figures gone: {gone}"
    gpos = {n: i for i, n in enumerate(gnames)}
    gf = got["arrays"]["report.floats"][[gpos[n] for n in wnames]]
    wf = want["arrays"]["report.floats"]
    for i, n in enumerate(wnames):
        _close(f"report[{n!r}]", gf[i:i + 1], wf[i:i + 1], where, REPORT_ATOL)
    for name, w in want["arrays"].items():
        if name != "report.floats":
            assert name in got["arrays"], f"{where}: {name} missing"
            _close(name, got["arrays"][name], w, where)
