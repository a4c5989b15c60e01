"""curvefair.batch.fair_files and `curvefair fair --scheduler` on a Dask LocalCluster of two
worker processes: the bytes of the one-process run, and a worker killed (SIGKILL) mid-run
loses nothing (its file is redone elsewhere, no partial or temporary file is left)."""

from __future__ import annotations

import json
import os
import signal
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from curvefair import interpolate_bspline, write_curves
from curvefair.batch import fair_files
from curvefair.cli import main

distributed = pytest.importorskip("distributed")

TOL = 0.05
N_FILES = 6


def _inputs(root: Path) -> Path:
    src = root / "in"
    src.mkdir()
    for k in range(N_FILES):
        rng = np.random.default_rng(k)
        x = np.linspace(0.0, 10.0, 40)
        p = np.c_[x, np.sin(x / 2.0) + 0.02 * rng.standard_normal(40)]
        write_curves(src / f"w{k}.json", [interpolate_bspline(p)])
    return src


def _outputs(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in folder.glob("w*.json")}


def _leftovers(folder: Path) -> list[Path]:
    return [p for p in folder.rglob(".*") if p.is_file()]


@pytest.mark.slow
def test_local_cluster_same_bytes_and_a_killed_worker_loses_nothing(tmp_path: Path,
                                                                    monkeypatch):
    src = _inputs(tmp_path)
    ref = fair_files([str(src)], tmp_path / "ref", jobs=1, tol=TOL)
    assert ref["n_ok"] == N_FILES
    # workers inherit the environment: each file sleeps before its write, long enough for
    # the kill below to land while a file is being worked on
    monkeypatch.setenv("CURVEFAIR_TEST_FILE_DELAY", "0.8")
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        client.wait_for_workers(2, timeout=120)
        run = fair_files([str(src)], tmp_path / "dask", client=client, tol=TOL)
        assert run["n_ok"] == N_FILES and run["n_failed"] == 0
        assert run["scheduler"] == cluster.scheduler_address  # the run report says where
        assert _outputs(tmp_path / "dask") == _outputs(tmp_path / "ref")
        r = CliRunner().invoke(main, ["fair", str(src), "-o", str(tmp_path / "cli"), "--tol",
                                      str(TOL), "--scheduler", cluster.scheduler_address,
                                      "-q"], catch_exceptions=False)
        assert r.exit_code == 0, r.output
        assert _outputs(tmp_path / "cli") == _outputs(tmp_path / "ref")

        pids_before = client.run(os.getpid)
        result: dict[str, object] = {}
        th = threading.Thread(target=lambda: result.update(fair_files(
            [str(src)], tmp_path / "killed", client=client, tol=TOL)))
        th.start()
        victim = None
        deadline = time.time() + 60
        while victim is None and time.time() < deadline:
            busy = [w for w, tasks in client.processing().items() if tasks]
            if busy:
                time.sleep(0.3)  # inside the task's sleep: the file is being worked on
                victim = busy[0]
            else:
                time.sleep(0.02)
        assert victim is not None
        os.kill(pids_before[victim], signal.SIGKILL)
        th.join(timeout=180)
        assert not th.is_alive()
        pids_after = client.run(os.getpid)
        assert pids_before[victim] not in pids_after.values()  # the worker really died
    assert result["n_ok"] == N_FILES and result["n_failed"] == 0, result
    assert _outputs(tmp_path / "killed") == _outputs(tmp_path / "ref")
    assert _leftovers(tmp_path / "killed") == []
    reports = sorted((tmp_path / "killed/.curvefair").glob("w*.json.json"))
    assert len(reports) == N_FILES
    assert all(json.loads(p.read_text())["status"] == "ok" for p in reports)
