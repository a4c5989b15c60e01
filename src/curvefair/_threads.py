"""Two threads for long per-point (per-segment) passes of compiled kernels.

curvefair's O(n) passes are compiled ``nogil`` kernels over independent ranges of points or
segments; :func:`ranges` shares the ranges of one pass between the calling thread and one
worker thread. Each range writes only its own rows, so the results are bitwise the same on
one thread or two, whatever the scheduling. ``CURVEFAIR_THREADS`` (1 or 2, read at import)
sets the number of threads; the default is 2 when the process may use two or more CPUs.
Used by the global fairing's Newton passes (:mod:`curvefair.fairing.global_fair`) and by the
sampling pass of :func:`curvefair.analyze`; :class:`Background` runs one whole job (the input's
analysis in :func:`curvefair.fair`) on the worker while the calling thread goes on.
"""

from __future__ import annotations

import os
import threading
import warnings
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from typing import Any

__all__ = ["THREADS", "CHUNKS", "cpu_count", "thread_setting", "pool", "ranges", "ranges_start",
           "bounds", "Background"]


def cpu_count() -> int:
    """CPUs this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def thread_setting() -> int:
    """Threads for the per-point passes: ``CURVEFAIR_THREADS`` (1 or 2; 1 keeps everything on
    the calling thread), default 2 when the process may use 2 or more CPUs."""
    env = os.environ.get("CURVEFAIR_THREADS", "").strip()
    if env:
        if env in ("1", "2"):
            return min(int(env), max(cpu_count(), 1))
        warnings.warn(f"CURVEFAIR_THREADS must be 1 or 2, got {env!r}; using the default",
                      RuntimeWarning, stacklevel=2)
    return min(2, cpu_count())


THREADS = thread_setting()  # 1: everything on the calling thread
CHUNKS = 16  # ranges per pass
_POOL: list[ThreadPoolExecutor] = []
_POOL_LOCK = threading.Lock()


def pool() -> ThreadPoolExecutor:
    """The one worker thread (created on first use)."""
    with _POOL_LOCK:
        if not _POOL:
            _POOL.append(ThreadPoolExecutor(max_workers=1, thread_name_prefix="curvefair"))
        return _POOL[0]


def bounds(lo: int, hi: int, chunks: int = CHUNKS) -> list[int]:
    """The ``chunks + 1`` range boundaries of ``lo .. hi`` that :func:`ranges` uses."""
    m = hi - lo
    return [lo + (m * q) // chunks for q in range(chunks + 1)]


def ranges(fn: Callable[[int, int], Any], lo: int, hi: int, threads: int, min_size: int,
           chunks: int = CHUNKS) -> list[Any]:
    """``[fn(a, b) for (a, b) in chunks of lo .. hi]`` (in order), the chunks shared between
    the calling thread and one worker thread when ``threads >= 2`` and ``hi - lo >=
    min_size`` (else one call ``fn(lo, hi)``). ``fn`` must be a compiled ``nogil`` kernel
    whose ranges are independent (each writes its own points only), so the results are
    bitwise the same on one thread. The chunks are claimed one at a time, and the calling
    thread waits only for chunks the worker has started: when the other core is busy (or the
    worker has not been scheduled yet) the calling thread simply does every chunk itself."""
    return ranges_start(fn, lo, hi, threads, min_size, chunks)()


def ranges_start(fn: Callable[[int, int], Any], lo: int, hi: int, threads: int,
                 min_size: int, chunks: int = CHUNKS) -> Callable[[], list[Any]]:
    """:func:`ranges` in two halves: the worker thread starts on the chunks now, the
    returned function (call it exactly once) does the chunks still unclaimed on the calling
    thread, waits for those the worker has started and returns the results. Between the two
    the calling thread may run other ``nogil`` compiled work that neither writes what ``fn``
    reads nor touches what it writes (e.g. a factorisation while the right-hand side is
    prepared). Single-threaded (or a short range): everything runs in the returned
    function."""
    if threads < 2 or hi - lo < min_size:
        return lambda: [fn(lo, hi)]
    k = chunks
    bnd = bounds(lo, hi, k)
    out: list[Any] = [None] * k
    lock = threading.Lock()
    # ``fn`` is held here, not by the closures: the worker's job can still sit in the pool's
    # queue after finish() (the worker busy with an earlier job, e.g. a _Prefault), and
    # finish() drops it, so that the arrays ``fn`` references are freed when the caller drops
    # them (measured: a Gram band's two work arrays, 5.25x the input's coordinate bytes,
    # stayed alive through the global fairing's set-up)
    state: dict[str, Any] = {"next": 0, "pending": 0, "error": None, "fn": fn}
    idle = threading.Event()
    idle.set()

    def claim(worker: bool) -> tuple[int, Any]:
        with lock:
            q = state["next"]
            if q >= k:
                return -1, None
            state["next"] = q + 1
            if worker:
                state["pending"] += 1
                idle.clear()
            return q, state["fn"]

    def work(worker: bool) -> None:
        while True:
            q, f = claim(worker)
            if q < 0:
                return
            try:
                out[q] = f(bnd[q], bnd[q + 1])
            except BaseException as exc:  # re-raised by the calling thread
                state["error"] = exc
            finally:
                if worker:
                    with lock:
                        state["pending"] -= 1
                        if state["pending"] == 0:
                            idle.set()

    pool().submit(work, True)

    def finish() -> list[Any]:
        work(False)
        while True:
            with lock:
                if state["pending"] == 0:
                    state["fn"] = None  # every chunk claimed and done
                    break
            idle.wait()
        if state["error"] is not None:
            raise state["error"]
        return out

    return finish


class Background:
    """``fn()`` started on the worker thread; :meth:`result` returns its value (or raises its
    exception). If the worker has not started the job when :meth:`result` is called (busy with
    another job, or not yet scheduled), the calling thread runs it itself: nothing ever waits
    for a job that has not begun. ``fn`` may use :func:`ranges` (run on the worker, its passes
    find the worker busy and do every chunk on that thread). Single-threaded
    (``threads < 2``): ``fn`` runs in :meth:`result`."""

    def __init__(self, fn: Callable[[], Any], threads: int | None = None) -> None:
        self._fn: Callable[[], Any] | None = fn
        self._lock = threading.Lock()
        self._done = threading.Event()
        self._value: Any = None
        self._error: BaseException | None = None
        if (THREADS if threads is None else threads) >= 2:
            pool().submit(self._run)

    def _run(self) -> None:
        with self._lock:
            fn, self._fn = self._fn, None  # claimed once: by the worker or by result()
        if fn is None:
            return
        try:
            self._value = fn()
        except BaseException as exc:  # re-raised by result()
            self._error = exc
        finally:
            self._done.set()

    def result(self) -> Any:
        """The job's value (run here if the worker has not started it; else waited for)."""
        self._run()
        self._done.wait()
        if self._error is not None:
            raise self._error
        return self._value
