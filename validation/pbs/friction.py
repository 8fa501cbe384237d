"""Steer-tyre friction demand: how much of the road's grip the steer tyres use.

The largest, over the turn, of the steer axle's horizontal tyre force over
its wheel load, as a share of the road's peak friction coefficient [%].
The forces are a model's own: the multibody plant's tyre forces
(``force.AXLE.SIDE.{x,y,z}`` of :meth:`artic.plant.Plant.extras`); KIN has
none, and the STM's axle forces are not exposed through the model protocol,
so for both the measure is not available.
"""

from __future__ import annotations

import numpy as np

ROAD_FRICTION = 0.8
"""The road's peak friction coefficient the demand is a share of: the
performance-based standards' assessment road (a dry sealed road)."""


def friction_demand(forces: np.ndarray, mu: float = ROAD_FRICTION) -> float:
    """Largest steer-axle friction demand [%] from its wheels' forces.

    Parameters
    ----------
    forces : ndarray, shape (N, K, 3)
        World-frame force of each of the steer axle's K wheel ends at N samples [N].
    mu : float
        The road's peak friction coefficient [-].
    """
    f = np.asarray(forces, dtype=float)
    fx, fy, fz = f[..., 0].sum(axis=1), f[..., 1].sum(axis=1), f[..., 2].sum(axis=1)
    loaded = fz > 0.0
    if not loaded.any():
        return float("nan")
    return float(100.0 * np.max(np.hypot(fx[loaded], fy[loaded]) / fz[loaded]) / mu)
