"""The plant's stepping: its resets, speed control, steering servo and checks.

:class:`Stepping` is one of the parts :class:`artic.plant.plant.Plant` is made
of: :meth:`~Stepping.reset` and :meth:`~Stepping.reset_steady` place the
combination, :meth:`~Stepping.step` advances it (in C where the compiled step
runs, else through MuJoCo from Python) with the speed controlled as the
plant's ``speed`` says, and every step is checked for divergence and for wheels
outside their tyre file's ranges.
"""

from __future__ import annotations

import math
import warnings

import mujoco
import numpy as np

from artic.mjcf import naming as nm
from artic.mjcf.errors import PlantError
from artic.mjcf.interface import InitialState, rotate
from artic.mjcf.vehicle import G
from artic.plant import closedloop
from artic.plant.follower import FOLLOW_KI
from artic.plant.tyre import check_ranges, steady_deflections

SPEED_KP = 2.0
"""Speed controller: proportional gain [1/s] (times the total mass)."""

SPEED_KI = 0.5
"""Speed controller: integral gain [1/s^2] (times the total mass)."""

BRAKE_SPIN_SCALE = 0.5
"""Wheel spin [rad/s] over which brake torque fades to zero at standstill."""

PARKING_BRAKE_GRADE = 0.2
"""Parking brake capacity: it holds the combination on this gradient [-] (20 %;
EU rules ask for 18 % for a laden combination)."""

DRIVE_FORCE_MAX = 0.15
"""Full throttle: drive force at the wheels as a fraction of the combination's
weight [-] (a laden truck in a low gear pulls off at about 1.5 m/s^2)."""

BRAKE_DECEL_MAX = 0.6
"""Full brake: deceleration of the combination [g] (a service brake's reach)."""

SLIP_KNOWN = 0.5
"""Wheel speed above which :meth:`~Stepping.reset_steady` takes a start's slip as known [m/s].

The slip follows from velocities a log measures with about 1 cm/s of noise:
its angle is uncertain by 45 deg at 1 cm/s and by 1 deg at 0.5 m/s. Below
this speed the steady deflections are scaled by ``|V| / SLIP_KNOWN`` (as the
STM scales its lagged slips), so a start at rest has relaxed tyres."""


class PlantWarning(UserWarning):
    """Something the plant had to limit, such as a steering angle beyond the linkage."""


class Stepping:
    """Resets, the speed controller, the step and its checks (a part of ``Plant``)."""

    @property
    def parking_brake(self) -> bool:
        """Whether the parking brake holds every wheel.

        It is dry friction on each wheel's spin joint, solved by MuJoCo's
        constraint solver (implicitly, so a held wheel does not chatter), with
        a torque per wheel end in proportion to its static load: together they
        hold the combination on a :data:`PARKING_BRAKE_GRADE` slope.
        """
        return bool(self.model.dof_frictionloss[self._spin_dof].any())

    @parking_brake.setter
    def parking_brake(self, on: bool) -> None:
        T = PARKING_BRAKE_GRADE * self.mass * G * self.R0 * self._brake_share if on else 0.0
        self.model.dof_frictionloss[self._spin_dof] = T

    def reset(self, initial: InitialState) -> None:
        """Place the combination at ``initial``, at rest on its springs, rolling at ``u1``.

        ``initial`` is what the sensors report (a log's first sample): the
        headings, the articulation and the lateral velocity of inertial units
        mounted turned by their yaw (``sensor_yaw``), which :meth:`observe`
        adds. The bodies are placed without it, so that ``observe`` reports
        ``initial`` back.
        """
        m, d = self.model, self.data
        mujoco.mj_resetData(m, d)
        e1, e2 = self._sensor_yaw
        psi = initial.psi_1 - e1
        gamma = initial.gamma - (e1 - e2)
        dx, dy = rotate(psi, self._s1[0], self._s1[1])
        d.qpos[:3] = [initial.x_1 - dx, initial.y_1 - dy, 0.0]
        d.qpos[3:7] = [math.cos(psi / 2), 0.0, 0.0, math.sin(psi / 2)]
        d.qpos[m.jnt_qposadr[self._hitch_yaw]] = -gamma
        v_y = math.sin(e1) * initial.u1 + math.cos(e1) * initial.v_y_1  # in the tractor's axes
        v_origin = v_y - initial.r_1 * self._s1[0]
        d.qvel[:3] = [*rotate(psi, initial.u1, v_origin), 0.0]
        d.qvel[5] = initial.r_1
        d.qvel[m.jnt_dofadr[self._hitch_yaw]] = initial.r_2 - initial.r_1
        d.qvel[self._spin_dof] = initial.u1 / self.R0
        self._integral = 0.0
        self.steer_limited = 0
        mujoco.mj_forward(m, d)
        self._psi[:] = (psi, psi - gamma)

    def reset_steady(self, initial: InitialState) -> None:
        """Place the combination at ``initial`` in the steady state of that motion.

        :meth:`reset`, and then what a vehicle in that motion carries that the
        signals do not show, instead of zero:

        - the steered wheels at ``initial.delta`` (the left one, within the
          linkage's range; the right one through the tie-rod linkage);
        - every wheel spinning at its rolling speed ``V_x / R_e`` (no
          longitudinal slip: the wheels roll free under the speed follower);
        - every tread deflection at its steady state for the wheel's motion
          (:func:`artic.plant.tyre.steady_deflections`: the slip angle and
          turn slip the motion gives, held as if the wheel had rolled there
          for a while), scaled by ``min(1, |V| / SLIP_KNOWN)``
          (:data:`SLIP_KNOWN`).

        The suspension stays at rest on its springs. The open-loop predictions
        start the plant so (:mod:`artic.validation.criteria.prediction`): a
        zeroed start would first build the slip the measured motion already has.
        """
        self.reset(initial)
        m, d = self.model, self.data
        lo, hi = self._servo_range
        delta = min(max(float(initial.delta), lo), hi)
        for name, left, right in zip(self._steered, self._steer_L, self._steer_R, strict=True):
            poly = m.eq_data[m.equality(nm.tie_rod(name)).id, :5]  # right = poly(left)
            d.qpos[left] = delta
            d.qpos[right] = np.polynomial.polynomial.polyval(delta, poly)
        mujoco.mj_forward(m, d)
        pos, hx, hy, vel, flat = self._wheel_kinematics(d)
        rho = self.R0_w - pos[:, 2]
        Fz = np.maximum(np.where(rho > 0.0, self.k_t_w * rho - self.c_t_w * vel[:, 2], 0.0), 0.0)
        Vx = np.einsum("ij,ij->i", vel, hx)
        Vy = np.einsum("ij,ij->i", vel, hy)
        Re = self.R0_w - np.maximum(rho, 0.0) / 3.0
        omega_z = d.cvel[self._hub_body][:, 2]
        d.qvel[self._spin_dof] = Vx / Re
        gate = np.minimum(1.0, np.hypot(Vx, Vy) / SLIP_KNOWN)
        for k, p in enumerate(self._tyres):
            w = (self._tyre_set == k) & ~flat
            u, v, phi = steady_deflections(p, Fz[w], Vx[w], np.zeros(w.sum()), Vy[w],
                                           omega_z[w])
            d.act[self._act_u[w]] = gate[w] * u
            d.act[self._act_v[w]] = gate[w] * v
            d.act[self._act_w[w]] = gate[w] * phi
        mujoco.mj_forward(m, d)

    def _speed(self) -> float:
        """Tractor speed along its x-axis [m/s].

        The tractor is the free root body, so ``qvel[:3]`` is its origin's
        velocity in the world frame; the x-axis is the first column of ``xmat``.
        """
        d = self.data
        R = d.xmat[self._tractor]
        v = d.qvel
        return float(R[0] * v[0] + R[3] * v[1] + R[6] * v[2])

    def _control(self, u_cmd: float, u_dot: float, h: float) -> None:
        d = self.data
        u = self._speed()
        e = u_cmd - u
        self._integral += e * h
        if self.speed_mode == "pedals":
            throttle = min(max(float(self.pedals[0]), 0.0), 1.0)
            brake = min(max(float(self.pedals[1]), 0.0), 1.0)
            direction = 1.0 if u_cmd >= 0.0 else -1.0  # the gear: forward or reverse
            weight = self.mass * G
            d.ctrl[self._drive] = direction * throttle * DRIVE_FORCE_MAX * weight * self.R0 \
                / len(self._drive)
            self._pedal_brake(brake, weight)
            return
        rr = self.tyre.QSY1 * self.mass * G * math.tanh(u_cmd / 0.1)
        if self.speed_mode == "follow":
            ff = self.mass_eff * u_dot + rr
            d.ctrl[self._follower] = u_cmd + ff / self._follower_kv + FOLLOW_KI * self._integral
            return
        F = self.mass * (u_dot + SPEED_KP * e + SPEED_KI * self._integral) + rr
        direction = math.copysign(1.0, u_cmd) if abs(u_cmd) > 0.05 else math.copysign(1.0, F)
        d.ctrl[self._brake] = 0.0
        d.ctrl[self._drive] = 0.0
        if F * direction >= 0.0:
            d.ctrl[self._drive] = F * self.R0 / len(self._drive)
        else:
            spin = d.qvel[self._spin_dof]
            d.ctrl[self._brake] = (-abs(F) * self.R0 * self._brake_share
                                   * np.tanh(spin / BRAKE_SPIN_SCALE))

    def _pedal_brake(self, brake: float, weight: float) -> None:
        """The service brake at pedal ``brake`` [0-1] on a combination of ``weight`` [N]."""
        spin = self.data.qvel[self._spin_dof]
        self.data.ctrl[self._brake] = (-brake * BRAKE_DECEL_MAX * weight * self.R0
                                       * self._brake_share * np.tanh(spin / BRAKE_SPIN_SCALE))

    def step(self, dt: float, delta: float, u1: float, u1_dot: float) -> None:
        """Advance ``dt`` [s]; see :mod:`artic.mjcf.interface`.

        ``delta`` turns the left front wheel (the steering box's wheel); the
        right one follows through the linkage.
        """
        m, d = self.model, self.data
        h = m.opt.timestep
        n = max(1, round(dt / h))
        if self._stepper is not None and self._compiled_step:
            # The same step in C: the speed controls here, the rest there.
            self._control(u1 + u1_dot * 0.5 * (n * h), u1_dot, n * h)
            code = self._stepper.step(delta, n)
            s = self._stepper.struct
            if s.steer_limited:
                first = self.steer_limited == 0
                self.steer_limited += s.steer_limited
                s.steer_limited = 0
                if first:
                    self.warn_steer_limited(s.first_limit_time, s.first_limit_delta)
            if code == closedloop.TYRE_RANGE:
                d.userdata[3 * self.n_wheels] = 0.0
                self.check_tyre_ranges()
            elif code == closedloop.DIVERGED:
                good = np.array(s.good_forces[:3 * self.n_wheels]).reshape(-1, 3)
                self._check(s.good_time, good, s.span)
                raise AssertionError("unreachable: a diverged step that _check accepts")
            elif code != closedloop.DONE:
                raise RuntimeError("the compiled step refused the plant's indices")
            return
        lo, hi = self._servo_range
        if not lo <= delta <= hi:
            self.steer_limited += 1
            if self.steer_limited == 1:
                self.warn_steer_limited(d.time, delta)
        d.ctrl[self._servo] = min(max(delta, lo), hi)
        # The speed controller is sampled once per call (zero-order hold over
        # dt), at the middle of the interval (the commanded ramp's mean, at
        # dt / 2 whatever the step), so MuJoCo runs n steps uninterrupted.
        self._control(u1 + u1_dot * 0.5 * (n * h), u1_dot, n * h)
        # MuJoCo resets a diverged simulation to t = 0 by itself: keep what a report needs.
        good_time, good_forces = d.time, self.last_forces.copy()
        mujoco.mj_step(m, d, nstep=n)
        self._check(good_time, good_forces, n * h)
        if self.backend == "python":
            self.check_tyre_ranges()
        elif d.userdata[3 * self.n_wheels]:  # the C callback counted wheels out of range
            d.userdata[3 * self.n_wheels] = 0.0
            self.check_tyre_ranges()

    def warn_steer_limited(self, time: float, delta: float) -> None:
        """Warn, once per run, that ``delta`` [rad] at ``time`` [s] was beyond the linkage."""
        lo, hi = self._servo_range
        warnings.warn(f"t = {time:.2f} s: left-wheel angle {math.degrees(delta):.1f} "
                      f"deg is beyond the linkage's [{math.degrees(lo):.1f}, "
                      f"{math.degrees(hi):.1f}] deg; limited", PlantWarning, stacklevel=3)

    def _check(self, good_time: float, good_forces: np.ndarray, span: float) -> None:
        """Raise :class:`PlantError` if the step diverged.

        The message gives the last time the state was sound (MuJoCo has reset
        ``d.time`` by now) and the wheel whose tyre force was largest then.
        """
        d = self.data
        if not d.warning.number.any() and np.isfinite(d.qvel).all():
            return
        bad = [mujoco.mjtWarning(i).name for i in range(len(d.warning)) if d.warning[i].number]
        finite = np.all(np.isfinite(d.qpos)) and np.all(np.isfinite(d.qvel))
        if bad or not finite:
            F = np.linalg.norm(good_forces, axis=1)
            F = np.where(np.isfinite(F), F, np.inf)
            k = int(np.argmax(F))
            raise PlantError(f"t = {good_time:.3f} s: the simulation diverged within the next "
                             f"{1e3 * span:.0f} ms ({', '.join(bad) or 'non-finite state'}); "
                             f"largest tyre force then at wheel {self.wheel_names[k]} "
                             f"({F[k]:.3g} N)")

    def check_tyre_ranges(self) -> list[str]:
        """Warn for wheels outside the tyre file's valid ranges now (see :mod:`artic.plant.tyre`).

        Called after every step; a wheel in the air (no load) is not reported.
        """
        out = []
        Fz_all = self.last_forces[:, 2] / self._n_tyres
        for k, p in enumerate(self._tyres):
            idx = np.flatnonzero((self._tyre_set == k) & (Fz_all > 0.0))
            if not idx.size:
                continue
            Fz = Fz_all[idx]
            Fzc = np.maximum(Fz, p.FZMIN)  # as in the force evaluation
            kappa = self.data.act[self._act_u[idx]] / p.sigma_kappa(Fzc)
            alpha = np.arctan(self.data.act[self._act_v[idx]] / p.sigma_alpha(Fzc))
            names = [self.wheel_names[i] for i in idx]
            out += check_ranges(p, Fz, kappa, alpha, names, f"t = {self.data.time:.2f} s")
        return out
