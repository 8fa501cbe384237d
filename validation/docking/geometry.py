"""Where each part of the combination is, and whether its outline touches an obstacle.

Every point the docking benchmark uses lies on a unit's centre line, and
follows from one pose of that unit:

- tractor: its drive axle (the plant's and the outline's origin), KIN's
  reference point ``x_ref`` ahead of it (KIN's equivalent rear axle, see
  :func:`artic.reduced.kinematic.wheelbases`), the kingpin ``L1c`` ahead of it,
  and its sensor;
- semitrailer: the kingpin (its origin), KIN's equivalent axle ``L2`` behind
  it, its rear end :attr:`~artic.mjcf.outline.Outline.rear_behind_kingpin`
  behind it, and its sensor.

Obstacles are rectangles aligned with the yard's axes (the dock row runs
along y). The outlines are :func:`artic.mjcf.outline.outline`'s boxes, so
the collision test sees what the plant and the recordings draw.
:func:`first_hit` is the separating-axis test of each unit's box against each
obstacle, compiled with numba because the planner calls it for every motion
it tries and the run for every plant step.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from artic.mjcf.interface import OBS_INDEX
from artic.mjcf.outline import outline
from artic.mjcf.vehicle import Vehicle
from artic.reduced.control import KIN
from artic.reduced.kinematic import wheelbases

_X1, _Y1, _PSI1, _X2, _Y2, _PSI2 = (OBS_INDEX[c] for c in ("x_1", "y_1", "psi_1",
                                                             "x_2", "y_2", "psi_2"))
_POSE = ((_X1, _Y1, _PSI1), (_X2, _Y2, _PSI2))


@dataclass(frozen=True)
class Box:
    """An obstacle: a rectangle aligned with the yard's axes [m].

    Parameters
    ----------
    name : str
        What it is (``dock``, ``neighbour-left``, ...), for a failure's reason.
    x_min, x_max, y_min, y_max : float
        Its extent in the yard.
    """

    name: str
    x_min: float
    x_max: float
    y_min: float
    y_max: float

    def as_row(self) -> tuple[float, float, float, float]:
        """Centre and half sizes ``(cx, cy, hx, hy)`` [m], as :func:`first_hit` takes them."""
        return ((self.x_min + self.x_max) / 2, (self.y_min + self.y_max) / 2,
                (self.x_max - self.x_min) / 2, (self.y_max - self.y_min) / 2)


def box_array(boxes: tuple[Box, ...]) -> np.ndarray:
    """The obstacles as rows ``(cx, cy, hx, hy)`` [m], shape (n, 4)."""
    return np.array([b.as_row() for b in boxes], dtype=float).reshape(-1, 4)


@dataclass(frozen=True)
class Frames:
    """The lengths that place every point of a vehicle, from its parameter file [m].

    Attributes
    ----------
    kin : KIN
        The vehicle's KIN (:class:`artic.reduced.control.KIN`).
    P : ndarray
        KIN's ``[L1, L1c, L2]`` (equivalent wheelbases).
    x_ref : float
        KIN's reference point ahead of the drive axle.
    L1c : float
        Kingpin ahead of the drive axle (the plant's).
    rear : float
        Semitrailer rear behind the kingpin.
    tractor_box, trailer_box : ndarray
        ``(centre x, half length, half width)`` of each unit's outline in its own frame.
    s1, s2 : ndarray
        Sensors in their unit's frame (tractor from the drive axle, semitrailer
        from the kingpin).
    sensor_yaw : tuple of float
        Mounting yaw of each sensor [rad]; the reported heading includes it.
    """

    kin: KIN
    P: np.ndarray
    x_ref: float
    L1c: float
    rear: float
    tractor_box: np.ndarray
    trailer_box: np.ndarray
    s1: np.ndarray
    s2: np.ndarray
    sensor_yaw: tuple[float, float]

    @classmethod
    def of(cls, v: Vehicle) -> Frames:
        """The frames of vehicle ``v``."""
        o = outline(v)
        kin = KIN(v)
        return cls(kin=kin, P=kin.P, x_ref=wheelbases(v)[2], L1c=v.L1c,
                   rear=o.rear_behind_kingpin,
                   tractor_box=np.array([(o.tractor_front + o.tractor_rear) / 2,
                                         (o.tractor_front - o.tractor_rear) / 2, o.width / 2]),
                   trailer_box=np.array([(o.trailer_front + o.trailer_rear) / 2,
                                         (o.trailer_front - o.trailer_rear) / 2, o.width / 2]),
                   s1=np.array(v.sensor1[:2], dtype=float),
                   s2=np.array(v.sensor2[:2], dtype=float),
                   sensor_yaw=(v.sensor1_yaw, v.sensor2_yaw))

    # ---------------------------------------------------------------- KIN state
    def kin_from_rear(self, x_r, y_r, psi_2, gamma) -> np.ndarray:
        """KIN state ``[X, Y, psi_1, gamma]`` from the semitrailer's rear pose [m, rad]."""
        xk = x_r + self.rear * np.cos(psi_2)
        yk = y_r + self.rear * np.sin(psi_2)
        psi_1 = psi_2 + gamma
        L1c_eq = self.kin.params.L1c
        return np.array([xk - L1c_eq * np.cos(psi_1), yk - L1c_eq * np.sin(psi_1), psi_1, gamma])

    def kingpin(self, kin: np.ndarray) -> tuple:
        """Kingpin ``(x, y)`` of KIN states (..., 4) [m]."""
        kin = np.asarray(kin)
        L1c_eq = self.kin.params.L1c
        return (kin[..., 0] + L1c_eq * np.cos(kin[..., 2]),
                kin[..., 1] + L1c_eq * np.sin(kin[..., 2]))

    def trailer_axle(self, kin: np.ndarray) -> np.ndarray:
        """KIN's semitrailer axle ``(x, y, psi_2)`` of KIN states (..., 4) [m, m, rad]."""
        kin = np.asarray(kin)
        xk, yk = self.kingpin(kin)
        psi_2 = kin[..., 2] - kin[..., 3]
        L2 = self.kin.params.L2
        return np.stack([xk - L2 * np.cos(psi_2), yk - L2 * np.sin(psi_2), psi_2],
                        axis=-1)

    def rear_of_kin(self, kin: np.ndarray) -> np.ndarray:
        """Semitrailer rear ``(x, y, psi_2)`` of KIN states (..., 4) [m, m, rad]."""
        kin = np.asarray(kin)
        xk, yk = self.kingpin(kin)
        psi_2 = kin[..., 2] - kin[..., 3]
        return np.stack([xk - self.rear * np.cos(psi_2), yk - self.rear * np.sin(psi_2), psi_2],
                        axis=-1)

    def unit_poses_of_kin(self, kin: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Unit poses ``(n, 3)`` of KIN states ``(n, 4)``: the outlines' origins."""
        kin = np.atleast_2d(kin)
        c1, s1 = np.cos(kin[:, 2]), np.sin(kin[:, 2])
        tractor = np.column_stack([kin[:, 0] - self.x_ref * c1, kin[:, 1] - self.x_ref * s1,
                                   kin[:, 2]])
        xk, yk = self.kingpin(kin)
        trailer = np.column_stack([xk, yk, kin[:, 2] - kin[:, 3]])
        return tractor, trailer

    # ---------------------------------------------------------------- sensors
    def unit_poses_of_signals(self, obs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Drive-axle and kingpin poses ``(n, 3)`` from signals ``(n, 13)`` (``OBSERVATION``).

        Each unit from its own sensor: position minus the sensor's offset,
        heading minus its mounting yaw.
        """
        return _unit_poses(np.atleast_2d(np.asarray(obs, dtype=float)), self._mounts)

    def first_hit_of_signals(self, obs: np.ndarray, boxes: np.ndarray) -> tuple[int, int, int]:
        """:func:`first_hit` of the poses of signals ``(n, 13)``, in one compiled call.

        What ``first_hit(*self.unit_poses_of_signals(obs), self.tractor_box,
        self.trailer_box, boxes)`` returns: a run tests the outlines of every
        plant step of a sample this way.
        """
        return _hit_of_signals(np.atleast_2d(np.asarray(obs, dtype=float)), self._mounts,
                               self.tractor_box, self.trailer_box, boxes)

    @functools.cached_property
    def _mounts(self) -> np.ndarray:
        """The sensors' offsets and yaws ``(s1x, s1y, s2x, s2y, yaw_1, yaw_2)`` [m, rad]."""
        return np.array([*self.s1[:2], *self.s2[:2], *self.sensor_yaw], dtype=float)

    def _pose_of_signals(self, obs: np.ndarray, unit: int) -> tuple[float, float, float]:
        """One unit's pose ``(x, y, psi)`` (0 tractor, 1 semitrailer) from one set of signals.

        :meth:`unit_poses_of_signals`' first row, to the bit, in scalars.
        """
        obs = np.asarray(obs, dtype=float).reshape(-1)  # one row, or the first of several
        s = self.s2 if unit else self.s1
        ix, iy, ipsi = _POSE[unit]
        psi = float(obs[ipsi]) - self.sensor_yaw[unit]
        c, sn = math.cos(psi), math.sin(psi)
        return (float(obs[ix]) - (c * float(s[0]) - sn * float(s[1])),
                float(obs[iy]) - (sn * float(s[0]) + c * float(s[1])), psi)

    def kin_of_signals(self, obs: np.ndarray) -> np.ndarray:
        """KIN state ``[X, Y, psi_1, gamma]`` from one set of signals.

        The tractor's point and heading from its sensor, the articulation as
        the signals give it (the heading difference of the two units).
        """
        x, y, psi_1 = self._pose_of_signals(obs, 0)
        gamma = float(obs[OBS_INDEX["gamma"]])
        return np.array([x + self.x_ref * math.cos(psi_1), y + self.x_ref * math.sin(psi_1),
                         psi_1, gamma])

    def rear_of_signals(self, obs: np.ndarray) -> np.ndarray:
        """Semitrailer rear ``(x, y, psi_2)`` from one set of signals, by its own sensor."""
        xk, yk, psi_2 = self._pose_of_signals(obs, 1)
        return np.array([xk - self.rear * math.cos(psi_2), yk - self.rear * math.sin(psi_2),
                         psi_2])

    def trailer_axle_of_signals(self, obs: np.ndarray) -> np.ndarray:
        """KIN's semitrailer axle ``(x, y, psi_2)`` from one set of signals, by its own sensor."""
        xk, yk, psi_2 = self._pose_of_signals(obs, 1)
        L2 = self.kin.params.L2
        return np.array([xk - L2 * math.cos(psi_2), yk - L2 * math.sin(psi_2), psi_2])

    def tractor_sensor_of_kin(self, kin: np.ndarray) -> tuple[float, float]:
        """The tractor sensor's position for a KIN state [m] (to place the plant)."""
        tractor, _ = self.unit_poses_of_kin(kin)
        x, y, psi = tractor[0]
        c, s = math.cos(psi), math.sin(psi)
        return (float(x + c * self.s1[0] - s * self.s1[1]),
                float(y + s * self.s1[0] + c * self.s1[1]))


@njit(cache=True)
def _unit_poses(obs, mounts):
    """:meth:`Frames.unit_poses_of_signals` compiled, with :attr:`Frames._mounts`.

    The same operations in the same order as numpy's element-wise ones (numba
    contracts no multiply-add and takes the C library's sine and cosine, as
    numpy does), so the poses are numpy's to the bit.
    """
    tractor = np.empty((obs.shape[0], 3))
    trailer = np.empty((obs.shape[0], 3))
    _poses_of_unit(obs, _X1, _Y1, _PSI1, mounts[0], mounts[1], mounts[4], tractor)
    _poses_of_unit(obs, _X2, _Y2, _PSI2, mounts[2], mounts[3], mounts[5], trailer)
    return tractor, trailer


@njit(cache=True, inline="always")
def _poses_of_unit(obs, ix, iy, ipsi, sx, sy, yaw, out):
    """One unit's poses into ``out`` from its sensor's columns, offset and yaw."""
    for k in range(obs.shape[0]):
        psi = obs[k, ipsi] - yaw
        c, sn = math.cos(psi), math.sin(psi)
        out[k, 0] = obs[k, ix] - (c * sx - sn * sy)
        out[k, 1] = obs[k, iy] - (sn * sx + c * sy)
        out[k, 2] = psi


@njit(cache=True)
def _hit_of_signals(obs, mounts, tractor_box, trailer_box, boxes):
    """:meth:`Frames.first_hit_of_signals` compiled."""
    tractor, trailer = _unit_poses(obs, mounts)
    return first_hit(tractor, trailer, tractor_box, trailer_box, boxes)


@njit(cache=True)
def _obb_hits_aabb(x, y, psi, cx_local, hx, hy, bx, by, bhx, bhy) -> bool:
    """Whether a unit's box overlaps an axis-aligned box (separating axes).

    The unit at pose ``x, y, psi`` has its box's centre ``cx_local`` ahead of
    its origin and half sizes ``hx, hy``; the obstacle its centre ``bx, by``
    and half sizes ``bhx, bhy``.
    """
    c, s = math.cos(psi), math.sin(psi)
    dx = x + c * cx_local - bx
    dy = y + s * cx_local - by
    if abs(dx) > bhx + hx * abs(c) + hy * abs(s):
        return False
    if abs(dy) > bhy + hx * abs(s) + hy * abs(c):
        return False
    if abs(dx * c + dy * s) > hx + bhx * abs(c) + bhy * abs(s):
        return False
    if abs(-dx * s + dy * c) > hy + bhx * abs(s) + bhy * abs(c):
        return False
    return True


@njit(cache=True)
def first_hit(tractor, trailer, tractor_box, trailer_box, boxes):
    """The first sample at which a unit's outline overlaps an obstacle.

    Parameters
    ----------
    tractor, trailer : ndarray, shape (n, 3)
        Drive-axle and kingpin poses ``(x, y, psi)`` [m, m, rad].
    tractor_box, trailer_box : ndarray, shape (3,)
        ``(centre x, half length, half width)`` in the unit's frame [m].
    boxes : ndarray, shape (m, 4)
        Obstacles ``(cx, cy, hx, hy)`` [m].

    Returns
    -------
    sample, box, unit : int
        Indices of the sample and the obstacle, and 0 for the tractor or 1
        for the semitrailer; ``(-1, -1, -1)`` when nothing touches.
    """
    for k in range(tractor.shape[0]):
        for j in range(boxes.shape[0]):
            bx, by, bhx, bhy = boxes[j, 0], boxes[j, 1], boxes[j, 2], boxes[j, 3]
            if _obb_hits_aabb(tractor[k, 0], tractor[k, 1], tractor[k, 2], tractor_box[0],
                              tractor_box[1], tractor_box[2], bx, by, bhx, bhy):
                return k, j, 0
            if _obb_hits_aabb(trailer[k, 0], trailer[k, 1], trailer[k, 2], trailer_box[0],
                              trailer_box[1], trailer_box[2], bx, by, bhx, bhy):
                return k, j, 1
    return -1, -1, -1


@njit(cache=True)
def swept_cells(tractor, trailer, tractor_box, trailer_box, x0, y0, cell, nx, ny):
    """Cells of a grid that the units' outlines cover at any of the given poses.

    Parameters
    ----------
    tractor, trailer : ndarray, shape (n, 3)
        Unit poses, as :func:`first_hit` takes them.
    tractor_box, trailer_box : ndarray, shape (3,)
        The outlines.
    x0, y0, cell : float
        Grid origin and cell size [m].
    nx, ny : int
        Grid size.

    Returns
    -------
    ndarray of bool, shape (nx, ny)
        Whether a cell's centre lay inside an outline.
    """
    grid = np.zeros((nx, ny), dtype=np.bool_)
    for k in range(tractor.shape[0]):
        for u in range(2):
            pose = tractor[k] if u == 0 else trailer[k]
            bx = tractor_box if u == 0 else trailer_box
            c, s = math.cos(pose[2]), math.sin(pose[2])
            cx = pose[0] + c * bx[0]
            cy = pose[1] + s * bx[0]
            ex = bx[1] * abs(c) + bx[2] * abs(s)
            ey = bx[1] * abs(s) + bx[2] * abs(c)
            i0 = max(0, int((cx - ex - x0) / cell))
            i1 = min(nx - 1, int((cx + ex - x0) / cell) + 1)
            j0 = max(0, int((cy - ey - y0) / cell))
            j1 = min(ny - 1, int((cy + ey - y0) / cell) + 1)
            for i in range(i0, i1 + 1):
                px = x0 + (i + 0.5) * cell - cx
                for j in range(j0, j1 + 1):
                    py = y0 + (j + 0.5) * cell - cy
                    if abs(px * c + py * s) <= bx[1] and abs(-px * s + py * c) <= bx[2]:
                        grid[i, j] = True
    return grid


@njit(cache=True)
def first_hits(tractor, trailer, tractor_box, trailer_box, boxes):
    """:func:`first_hit`'s sample for each of a batch of trajectories.

    Parameters
    ----------
    tractor, trailer : ndarray, shape (batch, n, 3)
        Drive-axle and kingpin poses of each trajectory [m, m, rad].
    tractor_box, trailer_box, boxes : ndarray
        As :func:`first_hit` takes them.

    Returns
    -------
    ndarray of int, shape (batch,)
        The first sample at which a unit of the trajectory touches an
        obstacle, ``-1`` where none does.
    """
    out = np.empty(tractor.shape[0], dtype=np.int64)
    for b in range(tractor.shape[0]):
        out[b] = first_hit(tractor[b], trailer[b], tractor_box, trailer_box, boxes)[0]
    return out
