"""artic's worker processes: they end with their parent and route MuJoCo's log.

:func:`completed` runs independent tasks on them (or on a given executor).

A ``ProcessPoolExecutor`` worker blocks reading its call queue. If the
campaign's main process is killed (``SIGKILL``, an out-of-memory kill), nothing
tells the workers, and each would wait for ever holding its memory.
:func:`init_worker` starts a daemon thread in the worker that checks once a
second whether the parent is still the one that started it, and ends the
worker when it is not (the worker is then re-parented, so ``getppid``
changes). Polling is used rather than ``PR_SET_PDEATHSIG``, which fires when
the *thread* that forked the worker ends, not the process.
"""

from __future__ import annotations

import multiprocessing
import os
import threading
import time
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import Executor, ProcessPoolExecutor, as_completed

from artic.validation.plumbing import runtime

PARENT_POLL = 1.0
"""Seconds between two checks of the parent [s]."""


def _watch(parent: int) -> None:
    while True:
        if os.getppid() != parent:
            os._exit(1)  # the parent is gone: nothing will read our results
        time.sleep(PARENT_POLL)


def init_worker(parent: int) -> None:
    """Initializer of a worker process (``initializer=init_worker, initargs=(os.getpid(),)``).

    Parameters
    ----------
    parent : int
        The process id of the process that starts the pool.
    """
    runtime.mujoco_settings()
    if os.getppid() != parent:
        os._exit(1)
    threading.Thread(target=_watch, args=(parent,), name="artic-parent-watch",
                     daemon=True).start()


def completed(fn: Callable, tasks: Iterable[tuple[object, tuple]], jobs: int = 1,
              executor: Executor | None = None, fresh: bool = False
              ) -> Iterator[tuple[object, object]]:
    """``(key, fn(*args))`` for each ``(key, args)`` of ``tasks``, as each finishes.

    The tasks run on ``executor`` when one is given; otherwise on ``jobs``
    worker processes started here (with :func:`init_worker`) when there are
    more jobs and tasks than one, or always with ``fresh``; otherwise one
    after another in this process. Workers are forked from this process, or
    with ``fresh`` started anew (``spawn``: they import what ``fn`` needs
    and nothing of this process's memory, for work that would grow it). A
    pool started here is shut down, its waiting tasks cancelled, when the
    iteration ends, fails, or is closed early (use ``contextlib.closing``).
    """
    tasks = list(tasks)
    own = executor is None and ((jobs > 1 and len(tasks) > 1) or (fresh and len(tasks) > 0))
    context = multiprocessing.get_context("spawn") if fresh else None
    pool = ProcessPoolExecutor(max_workers=max(1, min(jobs, len(tasks))), mp_context=context,
                               initializer=init_worker, initargs=(os.getpid(),)) if own \
        else executor
    try:
        if pool is None:
            for key, args in tasks:
                yield key, fn(*args)
            return
        futures = {pool.submit(fn, *args): key for key, args in tasks}
        for f in as_completed(futures):
            yield futures[f], f.result()
    finally:
        if own:
            pool.shutdown(cancel_futures=True)
