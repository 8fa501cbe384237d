"""Where every part of the combination was: the units' poses from the observed motion.

The low-speed measures need the paths of points the signals do not name
(the steer axle's centre, the body's corners, the semitrailer's axle group).
They follow from the tractor sensor's position, the two headings and the
vehicle's geometry, whichever model or log the motion came from:

- the tractor's frame has its origin at the drive axle's centre (the vehicle
  file's ``[tractor] sensor`` is measured from there); the steer axle is the
  tractor axle furthest forward, the fifth wheel ``L1c`` ahead of the origin;
- the semitrailer's frame has its origin at the kingpin, heading ``psi_2``;
  its axle group's centre is ``L2`` behind it (the middle axle of the
  gosar2022 tri-axle group: the point KIN's and J695's semitrailer wheelbase
  ends at);
- the bodies are :func:`artic.mjcf.outline.outline`'s boxes: the vehicle file
  holds the axles, tracks and the sensors, the outline module the front
  overhang (:data:`~artic.mjcf.outline.TRACTOR_FRONT_OVERHANG` ahead of the
  steer axle), the rear overhangs (the semitrailer's 13.6 m box
  :data:`~artic.mjcf.outline.KINGPIN_SETBACK` ahead of the kingpin, the
  tractor's frame :data:`~artic.mjcf.outline.TRACTOR_REAR_OVERHANG` behind its
  last axle) and the width (the widest track plus
  :data:`~artic.mjcf.outline.BODY_CLEARANCE` a side);
- the steer tyre's outer edge is half the tyre file's ``WIDTH`` outside the
  steer axle's track; a vehicle without a tyre file (one for KIN alone, such
  as the scale-model preset) has its edge at the track.

The semitrailer is placed at the kingpin the tractor's pose gives, so that a
model's hitch is rigid in the drawing even where the truth's fifth wheel has
lash; the semitrailer's own sensor is not used.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from artic.mjcf.outline import outline
from artic.mjcf.tir import read_tir
from artic.mjcf.vehicle import Vehicle

SPACING = 0.2
"""Spacing of the points along each body's outline [m]: a swept width measured
from them is at most ``SPACING**2 / (8 R)``, well under a millimetre, short of
the outline's own at a radius R of 5 m or more."""


@dataclass(frozen=True)
class Geometry:
    """The points of the combination the measures follow, in each unit's frame [m].

    Attributes
    ----------
    L1, L1c, L2 : float
        Steer axle, fifth wheel ahead of the drive axle; axle group behind the kingpin.
    steer_edge : float
        Lateral distance from the tractor's centre line to the steer tyre's outer edge.
    half_width : float
        Half the body's width.
    tractor_front, tractor_rear, trailer_front, trailer_rear : float
        Body ends along each unit's x (rear negative).
    """

    L1: float
    L1c: float
    L2: float
    steer_edge: float
    half_width: float
    tractor_front: float
    tractor_rear: float
    trailer_front: float
    trailer_rear: float

    @classmethod
    def of(cls, v: Vehicle) -> Geometry:
        """The geometry of vehicle ``v`` (see the module docstring for the sources)."""
        o = outline(v)
        front = max(v.tractor_axles, key=lambda a: a.x)
        tyre = v.tyre_file_for(front)
        width = read_tir(tyre).number("WIDTH", 0.315) if tyre else 0.0
        return cls(L1=float(front.x), L1c=v.L1c, L2=v.L2,
                   steer_edge=0.5 * front.track + 0.5 * width, half_width=0.5 * o.width,
                   tractor_front=o.tractor_front, tractor_rear=o.tractor_rear,
                   trailer_front=o.trailer_front, trailer_rear=o.trailer_rear)

    def box(self, unit: int) -> np.ndarray:
        """Points along unit ``unit``'s outline (1 the tractor, 2 the semitrailer), shape (M, 2)."""
        x0, x1 = ((self.tractor_rear, self.tractor_front) if unit == 1
                  else (self.trailer_rear, self.trailer_front))
        w = self.half_width
        nx = max(2, int(np.ceil((x1 - x0) / SPACING)) + 1)
        ny = max(2, int(np.ceil(2 * w / SPACING)) + 1)
        xs, ys = np.linspace(x0, x1, nx), np.linspace(-w, w, ny)
        return np.vstack([np.c_[xs, np.full(nx, -w)], np.c_[xs, np.full(nx, w)],
                          np.c_[np.full(ny, x0), ys], np.c_[np.full(ny, x1), ys]])


@dataclass(frozen=True)
class Motion:
    """The poses of both units over a run.

    Attributes
    ----------
    t : ndarray, shape (N,)
        Time [s].
    drive : ndarray, shape (N, 2)
        Tractor frame's origin (drive axle centre) [m].
    psi_1, psi_2 : ndarray, shape (N,)
        Headings [rad].
    geometry : Geometry
        Where the points lie in each unit.
    """

    t: np.ndarray
    drive: np.ndarray
    psi_1: np.ndarray
    psi_2: np.ndarray
    geometry: Geometry

    @classmethod
    def from_signals(cls, vehicle: Vehicle, t, x_1, y_1, psi_1, psi_2) -> Motion:
        """From the tractor sensor's position and both headings (the signal schema's)."""
        psi_1 = np.asarray(psi_1, dtype=float)
        sx, sy = vehicle.sensor1[0], vehicle.sensor1[1]
        c, s = np.cos(psi_1), np.sin(psi_1)
        drive = np.c_[np.asarray(x_1, float) - (c * sx - s * sy),
                      np.asarray(y_1, float) - (s * sx + c * sy)]
        return cls(np.asarray(t, float), drive, psi_1, np.asarray(psi_2, float),
                   Geometry.of(vehicle))

    @classmethod
    def from_observations(cls, vehicle: Vehicle, t, obs: np.ndarray) -> Motion:
        """From observations in ``OBSERVATION`` order."""
        obs = np.asarray(obs, dtype=float)
        return cls.from_signals(vehicle, t, obs[:, 0], obs[:, 1], obs[:, 2], obs[:, 8])

    def tractor(self, local: np.ndarray) -> np.ndarray:
        """World positions of tractor-frame points ``local`` (M, 2) at every sample, (N, M, 2)."""
        return _place(self.drive, self.psi_1, np.atleast_2d(local))

    @property
    def kingpin(self) -> np.ndarray:
        """The kingpin (N, 2) [m]."""
        return self.tractor(np.array([[self.geometry.L1c, 0.0]]))[:, 0]

    def trailer(self, local: np.ndarray) -> np.ndarray:
        """World positions of semitrailer-frame points ``local`` (M, 2), (N, M, 2)."""
        return _place(self.kingpin, self.psi_2, np.atleast_2d(local))

    @property
    def steer_axle(self) -> np.ndarray:
        """The steer axle's centre (N, 2) [m]."""
        return self.tractor(np.array([[self.geometry.L1, 0.0]]))[:, 0]

    @property
    def trailer_axle(self) -> np.ndarray:
        """The semitrailer axle group's centre (N, 2) [m]."""
        return self.trailer(np.array([[-self.geometry.L2, 0.0]]))[:, 0]

    def body_points(self) -> np.ndarray:
        """Both bodies' outline points at every sample, (N, M1 + M2, 2) [m]."""
        g = self.geometry
        return np.concatenate([self.tractor(g.box(1)), self.trailer(g.box(2))], axis=1)


def _place(origin: np.ndarray, psi: np.ndarray, local: np.ndarray) -> np.ndarray:
    c, s = np.cos(psi)[:, None], np.sin(psi)[:, None]
    x = origin[:, 0:1] + c * local[None, :, 0] - s * local[None, :, 1]
    y = origin[:, 1:2] + s * local[None, :, 0] + c * local[None, :, 1]
    return np.stack([x, y], axis=-1)
