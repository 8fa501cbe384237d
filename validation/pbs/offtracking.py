"""Off-tracking: how far inside the steer axle's path the semitrailer's axles run.

- **Steady off-tracking** (SAE J695, "Turning Ability and Off Tracking -
  Motor Vehicles"): on a circle driven until nothing changes, the steer
  axle's radius less the semitrailer axle group's, both about the circle's
  centre.
- **Low-speed off-tracking** of the FHWA's 90-degree turn: the largest
  distance, across the prescribed path, by which the semitrailer axle
  group's centre runs inside it.
The prescribed path is the steer axle's centre's; how closely a model's
steer axle followed it is :func:`path_error`.
"""

from __future__ import annotations

import numpy as np

from artic.validation.pbs.motion import Motion
from artic.validation.pbs.paths import TurnPath

STEADY_SHARE = 0.1
"""Share of a steady circle's samples, at its end, over which the radii are averaged."""


def steady_offtracking(centre: tuple[float, float], front: np.ndarray, rear: np.ndarray) -> float:
    """J695's steady off-tracking [m]: mean radius of ``front`` less that of ``rear`` (N, 2).

    Averaged over the last :data:`STEADY_SHARE` of the samples.
    """
    k = max(1, int(len(front) * STEADY_SHARE))
    rf = np.hypot(front[-k:, 0] - centre[0], front[-k:, 1] - centre[1])
    rr = np.hypot(rear[-k:, 0] - centre[0], rear[-k:, 1] - centre[1])
    return float(np.mean(rf) - np.mean(rr))


def max_offtracking(path: TurnPath, motion: Motion) -> float:
    """Largest distance [m] the semitrailer axle group's centre runs inside ``path``."""
    a = motion.trailer_axle
    _, n = path.frenet(a[:, 0], a[:, 1])
    return max(0.0, float(np.max(path.side * n)))


def path_error(path: TurnPath, motion: Motion) -> float:
    """Largest distance [m] of the steer axle's centre from ``path`` (the driver's error)."""
    a = motion.steer_axle
    _, n = path.frenet(a[:, 0], a[:, 1])
    return float(np.max(np.abs(n)))
