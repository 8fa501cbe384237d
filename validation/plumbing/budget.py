"""The simulated-time budget: seconds and runs of every model run, per kind of model.

:data:`BUDGET` counts the simulated seconds and runs of every model run
(:class:`Budget`), the campaign's cost in numbers that do not depend on the
machine. The harness and the generator count; the campaign and the command
line read it.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from contextlib import contextmanager

KINDS = ("multibody", "reduced", "other")
"""What :class:`Budget` counts apart: MuJoCo models (the plant and the independent
truth, the campaign's cost), the compiled reduced models (KIN, the STM), and any
model that runs in the harness's Python loop."""


class Budget:
    """Simulated seconds and runs, per kind of model, counted where the runs are made.

    The harness counts every run it makes (validation, the floor, the
    open-loop predictions, tuning, efficiency, the gain sweep), and the
    generator every log it drives; the campaign reads the difference over
    each stage (:meth:`since`). Unlike wall time, these numbers are the same
    on any machine and under any load, so the budget of a campaign can be read
    and compared without timing it. Thread-safe.

    A :meth:`scope` collects, besides, what one thread counts inside it, so
    that a run made on another machine (a Dask worker) can carry its own
    count back with its result (:meth:`merge`).
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._totals: dict[str, list[float]] = {k: [0, 0.0] for k in KINDS}
        self._local = threading.local()

    def add(self, kind: str, seconds: float, runs: int = 1) -> None:
        """Count ``runs`` runs of ``kind`` that simulated ``seconds`` [s] in all."""
        seconds = float(seconds) if seconds > 0 else 0.0
        with self._lock:
            total = self._totals.setdefault(kind, [0, 0.0])
            total[0] += runs
            total[1] += seconds
        for scope in getattr(self._local, "scopes", ()):
            part = scope.setdefault(kind, [0, 0.0])
            part[0] += runs
            part[1] += seconds

    def merge(self, counts: dict) -> None:
        """Add counts made elsewhere (:meth:`scope`'s, from another process)."""
        for kind, (runs, seconds) in counts.items():
            self.add(kind, seconds, int(runs))

    def snapshot(self) -> dict[str, tuple[int, float]]:
        """The totals so far: kind -> (runs, simulated seconds)."""
        with self._lock:
            return {k: (int(v[0]), float(v[1])) for k, v in self._totals.items()}

    def since(self, before: dict[str, tuple[int, float]]) -> dict[str, tuple[int, float]]:
        """What was counted after ``before`` (a :meth:`snapshot`): kind -> (runs, seconds)."""
        now = self.snapshot()
        out = {}
        for kind, (runs, seconds) in now.items():
            r0, s0 = before.get(kind, (0, 0.0))
            out[kind] = (runs - r0, seconds - s0)
        return out

    @contextmanager
    def scope(self) -> Iterator[dict[str, list[float]]]:
        """Collect into the yielded dict what this thread counts inside the block."""
        counts: dict[str, list[float]] = {}
        scopes = getattr(self._local, "scopes", ())
        self._local.scopes = (*scopes, counts)
        try:
            yield counts
        finally:
            self._local.scopes = scopes


BUDGET = Budget()
"""The process's count of simulated time (see :class:`Budget`)."""


def budget_text(counts: dict[str, tuple[int, float]]) -> str:
    """``'multibody 100 runs, 2858 s simulated; reduced 200 runs, 5716 s simulated'``."""
    parts = [f"{kind} {int(runs)} run{'s' if runs != 1 else ''}, {seconds:.0f} s simulated"
             for kind, (runs, seconds) in counts.items() if runs]
    return "; ".join(parts)
