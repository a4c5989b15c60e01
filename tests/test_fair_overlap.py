"""fair() analyses a long input on the worker thread while the join plan and the method run
(``curvefair.fairing.fair._start_analysis``, ``curvefair._threads.Background``), and every
kernel releases the GIL so that the two really run at once.

What must hold: the result and the whole report are bitwise those of the sequential call (the
analysis first, then the method) for every method, open and closed, planar and 3-D; the
lean analysis the job runs gives the figures of the full one; an error of the analysis is the
one raised, as when it ran first; a method asking for its input's figures meanwhile waits for
the job instead of analysing the curve again; a busy worker never holds the call up.
"""

from __future__ import annotations

import sys
import threading
import time

import numpy as np
import pytest

import curvefair as cf
from curvefair import _threads
from curvefair.analysis import analyze, fairness_figures

F = sys.modules["curvefair.fairing.fair"]  # (curvefair.fairing.fair is also the function)

FIGURES = ("energy2", "energy3", "max_jump", "max_top_jump", "sapidis_sum", "dkds_energy",
           "inflections", "extrema")


def _noisy(n, dim=2, closed=False, seed=3):
    rng = np.random.default_rng(seed)
    if closed:
        a = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
        P = np.c_[np.cos(a) * 10, np.sin(a) * 6] + 0.02 * rng.normal(size=(n, 2))
    else:
        t = np.linspace(0.0, 30.0, n)
        P = np.c_[t, 3.0 * np.sin(t / 2.0)] + 0.02 * rng.normal(size=(n, 2))
    if dim == 3:
        P = np.c_[P, 0.5 * np.cos(np.linspace(0.0, 9.0, n))]
    return P


def _curve(kind, n, dim=2, closed=False):
    P = _noisy(n, dim, closed)
    if kind == "bspline":
        return cf.interpolate_bspline(P, closed=closed)
    if kind == "quintic":
        return cf.interpolate_quintic(P)
    if kind == "uniform":
        return cf.interpolate_cubic(P, "uniform")
    return cf.interpolate_cubic(P, "chord", "periodic" if closed else "natural")


def _bits(res):
    rep = res.report.to_dict()
    rep.pop("time_s", None)
    rep.pop("driver_time_s", None)
    data = res.curve.control_points if hasattr(res.curve, "control_points") else res.curve.points
    return repr(rep), np.asarray(data).tobytes()


CASES = [
    ("bspline", "eck-hadenfeld", 2, False, {}),
    ("bspline", "global", 2, False, {}),
    ("bspline", "knot-removal", 2, True, {}),
    ("bspline", "eck-hadenfeld", 3, False, {}),
    ("bspline", "cheng-yu", 2, False, {"max_steps": 300}),
    ("bspline", None, 2, True, {}),
    ("uniform", "kjellander", 2, False, {"max_steps": 200}),
    ("cubic", "poliakoff", 3, False, {"max_steps": 200}),
    ("cubic", "wang-cao", 2, True, {"max_steps": 200}),
    ("quintic", "wang-quintic", 2, False, {"max_steps": 200}),
    ("cubic", "points-l1", 2, False, {}),
]


@pytest.mark.parametrize("kind,method,dim,closed,kw", CASES,
                         ids=[f"{c[1]}-{c[2]}d-{'closed' if c[3] else 'open'}" for c in CASES])
def test_overlapped_call_is_bitwise_the_sequential_one(monkeypatch, kind, method, dim, closed,
                                                       kw):
    """The same curve and report (floats as repr, times aside) whether the input's analysis
    ran before the method (OVERLAP_MIN out of reach) or beside it on the worker thread; the
    job is checked to have run on the worker."""
    monkeypatch.setattr(F, "OVERLAP_MIN", 10**12)
    ref = _bits(cf.fair(_curve(kind, 400, dim, closed), method, tol=0.05, **kw))
    c = _curve(kind, 400, dim, closed)  # a fresh object: no memo of the first call's figures
    where = []
    started = threading.Event()
    inner, start = F._memo_analysis_block, F._start_analysis

    def spy(curve, lean=None):
        if curve is c:
            where.append((threading.current_thread().name, lean))
            started.set()
        return inner(curve, lean)

    def start_and_wait(curve, beside=True):  # the method starts once the job has started
        out = start(curve, beside)
        started.wait(10)
        return out

    monkeypatch.setattr(F, "_memo_analysis_block", spy)
    monkeypatch.setattr(F, "_start_analysis", start_and_wait)
    monkeypatch.setattr(F, "OVERLAP_MIN", 100)
    monkeypatch.setattr(_threads, "THREADS", 2)
    got = cf.fair(c, method, tol=0.05, **kw)
    assert _bits(got) == ref
    if (dim == 3 and kind == "bspline") or F.METHODS[got.report["method"]].two_threads:
        # (excluded: analysed first, on the calling thread)
        assert where == [("MainThread", None)]
    else:
        assert where and where[0][0].startswith("curvefair") and where[0][1] is True


def test_long_curves_are_analysed_first(monkeypatch):
    """From RESCAN_MIN segments on (where the analysis is lean because memory limits the
    call) the input is analysed before the method, on the calling thread, as are short
    curves (below OVERLAP_MIN) and everything with one thread."""
    from curvefair.analysis import _sampling

    where = []
    inner = F._memo_analysis_block

    def spy(curve, lean=None):
        where.append((threading.current_thread().name, lean))
        return inner(curve, lean)

    monkeypatch.setattr(F, "_memo_analysis_block", spy)
    monkeypatch.setattr(_threads, "THREADS", 2)
    monkeypatch.setattr(F, "OVERLAP_MIN", 100)
    m = len(_curve("bspline", 400).control_points)  # (what the limits count)
    for rescan_min, threads, n, beside in ((10**9, 2, 400, True), (m, 2, 400, False),
                                           (m + 1, 2, 400, True), (10**9, 2, 97, False),
                                           (10**9, 1, 400, False)):
        monkeypatch.setattr(_sampling, "RESCAN_MIN", rescan_min)
        monkeypatch.setattr(_threads, "THREADS", threads)
        where.clear()
        cf.fair(_curve("bspline", n), "eck-hadenfeld", tol=0.05)
        assert len(where) == 2  # (the input's, then the result's)
        if beside:  # the job (the worker's, or the caller's if the worker had not begun)
            assert where[0][1] is True
        else:
            assert where[0] == ("MainThread", None)


@pytest.mark.parametrize("kind,dim,closed", [("bspline", 2, False), ("bspline", 2, True),
                                             ("bspline", 3, False), ("cubic", 2, False),
                                             ("cubic", 3, True), ("quintic", 2, False)])
def test_lean_figures_are_the_full_analysis_figures(kind, dim, closed):
    """``fairness_figures(lean=True)`` (no samples kept, each block's signs counted as it is
    made) gives bitwise ``analyze()``'s figures at a size far below RESCAN_MIN; so does
    ``lean=False``."""
    if kind == "quintic" and closed:
        pytest.skip("no closed quintic interpolation")
    c = _curve(kind, 3000, dim, closed)
    a = analyze(c)
    ref = {k: getattr(a, k) for k in FIGURES}
    for lean in (True, False, None):
        got = fairness_figures(c, lean=lean)
        assert {k: got[k] for k in FIGURES} == ref
    assert ref["extrema"] > 10


def test_analysis_error_is_the_one_raised(monkeypatch):
    """An error of the input's analysis wins over the method's, as when it ran first."""
    monkeypatch.setattr(F, "OVERLAP_MIN", 100)
    monkeypatch.setattr(_threads, "THREADS", 2)

    class Boom(cf.CurvefairError):
        pass

    def fail(curve, lean=None):
        raise Boom("analysis failed")

    monkeypatch.setattr(F, "_memo_analysis_block", fail)
    c = _curve("cubic", 400)  # non-uniform parameters: kjellander refuses them in its set-up
    with pytest.raises(Boom):
        cf.fair(c, "kjellander", tol=0.05)
    with pytest.raises(Boom):
        cf.fair(c, "poliakoff", tol=0.05, max_steps=50)
    monkeypatch.undo()
    with pytest.raises(cf.InputError, match="uniformly spaced"):
        cf.fair(c, "kjellander", tol=0.05)


def test_method_asking_for_its_inputs_figures_waits_for_the_job(monkeypatch):
    """points-l1 reads its input's figures during the run: with the job pending it waits for
    it; the input is analysed once."""
    monkeypatch.setattr(F, "OVERLAP_MIN", 100)
    monkeypatch.setattr(_threads, "THREADS", 2)
    from curvefair.fairing import points_l1

    c = _curve("cubic", 600)
    count = []
    asking = threading.Event()
    inner, is_point_data = F._analysis_block_of, points_l1._is_natural_chord_interpolant

    def spy(curve, lean=None):
        if curve is c:
            count.append(threading.current_thread().name)
            asking.wait(60)  # still running when the method asks (after its solve)
        return inner(curve, lean)

    def before_asking(curve):  # (what points-l1 calls just before it reads a0)
        asking.set()
        return is_point_data(curve)

    monkeypatch.setattr(F, "_analysis_block_of", spy)
    monkeypatch.setattr(points_l1, "_is_natural_chord_interpolant", before_asking)
    res = cf.fair(c, "points-l1", tol=0.05)
    assert asking.is_set()
    assert len(count) == 1 and count[0].startswith("curvefair"), count
    assert res.report["steps"] >= 0
    assert c not in F._ANALYSIS_PENDING


def test_busy_worker_does_not_hold_the_call(monkeypatch):
    """With the worker thread busy the calling thread analyses the input itself when it needs
    the figures; the call gives the sequential call's bits and returns long before the
    worker is free."""
    c = _curve("bspline", 500)
    monkeypatch.setattr(F, "OVERLAP_MIN", 10**12)
    ref = _bits(cf.fair(c, "eck-hadenfeld", tol=0.05))
    monkeypatch.setattr(F, "OVERLAP_MIN", 100)
    monkeypatch.setattr(_threads, "THREADS", 2)
    gate = threading.Event()
    _threads.pool().submit(gate.wait, 60)
    try:
        t0 = time.perf_counter()
        got = _bits(cf.fair(_curve("bspline", 500), "eck-hadenfeld", tol=0.05))
        assert time.perf_counter() - t0 < 30
    finally:
        gate.set()
    assert got == ref


def test_background_runs_once_on_the_worker_or_the_caller():
    """Background: the value (or the exception) of one run of ``fn``; on the worker when it
    is free, on the calling thread when it is busy; inline when single-threaded."""
    names = []

    def job():
        names.append(threading.current_thread().name)
        return 42

    b = _threads.Background(job, threads=2)
    deadline = time.perf_counter() + 10
    while not names and time.perf_counter() < deadline:
        time.sleep(0.001)
    assert b.result() == 42 and b.result() == 42
    assert names == [names[0]] and names[0].startswith("curvefair")

    gate = threading.Event()
    _threads.pool().submit(gate.wait, 60)
    try:
        names.clear()
        b = _threads.Background(job, threads=2)
        assert b.result() == 42 and names == [threading.current_thread().name]
    finally:
        gate.set()
    _threads.pool().submit(lambda: None).result(timeout=10)  # the stale job found nothing
    assert len(names) == 1

    names.clear()
    b = _threads.Background(job, threads=1)
    time.sleep(0.05)
    assert names == []  # nothing started: runs in result()
    assert b.result() == 42 and names == [threading.current_thread().name]

    def bad():
        raise cf.InputError("no")

    b = _threads.Background(bad, threads=2)
    for _ in range(2):
        with pytest.raises(cf.InputError, match="no"):
            b.result()
