"""Progress lines with counts and the time left, for every stage that takes a while.

A :class:`Counter` counts the finished items of one stage and prints
``[i/n] label: what - about 1 min 20 s left``. The time left is the time per
item measured since the first item finished (which carries the stage's start-up:
compiling, workers starting, the first of several items finishing side by side)
times the items still to do, and is said only once :data:`ESTIMATE_AFTER` items
have finished since then; before, the line has no estimate. Lines come at most every
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

ESTIMATE_AFTER = 3
"""Items that must finish after the first before a time left is said: the first one's time
holds the stage's start-up (numba compiling, MuJoCo models built, worker processes started),
which made a stage's first estimate six times its real time."""


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
        self._first: tuple[float, int] | None = None  # when the first item(s) finished
        self._last = -float("inf")
        self._lock = threading.Lock()

    def left(self) -> float:
        """Estimated time left [s], NaN until :data:`ESTIMATE_AFTER` items after the first.

        The time per item since the first finished, times the items left.
        """
        if self._first is None:
            return float("nan")
        t1, n1 = self._first
        since = self.done - n1
        if since < ESTIMATE_AFTER:
            return float("nan")
        return (time.perf_counter() - t1) / since * (self.total - self.done)

    def step(self, what: str = "", always: bool = False, count: int = 1) -> None:
        """Count ``count`` finished items; print a line if it is time to."""
        with self._lock:
            self.done += count
            now = time.perf_counter()
            if self._first is None:
                self._first = (now, self.done)
            last = self.done >= self.total
            if self.progress is None or not (always or last or now - self._last >= self.every):
                return
            self._last = now
            left = self.left()
            tail = (" - done" if last else f" - about {duration(left)} left"
                    if left == left else "")  # NaN: not measured yet, nothing said
            self.progress(f"[{self.done}/{self.total}] {self.label}"
                          + (f": {what}" if what else "") + tail)
