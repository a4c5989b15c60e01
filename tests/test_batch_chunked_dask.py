"""curvefair.batch.fair_chunked on a Dask LocalCluster of two worker processes (issue 17): a
point list of 20,000 rows in chunks of 5,000 gives the bytes of the one-process run with a
worker killed (SIGKILL) mid-run: it loses nothing (the scheduler reruns its chunk elsewhere; no
partial output, no temporary file). The outputs are compared as bytes and re-read with numpy;
the tolerance is checked per point on the re-read rows."""

from __future__ import annotations

import os
import signal
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from curvefair.batch import fair_chunked

distributed = pytest.importorskip("distributed")

TOL = 0.01
N, CHUNK = 20000, 5000


def _source(root: Path) -> tuple[Path, np.ndarray]:
    rng = np.random.default_rng(3)
    s = np.linspace(0.0, 8.0 * np.pi * N / 1000.0, N)
    P = np.c_[s, 3.0 * np.sin(s)] + 0.003 * rng.standard_normal((N, 2))
    src = root / "big.csv"
    np.savetxt(src, P, delimiter=",")
    return src, P


@pytest.mark.slow
def test_local_cluster_same_bytes_and_a_killed_worker_loses_nothing(tmp_path: Path,
                                                                    monkeypatch):
    src, P = _source(tmp_path)
    ref = fair_chunked(src, tmp_path / "ref.csv", tol=TOL, chunk=CHUNK, jobs=1)
    assert ref["n_chunks"] == 4
    Q = np.loadtxt(tmp_path / "ref.csv", delimiter=",")
    assert np.linalg.norm(Q - P, axis=1).max() <= TOL
    monkeypatch.setenv("CURVEFAIR_TEST_FILE_DELAY", "1.0")  # each chunk: caught running
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        client.wait_for_workers(2, timeout=120)
        # one run on the cluster, a worker killed while it fairs a chunk: the other chunks
        # went the normal way, the killed one was rerun elsewhere; all bytes as in one process
        pids = client.run(os.getpid)
        result: dict[str, object] = {}
        th = threading.Thread(target=lambda: result.update(fair_chunked(
            src, tmp_path / "killed.csv", tol=TOL, chunk=CHUNK, client=client)))
        th.start()
        victim = None
        deadline = time.time() + 60
        while victim is None and time.time() < deadline:
            busy = [w for w, tasks in client.processing().items() if tasks]
            if busy:
                time.sleep(0.4)  # inside the chunk's delay: the chunk is being worked on
                victim = busy[0]
            else:
                time.sleep(0.02)
        assert victim is not None
        os.kill(pids[victim], signal.SIGKILL)
        th.join(timeout=240)
        assert not th.is_alive()
        assert pids[victim] not in client.run(os.getpid).values()  # it really died
    assert result["n_chunks"] == 4
    assert (tmp_path / "killed.csv").read_bytes() == (tmp_path / "ref.csv").read_bytes()
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []
