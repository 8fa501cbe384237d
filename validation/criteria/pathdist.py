"""Shortest distance from points to a polyline (the lateral position error).

For every model point the error is its distance to the nearest point of the
measured path, taken as a polyline through the measured samples. The answer
is exact (to rounding): every segment is either measured or proven farther
than the best found.

**Data structure.** A bounding-box tree over the path's segments *in their
order along the path*: leaves hold :data:`LEAF` consecutive segments, and each
inner node the union of its two children's boxes, in a complete binary tree
stored as an array. Consecutive samples of a trajectory lie close together,
so these boxes are tight without any sorting, and the tree is built bottom-up
in ``O(M)`` time and memory for ``M`` path vertices.

**Query.** Each point descends the tree, nearer child first, and skips every
node whose box is farther than the best distance found so far. The search
starts from a good guess: the segment at the same place in time (a model run
and its log are sample-aligned) or the previous point's nearest segment,
whichever is nearer. Memory per query is one stack of at most the tree's
height.

**Complexity, and why one bad sample cannot blow it up.** Memory is
``O(M + N)`` for ``N`` points, whatever the geometry. Time is
``O(M + N (log M + k))``, where ``k`` is the number of leaves whose boxes
reach closer to a point than its answer: a property of how often the path
passes near that point (once or twice for a manoeuvre, a few times for a
figure-8 or a shuffle at the dock), not of any single sample. A single
sample (a 500 m GNSS step, a stop) changes at most two segments. Their
leaves' boxes grow, and so do the boxes of those leaves' ``log2(M / LEAF)``
ancestors and no other node's. A query is drawn into each grown box at most
once and descends from it only where boxes are closer than its answer, so
the step adds at most ``O(log M)`` node visits per query: ``O(N log M)`` in
all, never ``O(N M)``. (The earlier nearest-vertex search enlarged its
search radius to half the *longest* segment for every point, so one 500 m
step made every query examine the whole path: quadratic time, and gigabytes
of candidate arrays.) :func:`distance_to_polyline` returns the node visits
with ``return_work=True``; the tests bound them.

``python benchmarks/bench_pathdist_long.py`` times a one-hour log (360 000
samples) with and without a 500 m step.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from artic.mjcf.errors import UserError

LEAF = 8
"""Consecutive segments per leaf of the tree."""

_MAX_DEPTH = 64
"""Stack size of a query: the tree's height plus one never exceeds it (2^63 leaves)."""


@njit(cache=True)
def _build(ax, ay, bx, by):
    """Boxes of the implicit complete binary tree over the segments ``a -> b``.

    Node ``1`` is the root, node ``i`` has children ``2i`` and ``2i + 1``, and leaf
    ``j`` is node ``size + j``. Returns ``(lo, hi, size)``: per node the box's lower
    and upper corner; empty leaves get an empty box (``+inf`` low, ``-inf`` high).
    """
    n = ax.size
    n_leaves = (n + LEAF - 1) // LEAF
    size = 1
    while size < n_leaves:
        size *= 2
    lo = np.full((2 * size, 2), np.inf)
    hi = np.full((2 * size, 2), -np.inf)
    for leaf in range(n_leaves):
        node = size + leaf
        for s in range(leaf * LEAF, min(n, (leaf + 1) * LEAF)):
            lo[node, 0] = min(lo[node, 0], ax[s], bx[s])
            lo[node, 1] = min(lo[node, 1], ay[s], by[s])
            hi[node, 0] = max(hi[node, 0], ax[s], bx[s])
            hi[node, 1] = max(hi[node, 1], ay[s], by[s])
    for node in range(size - 1, 0, -1):
        for k in range(2):
            lo[node, k] = min(lo[2 * node, k], lo[2 * node + 1, k])
            hi[node, k] = max(hi[2 * node, k], hi[2 * node + 1, k])
    return lo, hi, size


@njit(cache=True, inline="always")
def _box_dist2(lo, hi, node, x, y):
    dx = max(lo[node, 0] - x, 0.0, x - hi[node, 0])
    dy = max(lo[node, 1] - y, 0.0, y - hi[node, 1])
    return dx * dx + dy * dy


@njit(cache=True, inline="always")
def _seg_dist2(ax, ay, bx, by, s, x, y):
    ex, ey = bx[s] - ax[s], by[s] - ay[s]
    px, py = x - ax[s], y - ay[s]
    den = ex * ex + ey * ey
    t = 0.0
    if den > 0.0:
        t = min(max((px * ex + py * ey) / den, 0.0), 1.0)
    dx, dy = px - t * ex, py - t * ey
    return dx * dx + dy * dy


@njit(cache=True, nogil=True)
def _query(px, py, ax, ay, bx, by, lo, hi, size, seed):
    """Distances of points ``(px, py)`` to the segments; also the work done (node visits).

    It releases the GIL, so metrics of several runs spread over threads.
    """
    n_seg = ax.size
    out = np.empty(px.size)
    stack = np.empty(_MAX_DEPTH, dtype=np.int64)
    prev = 0
    work = 0
    for q in range(px.size):
        x, y = px[q], py[q]
        if not (math.isfinite(x) and math.isfinite(y)):
            out[q] = np.nan
            continue
        best_seg = seed[q]
        best = _seg_dist2(ax, ay, bx, by, best_seg, x, y)
        d = _seg_dist2(ax, ay, bx, by, prev, x, y)
        if d < best:
            best, best_seg = d, prev
        stack[0] = 1
        top = 1
        while top > 0:
            top -= 1
            node = stack[top]
            work += 1
            if _box_dist2(lo, hi, node, x, y) >= best:
                continue
            if node >= size:
                first = (node - size) * LEAF
                for s in range(first, min(n_seg, first + LEAF)):
                    d = _seg_dist2(ax, ay, bx, by, s, x, y)
                    if d < best:
                        best, best_seg = d, s
                continue
            c1, c2 = 2 * node, 2 * node + 1
            d1 = _box_dist2(lo, hi, c1, x, y)
            d2 = _box_dist2(lo, hi, c2, x, y)
            if d1 > d2:
                c1, c2, d1, d2 = c2, c1, d2, d1
            # Farther child below the nearer one: the nearer is searched first.
            if d2 < best:
                stack[top] = c2
                top += 1
            if d1 < best:
                stack[top] = c1
                top += 1
        out[q] = math.sqrt(best)
        prev = best_seg
    return out, work


def distance_to_polyline(points: np.ndarray, path: np.ndarray,
                         return_work: bool = False) -> np.ndarray | tuple[np.ndarray, int]:
    """Shortest distance from each point to a polyline [m].

    Parameters
    ----------
    points : ndarray, shape (N, 2)
        Query points [m]; a non-finite point gets NaN.
    path : ndarray, shape (M, 2)
        Polyline vertices in order [m], all finite; repeated vertices
        (standstill) are fine.
    return_work : bool
        Also return the number of tree nodes visited, the measure of the
        work done (see the module docstring).

    Returns
    -------
    ndarray, shape (N,)
        Distances [m].
    work : int
        With ``return_work``.
    """
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    path = np.asarray(path, dtype=float)
    if path.ndim != 2 or path.shape[1] != 2 or len(path) == 0:
        raise UserError(f"path must have shape (M, 2) with M >= 1, got {path.shape}")
    if not np.all(np.isfinite(path)):
        raise UserError("path has non-finite vertices")
    if len(path) == 1:
        path = np.vstack([path, path])
    a, b = path[:-1], path[1:]
    ax, ay = np.ascontiguousarray(a[:, 0]), np.ascontiguousarray(a[:, 1])
    bx, by = np.ascontiguousarray(b[:, 0]), np.ascontiguousarray(b[:, 1])
    lo, hi, size = _build(ax, ay, bx, by)
    n, m = len(points), len(ax)
    # The segment at the same place in time: a good first guess for aligned runs.
    seed = np.minimum((np.arange(n) * (m / max(n, 1))).astype(np.int64), m - 1)
    out, work = _query(np.ascontiguousarray(points[:, 0]), np.ascontiguousarray(points[:, 1]),
                       ax, ay, bx, by, lo, hi, size, seed)
    return (out, int(work)) if return_work else out
