"""Set-up of artic's worker processes: they end with their parent, and route MuJoCo's log.

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

import os
import threading
import time

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
    from validation import runtime

    runtime.mujoco_settings()
    if os.getppid() != parent:
        os._exit(1)
    threading.Thread(target=_watch, args=(parent,), name="artic-parent-watch",
                     daemon=True).start()
