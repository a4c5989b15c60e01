"""``curvefair fair`` on a file with many curves: the curves left after the first ones go to a
pool of processes (``curvefair._records``), and the file written is the one a single process
writes.

The pool's thresholds (``PROBE_SECONDS``, ``MIN_SECONDS``, ``MIN_PER_WORKER``) are set to
zero here so that a small file (fast to fair) takes the pool path; the command runs
in-process (``CliRunner``) so that the patched thresholds apply, its workers are real
spawned processes. Geometry is compared entity by entity with ezdxf (the written files differ
only in ezdxf's time stamps and GUIDs), the report row by row.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from curvefair import _records
from curvefair.cli import main

TOL = 0.01


def _drawing(path: Path, n: int, seed: int = 3) -> None:
    """``n`` entities, alternately a cubic SPLINE by control points and a noisy LWPOLYLINE
    (read as point data with --polylines), as ``benchmarks/bench_dxf_entities.py``."""
    import ezdxf

    rng = np.random.default_rng(seed)
    doc = ezdxf.new("R2010")
    msp = doc.modelspace()
    for k in range(n):
        x0 = 30.0 * k
        if k % 2 == 0:
            a = np.linspace(0.0, 2.5, 12)
            P = np.c_[x0 + 10 * np.cos(a), 10 * np.sin(a)] + 0.05 * rng.normal(size=(12, 2))
            knots = np.r_[[0.0] * 4, np.arange(1.0, 9.0), [9.0] * 4]
            msp.add_open_spline([tuple(p) for p in P], degree=3, knots=knots.tolist())
        else:
            t = np.linspace(0.0, 20.0, 25)
            P = np.c_[x0 + t, np.sin(t / 3) * 4] + 0.02 * rng.normal(size=(25, 2))
            msp.add_lwpolyline([tuple(p) for p in P])
    doc.saveas(path)


def _entities(path: Path) -> list[tuple[str, np.ndarray]]:
    import ezdxf

    out = []
    for e in ezdxf.readfile(path).modelspace():
        if e.dxftype() == "SPLINE":
            out.append(("SPLINE", np.asarray(e.control_points, dtype=float)))
        elif e.dxftype() == "LWPOLYLINE":
            out.append(("LWPOLYLINE", np.asarray(e.get_points("xy"), dtype=float)))
    return out


def _rows(path: Path) -> list[dict]:
    rows = json.loads(path.read_text())["curves"]
    for r in rows:  # the times differ from run to run
        r.get("report", {}).pop("time_s", None)
    return rows


def _run(args: list[str]) -> None:
    res = CliRunner().invoke(main, args)
    assert res.exit_code == 0, (res.output, res.exception)


@pytest.fixture
def eager_pool(monkeypatch: pytest.MonkeyPatch) -> list[_records.Pool]:
    """Thresholds at zero (the pool starts after the first curve) and the pools started."""
    monkeypatch.setattr(_records, "PROBE_SECONDS", 0.0)
    monkeypatch.setattr(_records, "MIN_SECONDS", 0.0)
    monkeypatch.setattr(_records, "MIN_PER_WORKER", 1)
    started: list[_records.Pool] = []
    orig = _records.Pool.__init__

    def init(self: _records.Pool, workers: int) -> None:
        started.append(self)
        self.workers = workers
        orig(self, workers)
    monkeypatch.setattr(_records.Pool, "__init__", init)
    return started


def test_curves_on_a_pool_write_the_same_file(tmp_path: Path,
                                              eager_pool: list[_records.Pool]):
    src = tmp_path / "in.dxf"
    _drawing(src, 10)
    common = ["fair", str(src), "--tol", str(TOL), "--polylines", "-q"]
    _run(common + ["-o", str(tmp_path / "one.dxf"), "--report", str(tmp_path / "one.json"),
                   "--jobs", "1"])
    assert eager_pool == []  # one process asked for: no pool
    _run(common + ["-o", str(tmp_path / "two.dxf"), "--report", str(tmp_path / "two.json"),
                   "--jobs", "2"])
    # --jobs 2: one worker beside this process, which took curves from the end (none redone
    # here after a broken pool)
    assert [(p.workers, p.redone) for p in eager_pool] == [(1, 0)]
    assert 0 <= eager_pool[0].here < 9
    one, two = _entities(tmp_path / "one.dxf"), _entities(tmp_path / "two.dxf")
    assert [k for k, _ in one] == [k for k, _ in two] == ["SPLINE", "LWPOLYLINE"] * 5
    for (_, a), (_, b) in zip(one, two, strict=True):
        assert np.array_equal(a, b)
    # every curve was faired (moved) and is within tol of the input, as written
    src_e = _entities(src)
    for (_, a), (_, b) in zip(src_e, two, strict=True):
        d = np.linalg.norm(a - b, axis=1)
        assert 0 < d.max() <= TOL
    assert _rows(tmp_path / "one.json") == _rows(tmp_path / "two.json")


def test_failures_in_the_pool_are_reported_per_curve(tmp_path: Path,
                                                     eager_pool: list[_records.Pool]):
    # global takes B-splines only: the polylines (point data) fail, in the pool as here, and
    # are written back unchanged; the splines are faired
    src = tmp_path / "in.dxf"
    _drawing(src, 8)
    common = ["fair", str(src), "--tol", str(TOL), "--polylines", "-q", "--method", "global"]
    runs = {}
    for j in ("1", "2"):
        res = CliRunner().invoke(main, common + ["-o", str(tmp_path / f"o{j}.dxf"),
                                                 "--report", str(tmp_path / f"r{j}.json"),
                                                 "--jobs", j])
        runs[j] = res
    assert [(p.workers, p.redone) for p in eager_pool] == [(1, 0)]
    assert runs["1"].exit_code == runs["2"].exit_code == 1
    r1, r2 = _rows(tmp_path / "r1.json"), _rows(tmp_path / "r2.json")
    assert r1 == r2
    assert [r["status"] for r in r2] == ["ok", "failed"] * 4
    assert all("global" in r["error"] for r in r2 if r["status"] == "failed")
    one, two = _entities(tmp_path / "o1.dxf"), _entities(tmp_path / "o2.dxf")
    for (_, a), (_, b) in zip(one, two, strict=True):
        assert np.array_equal(a, b)
    for k, ((_, b), (_, s)) in enumerate(zip(two, _entities(src), strict=True)):
        assert np.array_equal(b, s) == (k % 2 == 1)  # failed polylines written as read


def test_worker_reports_warnings_and_errors():
    import warnings

    import curvefair as cf

    P = np.c_[np.linspace(0, 1, 30), np.sin(np.linspace(0, 3, 30))]
    c = cf.interpolate_bspline(P)
    status, res, caught = _records.fair_record(c, None, {"tol": TOL})
    assert status == "ok" and res.curve.n_ctrl == c.n_ctrl and caught == []
    status, msg, _ = _records.fair_record(c, "no-such-method", {"tol": TOL})
    assert status == "failed" and "no-such-method" in msg
    status, value, _ = _records.fair_record(c, None, {"tol": TOL, "no_such_option": 1})
    assert status == "failed" and "no_such_option" in value

    orig = cf.fair

    def warn_then_fair(curve, method=None, **kw):
        warnings.warn("a note from fair", UserWarning, stacklevel=1)
        return orig(curve, method, **kw)
    try:
        cf.fair = warn_then_fair
        status, _, caught = _records.fair_record(c, None, {"tol": TOL})
    finally:
        cf.fair = orig
    assert status == "ok" and caught == [(UserWarning, "a note from fair")]

    def broken_fair(curve, method=None, **kw):
        raise RuntimeError("a bug")
    try:
        cf.fair = broken_fair
        status, value, _ = _records.fair_record(c, None, {"tol": TOL})
    finally:
        cf.fair = orig
    assert (status, value) == ("crashed", None)  # the command then refairs it itself


@pytest.mark.parametrize("elapsed,done,left,workers,want", [
    (2.0, 100, 1000, 2, True),     # 20 ms a curve, 1000 left: 20 s
    (2.0, 100, 150, 2, False),     # 3 s left: the pool's start would eat the gain
    (0.5, 30, 1000, 2, False),     # still probing
    (2.0, 100, 1000, 1, False),    # one worker: no pool
    (2.0, 1, 7, 2, False),         # 28 s left but only 7 curves: fewer than 4 a worker
    (2.0, 1, 8, 2, True),
])
def test_when_a_pool_is_worth_it(elapsed, done, left, workers, want):
    assert _records.worth_a_pool(elapsed, done, left, workers) is want


def test_tasks_taken_back_from_the_pool_give_the_workers_results():
    # one worker: the pool queues at most two tasks ahead (running), so of six submitted at
    # once this process takes the last four at least; every outcome as fair_record's here
    import curvefair as cf

    rng = np.random.default_rng(8)
    curves = [cf.interpolate_bspline(np.c_[np.linspace(0, 4, 25), np.sin(np.linspace(0, 4, 25))]
                                     + 0.01 * rng.normal(size=(25, 2))) for _ in range(6)]
    pool = _records.Pool(1)
    try:
        tasks = [pool.submit(c, None, {"tol": TOL}) for c in curves]
        taken = 0
        for t in reversed(tasks):
            if not t.take():
                break
            taken += 1
        got = [t.result() for t in tasks]
    finally:
        pool.close()
    assert taken >= 4 and pool.here == taken and pool.redone == 0
    for c, (status, res, caught) in zip(curves, got, strict=True):
        ref = _records.fair_record(c, None, {"tol": TOL})
        assert status == ref[0] == "ok" and caught == []
        assert np.array_equal(res.curve.control_points, ref[1].curve.control_points)


_KILLED_PARENT = r"""
import os, signal, sys, time
import numpy as np
import curvefair as cf
from curvefair import _records

if __name__ == "__main__":
    pool = _records.Pool(2)
    c = cf.interpolate_bspline(np.c_[np.linspace(0, 4, 30), np.sin(np.linspace(0, 4, 30))])
    tasks = [pool.submit(c, None, {"tol": 0.01}) for _ in range(4)]
    tasks[0].result()  # the workers are up
    print(" ".join(str(p) for p in pool._pool._processes), flush=True)
    os.kill(os.getpid(), signal.SIGKILL)  # no finally, no atexit: the workers are orphans
"""


def test_workers_exit_when_the_command_is_killed(tmp_path: Path):
    """A command killed outright (SIGKILL, or SIGTERM's default action) runs no ``finally``:
    its pool's workers would wait on their queue forever. They watch their parent and exit."""
    import os
    import signal
    import subprocess
    import sys
    import time

    if not hasattr(signal, "SIGKILL"):
        pytest.skip("no SIGKILL here")
    script = tmp_path / "killed.py"
    script.write_text(_KILLED_PARENT)
    # output to files, not pipes: orphans holding a pipe would keep run() waiting
    out, err = tmp_path / "out.txt", tmp_path / "err.txt"
    with open(out, "w") as fo, open(err, "w") as fe:
        p = subprocess.run([sys.executable, str(script)], stdout=fo, stderr=fe, timeout=300)
    assert p.returncode == -signal.SIGKILL, err.read_text()
    pids = [int(x) for x in out.read_text().split()]
    assert len(pids) == 2

    def alive(pid: int) -> bool:
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return False
        # a zombie (exited, not yet reaped by init) counts as gone
        try:
            with open(f"/proc/{pid}/stat") as f:
                return f.read().split(") ")[1][0] != "Z"
        except OSError:
            return True
    deadline = time.monotonic() + 20.0
    while any(alive(pid) for pid in pids) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert not any(alive(pid) for pid in pids)
