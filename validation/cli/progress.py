"""Progress lines with counts and the time left, for every stage that takes a while.

A :class:`Counter` counts the finished items of one stage and prints
``[i/n] label: what - about 1 min 20 s left``. The time left is the mean time
per item so far times the items still to do. Lines come at most every
:data:`EVERY` seconds, so a stage of a hundred quick items prints a handful;
the last item, and any item with something to say (``always=True``), are
printed regardless. Thread-safe: runs on a pool report to one counter.
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Callable

EVERY = 3.0
"""Shortest time between two progress lines of one counter [s]."""


def stderr(line: str) -> None:
    """Print a progress line to standard error."""
    print(line, file=sys.stderr, flush=True)


def duration(seconds: float) -> str:
    """``'45 s'``, ``'3 min 05 s'``, ``'1 h 02 min'``."""
    s = int(round(max(seconds, 0.0)))
    if s < 60:
        return f"{s} s"
    if s < 3600:
        return f"{s // 60} min {s % 60:02d} s"
    return f"{s // 3600} h {s % 3600 // 60:02d} min"


class Counter:
    """Counts one stage's items and prints throttled progress lines with the time left.

    Parameters
    ----------
    total : int
        Items the stage will finish.
    label : str
        What is counted, for example ``"validation, unloaded"``.
    progress : callable, optional
        Receives the lines; nothing is printed without it.
    every : float
        Shortest time between lines [s].
    """

    def __init__(self, total: int, label: str, progress: Callable[[str], None] | None,
                 every: float = EVERY) -> None:
        self.total, self.label, self.progress, self.every = total, label, progress, every
        self.done = 0
        self._t0 = time.perf_counter()
        self._last = -float("inf")
        self._lock = threading.Lock()

    def left(self) -> float:
        """Estimated time left [s]: the mean time per finished item times the items left."""
        if self.done == 0:
            return float("nan")
        return (time.perf_counter() - self._t0) / self.done * (self.total - self.done)

    def step(self, what: str = "", always: bool = False, count: int = 1) -> None:
        """Count ``count`` finished items; print a line if it is time to."""
        with self._lock:
            self.done += count
            now = time.perf_counter()
            last = self.done >= self.total
            if self.progress is None or not (always or last or now - self._last >= self.every):
                return
            self._last = now
            tail = "done" if last else f"about {duration(self.left())} left"
            self.progress(f"[{self.done}/{self.total}] {self.label}"
                          + (f": {what}" if what else "") + f" - {tail}")
