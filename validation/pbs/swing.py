"""Frontal swing and tail swing: how far the bodies' corners swing outside the turn.

- **Frontal swing** of the tractor: the largest distance by which its front
  outside corner passes outside the path of the steer tyre's outer edge,
  measured across the path (radially on the arc).
- **Frontal swing of the semitrailer** (its "maximum of difference"): the
  largest distance by which the semitrailer's front outside corner stands
  outside the tractor's outer side, measured in the tractor's frame.
- **Tail swing**: the largest distance by which the semitrailer's rear
  outside corner moves outwards, perpendicular to the direction of entry,
  from the line it ran on before the turn.

"Outside" is the side away from the turn's centre: the right turning left.
"""

from __future__ import annotations

import numpy as np

from artic.validation.pbs.motion import Motion
from artic.validation.pbs.paths import TurnPath


def frontal_swing(path: TurnPath, motion: Motion) -> float:
    """Tractor's frontal swing [m] beyond the steer tyre's outer edge (``path``: the axle's)."""
    g = motion.geometry
    corner = motion.tractor(np.array([[g.tractor_front, -path.side * g.half_width]]))[:, 0]
    _, n = path.frenet(corner[:, 0], corner[:, 1])
    return max(0.0, float(np.max(-path.side * n)) - g.steer_edge)


def trailer_frontal_swing(path: TurnPath, motion: Motion) -> float:
    """Semitrailer's front outside corner outside the tractor's outer side [m] (tractor frame)."""
    g = motion.geometry
    corner = motion.trailer(np.array([[g.trailer_front, -path.side * g.half_width]]))[:, 0]
    d = corner - motion.drive
    c, s = np.cos(motion.psi_1), np.sin(motion.psi_1)
    y_local = -s * d[:, 0] + c * d[:, 1]
    return max(0.0, float(np.max(-path.side * y_local)) - g.half_width)


def tail_swing_of(points: np.ndarray, side: float) -> float:
    """Outward swing [m] of a corner's path ``points`` (N, 2), entering along +x.

    The corner's first sample is its line before the turn; outwards is ``-side``
    in y (a left turn, ``side`` +1, swings the tail to the right).
    """
    y = np.asarray(points, dtype=float)[:, 1] * side
    return max(0.0, float(y[0] - np.min(y)))


def tail_swing(path: TurnPath, motion: Motion) -> float:
    """Tail swing of the semitrailer's rear outside corner [m]."""
    g = motion.geometry
    corner = motion.trailer(np.array([[g.trailer_rear, -path.side * g.half_width]]))[:, 0]
    return tail_swing_of(corner, path.side)
