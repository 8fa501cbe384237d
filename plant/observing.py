"""The plant's observing: the signals at the sensor points, the articulation, the wheel loads.

:class:`Observing` is one of the parts :class:`artic.plant.plant.Plant` is made
of: what the harness reads after each step, in ``OBSERVATION`` order
(:mod:`artic.mjcf.interface`), from the compiled step where it runs.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from artic.mjcf.interface import wrap_angle


class Observing:
    """The signals, the articulation and the last tyre forces (a part of ``Plant``)."""

    @property
    def last_forces(self) -> np.ndarray:
        """Contact force of every wheel end from the last callback, world frame [N]."""
        if self.backend == "compiled":
            return self.data.userdata[:3 * self.n_wheels].reshape(-1, 3)
        return self._last_forces

    def observe(self, delta: float | None = None) -> np.ndarray:
        """Signals at the sensor points, in ``OBSERVATION`` order."""
        if self._stepper is not None and self._compiled_step:
            return self._stepper.observe()
        d = self.data
        out = np.empty(13)
        for i, (site, body) in enumerate(zip(self._sensor, (self._tractor, self._trailer),
                                             strict=True)):
            R = d.xmat[body]
            psi = math.atan2(R[3], R[0])
            psi = self._psi[i] + wrap_angle(psi - self._psi[i])
            self._psi[i] = psi
            vx, vy, r = self._sensor_velocity(i)
            xy = d.site_xpos[site]
            out[6 * i:6 * i + 6] = [xy[0], xy[1], psi + self._sensor_yaw[i], vx, vy, r]
        out[12] = wrap_angle(out[2] - out[8])
        return out

    def _sensor_velocity(self, i: int) -> tuple[float, float, float]:
        """``v_x``, ``v_y`` [m/s] and yaw rate [rad/s] at sensor ``i`` (0 tractor, 1 trailer).

        In the unit's axes: turned by the sensor's mounting yaw ``eps`` to the left.
        """
        res = self._velocity  # written whole by MuJoCo
        mujoco.mj_objectVelocity(self.model, self.data, mujoco.mjtObj.mjOBJ_SITE,
                                 self._sensor[i], res, 1)
        vx, vy = res[3], res[4]
        eps = self._sensor_yaw[i]
        if eps:
            c, s = math.cos(eps), math.sin(eps)
            vx, vy = c * vx + s * vy, -s * vx + c * vy
        return vx, vy, res[2]

    def sensor_speed(self) -> float:
        """The tractor sensor's longitudinal velocity [m/s]: ``observe()[3]`` alone."""
        return float(self._sensor_velocity(0)[0])

    @property
    def gamma(self) -> float:
        """Articulation angle as the inertial units report it, ``observe()[12]`` [rad].

        The hitch angle plus the units' mounting yaws' difference (zero for units
        mounted straight), so that the harness compares it with a log's like for like.
        """
        e1, e2 = self._sensor_yaw
        return float(wrap_angle(-self.data.qpos[self._hitch_qpos] + e1 - e2))

    def wheel_loads(self) -> np.ndarray:
        """Vertical force of every wheel end from the last callback [N]."""
        return self.last_forces[:, 2].copy()
