"""The curves of one file faired on several processes (``curvefair fair IN -o OUT``).

A drawing with thousands of entities or a font with hundreds of glyphs is many small, separate
:func:`curvefair.fair` calls: each takes milliseconds and holds the interpreter (numpy and
Python-level work between the compiled loops), so threads cannot share them; processes can.
Each call depends only on its curve and options and gives the same bits in any process (the
compiled kernels are the same code, their passes the same on one thread or two), so the curves
written are bit for bit those a single process writes.

A pool costs its start: every worker imports curvefair and loads its compiled kernels (about
1 s). The command therefore fairs the first curves itself and starts the pool only when the
rest, projected from the time those took, would take :data:`MIN_SECONDS` or more and enough
curves are left for every process (:func:`worth_a_pool`); small files never start one. With
``jobs`` processes asked for, the pool has ``jobs - 1`` workers and the calling process is the
last: while the workers start and then work from the front of the list, it takes curves from
the end (:meth:`Task.take`) until it meets one a worker has begun.
"""

from __future__ import annotations

import concurrent.futures as cf
import multiprocessing as mp
import os
import warnings
from typing import Any, cast

from ._threads import cpu_count
from .errors import CurvefairError

__all__ = ["PROBE_SECONDS", "MIN_SECONDS", "MIN_PER_WORKER", "default_workers", "worth_a_pool",
           "fair_record", "Task", "Pool"]

#: the command fairs curves itself for at least this long before it considers a pool
PROBE_SECONDS = 1.0
#: the projected time of the curves left from which a pool is started (its workers' start,
#: about 1 s each and side by side, is then a small part of what they save)
MIN_SECONDS = 4.0
#: curves left per process, at least, for a pool to be started
MIN_PER_WORKER = 4


def default_workers() -> int:
    """Processes for one file's curves (the calling one included): the CPUs this process may
    run on."""
    return max(1, cpu_count())


def worth_a_pool(elapsed: float, done: int, left: int, workers: int) -> bool:
    """Whether the ``left`` curves should be shared by ``workers`` processes (a pool of
    ``workers - 1`` and this one), after ``done`` curves took ``elapsed`` seconds here: only
    with two or more, after :data:`PROBE_SECONDS`, with :data:`MIN_PER_WORKER` curves per
    process left and the rest projected to take :data:`MIN_SECONDS` or more."""
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


_Outcome = tuple[str, Any, list[tuple[type[Warning], str]]]


def _worker_start(parent: int) -> None:
    """A worker ignores Ctrl-C (the command's process is interrupted and stops the pool; a
    worker's own KeyboardInterrupt would print a traceback from a process the user never
    started) and exits when the command's process is gone (killed by a signal, no ``finally``
    ran: the pool's queue keeps a worker waiting forever otherwise): a daemon thread looks at
    the parent every half second."""
    import signal
    import threading
    import time

    signal.signal(signal.SIGINT, signal.SIG_IGN)

    def watch() -> None:
        while True:
            time.sleep(0.5)
            if os.getppid() != parent:
                os._exit(1)
    threading.Thread(target=watch, name="curvefair-parent-watch", daemon=True).start()


class Task:
    """One curve given to a :class:`Pool`: :meth:`take` claims it for the calling process if
    no worker has started it (the calling process works from the end of the list while the
    workers start and work from the front), :meth:`result` gives :func:`fair_record`'s
    outcome, computed here if the task was taken or the pool broke (a worker died)."""

    def __init__(self, pool: Pool, fut: Any, args: tuple[Any, str | None, dict[str, Any]]
                 ) -> None:
        self._pool, self._fut, self._args = pool, fut, args
        self._here: _Outcome | None = None

    def take(self) -> bool:
        """Cancel the task in the pool (False once a worker has it) and fair it here."""
        if self._fut is not None and not self._fut.cancel():
            return False
        self._here = fair_record(*self._args)
        self._pool.here += 1
        return True

    def result(self) -> _Outcome:
        if self._here is None:
            try:
                return cast("_Outcome", self._fut.result())
            except Exception:  # noqa: BLE001 - the pool failed (a worker died, a result that
                # would not unpickle, ...): the curve is faired here, as without a pool
                self._pool.redone += 1
                self._here = fair_record(*self._args)
        return self._here


class Pool:
    """A process pool (``spawn``: no fork of a process with threads) for
    :func:`fair_record`; :meth:`submit` returns the curve's :class:`Task`."""

    def __init__(self, workers: int) -> None:
        self._pool = cf.ProcessPoolExecutor(max_workers=workers,
                                            mp_context=mp.get_context("spawn"),
                                            initializer=_worker_start,
                                            initargs=(os.getpid(),))
        self.here = 0  # tasks taken back by the calling process
        self.redone = 0  # tasks run in this process after the pool broke

    def submit(self, curve: Any, method: str | None, kwargs: dict[str, Any]) -> Task:
        try:
            fut = self._pool.submit(fair_record, curve, method, kwargs)
        except Exception:  # noqa: BLE001 - no pool (broken, or a worker could not start):
            fut = None  # the task runs here
        return Task(self, fut, (curve, method, kwargs))

    def close(self, wait: bool = True) -> None:
        """Stop the workers: after the last task (``wait``), or now (an interrupted command:
        the tasks not begun are cancelled, the workers finish the one they have and exit)."""
        self._pool.shutdown(wait=wait, cancel_futures=True)
