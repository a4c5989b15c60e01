"""The curves of one file faired on several processes (``curvefair fair IN -o OUT``).

A drawing with thousands of entities or a font with hundreds of glyphs is many small, separate
:func:`curvefair.fair` calls: each takes milliseconds and holds the interpreter (numpy and
Python-level work between the compiled loops), so threads cannot share them; processes can.
Each call depends only on its curve and options and gives the same bits in any process (the
compiled kernels are the same code, their passes the same on one thread or two), so the file
written is byte for byte the one a single process writes.

A pool costs its start: every worker imports curvefair and loads its compiled kernels (about
1-1.5 s, measured in docs/benchmarks.md). The command therefore fairs the first curves itself
and starts the pool only when the rest, projected from the time those took, would take
:data:`MIN_SECONDS` or more and enough curves are left for every worker
(:func:`worth_a_pool`). Small files never start one.
"""

from __future__ import annotations

import concurrent.futures as cf
import multiprocessing as mp
import warnings
from collections.abc import Callable
from typing import Any

from ._threads import cpu_count
from .errors import CurvefairError

__all__ = ["PROBE_SECONDS", "MIN_SECONDS", "MIN_PER_WORKER", "default_workers", "worth_a_pool",
           "fair_record", "Pool"]

#: the command fairs curves itself for at least this long before it considers a pool
PROBE_SECONDS = 1.0
#: the projected time of the curves left from which a pool is started (its workers' start,
#: 1-1.5 s each and side by side, is then a small part of what they save)
MIN_SECONDS = 4.0
#: curves left per worker, at least, for a pool to be started
MIN_PER_WORKER = 4


def default_workers() -> int:
    """Worker processes for one file's curves: the CPUs this process may run on."""
    return max(1, cpu_count())


def worth_a_pool(elapsed: float, done: int, left: int, workers: int) -> bool:
    """Whether the ``left`` curves should go to a pool of ``workers`` processes, after ``done``
    curves took ``elapsed`` seconds here: only with two workers or more, after
    :data:`PROBE_SECONDS`, with :data:`MIN_PER_WORKER` curves per worker left and the rest
    projected to take :data:`MIN_SECONDS` or more."""
    if workers < 2 or done < 1 or elapsed < PROBE_SECONDS or left < MIN_PER_WORKER * workers:
        return False
    return elapsed / done * left >= MIN_SECONDS


def fair_record(curve: Any, method: str | None, kwargs: dict[str, Any]
                ) -> tuple[str, Any, list[tuple[type[Warning], str]]]:
    """One curve faired in a worker: ``(status, value, warnings)``. ``status`` ``"ok"``
    (``value`` the :class:`~curvefair.FairingResult`), ``"failed"`` (a curvefair error:
    ``value`` its message, as the command reports it) or ``"crashed"`` (any other exception:
    the calling process fairs the curve again itself, so that the error surfaces there as it
    would without a pool). ``warnings``: the category and message of every warning raised, for
    the calling process to show as its own."""
    from . import fair

    value: Any
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            res = fair(curve, method, **kwargs)
        except CurvefairError as exc:
            status, value = "failed", str(exc)
        except Exception:  # noqa: BLE001 - redone in the calling process, which reports it
            status, value = "crashed", None
        else:
            status, value = "ok", res
    return status, value, [(w.category, str(w.message)) for w in caught]


class Pool:
    """A process pool (``spawn``: no fork of a process with threads) for
    :func:`fair_record`; :meth:`submit` returns a function that gives the task's result,
    running the task in this process if the pool has broken (a worker died)."""

    def __init__(self, workers: int) -> None:
        self._pool = cf.ProcessPoolExecutor(max_workers=workers,
                                            mp_context=mp.get_context("spawn"))
        self.redone = 0  # tasks run in this process after the pool broke

    def submit(self, curve: Any, method: str | None, kwargs: dict[str, Any]
               ) -> Callable[[], tuple[str, Any, list[tuple[type[Warning], str]]]]:
        try:
            fut = self._pool.submit(fair_record, curve, method, kwargs)
        except cf.process.BrokenProcessPool:
            fut = None

        def result() -> tuple[str, Any, list[tuple[type[Warning], str]]]:
            if fut is not None:
                try:
                    return fut.result()
                except cf.process.BrokenProcessPool:
                    pass
            self.redone += 1
            return fair_record(curve, method, kwargs)
        return result

    def close(self) -> None:
        self._pool.shutdown(wait=True, cancel_futures=True)
