"""What a yard does to a docking run that the design did not see: road, slope and actuators.

The robustness sweeps (:mod:`artic.validation.docking.sweep`) vary these one
at a time; :func:`artic.validation.docking.run.drive` takes each as a keyword
whose default is today's benchmark, bit for bit:

- **road friction** (:func:`road`): a factor on the tyres' friction, dry
  asphalt 1.0, wet about 0.7, packed snow about 0.3. It multiplies the
  Magic Formula's friction scaling factors ``LMUX`` and ``LMUY`` of every
  tyre, on top of any scaling the vehicle file carries (``[tyre.scaling]``),
  so the peaks of the longitudinal and lateral force (``D = mu Fz``, with
  ``mu = (PDY1 + PDY2 dfz) LMUY``) fall by the factor while the cornering
  stiffness ``K_y`` (which carries no ``LMUY``) stays: on a slippery yard the
  tyres saturate earlier, not softer. The benchmark's plant follows the
  commanded speed with a servo on the tractor's axis, its wheels rolling free
  (``Plant(speed="follow")``), so the factor limits the cornering forces, not
  traction or braking;
- **grade** (:func:`road`): the yard's slope along the dock's approach, in per
  cent. The dock faces +x and the approach runs along the yard's x-axis, so
  a grade is the plant's ``[plant] grade`` (+x uphill,
  :func:`artic.mjcf.builder.gravity` tilts the model's gravity): a
  **positive grade falls towards the dock** (a depressed dock approach, the
  common one; a combination reversing onto the dock rolls downhill), a
  negative one climbs to it. ``theta = atan(grade / 100)``;
- **actuator delay** (:class:`ActuatorDelay`): the time between a command and
  the actuators' acting on it, a first-in first-out queue of the controller's
  commands at the plant's step (:data:`artic.validation.docking.run.PLANT_DT`),
  so a delay must be a whole number of plant steps. Until the first command
  arrives the actuators hold the start (wheel where it was, speed zero);
- **steering-wheel rate limit**: the fastest the steering actuator turns the
  wheel, :data:`artic.validation.docking.run.STEER_RATE` today.

The controllers are told the nominal actuators (their ``Task`` keeps
``steer_rate`` at 360 deg/s and knows no delay) and the nominal vehicle: a
sweep asks how a design holds up when the yard differs from what it was
designed for.
"""

from __future__ import annotations

import dataclasses
import math
from collections import deque

from artic.mjcf.errors import UserError
from artic.mjcf.vehicle import Vehicle

FRICTION_SCALES = ("LMUX", "LMUY")
"""The Magic Formula's friction scaling factors a road's friction multiplies."""


def road(vehicle: Vehicle, friction: float = 1.0, grade: float = 0.0) -> Vehicle:
    """``vehicle`` on a yard of road friction ``friction`` and slope ``grade``.

    Parameters
    ----------
    vehicle : Vehicle
        The plant's vehicle.
    friction : float
        Factor on the tyres' friction [-]: 1.0 dry, about 0.3 packed snow.
    grade : float
        Slope along the yard's x-axis [%], positive when the yard falls
        towards the dock (+x uphill); added to any grade the vehicle file has.

    Returns
    -------
    Vehicle
        ``vehicle`` itself at the nominal yard (1.0, 0.0), so a nominal run is
        today's bit for bit; else a copy with the tyres' ``LMUX``, ``LMUY``
        scaling and the plant's grade changed.

    Raises
    ------
    UserError
        For a friction factor that is not positive and finite, or a grade that
        is not finite.
    """
    friction, grade = float(friction), float(grade)
    if not (math.isfinite(friction) and friction > 0.0):
        raise UserError(f"friction {friction:g}: a road friction factor must be positive "
                        "(1.0 dry, about 0.3 packed snow)")
    if not math.isfinite(grade):
        raise UserError(f"grade {grade:g}: the yard's slope must be a finite number [%]")
    if friction == 1.0 and grade == 0.0:
        return vehicle
    out = vehicle
    if friction != 1.0:
        scaling = dict(vehicle.tyre_scaling)
        for key in FRICTION_SCALES:
            scaling[key] = scaling.get(key, 1.0) * friction
        out = dataclasses.replace(out, tyre_scaling=tuple(sorted(scaling.items())))
    if grade != 0.0:
        plant = dataclasses.replace(out.plant,
                                    grade=out.plant.grade + math.atan(grade / 100.0))
        out = dataclasses.replace(out, plant=plant)
    return out


class ActuatorDelay:
    """The actuators' dead time: a first-in first-out queue of commands at the plant's step.

    A command given at plant step ``i`` acts from plant step ``i + steps``
    on; until then the previous one holds.

    Parameters
    ----------
    delay : float
        Dead time [s], a whole number of ``plant_dt`` (within 1e-9 s).
    plant_dt : float
        The plant's step [s].
    initial : tuple
        What the actuators hold before the first command arrives.

    Raises
    ------
    UserError
        For a negative delay or one that is not a whole number of plant steps.
    """

    def __init__(self, delay: float, plant_dt: float, initial: tuple) -> None:
        delay = float(delay)
        steps = round(delay / plant_dt) if math.isfinite(delay) else -1
        if steps < 0 or abs(steps * plant_dt - delay) > 1e-9:
            raise UserError(f"delay {delay:g} s: the actuator delay must be zero or more and a "
                            f"whole number of the plant's {1e3 * plant_dt:g} ms steps")
        self.steps = steps
        self._queue: deque[tuple[int, tuple]] = deque()
        self.current = initial

    def command(self, step: int, value: tuple) -> None:
        """The controller commands ``value`` at plant step ``step``."""
        self._queue.append((step + self.steps, value))

    def at(self, step: int) -> tuple:
        """What the actuators act on at plant step ``step`` (steps in increasing order)."""
        while self._queue and self._queue[0][0] <= step:
            self.current = self._queue.popleft()[1]
        return self.current

    def fill(self, step: int, out) -> None:
        """:meth:`at` of ``step``, ``step + 1``, ... into the rows of ``out``, one per step.

        ``out`` is an array of ``(n, len(value))``; the steps follow the ones asked for
        before, as :meth:`at`'s do, and leave the queue as ``at(step + n - 1)`` would.
        """
        queue, n, j = self._queue, len(out), 0
        while queue and queue[0][0] < step + n:
            first, value = queue.popleft()
            i = max(first - step, 0)
            if i > j:
                out[j:i] = self.current
                j = i
            self.current = value
        out[j:] = self.current
