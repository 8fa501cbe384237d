"""How the synthetic truth's driver reaches the road: steering column and pedals.

The independent and structural truths do not hand their model a road-wheel
angle and a speed. Their driver turns a steering wheel and works two pedals:

- :class:`SteeringColumn`: between the steering wheel (what the CAN bus
  reports as ``delta_h``) and the steering box lie free play (backlash) and
  an offset that drifts during the run (the column's centre creeping as the
  tie rods and the box settle). The road wheels see
  ``map(play(delta_h) - drift(t))``. The independent truth's play, with its
  torsion bar and assist, is in its own compiled column
  (:mod:`artic.validation.synthetic.column`); here only its drift;
- :class:`PedalDriver`: a driver who keeps a target speed with throttle and
  brake, reacting after a delay, moving the pedals at a finite rate, and never
  pressing both;
- :class:`TruthActuation`: the plant behind those two, with the model
  interface the generators drive. It records the steering-wheel angle the
  driver held, which is what the log then reports.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from artic.mjcf.interface import InitialState
from artic.mjcf.vehicle import G

if TYPE_CHECKING:  # the plant's truths only; the yard truth's seat has its own gear
    from artic.mjcf.steering import Steering


@dataclass
class SteeringColumn:
    """Free play and a drifting offset between the steering wheel and the box.

    Parameters
    ----------
    backlash : float
        Total free play at the steering wheel [rad]: the box follows only
        when the wheel has taken up ``backlash / 2`` either way.
    drift_rate : float
        Rate at which the column's zero drifts [rad/s] (steering-wheel angle).
    """

    backlash: float = 0.0
    drift_rate: float = 0.0
    _out: float | None = None

    def reset(self, delta_h: float) -> None:
        """Start with the play centred on ``delta_h`` [rad]."""
        self._out = delta_h

    def __call__(self, delta_h: float, t: float) -> float:
        """Steering-wheel angle that reaches the box at time ``t`` [rad]."""
        if self._out is None:
            self._out = delta_h
        half = 0.5 * self.backlash
        if delta_h - self._out > half:
            self._out = delta_h - half
        elif self._out - delta_h > half:
            self._out = delta_h + half
        return self._out - self.drift_rate * t


def _clamp01(x: float) -> float:
    """``min(max(x, 0.0), 1.0)``, the same object for every ``x``."""
    x = 0.0 if 0.0 > x else x
    return 1.0 if 1.0 < x else x


def _clamp(x: float, step: float) -> float:
    """``min(max(x, -step), step)``, the same object for every ``x``."""
    x = -step if -step > x else x
    return step if step < x else x


@dataclass
class PedalDriver:
    """A driver keeping a target speed with throttle and brake.

    Parameters
    ----------
    mass : float
        Combination mass [kg]; the driver knows roughly how the truck pulls.
    delay : float
        Reaction time [s].
    gain : float
        Speed-error gain [1/s]: wanted acceleration per m/s of error. The
        driver also trims out a lasting error (a slope, cornering drag) with
        an integral gain ``gain^2 / 4`` [1/s^2], critically damped.
    pedal_rate : float
        Fastest pedal travel [1/s] (full travel in ``1 / pedal_rate`` s).
    drive_force_max, brake_decel_max : float
        What full throttle and full brake give: force over weight [-] and
        deceleration [g] (the plant's :data:`artic.plant.plant.DRIVE_FORCE_MAX` and
        ``BRAKE_DECEL_MAX``).
    resistance : float
        Rolling resistance the driver expects, over weight [-].
    dt : float
        Step [s].
    """

    mass: float
    delay: float = 0.4
    gain: float = 1.5
    pedal_rate: float = 2.0
    drive_force_max: float = 0.15
    brake_decel_max: float = 0.6
    resistance: float = 0.006
    dt: float = 0.01
    throttle: float = 0.0
    brake: float = 0.0
    _trim: float = 0.0
    _seen: deque = field(default_factory=deque)

    def __post_init__(self) -> None:
        self._seen = deque([0.0] * max(1, round(self.delay / self.dt)))

    def reset(self, u: float) -> None:
        """Start having seen speed ``u`` [m/s], pedals released."""
        self._seen = deque([abs(u)] * len(self._seen))
        self.throttle = self.brake = 0.0
        self._trim = 0.0

    def command(self, u_target: float, a_target: float, u: float) -> tuple[float, float]:
        """Throttle and brake for the next step, from the speed seen ``delay`` ago.

        Speeds are magnitudes along the travel direction (the gear decides it).
        """
        # Called every step: locals, and the clamps as conditionals that pick what
        # min(max(x, lo), hi) picks (its first argument unless another is strictly
        # beyond it), so that every number is the same to the bit.
        seen_q = self._seen
        seen_q.append(abs(u))
        seen = seen_q.popleft()
        gain, dt, target = self.gain, self.dt, abs(u_target)
        err = target - seen
        moving = target > 0.05
        if moving:
            self._trim += 0.25 * gain ** 2 * err * dt
        else:
            self._trim = 0.0  # stopping or stopped: the brake does it
        a = a_target + gain * err + self._trim
        need = a / G + self.resistance * (1.0 if moving else 0.0)
        want_t = _clamp01(need / self.drive_force_max)
        want_b = _clamp01(-need / self.brake_decel_max)
        if target < 1e-3 and seen < 0.05:
            want_t, want_b = 0.0, (0.3 if 0.3 > want_b else want_b)  # stopped: hold the brake
        step = self.pedal_rate * dt
        throttle, brake = self.throttle, self.brake
        # One foot: release one pedal before pressing the other.
        if want_b > 0.0 and throttle > 0.0:
            want_t = 0.0
        if want_t > 0.0 and brake > 0.0:
            want_b = 0.0
        throttle += _clamp(want_t - throttle, step)
        brake += _clamp(want_b - brake, step)
        if throttle > 0.0 and brake > 0.0:  # still moving across
            if want_t > 0.0:
                brake = 0.0 if 0.0 > brake - step else brake - step
            if want_b > 0.0:
                throttle = 0.0 if 0.0 > throttle - step else throttle - step
        self.throttle, self.brake = throttle, brake
        return throttle, brake


class TruthActuation:
    """The truth's plant behind its steering column and pedals (a model for the drivers).

    Parameters
    ----------
    plant : plant.Plant
        Built with ``speed="pedals"`` when ``pedals`` is given.
    steering : Steering
        The truth's own steering map (steering wheel to road wheel).
    column : SteeringColumn
        Free play and drift.
    pedals : PedalDriver, optional
        Without one, the plant's own ``speed`` mode takes the speed command.
    record : bool
        Keep the plant's full state (``plant.full_state()``) at every
        :meth:`observe`, in :attr:`states`: the state each sample was taken in.
    """

    name = "mbd"

    def __init__(self, plant, steering: Steering, column: SteeringColumn,
                 pedals: PedalDriver | None = None, record: bool = False) -> None:
        self.plant = plant
        self.steering = steering
        self.column = column
        self.pedals = pedals
        self.delta_h: list[float] = []
        self.t = 0.0
        self.states: list[np.ndarray] | None = [] if record else None
        """The plant's full state at every :meth:`observe` since :meth:`reset` (``record``)."""
        self.held: list[tuple[float, ...]] | None = [] if record else None
        """What the plant was given at every step since :meth:`reset` (``record``):
        its ``step`` arguments (road-wheel angle [rad], speed [m/s], its rate
        [m/s^2]) and the pedals (throttle, brake) [-], zero without a driver."""

    def reset(self, initial: InitialState) -> None:
        """Reset the plant, the column and the driver."""
        self.plant.reset(initial)
        self.column.reset(self.steering.steering_wheel(0.0))
        if self.pedals is not None:
            self.pedals.reset(initial.u1)
        self.delta_h = []
        self.t = 0.0
        if self.states is not None:
            self.states = []
            self.held = []

    def step_steering_wheel(self, dt: float, delta_h: float, u1: float, u1_dot: float) -> None:
        """Advance ``dt`` [s]: steering wheel at ``delta_h`` [rad], target speed ``u1``."""
        self.delta_h.append(delta_h)
        delta = float(self.steering.road_wheel(self.column(delta_h, self.t)))
        if self.pedals is not None:
            self.plant.pedals = self.pedals.command(u1, math.copysign(1.0, u1) * u1_dot
                                                    if u1 else 0.0,
                                                    self.plant.sensor_speed())
        if self.held is not None:
            pedals = self.plant.pedals if self.pedals is not None else (0.0, 0.0)
            self.held.append((delta, u1, u1_dot, *map(float, pedals)))
        self.plant.step(dt, delta, u1, u1_dot)
        self.t += dt

    def step(self, dt: float, delta: float, u1: float, u1_dot: float) -> None:
        """Advance with the road-wheel angle the driver wants: he turns the wheel for it."""
        self.step_steering_wheel(dt, float(self.steering.steering_wheel(delta)), u1, u1_dot)

    def observe(self, delta: float | None = None) -> np.ndarray:
        """The plant's signals (and, recording, its full state now)."""
        if self.states is not None:
            self.states.append(self.plant.full_state())
        return self.plant.observe(delta)

    @property
    def gamma(self) -> float:
        """Articulation angle [rad]."""
        return self.plant.gamma

    def compiled(self) -> None:
        """No compiled form."""
        return None

    def close(self) -> None:
        """Nothing of its own to release; the plant is closed by its owner."""
