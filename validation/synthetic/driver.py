"""A driver who reverses a semitrailer onto a dock.

The dock faces +x with its face at ``x = x_dock``; the semitrailer must end
with its rear at the face, on the dock's centre line ``y = y_dock``, heading +x.
A driver does it in reverse the way one is taught:

1. aim the trailer: the rear's lateral offset ``e_y`` sets a desired trailer
   heading ``psi_2 = atan(k_y e_y)``, limited to 25 deg;
2. swing the trailer: the heading error sets a desired trailer yaw rate, and
   with ``r_2 ~ u sin(gamma) / L2`` in reverse, a reference articulation,
   limited to 35 deg;
3. hold the articulation: ``delta = delta_ss(gamma_ref) + K (gamma - gamma_ref)``,
   the stabilising feedback of the harness, K = 3.

The loops are nested from fast to slow (articulation about 2 s, heading 5 s,
lateral offset about 10 m of travel), with gains tuned on KIN over offsets
of up to 4 m and 8 deg. Faster outer loops, or a higher K against the delay
and the rate limit, oscillate.

The driver reacts with a delay (0.3 s) and turns the wheel at a limited rate.
Near the dock the driver slows down. If the trailer is still off line or
angle within 8 m of the face, the driver pulls forward 12 m, steering the
tractor back onto the line, and reverses again: a shuffle. At most
``max_shuffles`` of them.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field

import numpy as np

from artic.mjcf.interface import wrap_angle
from artic.mjcf.outline import DOCK_FACE, outline
from artic.mjcf.vehicle import Vehicle
from artic.validation.harness.feedback import feedback_law
from artic.validation.harness.simulate import steady_articulation_delta


@dataclass
class DockingDriver:
    """Driver model for docking and parking.

    Parameters
    ----------
    vehicle : Vehicle
        Geometry (L1, L1c, L2, trailer axles) and ``delta_max``.
    x_dock, y_dock : float
        Dock face position and centre line [m].
    speed : float
        Approach speed [m/s], positive.
    delay : float
        Reaction delay [s].
    rate : float
        Largest road-wheel angle rate [rad/s].
    """

    vehicle: Vehicle
    x_dock: float = DOCK_FACE[0]
    y_dock: float = DOCK_FACE[1]
    speed: float = 3.0 / 3.6
    delay: float = 0.3
    rate: float = 0.3
    max_shuffles: int = 2
    k_y: float = 0.12
    k_psi: float = 0.2
    gain: float = 3.0
    dt: float = 0.01
    mode: str = "reverse"
    shuffles: int = 0
    _forward_from: float = 0.0
    _buffer: deque = field(default_factory=deque)
    _delta: float = 0.0

    def __post_init__(self) -> None:
        self._buffer = deque([0.0] * max(1, round(self.delay / self.dt)))
        self.rear = outline(self.vehicle).rear_behind_kingpin

    def rear_point(self, obs: np.ndarray) -> tuple[float, float]:
        """Semitrailer rear centre from an observation [m]."""
        v = self.vehicle
        psi1, psi2 = obs[2], obs[8]
        s1x, s1y = v.sensor1[0] - v.L1c, v.sensor1[1]
        kx = obs[0] - math.cos(psi1) * s1x + math.sin(psi1) * s1y
        ky = obs[1] - math.sin(psi1) * s1x - math.cos(psi1) * s1y
        return kx - self.rear * math.cos(psi2), ky - self.rear * math.sin(psi2)

    def errors(self, obs: np.ndarray) -> tuple[float, float, float]:
        """Distance of the rear to the dock face, lateral offset and heading error [m, m, rad]."""
        x, y = self.rear_point(obs)
        return x - self.x_dock, y - self.y_dock, float(wrap_angle(obs[8]))

    def command(self, obs: np.ndarray) -> tuple[float, float, bool]:
        """Road-wheel angle and speed for the next step, and whether the manoeuvre is done.

        Parameters
        ----------
        obs : ndarray
            The model's observation (``OBSERVATION`` order).
        """
        v = self.vehicle
        dist, e_y, e_psi = self.errors(obs)
        gamma = obs[12]
        if self.mode == "reverse":
            if dist < 0.05:
                return self._steer(0.0), 0.0, True
            if (dist < 8.0 and (abs(e_y) > 0.3 or abs(e_psi) > math.radians(2.5))
                    and self.shuffles < self.max_shuffles):
                self.mode, self._forward_from = "forward", dist
                self.shuffles += 1
            u = -self.speed if dist > 6.0 else -max(0.3, self.speed * dist / 6.0)
            psi2_des = math.atan(self.k_y * e_y)
            psi2_des = max(-math.radians(25.0), min(math.radians(25.0), psi2_des))
            r2_des = self.k_psi * float(wrap_angle(psi2_des - e_psi))
            s = max(-math.sin(math.radians(35.0)), min(math.sin(math.radians(35.0)),
                                                        r2_des * v.L2 / u))
            g_ref = math.asin(s)
            d_ff = steady_articulation_delta(g_ref, v)
            delta, _, _ = feedback_law(d_ff, gamma, g_ref, 1.0, self.gain,
                                       v.steering.delta_max)
            return self._steer(delta), u, False
        # Forward: steer the tractor back onto the line while the trailer straightens.
        if dist > self._forward_from + 12.0:
            self.mode = "reverse"
        psi1 = float(wrap_angle(obs[2]))
        e_y1 = obs[1] - self.y_dock
        psi1_des = -math.atan(0.15 * e_y1)
        delta = max(-0.3, min(0.3, 1.5 * float(wrap_angle(psi1_des - psi1))))
        return self._steer(delta), self.speed, False

    def _steer(self, target: float) -> float:
        self._buffer.append(target)
        delayed = self._buffer.popleft()
        step = self.rate * self.dt
        self._delta += max(-step, min(step, delayed - self._delta))
        return self._delta


def drive_to_dock(model, driver: DockingDriver, initial, max_time: float = 240.0):
    """Run a model under the docking driver until it docks (or time runs out).

    Returns
    -------
    t, obs, delta, u : ndarray
        Time [s], observations, road-wheel angle [rad] and speed [m/s] per sample.
    docked : bool
        Whether the driver finished.
    """
    from artic.validation.models import driven

    model = driven(model)
    model.reset(initial)
    dt = driver.dt
    t, obs, delta, speed = [], [], [], []
    u_prev = initial.u1
    for k in range(int(max_time / dt)):
        o = model.observe()
        d, u, done = driver.command(o)
        t.append(k * dt)
        obs.append(o)
        delta.append(d)
        speed.append(u_prev)
        if done:
            return np.array(t), np.array(obs), np.array(delta), np.array(speed), True
        # The driver's pedal: speed changes at most 0.5 m/s^2.
        u_next = u_prev + max(-0.5 * dt, min(0.5 * dt, u - u_prev))
        model.step(dt, d, u_prev, (u_next - u_prev) / dt)
        u_prev = u_next
    return np.array(t), np.array(obs), np.array(delta), np.array(speed), False
