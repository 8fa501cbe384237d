"""The low-speed swept path: the widest cross-section of the road a turn takes.

The swept path is the ground every part of the bodies passes over. Its width
at a station of the prescribed path is the distance, across the path (radially
on the arc), from its outermost to its innermost point there; the low-speed
swept path measure is the largest such width over the turn. The points come
from :meth:`artic.validation.pbs.motion.Motion.body_points`; a station's
width is taken from the points whose path coordinates fall in a bin of
:data:`BIN` around it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from artic.validation.pbs.paths import TurnPath

BIN = 0.1
"""Width of a station bin [m]. A body edge crossing a bin at an angle a to the
path spans up to ``BIN tan a`` across it; at the arc's radii (12 m) the
envelope's slope is under 0.3 where it is widest, so the width is resolved to
about 3 cm or better."""

CHUNK = 65_536
"""Points put through :meth:`TurnPath.frenet` at a time: its dozen temporaries of
a turn's 1.6 million outline points (a truth's 63 s drive, 258 points a sample)
reached 150 MB at once; in chunks, 6 MB."""


@dataclass(frozen=True)
class Swept:
    """The swept path's envelope along the prescribed path.

    Attributes
    ----------
    station : ndarray
        Bin centres along the path [m].
    outer, inner : ndarray
        Largest and smallest offset to the left of the path in each bin [m]
        (NaN where no point fell).
    """

    station: np.ndarray
    outer: np.ndarray
    inner: np.ndarray

    @property
    def width(self) -> np.ndarray:
        """Width at each station [m]."""
        return self.outer - self.inner

    def widest(self, s_from: float, s_to: float) -> float:
        """Largest width between stations ``s_from`` and ``s_to`` [m]."""
        keep = (self.station >= s_from) & (self.station <= s_to)
        w = self.width[keep]
        return float(np.nanmax(w)) if np.isfinite(w).any() else float("nan")


def swept(path: TurnPath, points: np.ndarray) -> Swept:
    """The envelope of points ``(..., 2)`` [m] in the path's coordinates."""
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    s, n = np.empty(len(p)), np.empty(len(p))
    for i in range(0, len(p), CHUNK):  # elementwise, so the same values as in one call
        s[i:i + CHUNK], n[i:i + CHUNK] = path.frenet(p[i:i + CHUNK, 0], p[i:i + CHUNK, 1])
    lo = np.floor(np.nanmin(s) / BIN)
    k = (np.floor(s / BIN) - lo).astype(np.int64)
    m = int(k.max()) + 1
    outer = np.full(m, -np.inf)
    inner = np.full(m, np.inf)
    np.maximum.at(outer, k, n)
    np.minimum.at(inner, k, n)
    empty = ~np.isfinite(outer)
    outer[empty] = np.nan
    inner[empty] = np.nan
    return Swept((lo + np.arange(m) + 0.5) * BIN, outer, inner)


def swept_width(path: TurnPath, points: np.ndarray, s_from: float | None = None,
                s_to: float | None = None) -> float:
    """The low-speed swept path [m]: the widest cross-section between two stations.

    Parameters
    ----------
    path : TurnPath
        The prescribed path.
    points : ndarray, shape (..., 2)
        Every point of the bodies at every sample [m].
    s_from, s_to : float, optional
        Stations to measure between [m]; the arc's start and the path's end by default.
    """
    a = path.entry if s_from is None else s_from
    b = path.length if s_to is None else s_to
    return swept(path, points).widest(a, b)
