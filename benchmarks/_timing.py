"""Timing helper shared by the benchmarks (not a benchmark: run.py runs bench_*.py)."""

from __future__ import annotations

import math
import time
from collections.abc import Callable

REPEATS = 5


def best_wall(fn: Callable[[], object], repeats: int = REPEATS) -> float:
    """Best wall time of ``fn()`` over ``repeats`` calls after one warm-up (compilation) [s]."""
    fn()
    best = math.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best
