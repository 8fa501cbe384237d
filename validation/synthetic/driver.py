"""The truth's own driver, who reverses a semitrailer onto a dock by preview.

The dock faces +x with its face at ``x = x_dock``; the semitrailer must end
with its rear at the face, on the dock's centre line ``y = y_dock``, heading
+x. The driver turns the **steering wheel** (``delta_h``), as a driver does,
and shares no formula with the validation harness (``artic.validation.harness``)
nor with the reduced models (``artic.reduced``): the truth that generates the
logs must not steer by the law it validates. Two levels
(``docs/design/truth.md`` derives them and gives the parameters' sources):

1. **preview** (the path): the driver looks along the dock's centre line a
   preview distance ``D`` behind the semitrailer's axle, in its direction of
   travel, and asks the trailer for the arc through that aim point (pure
   pursuit, ``kappa = 2 sin(alpha) / D``, ``alpha`` the aim point's bearing
   from the trailer's direction of travel). A trailer is steered at its
   kingpin: the arc asks for the articulation ``gamma_ref = -atan(L2 kappa)``
   (the trailer as a vehicle of wheelbase ``L2`` steered at its front),
   limited to ``gamma_ref_max``;
2. **articulation** (compensatory): reversing, the articulation runs away
   unless the tractor chases it. The driver turns the wheel in proportion to
   the articulation's error, ``delta_h = straight + G (gamma - gamma_ref)``,
   ``G`` steering-wheel radians per radian, with no model of the steady turn:
   the preview level absorbs the steady error.

Pulling forward (a shuffle) the driver follows the same line with the
tractor: pure pursuit on its drive axle, the road wheels at
``atan(2 L1 sin(alpha) / D_forward)`` through the gear the driver knows
(``i_s`` and the straight-ahead ``delta_h_offset`` of the vehicle file).

A human acts late and turns the wheel at a finite rate: each decision reaches
the wheel ``delay`` later (a FIFO of ``delay / dt`` steps), and the wheel moves
at most ``rate`` [rad/s] towards it, never past its lock (``i_s delta_max``
either side of straight ahead).

Near the dock the driver slows down. If the trailer is still off line or
angle within 8 m of the face, the driver pulls forward 12 m and reverses
again: a shuffle, at most ``max_shuffles`` of them. These rules and the speeds
are the docking manoeuvre's (unchanged since the first truth).
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field

import numpy as np

from artic.mjcf.interface import wrap_angle
from artic.mjcf.outline import DOCK_FACE, outline
from artic.mjcf.vehicle import Vehicle
from artic.validation.models import driven

DELAY = 0.25
"""The driver's reaction delay [s]: perception to the wheel's first move."""

WHEEL_RATE = math.radians(360.0)
"""Fastest steering-wheel turn [rad/s]: one turn a second, an unhurried hand."""

PREVIEW = 11.0
"""Preview distance reversing [m]: from the semitrailer's axle to the aim point."""

PREVIEW_FORWARD = 12.0
"""Preview distance pulling forward [m]: from the tractor's drive axle."""

WHEEL_GAIN = 55.0
"""Steering-wheel angle per articulation error reversing [rad/rad] (deg per deg)."""

GAMMA_REF_MAX = math.radians(30.0)
"""Largest articulation the driver asks for [rad]."""


@dataclass
class DockingDriver:
    """Driver model for docking and parking: preview on the line, compensation on the articulation.

    Parameters
    ----------
    vehicle : Vehicle
        What the driver knows of the truck: its lengths (L1, L1c, L2, the
        sensor's place, the semitrailer's rear) and its steering gear
        (``[steering.mbd]``: ``i_s``, ``delta_h_offset``, ``delta_max``).
    x_dock, y_dock : float
        Dock face position and centre line [m].
    speed : float
        Approach speed [m/s], positive.
    delay : float
        Reaction delay [s].
    rate : float
        Fastest steering-wheel turn [rad/s].
    preview, preview_forward : float
        Preview distances reversing (from the semitrailer's axle) and pulling
        forward (from the drive axle) [m].
    wheel_gain : float
        Steering-wheel angle per radian of articulation error [rad/rad].
    gamma_ref_max : float
        Largest articulation asked for [rad].
    max_shuffles : int
        Pull-forwards allowed.
    dt : float
        The driver's step [s].
    """

    vehicle: Vehicle
    x_dock: float = DOCK_FACE[0]
    y_dock: float = DOCK_FACE[1]
    speed: float = 3.0 / 3.6
    delay: float = DELAY
    rate: float = WHEEL_RATE
    preview: float = PREVIEW
    preview_forward: float = PREVIEW_FORWARD
    wheel_gain: float = WHEEL_GAIN
    gamma_ref_max: float = GAMMA_REF_MAX
    max_shuffles: int = 2
    dt: float = 0.01
    mode: str = "reverse"
    shuffles: int = 0
    _forward_from: float = 0.0
    _buffer: deque = field(default_factory=deque)
    delta_h: float = 0.0

    def __post_init__(self) -> None:
        s = self.vehicle.steering_for("mbd")
        self.i_s, self.straight = s.i_s, s.delta_h_offset
        self.lock = s.i_s * s.delta_max
        self.delta_h = self.straight
        self._buffer = deque([self.straight] * round(self.delay / self.dt))
        self.rear = outline(self.vehicle).rear_behind_kingpin

    def gear(self, delta_h: float) -> float:
        """The road-wheel angle the driver expects of steering-wheel angle ``delta_h`` [rad]."""
        return (delta_h - self.straight) / self.i_s

    def kingpin(self, obs: np.ndarray) -> tuple[float, float]:
        """Kingpin position from an observation [m]."""
        v = self.vehicle
        psi1 = obs[2]
        s1x, s1y = v.sensor1[0] - v.L1c, v.sensor1[1]
        return (obs[0] - math.cos(psi1) * s1x + math.sin(psi1) * s1y,
                obs[1] - math.sin(psi1) * s1x - math.cos(psi1) * s1y)

    def rear_point(self, obs: np.ndarray) -> tuple[float, float]:
        """Semitrailer rear centre from an observation [m]."""
        kx, ky = self.kingpin(obs)
        return kx - self.rear * math.cos(obs[8]), ky - self.rear * math.sin(obs[8])

    def errors(self, obs: np.ndarray) -> tuple[float, float, float]:
        """Distance of the rear to the dock face, lateral offset and heading error [m, m, rad]."""
        x, y = self.rear_point(obs)
        return x - self.x_dock, y - self.y_dock, float(wrap_angle(obs[8]))

    def aim_curvature(self, x: float, y: float, heading: float, direction: float,
                      distance: float) -> float:
        """Pure pursuit of the dock's centre line from point ``(x, y)`` [1/m].

        Parameters
        ----------
        x, y : float
            The followed point (an axle's centre) [m].
        heading : float
            Its unit's heading [rad].
        direction : float
            -1 travelling towards the dock (reversing, -x), +1 away (forward, +x).
        distance : float
            Preview distance [m].

        Returns
        -------
        float
            Curvature of the arc through the aim point, positive turning left
            in the direction of travel [1/m].
        """
        e = y - self.y_dock
        ahead = math.sqrt(max(distance * distance - e * e, 0.0))
        aim_x = x + direction * ahead
        travel = heading if direction > 0 else heading + math.pi
        alpha = float(wrap_angle(math.atan2(self.y_dock - y, aim_x - x) - travel))
        return 2.0 * math.sin(alpha) / distance

    def reference_articulation(self, obs: np.ndarray) -> float:
        """The articulation the preview asks for, reversing [rad]."""
        kx, ky = self.kingpin(obs)
        psi2 = obs[8]
        L2 = self.vehicle.L2
        kappa = self.aim_curvature(kx - L2 * math.cos(psi2), ky - L2 * math.sin(psi2), psi2,
                                   -1.0, self.preview)
        # Travelling rear first, the trailer turns left (travel direction) when the
        # tractor folds to the right of it: gamma < 0.
        g = -math.atan(L2 * kappa)
        return max(-self.gamma_ref_max, min(self.gamma_ref_max, g))

    def command(self, obs: np.ndarray) -> tuple[float, float, bool]:
        """Steering-wheel angle and speed for the next step, and whether the manoeuvre is done.

        Parameters
        ----------
        obs : ndarray
            The vehicle's observation (``OBSERVATION`` order).

        Returns
        -------
        delta_h : float
            Steering-wheel angle held over the next step [rad].
        u : float
            Target speed [m/s], negative reversing.
        done : bool
            Whether the rear is at the dock face.
        """
        dist, e_y, e_psi = self.errors(obs)
        if self.mode == "reverse":
            if dist < 0.05:
                return self._turn(self.delta_h), 0.0, True
            if (dist < 8.0 and (abs(e_y) > 0.3 or abs(e_psi) > math.radians(2.5))
                    and self.shuffles < self.max_shuffles):
                self.mode, self._forward_from = "forward", dist
                self.shuffles += 1
            u = -self.speed if dist > 6.0 else -max(0.3, self.speed * dist / 6.0)
            error = float(wrap_angle(obs[12] - self.reference_articulation(obs)))
            return self._turn(self.straight + self.wheel_gain * error), u, False
        # Forward: the tractor's drive axle follows the line away from the dock.
        if dist > self._forward_from + 12.0:
            self.mode = "reverse"
        v = self.vehicle
        psi1 = obs[2]
        ax = obs[0] - math.cos(psi1) * v.sensor1[0] + math.sin(psi1) * v.sensor1[1]
        ay = obs[1] - math.sin(psi1) * v.sensor1[0] - math.cos(psi1) * v.sensor1[1]
        kappa = self.aim_curvature(ax, ay, psi1, 1.0, self.preview_forward)
        return self._turn(self.straight + self.i_s * math.atan(v.L1 * kappa)), self.speed, False

    def _turn(self, target: float) -> float:
        """The wheel after one step: the decision of ``delay`` ago, at the hand's rate, to lock."""
        self._buffer.append(target)
        wanted = self._buffer.popleft()
        wanted = max(self.straight - self.lock, min(self.straight + self.lock, wanted))
        step = self.rate * self.dt
        self.delta_h += max(-step, min(step, wanted - self.delta_h))
        return self.delta_h


@dataclass(frozen=True)
class DockRun:
    """A docking or parking drive, sample by sample.

    Parameters
    ----------
    t : ndarray
        Time [s].
    obs : ndarray
        The vehicle's observations (``OBSERVATION`` order).
    delta_h : ndarray
        Steering-wheel angle the driver held from each sample [rad].
    delta : ndarray
        The road-wheel angle the driver expects of it (his gear) [rad].
    u : ndarray
        Speed at each sample, as the driver's pedal ramped it [m/s].
    docked : bool
        Whether the driver finished.
    """

    t: np.ndarray
    obs: np.ndarray
    delta_h: np.ndarray
    delta: np.ndarray
    u: np.ndarray
    docked: bool


def drive_dock(vehicle, driver: DockingDriver, initial, max_time: float = 240.0) -> DockRun:
    """Drive a vehicle with the docking driver until it docks (or time runs out).

    Parameters
    ----------
    vehicle : object
        A driver's seat (``step_steering_wheel``, as the truths'
        :class:`artic.validation.synthetic.yardtruth.YardSeat`): it gets the
        steering wheel. Any other model (``reset``, ``observe``, ``step``; a
        state-space model gets its state holder) gets the road-wheel angle of
        the driver's gear.
    driver : DockingDriver
        The driver.
    initial : InitialState
        Start pose, at rest or moving.
    max_time : float
        Longest drive [s].
    """
    if not callable(getattr(vehicle, "reset", None)):  # a state-space model (KIN, STM)
        vehicle = driven(vehicle)
    wheel = getattr(vehicle, "step_steering_wheel", None)
    vehicle.reset(initial)
    dt = driver.dt
    t, obs, delta_h, speed = [], [], [], []
    u_prev = initial.u1
    docked = False
    for k in range(int(max_time / dt)):
        o = vehicle.observe()
        d_h, u, docked = driver.command(o)
        t.append(k * dt)
        obs.append(o)
        delta_h.append(d_h)
        speed.append(u_prev)
        if docked:
            break
        # The driver's pedal: speed changes at most 0.5 m/s^2.
        u_next = u_prev + max(-0.5 * dt, min(0.5 * dt, u - u_prev))
        if wheel is not None:
            wheel(dt, d_h, u_prev, (u_next - u_prev) / dt)
        else:
            vehicle.step(dt, driver.gear(d_h), u_prev, (u_next - u_prev) / dt)
        u_prev = u_next
    dh = np.array(delta_h)
    return DockRun(np.array(t), np.array(obs), dh, (dh - driver.straight) / driver.i_s,
                   np.array(speed), docked)


def drive_to_dock(model, driver: DockingDriver, initial, max_time: float = 240.0):
    """:func:`drive_dock` as a tuple, road-wheel angles.

    Returns
    -------
    t, obs, delta, u : ndarray
        Time [s], observations, road-wheel angle of the driver's gear [rad] and
        speed [m/s] per sample.
    docked : bool
        Whether the driver finished.
    """
    r = drive_dock(model, driver, initial, max_time)
    return r.t, r.obs, r.delta, r.u, r.docked
