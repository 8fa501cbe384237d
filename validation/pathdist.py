"""Shortest distance from points to a polyline (the lateral position error).

For every model point the error is its distance to the nearest point of the
measured path, taken as a polyline through the measured samples.

Exact and vectorised. A KD-tree over the path's vertices gives each point its
nearest vertex at distance ``d0``, an upper bound on the answer. If the nearest
point of the path lies on segment ``AB`` (length at most ``L``) at distance
``d``, then one of ``A`` and ``B`` lies within ``sqrt(d**2 + (L/2)**2)``, which
is at most ``sqrt(d0**2 + (L/2)**2)``. So the segments next to the ``k`` nearest
vertices are enough whenever the ``k``-th vertex is farther than that bound.
The points where it is not are redone with more candidates, until all are.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree


def _segment_distances(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distances from points ``p`` to segments ``a-b``, elementwise (broadcasting) [m]."""
    ab = b - a
    ap = p - a
    den = np.einsum("...i,...i->...", ab, ab)
    num = np.einsum("...i,...i->...", ap, ab)
    with np.errstate(invalid="ignore", divide="ignore"):
        s = np.where(den > 0.0, num / den, 0.0)
    s = np.clip(s, 0.0, 1.0)
    closest = a + s[..., None] * ab
    return np.linalg.norm(p - closest, axis=-1)


def distance_to_polyline(points: np.ndarray, path: np.ndarray, k: int = 8) -> np.ndarray:
    """Shortest distance from each point to a polyline [m].

    Parameters
    ----------
    points : ndarray, shape (N, 2)
        Query points [m].
    path : ndarray, shape (M, 2)
        Polyline vertices in order [m]; repeated vertices (standstill) are fine.
    k : int
        Nearest vertices tried first per point.

    Returns
    -------
    ndarray, shape (N,)
        Distances [m].
    """
    points = np.asarray(points, dtype=float)
    path = np.asarray(path, dtype=float)
    if path.ndim != 2 or path.shape[1] != 2 or len(path) == 0:
        raise ValueError(f"path must have shape (M, 2) with M >= 1, got {path.shape}")
    m = len(path)
    if m == 1:
        return np.linalg.norm(points - path[0], axis=1)
    half = 0.5 * float(np.max(np.linalg.norm(np.diff(path, axis=0), axis=1)))
    tree = cKDTree(path)
    out = np.empty(len(points))
    todo = np.arange(len(points))
    while todo.size:
        kk = min(k, m)
        dist, idx = tree.query(points[todo], k=kk)
        dist, idx = dist.reshape(len(todo), kk), idx.reshape(len(todo), kk)
        # Segments on both sides of each candidate vertex.
        lo = np.clip(np.concatenate([idx - 1, idx], axis=1), 0, m - 2)
        d = _segment_distances(points[todo, None, :], path[lo], path[lo + 1]).min(axis=1)
        bound = np.sqrt(dist[:, 0] ** 2 + half ** 2)
        done = (dist[:, -1] > bound) | (kk == m)
        out[todo[done]] = d[done]
        todo = todo[~done]
        k *= 4
    return out
