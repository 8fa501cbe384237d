"""The controller interface: observe the sensors, command the steering wheel and the speed.

A controller is a class with a no-argument constructor and two methods:

- ``reset(task)`` before each run, with the :class:`Task`: the vehicle's
  parameter file (what a controller may be designed on), the yard, the
  planner's path and the sample period;
- ``command(obs)`` every ``task.dt`` (10 Hz), with an :class:`Observation`:
  the signals of the synthetic campaign's sensors, with their noise
  (RTK/INS poses, velocities and yaw rates of both units, the articulation
  from the two headings, the steering wheel from the CAN bus; with ``artic
  dock --sensors tractor`` or ``camera``, the semitrailer's channels and the
  articulation are the estimator's, :mod:`artic.validation.docking.estimator`).
  It returns a :class:`Command`: the steering-wheel angle, the tractor's
  speed, and whether it has finished.

What a controller intends travels with its command, for the recording, and
is optional: ``Command.horizon``, the path it predicts for the point it
steers (the MPC's predicted horizon; the reference controller's prediction
of its own closed loop), and ``Command.reference``, the plan's points it
tracks (the point it compares itself with now, then those its horizon aims
at). A controller that gives neither still runs, scores and records.

A controller never sees the plant's state. :class:`Controller` is a base
with the helpers most controllers want: where the semitrailer's rear is by
its sensor, its errors at the dock, and the steering wheel for a road-wheel
angle through the vehicle file's steering map (KIN's, eq. (3)).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from artic.mjcf.interface import OBS_INDEX, wrap_angle
from artic.mjcf.vehicle import Vehicle
from artic.validation.docking.geometry import Frames
from artic.validation.docking.planner import Plan, steady_delta
from artic.validation.docking.scenarios import Yard


@dataclass(frozen=True)
class Observation:
    """What the sensors report at one sample.

    Parameters
    ----------
    t : float
        Time since the start [s].
    signals : ndarray, shape (13,)
        Measured signals in :data:`artic.mjcf.interface.OBSERVATION` order
        (``x_1, y_1, psi_1, v_x_1, v_y_1, r_1``, the same ``_2`` for the
        semitrailer's sensor, ``gamma``) [m, rad, m/s, rad/s]. With the
        tractor-only sensor sets the semitrailer's and ``gamma`` are the
        estimator's (:class:`artic.validation.docking.sensing.EstimatedStream`).
    delta_h : float
        Steering-wheel angle from the CAN bus [rad].
    """

    t: float
    signals: np.ndarray
    delta_h: float

    def __getitem__(self, name: str) -> float:
        """One signal by its schema name, e.g. ``obs["gamma"]``."""
        return float(self.signals[OBS_INDEX[name]])


@dataclass(frozen=True)
class Command:
    """What a controller asks for until its next sample.

    Parameters
    ----------
    delta_h : float
        Steering-wheel angle [rad] (offset included, as the CAN bus reports it).
    u1 : float
        Tractor speed [m/s]; negative reverses.
    done : bool
        The controller has finished (docked, or given up): the run stops it
        and scores where it stands.
    horizon : ndarray, optional
        The controller's predicted path of the point it steers by (the
        semitrailer axle reversing), rows ``(x, y)`` [m], now first, for the
        recording.
    reference : ndarray, optional
        The plan's points the controller tracks, rows ``(x, y)`` [m]: first
        the one it compares itself with now, then those its horizon aims at,
        for the recording.

    See Also
    --------
    artic.Controller : the base whose ``command`` returns one.
    artic.KIN : the kinematic model a controller predicts with.
    artic.Plant : the multibody plant the command drives.

    Examples
    --------
    Reverse at 1 m/s with the steering wheel a quarter turn to the left:

    >>> import math
    >>> import artic
    >>> command = artic.Command(delta_h=math.radians(90.0), u1=-1.0)
    >>> command.u1 < 0, command.done
    (True, False)
    """

    delta_h: float
    u1: float
    done: bool = False
    horizon: np.ndarray | None = None
    reference: np.ndarray | None = None


@dataclass(frozen=True)
class Task:
    """What a controller is told before a run.

    Parameters
    ----------
    vehicle : Vehicle
        The parameter file: geometry, steering map, limits.
    yard : Yard
        The dock and the obstacles.
    plan : Plan or None
        The planner's path, when one was made.
    dt : float
        Sample period [s].
    speed : float
        The yard's cruising speed in reverse [m/s], positive.
    speed_max : float
        The speed limit either way [m/s]; faster commands are held to it.
    accel_max : float
        How fast the speed follows a command [m/s^2].
    steer_rate : float
        How fast the steering wheel follows a command [rad/s].
    """

    vehicle: Vehicle
    yard: Yard
    plan: Plan | None
    dt: float
    speed: float
    speed_max: float
    accel_max: float
    steer_rate: float


class Controller:
    """Base of the docking controllers; subclasses write :meth:`command`.

    See Also
    --------
    artic.Command : what :meth:`command` returns.
    artic.load_vehicle : the vehicle the controller is told.
    artic.KIN : the kinematic model a controller predicts with.
    artic.STM : the single-track model, with tyres and inertia.

    Examples
    --------
    A controller that reverses straight back, with the helpers of the base class
    (``artic dock --controller my_module:Straight`` runs it):

    >>> import artic
    >>> class Straight(artic.Controller):
    ...     name = "straight"
    ...     def command(self, obs):
    ...         distance, lateral, heading = self.dock_errors(obs)
    ...         return artic.Command(self.steering_wheel(0.0), u1=-1.0, done=distance < 0.1)
    >>> from artic.validation.docking.controllers.base import Observation, Task
    >>> from artic.validation.docking.scenarios import make_yard
    >>> vehicle = artic.load_vehicle("gosar2022-unloaded")
    >>> controller = Straight()
    >>> controller.reset(Task(vehicle, make_yard(vehicle), None, dt=0.1, speed=1.0,
    ...                       speed_max=2.0, accel_max=0.5, steer_rate=1.0))
    >>> import numpy as np
    >>> signals = np.zeros(13)  # both units at the origin, heading 0 [m, rad]
    >>> command = controller.command(Observation(t=0.0, signals=signals, delta_h=0.0))
    >>> command.u1, command.done
    (-1.0, False)
    """

    name = "controller"

    requires: tuple[tuple[str, str], ...] = ()
    """Modules the controller imports in its runs, each with how to install it, e.g.
    ``(("casadi", 'pip install "artic[mpc]"'),)``: ``artic dock`` checks them before any
    run starts (:func:`artic.validation.docking.controllers.load`)."""

    def reset(self, task: Task) -> None:
        """Start a run: keep the task and the vehicle's frames and steering map."""
        self.task = task
        self.vehicle = task.vehicle
        self.frames = Frames.of(task.vehicle)
        self.steering = task.vehicle.steering_for("kin")

    def command(self, obs: Observation) -> Command:
        """The command for the next sample period."""
        raise NotImplementedError(f"{type(self).__name__} must define command(obs)")

    # ------------------------------------------------------------ helpers
    def rear(self, obs: Observation) -> np.ndarray:
        """Semitrailer rear ``(x, y, psi_2)`` by its sensor [m, m, rad]."""
        return self.frames.rear_of_signals(obs.signals)

    def dock_errors(self, obs: Observation) -> tuple[float, float, float]:
        """The rear's distance to the face, offset from the door's centre line, and heading.

        Returns
        -------
        distance, lateral, heading : float
            [m] (positive: short of the face), [m] (positive: left of the
            line, seen from the dock), [rad] (zero: square to the dock).
        """
        x, y, psi = self.rear(obs)
        yard = self.task.yard
        return float(x - yard.x_dock), float(y - yard.y_dock), float(wrap_angle(float(psi)))

    def steering_wheel(self, delta: float) -> float:
        """Steering-wheel angle for road-wheel angle ``delta`` [rad], within the lock."""
        d = self.vehicle.steering.delta_max
        return float(self.steering.steering_wheel(min(max(float(delta), -d), d)))

    def road_wheel(self, delta_h: float) -> float:
        """Road-wheel angle of a steering-wheel angle [rad] (the vehicle file's map)."""
        return float(self.steering.road_wheel(delta_h))


    def steady_delta(self, gamma: float) -> float:
        """KIN's road-wheel angle that holds articulation ``gamma`` [rad] steady [rad].

        ``gamma_dot = 0`` in eq. (1), in either direction of travel
        (:func:`artic.validation.docking.planner.steady_delta`).
        """
        return float(steady_delta(gamma, self.frames.P))
