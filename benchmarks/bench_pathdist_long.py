"""Path distance on a one-hour log, clean and with one 500 m position step.

A 60-minute yard log at 100 Hz (360 000 samples): the tractor drives loops
and figure-eights of a 25 m yard, and the "model" runs 0.3 m beside it. The
error criterion needs the distance of every model point to the measured
polyline (:func:`artic.validation.criteria.pathdist.distance_to_polyline`). The same is
timed with a single 500 m jump in the measured path halfway through, the
case that used to take quadratic time and gigabytes. Printed: wall time
(best of a few after a warm-up that compiles), node visits per point (the
work measure the tests bound), and the peak of Python-level allocations.

Run: ``python benchmarks/run.py`` (or this file alone).
"""

from __future__ import annotations

import tracemalloc

import numpy as np

from _timing import best_wall
from artic.validation.criteria.pathdist import distance_to_polyline

SAMPLES = 360_000
"""One hour at 100 Hz."""


def yard_log(n: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """A looping yard path of ``n`` samples (an hour) and model points 0.3 m beside it [m]."""
    t = np.arange(SAMPLES if n is None else n) * 0.01
    path = np.column_stack([25.0 * np.sin(t / 40.0), 12.0 * np.sin(t / 20.0)])
    path += np.random.default_rng(0).normal(0.0, 0.01, path.shape)  # GNSS noise
    d = np.gradient(path, axis=0)
    normal = np.column_stack([-d[:, 1], d[:, 0]])
    normal /= np.maximum(np.linalg.norm(normal, axis=1), 1e-12)[:, None]
    return path, path + 0.3 * normal


def main() -> dict[str, float]:
    path, points = yard_log()
    n = len(path)
    stepped = path.copy()
    stepped[n // 2:] += [500.0, 0.0]
    out = {}
    for label, p in (("clean", path), ("500 m step", stepped)):
        wall = best_wall(lambda p=p: distance_to_polyline(points, p), repeats=3)
        _, work = distance_to_polyline(points, p, return_work=True)
        tracemalloc.start()
        distance_to_polyline(points, p)
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        out[label] = wall
        print(f"  {n / 360000:.2g} h log ({n} points to {n} vertices), {label}: {wall:.3f} s, "
              f"{work / n:.0f} node visits per point, peak Python allocation "
              f"{peak / 2 ** 20:.0f} MiB")
    return out


if __name__ == "__main__":
    main()
