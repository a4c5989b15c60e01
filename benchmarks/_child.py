"""Run a measurement in a fresh interpreter, for its own peak memory and a cold import."""

from __future__ import annotations

import multiprocessing as mp
from collections.abc import Callable
from typing import Any


def in_child(target: Callable[..., None], *args: Any) -> Any:
    """``target(*args, queue)`` in a spawned child process; returns what it put on the queue
    (one item). Spawned, not forked: the child's resident memory is its own run's."""
    ctx = mp.get_context("spawn")
    q: mp.Queue = ctx.Queue()
    p = ctx.Process(target=target, args=(*args, q))
    p.start()
    out = q.get()
    p.join()
    return out
