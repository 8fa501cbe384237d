"""A path-following driver for the low-speed manoeuvres: the steer axle on the prescribed path.

The standards prescribe the path of a point of the tractor's front (the PBS
turn: the steer tyre's outer edge; the FHWA turn and J695's circle: the steer
axle's centre), not a steering input. The driver steers the front wheels so
that the steer axle's centre runs on the path, by the law of a front-axle
path follower (the road wheels along the path's heading a preview ahead, plus
the arc tangent of the lateral error over the speed; on an arc the preview
holds the axle ``PREVIEW u^2 / (GAIN R)`` outside it, about 3 cm in the PBS
turn), turning the wheels at a finite rate and never past their lock, and
holds the speed. He knows the
combination as every other driver of artic does (the docking driver,
:mod:`artic.validation.synthetic.driver`): its tractor sensor's place and
wheelbase from the vehicle file, and for a model behind a steering wheel, its
gear. The same driver drives KIN, the STM, the plant and the truth.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from artic.mjcf.interface import InitialState, wrap_angle
from artic.mjcf.vehicle import Vehicle
from artic.validation.pbs.paths import TurnPath

GAIN = 4.0
"""Lateral-error gain [1/s]: a 0.1 m error at 5 km/h turns the wheels by 16 deg."""

PREVIEW = 0.6
"""How far ahead the driver takes the path's heading [s of travel]: the time the
wheels need to turn to the arc's angle at :data:`RATE`."""

RATE = 0.6
"""Fastest road-wheel turn [rad/s]: 0.6 rad/s is 12 rad/s (two turns a
second) of steering wheel at a 21:1 gear, a driver turning in hand over hand."""


@dataclass
class PathDriver:
    """Steers the steer axle's centre along ``path`` at ``speed``.

    Parameters
    ----------
    vehicle : Vehicle
        What the driver knows: the tractor sensor's place, the steer axle's, the lock.
    path : TurnPath
        The steer axle's centre's path.
    speed : float
        Speed [m/s].
    dt : float
        The driver's step [s].
    """

    vehicle: Vehicle
    path: TurnPath
    speed: float
    dt: float = 0.01
    delta: float = 0.0

    def __post_init__(self) -> None:
        v = self.vehicle
        self.L1 = float(max(a.x for a in v.tractor_axles))
        self.lock = v.steering_for("mbd").delta_max
        self._s = 0.0

    def start(self) -> InitialState:
        """The start: steer axle at the path's start, straight, at speed."""
        v = self.vehicle
        x1 = v.sensor1[0] - self.L1  # the sensor from the steer axle, heading +x
        return InitialState(x1, v.sensor1[1], 0.0, 0.0, u1=self.speed)

    def steer_axle(self, obs: np.ndarray) -> tuple[float, float]:
        """Steer axle centre from an observation [m]."""
        v = self.vehicle
        c, s = math.cos(obs[2]), math.sin(obs[2])
        dx, dy = self.L1 - v.sensor1[0], -v.sensor1[1]
        return obs[0] + c * dx - s * dy, obs[1] + s * dx + c * dy

    def locate(self, obs: np.ndarray) -> tuple[float, float]:
        """The steer axle's station and offset to the left of the path [m].

        The driver keeps count of how far round the arc he is, so that a circle
        of more than half a turn is followed round.
        """
        x, y = self.steer_axle(obs)
        p = self.path
        turned = min(max((self._s - p.entry) / p.radius, 0.0), p.angle)
        s, n = p.frenet(np.array([x]), np.array([y]), turned)
        self._s = float(s[0])
        return self._s, float(n[0])

    def station(self, obs: np.ndarray) -> float:
        """The steer axle's station on the path [m]."""
        return self.locate(obs)[0]

    def command(self, obs: np.ndarray) -> float:
        """Road-wheel angle for the next step [rad]."""
        s, n = self.locate(obs)
        heading = float(self.path.pose(s + PREVIEW * self.speed)[2])
        want = float(wrap_angle(heading - float(obs[2]))) + math.atan2(-GAIN * n, self.speed)
        want = max(-self.lock, min(self.lock, want))
        step = RATE * self.dt
        self.delta += max(-step, min(step, want - self.delta))
        return self.delta


def drive_path(model, driver: PathDriver, forces=None, max_time: float = 300.0):
    """Drive ``model`` (the model protocol's calls) along the driver's path to its end.

    Parameters
    ----------
    model : object
        ``reset``, ``observe``, ``step(dt, delta, u1, u1_dot)`` (the truth's seat
        turns its steering wheel for ``delta`` through its own gear).
    driver : PathDriver
        The driver.
    forces : callable, optional
        ``forces()`` after each observation: the steer axle's wheel forces (K, 3) [N].
    max_time : float
        Longest drive [s].

    Returns
    -------
    t, obs, delta : ndarray
        Time [s], observations, road-wheel angle held from each sample [rad].
    f : ndarray or None
        ``forces()`` at each sample, (N, K, 3).
    """
    model.reset(driver.start())
    dt, u = driver.dt, driver.speed
    t, obs, delta, f = [], [], [], []
    for k in range(int(max_time / dt)):
        o = np.asarray(model.observe(), dtype=float)
        t.append(k * dt)
        obs.append(o)
        if forces is not None:
            f.append(np.array(forces(), dtype=float))
        d = driver.command(o)
        delta.append(d)
        if driver.station(o) >= driver.path.length:
            break
        model.step(dt, d, u, 0.0)
    return (np.array(t), np.array(obs), np.array(delta),
            np.array(f) if forces is not None else None)
