"""The multibody reference plant behind the harness's model interface.

Every integrator stage (RK4, 5 ms by default: see :data:`mjcf.builder.TIMESTEP`)
the passive-force callback runs for every wheel end at once:

- wheel-centre position and velocity, from the hub site and its body's
  spatial velocity; the heading is the hub's x-axis, flattened onto the
  ground;
- vertical force per tyre, ``k_t (R0 - z) - c_t z_dot``, never pulling;
- slips from the tread deflections held in the ``tread.*`` actuators'
  activations, and their rates written to those actuators' controls, which
  MuJoCo integrates (see :mod:`plant.tyre`);
- PAC2002 forces and rolling resistance, applied at the contact point.

The speed controller tracks the commanded tractor speed with drive torque
on the driven wheels, and with brake torque on all wheels when it must slow
the combination. The steering servo turns the left front wheel to the
commanded road-wheel angle. The right wheel follows through the tie-rod
trapezoid, which gives the left/right asymmetry of eq. (3) by itself, so
the plant's steering map has ``q = 0``.

After every step the plant checks MuJoCo's warning counters and the state.
Anything non-finite raises :class:`PlantError` naming the last sound time
and the wheel with the largest tyre force then; nothing is reset silently.
"""

from __future__ import annotations

import math
import warnings

import mujoco
import numpy as np

from mjcf import naming as nm
from mjcf.builder import build_model, linkage
from mjcf.interface import InitialState, rotate, wrap_angle
from mjcf.masses import layout
from mjcf.vehicle import G, Vehicle
from plant import callback, ctyre
from plant.tyre import (
    TyreParams,
    check_ranges,
    deflection_rates,
    rolling_resistance,
    transient_forces,
)

SPEED_KP = 2.0
"""Speed controller: proportional gain [1/s] (times the total mass)."""

SPEED_KI = 0.5
"""Speed controller: integral gain [1/s^2] (times the total mass)."""

BRAKE_SPIN_SCALE = 0.5
"""Wheel spin [rad/s] over which brake torque fades to zero at standstill."""


BACKENDS = ("auto", "c", "numpy")
"""Tyre callback implementations: compiled (:mod:`plant.ctyre`) or the numpy reference."""

_fallback_warned = False


def _warn_fallback() -> None:
    global _fallback_warned
    if not _fallback_warned:
        _fallback_warned = True
        warnings.warn(f"the compiled tyre callback is unavailable ({ctyre.unavailable_reason()}); "
                      "the plant uses the numpy tyre model, about 16 times slower", PlantWarning,
                      stacklevel=3)


class PlantError(RuntimeError):
    """The simulation diverged; the message names the time and the wheel."""


class PlantWarning(UserWarning):
    """Something the plant had to limit, such as a steering angle beyond the linkage."""


class Plant:
    """The MuJoCo reference plant, driven like KIN and STM.

    Parameters
    ----------
    vehicle : Vehicle
        Every number of the model comes from here and its tyre file.
    timestep : float, optional
        MuJoCo timestep [s]; the model's default (5 ms, RK4) otherwise.
    """

    name = "mbd"

    def __init__(self, vehicle: Vehicle, timestep: float | None = None,
                 backend: str = "auto") -> None:
        if backend not in BACKENDS:
            raise ValueError(f"backend {backend!r}: expected one of {', '.join(BACKENDS)}")
        if backend != "numpy" and ctyre.library() is None:
            if backend == "c":
                raise RuntimeError(ctyre.unavailable_reason())
            _warn_fallback()
            backend = "numpy"
        self.backend = "c" if backend == "auto" else backend
        self.vehicle = vehicle
        self._tyre = TyreParams.from_tir(vehicle.tyre_file)
        spec = build_model(vehicle)
        n_wheels = 2 * len(vehicle.axles)
        if self.backend == "c":
            if spec.numerics:
                raise ValueError("the plant's spec must not carry numerics of its own")
            spec.add_numeric(name=ctyre.BLOCK, size=ctyre.block_size(n_wheels))
            spec.nuserdata = 3 * n_wheels + 1  # forces, then the out-of-range count
        self.model = callback.compile_spec(spec)
        if timestep is not None:
            self.model.opt.timestep = timestep
        self.data = mujoco.MjData(self.model)
        self._index(vehicle)
        self._psi = np.zeros(2)
        self._integral = 0.0
        self.steer_limited = 0
        self._last_forces = np.zeros((self.n_wheels, 3))
        self._closed = False
        if self.backend == "c":
            self.tyre = self._tyre  # writes the C callback's block
            callback.install(self.model, callback.NATIVE)
        else:
            callback.install(self.model, self._passive)

    def _wheel_table(self) -> np.ndarray:
        m = self.model
        cols = {"hub_site": self._hub, "hub_body": self._hub_body, "root_body": self._root,
                "wheel_body": self._wheel_body, "spin_dof": self._spin_dof,
                "act_u": self._act_u, "act_v": self._act_v, "ctrl_u": self._tread_u,
                "ctrl_v": self._tread_v, "n_tyres": self._n_tyres, "side": self._side}
        assert m.nu > max(self._tread_v)
        return np.column_stack([cols[f] for f in ctyre.WHEEL_FIELDS])

    @property
    def tyre(self) -> TyreParams:
        """The tyre coefficients in use; assigning new ones takes effect at the next step."""
        return self._tyre

    @tyre.setter
    def tyre(self, p: TyreParams) -> None:
        self._tyre = p
        if self.backend == "c":
            self.model.numeric_data[:] = ctyre.block(p, self.R0, self.k_t, self.c_t,
                                                     self._wheel_table())

    @property
    def last_forces(self) -> np.ndarray:
        """Contact force of every wheel end from the last callback, world frame [N]."""
        if self.backend == "c":
            return self.data.userdata[:-1].reshape(-1, 3)
        return self._last_forces

    # ------------------------------------------------------------ indexing
    def _index(self, v: Vehicle) -> None:
        m = self.model
        lay = layout(v)
        ends = [(a, side) for a in lay.axles for side in nm.SIDES]
        self.n_wheels = len(ends)
        self.wheel_names = [f"{a.axle.name} {side}" for a, side in ends]
        self._hub = np.array([m.site(nm.hub(a.axle.name, s)).id for a, s in ends])
        self._hub_body = m.site_bodyid[self._hub]
        self._root = m.body_rootid[self._hub_body]
        self._wheel_body = np.array([m.body(nm.wheel(a.axle.name, s)).id for a, s in ends])
        self._spin_dof = np.array([m.jnt_dofadr[m.joint(nm.spin(a.axle.name, s)).id]
                                   for a, s in ends])
        self._n_tyres = np.array([float(a.n_tyres) for a, _ in ends])
        self._side = np.array([1.0 if s == "L" else -1.0 for _, s in ends])
        self._tread_u = np.array([m.actuator(nm.tread(a.axle.name, s, "u")).id for a, s in ends])
        self._tread_v = np.array([m.actuator(nm.tread(a.axle.name, s, "v")).id for a, s in ends])
        self._act_u = m.actuator_actadr[self._tread_u]
        self._act_v = m.actuator_actadr[self._tread_v]
        self._drive = [m.actuator(nm.drive(a.axle.name, s)).id for a, s in ends if a.axle.driven]
        self._brake = np.array([m.actuator(nm.brake(a.axle.name, s)).id for a, s in ends])
        static = np.array([a.static_load / 2.0 for a, _ in ends])
        self._brake_share = static / static.sum()
        steered = [a.axle.name for a in lay.axles if a.axle.steered]
        self._servo = [m.actuator(nm.servo(n)).id for n in steered]
        self._servo_range = linkage(v)[2]
        self._steer_L = [m.jnt_qposadr[m.joint(nm.steer(n, "L")).id] for n in steered]
        self._steer_R = [m.jnt_qposadr[m.joint(nm.steer(n, "R")).id] for n in steered]
        self._tractor = m.body(nm.TRACTOR).id
        self._trailer = m.body(nm.TRAILER).id
        self._hitch_yaw = m.joint(nm.HITCH_YAW).id
        self._sensor = [m.site(nm.sensor(1)).id, m.site(nm.sensor(2)).id]
        self._s1 = np.array(v.sensor1[:2])
        self.mass = v.m1 + v.m2
        self.R0, self.k_t, self.c_t = lay.R0, lay.k_tyre, lay.c_tyre

    # ------------------------------------------------------------ tyres
    def _wheel_kinematics(self, d: mujoco.MjData):
        """Per wheel end: hub position, heading, lateral axis, centre velocity."""
        pos = d.site_xpos[self._hub]
        R = d.site_xmat[self._hub].reshape(-1, 3, 3)
        hx = R[:, :, 0].copy()
        hx[:, 2] = 0.0
        hx /= np.linalg.norm(hx, axis=1)[:, None]
        hy = np.column_stack([-hx[:, 1], hx[:, 0], np.zeros(len(hx))])
        cvel = d.cvel[self._hub_body]
        r = pos - d.subtree_com[self._root]
        w, v0 = cvel[:, :3], cvel[:, 3:]
        vel = v0 + np.column_stack([w[:, 1] * r[:, 2] - w[:, 2] * r[:, 1],
                                    w[:, 2] * r[:, 0] - w[:, 0] * r[:, 2],
                                    w[:, 0] * r[:, 1] - w[:, 1] * r[:, 0]])
        return pos, hx, hy, vel

    def _passive(self, m: mujoco.MjModel, d: mujoco.MjData) -> None:
        pos, hx, hy, vel = self._wheel_kinematics(d)
        rho = self.R0 - pos[:, 2]
        Fz = np.where(rho > 0.0, self.k_t * rho - self.c_t * vel[:, 2], 0.0)
        Fz = np.maximum(Fz, 0.0)
        Vx = np.einsum("ij,ij->i", vel, hx)
        Vy = np.einsum("ij,ij->i", vel, hy)
        Re = self.R0 - np.maximum(rho, 0.0) / 3.0
        Vsx = Vx - d.qvel[self._spin_dof] * Re
        u, v = d.act[self._act_u], d.act[self._act_v]
        du, dv = deflection_rates(self.tyre, Fz, Vx, Vsx, Vy, u, v)
        d.ctrl[self._tread_u] = du
        d.ctrl[self._tread_v] = dv
        Fx, Fy = transient_forces(self.tyre, Fz, Vx, Vsx, Vy, u, v, self._side)
        My = rolling_resistance(self.tyre, Fz, Vx)
        n = self._n_tyres
        F = (n * Fx)[:, None] * hx + (n * Fy)[:, None] * hy
        F[:, 2] += n * Fz
        torque = (n * My)[:, None] * hy  # about the spin axis
        contact = pos.copy()
        contact[:, 2] = 0.0
        self._last_forces = F
        for i in range(self.n_wheels):
            mujoco.mj_applyFT(m, d, F[i], torque[i], contact[i], int(self._wheel_body[i]),
                              d.qfrc_passive)

    # ------------------------------------------------------------ interface
    def reset(self, initial: InitialState) -> None:
        """Place the combination at ``initial``, at rest on its springs, rolling at ``u1``."""
        m, d = self.model, self.data
        mujoco.mj_resetData(m, d)
        psi = initial.psi_1
        dx, dy = rotate(psi, self._s1[0], self._s1[1])
        d.qpos[:3] = [initial.x_1 - dx, initial.y_1 - dy, 0.0]
        d.qpos[3:7] = [math.cos(psi / 2), 0.0, 0.0, math.sin(psi / 2)]
        d.qpos[m.jnt_qposadr[self._hitch_yaw]] = -initial.gamma
        v_origin = initial.v_y_1 - initial.r_1 * self._s1[0]
        d.qvel[:3] = [*rotate(psi, initial.u1, v_origin), 0.0]
        d.qvel[5] = initial.r_1
        d.qvel[m.jnt_dofadr[self._hitch_yaw]] = initial.r_2 - initial.r_1
        d.qvel[self._spin_dof] = initial.u1 / self.R0
        self._integral = 0.0
        self.steer_limited = 0
        mujoco.mj_forward(m, d)
        self._psi = np.array([psi, psi - initial.gamma])

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
        rr = self.tyre.QSY1 * self.mass * G * math.tanh(u_cmd / 0.1)
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

    def step(self, dt: float, delta: float, u1: float, u1_dot: float) -> None:
        """Advance ``dt`` [s]; see :mod:`mjcf.interface`.

        ``delta`` turns the left front wheel (the steering box's wheel); the
        right one follows through the linkage.
        """
        m, d = self.model, self.data
        lo, hi = self._servo_range
        if not lo <= delta <= hi:
            self.steer_limited += 1
            if self.steer_limited == 1:
                warnings.warn(f"t = {d.time:.2f} s: left-wheel angle {math.degrees(delta):.1f} "
                              f"deg is beyond the linkage's [{math.degrees(lo):.1f}, "
                              f"{math.degrees(hi):.1f}] deg; limited", PlantWarning,
                              stacklevel=2)
        d.ctrl[self._servo] = min(max(delta, lo), hi)
        h = m.opt.timestep
        n = max(1, round(dt / h))
        # The speed controller is sampled once per call (zero-order hold over
        # dt), at the middle of the interval, so MuJoCo runs n steps uninterrupted.
        self._control(u1 + u1_dot * 0.5 * (n - 1) * h, u1_dot, n * h)
        # MuJoCo resets a diverged simulation to t = 0 by itself: keep what a report needs.
        good_time, good_forces = d.time, self.last_forces.copy()
        mujoco.mj_step(m, d, nstep=n)
        self._check(good_time, good_forces, n * h)
        if self.backend == "numpy":
            self.check_tyre_ranges()
        elif d.userdata[-1]:  # the C callback counted wheels outside the file's ranges
            d.userdata[-1] = 0.0
            self.check_tyre_ranges()

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

    def observe(self, delta: float | None = None) -> np.ndarray:
        """Signals at the sensor points, in ``OBSERVATION`` order."""
        m, d = self.model, self.data
        out = np.empty(13)
        res = np.zeros(6)
        for i, (site, body) in enumerate(zip(self._sensor, (self._tractor, self._trailer),
                                             strict=True)):
            R = d.xmat[body].reshape(3, 3)
            psi = math.atan2(R[1, 0], R[0, 0])
            psi = self._psi[i] + wrap_angle(psi - self._psi[i])
            self._psi[i] = psi
            mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_SITE, site, res, 1)
            out[6 * i:6 * i + 6] = [d.site_xpos[site][0], d.site_xpos[site][1], psi,
                                    res[3], res[4], res[2]]
        out[12] = wrap_angle(out[2] - out[8])
        return out

    @property
    def gamma(self) -> float:
        """Articulation angle [rad]."""
        return float(wrap_angle(-self.data.qpos[self.model.jnt_qposadr[self._hitch_yaw]]))

    def wheel_loads(self) -> np.ndarray:
        """Vertical force of every wheel end from the last callback [N]."""
        return self.last_forces[:, 2].copy()

    def check_tyre_ranges(self) -> list[str]:
        """Warn for wheels outside the tyre file's valid ranges now (see :mod:`plant.tyre`).

        Called after every step; a wheel in the air (no load) is not reported.
        """
        n = self._n_tyres
        Fz = self.last_forces[:, 2] / n
        Fzc = np.maximum(Fz, self.tyre.FZMIN)  # as in the force evaluation
        kappa = self.data.act[self._act_u] / self.tyre.sigma_kappa(Fzc)
        alpha = np.arctan(self.data.act[self._act_v] / self.tyre.sigma_alpha(Fzc))
        loaded = Fz > 0.0
        if not loaded.any():
            return []
        names = [w for w, ok in zip(self.wheel_names, loaded, strict=True) if ok]
        return check_ranges(self.tyre, Fz[loaded], kappa[loaded], alpha[loaded], names,
                            f"t = {self.data.time:.2f} s")

    def compiled(self) -> None:
        """The plant has no compiled form for the harness's loop: ``None``."""
        return None

    def close(self) -> None:
        """Release the passive-force callback."""
        if not self._closed:
            callback.uninstall(self.model)
            self._closed = True

    def __enter__(self) -> Plant:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __del__(self) -> None:
        try:
            self.close()
        except Exception:  # noqa: BLE001 - interpreter shutdown
            pass
