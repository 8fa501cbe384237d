"""Points of the semitrailer, from the signals of its own sensor.

A point on the semitrailer's centre line lies ``x`` [m] along its own frame,
whose origin is the kingpin (rear negative, :mod:`artic.mjcf.vehicle`). Its
position in the yard follows from the sensor's position ``(x_2, y_2)`` and
the semitrailer's heading ``psi_2`` with the sensor's lever arm ``sensor2``:

    p = (x_2, y_2) + R(psi_2) (x - x_s2, -y_s2)

The same construction serves a measured log and a model's run, so that an
error between the two is the error of one body point. ``psi_2`` is taken as
the semitrailer's heading: a sensor's mounting yaw (a fraction of a degree)
moves a point 10 m away by a few centimetres at most, and the measured and
the modelled point alike.
"""

from __future__ import annotations

import numpy as np

from artic.mjcf.outline import outline
from artic.mjcf.vehicle import Vehicle


def trailer_point(vehicle: Vehicle, x: float, x_2: np.ndarray, y_2: np.ndarray,
                  psi_2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Yard position of the semitrailer's centre-line point ``x`` behind the kingpin [m].

    Parameters
    ----------
    vehicle : Vehicle
        For the sensor's lever arm ``sensor2``.
    x : float
        The point along the semitrailer's frame, from the kingpin, forward positive [m].
    x_2, y_2, psi_2 : ndarray
        The semitrailer sensor's position [m] and the semitrailer's heading [rad].

    Returns
    -------
    x, y : ndarray
        The point in the yard [m].
    """
    psi = np.asarray(psi_2, dtype=float)
    dx, dy = x - vehicle.sensor2[0], -vehicle.sensor2[1]
    c, s = np.cos(psi), np.sin(psi)
    return np.asarray(x_2, dtype=float) + c * dx - s * dy, \
        np.asarray(y_2, dtype=float) + s * dx + c * dy


def axle_x(vehicle: Vehicle) -> float:
    """The semitrailer's axle-group centre, ``-L2`` from the kingpin [m]."""
    return -float(vehicle.L2)


def rear_x(vehicle: Vehicle) -> float:
    """The semitrailer's rear edge from the kingpin, from :mod:`artic.mjcf.outline` [m]."""
    return float(outline(vehicle).trailer_rear)
