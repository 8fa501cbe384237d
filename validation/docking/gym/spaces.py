"""The environment's observation vector and action scale, shared with the policy adapter.

Observation (:data:`OBSERVATION_NAMES`, :data:`OBSERVATION_UNITS`): the 13
measured signals of :data:`artic.mjcf.interface.OBSERVATION` as ``artic dock``
gives them to a controller (same sensors, noise and seeds), the steering wheel
from the CAN bus, and the three dock errors of
:meth:`artic.Controller.dock_errors` from those signals: 17 numbers, in the
yard's frame (the dock's face at ``x_dock``; see the scenario).

Action: two numbers in [-1, 1]. The first is the steering-wheel angle from its
centre (where the road wheels point straight) as a share of the wheel's angle
at the road wheels' lock on that side, the second the tractor's speed as a share of the
yard's limit :data:`artic.validation.docking.run.SPEED_MAX` (negative:
reverse). :class:`ActionScale` maps them both ways.

A policy has no "done" output: the run ends docked when the policy asks for
zero speed (:data:`STOP_SPEED`) within :data:`STOP_DISTANCE` of the face
(:func:`stopped_at_dock`), as a driver stops at the dock and sets the brake;
the reference controller asks exactly that when it is done.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from artic.mjcf.errors import UserError
from artic.mjcf.interface import OBSERVATION
from artic.mjcf.vehicle import Vehicle
from artic.validation.docking.controllers.base import Command, Controller, Observation
from artic.validation.docking.run import SPEED_MAX

_UNITS = {"x": "m", "y": "m", "psi": "rad", "v": "m/s", "r": "rad/s", "gamma": "rad"}

OBSERVATION_NAMES: tuple[str, ...] = (*OBSERVATION, "delta_h", "dock_distance",
                                      "dock_lateral", "dock_heading")
"""The observation vector's entries, in order."""

OBSERVATION_UNITS: tuple[str, ...] = (
    *(_UNITS[name.split("_")[0]] for name in OBSERVATION), "rad", "m", "m", "rad")
"""Their units."""

STOP_SPEED = 0.01
"""A commanded speed below this [m/s] asks the tractor to stop."""

STOP_DISTANCE = 1.0
"""Within this distance of the dock's face [m] a stop ends the run (the driving
test's 0.91 m tolerance, rounded up)."""


def observation_vector(obs: Observation, ctrl: Controller) -> np.ndarray:
    """The 17 numbers of :data:`OBSERVATION_NAMES` [m, rad, m/s, rad/s].

    Parameters
    ----------
    obs : Observation
        What the sensors report.
    ctrl : Controller
        A controller reset on the run's task: its :meth:`~artic.Controller.dock_errors`.

    Examples
    --------
    >>> import numpy as np
    >>> import artic
    >>> from artic.gym import observation_vector
    >>> from artic.validation.docking.controllers.base import Observation, Task
    >>> from artic.validation.docking.scenarios import make_yard
    >>> vehicle = artic.load_vehicle("gosar2022-unloaded")
    >>> ctrl = artic.Controller()
    >>> ctrl.reset(Task(vehicle, make_yard(vehicle), None, 0.1, 1.0, 1.67, 0.5, 6.3))
    >>> vector = observation_vector(Observation(0.0, np.zeros(13), 0.0), ctrl)
    >>> vector.shape  # 13 signals, the steering wheel, 3 dock errors
    (17,)
    """
    errors = ctrl.dock_errors(obs)
    out = np.empty(len(OBSERVATION_NAMES))
    out[:13] = obs.signals
    out[13] = obs.delta_h
    out[14:] = errors
    return out


@dataclass(frozen=True)
class ActionScale:
    """The action's limits for one vehicle.

    The steering share is scaled on each side to that side's lock: the vehicle's
    steering map need not be symmetric about its centre (its offset, its
    linkage's non-linear term), so +1 is the left lock and -1 the right lock.

    Parameters
    ----------
    offset : float
        Steering wheel at the road wheels' centre [rad].
    left : float
        Steering wheel from its centre to the left lock [rad], positive.
    right : float
        Steering wheel from its centre to the right lock [rad], positive.
    speed : float
        The yard's speed limit [m/s].

    Examples
    --------
    Full left lock, reversing at half the yard's limit:

    >>> import numpy as np
    >>> import artic
    >>> from artic.gym import ActionScale
    >>> scale = ActionScale.of(artic.load_vehicle("gosar2022-unloaded"))
    >>> cmd = scale.command(np.array([1.0, -0.5]))
    >>> bool(cmd.delta_h > scale.offset), round(cmd.u1, 3), scale.action(cmd).round(6).tolist()
    (True, -0.833, [1.0, -0.5])
    """

    offset: float
    left: float
    right: float
    speed: float

    @classmethod
    def of(cls, vehicle: Vehicle) -> ActionScale:
        """The scale of ``vehicle``: its steering map (KIN's, eq. (3)) and the yard's limit."""
        steering = vehicle.steering_for("kin")
        road = steering
        offset = float(road.steering_wheel(0.0))
        left = float(road.steering_wheel(steering.delta_max)) - offset
        right = offset - float(road.steering_wheel(-steering.delta_max))
        return cls(offset, left, right, SPEED_MAX)

    def command(self, action: np.ndarray) -> Command:
        """The command of an action (clipped to [-1, 1]).

        Raises
        ------
        UserError
            For an action of another shape than ``(2,)``, or not finite.
        """
        a = np.asarray(action, dtype=float)
        if a.shape != (2,):
            raise UserError(f"action of shape {a.shape}: expected shape (2,), the steering "
                            "wheel and the speed, each in [-1, 1]")
        steer, speed = float(a[0]), float(a[1])
        if not (math.isfinite(steer) and math.isfinite(speed)):
            raise UserError(f"action {a.tolist()}: not finite; expected the steering wheel "
                            "and the speed, each in [-1, 1]")
        steer, speed = min(max(steer, -1.0), 1.0), min(max(speed, -1.0), 1.0)  # np.clip's
        side = self.left if steer >= 0.0 else self.right
        return Command(self.offset + steer * side, speed * self.speed)

    def action(self, cmd: Command) -> np.ndarray:
        """The action of a command (the inverse of :meth:`command`, clipped to [-1, 1])."""
        turn = float(cmd.delta_h) - self.offset
        a = np.array([turn / (self.left if turn >= 0.0 else self.right),
                      float(cmd.u1) / self.speed])
        return np.clip(a, -1.0, 1.0)


def stopped_at_dock(cmd: Command, dock_distance: float) -> bool:
    """Whether ``cmd`` ends the run: zero speed within :data:`STOP_DISTANCE` of the face.

    Parameters
    ----------
    cmd : Command
        The command.
    dock_distance : float
        The rear's measured distance short of the face [m].
    """
    return abs(float(cmd.u1)) < STOP_SPEED and abs(dock_distance) < STOP_DISTANCE and \
        math.isfinite(dock_distance)
